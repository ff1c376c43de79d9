// The walls the boundary section serves: the target test and wall points of a level id or cut step, the next
// wall along a curve, and how the section follows a change of level id (phase 0 of first_hit).
#include "collision_query_internal.hpp"

namespace hk {

bool BoundarySection::wall_neighbour(SegmentRef s, int level, int dir, SegmentRef* out) const noexcept {
  level = walls_of(level);
  const Scene& sc = *scene_;
  const CurveInfo& ci = sc.curve(static_cast<std::size_t>(s.curve));
  const auto n = static_cast<std::int32_t>(ci.segment_count[s.level]);
  std::int32_t k = s.segment + (dir > 0 ? 1 : -1);
  if (k < 0 || k >= n) {
    if (!ci.closed) return false;
    k = (k + n) % n;
  }
  if (k == s.segment) return false;
  if (!is_cut_level(level)) {
    *out = SegmentRef{s.curve, s.level, k};
    return true;
  }
  // The cut segment covering level-0 segment j, the first past s's end (or the last before its start):
  // exactly one of its ancestors-or-self is in the cut. Same-level segment k's level-0 range holds j.
  const int step = level - kCutLevelBase;
  const auto n0 = static_cast<std::int64_t>(ci.segment_count[0]);
  const std::int64_t j =
      dir > 0 ? (static_cast<std::int64_t>(k) << s.level) : ((static_cast<std::int64_t>(k) + 1) << s.level) - 1;
  const CurveNodes& cn = sc.curve_nodes(static_cast<std::size_t>(s.curve));
  for (int l = static_cast<int>(ci.levels) - 1; l >= 0; --l) {
    const auto i = static_cast<std::uint32_t>((j % n0) >> l);
    if (in_cut(cut_mask_, cn.box_offset[l] + i, step)) {
      *out = SegmentRef{s.curve, l, static_cast<std::int32_t>(i)};
      return !(out->level == s.level && out->segment == s.segment);
    }
  }
  return false;  // not reached: every level-0 segment is under exactly one cut segment
}

// Phase 0: the section serves the level ids of this query and the one before it (two in turn while the
// contact solver renders both walls of a level change; one otherwise): every segment entry is at or above
// the walls of both on its curve (a level: its clamp_level; a cut step: the cut), so its box holds their
// walls, and splits stop at the coarser of the two (at_floor). A new id keeps the section: entries below
// its walls give way to their ancestor at them (coarsen_section), which holds the same stretch of curve; to
// a finer id nothing changes. The free-space ball holds for the two ids it was measured for, and is
// forgotten at any other. The frontier is the wide one while the wide index serves both ids (wide_frontier), else
// the tree's; a change of ids that changes which starts the section again from that frontier's root (reset).
// Called only when the ids change (first_hit).
void BoundarySection::Ops::follow_level(BoundarySection& self, int level) noexcept {
  const int previous = self.last_level_, served = self.other_level_;  // the section serves both
  self.other_level_ = previous < 0 ? level : previous;
  self.last_level_ = level;
  const bool wide = wide_frontier(self, level) && wide_frontier(self, self.other_level_);
  if (previous < 0 || wide != self.wide_mode_) {  // the other frontier: start it from its root
    self.wide_mode_ = wide;
    self.reset();
    return;
  }
  if (level == previous) return;
  if (level != self.ball_levels_[0] && level != self.ball_levels_[1]) self.ball_radius_sq_ = 0.0;
  if (level != served) coarsen_section(self, level);  // a transition's two ids in turn: nothing to coarsen
}

// The node's ancestor at the walls of `level` on its curve (a segment of that level, or of that cut step's cut)
// when the node lies below them, else the node itself: up by Scene::parent, O(levels).
std::uint32_t BoundarySection::Ops::wall_ancestor(const BoundarySection& self, std::uint32_t node, int level) noexcept {
  const Scene& sc = *self.scene_;
  if (!sc.is_segment(node)) return node;
  if (!is_cut_level(level)) {
    const int target = sc.clamp_level(sc.tag_curve(node), level);
    std::uint32_t a = node;
    while (sc.tag_level(a) < target) a = sc.parent(a);  // target ≤ the curve's coarsest: a stays a segment
    return a;
  }
  for (std::uint32_t a = sc.parent(node); sc.is_segment(a); a = sc.parent(a)) {  // the cut is a frontier: at most one
    if (in_cut(self.cut_mask_, a, level - kCutLevelBase)) return a;
  }
  return node;
}

// Every segment entry below the walls of `level` replaced by its ancestor at them (wall_ancestor; once, however
// many of its descendants were in), so the section still covers the same stretches of curve, no node with
// its ancestor. Without room for the ancestors (a section at its storage bound), the section starts again
// from the root.
void BoundarySection::Ops::coarsen_section(BoundarySection& self, int level) noexcept {
  const std::size_t n = self.section_.size();
  bool changed = false;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t node = self.section_[i];
    const std::uint32_t ancestor = wall_ancestor(self, node, level);
    if (ancestor == node) continue;
    if (self.section_.size() >= self.capacity_) {
      self.reset();
      return;
    }
    mark_out(self, node, self.section_parent_[i]);
    if (!in_section(self, ancestor)) push_section(self, ancestor, parent_or_none(self, ancestor));
    changed = true;
  }
  if (changed) drop_departed_entries(self);
}

// The section without the entries that left it (kInSection cleared), in order, rectangles with them (after
// coarsen_section).
void BoundarySection::Ops::drop_departed_entries(BoundarySection& self) noexcept {
  std::size_t w = 0;
  for (std::size_t i = 0; i < self.section_.size();
       ++i) {  // every entry copied, kept by advancing w: no branch to mispredict
    const std::uint32_t node = self.section_[i];
    self.section_rect_.copy(w, i);
    self.section_[w] = node;
    self.section_parent_[w] = self.section_parent_[i];
    w += self.node_state_[node] & kInSection;
  }
  self.section_.resize(w);
}

}  // namespace hk
