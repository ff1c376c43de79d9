#pragma once
/// @file outline.hpp
/// Two-tone pictures (silhouettes, logos, diagrams, scanned drawings) traced from a threshold instead of
/// found by Canny: every boundary between the two tones becomes one chain, closed where it does not
/// run into the picture's frame, lying on the boundary to within one pixel. Canny on such a picture breaks
/// outlines at corners and junctions (non-maximum suppression thins the ridge and hysteresis loses its weak
/// ends), so a silhouette is felt as open strokes; a threshold's boundary is closed by construction.

#include <vector>

#include <opencv2/core.hpp>

#include "vision/linking.hpp"

namespace hk::vision {

/// What classify_two_tone found.
struct TwoTone {
  bool two_tone = false;    ///< the picture is two-tone (see classify_two_tone)
  double threshold = 0.0;   ///< Otsu's threshold [grey level]: the dark tone is <= threshold
  double dark_mean = 0.0;   ///< mean grey of the dark class [grey level]
  double light_mean = 0.0;  ///< mean grey of the light class [grey level]
  double near_share = 0.0;  ///< share of the pixels within kToneSpreadLevels of their class's mean, [0, 1]
  /// Mean width of the foreground (the tone covering less of the frame, as in trace_outlines): 2 · its area /
  /// the length of its boundary (4-neighbour pairs of unlike tone) [px]; a stroke of width w gives about w,
  /// a disc of radius r gives r. 0 when the picture has one tone. Tells a line drawing (strokes to be felt
  /// as one line each) from a silhouette (regions to be felt by their outline).
  double ink_width_px = 0.0;
};

/// A pixel this far from its tone's mean still belongs to the tone [grey levels].
inline constexpr double kToneSpreadLevels = 32.0;
/// The two tones' means are at least this far apart [grey levels].
inline constexpr double kMinToneGapLevels = 96.0;
/// At least this share of the pixels lies near a tone (the rest: anti-aliased or JPEG-rung boundaries).
inline constexpr double kMinNearShare = 0.98;

/// Splits the grey histogram in two with Otsu's threshold (N. Otsu, "A Threshold Selection Method from
/// Gray-Level Histograms", IEEE SMC 9(1), 1979; cv::threshold with THRESH_OTSU) and calls the picture two-tone
/// when the classes' means are at least kMinToneGapLevels apart and at least kMinNearShare of the pixels lie
/// within kToneSpreadLevels of their class's mean. On the test pictures: the silhouettes (1.000), the horse,
/// the Linux logo and the line drawings (0.983-0.988) are two-tone; photographs (0.49-0.95 or tones < 50
/// levels apart) are not. Also measures the foreground's ink_width_px (on every picture, two-tone or not).
/// @param grey CV_8UC1, not empty.
/// @throws hk::ArgumentError for an empty or non-CV_8UC1 image.
TwoTone classify_two_tone(const cv::Mat& grey);

/// The boundaries between the two tones of `grey` (split at `threshold`: dark <= threshold) as chains in pixel
/// coordinates (u right, v down, origin at the centre of the top-left pixel):
/// - the foreground is the tone that covers less of the picture's frame (the background usually fills it);
///   its outer boundaries and its holes' boundaries are traced with cv::findContours (S. Suzuki and K. Abe,
///   "Topological Structural Analysis of Digitized Binary Images by Border Following", CVGIP 30(1), 1985;
///   RETR_LIST, CHAIN_APPROX_NONE): foreground 8-connected, background 4-connected;
/// - points are the centres of the foreground's boundary pixels, so they lie half a pixel (a diagonal step:
///   0.71 px) inside the crack between the tones; consecutive points are 8-adjacent as in link_edges' chains,
///   but unlike them a chain passes a pixel twice where the region is one pixel wide (a hair is walked out and
///   back, a one-pixel bridge or the last pixels of a sharp tip both ways): the outline stays one chain;
/// - a boundary that never touches the frame is one closed chain; one that runs along the frame (a shape cut
///   by the picture's edge) loses its points on the frame row or column (the frame is no boundary) and leaves
///   one open chain per stretch between them;
/// - chains of fewer than `min_points` points are dropped.
/// @param grey CV_8UC1, not empty.
/// @throws hk::ArgumentError for an empty or non-CV_8UC1 image, or min_points < 1.
std::vector<Chain> trace_outlines(const cv::Mat& grey, double threshold, int min_points = 3);

}  // namespace hk::vision
