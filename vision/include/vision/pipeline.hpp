#pragma once
/// @file pipeline.hpp
/// The vision pipeline in one call, for the app: file -> grey -> edges -> chains.
///
/// Edge detection runs on a downscaled image because a fingertip cannot resolve more than a few
/// hundred features across the workspace and Canny on a 40 MP photo would take seconds; the
/// chains are scaled back to the original pixel grid so that the caller maps one image size.

#include <cstdint>
#include <string>
#include <vector>

#include "vision/edges.hpp"
#include "vision/intake.hpp"
#include "vision/linking.hpp"
#include "vision/outline.hpp"

namespace hk::vision {

/// How boundaries are found ([vision] detector).
/// The edge detectors (Canny, Surround, Bilateral, Edpf) were compared on every test picture and on generated
/// texture (docs/PERFORMANCE.md, "Texture out before edges"; bench/scene_detectors.sh); Auto uses the best.
enum class Detector : std::uint8_t {
  Auto,   ///< Outline for a two-tone picture (classify_two_tone), Canny for a line drawing, kAutoEdgeDetector for any
          ///< other
  Canny,  ///< detect_edges + link_edges (Gaussian blur, Canny, pixel-graph linking), no texture suppression
  Surround,   ///< Canny, then chains that do not stand out from their surround dropped as texture (texture.hpp)
  Bilateral,  ///< Canny after an edge-preserving bilateral filter (cv::bilateralFilter, kBilateral* below)
  Edpf,       ///< Edge Drawing, parameter-free (cv::ximgproc::EdgeDrawing, PFmode: a-contrario validated segments)
  Outline,    ///< trace_outlines at Otsu's threshold, whatever the picture
};

/// The edge detector Auto uses for a picture that is not two-tone (chosen by the measurements, see Detector).
inline constexpr Detector kAutoEdgeDetector = Detector::Surround;

/// The [vision] detector name of `d`: "auto", "canny", "surround", "bilateral", "edpf" or "outline".
const char* detector_name(Detector d);
/// The Detector named `name`; throws hk::ArgumentError (naming the choices) for any other name.
Detector detector_from_name(const std::string& name);

/// Bilateral filter of Detector::Bilateral, at the processed resolution: neighbourhood diameter [px], colour
/// sigma [grey levels] (differences well above it are edges and kept), space sigma [px]. Applied before the
/// Gaussian blur of detect_edges.
inline constexpr int kBilateralDiameterPx = 9;
inline constexpr double kBilateralSigmaGrey = 40.0;
inline constexpr double kBilateralSigmaSpacePx = 4.0;

/// Parameters of extract_chains.
struct ExtractParams {
  Detector detector = Detector::Auto;  ///< how boundaries are found
  ImageLimits limits;                  ///< refusal limits for the file (see load_image)
  EdgeParams edges;                    ///< edge detection, at the processed resolution
  int max_image_side_px = 800;         ///< longest side the image is shrunk to before edges [px], >= 1
  double min_chain_length_px = 20;     ///< shortest chain kept [processed px], >= 0 (see link_edges)
  /// Surround inhibition α of Detector::Surround's texture test (stands_out), >= 0; 0 keeps every chain.
  double surround_inhibition = 1.5;
  /// Auto: a two-tone picture whose ink (TwoTone::ink_width_px) is at most this wide at the workspace scale is
  /// a line drawing and goes to Canny, whose two edges of each stroke the caller merges into one centre line
  /// (thin_lines.hpp); wider ink is traced as outlines. 0 = no picture is a line drawing. [m], >= 0
  double line_drawing_max_ink_m = 0.0;
  double workspace_width_m = 0.14;   ///< the workspace the picture is fitted to (fit_to_workspace) [m], > 0
  double workspace_height_m = 0.09;  ///< [m], > 0
};

/// Wall-clock time of each stage [ms].
struct StageTimes {
  double load_ms;     ///< load_image + to_grey (file checks, decoding, grey, downscale)
  double edges_ms;    ///< detect_edges
  double linking_ms;  ///< link_edges + edge strength at the chain points + scaling the chains back
};

/// Result of extract_chains.
struct Extraction {
  int width_px;   ///< decoded image width [original px]
  int height_px;  ///< decoded image height [original px]
  /// Linked chains in ORIGINAL image pixel coordinates (u right, v down, origin at the centre of
  /// the top-left pixel) [px]. When the image was shrunk, a processed pixel centre (u', v') maps
  /// to ((u' + 0.5) * sx - 0.5, (v' + 0.5) * sy - 0.5) with sx = width_px / processed width and
  /// sy likewise, so points are not integers and consecutive points are about px_scale apart.
  std::vector<Chain> chains;
  /// Edge strength at every chain point (point_strength[k][i] at chains[k].points_px[i]): the L2
  /// gradient magnitude sqrt(gx^2 + gy^2) of the 3x3 Sobel derivatives of the blurred processed
  /// image at the point's processed pixel, i.e. exactly the magnitude Canny thresholded there, in
  /// the units of edge_map.low and edge_map.high (a blurred step of D grey levels gives about
  /// 8 D / (sigma sqrt(2 pi))). Used to rank curves by salience: a faint shading edge matters less
  /// than a strong outline of the same length.
  PointValues point_strength;
  /// Canny: the edges and the thresholds used, at the processed resolution. Outline: `edges` the traced
  /// boundary pixels kept (255, at the processed resolution), low = 0
  /// and high = half the Sobel magnitude a blurred step between the two tones gives (a boundary as sure as
  /// one over Canny's high threshold), so curve strengths compare with `high` alike.
  EdgeMap edge_map;
  Detector detector_used = Detector::Canny;  ///< the detector that ran (never Auto: what Auto chose)
  std::size_t texture_chains = 0;  ///< Surround: chains dropped as texture (not standing out from their surround)
  bool line_drawing = false;       ///< two-tone, but ink no wider than ExtractParams::line_drawing_max_ink_m
  TwoTone tones;                   ///< classify_two_tone of the processed grey image (Auto and Outline)
  double px_scale;                 ///< original px per processed px (>= 1; 1 = not shrunk), see to_grey
  StageTimes times;                ///< per-stage wall time
};

/// load_image -> to_grey (shrink to max_image_side_px) -> boundaries: detect_edges -> link_edges
/// (min_chain_length_px, measured at the processed resolution like the blur), or for a two-tone picture
/// (ExtractParams::detector) trace_outlines -> edge strength at each chain point (see
/// Extraction::point_strength; the blur and Sobel of detect_edges, sampled at the chain points only) ->
/// chains scaled back to original pixels.
///
/// @throws InputError when the file is refused (see load_image).
/// @throws hk::ArgumentError on invalid parameters.
Extraction extract_chains(const std::string& path, const ExtractParams& p);

/// extract_chains on pixels already in memory (a rendered PDF page, a camera frame), with regions where
/// edges are ignored: to_grey (shrink) -> detect_edges -> edge pixels under `ignore_mask` cleared ->
/// link_edges -> edge strength -> chains scaled back to `image`'s pixels. Used for document pages, whose
/// text is spoken, not felt: the letters' outlines never become curves.
///
/// @param image        CV_8UC1 (grey), CV_8UC3 (BGR) or CV_8UC4 (BGRA); not empty.
/// @param ignore_mask  empty (nothing ignored) or CV_8UC1 of image's size; nonzero = ignore edges there. It
///                     is shrunk with the image by area averaging and any coverage counts, so an ignored
///                     region never shrinks away.
/// Extraction::times.load_ms covers the grey conversion and shrinking only.
/// @throws hk::ArgumentError on invalid parameters, an empty or unsupported image, or a mask of
///         another size or type.
Extraction extract_chains_from_image(const cv::Mat& image, const ExtractParams& p, const cv::Mat& ignore_mask = {});

}  // namespace hk::vision
