#pragma once
/// @file scene_chains.hpp
/// A picture → the curves a hand is given, in workspace metres, and why the others were left out (scene
/// simplification in one place; DESIGN.md "Data flow"). One call: scene_chains (a file) or
/// scene_chains_from_image (pixels in memory) runs extract_chains and then simplify_chains:
///   1. thin lines: the two edges of a stroke thinner than a fingertip resolves become its centre line
///      (merge_thin_lines, at the processed resolution);
///   2. gaps: chain ends facing each other across at most gap_close_m are joined (close_gaps);
///   3. pixels → metres (fit_to_workspace), chains shorter than min_chain_length_m dropped;
///   4. the budgets: curves along the picture's frame dropped; the rest taken in decreasing shape_salience,
///      each kept while fewer than max_shapes are and its level-0 segments (the caller's SegmentCost) still fit
///      max_segments.
/// Steps 1 and 2 are for edge detectors' chains only: a traced outline (Detector::Outline) is closed by
/// construction and exact to the pixel. The caller (app) builds the multiresolution model of the curves.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vision/mapping.hpp"
#include "vision/pipeline.hpp"

namespace hk::vision {

/// One curve of the scene in workspace metres (x right, y up, DESIGN.md "Frames and units").
struct SceneCurve {
  std::vector<cv::Point2d> points_m;  ///< vertices [m]; a closed curve's last point is not repeated
  bool closed = false;                ///< a closed outline
  /// Mean edge strength along it, in Canny threshold units (the Sobel-3x3 L2 gradient magnitude Canny
  /// thresholded, Extraction::point_strength; a centre line takes the mean of its two sides).
  double strength = 0.0;
};

/// Length of a curve [m], with the closing segment of a closed one (what a hand can follow).
double curve_length_m(const SceneCurve& c);

/// Area enclosed by the points taken as a closed polygon (shoelace formula, absolute value) [m²]; 0 for fewer
/// than 3 points.
double enclosed_area_m2(const std::vector<cv::Point2d>& points_m);

/// What a curve offers a hand, for ranking it against the others.
struct ShapeFeatures {
  double length_m = 0.0;  ///< curve length [m]
  double strength = 0.0;  ///< mean edge strength along it (SceneCurve::strength) [Canny threshold units]
  bool closed = false;    ///< a closed outline
  double area_m2 = 0.0;   ///< area it encloses when closed [m²], else 0
};

/// Salience of a shape for the budgets: its length plus, when closed, twice the square
/// root of the area it encloses, weighted by its mean edge strength relative to canny_high:
///
///   shape_salience = (length_m + closed · 2·√area_m2) · max(strength, 0) / canny_high
///
/// A closed outline is an object a visitor can recognise by going round it, and a large one more than a
/// small one: a square of side a counts 4a + 2a, a circle of radius r 2πr + 3.5 r; a thin closed loop (a
/// hair, a crack in the texture, w × L) gains only 2·√(w/L) of its length. Strength counts in proportion,
/// not clipped at canny_high as the old ranking (curve_salience, tests/support/curve_salience.hpp) was: with at most
/// max_shapes curves kept, the strongest boundaries of a photograph are its objects' outlines, and so the kept curves
/// carry more of the picture's edge strength × length than the old ranking's (tests/app/test_shape_budget.cpp). 0 for a
/// non-finite input or a non-positive canny_high; area_m2 must be >= 0 (0 for an open curve).
double shape_salience(const ShapeFeatures& f, double canny_high);

/// Share of a curve's points (in metres, mapped back to pixels through `map`) within band_m of the picture's
/// frame, the outer edge of its outer pixels, [0, 1]; 0 for no point.
double border_share(const SceneCurve& c, const PxToM& map, int width_px, int height_px, double band_m);

/// Curves with at least kBorderShare of their points within kBorderBandM of the picture's frame run along
/// the border (a scanned page's edge, a photo's frame line): not shapes, dropped.
inline constexpr double kBorderBandM = 0.001;  // [m]
inline constexpr double kBorderShare = 0.5;

/// Chains (pixels) → curves in workspace metres, dropping chains shorter than min_length_m (a fingertip cannot
/// resolve them); strengths[k] (optional: empty = strength 0) are chains[k]'s per-point strengths, averaged.
/// `too_short` (optional) receives the number dropped.
std::vector<SceneCurve> chains_to_curves(const std::vector<Chain>& chains, const PointValues& strengths,
                                         const PxToM& map, double min_length_m, std::size_t* too_short = nullptr);

/// Level-0 segments the haptic model of a curve costs (the caller's multiresolution model decides: the app
/// passes haptics' plan_levels). Must not throw.
using SegmentCost = std::function<std::size_t(const SceneCurve&)>;

/// The settings of simplify_chains, at the workspace scale ([vision] and [workspace] of the settings).
struct SimplifyParams {
  double workspace_width_m = 0.14;     ///< the workspace the picture is fitted to [m], > 0
  double workspace_height_m = 0.09;    ///< [m], > 0
  double thin_line_max_width_m = 0.0;  ///< strokes thinner than this are felt as their centre line [m]; 0 = off
  double gap_close_m = 0.0;            ///< widest gap between chain ends joined [m]; 0 = off
  double min_chain_length_m = 0.0;     ///< shorter curves are dropped [m], >= 0
  std::size_t max_shapes = 30;         ///< curves kept at most, >= 1
  std::size_t max_segments = 30000;    ///< level-0 segments kept at most (SegmentCost), >= 1
};

/// What simplify_chains left out and why, in pipeline order (each count is of the stage before it):
///   chains found --thin lines--> chains_after_thin_lines --gaps--> chains_after_gaps
///   = chains_too_short + chains_along_border + chains_over_max_shapes + chains_over_budget + curves kept.
struct SimplifyReport {
  std::size_t chains_found = 0;             ///< chains given (the extraction's)
  std::size_t thin_line_pairs_merged = 0;   ///< pairs of facing edges felt as one centre line
  std::size_t chains_after_thin_lines = 0;  ///< chains after thin-line merging
  std::size_t gaps_closed = 0;              ///< chain ends joined across a gap of at most gap_close_m
  std::size_t chains_closed_by_gaps = 0;    ///< chains that came out closed from those joins
  std::size_t chains_after_gaps = 0;        ///< chains after gap closing
  std::size_t chains_too_short = 0;         ///< dropped: shorter than min_chain_length_m
  std::size_t chains_along_border = 0;      ///< dropped: along the picture's frame (border_share >= kBorderShare)
  std::size_t chains_over_max_shapes = 0;   ///< dropped: max_shapes more salient curves were kept
  std::size_t chains_over_budget = 0;       ///< dropped: would exceed max_segments (least salient first)
  std::size_t segments_before_budget = 0;   ///< level-0 segments (SegmentCost) of every curve long enough to feel
  std::size_t segments_after_budget = 0;    ///< level-0 segments of the curves kept (<= max_segments)
  double thin_lines_ms = 0.0;               ///< wall time of thin-line merging [ms]
  double gaps_ms = 0.0;                     ///< wall time of gap closing [ms]
};

/// A picture's scene: the extraction (its chains moved into `curves`) and the curves kept, in the picture's
/// order (not the ranking's), with the report.
struct SceneChains {
  Extraction extraction;           ///< extract_chains' result; its chains and point strengths are moved out (empty)
  PxToM px_to_m{};                 ///< original pixels → workspace metres (fit_to_workspace)
  std::vector<SceneCurve> curves;  ///< the curves kept
  SimplifyReport report;
};

/// Steps 1-4 above on an extraction. `cost` prices each curve for max_segments.
/// @throws hk::ArgumentError for invalid parameters (a non-positive workspace or max_shapes, a negative or
///         non-finite length).
SceneChains simplify_chains(Extraction ex, const SimplifyParams& p, const SegmentCost& cost);

/// extract_chains(path, ep) then simplify_chains.
/// @throws InputError when the file is refused (see load_image); hk::ArgumentError as above.
SceneChains scene_chains(const std::string& path, const ExtractParams& ep, const SimplifyParams& p,
                         const SegmentCost& cost);

/// extract_chains_from_image(image, ep, ignore_mask) then simplify_chains.
/// @throws hk::ArgumentError as extract_chains_from_image and simplify_chains.
SceneChains scene_chains_from_image(const cv::Mat& image, const ExtractParams& ep, const SimplifyParams& p,
                                    const SegmentCost& cost, const cv::Mat& ignore_mask = {});

}  // namespace hk::vision
