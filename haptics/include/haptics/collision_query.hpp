#pragma once
/// @file collision_query.hpp
/// Anytime hierarchical collision detection of a swept point against the scene's collision trees
/// (seed paper §3; DESIGN.md "Collision query").
///
/// The handle moves from a to b in one tick. The boundary section — the frontier of tree nodes near the
/// handle — is kept from tick to tick and changes by splits (a box hit by the sweep is refined to its
/// children) and merges (siblings whose parent is clear by a margin are replaced by the parent; a full query owes
/// the checks, the ticks the free-space ball answers pay them, one each). At level ids the wide index serves
/// (wide_index.hpp), the frontier's nodes above the items are the index's spatial nodes rather than the tree's
/// curve-following ones (wide_frontier_active).
/// Each tick the sweep is clipped (Liang–Barsky) against the boxes of the boundary section; hit boxes
/// are sorted by entry parameter and refined depth-first, nearest first, down to the target level,
/// where the sweep is intersected with that level's polyline (a box within 3 levels of a level target has
/// the segments under it tested at once, as the wide index's items do). The rectangles of the section's
/// entries settle most of them: only an entry whose rectangle meets the sweep or is nearer than the nearest
/// box found has its box rebuilt. Boxes whose entry lies past the best hit
/// so far are pruned. A budget of box tests (QueryBudget, shared by every query of a servo tick) makes it
/// anytime: past it, boxes are no longer refined, and the answer is the one at the finest level reached — reported
/// conservatively: the sweep is clear up to the entry of the nearest box not refined within the budget (a box holds
/// everything finer, so no wall of the target level lies before it). The caller can then stop short instead of crossing
/// a wall it has not resolved; the boundary section keeps the refinement for the next tick. Between full queries a
/// free-space ball answers at once: a full query measures how far the end of its sweep is from the nearest box of the
/// section (as it scanned it, before that tick's splits and merges: those boxes cover the same walls), and a later
/// sweep wholly inside that distance cannot hit anything (seed §3 suggests scheduling box updates from box distances).
/// Near a wall that ball is only as large as the gap, so a full query also notes the walls under its nearest section
/// entries (up to 16, from segment boxes within 3 levels of their walls) with a second, larger ball around the same
/// centre, reaching to the nearest entry left out: a sweep of that level id inside it is answered exactly by testing
/// those walls alone (a hand resting on or sliding along a wall); the first such sweep copies them out. First
/// hits of equal t go to the smallest (curve, level, segment), so no answer depends on which path gave it.
/// The section serves the level ids of the last two queries (the contact solver renders two levels in turn
/// while it changes level): its entries stay at or above the walls of both, and a change of id keeps it
/// (entries below the new id's walls give way to their ancestors at them).
///
/// Real-time: all storage is sized in the constructor; `first_hit` allocates nothing, takes no lock,
/// throws nothing.

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "haptics/float_round.hpp"
#include "haptics/scene.hpp"
#include "haptics/tolerance_cut.hpp"

namespace hk {

/// Liang–Barsky clipping of the segment a→b against a box (grown by margin_m on every side).
/// Returns true on overlap and writes the entry and exit parameters in [0, 1].
bool clip_segment_box(const ErrorBox& box, Vec2 a, Vec2 b, double margin_m, double* t_enter, double* t_exit) noexcept;

/// Proper or touching intersection of the sweep a→b with segment p→q. Returns true with `t` the sweep
/// parameter in [0, 1] of the first common point; parallel (including collinear) pairs never hit,
/// because a sweep sliding along a wall does not cross it.
bool intersect_sweep_segment(Vec2 a, Vec2 b, Vec2 p, Vec2 q, double* t) noexcept;

/// The work limit that makes queries anytime: a count of box tests, shared by every query (and
/// closest-point walk) it is passed to, so one number bounds a servo tick's collision work. No clock.
///
/// Two kinds of box test draw on it. Optional work (refining a hit box into its children or testing the
/// target level's segments under it, one per segment; merge checks; closest-point walks) is done only while the budget
/// lasts: `spend()` refuses once `box_tests_used` has reached `max_box_tests`, so that work never takes the count past
/// the limit. The clip of the sweep against the boundary section itself is always done in full (it is what proves the
/// sweep clear at all) and is charged even past the limit: that is the only overrun, so after any number of queries
/// box_tests_used ≤ max_box_tests + the section entries they scanned (QueryStats::section_box_tests).
struct QueryBudget {
  std::int32_t max_box_tests = 0;   ///< box tests allowed [count]; 0 = no limit
  std::int32_t box_tests_used = 0;  ///< box tests charged so far by everything sharing this budget [count]
  bool ran_out = false;             ///< some optional work was refused for want of budget

