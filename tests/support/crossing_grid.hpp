#pragma once
// An independent crossing checker for long runs: the level's segments bucketed in a uniform grid
// (no tree, no solver code), each candidate tested with the strict orientation predicate.
#include <algorithm>
#include <cmath>
#include <vector>

#include "curves.hpp"
#include "haptics/tolerance_cut.hpp"

namespace hk::test {

/// Curve c's polyline at level id `id` [m]: a level or tolerance step, its level's points (Scene::clamp_level);
/// a cut step, the cut's joined polyline, from tolerance_cut and joined_cut_points (not from the masks the
/// solver walks with). A closed curve's last point joins its first (not repeated); an open one has one more
/// point than segments.
inline std::vector<Vec2> polyline_at(const Scene& sc, std::size_t c, int id) {
  if (is_cut_level(id)) {
    std::vector<SegmentRef> cut;
    tolerance_cut(sc, c, kToleranceLadder_m[tolerance_step_of(id)], &cut);
    return joined_cut_points(sc, c, cut.data(), cut.size());
  }
  const int l = sc.clamp_level(c, id);
  const Vec2* p = sc.points(c, l);
  return std::vector<Vec2>(p, p + sc.curve(c).point_count[l]);
}

class CrossingGrid {
 public:
  /// The walls of level id `level` (a level, tolerance step or cut step: polyline_at).
  CrossingGrid(const Scene& sc, int level, double cell_m = 0.002) : cell_(cell_m) {
    lo_ = {-0.1, -0.1};
    nx_ = ny_ = static_cast<int>(std::ceil(0.2 / cell_m));
    cells_.resize(static_cast<std::size_t>(nx_ * ny_));
    for (std::size_t c = 0; c < sc.curve_count(); ++c) {
      const std::vector<Vec2> pts = polyline_at(sc, c, level);
      const std::size_t pieces = sc.curve(c).closed ? pts.size() : pts.size() - 1;
      for (std::size_t k = 0; k < pieces; ++k) {
        const Vec2 a = pts[k], b = pts[(k + 1) % pts.size()];
        const int id = static_cast<int>(segs_.size());
        segs_.push_back({a, b});
        for_cells(a, b, [&](int cell) { cells_[static_cast<std::size_t>(cell)].push_back(id); });
      }
    }
    stamp_.assign(segs_.size(), 0);
  }

  /// Number of segments the move p→q crosses strictly.
  int crossings(Vec2 p, Vec2 q) {
    ++tick_;
    int n = 0;
    for_cells(p, q, [&](int cell) {
      for (int id : cells_[static_cast<std::size_t>(cell)]) {
        if (stamp_[static_cast<std::size_t>(id)] == tick_) continue;
        stamp_[static_cast<std::size_t>(id)] = tick_;
        if (crosses_strictly(p, q, segs_[static_cast<std::size_t>(id)].first,
                             segs_[static_cast<std::size_t>(id)].second))
          ++n;
      }
    });
    return n;
  }

 private:
  template <class F>
  void for_cells(Vec2 a, Vec2 b, F f) const {
    auto ix = [&](double x) { return std::clamp(static_cast<int>(std::floor((x - lo_.x) / cell_)), 0, nx_ - 1); };
    auto iy = [&](double y) { return std::clamp(static_cast<int>(std::floor((y - lo_.y) / cell_)), 0, ny_ - 1); };
    for (int i = ix(std::min(a.x, b.x)); i <= ix(std::max(a.x, b.x)); ++i)
      for (int j = iy(std::min(a.y, b.y)); j <= iy(std::max(a.y, b.y)); ++j) f(j * nx_ + i);
  }
  double cell_;
  Vec2 lo_;
  int nx_, ny_;
  std::vector<std::vector<int>> cells_;
  std::vector<std::pair<Vec2, Vec2>> segs_;
  std::vector<unsigned> stamp_;
  unsigned tick_ = 0;
};

}  // namespace hk::test
