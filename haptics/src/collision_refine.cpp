// Phases 2 and 7 of first_hit: hit boxes refined nearest first down to the target level's segments, and the
// answer (exact, blocked at the budget, or clear).
#include "collision_query_internal.hpp"

namespace hk {

// Intersects the sweep with one segment of the target level; keeps the nearest hit (of equals, the smallest
// (curve, level, segment): the answer does not depend on the order of the walk, nor on the section's state).
void BoundarySection::Ops::test_segment(BoundarySection& self, Query& q, std::uint32_t node) noexcept {
  const NodeInfo in = self.scene_->info(node);
  const SegmentRef ref{static_cast<std::int32_t>(in.curve), in.level, static_cast<std::int32_t>(in.index)};
  if (q.is_excluded(ref)) return;
  Vec2 p0, p1;
  wall_node_points(self, node, q.level, &p0, &p1);
  q.test_wall(ref, p0, p1);
}

// Pushes the children of `node` the sweep enters, nearest on top. Returns false, with nothing pushed,
// when the budget or the stack ran out first: the box then stays unrefined.
bool BoundarySection::Ops::push_hit_children(BoundarySection& self, Query& q, std::uint32_t node, int& top) noexcept {
  if (is_wide_id(self, node)) return push_wide_children(self, q, node, top);
  const Scene& sc = *self.scene_;
  std::uint32_t first = 0, count = 0;
  sc.children(node, &first, &count);
  const int base = top;
  for (std::uint32_t i = 0; i < count; ++i) {
    double te = 0.0, tx = 0.0;
    if (!q.spend_box()) {
      top = base;
      return false;
    }
    if (overlaps(sc.loose_aabb(first + i), q.sweep, 0.0) &&
        clip_segment_box_inline(sc.box(first + i), q.a, q.b, 0.0, &te, &tx) && te <= q.best.t &&
        !push(self, top, {te, first + i, kNotAnEntry})) {
      top = base;  // the stack is full: as past the budget
      return false;
    }
  }
  std::sort(self.stack_.begin() + base, self.stack_.begin() + top,
            [](const Candidate& x, const Candidate& y) { return x.t_enter > y.t_enter; });
  return true;
}

// push_hit_children for a wide node (the wide frontier): its four rectangles in one SIMD test (sweep_node, as the
// wide index's walks), four optional box tests, all or none; the slots the sweep enters before the horizon pushed,
// nearest on top, as their section ids (a wide node, or an item's segment node).
bool BoundarySection::Ops::push_wide_children(BoundarySection& self, Query& q, std::uint32_t node, int& top) noexcept {
  if (!q.spend_wide_node()) return false;
  const WideNode& n = self.scene_->wide_index().nodes[node - self.wide_base_];
  float t_enter[4];
  const double h = q.horizon();
  const int mask = sweep_node(n, q.ax, q.ay, q.ix, q.iy, h > 1.0 ? 1.0f : float_at_least(h), t_enter);
  const int base = top;
  for (int i = 0; i < 4; ++i) {
    if (!(mask & (1 << i))) continue;
    const std::uint32_t id = wide_child_id(self, n.child[i]);
    if (!push(self, top, {static_cast<double>(t_enter[i]), id, kNotAnEntry})) {
      top = base;  // the stack is full: as past the budget
      return false;
    }
  }
  std::sort(self.stack_.begin() + base, self.stack_.begin() + top,
            [](const Candidate& x, const Candidate& y) { return x.t_enter > y.t_enter; });
  return true;
}

// A box near its target level: the target level's segments under it (at most 2^kDirectLevels, consecutive
// nodes whose points are consecutive too) tested directly rather than through the boxes between, as the wide
// index's walks test the segments under an item. Same first hit (the nearest of the segments under the box,
// the boxes between only prune). Each segment costs one optional box test, all or none: false, with nothing
// tested or charged, when the box is not a segment box within kDirectLevels of a level target (a cut step's
// segments are of mixed levels) or the budget cannot cover them (the descent then goes box by box, anytime).
bool BoundarySection::Ops::test_segments_under(BoundarySection& self, Query& q, std::uint32_t node) noexcept {
  std::uint32_t first = 0;
  const std::uint32_t count = segments_under(self, node, q.level, &first);
  if (count == 0 || !q.budget->affords(static_cast<std::int32_t>(count)))
    return false;  // not refused: the descent may still go part way
  q.spend_boxes(static_cast<std::int32_t>(count));
  test_level_run(self, q, first, count);
  return true;
}

// Phase 2: nearest first. Hit boxes in order of entry, each refined depth-first (nearest child first)
// down to the target level (within 3 levels of it, the segments under the box at once: test_segments_under),
// pruned past the best hit. Past the budget, boxes are not refined: the nearest
// such box bounds what is proven clear (a box holds everything finer).
void BoundarySection::Ops::refine_candidates(BoundarySection& self, Query& q) noexcept {
  std::sort(self.candidates_.begin(), self.candidates_.end(),
            [](const Candidate& x, const Candidate& y) { return x.t_enter < y.t_enter; });
  for (const Candidate& cand : self.candidates_) {
    if (cand.t_enter > q.horizon()) break;
    int top = 0;
    self.stack_[top++] = cand;
    while (top > 0) {
      const Candidate cur = self.stack_[--top];
      if (cur.t_enter > q.horizon()) continue;
      if (at_target(self, cur.node, q.level)) {
        test_segment(self, q, cur.node);
      } else if (!test_segments_under(self, q, cur.node) && !push_hit_children(self, q, cur.node, top) &&
                 cur.t_enter < q.unresolved_t) {
        q.unresolved_t = cur.t_enter;
        q.unresolved_node = cur.node;
      }
    }
  }
}

// Phase 7: the answer. An exact hit; or, when a box left unrefined begins before it, the finest level
// reached and how far the sweep is proven clear; or clear to the end.
SweepHit BoundarySection::Ops::finish(const BoundarySection& self, Query& q) noexcept {
  const Scene& sc = *self.scene_;
  SweepHit best = q.best;
  if (q.unresolved_t < best.t) {
    best.hit = false;
    best.blocked = true;
    best.t = q.unresolved_t;
    const std::uint32_t node = q.unresolved_node;
    if (node == kWideEmpty || (!sc.is_segment(node) && !sc.is_chunk(node))) {
      best.segment =
          SegmentRef{-1, Scene::kMaxLevels, -1};  // above the curves (hierarchy or wide index): no segment to name yet
    } else {
      const NodeInfo in = sc.info(node);
      const int level = sc.is_chunk(node) ? static_cast<int>(sc.curve_nodes(in.curve).levels) - 1
                                          : in.level;  // a chunk: its coarsest segments
      best.segment = SegmentRef{static_cast<std::int32_t>(in.curve), level, static_cast<std::int32_t>(in.index)};
    }
    q.st.coarsest_answer_level = std::max(q.st.coarsest_answer_level, best.segment.level);
  }
  if (best.hit || best.blocked) {
    best.point_m = lerp(q.a, q.b, best.t);
  } else {
    best.t = 1.0;
  }
  q.st.budget_exhausted = q.budget->exhausted() || q.refused;
  q.st.section_size = static_cast<std::int32_t>(self.section_.size());
  return best;
}

}  // namespace hk
