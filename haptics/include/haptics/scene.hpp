#pragma once
/// @file scene.hpp
/// The scene index: every curve's multiresolution polylines and its collision tree of error boxes
/// (seed paper §3, DESIGN.md "Collision tree"), stored scene-wide in flat arrays addressed by node ids,
/// so the servo tick walks them with indices and a fixed-size stack and never chases pointers.
///
/// Node numbering. Each level l of curve c owns a run of slots starting at node
/// `curves[c].box_offset[l]`: one per point of the level, plus, for a closed curve, one repeating its
/// first point, so a level of s segments has s + 1 slots and segment k runs from slot k's point to slot
/// k + 1's. Segment k is node `box_offset[l] + k`; the run's last slot starts no segment and no walk
/// reaches it. Children of segment k at level l (l ≥ 1) are segments 2k and 2k+1 at level l−1: index
/// arithmetic, no links stored. After all slots come the chunks: runs of at most 4 consecutive
/// coarsest-level segments of one curve, each with an axis-aligned box around its segments' boxes.
/// Above the chunks sits a bounding-volume hierarchy (axis-aligned boxes, median split on the longer
/// axis, at most 4 chunks per leaf), entered through one node, `scene_root()`. Chunks are numbered in
/// the hierarchy's leaf order, so every node's children are consecutive ids, and no node has more than
/// 4 children: the boundary section stays small however long or many the curves are.
///
/// Storage (compact boxes). A segment's error box is not stored whole: its frame follows
/// from its end points (origin at the first, axis toward the second), so a slot keeps its point
/// (16 bytes, shared by the segment ending there) and the box's four extents quantised to 16 bits,
/// rounded outward (8 bytes), plus a 4-byte tag (curve and level). Only the few chunk and hierarchy nodes
/// keep an axis-aligned box and links.
/// The multiresolution is transformed straight into the slots (multires.hpp forward_levels): a level's
/// slots are its scaling coefficients, and the scene keeps no other copy of the model. The wavelet
/// coefficients are not kept (the walks never read them; build_multires gives the whole model, bit for
/// bit the same levels, for analysis), nor the level-0 points' arc lengths (level0_arc_m computes them).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "haptics/multires.hpp"
#include "haptics/wide_index.hpp"
#include "hk/constants.hpp"
#include "hk/vec2.hpp"

