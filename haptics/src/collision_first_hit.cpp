// first_hit: the free-space ball, else its walls, else a full query through the phases of the boundary
// section (seed paper §3).
#include "collision_query_internal.hpp"

namespace hk {

// What a ball tick (a → b answered by the free-space ball or its walls) does to the section: the merge checks full
// queries left owed, while some are (merge_on_ball_tick), counted in *stats (box_tests, merges) with the section's
// size after them.
inline void BoundarySection::Ops::pay_merge_debt(BoundarySection& self, Vec2 a, Vec2 b, QueryBudget& budget,
                                                 QueryStats* stats) noexcept {
  QueryStats unused;
  if (self.merge_debt_ > 0) merge_on_ball_tick(self, a, b, budget, stats ? *stats : unused);
  if (stats) stats->section_size = static_cast<std::int32_t>(self.section_.size());
}

SweepHit BoundarySection::first_hit(Vec2 a, Vec2 b, int level, const SegmentRef* excluded, int excluded_count,
                                    QueryBudget& budget, QueryStats* stats_out) noexcept {
  level = walls_of(level);
  if (level != last_level_ || level != other_level_)
    Ops::follow_level(*this, level);  // else it serves this id alone, as before
  if (Ops::inside_free_ball(*this, a, b)) {
    if (stats_out) *stats_out = QueryStats{};
    Ops::pay_merge_debt(*this, a, b, budget, stats_out);
    SweepHit clear;
    clear.point_m = b;
    return clear;
  }
  return Ops::first_hit_near_walls(*this, a, b, level, excluded, excluded_count, budget, stats_out);
}

// first_hit past its free-space ball: the ball's walls, else a full query. Out of line, so the ball's answer (most
// ticks) does not pay this part's stack frame and saved registers.
[[gnu::noinline]] SweepHit BoundarySection::Ops::first_hit_near_walls(BoundarySection& self, Vec2 a, Vec2 b, int level,
                                                                      const SegmentRef* excluded, int excluded_count,
                                                                      QueryBudget& budget,
                                                                      QueryStats* stats_out) noexcept {
  SweepHit near;
  if (answer_from_ball_walls(self, a, b, level, excluded, excluded_count, &near, stats_out)) {
    pay_merge_debt(self, a, b, budget, stats_out);  // a ball tick too
    return near;
  }
  Query q(a, b, level, excluded, excluded_count, budget);
  next_tick(self);
  clip_section(self, q);
  refine_candidates(self, q);
  gather_ball_walls(self, q);  // before the section changes: it reads the entries as phase 1 scanned them
  split_hit_boxes(self, q);
  merge_idle_siblings(self, q);
  clear_marks(self);
  place_free_ball(self, q);
  const SweepHit answer = finish(self, q);
  if (stats_out) *stats_out = q.st;
  return answer;
}

}  // namespace hk
