#pragma once
/// @file scene.hpp
/// The scene index: every curve's multiresolution polylines and its collision tree of error boxes
/// (seed paper §3, DESIGN.md "Collision tree"), stored scene-wide in flat arrays addressed by node ids,
/// so the servo tick walks them with indices and a fixed-size stack and never chases pointers.
///
/// Node numbering. Segment k of level l of curve c is node `curves[c].box_offset[l] + k`; children of
/// segment k at level l (l ≥ 1) are segments 2k and 2k+1 at level l−1. After all segment nodes come the
/// chunks: runs of at most 4 consecutive coarsest-level segments of one curve, each with an axis-aligned
/// box around its segments' boxes. Above the chunks sits a bounding-volume hierarchy (axis-aligned
/// boxes, median split on the longer axis, at most 4 chunks per leaf), entered through one node,
/// `scene_root()`. Chunks are numbered in the hierarchy's leaf order, so every node's children are
/// consecutive ids, and no node has more than 4 children: the boundary section stays small however
/// long or many the curves are.

#include <cstdint>
#include <vector>

#include "haptics/multires.hpp"
#include "haptics/vec2.hpp"
#include "hk/constants.hpp"

namespace hk {

/// A box aligned with a segment (seed §3 "error bounding box"). 64 bytes.
/// Points q inside satisfy u_min ≤ dot(q − origin, axis) ≤ u_max and n_min ≤ cross(axis, q − origin) ≤ n_max.
struct ErrorBox {
  Vec2 origin_m;        ///< frame origin: the segment's first point [m]
  Vec2 axis;            ///< unit vector along the segment (x axis for a zero-length segment)
  double u_min = 0.0;   ///< extent along axis [m]
  double u_max = 0.0;
  double n_min = 0.0;   ///< extent along the left normal [m]
  double n_max = 0.0;
};
static_assert(sizeof(ErrorBox) == 64, "ErrorBox: one cache line per box");

/// An axis-aligned rectangle [m]: the cheap first test before a box's exact clip. 32 bytes.
struct Aabb {
  Vec2 lo, hi;
};
static_assert(sizeof(Aabb) == 32, "Aabb: two per cache line");

/// True when two rectangles overlap after growing `a` by margin_m on every side.
inline bool overlaps(const Aabb& a, const Aabb& b, double margin_m) {
  return a.lo.x - margin_m <= b.hi.x && b.lo.x <= a.hi.x + margin_m && a.lo.y - margin_m <= b.hi.y && b.lo.y <= a.hi.y + margin_m;
}

/// True when p lies in the box, grown by `margin_m` on every side.
bool box_contains(const ErrorBox& box, Vec2 p, double margin_m = 0.0);
/// The four corners of the box [m], counter-clockwise.
void box_corners(const ErrorBox& box, Vec2 out[4]);
/// Largest distance of a box point from the line through its segment [m]: max(|n_min|, |n_max|).
double box_half_width(const ErrorBox& box);
/// Largest distance of a box point from its segment, of length segment_length_m [m]: the half-width
/// combined with how far the box reaches past the segment's ends. A point the box holds is no farther
/// from the segment than this, so it bounds the error of what the box stands for.
double box_error_bound(const ErrorBox& box, double segment_length_m);

/// Where one curve's data sits in the scene arrays. Levels 0 .. levels−1.
struct CurveInfo {
  bool closed = false;
  int levels = 0;
  std::uint32_t point_offset[kMaxLevels] = {};   ///< index of level l's first point in Scene::points_m
  std::uint32_t point_count[kMaxLevels] = {};    ///< points of level l
  std::uint32_t box_offset[kMaxLevels] = {};     ///< node id of level l's first segment
  std::uint32_t segment_count[kMaxLevels] = {};  ///< segments of level l (closed: points; open: points − 1)
  double max_error_m[kMaxLevels] = {};           ///< largest distance of an original point from the level-l segment standing for it [m]
  double max_box_half_width_m[kMaxLevels] = {};  ///< largest error box half-width at level l [m]
  double max_error_bound_m[kMaxLevels] = {};     ///< largest box_error_bound of level l: bounds max_error_m[l] [m]
};

/// Identifies one segment of one level of one curve. 12 bytes.
struct SegmentRef {
  std::int32_t curve = -1;
  std::int32_t level = 0;
  std::int32_t segment = -1;
};
static_assert(sizeof(SegmentRef) == 12, "SegmentRef: passed by value in the servo path");
constexpr bool operator==(SegmentRef a, SegmentRef b) { return a.curve == b.curve && a.level == b.level && a.segment == b.segment; }

/// Per-node bookkeeping the tree walks need. 12 bytes.
struct NodeInfo {
  std::uint32_t curve = 0;    ///< curve of a segment or chunk; curve of the first chunk under a hierarchy node
  std::int32_t level = 0;     ///< segment level; `levels` of its curve for a chunk; kHierarchyLevel above
  std::uint32_t index = 0;    ///< segment index within its level; a chunk's first coarsest segment; 0 above
};
static_assert(sizeof(NodeInfo) == 12, "NodeInfo: 12 bytes per node");

/// Build timings of a scene [ms].
struct SceneBuildTimes {
  double multires_ms = 0.0;
  double tree_ms = 0.0;
};

/// All curves of a picture, ready for the servo loop. Immutable once built; shared read-only.
class Scene {
 public:
  static constexpr int kMaxLevels = hk::kMaxLevels;  ///< see hk/constants.hpp
  static constexpr std::int32_t kHierarchyLevel = 1000;  ///< NodeInfo::level of the nodes above the chunks