namespace hk {

/// A box aligned with a segment (seed §3 "error bounding box"), as the queries use it. 64 bytes; the scene
/// stores it compactly (BoxExtent) and Scene::box() rebuilds it.
/// Points q inside satisfy u_min ≤ dot(q − origin, axis) ≤ u_max and n_min ≤ cross(axis, q − origin) ≤ n_max.
struct ErrorBox {
  Vec2 origin_m;       ///< frame origin: the segment's first point [m]
  Vec2 axis;           ///< unit vector along the segment (x axis for a zero-length segment)
  double u_min = 0.0;  ///< extent along axis [m]
  double u_max = 0.0;
  double n_min = 0.0;  ///< extent along the left normal [m]
  double n_max = 0.0;
};
static_assert(sizeof(ErrorBox) == 64, "ErrorBox: one cache line per box");

/// An axis-aligned rectangle [m]: the cheap first test before a box's exact clip. 32 bytes.
struct Aabb {
  Vec2 lo, hi;
};
static_assert(sizeof(Aabb) == 32, "Aabb: two per cache line");

/// An axis-aligned rectangle as an ErrorBox [m]: origin (0, 0), axis (1, 0), its extents the rectangle's (how a
/// chunk's, a hierarchy node's or a wide index node's box is tested like a segment's).
inline ErrorBox rect_box(const Aabb& r) {
  return ErrorBox{Vec2{0.0, 0.0}, Vec2{1.0, 0.0}, r.lo.x, r.hi.x, r.lo.y, r.hi.y};
}

/// The rectangle of two points [m] (a segment's, or a sweep's from a to b), grown by grow_m ≥ 0 on every side.
inline Aabb rect_of(Vec2 a, Vec2 b, double grow_m = 0.0) {
  return Aabb{{std::min(a.x, b.x) - grow_m, std::min(a.y, b.y) - grow_m},
              {std::max(a.x, b.x) + grow_m, std::max(a.y, b.y) + grow_m}};
}

/// True when two rectangles overlap after growing `a` by margin_m on every side.
inline bool overlaps(const Aabb& a, const Aabb& b, double margin_m) {
  return a.lo.x - margin_m <= b.hi.x && b.lo.x <= a.hi.x + margin_m && a.lo.y - margin_m <= b.hi.y &&
         b.lo.y <= a.hi.y + margin_m;
}

/// True when p lies in the box, grown by `margin_m` on every side.
bool box_contains(const ErrorBox& box, Vec2 p, double margin_m = 0.0);
/// The four corners of the box [m], counter-clockwise.
void box_corners(const ErrorBox& box, Vec2 out[4]);
/// Largest distance of a box point from the line through its segment [m]: max(|n_min|, |n_max|).
inline double box_half_width(const ErrorBox& box) { return std::max(std::abs(box.n_min), std::abs(box.n_max)); }
/// Largest distance of a box point from its segment, of length segment_length_m [m]: the half-width
/// combined with how far the box reaches past the segment's ends. A point the box holds is no farther
/// from the segment than this, so it bounds the error of what the box stands for.
double box_error_bound(const ErrorBox& box, double segment_length_m);

/// Where one curve's data sits in the scene arrays, and what was measured of it. Levels 0 .. levels−1.
/// For setup code and tests; the servo path reads CurveNodes instead.
struct CurveInfo {
  bool closed = false;
  int levels = 0;
  double length_m = 0.0;  ///< arc length of the original curve (closed: the whole loop) [m]
  std::uint32_t point_offset[kMaxLevels] =
      {};  ///< index of level l's first point in the scene's point array (= box_offset[l])
  std::uint32_t point_count[kMaxLevels] =
      {};  ///< distinct points of level l (a closed curve's repeated first point not counted)
  std::uint32_t box_offset[kMaxLevels] = {};     ///< node id of level l's first segment
  std::uint32_t segment_count[kMaxLevels] = {};  ///< segments of level l (closed: points; open: points − 1)
  double max_error_m[kMaxLevels] =
      {};  ///< largest distance of an original point from the level-l segment standing for it [m]
  double max_box_half_width_m[kMaxLevels] = {};  ///< largest error box half-width at level l [m]
  double max_error_bound_m[kMaxLevels] =
      {};  ///< largest box_error_bound of level l (to a few ulps): bounds max_error_m[l] [m]
};

/// What the tree walks need of a curve: its levels' first node ids, the quantum of their box extents,
/// its level count, its level at each tolerance step. 144 bytes.
struct CurveNodes {
  std::uint32_t box_offset[kMaxLevels] = {};  ///< node id of level l's first segment (= slot of its first point)
  float quantum_m[kMaxLevels] = {};           ///< the unit of level l's BoxExtent [m]
  std::uint32_t levels = 0;                   ///< levels of the curve (its coarsest is levels − 1)
  std::uint32_t chunk_offset = 0;             ///< index of the curve's first chunk in Scene's chunk-of-curve array
  /// Level of the curve at tolerance step t (hk/constants.hpp): the coarsest whose max_error_bound_m is
  /// ≤ kToleranceLadder_m[t], 0 when none is.
  std::uint8_t tolerance_level[kToleranceSteps] = {};
};
static_assert(sizeof(CurveNodes) == 144, "CurveNodes: 144 bytes per curve");

/// The stored part of a segment's error box: its extents in the segment's frame (origin at the
/// segment's first point a, unit axis toward its second b, n along the left normal) as multiples of the
/// level's quantum q (CurveNodes::quantum_m), rounded outward so that the box only grows:
/// u from u_min·q to |b − a| + u_over·q, n from n_min·q to n_max·q [m]. The quantum is the level's
/// largest extent over 32000, so a box is at most q ≈ 3·10⁻⁵ of the level's widest extent larger than
/// exact. 8 bytes.
struct BoxExtent {
  std::int16_t u_min = 0, u_over = 0;  ///< along the axis: before the segment's start, past its end [quanta]
  std::int16_t n_min = 0, n_max = 0;   ///< along the left normal [quanta]
};
static_assert(sizeof(BoxExtent) == 8, "BoxExtent: eight per cache line");

/// Identifies one segment of one level of one curve. 12 bytes.
struct SegmentRef {
  std::int32_t curve = -1;
  std::int32_t level = 0;
  std::int32_t segment = -1;
};
static_assert(sizeof(SegmentRef) == 12, "SegmentRef: passed by value in the servo path");
constexpr bool operator==(SegmentRef a, SegmentRef b) {
  return a.curve == b.curve && a.level == b.level && a.segment == b.segment;
}

/// What a node is: its curve, level and index. 12 bytes. Stored for chunk and hierarchy nodes; computed
/// from a segment node's tag (Scene::info).
struct NodeInfo {
  std::uint32_t curve = 0;  ///< curve of a segment or chunk; curve of the first chunk under a hierarchy node
  std::int32_t level = 0;   ///< segment level; `levels` of its curve for a chunk; kHierarchyLevel above
  std::uint32_t index = 0;  ///< segment index within its level; a chunk's first coarsest segment; 0 above
};
static_assert(sizeof(NodeInfo) == 12, "NodeInfo: 12 bytes per node");

/// Build timings of a scene [ms].
struct SceneBuildTimes {
  double multires_ms = 0.0;  ///< level plans and arc tables, laying out the slots, the multiresolution into them [ms]
  double tree_ms = 0.0;      ///< error boxes and their quantising, chunks, hierarchy, wide index [ms]
};

/// All curves of a picture, ready for the servo loop. Immutable once built; shared read-only.
class Scene {
 public:
  static constexpr int kMaxLevels = hk::kMaxLevels;      ///< see hk/constants.hpp
  static constexpr std::int32_t kHierarchyLevel = 1000;  ///< NodeInfo::level of the nodes above the chunks

