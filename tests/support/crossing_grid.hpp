#pragma once
// An independent crossing checker for long runs: the level's segments bucketed in a uniform grid
// (no tree, no solver code), each candidate tested with the strict orientation predicate.
#include <algorithm>
#include <cmath>
#include <vector>

#include "curves.hpp"

namespace hk::test {

class CrossingGrid {
 public:
  CrossingGrid(const Scene& sc, int level, double cell_m = 0.002) : cell_(cell_m) {
    lo_ = {-0.1, -0.1};
    nx_ = ny_ = static_cast<int>(std::ceil(0.2 / cell_m));
    cells_.resize(static_cast<std::size_t>(nx_ * ny_));
    for (std::size_t c = 0; c < sc.curve_count(); ++c) {
      const int l = sc.clamp_level(c, level);
      for (std::uint32_t k = 0; k < sc.curve(c).segment_count[l]; ++k) {
        Vec2 a, b;
        sc.segment({static_cast<int>(c), l, static_cast<int>(k)}, &a, &b);
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
        if (crosses_strictly(p, q, segs_[static_cast<std::size_t>(id)].first, segs_[static_cast<std::size_t>(id)].second)) ++n;
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
