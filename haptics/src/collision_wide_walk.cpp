// first_hit_wide: the walks of the wide index (wide_index.hpp) with their own free-space ball, and the descent
// of the tree of error boxes at level ids the index does not serve.
#include "collision_query_internal.hpp"

namespace hk {

// Tests the sweep against the target level's segments at an item (test_level_run).
void BoundarySection::Ops::wide_test_item(BoundarySection& self, Query& q, std::uint32_t item) noexcept {
  std::uint32_t first = 0;
  const std::uint32_t count = item_segments(self, item, q.level, &first);
  test_level_run(self, q, first, count);
}

// One walk of the wide index for both answers of first_hit_wide: the first hit of the sweep, and the
// free-space ball at its end. A child is entered when the sweep meets its rectangle before the best hit
// so far (for the hit) or when its rectangle is nearer to b than the ball so far (for the ball), nearest
// to b first, so that the ball shrinks early. At an item the sweep is tested exactly; for the ball the
// item rectangle's own distance is taken as it is (it bounds every wall under it from below). Each node
// opened is four box tests (its four rectangles, in one SIMD test); past the budget nodes are not opened:
// the nearest such node the sweep enters bounds what is proven clear, and the ball is unknown. Returns
// the ball's radius [m] (0 when unknown).
double BoundarySection::Ops::wide_walk(BoundarySection& self, Query& q, double ball_cap_m) noexcept {
  const WideIndex& wi = self.scene_->wide_index();
  if (wi.nodes.empty()) return ball_cap_m;
  const float ax = q.ax, ay = q.ay, ix = q.ix, iy = q.iy;
  const float bx = static_cast<float>(q.b.x), by = static_cast<float>(q.b.y);
  float ball_sq = seeded_ball_sq(self, wi, bx, by, static_cast<float>(ball_cap_m * ball_cap_m));
  bool ball_known = true;
  int top = 0;
  push_walk(self, 0.0f, 0.0f, 0u, 0, top);  // the root
  while (top > 0) {
    const std::size_t k = static_cast<std::size_t>(--top);
    const WalkEntry e{self.walk_.t_enter[k], self.walk_.d_sq[k], self.walk_.code[k]};
    const bool for_hit = static_cast<double>(e.t_enter) <= q.horizon();
    const bool for_ball = e.d_sq < ball_sq;
    if (!for_hit && !for_ball) continue;
    if (e.code & kWideLeaf) {  // pushed for the hit only: its distance was taken for the ball when its node was opened
      wide_test_item(self, q, e.code & ~kWideLeaf);
      continue;
    }
    if (!q.spend_wide_node()) {
      ball_known = false;
      if (for_hit && e.t_enter < q.unresolved_t) {
        q.unresolved_t = e.t_enter;
        q.unresolved_node = kWideEmpty;
      }
      continue;
    }
    const WideNode& n = wi.nodes[e.code];
    float t_enter[4], d_sq[4];
    const double h = q.horizon();
    const int hit_mask = sweep_node(n, ax, ay, ix, iy, h > 1.0 ? 1.0f : float_at_least(h), t_enter);
    const int near_mask = near_node(n, bx, by, ball_sq, d_sq);
    const int base = top;
    for (int i = 0; i < 4; ++i) {
      const int bit = 1 << i;
      if (!((hit_mask | near_mask) & bit)) continue;
      const bool leaf = (n.child[i] & kWideLeaf) != 0;
      if (leaf && d_sq[i] < ball_sq) {  // an item's rectangle: its distance is final, the ball shrinks at once
        ball_sq = d_sq[i];
        self.wide_ball_seed_ = e.code << 2 | static_cast<std::uint32_t>(i);
      }
      if (leaf && !(hit_mask & bit)) continue;
      if (!push_walk(self, (hit_mask & bit) ? t_enter[i] : std::numeric_limits<float>::infinity(), d_sq[i], n.child[i],
                     base, top)) {  // full: as past the budget
        ball_known = false;
        if (e.t_enter < q.unresolved_t) {
          q.unresolved_t = e.t_enter;
          q.unresolved_node = kWideEmpty;
        }
        top = base;
        break;
      }
    }
  }
  if (!ball_known) return 0.0;
  // The float distances bound the padded rectangles' from below up to a few ulps; the factor keeps the
  // ball strictly inside what the exact rectangles allow.
  return std::sqrt(static_cast<double>(ball_sq)) * (1.0 - 1e-6);
}

// The ball's first bound: the squared distance from (bx, by) to the item rectangle nearest to the last
// walk's end (a real rectangle, so an upper bound on the nearest one's, and pruning at it from the root
// down opens fewer nodes; the hand moves little between ticks), computed as near_node computes it, or
// cap_sq when there is no such rectangle or it is farther.
float BoundarySection::Ops::seeded_ball_sq(const BoundarySection& self, const WideIndex& wi, float bx, float by,
                                           float cap_sq) noexcept {
  if (self.wide_ball_seed_ == kWideEmpty) return cap_sq;
  const WideNode& n = wi.nodes[self.wide_ball_seed_ >> 2];
  const std::uint32_t i = self.wide_ball_seed_ & 3u;
  const float dx = std::max(std::max(n.lo_x[i] - bx, bx - n.hi_x[i]), 0.0f);
  const float dy = std::max(std::max(n.lo_y[i] - by, by - n.hi_y[i]), 0.0f);
  return std::min(dx * dx + dy * dy, cap_sq);
}

SweepHit BoundarySection::first_hit_wide(Vec2 a, Vec2 b, int level, const SegmentRef* excluded, int excluded_count,
                                         QueryBudget& budget, QueryStats* stats_out) noexcept {
  level = walls_of(level);
  if (is_cut_level(level)) {  // not walked here (first_hit walks cuts): nothing is proven clear, never guess
    if (stats_out) *stats_out = QueryStats{};
    SweepHit none;
    none.blocked = true;
    none.t = 0.0;
    none.point_m = a;
    none.segment = SegmentRef{-1, Scene::kMaxLevels, -1};
    return none;
  }
  if (!Ops::wide_serves(*this, level))
    return Ops::first_hit_tree(*this, a, b, level, excluded, excluded_count, budget, stats_out);
  const double r_sq = wide_ball_radius_m_ * wide_ball_radius_m_;
  if (length_sq(a - wide_ball_center_m_) < r_sq && length_sq(b - wide_ball_center_m_) < r_sq) {
    if (stats_out) *stats_out = QueryStats{};
    SweepHit clear;
    clear.point_m = b;
    return clear;
  }
  Query q(a, b, level, excluded, excluded_count, budget);
  const double ball_m = Ops::wide_walk(*this, q, kWideBallCap_m);
  const bool clear = !q.best.hit && q.unresolved_t == std::numeric_limits<double>::infinity();
  wide_ball_center_m_ = b;
  wide_ball_radius_m_ = clear ? ball_m : 0.0;
  const SweepHit answer = Ops::finish(*this, q);
  q.st.section_size = 0;
  if (stats_out) *stats_out = q.st;
  return answer;
}

// first_hit_wide at a level id coarser than the wide index's items: the descent of first_hit's phase 2 from the
// scene root, with no section and no ball (refine_candidates: nearest box first, pruned past the best hit, one
// optional box test per box). Past the budget the answer is blocked at the nearest box left unrefined, named as
// first_hit names it (finish).
SweepHit BoundarySection::Ops::first_hit_tree(BoundarySection& self, Vec2 a, Vec2 b, int level,
                                              const SegmentRef* excluded, int excluded_count, QueryBudget& budget,
                                              QueryStats* stats_out) noexcept {
  const Scene& sc = *self.scene_;
  Query q(a, b, level, excluded, excluded_count, budget);
  self.candidates_.clear();
  if (sc.curve_count() > 0) {
    const std::uint32_t root = sc.scene_root();
    double te = 0.0, tx = 0.0;
    if (!q.spend_box()) {
      q.unresolved_t = 0.0;  // nothing proven clear
      q.unresolved_node = root;
    } else if (clip_segment_box_inline(sc.box(root), a, b, 0.0, &te, &tx)) {
      self.candidates_.push_back({te, root, kNotAnEntry});
    }
  }
  refine_candidates(self, q);
  const SweepHit answer = finish(self, q);
  q.st.section_size = 0;
  if (stats_out) *stats_out = q.st;
  return answer;
}

}  // namespace hk
