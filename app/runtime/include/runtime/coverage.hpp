#pragma once
/// @file coverage.hpp
/// How much of a scene a run reached (DESIGN.md "Headless runs": summary.json
/// `coverage {length_fraction, curves_touched, curves}`): the fraction of the level-0 curves' length that
/// the proxy came within a radius of (1 mm), and the curves the proxy touched (was in contact with) at all.

#include <cstddef>
#include <unordered_map>
#include <vector>

#include "haptics/scene.hpp"
#include "hk/vec2.hpp"

namespace hk::app {

/// What coverage() found.
struct Coverage {
  double length_fraction =
      0.0;  ///< level-0 curve length within `radius_m` of a proxy position / all of it, in [0, 1]; 0 for an empty scene
  std::size_t curves_touched = 0;  ///< curves the proxy was in contact with (edge or vertex) at least once
  std::size_t curves = 0;          ///< curves in the scene
};

/// Collects a run's proxy positions and touched curves tick by tick, then measures the coverage.
class CoverageMeter {
 public:
  /// `radius_m` > 0: a curve point counts as reached when some proxy position lies within it [m].
  explicit CoverageMeter(double radius_m = 0.001);
  /// One tick: the proxy [m] and, while in contact, the curves of its constraints (−1 = none).
  void add(Vec2 proxy_m, int curve_a = -1, int curve_b = -1);
  /// The coverage of `scene`'s level-0 polylines, each sampled every radius/4 along its length (closed
  /// curves including the closing segment). Positions are kept in a hash grid of radius-sized cells, so a
  /// sample looks at 9 cells.
  Coverage measure(const Scene& scene) const;

 private:
  bool reached(Vec2 p) const;
  double radius_m_;
  std::unordered_map<long long, std::vector<Vec2>> cells_;  // cell key → proxy positions in it (1 per 1/8 radius moved)
  std::vector<bool> touched_;
  Vec2 last_kept_{1e300, 1e300};
};

}  // namespace hk::app
