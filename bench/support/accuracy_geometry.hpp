#pragma once
// Distances between polylines for bench/accuracy.cpp: a uniform grid of segments for nearest-distance
// queries, and the directed Hausdorff distance evaluated to a stated tolerance.
//
// Why not plain dense sampling: the distance d(p) from a point p to a fixed set is 1-Lipschitz, so
// walking along a segment of A, every point within δ ahead of p has d ≤ d(p) + δ. With M the largest
// distance seen so far, stepping δ = M − d(p) + tol can therefore never skip a point whose distance
// exceeds M + tol: the result underestimates the true directed Hausdorff distance by at most `tol`,
// however coarse the steps are where the curves are close. Far from the worst point this takes long
// steps, near it steps of `tol`, so a tolerance of micrometres costs less than fixed 20 µm sampling.
// Every vertex of A is evaluated (vertex distances seed M), so the result is also ≥ the exact
// vertex-to-polyline maximum, which the caller cross-checks by brute force.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "hk/vec2.hpp"

namespace hk::bench {

/// Squared distance from p to segment [a, b] [m²].
inline double segment_distance_sq(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const double len_sq = length_sq(ab);
  double t = len_sq > 0.0 ? dot(p - a, ab) / len_sq : 0.0;
  t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  return length_sq(p - lerp(a, b, t));
}

/// Number of segments of a polyline (closed: one more, the closing segment back to the first point).
inline std::size_t polyline_segments(const std::vector<Vec2>& pts, bool closed) {
  if (pts.size() < 2) return 0;
  return closed ? pts.size() : pts.size() - 1;
}

/// Distance from p to a polyline by looking at every segment: slow, obviously right, the reference
/// the grid is checked against.
inline double brute_distance_m(Vec2 p, const std::vector<Vec2>& pts, bool closed) {
  const std::size_t ns = polyline_segments(pts, closed);
  if (ns == 0) return pts.empty() ? std::numeric_limits<double>::infinity() : distance(p, pts[0]);
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < ns; ++k) best = std::min(best, segment_distance_sq(p, pts[k], pts[(k + 1) % pts.size()]));
  return std::sqrt(best);
}

/// Nearest distance from a point to one polyline through a uniform grid of its segments. Each segment
/// is listed in every cell its bounding box overlaps; a query visits square rings of cells around the
/// query's cell until nothing outside the visited block can be closer than the best found.
/// Not thread-safe (a per-query stamp array avoids testing a segment twice); one grid per thread.
class SegmentGrid {
 public:
  SegmentGrid(const std::vector<Vec2>& pts, bool closed) {
    const std::size_t ns = polyline_segments(pts, closed);
    for (std::size_t k = 0; k < ns; ++k) {
      a_.push_back(pts[k]);
      b_.push_back(pts[(k + 1) % pts.size()]);
    }
    if (ns == 0 && !pts.empty()) {  // a single point: a zero-length segment
      a_.push_back(pts[0]);
      b_.push_back(pts[0]);
    }
    const std::size_t n = a_.size();
    Vec2 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()}, hi{-lo.x, -lo.y};
    double total_len_m = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      for (Vec2 q : {a_[k], b_[k]}) {
        lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
        hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
      }
      total_len_m += distance(a_[k], b_[k]);
    }
    // Cells about one segment long: a query then tests a handful of segments at any level. The cell
    // count is capped near 4 per segment so that a curve with a few long segments does not allocate
    // a huge, mostly empty grid.
    const double w_m = std::max(hi.x - lo.x, 1e-9), h_m = std::max(hi.y - lo.y, 1e-9);
    cell_m_ = std::max(n > 0 ? total_len_m / static_cast<double>(n) : 1e-6, 1e-7);
    const double max_cells = 4.0 * static_cast<double>(n) + 1024.0;
    if ((w_m / cell_m_ + 1.0) * (h_m / cell_m_ + 1.0) > max_cells)
      cell_m_ = std::sqrt(w_m * h_m / max_cells) + std::max(w_m, h_m) / max_cells;
    origin_ = lo;
    nx_ = static_cast<int>(w_m / cell_m_) + 1;
    ny_ = static_cast<int>(h_m / cell_m_) + 1;
    // Compressed rows: count, prefix sum, fill.
    start_.assign(static_cast<std::size_t>(nx_) * ny_ + 1, 0);
    auto for_cells = [&](std::size_t k, auto&& fn) {
      const int x0 = cell_x(std::min(a_[k].x, b_[k].x)), x1 = cell_x(std::max(a_[k].x, b_[k].x));
      const int y0 = cell_y(std::min(a_[k].y, b_[k].y)), y1 = cell_y(std::max(a_[k].y, b_[k].y));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) fn(static_cast<std::size_t>(y) * nx_ + x);
    };
    for (std::size_t k = 0; k < n; ++k) for_cells(k, [&](std::size_t c) { ++start_[c + 1]; });
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    items_.resize(start_.back());
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t k = 0; k < n; ++k)
      for_cells(k, [&](std::size_t c) { items_[fill[c]++] = static_cast<std::uint32_t>(k); });
    stamp_.assign(n, 0);
  }

  /// Distance from p to the polyline [m].
  double distance_m(Vec2 p) const {
    if (a_.empty()) return std::numeric_limits<double>::infinity();
    if (++epoch_ == 0) {  // stamps wrapped: clear them once every 2^32 queries
      std::fill(stamp_.begin(), stamp_.end(), 0);
      epoch_ = 1;
    }
    const int cx = cell_x(p.x), cy = cell_y(p.y);
    double best_sq = std::numeric_limits<double>::infinity();
    for (int r = 0;; ++r) {
      const int x0 = cx - r, x1 = cx + r, y0 = cy - r, y1 = cy + r;
      for (int y = std::max(y0, 0); y <= std::min(y1, ny_ - 1); ++y) {
        const bool edge_row = (y == y0 || y == y1);
        for (int x = std::max(x0, 0); x <= std::min(x1, nx_ - 1); ++x) {
          if (!edge_row && x != x0 && x != x1) continue;  // only the ring, the inside was visited before
          const std::size_t c = static_cast<std::size_t>(y) * nx_ + x;
          for (std::uint32_t i = start_[c]; i < start_[c + 1]; ++i) {
            const std::uint32_t k = items_[i];
            if (stamp_[k] == epoch_) continue;
            stamp_[k] = epoch_;
            best_sq = std::min(best_sq, segment_distance_sq(p, a_[k], b_[k]));
          }
        }
      }
      // Everything not yet visited lies in cells outside the block [x0, x1] × [y0, y1]; a side that
      // already reaches the grid's edge has nothing beyond it. The query cell is clamped into the
      // grid, so p is inside the block along every axis whose far side is still open.
      double bound_m = std::numeric_limits<double>::infinity();
      if (x0 > 0) bound_m = std::min(bound_m, p.x - (origin_.x + x0 * cell_m_));
      if (x1 < nx_ - 1) bound_m = std::min(bound_m, origin_.x + (x1 + 1) * cell_m_ - p.x);
      if (y0 > 0) bound_m = std::min(bound_m, p.y - (origin_.y + y0 * cell_m_));
      if (y1 < ny_ - 1) bound_m = std::min(bound_m, origin_.y + (y1 + 1) * cell_m_ - p.y);
      if (bound_m == std::numeric_limits<double>::infinity()) break;  // the block covers the whole grid
      if (bound_m > 0.0 && best_sq <= bound_m * bound_m) break;
    }
    return std::sqrt(best_sq);
  }

 private:
  int cell_x(double x) const { return std::clamp(static_cast<int>(std::floor((x - origin_.x) / cell_m_)), 0, nx_ - 1); }
  int cell_y(double y) const { return std::clamp(static_cast<int>(std::floor((y - origin_.y) / cell_m_)), 0, ny_ - 1); }

  std::vector<Vec2> a_, b_;
  Vec2 origin_{};
  double cell_m_ = 1.0;
  int nx_ = 1, ny_ = 1;
  std::vector<std::uint32_t> start_, items_;
  mutable std::vector<std::uint32_t> stamp_;
  mutable std::uint32_t epoch_ = 0;
};

