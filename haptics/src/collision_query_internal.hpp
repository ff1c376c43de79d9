#pragma once
// What the files of the collision query share and the public header leaves out: small geometric helpers, the
// tie-break of answers, the section's private operations (BoundarySection::Ops, static functions taking the
// section), one first_hit's state (BoundarySection::Query), and the small operations its inner loops call from
// several files, defined inline here so they stay inlined (collision_query.hpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "collision_simd.hpp"
#include "haptics/collision_query.hpp"

namespace hk {
namespace collision_detail {

// Writes the section scan's masks four bits at a time: the bits of entries i .. i + 3 (i a multiple of 4, in
// increasing order) go to bits i % 64 .. i % 64 + 3 of words[i / 64]; finish(end) stores the last, partial word.
struct QuadBitWriter {
  std::uint64_t* words;
  std::uint64_t word = 0;
  void put(std::size_t i, unsigned four_bits) noexcept {
    word |= static_cast<std::uint64_t>(four_bits) << (i % 64);
    if (i % 64 == 60) {
      words[i / 64] = word;
      word = 0;
    }
  }
  void finish(std::size_t end) noexcept {
    if (end % 64 != 0) words[end / 64] = word;
  }
};

// Squared distance from p to an axis-aligned rectangle (0 inside) [m²]: a lower bound on the distance to the
// box it holds.
inline double rect_distance_sq(const Aabb& r, Vec2 p) {
  const double dx = std::max({r.lo.x - p.x, 0.0, p.x - r.hi.x});
  const double dy = std::max({r.lo.y - p.y, 0.0, p.y - r.hi.y});
  return dx * dx + dy * dy;
}

// Squared distance from p to a box (0 inside) [m²].
inline double box_distance_sq(const ErrorBox& box, Vec2 p) {
  const Vec2 r = p - box.origin_m;
  const double u = dot(r, box.axis);
  const double n = cross(box.axis, r);
  const double du = std::max({box.u_min - u, 0.0, u - box.u_max});
  const double dn = std::max({box.n_min - n, 0.0, n - box.n_max});
  return du * du + dn * dn;
}

// True for a segment node at the level a walk targets, resolved per curve (Scene::clamp_level). A walk
// reaches a curve's segments from its coarsest level down, so a segment's level is never above that
// clamp, which for a level then comes down to comparing with the target itself (or 0, for a negative
// target); a tolerance step needs the curve's own level for it.
inline bool at_target_level(const Scene& sc, std::uint32_t node, int level) {
  if (!sc.is_segment(node)) return false;
  if (level >= kToleranceLevelBase) return sc.tag_level(node) <= sc.clamp_level(sc.tag_curve(node), level);
  return sc.tag_level(node) <= std::max(level, 0);
}

// "d at s is a better answer than best_d at best_s": smaller (a distance, or a first hit's sweep parameter), or
// as small and the smaller (curve, level, segment), so ties do not depend on the order segments are met in.
inline bool closer(double d, SegmentRef s, double best_d, SegmentRef best_s) {
  if (d != best_d) return d < best_d;
  if (s.curve != best_s.curve) return s.curve < best_s.curve;
  if (s.level != best_s.level) return s.level < best_s.level;
  return s.segment < best_s.segment;
}

// True when s is one of the count segments at excluded (the walls a query leaves out: edge contact's).
inline bool is_excluded(SegmentRef s, const SegmentRef* excluded, int count) {
  for (int i = 0; i < count; ++i) {
    if (excluded[i] == s) return true;
  }
  return false;
}

// Larger than every real segment reference: "no answer yet".
constexpr SegmentRef kNoSegment{std::numeric_limits<std::int32_t>::max(), std::numeric_limits<std::int32_t>::max(),
                                std::numeric_limits<std::int32_t>::max()};

// The bodies of clip_segment_box and intersect_sweep_segment (collision_query.hpp), inline for the query's inner
// loops; the public functions (sweep_geometry.cpp) call these.
inline bool clip_segment_box_inline(const ErrorBox& box, Vec2 a, Vec2 b, double margin_m, double* t_enter,
                                    double* t_exit) noexcept {
  // Work in the box frame: u along the axis, n along the left normal.
  const Vec2 ra = a - box.origin_m;
  const Vec2 d = b - a;
  const double p0[2] = {dot(ra, box.axis), cross(box.axis, ra)};
  const double dp[2] = {dot(d, box.axis), cross(box.axis, d)};
  const double lo[2] = {box.u_min - margin_m, box.n_min - margin_m};
  const double hi[2] = {box.u_max + margin_m, box.n_max + margin_m};
  // Both slabs always, without a branch on the data (a clip's outcome is a coin toss to the predictor): t0 only
  // grows and t1 only shrinks, so an empty interval after the first slab stays empty.
  double t0 = 0.0, t1 = 1.0;
  bool inside_parallel = true;
  for (int i = 0; i < 2; ++i) {
    if (dp[i] == 0.0) {  // parallel to this slab: inside it or not at all (seldom: a predictable branch)
      inside_parallel = inside_parallel && p0[i] >= lo[i] && p0[i] <= hi[i];
      continue;
    }
    const double inv = 1.0 / dp[i];
    const double ta = (lo[i] - p0[i]) * inv;
    const double tb = (hi[i] - p0[i]) * inv;
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  if (!inside_parallel || t0 > t1) return false;
  *t_enter = t0;
  *t_exit = t1;
  return true;
}

inline bool intersect_sweep_segment_inline(Vec2 a, Vec2 b, Vec2 p, Vec2 q, double* t) noexcept {
  const Vec2 r = b - a;
  const Vec2 s = q - p;
  const double denom = cross(r, s);
  if (denom == 0.0) return false;  // parallel or collinear: sliding along a wall is not crossing it
  const Vec2 ap = p - a;
  const double tt = cross(ap, s) / denom;
  const double uu = cross(ap, r) / denom;
  if (tt < 0.0 || tt > 1.0 || uu < 0.0 || uu > 1.0) return false;
  *t = tt;
  return true;
}

}  // namespace collision_detail

// The collision query's files use these helpers unqualified.
using namespace collision_detail;

// The section's private operations, as static functions of a nested struct (so they reach its members) declared
// here rather than in the public header: the phases of first_hit, the frontier's edits, the wide and
// closest-point walks. Each takes the section as its first argument `self`.
struct BoundarySection::Ops {
  static bool at_target(const BoundarySection& self, std::uint32_t node, int level) noexcept;
  static void wall_node_points(const BoundarySection& self, std::uint32_t node, int level, Vec2* a, Vec2* b) noexcept;
  // The phases of first_hit, in order (each documented where it is defined).
  [[gnu::cold]] static void follow_level(BoundarySection& self, int level) noexcept;
  static void coarsen_section(BoundarySection& self, int level) noexcept;
  static std::uint32_t wall_ancestor(const BoundarySection& self, std::uint32_t node, int level) noexcept;
  static bool at_floor(const BoundarySection& self, std::uint32_t node, int level) noexcept;
  static bool inside_free_ball(const BoundarySection& self, Vec2 a, Vec2 b) noexcept;
  static SweepHit first_hit_near_walls(BoundarySection& self, Vec2 a, Vec2 b, int level, const SegmentRef* excluded,
                                       int excluded_count, QueryBudget& budget, QueryStats* stats_out) noexcept;
  static SweepHit first_hit_tree(BoundarySection& self, Vec2 a, Vec2 b, int level, const SegmentRef* excluded,
                                 int excluded_count, QueryBudget& budget, QueryStats* stats_out) noexcept;
  // Whether the wide index holds the walls of level id `level` (not a cut step): every curve is at or below its item
  // level there (wide_index.hpp). The walks of coarser ids go through the tree of error boxes.
  // A level below 0 is level 0 (Scene::clamp_level).
  static bool wide_serves(const BoundarySection& self, int level) noexcept {
    return level < kCutLevelBase && self.wide_serves_[static_cast<std::size_t>(std::max(level, 0))];
  }
  static bool answer_from_ball_walls(BoundarySection& self, Vec2 a, Vec2 b, int level, const SegmentRef* excluded,
                                     int excluded_count, SweepHit* out, QueryStats* stats) noexcept;
  static void copy_ball_walls(BoundarySection& self) noexcept;
  static void next_tick(BoundarySection& self) noexcept;
  static void clip_section(BoundarySection& self, Query& q) noexcept;
  static std::size_t scan_section_rects(BoundarySection& self, const Query& q) noexcept;
  static void mark_near_rects(BoundarySection& self, double bound_sq, std::size_t skip) noexcept;
  static void refine_candidates(BoundarySection& self, Query& q) noexcept;
  static bool push_hit_children(BoundarySection& self, Query& q, std::uint32_t node, int& top) noexcept;
  static bool push_wide_children(BoundarySection& self, Query& q, std::uint32_t node, int& top) noexcept;
  static std::uint32_t segments_under(const BoundarySection& self, std::uint32_t node, int level,
                                      std::uint32_t* first) noexcept;
  static bool test_segments_under(BoundarySection& self, Query& q, std::uint32_t node) noexcept;
  static void test_segment(BoundarySection& self, Query& q, std::uint32_t node) noexcept;
  static void test_level_run(BoundarySection& self, Query& q, std::uint32_t first, std::uint32_t count) noexcept;
  static void split_hit_boxes(BoundarySection& self, Query& q) noexcept;
  static void merge_idle_siblings(BoundarySection& self, Query& q) noexcept;
  static void merge_on_ball_tick(BoundarySection& self, Vec2 a, Vec2 b, QueryBudget& budget, QueryStats& st) noexcept;
  static void merge_check_on_ball_tick(BoundarySection& self, Vec2 a, Vec2 b, QueryBudget& budget,
                                       QueryStats& st) noexcept;
  static void pay_merge_debt(BoundarySection& self, Vec2 a, Vec2 b, QueryBudget& budget, QueryStats* stats) noexcept;
  static bool merge_if_clear(BoundarySection& self, std::size_t e, std::uint32_t parent, const std::uint32_t* child,
                             std::uint32_t count, Vec2 a, Vec2 b) noexcept;
  static void gather_ball_walls(BoundarySection& self, const Query& q) noexcept;
  static std::size_t nearest_rect_left(const BoundarySection& self, std::size_t n) noexcept;
  static void place_free_ball(BoundarySection& self, const Query& q) noexcept;
  static void drop_departed_entries(BoundarySection& self) noexcept;
  static SweepHit finish(const BoundarySection& self, Query& q) noexcept;
  static void split(BoundarySection& self, std::uint32_t node, std::size_t entry) noexcept;
  static void split_wide(BoundarySection& self, std::uint32_t node, std::size_t entry) noexcept;
  static void set_section_entry(BoundarySection& self, std::size_t entry, std::uint32_t node,
                                std::uint32_t parent) noexcept;
  static void place_entry(BoundarySection& self, std::size_t entry, std::uint32_t node, std::uint32_t parent) noexcept;
  static void remove_section_entry(BoundarySection& self, std::size_t entry) noexcept;
  static bool merge_children(BoundarySection& self, std::size_t entry, std::uint32_t parent,
                             const std::uint32_t* children, std::uint32_t count) noexcept;
  // The wide frontier (collision_query.hpp, before wide_mode_): whether it serves `level`, and its section ids.
  static bool wide_frontier(const BoundarySection& self, int level) noexcept {
    return wide_serves(self, level) && !self.scene_->wide_index().nodes.empty();
  }
  static bool is_wide_id(const BoundarySection& self, std::uint32_t id) noexcept { return id >= self.wide_base_; }
  // The section id of a wide node's child code (WideNode::child, not kWideEmpty): an item's segment node, or a wide
  // node.
  static std::uint32_t wide_child_id(const BoundarySection& self, std::uint32_t code) noexcept {
    return (code & kWideLeaf) ? (code & ~kWideLeaf) : self.wide_base_ + code;
  }
  static Aabb entry_rect(const BoundarySection& self, std::uint32_t id) noexcept;
  static ErrorBox entry_box(const BoundarySection& self, std::uint32_t id) noexcept;
  static ErrorBox entry_box_at(const BoundarySection& self, std::size_t entry) noexcept;
  static std::uint32_t entry_children(const BoundarySection& self, std::uint32_t id, std::uint32_t* out) noexcept;
  static std::uint32_t child_count(const BoundarySection& self, std::uint32_t id) noexcept;
  static void link_wide_nodes(BoundarySection& self);
  static std::uint32_t item_segments(const BoundarySection& self, std::uint32_t item, int level,
                                     std::uint32_t* first) noexcept;
  static bool push_walk(BoundarySection& self, float t_enter, float d_sq, std::uint32_t code, int base,
                        int& top) noexcept;
  static void wide_test_item(BoundarySection& self, Query& q, std::uint32_t item) noexcept;
  static double wide_walk(BoundarySection& self, Query& q, double ball_cap_m) noexcept;
  static float seeded_ball_sq(const BoundarySection& self, const WideIndex& wi, float bx, float by,
                              float cap_sq) noexcept;
  // Appends node with its rectangle and marks it in (the caller checked the room); parent: parent_or_none(node).
  static void push_section(BoundarySection& self, std::uint32_t node, std::uint32_t parent) noexcept;
  static std::uint32_t parent_or_none(const BoundarySection& self, std::uint32_t node) noexcept;
  static void mark_out(BoundarySection& self, std::uint32_t node, std::uint32_t parent) noexcept;
  static bool in_section(const BoundarySection& self, std::uint32_t node) noexcept {
    return (self.node_state_[node] & kInSection) != 0;
  }
  static std::uint32_t children_in(const BoundarySection& self, std::uint32_t node) noexcept {
    return self.node_state_[node] / kChildInUnit;
  }
  static void clear_state(BoundarySection& self, std::uint32_t node, std::uint8_t bits) noexcept {
    self.node_state_[node] &= static_cast<std::uint8_t>(~bits);
  }
  /// Checked push onto the DFS stack (sized by hk::tree_stack_entries): false, and nothing pushed, when it
  /// is full, which a tree within kMaxLevels + kMaxHierarchyDepth levels never fills.
  static bool push(BoundarySection& self, int& top, Candidate c) noexcept {
    if (static_cast<std::size_t>(top) >= self.stack_.size()) return false;
    self.stack_[static_cast<std::size_t>(top++)] = c;
    return true;
  }
  // Checked: a node is marked at most once per bit in a query, and only section entries (kHitMark) and their
  // parents (kCheckedMark) are, so the list never fills; were it full, the mark is not set, which costs only work
  // (a hit entry's parent box meets the sweep too, so it is not merged; a parent may be checked twice).
  static void mark(BoundarySection& self, std::uint32_t node, std::uint8_t bit) noexcept {
    if (self.marked_count_ == self.marked_.size()) return;
    self.node_state_[node] |= bit;
    self.marked_[self.marked_count_++] = node;
  }
  static void clear_marks(BoundarySection& self) noexcept;
  static void closest_seed(const BoundarySection& self, ClosestQuery& q) noexcept;
  static bool closest_walk(BoundarySection& self, ClosestQuery& q, QueryBudget* budget) noexcept;
  static bool closest_tree_walk(BoundarySection& self, ClosestQuery& q, QueryBudget* budget) noexcept;
  static void closest_test_item(BoundarySection& self, ClosestQuery& q, std::uint32_t item) noexcept;
  static bool closest_open_node(BoundarySection& self, const ClosestQuery& q, const WideNode& n, float px, float py,
                                int* top, std::uint32_t* next) noexcept;
  static std::uint32_t closest_pop(const BoundarySection& self, const ClosestQuery& q, int* top) noexcept;
  static void closest_offer(const BoundarySection& self, ClosestQuery& q, std::uint32_t node, Vec2 a, Vec2 b) noexcept;
};

// One query's inputs, answer so far and counters, passed to each phase of first_hit.
struct BoundarySection::Query {
  Vec2 a, b;      // the sweep [m]
  Aabb sweep;     // the rectangle around it
  int level = 0;  // target level (clamped per curve)
  const SegmentRef* excluded = nullptr;
  int excluded_count = 0;
  QueryBudget* budget = nullptr;
  SweepHit best;                                                  // nearest exact hit so far (t = +inf: none)
  double unresolved_t = std::numeric_limits<double>::infinity();  // entry of the nearest box left unrefined
  std::uint32_t unresolved_node = 0;
  double nearest_sq = std::numeric_limits<double>::infinity();  // squared distance from b to the section's nearest box
  QueryStats st;
  bool refused =
      false;  // optional work was refused for want of budget (a wide node may be refused before it is quite spent)
  std::size_t scanned = 0;       // section entries phase 1 scanned (the first ones of section_)
  std::size_t hit = 0;           // of which the sweep met, grown by the merge margin (kHitMark)
  std::size_t nearest_rect = 0;  // of which the one whose rectangle is nearest to b (scanned when none)