  /// True when no optional box test may be done any more.
  bool exhausted() const noexcept { return max_box_tests > 0 && box_tests_used >= max_box_tests; }
  /// Charges one optional box test. Returns false (and sets ran_out) when the budget is spent.
  bool spend() noexcept { return spend(1); }
  /// Charges n optional box tests at once (a wide node's four rectangles, tested together), all or none:
  /// false (and ran_out set), with nothing charged, when fewer than n are left.
  bool spend(std::int32_t n) noexcept {
    if (!affords(n)) {
      ran_out = true;
      return false;
    }
    box_tests_used += n;
    return true;
  }
  /// True when n more optional box tests fit in the budget (spend(n) would charge them). Marks nothing.
  bool affords(std::int32_t n) const noexcept { return max_box_tests <= 0 || box_tests_used + n <= max_box_tests; }
  /// Charges n box tests that are done regardless (a scan of n section entries).
  void charge(std::int32_t n) noexcept { box_tests_used += n; }
};

/// Result of a sweep query.
struct SweepHit {
  bool hit = false;      ///< the exact first hit at the target level was found
  bool blocked = false;  ///< the budget ran out first: the sweep is proven clear only up to `t`
  double t = 1.0;        ///< hit: sweep parameter of the first hit; blocked: where the first box not
                         ///< refined within the budget begins (no wall of the target level lies before it); else 1
  Vec2 point_m;          ///< a + t (b − a) [m]
  SegmentRef segment;    ///< hit: the segment hit; blocked: the coarse segment of that box, i.e. the
                         ///< answer at the finest level reached (level > target)
};

/// Work done by one query (for timing analysis and the anytime chart).
struct QueryStats {
  std::int32_t box_tests = 0;          ///< every box test of the query (section clips, refinement, merges)
  std::int32_t section_box_tests = 0;  ///< of which clips of the boundary section, done even past the budget
  std::int32_t segment_tests = 0;
  std::int32_t splits = 0;
  std::int32_t merges = 0;
  std::int32_t section_size = 0;           ///< boundary-section nodes after the query
  std::int32_t coarsest_answer_level = 0;  ///< coarsest level reached by an answer (> target when the budget ran out)
  bool budget_exhausted = false;  ///< the budget was spent when (or before) this query ended, or optional work of
                                  ///< this query was refused for want of it (a wide node needs four tests at once)
  bool ball_walls = false;        ///< answered by the free-space ball's walls (first_hit: no box test but the merge
                                  ///< checks it pays, its segment tests those walls'; false for the plain ball and a
                                  ///< full query)
};

/// The boundary section of one scene plus the scratch space of the query. One per servo thread.
class BoundarySection {
 public:
  static constexpr int kMaxExcluded = 2;
  /// Bound on the section's entries [count], so on its storage and on its scan (done even past the budget). The
  /// dense long walk of the tests keeps at most 174 entries (811–884 with the tree's frontier alone); the bench's
  /// walks keep ~25.
  static constexpr std::size_t kMaxSectionEntries = 1u << 13;