  /// Builds multiresolution models and collision trees for `curves` (workspace metres), with at most
  /// `max_levels` levels above level 0 (clamped to kMaxLevels − 1). Curves with fewer than 2 distinct
  /// points or zero length are skipped (counted in skipped_curves()). Throws std::bad_alloc when memory
  /// runs out, and hk::ArgumentError when the nodes would not fit 32-bit ids, or the curves a 28-bit tag
  /// (far beyond any picture's segment budget).
  static Scene build(const std::vector<Polyline>& curves, int max_levels);

  std::size_t curve_count() const noexcept { return curves_.size(); }
  const CurveInfo& curve(std::size_t c) const noexcept { return curves_[c]; }
  /// What the tree walks read of curve c (node offsets, levels).
  const CurveNodes& curve_nodes(std::size_t c) const noexcept { return curve_nodes_[c]; }
  /// Arc length along the original curve to curve c's level-0 point i [m]: its resampling parameter, bit
  /// for bit build_multires' arc_m[i]. i < curve(c).point_count[0].
  double level0_arc_m(std::size_t c, std::size_t i) const {
    const CurveInfo& ci = curves_[c];
    return hk::level0_arc_m(ci.length_m, ci.point_count[0], ci.closed, i);
  }
  /// Index of curve c in the `curves` handed to build().
  std::size_t source_index(std::size_t c) const { return source_index_[c]; }
  std::size_t skipped_curves() const { return skipped_; }

  /// Total node ids: the slots of all levels of all curves, the chunks, the hierarchy above.
  std::size_t node_count() const noexcept { return segment_nodes_ + group_box_.size(); }
  /// The one node every walk starts from (a hierarchy node; valid only when curve_count() > 0).
  std::uint32_t scene_root() const noexcept { return scene_root_; }
  /// True for slot ids (segment nodes; the last slot of each level, which starts no segment, included);
  /// false for chunks and the hierarchy.
  bool is_segment(std::uint32_t node) const noexcept { return node < segment_nodes_; }
  /// True for a chunk (a run of coarsest segments of one curve).
  bool is_chunk(std::uint32_t node) const noexcept {
    return node >= segment_nodes_ && node < segment_nodes_ + chunk_count_;
  }
  /// Coarsest segments per chunk, at most.
  static constexpr std::uint32_t kSegmentsPerChunk = 4;

  /// Curve (bits 4..31) and level (bits 0..3) of a segment node, packed.
  static constexpr std::uint32_t kTagLevelBits = 4;
  static_assert(kMaxLevels <= (1 << kTagLevelBits), "a level fits the tag's level bits");
  std::uint32_t tag_curve(std::uint32_t node) const noexcept { return tag_[node] >> kTagLevelBits; }
  int tag_level(std::uint32_t node) const noexcept {
    return static_cast<int>(tag_[node] & ((1u << kTagLevelBits) - 1));
  }