  /// Builds multiresolution models and collision trees for `curves` (workspace metres), with at most
  /// `max_levels` levels above level 0 (clamped to kMaxLevels − 1). Curves with fewer than 2 distinct
  /// points or zero length are skipped (counted in skipped_curves()). Throws std::bad_alloc only.
  static Scene build(const std::vector<Polyline>& curves, int max_levels);

  std::size_t curve_count() const { return curves_.size(); }
  const CurveInfo& curve(std::size_t c) const { return curves_[c]; }
  /// The multiresolution model of curve c (scaling and wavelet coefficients; not used by the servo path).
  const CurveMultires& model(std::size_t c) const { return models_[c]; }
  /// Index of curve c in the `curves` handed to build().
  std::size_t source_index(std::size_t c) const { return source_index_[c]; }
  std::size_t skipped_curves() const { return skipped_; }

  /// Total nodes: segment nodes of all levels of all curves, the chunks, the hierarchy above.
  std::size_t node_count() const { return boxes_.size(); }
  /// The one node every walk starts from (a hierarchy node; valid only when curve_count() > 0).
  std::uint32_t scene_root() const { return scene_root_; }
  /// True for segment nodes (they carry a segment of some level); false for curve roots and above.
  bool is_segment(std::uint32_t node) const { return node < segment_nodes_; }
  /// True for a chunk (a run of coarsest segments of one curve).
  bool is_chunk(std::uint32_t node) const { return node >= segment_nodes_ && node < segment_nodes_ + chunk_count_; }
  /// Coarsest segments per chunk, at most.
  static constexpr std::uint32_t kSegmentsPerChunk = 4;
  const ErrorBox& box(std::uint32_t node) const { return boxes_[node]; }
  /// Axis-aligned rectangle around a node's box (its four corners) [m].
  const Aabb& aabb(std::uint32_t node) const { return aabbs_[node]; }
  const NodeInfo& info(std::uint32_t node) const { return info_[node]; }
  std::uint32_t node_of(SegmentRef s) const { return curves_[static_cast<std::size_t>(s.curve)].box_offset[s.level] + static_cast<std::uint32_t>(s.segment); }
  /// Parent of a node (the scene root's parent is itself).
  std::uint32_t parent(std::uint32_t node) const { return parent_[node]; }
  /// First child and child count of a node; children are consecutive ids (0 for a level-0 segment).
  void children(std::uint32_t node, std::uint32_t* first, std::uint32_t* count) const {
    *first = child_first_[node];
    *count = child_count_[node];
  }
  /// Bytes of the arrays the servo path reads (boxes, node links, points), for bytes-per-segment figures.
  std::size_t hot_bytes() const;

  /// Level-l points of curve c (the scaling coefficients) [m].
  const Vec2* points(std::size_t c, int level) const { return points_m_.data() + curves_[c].point_offset[level]; }
  /// End points of a segment [m].
  void segment(SegmentRef s, Vec2* a, Vec2* b) const;
  /// Segment count over all curves at `level` (curves with fewer levels use their coarsest).
  std::size_t total_segments(int level) const;
  /// The largest error-box half-width of any curve at `level` (curves with fewer levels count with their
  /// coarsest) [m]: how far apart two levels' polylines can be across the curve; 0 for an empty scene.
  /// O(curves): for setup code.
  double max_box_half_width_m(int level) const;
  /// The scene's error bound at `level`: the largest box_error_bound of any curve there (curves with fewer
  /// levels count with their coarsest) [m]; no original point is farther than this from the level-`level`
  /// segment standing for it. 0 for an empty scene. O(curves): for setup code.
  double max_error_bound_m(int level) const;
  /// Levels of the curve with the most levels (1 for an empty scene).
  int max_curve_levels() const;
  /// Coarsest level available in every curve clamped: min(level, levels−1 of curve c).
  int clamp_level(std::size_t c, int level) const {
    const int top = curves_[c].levels - 1;
    return level < 0 ? 0 : (level > top ? top : level);
  }
  /// Bounding rectangle of every curve's level-0 points [m].
  Vec2 bounds_min() const { return bounds_min_; }
  Vec2 bounds_max() const { return bounds_max_; }
  const SceneBuildTimes& build_times() const { return times_; }

 private:
  friend class SceneBuild;  // the build phases (scene.cpp)
  std::vector<CurveInfo> curves_;
  std::vector<CurveMultires> models_;
  std::vector<std::size_t> source_index_;
  std::vector<Vec2> points_m_;
  std::vector<ErrorBox> boxes_;
  std::vector<Aabb> aabbs_;
  std::vector<NodeInfo> info_;
  std::vector<std::uint32_t> parent_, child_first_, child_count_;
  std::size_t segment_nodes_ = 0;
  std::size_t chunk_count_ = 0;
  std::uint32_t scene_root_ = 0;
  std::size_t skipped_ = 0;
  Vec2 bounds_min_{0, 0}, bounds_max_{0, 0};
  SceneBuildTimes times_;
};

}  // namespace hk