  /// Sizes every buffer for `scene` (which must outlive this object) and starts at the roots. With
  /// `cut_walls` it also computes the cut masks and their bounds (tolerance_cut_masks, cut_bounds: a byte
  /// per node, about a tenth of a second at 10^6 segments), which the walls at cut steps need; without them a
  /// cut step renders as the tolerance step of the same tolerance (each curve at its level for it). Throws
  /// hk::ArgumentError for a scene node with more than 7 children (a Scene has at most 4), or when the scene's
  /// nodes and wide index nodes together do not fit 32-bit section ids.
  explicit BoundarySection(const Scene& scene, double merge_margin_m = 3e-4, bool cut_walls = true);
  /// The same, reading the cut masks and bounds from `cuts` (make_cut_walls of the same `scene`, shared with
  /// other sections of it) instead of computing its own; null: no cut masks, as `cut_walls` = false. Throws
  /// hk::ArgumentError when `cuts` was made for another scene, or as the constructor above.
  BoundarySection(const Scene& scene, double merge_margin_m, std::shared_ptr<const CutWalls> cuts);

  /// Forgets the frontier (back to one root per curve), both free-space balls and the closest-point seed. Real-time
  /// safe.
  void reset() noexcept;

  /// First hit of the sweep a→b against the polylines at level id `level` (clamped per curve to its coarsest;
  /// at a cut step, level id kCutLevelBase + step, its tolerance cut's joined segments: see below),
  /// ignoring up to kMaxExcluded segments (the contact solver's active constraints). Updates the
  /// boundary section, which serves this id and the previous query's (splits stop at the coarser of the
  /// two; a new id coarsens the entries below its walls, O(section entries), O(levels) each at a cut step).
  /// Of walls hit at the same t, the answer is the smallest (curve, level, segment). A sweep inside the free-space
  /// ball, or inside the ball of its walls (at most 16 segment tests), is answered without a box test of its own, and
  /// pays one merge check full queries left owed, two while more than 8 are (one optional box test each).
  /// Charges its box tests to `budget` (see QueryBudget). Real-time safe.
  /// At level id kCutLevelBase + step (0 ≤ step < kToleranceSteps, tolerance kToleranceLadder_m[step]) the walls are
  /// the tolerance cut's instead of a level's: each curve's segments of mixed levels that tolerance_cut chooses
  /// (refined while a box's error bound exceeds the tolerance; seed §3, "contact computations at a desired tolerance
  /// level"), drawn joined (joined_cut_segment: where the cut changes level, both pieces meet at the finer segment's
  /// end). The walk is the same, stopping at the cut's segments: each joined piece lies inside its own segment's error
  /// box (tolerance_cut.hpp), so the boxes prune it exactly as they prune a level; a box above the cut holds every
  /// joined piece under it. A change of step, or between a step and a level, keeps the section. The answer's segment
  /// is the cut segment hit (its own level and index). Answers equal a brute-force test of the joined polylines (t bit
  /// for bit; tests).
  SweepHit first_hit(Vec2 a, Vec2 b, int level, const SegmentRef* excluded, int excluded_count, QueryBudget& budget,
                     QueryStats* stats = nullptr) noexcept;
  /// The same first hit through the scene's wide index alone (wide_index.hpp), for comparison with
  /// first_hit: no boundary section. A depth-first walk from the index's root, nearest entry first, pruned
  /// past the best hit; at an item it tests the target level's segments under it. Coherence comes
  /// from a free-space ball of its own: after a sweep proven clear, a nearest-first walk measures the
  /// distance from b to the nearest item rectangle (capped at kWideBallCap_m), and a later sweep inside that
  /// ball is answered at once (the rectangles hold the walls of every level id the index serves, and only
  /// those ids use the ball).
  /// Anytime: each wide node opened is four optional box tests charged to `budget` (its four rectangles,
  /// in one SIMD test); past it, nodes are not opened and the answer is blocked at the entry of the nearest
  /// one, with segment {-1, kMaxLevels, -1}: unlike first_hit, no coarser level's segment is known there.
  /// Same answers as first_hit otherwise (t bit for bit; checked against brute force in the tests).
  /// The index holds the levels at or below its items (wide_index.hpp): at a level id where some curve is
  /// coarser, the sweep descends the tree of error boxes from the scene root instead, as first_hit's
  /// descent does (no ball; one optional box test a box; blocked answers name the box's segment as
  /// first_hit's do, or {-1, kMaxLevels, -1} above the curves). At a cut step (whose joined pieces the item
  /// rectangles need not hold) it answers blocked at t = 0, nothing proven clear. Does not read or change
  /// the boundary section. Real-time safe.
  SweepHit first_hit_wide(Vec2 a, Vec2 b, int level, const SegmentRef* excluded, int excluded_count,
                          QueryBudget& budget, QueryStats* stats = nullptr) noexcept;
  /// Closest point on the tolerance cut at step `step` (its joined pieces, as first_hit meets them at level id
  /// kCutLevelBase + step) to p within max_distance_m; false when nothing is that close. `curve` ≥ 0 restricts it to
  /// that curve. Ties as closest_point (the smallest (curve, level, segment)). A distance-pruned depth-first walk of
  /// the tree of error boxes from the scene root, nearest box first (branch and bound, as closest_point): each joined
  /// piece lies inside its own segment's box, so a box's distance bounds every piece under it from below. Not
  /// the wide index, whose rectangles hold each level's own pieces, and not seeded between calls. With a
  /// `budget`, each box measured is one optional box test; when it runs out the walk stops and returns false
  /// with budget->ran_out set (the answer is then unknown, not "nothing close"). Without has_cuts(), the
  /// closest point at the tolerance step of the same tolerance. Allocates nothing.
  /// `skip_curves` (skip_count of them) as closest_point's.
  bool closest_point_cut(Vec2 p, int step, double max_distance_m, Vec2* point_out, SegmentRef* segment_out,
                         int curve = -1, QueryBudget* budget = nullptr, const int* skip_curves = nullptr,
                         int skip_count = 0) noexcept;
  /// Bytes of this section's own storage [B]: per scene node, 1 (in the frontier, children in it, a full query's
  /// marks); per wide index node, 5 (the same byte, and its parent for the wide frontier) and per item 4 (its parent);
  /// per entry of its capacity (at most kMaxSectionEntries + a few), its node, parent, float rectangle,
  /// scan scratch, candidate and two slots of the marks' list; the walks' stacks. Not the scene's, nor the cut masks
  /// (shared: cut_walls()). One section per servo thread. O(1).
  std::size_t bytes() const noexcept;
  /// Whether the section has the cut masks (the constructor's `cut_walls`, or a non-null `cuts`).
  bool has_cuts() const noexcept { return cut_mask_ != nullptr; }
  /// Cut membership of the scene's nodes (tolerance_cut_masks; node_count() entries; null without has_cuts()).
  const std::uint8_t* cut_masks() const noexcept { return cut_mask_; }
  /// The cut masks and bounds this section reads (shared with the other sections built from them; null without
  /// has_cuts()).
  const std::shared_ptr<const CutWalls>& cut_walls() const noexcept { return cuts_; }
  /// The bounds of each step's cut (cut_bounds; all 0 without has_cuts()).
  const CutBounds& cut_bounds() const noexcept { return cuts_ ? cuts_->bounds : kNoCutBounds; }
  /// The end points [m] of segment `s` as a wall of level id `level`: joined (joined_cut_segment) when `level`
  /// is a cut step and s is one of its segments, else the segment's own. Real-time safe.
  void wall_points(SegmentRef s, int level, Vec2* a, Vec2* b) const noexcept {
    level = walls_of(level);
    const std::uint32_t node = scene_->node_of(s);
    const int step = level - kCutLevelBase;
    if (is_cut_level(level) && in_cut(cut_mask_, node, step)) {
      joined_cut_segment(*scene_, cut_mask_, node, step, a, b);
    } else {
      scene_->segment_points(node, a, b);
    }
  }
  /// Whether segment `s` is a wall of level id `level`: a segment of its cut (a cut step), or at its curve's
  /// level for the id (Scene::clamp_level). Real-time safe.
  bool is_wall(SegmentRef s, int level) const noexcept {
    level = walls_of(level);
    if (is_cut_level(level)) return in_cut(cut_mask_, scene_->node_of(s), level - kCutLevelBase);
    return s.level == scene_->clamp_level(static_cast<std::size_t>(s.curve), level);
  }
  /// The wall next to `s` along its curve at level id `level`, across its start (dir < 0) or end (dir > 0):
  /// the next segment of the same level, or at a cut step the cut segment covering the next stretch of the
  /// curve (any level; its joined end meets s's). False at an open curve's end (and for a one-segment
  /// closed curve). O(levels) at a cut step; real-time safe.
  bool wall_neighbour(SegmentRef s, int level, int dir, SegmentRef* out) const noexcept;

