#pragma once
/// @file tolerance_cut.hpp
/// A cut through one curve's collision tree at a tolerance instead of a level (seed paper §3,
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
/// so where the cut changes level it has a break. The cut is drawn joined (joined_cut_points): at a
/// junction both pieces meet at the end point of the finer of the two segments. That point is a point of
/// a finer level at the coarser segment's end, which the coarser segment's error box holds (Scene: a box
/// holds every finer level's points under its segment, both ends included), so every piece of the joined
/// polyline still lies inside its own segment's error box and a miss on the box still proves a miss on it.
/// The join moves the coarser segment's end by `CutStats::max_join_shift_m` at most, so every original
/// vertex lies within max_bound_m + max_join_shift_m of the joined piece standing for it.
///
/// The cut as walls (`[haptics] level_mode = "cut"`, the cut steps of hk/constants.hpp): the servo's walks
/// do not build these lists. They read tolerance_cut_masks (which segments are cut at each step) and draw
/// each one with joined_cut_segment (BoundarySection::first_hit, closest_point_cut, wall_points).

#include <cstdint>
#include <memory>
#include <vector>

#include "haptics/scene.hpp"
#include "hk/constants.hpp"

namespace hk {

/// Size and error of a tolerance cut of one curve.
struct CutStats {
  std::size_t segments = 0;  ///< segments in the cut
  std::size_t breaks = 0;    ///< junctions where consecutive cut segments do not share an end point (joined)
  std::size_t vertices = 0;  ///< vertices of the joined polyline: segments, + 1 when the curve is open
  double max_bound_m = 0.0;  ///< largest box_error_bound of a cut segment [m]
  double max_join_shift_m =
      0.0;  ///< largest distance a segment's end moved to join a finer neighbour [m]; 0 without breaks
};

/// The tolerance cut of curve `curve` of `scene`, in curve order (segment refs of mixed levels covering
/// every level-0 segment exactly once), appended to `out`. tol_m ≥ 0 [m]; `curve` < curve_count().
/// Allocates (setup and analysis code, not the servo path). Returns its size and error bound.
CutStats tolerance_cut(const Scene& scene, std::size_t curve, double tol_m, std::vector<SegmentRef>* out);

/// The joined polyline of a tolerance cut of curve `curve`: `cut` points to the `count` segment refs that
/// tolerance_cut wrote for that curve, in order. Returns its vertices [m], count of them for a closed curve
/// (the last piece runs back to the first vertex), count + 1 for an open one: piece i runs from vertex i
/// to vertex i + 1. Each junction's vertex is the end point of the finer of the two segments meeting there
/// (either, when they are at one level: they share it). Empty when count is 0. Allocates (analysis code).
std::vector<Vec2> joined_cut_points(const Scene& scene, std::size_t curve, const SegmentRef* cut, std::size_t count);

/// Cut membership of every segment node of `scene` at every tolerance step (hk/constants.hpp), for walks that
/// stop at the cut instead of a level (BoundarySection::first_hit at level id kCutLevelBase + step): scene.node_count()
/// entries; entry n has bit t set when segment node n is a segment of tolerance_cut(scene, its curve,
/// kToleranceLadder_m[t]). The bounds are the ones tolerance_cut computes, compared the same way, so the cuts are the
/// same; one pass down each curve's tree computes each segment's bound once for all steps. Group nodes (chunks,
/// hierarchy) and segments below every step's cut are 0. Allocates (setup, not the servo path).
std::vector<std::uint8_t> tolerance_cut_masks(const Scene& scene);

/// Whether segment node `node` is a segment of tolerance step `step`'s cut: bit `step` of masks[node], where
/// `masks` is tolerance_cut_masks(scene) and 0 ≤ step < kToleranceSteps. Real-time safe.
inline bool in_cut(const std::uint8_t* masks, std::uint32_t node, int step) noexcept {
  return ((masks[node] >> step) & 1u) != 0;
}

/// What each tolerance step's cut keeps, over the whole scene, for the contact solver's level-change checks and
/// the level policy (the cut's counterparts of Scene::max_box_half_width_m and Scene::max_error_bound_m).
struct CutBounds {
  double error_bound_m[kToleranceSteps] = {};  ///< largest box_error_bound of a cut segment + largest join shift: no
                                               ///< original vertex is farther from its joined piece [m]
  double half_width_m[kToleranceSteps] =
      {};  ///< largest error-box half-width of a cut segment [m]; a joined piece lies anywhere in its box
};

/// The CutBounds of every step of `scene`'s cuts; `masks` is tolerance_cut_masks(scene). O(nodes · steps);
/// setup code.
CutBounds cut_bounds(const Scene& scene, const std::uint8_t* masks);

/// What the walls at the cut steps need of one scene, computed once and read by every boundary section of it
/// (the servo loop's contact and groove solvers share one): the cut masks and their bounds. About a tenth of
/// a second and one byte per node at 10^6 segments; immutable once built, so sharing it across threads is
/// safe.
struct CutWalls {
  const Scene* scene = nullptr;     ///< the scene it was computed for (a section checks it is its own)
  std::vector<std::uint8_t> masks;  ///< tolerance_cut_masks(*scene): scene->node_count() entries
  CutBounds bounds;                 ///< cut_bounds(*scene, masks.data())
};

/// The CutWalls of `scene` (which must outlive them). Allocates (setup, not the servo path).
std::shared_ptr<const CutWalls> make_cut_walls(const Scene& scene);

/// The end points [m] of cut segment `node` at tolerance step `step` (0 ≤ step < kToleranceSteps), drawn
/// joined as joined_cut_points draws them: where the cut segment next to it along the curve is finer, its
/// end there is that finer segment's end point; otherwise its own. `masks` is tolerance_cut_masks(scene),
/// and `node` must have bit `step` set in it (a segment of that cut). O(level of the node) mask reads per
/// end; allocates nothing, real-time safe.
void joined_cut_segment(const Scene& scene, const std::uint8_t* masks, std::uint32_t node, int step, Vec2* a,
                        Vec2* b) noexcept;

}  // namespace hk
