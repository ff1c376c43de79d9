#pragma once
/// @file tolerance_cut.hpp
/// A cut through one curve's collision tree at a tolerance instead of a level (issue 18; seed paper §3,
/// "contact computations at a desired tolerance level"): start from the coarsest segments and refine a
/// segment into its two children only while its error box allows an error above the tolerance. Flat
/// parts of the curve stay coarse, bends get fine segments, so a given maximum error takes fewer
/// vertices than any single level.
///
/// What the cut guarantees: every original vertex lies within max(tol_m, that segment's bound) of the
/// cut segment standing for it, where a segment's bound is `box_error_bound` of its box, and a segment
/// coarser than level 0 is kept only when its bound is ≤ tol_m. Level-0 segments are never refined
/// (nothing finer exists), so tolerances below the level-0 error are met only as far as level 0 meets them.
///
/// Segments of two levels do not share their end points (each level is its own smoothing of the curve),
/// so where the cut changes level its polyline has a break: two vertices where a single level has one.
/// `CutStats::vertices` counts them; joining the break costs a segment no longer than the two levels'
/// bounds together.

#include <cstdint>
#include <vector>

#include "haptics/scene.hpp"

namespace hk {

/// Size and error of a tolerance cut of one curve.
struct CutStats {
  std::size_t segments = 0;  ///< segments in the cut
  std::size_t breaks = 0;    ///< places where consecutive cut segments do not share an end point
  std::size_t vertices = 0;  ///< vertices of the cut drawn as a polyline: segments + breaks (+1 when open)
  double max_bound_m = 0.0;  ///< largest box_error_bound of a cut segment [m]
};

/// The tolerance cut of curve `curve` of `scene`, in curve order (segment refs of mixed levels covering
/// every level-0 segment exactly once), appended to `out`. tol_m ≥ 0 [m]; `curve` < curve_count().
/// Allocates (setup and analysis code, not the servo path). Returns its size and error bound.
CutStats tolerance_cut(const Scene& scene, std::size_t curve, double tol_m, std::vector<SegmentRef>* out);

}  // namespace hk