  /// The same for a one-off query: spends a copy of `budget` (tests, benches). Real-time safe.
  SweepHit first_hit(Vec2 a, Vec2 b, int level, const SegmentRef* excluded, int excluded_count,
                     const QueryBudget& budget, QueryStats* stats = nullptr) noexcept {
    QueryBudget copy = budget;
    return first_hit(a, b, level, excluded, excluded_count, copy, stats);
  }

  /// Closest point on the polylines at `level` (clamped per curve) to p within max_distance_m. Returns
  /// false when nothing is that close. A cut step is answered by closest_point_cut. `curve` ≥ 0 restricts the search to
  /// that curve. Among segments at the same distance (a vertex two segments share) the smallest (curve, level, segment)
  /// is the answer, so it does not depend on the order anything was visited in.
  ///
  /// A distance-pruned walk of the scene's wide index (wide_index.hpp): depth first, nearest rectangle
  /// first, four rectangles per SIMD test, the target level's segments under each item reached; it neither
  /// uses nor changes the frontier. At a level id where some curve is coarser than its items (which the
  /// index does not hold), the same branch and bound walks the tree of error boxes from the scene root,
  /// one box a step, as closest_point_cut does. Coherent between calls like the first hit's free-space
  /// ball: the previous call's answer (same level and curve), measured again at p, seeds the bound, so
  /// the walk is pruned tightly from the root down (the branch-and-bound nearest-neighbour search of
  /// Roussopoulos, Kelley & Vincent 1995, with the proxy's coherence of seed §3).
  ///
  /// With a `budget`, each wide node the walk opens is four optional box tests charged to it (each box of
  /// the tree walk, one); when it
  /// runs out the walk stops and returns false with budget->ran_out set (the answer is then unknown, not
  /// "nothing close"), and the next call is not seeded. Allocates nothing.
  ///
  /// `skip_curves` (skip_count curve indices, a handful) are left out: the answer is the closest point of the
  /// other curves, so repeated calls that skip the curves found so far list every curve within max_distance_m,
  /// nearest first (ContactSolver::level_change_is_safe).
  bool closest_point(Vec2 p, int level, double max_distance_m, Vec2* point_out, SegmentRef* segment_out, int curve = -1,
                     QueryBudget* budget = nullptr, const int* skip_curves = nullptr, int skip_count = 0) noexcept;

