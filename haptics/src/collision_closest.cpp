// Closest points: the branch-and-bound walk of the wide index (closest_point) and of the tree of error boxes
// (closest_point_cut), seeded by the previous answer.
#include "collision_query_internal.hpp"

namespace hk {

// The best closest-point answer so far of one call, its pruning bound, and where to write the answer.
struct BoundarySection::ClosestQuery {
  Vec2 p;
  int level = 0;
  int curve = -1;
  double best_m = 0.0;      // distance of the best answer so far, or max_distance_m before there is one [m]
  double bound_sq = 0.0;    // best_m² grown by a few ulps: rounding never prunes what best_m itself would keep [m²]
  float bound_sq_f = 0.0f;  // bound_sq as a float no smaller, for the SIMD rectangle tests [m²]
  SegmentRef best_s = kNoSegment;
  std::uint32_t best_node = kWideEmpty;
  Vec2 best_point;
  const int* skip = nullptr;  // curves left out of the answer (skip_count of them)
  int skip_count = 0;
  ClosestQuery(Vec2 p_in, int level_in, int curve_in, double max_distance_m, const int* skip_in = nullptr,
               int skip_count_in = 0)
      : p(p_in), level(level_in), curve(curve_in), skip(skip_in), skip_count(skip_count_in) {
    set_best(max_distance_m);
  }
  void set_best(double d_m) {
    best_m = d_m;
    bound_sq = d_m * d_m * (1.0 + 1e-12);
    bound_sq_f = float_at_least(bound_sq);
  }
  bool found() const { return best_node != kWideEmpty; }
  // Whether curve c is left out (a short scan: the callers skip a handful).
  bool skips(std::uint32_t c) const {
    for (int i = 0; i < skip_count; ++i) {
      if (static_cast<std::uint32_t>(skip[i]) == c) return true;
    }
    return false;
  }
};

// Offers segment node `node` (end points a, b) to the query: taken when nearer than the best so far, or as
// near with the smaller (curve, level, segment). The caller has checked that the end points' rectangle
// is within the bound (rect_within_bound), perhaps before the bound last shrank: the exact distance is
// compared with the bound as it is now. The segment's reference is looked up only where it decides a
// tie or wins. Inlined: it runs several times a call.
[[gnu::always_inline]] inline void BoundarySection::Ops::closest_offer(const BoundarySection& self, ClosestQuery& q,
                                                                       std::uint32_t node, Vec2 a, Vec2 b) noexcept {
  const Vec2 p = q.p;
  const Vec2 c = closest_point_on_segment(p, a, b);
  const double d_sq = length_sq(p - c);
  if (d_sq > q.bound_sq) return;
  const double d = std::sqrt(d_sq);  // bit for bit distance(p, c)
  if (d > q.best_m) return;
  const NodeInfo in = self.scene_->info(node);
  if (q.skip_count > 0 && q.skips(in.curve)) return;
  const SegmentRef ref{static_cast<std::int32_t>(in.curve), in.level, static_cast<std::int32_t>(in.index)};
  if (!closer(d, ref, q.best_m, q.best_s)) return;
  q.set_best(d);
  q.best_s = ref;
  q.best_node = node;
  q.best_point = c;
}

namespace {

// True when the rectangle of a and b comes within sqrt(bound_sq) of p: a lower bound on the segment's
// distance, without a division.
inline bool rect_within_bound(Vec2 p, Vec2 a, Vec2 b, double bound_sq) {
  const double rx = std::max({std::min(a.x, b.x) - p.x, 0.0, p.x - std::max(a.x, b.x)});
  const double ry = std::max({std::min(a.y, b.y) - p.y, 0.0, p.y - std::max(a.y, b.y)});
  return rx * rx + ry * ry <= bound_sq;
}

// rect_within_bound for the two segments s[0]→s[1] and s[1]→s[2] at once (SSE2, the same operations in
// double, so the same answers): bit 0 for the first, bit 1 for the second.
inline int rects_within_bound2(const Vec2* s, Vec2 p, double bound_sq) {
#if defined(__SSE2__)
  const __m128d p0 = _mm_loadu_pd(&s[0].x), p1 = _mm_loadu_pd(&s[1].x), p2 = _mm_loadu_pd(&s[2].x);
  const __m128d ax = _mm_unpacklo_pd(p0, p1), ay = _mm_unpackhi_pd(p0, p1);
  const __m128d bx = _mm_unpacklo_pd(p1, p2), by = _mm_unpackhi_pd(p1, p2);
  const __m128d px = _mm_set1_pd(p.x), py = _mm_set1_pd(p.y), zero = _mm_setzero_pd();
  const __m128d rx =
      _mm_max_pd(_mm_max_pd(_mm_sub_pd(_mm_min_pd(ax, bx), px), _mm_sub_pd(px, _mm_max_pd(ax, bx))), zero);
  const __m128d ry =
      _mm_max_pd(_mm_max_pd(_mm_sub_pd(_mm_min_pd(ay, by), py), _mm_sub_pd(py, _mm_max_pd(ay, by))), zero);
  const __m128d r2 = _mm_add_pd(_mm_mul_pd(rx, rx), _mm_mul_pd(ry, ry));
  return _mm_movemask_pd(_mm_cmple_pd(r2, _mm_set1_pd(bound_sq)));
#else
  return (rect_within_bound(p, s[0], s[1], bound_sq) ? 1 : 0) | (rect_within_bound(p, s[1], s[2], bound_sq) ? 2 : 0);
#endif
}

}  // namespace

// The seed: the previous call's answer, measured again at the new point, when that call was for the same
// level and curve. A real candidate, so the walk's bound is tight from the root down; the hand moves
// little between ticks, so it is nearly always the answer again or within a few of it.
void BoundarySection::Ops::closest_seed(const BoundarySection& self, ClosestQuery& q) noexcept {
  if (self.last_closest_node_ == kWideEmpty || self.last_closest_level_ != q.level ||
      self.last_closest_curve_ != q.curve)
    return;
  Vec2 a, b;
  self.scene_->segment_points(self.last_closest_node_, &a, &b);
  closest_offer(self, q, self.last_closest_node_, a, b);
}

// At an item of the walk: offers the target level's segments under it.
void BoundarySection::Ops::closest_test_item(BoundarySection& self, ClosestQuery& q, std::uint32_t item) noexcept {
  const Scene& sc = *self.scene_;
  if (q.curve >= 0 && static_cast<int>(sc.tag_curve(item)) != q.curve) return;
  if (q.skip_count > 0 && q.skips(sc.tag_curve(item))) return;
  std::uint32_t first = 0;
  const std::uint32_t count = item_segments(self, item, q.level, &first);
  // The segments under an item are consecutive slots: their rectangles two at a time, then the exact
  // distance of those within the bound (which may shrink on the way).
  const Vec2* s = sc.slot_points(first);
  std::uint32_t i = 0;
  for (; i + 1 < count; i += 2) {
    const int mask = rects_within_bound2(s + i, q.p, q.bound_sq);
    if (mask & 1) closest_offer(self, q, first + i, s[i], s[i + 1]);
    if (mask & 2) closest_offer(self, q, first + i + 1, s[i + 1], s[i + 2]);
  }
  if (i < count && rect_within_bound(q.p, s[i], s[i + 1], q.bound_sq))
    closest_offer(self, q, first + i, s[i], s[i + 1]);
}

// Opens node n for the closest-point walk: *next is its nearest child within the bound (kWideEmpty when
// none is), and the others within it are pushed. False, with *top as it was, when the stack is full.
[[gnu::always_inline]] inline bool BoundarySection::Ops::closest_open_node(BoundarySection& self, const ClosestQuery& q,
                                                                           const WideNode& n, float px, float py,
                                                                           int* top, std::uint32_t* next) noexcept {
  float d_sq[4];
  const int mask = near_node(n, px, py, q.bound_sq_f, d_sq);
  *next = kWideEmpty;
  if (mask == 0) return true;
  const int base = *top;
  for (int i = 0; i < 4; ++i) {
    if (!(mask & (1 << i))) continue;
    if (!push_walk(self, std::numeric_limits<float>::infinity(), d_sq[i], n.child[i], base, *top)) {
      *top = base;
      return false;
    }
  }
  *next = self.walk_.code[static_cast<std::size_t>(--*top)];  // pushed nearest last: on top
  return true;
}

// The next entry of the closest-point walk still within the bound, taken off the stack; kWideEmpty when
// none is left.
[[gnu::always_inline]] inline std::uint32_t BoundarySection::Ops::closest_pop(const BoundarySection& self,
                                                                              const ClosestQuery& q,
                                                                              int* top) noexcept {
  while (*top > 0) {
    const std::size_t k = static_cast<std::size_t>(--*top);
    if (static_cast<double>(self.walk_.d_sq[k]) <= q.bound_sq) return self.walk_.code[k];
  }
  return kWideEmpty;
}

// The walk of the wide index: depth first, nearest rectangle first, pruned at the best distance so far
// (which only shrinks). At a node the nearest child within the bound is entered at once and the others
// are pushed, farthest first, for later. False when the budget or the stack ran out (the answer is then
// unknown).
bool BoundarySection::Ops::closest_walk(BoundarySection& self, ClosestQuery& q, QueryBudget* budget) noexcept {
  const WideIndex& wi = self.scene_->wide_index();
  if (wi.nodes.empty()) return true;
  const float px = static_cast<float>(q.p.x), py = static_cast<float>(q.p.y);
  int top = 0;
  std::uint32_t code = 0u;  // the entry being visited: the root first
  for (;;) {
    if (code & kWideLeaf) {
      closest_test_item(self, q, code & ~kWideLeaf);
    } else if (budget && !budget->spend(kWideBoxTestsPerNode)) {
      return false;  // the caller sees budget->ran_out
    } else if (!closest_open_node(self, q, wi.nodes[code], px, py, &top, &code)) {
      if (budget) budget->ran_out = true;  // the stack is full: the answer is unknown, as past the budget
      return false;
    } else if (code != kWideEmpty) {
      continue;  // the nearest child, entered at once
    }
    code = closest_pop(self, q, &top);
    if (code == kWideEmpty) return true;
  }
}

bool BoundarySection::closest_point(Vec2 p, int level, double max_distance_m, Vec2* point_out, SegmentRef* segment_out,
                                    int curve, QueryBudget* budget, const int* skip_curves, int skip_count) noexcept {
  level = walls_of(level);
  if (is_cut_level(level)) {
    return closest_point_cut(p, level - kCutLevelBase, max_distance_m, point_out, segment_out, curve, budget,
                             skip_curves, skip_count);
  }
  if (scene_->curve_count() == 0) return false;
  ClosestQuery q(p, level, curve, max_distance_m, skip_curves, skip_count);
  Ops::closest_seed(*this, q);
  const bool complete =
      Ops::wide_serves(*this, level) ? Ops::closest_walk(*this, q, budget) : Ops::closest_tree_walk(*this, q, budget);
  last_closest_level_ = level;
  last_closest_curve_ = curve;
  last_closest_node_ = complete ? q.best_node : kWideEmpty;
  if (!complete || !q.found()) return false;
  if (point_out) *point_out = q.best_point;
  if (segment_out) *segment_out = q.best_s;
  return true;
}

// The walk of the tree of error boxes for closest points, from the scene root: depth first, nearest box first,
// pruned at the best distance so far (branch and bound, as closest_walk). Each box's distance bounds every wall
// under it from below: a level's segments (a box holds everything finer) and a cut's joined pieces (each inside its
// own segment's box, tolerance_cut.hpp). Stops at the walls of q.level (at_target), offering each, joined at a cut
// step. With a `budget`, each box measured is one optional box test; false when it or the stack ran out (the
// answer is then unknown, budget->ran_out set).
bool BoundarySection::Ops::closest_tree_walk(BoundarySection& self, ClosestQuery& q, QueryBudget* budget) noexcept {
  const Scene& sc = *self.scene_;
  const Vec2 p = q.p;
  const int curve = q.curve;
  // A node of another curve than `curve`, or of a skipped one, holds nothing to answer (a hierarchy node may: kept).
  const auto other_curve = [&sc, &q, curve](std::uint32_t node) {
    if (curve < 0 && q.skip_count == 0) return false;
    std::uint32_t c = 0;
    if (sc.is_segment(node)) {
      c = sc.tag_curve(node);
    } else if (sc.is_chunk(node)) {
      c = sc.info(node).curve;
    } else {
      return false;
    }
    return (curve >= 0 && c != static_cast<std::uint32_t>(curve)) || q.skips(c);
  };
  int top = 0;
  self.stack_[static_cast<std::size_t>(top++)] =
      Candidate{0.0, sc.scene_root(), kNotAnEntry};  // t_enter: the box's squared distance [m²]
  while (top > 0) {
    const Candidate cur = self.stack_[static_cast<std::size_t>(--top)];
    if (cur.t_enter > q.bound_sq) continue;  // the bound shrank since it was pushed
    if (at_target(self, cur.node, q.level)) {
      Vec2 a, b;
      wall_node_points(self, cur.node, q.level, &a, &b);
      closest_offer(self, q, cur.node, a, b);
      continue;
    }
    std::uint32_t first = 0, count = 0;
    sc.children(cur.node, &first, &count);
    const int base = top;
    for (std::uint32_t i = 0; i < count; ++i) {
      const std::uint32_t child = first + i;
      if (other_curve(child)) continue;
      if (rect_distance_sq(sc.loose_aabb(child), p) > q.bound_sq)
        continue;  // the rectangle holds the box: a cheaper lower bound
      if (budget && !budget->spend()) return false;
      const double d_sq = box_distance_sq(sc.box(child), p);
      if (d_sq > q.bound_sq) continue;
      if (!push(self, top,
                Candidate{d_sq, child, kNotAnEntry})) {  // full (never, within the tree's depth): the answer is unknown
        if (budget) budget->ran_out = true;
        return false;
      }
    }
    std::sort(self.stack_.begin() + base, self.stack_.begin() + top,
              [](const Candidate& x, const Candidate& y) { return x.t_enter > y.t_enter; });
  }
  return true;
}

bool BoundarySection::closest_point_cut(Vec2 p, int step, double max_distance_m, Vec2* point_out,
                                        SegmentRef* segment_out, int curve, QueryBudget* budget, const int* skip_curves,
                                        int skip_count) noexcept {
  if (!has_cuts()) {
    return closest_point(p, kToleranceLevelBase + step, max_distance_m, point_out, segment_out, curve, budget,
                         skip_curves, skip_count);
  }
  const Scene& sc = *scene_;
  if (sc.curve_count() == 0) return false;
  ClosestQuery q(p, kCutLevelBase + step, curve, max_distance_m, skip_curves, skip_count);
  if (!Ops::closest_tree_walk(*this, q, budget)) return false;
  if (!q.found()) return false;
  if (point_out) *point_out = q.best_point;
  if (segment_out) *segment_out = q.best_s;
  return true;
}

}  // namespace hk