  /// The error box of a node: a segment's, rebuilt from its end points and stored extents; a chunk's or
  /// hierarchy node's axis-aligned box as an ErrorBox with origin (0, 0) and axis (1, 0). O(1), one root.
  /// A slot id must start a segment (as segment_box()).
  ErrorBox box(std::uint32_t node) const noexcept {
    if (node >= segment_nodes_) return rect_box(group_box_[node - segment_nodes_]);
    return segment_box(node);
  }
  /// The error box of segment node `node`: a slot that starts a segment, not a level's last slot
  /// (is_segment() is true for that one too, but it has no box: this would read the next level's first
  /// point, or past the array for the scene's last slot). Unchecked, for the walks' speed.
  ErrorBox segment_box(std::uint32_t node) const noexcept {
    const Vec2 a = points_m_[node];
    double length_m = 0.0;
    const Vec2 axis = segment_frame(a, points_m_[node + 1], &length_m);
    const double q = curve_nodes_[tag_curve(node)].quantum_m[tag_level(node)];
    const BoxExtent& e = extent_[node];
    return ErrorBox{a, axis, e.u_min * q, length_m + e.u_over * q, e.n_min * q, e.n_max * q};
  }
  /// The frame of the segment a→b: returns the unit vector along it ((1, 0) for a zero-length one) and
  /// writes its length [m]. The build measures extents in this frame and box() rebuilds it with this same
  /// function.
  static Vec2 segment_frame(Vec2 a, Vec2 b, double* length_m) {
    const Vec2 d = b - a;
    *length_m = length(d);
    if (!(*length_m > 1e-300)) return Vec2{1.0, 0.0};
    const double inverse = 1.0 / *length_m;  // one division for both components
    return Vec2{d.x * inverse, d.y * inverse};
  }
  /// A rectangle that holds a node's box [m], cheaply: for a segment, the rectangle of its end points
  /// grown by the box's largest overhang plus its largest half-width (no root, looser than aabb());
  /// for a chunk or hierarchy node, its stored rectangle. For rejecting boxes before rebuilding them.
  Aabb loose_aabb(std::uint32_t node) const noexcept {
    if (node >= segment_nodes_) return group_box_[node - segment_nodes_];
    const Vec2 a = points_m_[node], b = points_m_[node + 1];
    const BoxExtent& e = extent_[node];
    const int reach =
        std::max<int>(std::max<int>(-e.u_min, e.u_over), 0) + std::max<int>(std::max<int>(-e.n_min, e.n_max), 0);
    const double r = reach * static_cast<double>(curve_nodes_[tag_curve(node)].quantum_m[tag_level(node)]);
    return rect_of(a, b, r);
  }
  /// Axis-aligned rectangle around a node's box [m]: stored for chunks and the hierarchy, computed for
  /// segments (from the box's centre and half-extents, a few ulps wider than its four corners' rectangle).
  Aabb aabb(std::uint32_t node) const noexcept;
  /// Curve, level and index of a node (see NodeInfo).
  NodeInfo info(std::uint32_t node) const noexcept {
    if (node >= segment_nodes_) return group_info_[node - segment_nodes_];
    const std::uint32_t c = tag_curve(node);
    const int l = tag_level(node);
    return NodeInfo{c, l, node - curve_nodes_[c].box_offset[l]};
  }
  std::uint32_t node_of(SegmentRef s) const noexcept {
    return curve_nodes_[static_cast<std::size_t>(s.curve)].box_offset[s.level] + static_cast<std::uint32_t>(s.segment);
  }
  /// Parent of a node (the scene root's parent is itself). Inline: the section's merge checks ask it per entry.
  std::uint32_t parent(std::uint32_t node) const noexcept {
    if (node >= segment_nodes_) return group_parent_[node - segment_nodes_];
    const CurveNodes& cn = curve_nodes_[tag_curve(node)];
    const int l = tag_level(node);
    const std::uint32_t k = node - cn.box_offset[l];
    if (static_cast<std::uint32_t>(l) + 1 < cn.levels) return cn.box_offset[l + 1] + k / 2;
    return chunk_of_curve_[cn.chunk_offset + k / kSegmentsPerChunk];  // a coarsest segment: its chunk
  }
  /// First child and child count of a node; children are consecutive ids (0 for a level-0 segment).
  void children(std::uint32_t node, std::uint32_t* first, std::uint32_t* count) const noexcept {
    if (node >= segment_nodes_) {
      const std::size_t g = node - segment_nodes_;
      *first = group_child_first_[g];
      *count = group_child_count_[g];
      return;
    }
    const int l = tag_level(node);
    if (l == 0) {
      *first = 0;
      *count = 0;
      return;
    }
    const CurveNodes& cn = curve_nodes_[tag_curve(node)];
    *first = cn.box_offset[l - 1] + 2 * (node - cn.box_offset[l]);
    *count = 2;
  }
  /// Bytes of the arrays the servo path reads (points, box extents, tags, per-curve node offsets, the
  /// chunks' and hierarchy's boxes and links, the wide index's nodes), for bytes-per-segment figures.
  std::size_t hot_bytes() const;

