// Phases 4 and 5 of first_hit: the boundary section follows the handle, hit boxes split and idle siblings
// merged into their parent, lazily (merge checks paid on the free-space ball's ticks).
#include "collision_query_internal.hpp"

namespace hk {

// Phase 4: the boundary section follows the handle: what was hit is split (one level per tick), down to
// the coarser of the two ids the section serves (follow_level).
void BoundarySection::Ops::split_hit_boxes(BoundarySection& self, Query& q) noexcept {
  for (const Candidate& cand : self.candidates_) {
    if (!at_floor(self, cand.node, q.level)) {
      split(self, cand.node, cand.entry);
      ++q.st.splits;
    }
  }
}

// Phase 5: siblings whose parent is clear of the sweep by the margin merge into it (merge_children: in place, no
// entry left to drop). Merging only shrinks the section, so it can be lazy: a full query owes one check per 8 idle
// entries (merge_debt_), which the ticks the free-space ball or its walls answer pay, one or two each
// (merge_on_ball_tick); past kMaxMergeDebt owed (a walk through walls, few ball ticks) the full query pays the excess
// itself, parents taken round robin.
void BoundarySection::Ops::merge_idle_siblings(BoundarySection& self, Query& q) noexcept {
  // Merges must keep up with the splits, or the section grows without bound: with 4 checks per tick and no
  // more, a long walk over a dense scene grew it to 9 000–18 000 entries (CollisionQuery.
  // BoundarySectionStaysSmallOnALongWalk; the tick's scan grows with it). So one check per kIdlePerMergeCheck
  // idle entries: a section grown by a burst of splits is merged back (with the tree's frontier and the checks made
  // by the full query itself, 884 entries at most on that walk, one per 16 fell behind there, 3 037; with the wide
  // frontier and the checks paid by the ball ticks, 174). Nothing more, so a section with fewer than 8 idle entries
  // owes none: two checks more every full query, whatever the section's size, cost more than the smaller
  // section they keep saves (PERFORMANCE.md, round two).
  constexpr std::size_t kIdlePerMergeCheck = 8;
  // As many entries as phase 1 scanned, in section order from a point that moves with the tick (round robin);
  // the idle ones are those it did not find hit. Splits and merges since put other nodes at some of them (a
  // child, a parent, the last entry moved into a merged sibling's place) and the section may be shorter now: a
  // new node was not hit this tick, so its parent is checked too; the parent of a split one was hit and stays.
  const std::size_t n = q.scanned;
  if (n == 0) return;
  self.merge_debt_ += static_cast<int>((n - q.hit) / kIdlePerMergeCheck);
  if (self.merge_debt_ <= kMaxMergeDebt) return;            // the ball ticks after this one pay (merge_on_ball_tick)
  const int max_checks = self.merge_debt_ - kMaxMergeDebt;  // what is owed past the cap: at most this query's own share
  self.merge_debt_ = kMaxMergeDebt;
  int checks = 0;
  std::size_t e = self.tick_ % n;
  for (std::size_t j = 0; j < n && checks < max_checks; ++j, e = e + 1 == n ? 0 : e + 1) {
    if (e >= self.section_.size()) continue;
    const std::uint32_t node = self.section_[e];
    const std::uint32_t parent = self.section_parent_[e];  // kNoParent: the root
    // Every entry is in the section and none of its ancestors is (splits and merges change it in place, a
    // frontier), so only the marks decide. One check per parent per tick: a node with many children would
    // otherwise ask again for each.
    if ((self.node_state_[node] & kHitMark) || parent == kNoParent || (self.node_state_[parent] & kCheckedMark))
      continue;
    mark(self, parent, kCheckedMark);
    ++checks;
    // All children in: most checks end here, a sibling split deeper (three in four), on one count rather than a loop
    // over the children whose exit the predictor cannot learn. Then none of them hit this tick.
    if (children_in(self, parent) != child_count(self, parent)) continue;
    std::uint32_t child[kMaxEntryChildren];
    const std::uint32_t count = entry_children(self, parent, child);
    bool all_idle = true;
    for (std::uint32_t i = 0; i < count; ++i) all_idle &= (self.node_state_[child[i]] & kHitMark) == 0;
    if (!all_idle) continue;
    if (!q.spend_box()) break;  // merging can wait for a tick with budget left
    q.st.merges += merge_if_clear(self, e, parent, child, count, q.a, q.b);
  }
}

// The merge of a check that found all `count` children of `parent` in the section (`child`, one at entry e): when the
// parent's box is clear of the sweep a → b by the merge margin (so none of them meets it either), it takes their place
// (merge_children). One box test, which the caller charges. True when it merged.
bool BoundarySection::Ops::merge_if_clear(BoundarySection& self, std::size_t e, std::uint32_t parent,
                                          const std::uint32_t* child, std::uint32_t count, Vec2 a, Vec2 b) noexcept {
  double te = 0.0, tx = 0.0;
  if (clip_segment_box_inline(entry_box(self, parent), a, b, self.merge_margin_m_, &te, &tx)) return false;
  return merge_children(self, e, parent, child, count);
}

// The merge checks full queries left owed (merge_debt_, at least one), paid on a ball tick: one the free-space ball or
// its walls answered (a → b the sweep). One check, two while more than half of kMaxMergeDebt is owed (so that runs of
// full queries seldom leave any past the cap for a full query to pay: PERFORMANCE.md, round two). Each is
// merge_check_on_ball_tick's: at most one optional box test, charged to `budget` and counted in st.
[[gnu::noinline]] void BoundarySection::Ops::merge_on_ball_tick(BoundarySection& self, Vec2 a, Vec2 b,
                                                                QueryBudget& budget, QueryStats& st) noexcept {
  const int checks = self.merge_debt_ > kMaxMergeDebt / 2 ? 2 : 1;
  for (int i = 0; i < checks; ++i) merge_check_on_ball_tick(self, a, b, budget, st);
}

// One merge check of the round robin on a ball tick: the parent of the next entry, when all its children are in the
// section and its box is clear of the sweep by the margin (so none of them meets the sweep either), takes their place.
// One optional box test, charged to `budget` and counted in st (box_tests; merges when it merged).
void BoundarySection::Ops::merge_check_on_ball_tick(BoundarySection& self, Vec2 a, Vec2 b, QueryBudget& budget,
                                                    QueryStats& st) noexcept {
  --self.merge_debt_;
  const std::size_t n = self.section_.size();
  if (n == 0) return;
  const std::size_t e = self.merge_cursor_++ % n;
  const std::uint32_t parent = self.section_parent_[e];
  if (parent == kNoParent || children_in(self, parent) != child_count(self, parent) || !budget.spend()) return;
  ++st.box_tests;
  std::uint32_t child[kMaxEntryChildren];
  const std::uint32_t count = entry_children(self, parent, child);
  st.merges += merge_if_clear(self, e, parent, child, count, a, b);
}

}  // namespace hk
