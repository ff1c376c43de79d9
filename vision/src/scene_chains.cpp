// Scene simplification (see scene_chains.hpp): thin lines, gaps, metres, budgets — the stages of
// simplify_chains as named functions.

#include "vision/scene_chains.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <utility>

#include "hk/error.hpp"
#include "vision/gaps.hpp"
#include "vision/thin_lines.hpp"

namespace hk::vision {

namespace {

// The curve's length [m], its segments' lengths added in order (a closed curve's closing segment last),
// or the partial sum at the first point where settled(partial sum) holds.
template <class Settled>
double summed_length_m(const SceneCurve& c, Settled settled) {
  double l = 0.0;
  for (std::size_t i = 1; i < c.points_m.size(); ++i) {
    l += cv::norm(c.points_m[i] - c.points_m[i - 1]);
    if (settled(l)) return l;
  }
  if (c.closed && c.points_m.size() > 1) l += cv::norm(c.points_m.front() - c.points_m.back());
  return l;
}

// !(curve_length_m(c) < min_length_m), the same decision bit for bit, without measuring past the point
// where it is settled: the length is a sum of non-negative terms added in the same order, so once a partial
// sum is not below the minimum the whole is not either (floating-point addition of non-negatives never
// decreases, and a NaN, once in, stays).
bool reaches_length_m(const SceneCurve& c, double min_length_m) {
  const auto reached = [min_length_m](double l) { return !(l < min_length_m); };
  return reached(summed_length_m(c, reached));
}

}  // namespace

double curve_length_m(const SceneCurve& c) {
  return summed_length_m(c, [](double) { return false; });
}

double enclosed_area_m2(const std::vector<cv::Point2d>& points_m) {
  const std::size_t n = points_m.size();
  if (n < 3) return 0.0;
  double twice = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const cv::Point2d a = points_m[i], b = points_m[(i + 1) % n];
    twice += a.x * b.y - b.x * a.y;
  }
  return 0.5 * std::abs(twice);
}

double shape_salience(const ShapeFeatures& f, double canny_high) {
  if (!std::isfinite(f.area_m2) || f.area_m2 < 0.0) return 0.0;
  if (!std::isfinite(f.length_m) || !std::isfinite(f.strength) || !std::isfinite(canny_high) || canny_high <= 0.0)
    return 0.0;
  const double outline_m = f.length_m + (f.closed ? 2.0 * std::sqrt(f.area_m2) : 0.0);
  return outline_m * std::max(0.0, f.strength) / canny_high;
}

double border_share(const SceneCurve& c, const PxToM& map, int width_px, int height_px, double band_m) {
  if (c.points_m.empty()) return 0.0;
  const double band_px = band_m / map.scale_m_per_px;
  std::size_t near = 0;
  for (const cv::Point2d& q : c.points_m) {
    const double u = map.u_px(q.x), v = map.v_px(q.y);
    // The frame is the outer edge of the outer pixels: u = -0.5 and u = width - 0.5.
    const double to_frame = std::min({u + 0.5, width_px - 0.5 - u, v + 0.5, height_px - 0.5 - v});
    near += to_frame <= band_px;
  }
  return static_cast<double>(near) / static_cast<double>(c.points_m.size());
}