  /// Level-l points of curve c (the scaling coefficients) [m]: point_count[l] of them, then, for a closed
  /// curve, the first again.
  const Vec2* points(std::size_t c, int level) const noexcept {
    return points_m_.data() + curves_[c].point_offset[level];
  }
  /// End points of a segment [m].
  void segment(SegmentRef s, Vec2* a, Vec2* b) const noexcept { segment_points(node_of(s), a, b); }
  /// The point of slot `node` [m]: segment node k runs from slot_points(k)[0] to slot_points(k)[1], and
  /// consecutive segments of a level share their slots (for walks that read a run of segments at once).
  const Vec2* slot_points(std::uint32_t node) const noexcept { return points_m_.data() + node; }
  /// End points of segment node `node` [m].
  void segment_points(std::uint32_t node, Vec2* a, Vec2* b) const noexcept {
    *a = points_m_[node];
    *b = points_m_[node + 1];
  }
  /// Segment count over all curves at level id `level` (each curve at clamp_level(c, level)).
  std::size_t total_segments(int level) const;
  /// The largest error-box half-width of any curve at level id `level` (each curve at clamp_level(c, level))
  /// [m]: how far apart two levels' polylines can be across the curve; 0 for an empty scene. O(curves): for
  /// setup code.
  double max_box_half_width_m(int level) const;
  /// The scene's error bound at level id `level`: the largest box_error_bound of any curve there (each curve
  /// at clamp_level(c, level)) [m]; no original point is farther than this from the level-`level`
  /// segment standing for it. 0 for an empty scene. O(curves): for setup code.
  double max_error_bound_m(int level) const;
  /// The coarsest level of curve c whose error bound (CurveInfo::max_error_bound_m) is ≤ tol_m [m], 0 when none
  /// is: the curve's level at a tolerance step (CurveNodes::tolerance_level), for any tolerance. O(levels).
  int coarsest_level_within(std::size_t c, double tol_m) const;
  /// Levels of the curve with the most levels (1 for an empty scene).
  int max_curve_levels() const;
  /// The level curve c renders at for level id `level` (hk/constants.hpp): a level is clamped to the
  /// curve's, min(level, levels−1) (0 below 0); a tolerance step gives the curve's own level for that
  /// tolerance (CurveNodes::tolerance_level). A cut step renders no single level: it gives its tolerance
  /// step's level, the one its cut refines (the cut's own segments: tolerance_cut.hpp). Ids past the last
  /// cut step count as the last.
  int clamp_level(std::size_t c, int level) const noexcept {
    const CurveNodes& cn = curve_nodes_[c];
    if (level >= kToleranceLevelBase) {
      const int step = level >= kCutLevelBase ? level - kCutLevelBase : level - kToleranceLevelBase;
      return cn.tolerance_level[std::min(step, kToleranceSteps - 1)];
    }
    const int top = static_cast<int>(cn.levels) - 1;
    return level < 0 ? 0 : (level > top ? top : level);
  }
  /// Bounding rectangle of every curve's level-0 points [m].
  Vec2 bounds_min() const { return bounds_min_; }
  Vec2 bounds_max() const { return bounds_max_; }
  const SceneBuildTimes& build_times() const { return times_; }
  /// The spatial 4-wide index over the item-level error boxes (wide_index.hpp), which the walks of
  /// first_hit and closest_point use instead of the curve-following hierarchy above the items.
  const WideIndex& wide_index() const noexcept { return wide_; }

 private:
  friend class SceneBuild;  // the build phases (scene_build.cpp)
  std::vector<CurveInfo> curves_;
  std::vector<CurveNodes> curve_nodes_;
  std::vector<std::size_t> source_index_;
  // Per slot (node ids 0 .. segment_nodes_ − 1).
  std::vector<Vec2> points_m_;
  std::vector<BoxExtent> extent_;
  std::vector<std::uint32_t> tag_;
  // Per chunk and hierarchy node (node id − segment_nodes_).
  std::vector<Aabb> group_box_;
  std::vector<NodeInfo> group_info_;
  std::vector<std::uint32_t> group_parent_, group_child_first_, group_child_count_;
  // Chunk node of each curve's chunks, in the curve's order (CurveNodes::chunk_offset + k / kSegmentsPerChunk
  // for its coarsest segment k): the parent of a coarsest segment.
  std::vector<std::uint32_t> chunk_of_curve_;
  std::size_t segment_nodes_ = 0;
  std::size_t chunk_count_ = 0;
  std::uint32_t scene_root_ = 0;
  std::size_t skipped_ = 0;
  Vec2 bounds_min_{0, 0}, bounds_max_{0, 0};
  SceneBuildTimes times_;
  WideIndex wide_;
};

}  // namespace hk
