#pragma once
/// @file faces.hpp
/// Guesses at faces in a picture, said as what they are: "something that could be a face". OpenCV's own
/// Haar cascade classifiers as Debian ships them (package opencv-data): the frontal (alt2) and the profile
/// cascade (Viola and Jones, "Rapid object detection using a boosted cascade of simple features", CVPR 2001;
/// Lienhart and Maydt's extended features, ICIP 2002), run on the picture shrunk to kFaceSearchSidePx. A box
/// counts only when the same cascade finds it again in the mirror image of its neighbourhood (intersection over
/// union at least kMirrorAgreement once mirrored back): a face looks like a face either way round, while the
/// cascades' chance hits on fins, coins and grids rarely survive the mirror. On the tests/data pictures this
/// finds the cameraman's face and nothing in the others (docs/visits/meaning.md has the table). Off the window
/// thread: it runs in the scene build's worker, and its result is kept in the scene cache.

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace hk::meaning {

/// Where Debian's opencv-data puts the Haar cascades.
inline constexpr const char* kOpenCvCascadeDir = "/usr/share/opencv4/haarcascades";
/// The long side the picture is shrunk to before the search [px]: faces a visitor could feel are at least a
/// tenth of the picture, 25 px here, above the cascades' 20 px (frontal) and 24 px (profile) windows.
inline constexpr int kFaceSearchSidePx = 224;
/// Smallest face searched for [px of the shrunk picture].
inline constexpr int kMinFacePx = 32;
/// Least intersection over union of a box found in the picture and one found in its mirror image.
inline constexpr double kMirrorAgreement = 0.4;

/// The faces guessed in `picture` (BGR or grey, any size; empty: none), as boxes on its pixels [px], at most 8,
/// the largest first. `cascade_dir`: the folder of haarcascade_frontalface_alt2.xml and
/// haarcascade_profileface.xml; when they cannot be loaded, no faces (one log line per process). The cascades
/// are loaded once per thread (about 20 ms). Cost: two cascade scans of a 224 px picture and a small one per
/// candidate, tens of milliseconds (docs/bench/meaning_cost.md has the figures). Never throws but std::bad_alloc.
std::vector<cv::Rect> find_faces(const cv::Mat& picture, const std::string& cascade_dir = kOpenCvCascadeDir);

}  // namespace hk::meaning