std::vector<SceneCurve> chains_to_curves(const std::vector<Chain>& chains, const PointValues& strengths,
                                         const PxToM& map, double min_length_m, std::size_t* too_short) {
  std::vector<SceneCurve> out;
  out.reserve(chains.size());
  std::size_t dropped = 0;
  for (std::size_t k = 0; k < chains.size(); ++k) {
    SceneCurve c;
    c.closed = chains[k].closed;
    c.points_m.reserve(chains[k].points_px.size());
    for (const cv::Point2d& q : chains[k].points_px) c.points_m.emplace_back(map.x_m(q.x), map.y_m(q.y));
    if (!reaches_length_m(c, min_length_m)) {
      ++dropped;
      continue;
    }
    if (k < strengths.size() && !strengths[k].empty()) {
      c.strength =
          std::accumulate(strengths[k].begin(), strengths[k].end(), 0.0) / static_cast<double>(strengths[k].size());
    }
    out.push_back(std::move(c));
  }
  if (too_short) *too_short = dropped;
  return out;
}

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void check(const SimplifyParams& p) {
  for (const double v : {p.workspace_width_m, p.workspace_height_m})
    if (!std::isfinite(v) || v <= 0.0) throw hk::ArgumentError("simplify_chains: the workspace must be finite and > 0");
  for (const double v : {p.thin_line_max_width_m, p.gap_close_m, p.min_chain_length_m})
    if (!std::isfinite(v) || v < 0.0) throw hk::ArgumentError("simplify_chains: lengths must be finite and >= 0");
  if (p.max_shapes < 1 || p.max_segments < 1)
    throw hk::ArgumentError("simplify_chains: max_shapes and max_segments must be >= 1");
}

/// The chains and their strengths between the stages.
struct Work {
  std::vector<Chain> chains;
  PointValues strength;
};

/// Step 1: the two edges of a stroke thinner than a fingertip can resolve become its centre
/// line. Merged at the resolution the edges were found at (extract_chains returns original pixels; the
/// inverse of its scale-back is exact), where the chains are 8-connected pixel walks.
void merge_strokes(Work& w, const Extraction& ex, const PxToM& map, const SimplifyParams& p, SimplifyReport& r) {
  const auto t0 = std::chrono::steady_clock::now();
  const double sx = static_cast<double>(ex.width_px) / ex.edge_map.edges.cols;
  const double sy = static_cast<double>(ex.height_px) / ex.edge_map.edges.rows;
  for (Chain& c : w.chains)
    for (cv::Point2d& q : c.points_px) q = {(q.x + 0.5) / sx - 0.5, (q.y + 0.5) / sy - 0.5};
  // Metres → original px → processed px (sx and sy differ from each other only by rounding).
  const double width_px = p.thin_line_max_width_m / map.scale_m_per_px / (0.5 * (sx + sy));
  ThinLineStats st;
  PointValues merged_strength;
  w.chains = merge_thin_lines(w.chains, width_px, &st, w.strength, &merged_strength);
  w.strength = std::move(merged_strength);
  r.thin_line_pairs_merged = st.pairs_merged;
  for (Chain& c : w.chains)
    for (cv::Point2d& q : c.points_px) q = {(q.x + 0.5) * sx - 0.5, (q.y + 0.5) * sy - 0.5};
  r.thin_lines_ms = ms_since(t0);
}

/// Step 2: chain ends facing each other across at most gap_close_m are joined, so outlines
/// Canny broke at a highlight or a notch are felt closed.
void join_gaps(Work& w, const Extraction& ex, const PxToM& map, const SimplifyParams& p, SimplifyReport& r) {
  const auto t0 = std::chrono::steady_clock::now();
  GapParams gp;
  // The gap is the space between the two end pixels: their centres' distance less one pixel (of the
  // resolution the chains were found at, px_scale original px); in original px, as the chains are.
  gp.max_gap_px = p.gap_close_m / map.scale_m_per_px + ex.px_scale;
  gp.direction_span_px = std::max(gp.direction_span_px, 2.0 * gp.max_gap_px);
  // Outlines are completed, crumbs are not assembled: each piece joined is at least half as long as a curve
  // worth keeping (min_chain_length_m).
  gp.min_piece_px = 0.5 * p.min_chain_length_m / map.scale_m_per_px;
  GapStats gs;
  PointValues joined_strength;
  w.chains = close_gaps(w.chains, gp, &gs, w.strength, &joined_strength);
  w.strength = std::move(joined_strength);
  r.gaps_closed = gs.joins;
  r.chains_closed_by_gaps = gs.chains_closed;
  r.gaps_ms = ms_since(t0);
}