  /// Ids of the current boundary section's entries (for the operator overlay and tests): scene node ids, and with
  /// the wide frontier (wide_frontier_active) also wide index nodes, node w as Scene::node_count() + w.
  const std::vector<std::uint32_t>& section() const { return section_; }
  /// Whether the section's entries above the items are the wide index's nodes rather than the tree's chunks,
  /// hierarchy and coarse segments: at level ids the wide index serves (both ids the section serves); a change
  /// of id that changes this starts the section again from its root. The frontier of first_hit.
  bool wide_frontier_active() const noexcept { return wide_mode_; }
  /// The parent of section entry id `id` in the frontier's hierarchy, or 0xffffffff for its root: the scene's
  /// (Scene::parent) in the tree's frontier and below the items; above them in the wide frontier, the wide node
  /// whose slot names it (an item's, or a wide node's). For tests.
  std::uint32_t entry_parent(std::uint32_t id) const noexcept;

 private:
  struct Ops;    // the private operations (static functions taking the section; collision_query_internal.hpp)
  struct Query;  // one first_hit's inputs, answer so far and counters (collision_query_internal.hpp)
  // The level id whose walls stand for `level` here: itself, or for a cut step without the masks its
  // tolerance step (see the constructor).
  int walls_of(int level) const noexcept {
    return is_cut_level(level) && cut_mask_ == nullptr ? level - kToleranceSteps : level;
  }
  static constexpr int kDirectLevels = kWideItemLevel;  // a box this near its walls has them tested at once (8 at most)
  static constexpr int kMaxMergeDebt =
      16;                         // merge checks full queries leave to the ball ticks (ball or walls answers), at most
  int merge_debt_ = 0;            // merge checks owed (merge_idle_siblings)
  std::size_t merge_cursor_ = 0;  // the ball ticks' round robin over the entries
  // The wide frontier. At level ids the wide index serves (wide_serves; both ids the section serves), the section's
  // entries above the items are the wide index's nodes rather than the tree's chunks, hierarchy and coarse segments
  // (whose boxes follow the curves and overlap: a descent from them opens many): the frontier is then a cut through
  // the index's nodes, its items (segment nodes of the item level) and the tree of error boxes below them. Wide node
  // w is the section id wide_base_ + w, past every scene node; its box is its rectangle in its parent's slot.
  // follow_level switches between the two frontiers (from the roots) when the ids' service changes.
  static constexpr std::uint32_t kMaxEntryChildren = 7;  // a node's children in the frontier are counted in three bits
  bool wide_mode_ = false;                               // the frontier is the wide one (follow_level)
  std::uint32_t wide_base_ = 0;                          // section id of wide node 0: the scene's node_count()
  std::vector<std::uint32_t> wide_up_;  // per wide node: its parent node << 2 | its slot there (kNoParent: the root)
  std::vector<std::uint32_t>
      item_up_;  // per item, in the index's item order (curve by curve): the wide node << 2 | slot naming it
  std::vector<std::uint32_t> item_first_;  // per curve: the order of its first item
  Aabb wide_root_rect_{};                  // the wide root's rectangle: its slots' union
  // The walks of the wide index (wide_index.hpp). One stack serves both: an entry is a child code with its
  // rectangle's squared distance from the walk's point (the order of the walk) and, for first_hit_wide,
  // where the sweep enters it (+inf when it does not). 12 bytes an entry, as three arrays: every access
  // is one 4-byte field, so no load spans two stores (that stalls store forwarding: about half of the
  // closest-point walk's own samples in perf when entries were 12-byte structs).
  struct WalkEntry {
    float t_enter;
    float d_sq;
    std::uint32_t code;
  };  // one popped entry, in registers
  struct WalkStack {
    std::vector<float> t_enter, d_sq;
    std::vector<std::uint32_t> code;
    std::size_t size() const { return code.size(); }
    void resize(std::size_t n) {
      t_enter.resize(n);
      d_sq.resize(n);
      code.resize(n);
    }
  };
  WalkStack walk_;  // the wide walks' stack (WideIndex::stack_entries)
  const Scene* scene_;
  double merge_margin_m_;
  std::vector<std::uint32_t> section_;  // frontier node ids (capacity_ reserved)
  std::vector<std::uint32_t>
      section_parent_;  // per entry, in step with section_: its node's parent (kNoParent: the root)
  // The section entries' rectangles [m], in step with section_, as four arrays (structure of arrays) of floats
  // widened outward (float_below, float_above: each holds the exact rectangle, Scene::aabb), so the per-tick scan
  // tests four entries per SSE instruction and streams through memory; sized capacity_ + kScanLanes (the scan
  // reads and pads whole groups of four past the last entry) and never resized, so the servo path allocates nothing.
  static constexpr std::size_t kScanLanes = 4;
  struct SectionRects {
    std::vector<float> lo_x, lo_y, hi_x, hi_y;
    void size_for(std::size_t n) {
      lo_x.assign(n, 0.0f);
      lo_y.assign(n, 0.0f);
      hi_x.assign(n, 0.0f);
      hi_y.assign(n, 0.0f);
    }
    void set(std::size_t i, const Aabb& r) noexcept {
      lo_x[i] = float_below(r.lo.x);
      lo_y[i] = float_below(r.lo.y);
      hi_x[i] = float_above(r.hi.x);
      hi_y[i] = float_above(r.hi.y);
    }
    // Entries first .. first + kScanLanes − 1 as rectangles infinitely far from every point, meeting none (lo = +inf,
    // hi = -inf): what the scan reads past the section's last entry, in its last group of four.
    void set_far_group(std::size_t first) noexcept {
      constexpr float kInf = std::numeric_limits<float>::infinity();
      std::fill_n(lo_x.data() + first, kScanLanes, kInf);  // one four-float store each
      std::fill_n(lo_y.data() + first, kScanLanes, kInf);
      std::fill_n(hi_x.data() + first, kScanLanes, -kInf);
      std::fill_n(hi_y.data() + first, kScanLanes, -kInf);
    }
    // Entry i's rectangle from floats that already hold it (a wide index slot's), as they are.
    void set_floats(std::size_t i, float lx, float ly, float hx, float hy) noexcept {
      lo_x[i] = lx;
      lo_y[i] = ly;
      hi_x[i] = hx;
      hi_y[i] = hy;
    }
    void copy(std::size_t to, std::size_t from) noexcept {
      lo_x[to] = lo_x[from];
      lo_y[to] = lo_y[from];
      hi_x[to] = hi_x[from];
      hi_y[to] = hi_y[from];
    }
  };
  SectionRects section_rect_;
  // scan scratch, per entry: a lower bound on the squared distance from the sweep's end to its rectangle [m²]
  // (scan_section_rects), in step with section_ and sized as section_rect_
  std::vector<float> rect_d_sq_;
  std::vector<std::uint64_t> rect_overlap_bits_;  // scan scratch, a bit per entry: its rectangle, grown by the merge
                                                  // margin, may meet the sweep's
  std::vector<std::uint64_t>
      rect_near_bits_;    // scan scratch, a bit per entry: its rectangle may be nearer than the nearest box so far
  double scale_m_ = 0.0;  // the largest coordinate magnitude of any section rectangle (the scene root's) [m]
  static constexpr std::uint32_t kNoParent = 0xffffffffu;  // the root's `parent` below: counted nowhere
  // The section's state of each node, one byte (node_state_): bit 0 (kInSection) while the node is in the frontier;
  // bits 1 and 2 the marks of one full query (kHitMark, kCheckedMark, below); bits 3 to 5 how many of its children
  // (at most 4, scene.hpp) are in the frontier, in units of kChildInUnit. Bits 6 and 7 stay clear.
  static constexpr std::uint8_t kInSection = 1, kChildInUnit = 8, kChildrenInMask = 0x38;
  std::vector<std::uint8_t> node_state_;
  struct Candidate {
    double t_enter;
    std::uint32_t node;
    std::uint32_t entry;
  };  // entry: its place in section_ (a hit entry), or kNotAnEntry. 16 bytes
  static constexpr std::uint32_t kNotAnEntry = 0xffffffffu;
  static_assert(sizeof(Candidate) == 16, "Candidate: four per cache line");
  std::vector<Candidate> candidates_;  // section nodes hit this tick
  std::vector<Candidate> stack_;       // DFS stack, tree_stack_entries(widest fan-out) entries, sized at build
  // Marks of one full query, bits of node_state_, set by its phases and cleared by clear_marks (the nodes marked are
  // listed in marked_, so clearing costs what marking did): kHitMark, the node's box grown by the merge margin met
  // the sweep (clip_section); kCheckedMark, a parent considered for a merge (merge_idle_siblings).
  static constexpr std::uint8_t kHitMark = 2, kCheckedMark = 4, kMarks = kHitMark | kCheckedMark;
  static_assert(((kInSection | kMarks) & kChildrenInMask) == 0 && kChildrenInMask / kChildInUnit >= 4,
                "node_state_: the flags and a count of up to 4 children in, in separate bits");
  std::vector<std::uint32_t>
      marked_;  // the nodes marked so far this query, marked_count_ of them (2 × capacity_ slots)
  std::size_t marked_count_ = 0;
  // The closest-point walk (see closest_point; its phases are Ops::closest_*).
  struct ClosestQuery;  // one call's point, best answer so far and bound (collision_closest.cpp)
  std::uint32_t last_closest_node_ = kWideEmpty;  // the previous call's answer (segment node), the next call's seed
  int last_closest_level_ = -1, last_closest_curve_ = -1;
  std::uint32_t tick_ = 0;
  int last_level_ = -1;   // level id of the last first_hit (-1: none yet)
  int other_level_ = -1;  // level id of the one before it: the section serves both (follow_level)
  static constexpr CutBounds kNoCutBounds{};
  std::shared_ptr<const CutWalls> cuts_;    // the cut masks and bounds (shared; null: none)
  const std::uint8_t* cut_mask_ = nullptr;  // cuts_->masks: per node, the tolerance steps whose cut it is a segment of
  std::size_t capacity_ = 0;                // entries reserved in section_ and the scratch arrays
  Vec2 ball_center_m_;  // free-space ball: no box of the section as last scanned, so no wall, comes closer to its
                        // centre than its radius
  double ball_radius_sq_ = 0.0;    // its radius squared [m²] (kept squared: the tests compare squares); 0 = unknown
  int ball_levels_[2] = {-1, -1};  // the level ids whose walls the ball was proven clear of
  // The ball's walls (gather_ball_walls): a larger ball, around the same centre, whose every wall of one level id
  // is known, so a sweep inside it is answered exactly by testing those walls alone. The full query notes them as
  // runs of consecutive segments; their points are copied on the first sweep inside the ball (copy_ball_walls),
  // so a full query whose walls ball is never entered reads none of them. 1 312 bytes.
  static constexpr int kMaxBallWalls = 16;
  static constexpr int kBallWallEntries = 6;  // section entries whose walls may be copied, nearest first
  struct BallWalls {
    Vec2 center_m;
    double radius_sq = 0.0;  // radius squared [m²]; 0 = none
    int level = -1;          // the level id whose walls these are
    int count = 0;           // walls [0, kMaxBallWalls]
    int runs = 0;            // runs of walls, one per section entry [0, kBallWallEntries]
    bool copied = false;     // the arrays below hold the runs' walls
    std::uint32_t run_first[kBallWallEntries] = {},
                  run_count[kBallWallEntries] = {};  // each run's first segment node, and its length
    Vec2 p0_m[kMaxBallWalls], p1_m[kMaxBallWalls];   // each wall's end points [m]
    // the rectangle around them [m], as four arrays: answer_from_ball_walls tests two per SSE2 instruction
    alignas(16) double lo_x[kMaxBallWalls] = {}, lo_y[kMaxBallWalls] = {}, hi_x[kMaxBallWalls] = {},
                       hi_y[kMaxBallWalls] = {};
    SegmentRef ref[kMaxBallWalls];
  };
  static_assert(kMaxBallWalls % 2 == 0 && kMaxBallWalls <= 31, "BallWalls: tested in pairs, as bits of an unsigned");
  static_assert(sizeof(BallWalls) == 1312, "BallWalls: the byte count in its comment");
  BallWalls ball_walls_;
  Vec2 wide_ball_center_m_;  // first_hit_wide's free-space ball: no item rectangle (so no wall of a level id it serves)
                             // comes closer
  double wide_ball_radius_m_ = 0.0;  // [m]; 0 = unknown
  std::array<bool, kCutLevelBase>
      wide_serves_{};                          // per level id below the cut steps: wide_serves (set at construction)
  std::uint32_t wide_ball_seed_ = kWideEmpty;  // the last walk's nearest item rectangle: wide node << 2 | slot
};

}  // namespace hk