/// Directed Hausdorff distance max_{a ∈ A} d(a, B) [m], where B is given by its grid; A is the whole
/// polyline (every point of every segment, closing segment included), not just its vertices.
/// Underestimates the true value by at most `tol_m` (see the file comment); `seed_m` is a known lower
/// bound (e.g. the largest of some sampled distances), which only makes the early steps longer.
inline double directed_hausdorff_m(const std::vector<Vec2>& a_pts, bool a_closed, const SegmentGrid& b, double tol_m,
                                   double seed_m = 0.0) {
  double worst_m = seed_m;
  for (const Vec2& p : a_pts) worst_m = std::max(worst_m, b.distance_m(p));
  const std::size_t ns = polyline_segments(a_pts, a_closed);
  for (std::size_t k = 0; k < ns; ++k) {
    const Vec2 s0 = a_pts[k], s1 = a_pts[(k + 1) % a_pts.size()];
    const double len_m = distance(s0, s1);
    double t_m = 0.0;
    double d_m = b.distance_m(s0);  // the vertex again (cheap), so the first step is sized from it
    while (true) {
      t_m += worst_m - d_m + tol_m;
      if (t_m >= len_m) break;  // the segment's far end is a vertex, already evaluated
      d_m = b.distance_m(lerp(s0, s1, t_m / len_m));
      worst_m = std::max(worst_m, d_m);
    }
  }
  return worst_m;
}

/// Root mean square of d(o, B) over the polyline O by arc length [m], midpoint rule with pieces of at
/// most `step_m`; `max_out` receives the largest sampled distance (a lower bound of the directed
/// Hausdorff distance O → B, used to seed it).
inline double rms_distance_m(const std::vector<Vec2>& o_pts, bool o_closed, const SegmentGrid& b, double step_m,
                             double* max_out) {
  double sum_sq = 0.0, sum_len = 0.0, worst = 0.0;
  const std::size_t ns = polyline_segments(o_pts, o_closed);
  for (std::size_t k = 0; k < ns; ++k) {
    const Vec2 s0 = o_pts[k], s1 = o_pts[(k + 1) % o_pts.size()];
    const double len_m = distance(s0, s1);
    if (len_m <= 0.0) continue;
    const int pieces = std::max(1, static_cast<int>(std::ceil(len_m / step_m)));
    const double w_m = len_m / pieces;
    for (int i = 0; i < pieces; ++i) {
      const double d = b.distance_m(lerp(s0, s1, (i + 0.5) / pieces));
      sum_sq += w_m * d * d;
      worst = std::max(worst, d);
    }
    sum_len += len_m;
  }
  if (max_out) *max_out = worst;
  return sum_len > 0.0 ? std::sqrt(sum_sq / sum_len) : 0.0;
}

}  // namespace hk::bench