/// Step 4: curves along the picture's frame dropped; the rest taken in
/// decreasing shape_salience (ties: picture order), each kept while fewer than max_shapes are and its
/// segments still fit max_segments (a less salient one further down may still fit). The kept curves stay in
/// picture order, so curve ids follow the picture, not the ranking.
std::vector<SceneCurve> apply_budgets(std::vector<SceneCurve> curves, const Extraction& ex, const PxToM& map,
                                      const SimplifyParams& p, const SegmentCost& cost, SimplifyReport& r) {
  std::vector<std::size_t> order;
  std::vector<double> salience(curves.size(), 0.0);
  std::vector<std::size_t> segments(curves.size(), 0);
  for (std::size_t i = 0; i < curves.size(); ++i) {
    segments[i] = cost(curves[i]);
    r.segments_before_budget += segments[i];
    if (border_share(curves[i], map, ex.width_px, ex.height_px, kBorderBandM) >= kBorderShare) {
      ++r.chains_along_border;
      continue;
    }
    order.push_back(i);
    const SceneCurve& c = curves[i];
    salience[i] = shape_salience(
        {curve_length_m(c), c.strength, c.closed, c.closed ? enclosed_area_m2(c.points_m) : 0.0}, ex.edge_map.high);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return salience[a] > salience[b]; });
  std::vector<char> keep(curves.size(), 0);
  std::size_t kept = 0;
  for (const std::size_t i : order) {
    if (kept == p.max_shapes) {
      ++r.chains_over_max_shapes;
    } else if (r.segments_after_budget + segments[i] > p.max_segments) {
      ++r.chains_over_budget;
    } else {
      r.segments_after_budget += segments[i];
      ++kept;
      keep[i] = 1;
    }
  }
  std::vector<SceneCurve> out;
  out.reserve(kept);
  for (std::size_t i = 0; i < curves.size(); ++i)
    if (keep[i]) out.push_back(std::move(curves[i]));
  return out;
}

}  // namespace

SceneChains simplify_chains(Extraction ex, const SimplifyParams& p, const SegmentCost& cost) {
  check(p);
  SceneChains out;
  out.px_to_m = fit_to_workspace(ex.width_px, ex.height_px, p.workspace_width_m, p.workspace_height_m);
  out.report.chains_found = ex.chains.size();
  Work w{std::move(ex.chains), std::move(ex.point_strength)};
  ex.chains.clear();
  ex.point_strength.clear();
  // Steps 1 and 2 are for edge detectors' chains: a traced outline is closed by construction and exact to
  // the pixel, its narrow parts included; its open ends are where a shape runs into the frame.
  const bool edges = ex.detector_used != Detector::Outline;
  if (edges && p.thin_line_max_width_m > 0.0) merge_strokes(w, ex, out.px_to_m, p, out.report);
  out.report.chains_after_thin_lines = w.chains.size();
  if (edges && p.gap_close_m > 0.0) join_gaps(w, ex, out.px_to_m, p, out.report);
  out.report.chains_after_gaps = w.chains.size();
  std::vector<SceneCurve> curves =
      chains_to_curves(w.chains, w.strength, out.px_to_m, p.min_chain_length_m, &out.report.chains_too_short);
  out.curves = apply_budgets(std::move(curves), ex, out.px_to_m, p, cost, out.report);
  out.extraction = std::move(ex);
  return out;
}

SceneChains scene_chains(const std::string& path, const ExtractParams& ep, const SimplifyParams& p,
                         const SegmentCost& cost) {
  check(p);
  return simplify_chains(extract_chains(path, ep), p, cost);
}

SceneChains scene_chains_from_image(const cv::Mat& image, const ExtractParams& ep, const SimplifyParams& p,
                                    const SegmentCost& cost, const cv::Mat& ignore_mask) {
  check(p);
  return simplify_chains(extract_chains_from_image(image, ep, ignore_mask), p, cost);
}

}  // namespace hk::vision