  float ax = 0.0f, ay = 0.0f, ix = 0.0f,
        iy = 0.0f;  // the sweep for sweep_node: its start, the reciprocals of its extent

  Query(Vec2 a_m, Vec2 b_m, int target_level, const SegmentRef* excluded_segments, int n_excluded,
        QueryBudget& shared_budget)
      : a(a_m),
        b(b_m),
        sweep(rect_of(a_m, b_m)),
        level(target_level),
        excluded(excluded_segments),
        excluded_count(n_excluded),
        budget(&shared_budget) {
    best.t = std::numeric_limits<double>::infinity();  // no exact hit yet
    best.point_m = b_m;
    ax = static_cast<float>(a_m.x);
    ay = static_cast<float>(a_m.y);
    ix = slab_reciprocal(b_m.x - a_m.x);
    iy = slab_reciprocal(b_m.y - a_m.y);
  }

  // The section entries' clips: always done and charged, even past the budget.
  void charge_section_boxes(std::int32_t n) noexcept {
    st.box_tests += n;
    st.section_box_tests += n;
    budget->charge(n);
  }
  // Any other box test: only while the budget lasts.
  bool spend_box() noexcept { return spend_boxes(1); }
  // A wide node's four rectangles: all or none.
  bool spend_wide_node() noexcept { return spend_boxes(kWideBoxTestsPerNode); }
  bool spend_boxes(std::int32_t n) noexcept {
    if (!budget->spend(n)) {
      refused = true;
      return false;
    }
    st.box_tests += n;
    return true;
  }
  bool is_excluded(SegmentRef s) const noexcept { return hk::is_excluded(s, excluded, excluded_count); }
  // One wall (segment ref from p0 to p1 [m], not excluded) tested against the sweep; kept when it is the nearest hit
  // so far (of equals, the smallest (curve, level, segment): the answer does not depend on the order of the walk).
  // A rectangle test first: the rectangles apart, no common point.
  void test_wall(SegmentRef ref, Vec2 p0, Vec2 p1) noexcept {
    ++st.segment_tests;
    st.coarsest_answer_level = std::max(st.coarsest_answer_level, ref.level);
    double t = 0.0;
    if (overlaps(rect_of(p0, p1), sweep, 0.0) && intersect_sweep_segment_inline(a, b, p0, p1, &t) &&
        closer(t, ref, best.t, best.segment)) {
      best.hit = true;
      best.t = t;
      best.segment = ref;
    }
  }
  // Boxes entered past this cannot hold anything nearer than what is known.
  double horizon() const noexcept { return std::min(best.t, unresolved_t); }
};

// ---- Small operations the phases in several files call, inline so that they stay inlined ----

// at_target_level, and for a cut step the cut's own segments. A walk comes down from the roots and stops at
// the first cut segment on its way, so it never reaches a node below the cut.
inline bool BoundarySection::Ops::at_target(const BoundarySection& self, std::uint32_t node, int level) noexcept {
  if (is_cut_level(level)) return self.scene_->is_segment(node) && in_cut(self.cut_mask_, node, level - kCutLevelBase);
  return at_target_level(*self.scene_, node, level);
}

// The end points of wall node `node` (at_target of `level`, already walls_of): joined at a cut step, else the
// segment's own.
inline void BoundarySection::Ops::wall_node_points(const BoundarySection& self, std::uint32_t node, int level, Vec2* a,
                                                   Vec2* b) noexcept {
  if (is_cut_level(level)) {
    joined_cut_segment(*self.scene_, self.cut_mask_, node, level - kCutLevelBase, a, b);
  } else {
    self.scene_->segment_points(node, a, b);
  }
}

// Splits stop here: a segment node at the walls of either id the section serves (so at the coarser of the
// two; the section's entries are never below either, follow_level).
inline bool BoundarySection::Ops::at_floor(const BoundarySection& self, std::uint32_t node, int level) noexcept {
  return at_target(self, node, level) || at_target(self, node, self.other_level_);
}

// The box of section id `id`: a scene node's (Scene::box), or a wide node's rectangle as an axis-aligned box (as
// Scene::box gives a chunk's).
inline ErrorBox BoundarySection::Ops::entry_box(const BoundarySection& self, std::uint32_t id) noexcept {
  if (!is_wide_id(self, id)) return self.scene_->box(id);
  return rect_box(entry_rect(self, id));
}

// entry_box of section entry i, for a wide node read from the section's own rectangle rather than the index: its
// slot's in its parent, stored as it is by a split (split_wide) or widened outward a little (set_section_entry);
// either holds everything under the node.
inline ErrorBox BoundarySection::Ops::entry_box_at(const BoundarySection& self, std::size_t i) noexcept {
  const std::uint32_t id = self.section_[i];
  if (!is_wide_id(self, id)) return self.scene_->box(id);
  const SectionRects& r = self.section_rect_;
  return rect_box(Aabb{{r.lo_x[i], r.lo_y[i]}, {r.hi_x[i], r.hi_y[i]}});
}

// How many children section id `id` has in the frontier's hierarchy (entry_children's count), cheaply.
inline std::uint32_t BoundarySection::Ops::child_count(const BoundarySection& self, std::uint32_t id) noexcept {
  if (is_wide_id(self, id)) {
    const WideNode& n = self.scene_->wide_index().nodes[id - self.wide_base_];
    return static_cast<std::uint32_t>((n.child[0] != kWideEmpty) + (n.child[1] != kWideEmpty) +
                                      (n.child[2] != kWideEmpty) + (n.child[3] != kWideEmpty));
  }
  std::uint32_t first = 0, count = 0;
  self.scene_->children(id, &first, &count);
  return count;
}

// Marks a node out of the section, and no longer counted among its parent's children in.
inline void BoundarySection::Ops::mark_out(BoundarySection& self, std::uint32_t node, std::uint32_t parent) noexcept {
  clear_state(self, node, kInSection);
  if (parent != kNoParent)
    self.node_state_[parent] = static_cast<std::uint8_t>(self.node_state_[parent] - kChildInUnit);  // it was counted
}

inline void BoundarySection::Ops::next_tick(BoundarySection& self) noexcept {
  ++self.tick_;
}  // wraps harmlessly: it only turns the merges' round robin

// The end of a full query: every mark its phases set, cleared (the next query starts with none).
inline void BoundarySection::Ops::clear_marks(BoundarySection& self) noexcept {
  for (std::size_t i = 0; i < self.marked_count_; ++i) clear_state(self, self.marked_[i], kMarks);
  self.marked_count_ = 0;
}

// Free-space ball (seed §3: "distances to the boxes ... can be used to schedule box updates"): the
// last full query proved that no box of the section comes within the ball's radius of ball_center_m_, and
// those boxes covered every wall of the level ids it served (ball_levels_; follow_level forgets the ball for
// any other id). A sweep inside that ball cannot hit anything: answer at once.
inline bool BoundarySection::Ops::inside_free_ball(const BoundarySection& self, Vec2 a, Vec2 b) noexcept {
  const double r_sq = self.ball_radius_sq_;
  const Vec2 da = a - self.ball_center_m_, db = b - self.ball_center_m_;
  return (dot(da, da) < r_sq) & (dot(db, db) < r_sq);  // r = 0 (unknown) admits nothing; & : one branch, not two
}

// The walls of level id `level` under a segment node at most kDirectLevels above them: their count (at most
// 2^kDirectLevels) and, in *first, the first one's node (they are consecutive nodes, whose points are
// consecutive too); 0 for any other node (a chunk or above, a node farther above its walls, a cut step's
// walls, which are of mixed levels). The node must not lie below the walls (no section entry does).
inline std::uint32_t BoundarySection::Ops::segments_under(const BoundarySection& self, std::uint32_t node, int level,
                                                          std::uint32_t* first) noexcept {
  const Scene& sc = *self.scene_;
  if (!sc.is_segment(node) || is_cut_level(level)) return 0;
  const std::uint32_t c = sc.tag_curve(node);
  const int l = sc.tag_level(node);
  const int target = sc.clamp_level(c, level);
  if (l - target > kDirectLevels) return 0;
  const CurveNodes& cn = sc.curve_nodes(c);
  *first = cn.box_offset[target] + ((node - cn.box_offset[l]) << (l - target));
  return 1u << (l - target);
}

// test_segment for the `count` consecutive segment nodes of one level of one curve from `first` (not a cut step's),
// with what they share found once: their curve and level (their indices run on from the first's) and their points
// (consecutive slots), each its own level's wall.
inline void BoundarySection::Ops::test_level_run(BoundarySection& self, Query& q, std::uint32_t first,
                                                 std::uint32_t count) noexcept {
  const NodeInfo in = self.scene_->info(first);
  const Vec2* pts = self.scene_->slot_points(first);
  for (std::uint32_t i = 0; i < count; ++i) {
    const SegmentRef ref{static_cast<std::int32_t>(in.curve), in.level, static_cast<std::int32_t>(in.index + i)};
    if (!q.is_excluded(ref)) q.test_wall(ref, pts[i], pts[i + 1]);
  }
}

// The segments a walk tests at an item (segment node `item` of the item level): the target level's segments
// under it (the item itself at the item level). Writes the first node and returns the count. The walks of the
// wide index take only the level ids it serves (wide_serves), whose level is at or below every curve's items.
inline std::uint32_t BoundarySection::Ops::item_segments(const BoundarySection& self, std::uint32_t item, int level,
                                                         std::uint32_t* first) noexcept {
  const Scene& sc = *self.scene_;
  const std::uint32_t c = sc.tag_curve(item);
  const int k_level = sc.tag_level(item);
  const CurveNodes& cn = sc.curve_nodes(c);
  const std::uint32_t k = item - cn.box_offset[k_level];
  const int l = sc.clamp_level(c, level);  // ≤ k_level (wide_serves)
  *first = cn.box_offset[l] + (k << (k_level - l));
  return 1u << (k_level - l);
}

// Checked push onto the wide walks' stack, in order: among the entries pushed since `base` (a node's
// children, at most four) the one nearest to the walk's point ends on top. False, with nothing pushed,
// when the stack is full.
[[gnu::always_inline]] inline bool BoundarySection::Ops::push_walk(BoundarySection& self, float t_enter, float d_sq,
                                                                   std::uint32_t code, int base, int& top) noexcept {
  if (static_cast<std::size_t>(top) >= self.walk_.size()) return false;
  float* t = self.walk_.t_enter.data();
  float* d = self.walk_.d_sq.data();
  std::uint32_t* c = self.walk_.code.data();
  int k = top++;
  for (; k > base && d[k - 1] < d_sq; --k) {
    t[k] = t[k - 1];
    d[k] = d[k - 1];
    c[k] = c[k - 1];
  }
  t[k] = t_enter;
  d[k] = d_sq;
  c[k] = code;
  return true;
}

}  // namespace hk
