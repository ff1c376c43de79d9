// God-object contact solver (seed paper §4). See contact.hpp for the model.
#include "haptics/contact.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace hk {
ContactSolver::ContactSolver(const Scene& scene, const ContactParams& params)
    : ContactSolver(scene, params, params.cut_walls ? make_cut_walls(scene) : nullptr) {}

ContactSolver::ContactSolver(const Scene& scene, const ContactParams& params, std::shared_ptr<const CutWalls> cuts)
    : scene_(&scene), params_(params), section_(scene, 3e-4, std::move(cuts)) {
  for (int id = 0; id < kLevelIds;
       ++id) {  // a cut step without the masks renders as its tolerance step, as Scene gives it
    const bool cut = is_cut_level(id) && section_.has_cuts();
    max_wall_offset_m_[id] =
        cut ? 2.0 * section_.cut_bounds().error_bound_m[tolerance_step_of(id)] : scene.max_error_bound_m(id);
  }
}

ContactSolver::SegGeom ContactSolver::geom(SegmentRef s, int level) const noexcept {
  SegGeom g;
  section_.wall_points(s, level, &g.a, &g.b);
  const Vec2 d = g.b - g.a;
  g.len = length(d);
  g.u = normalized_or(d, Vec2{1.0, 0.0});
  g.n = left_perp(g.u);
  return g;
}

void ContactSolver::reset(Vec2 p_m, int level, std::int32_t max_box_tests) noexcept {
  proxy_ = p_m;
  state_ = ContactState::Free;
  sticking_ = false;
  transition_level_ = -1;
  level_ = level;
  press_ticks_ = 0;
  release_left_ = 0;
  last_force_n_ = Vec2{0.0, 0.0};
  section_.reset();
  QueryBudget budget;
  budget.max_box_tests = max_box_tests;
  push_off_walls(&budget);
}

void ContactSolver::push_off_walls(QueryBudget* budget) noexcept {
  // A proxy on a wall would have no side: push it off along the wall's normal, to the side it is on.
  Vec2 q;
  SegmentRef s;
  if (section_.closest_point(proxy_, level_, 2.0 * params_.skin_m, &q, &s, -1, budget)) {
    const SegGeom g = geom(s, level_);
    const double side = dot(g.n, proxy_ - g.a) >= 0.0 ? 1.0 : -1.0;
    proxy_ = q + (2.0 * params_.skin_m * side) * g.n;
  }
}

namespace {
// A duration in servo ticks, at least one.
long ticks_of(double duration_s, double period_s) noexcept {
  return std::max(1L, std::lround(duration_s / (period_s > 0.0 ? period_s : 0.001)));
}
}  // namespace

bool ContactSolver::pop_due() const noexcept {
  return params_.pop_force_n > 0.0 && state_ != ContactState::Free &&
         press_ticks_ >= ticks_of(params_.pop_hold_s, params_.period_s);
}

void ContactSolver::pop_through(Step& s) noexcept {
  // The wall gives way: the proxy goes to the handle, beyond the wall(s) it was held by, off any polyline.
  proxy_ = s.in.handle_m;
  push_off_walls(&s.budget);
  if (s.out.path_count < ContactOutput::kMaxPath) s.out.path_m[s.out.path_count++] = proxy_;
  state_ = ContactState::Free;
  sticking_ = false;
  transition_level_ = -1;
  press_ticks_ = 0;
  release_from_n_ = last_force_n_;
  release_left_ = ticks_of(params_.pop_release_s, params_.period_s);
  s.out.events |= kEventPopThrough;
}

Vec2 ContactSolver::release_force(Vec2 f) noexcept {
  if (release_left_ > 0) {
    const double share =
        static_cast<double>(release_left_) / static_cast<double>(ticks_of(params_.pop_release_s, params_.period_s));
    f += std::min(share, 1.0) * release_from_n_;
    --release_left_;
    const double mag = length(f);
    if (mag > params_.max_force_n) f = (params_.max_force_n / mag) * f;
    if (!is_finite(f)) f = Vec2{0.0, 0.0};
  }
  last_force_n_ = f;
  return f;
}

void ContactSolver::count_press(const ContactInput& in, ContactOutput& out) noexcept {
  // How hard the hand presses: the spring's force, unclamped (the clamp is what the device can give).
  const bool pressing = params_.pop_force_n > 0.0 && in.press_counts && state_ != ContactState::Free &&
                        params_.stiffness_n_per_m * distance(proxy_, in.handle_m) >= params_.pop_force_n;
  press_ticks_ = pressing ? press_ticks_ + 1 : 0;
  out.press_s = static_cast<double>(press_ticks_) * params_.period_s;
}

int ContactSolver::side_of_curve(Vec2 p, int curve, int level, double radius_m, QueryBudget* budget) noexcept {
  Vec2 q;
  SegmentRef s;
  if (!section_.closest_point(p, level, radius_m, &q, &s, curve, budget)) return budget && budget->ran_out ? 3 : 0;
  const SegGeom g = geom(s, level);
  // The sign of (p − q) against the normal at q decides the side; where q is a vertex that normal is the
  // angle-weighted pseudo-normal (in 2D the bisector of the two edges' normals), which makes the sign
  // exact (Bærentzen & Aanæs 2005, "Signed distance computation using the angle weighted pseudonormal",
  // IEEE TVCG 11(3)).
  Vec2 n = g.n;
  const double t = dot(q - g.a, g.u);
  SegmentRef nb;
  for (int dir : {-1, +1}) {
    if (dir < 0 ? t > 1e-12 : t < g.len - 1e-12) continue;
    // Nearest to an open end (which every level shares): the end segment's own line decides, as if it ran on
    // past the end. Beyond the end, the wedge between two levels' end segments is between the polylines (their
    // loop, closed at the shared end, holds it), and there the two lines give different sides.
    if (!section_.wall_neighbour(s, level, dir, &nb)) continue;
    n = normalized_or(g.n + geom(nb, level).n, g.n);
  }
  const double d = dot(p - q, n);
  return d > 0.0 ? 1 : (d < 0.0 ? -1 : 2);  // 2: on the polyline, no side
}

bool ContactSolver::level_change_is_safe(int new_level, QueryBudget* budget) noexcept {
  if (new_level == level_) return true;
  if (transition_level_ >= 0) return false;  // one change at a time
  // A curve's polylines at two levels lie within E = (largest wall offset at one level + at the other) of
  // each other, so a point between them lies within E of both; search twice as far.
  const double e = max_wall_offset_m_[std::clamp(level_, 0, kLevelIds - 1)] +
                   max_wall_offset_m_[std::clamp(new_level, 0, kLevelIds - 1)];
  const double radius = 2.0 * e + 4.0 * params_.skin_m;
  // The curves that could have the proxy between their two levels: those it touches, and every curve within
  // the radius at either level, found nearest first by closest points that skip the curves found so far.
  int curves[kMaxSideCurves];
  int n = 0;
  if (state_ != ContactState::Free) curves[n++] = c_[0].seg.curve;
  if (state_ == ContactState::Vertex && c_[1].seg.curve != c_[0].seg.curve) curves[n++] = c_[1].seg.curve;
  for (int l : {level_, new_level}) {
    Vec2 q;
    SegmentRef s;
    while (section_.closest_point(proxy_, l, radius, &q, &s, -1, budget, curves, n)) {
      if (n == kMaxSideCurves) return false;  // more curves this close than one check takes: wait
      curves[n++] = s.curve;
    }
    if (budget && budget->ran_out) return false;  // not known within this tick's budget: wait
  }
  for (int i = 0; i < n; ++i) {
    const int before = side_of_curve(proxy_, curves[i], level_, radius, budget);
    const int after = side_of_curve(proxy_, curves[i], new_level, radius, budget);
    if (before == 3 || after == 3) return false;  // not known within this tick's budget: wait
    if (before == 2 || after == 2) return false;
    if (before != 0 && after != 0 && before != after) return false;  // the proxy would be behind the new wall
  }
  return true;
}

bool ContactSolver::excluded_at(const Constraint& c, int level) const noexcept {
  if (c.level == level) return true;
  if (!section_.is_wall(c.seg, level)) return false;
  if (!is_cut_level(level) && !is_cut_level(c.level))
    return true;  // a level's segment: the same end points under every id
  Vec2 a0, b0, a1, b1;
  section_.wall_points(c.seg, c.level, &a0, &b0);
  section_.wall_points(c.seg, level, &a1, &b1);
  return a0 == a1 && b0 == b1;
}

ContactSolver::Move ContactSolver::move_to(Vec2 target, int level, const Constraint* excluded, QueryBudget& budget,
                                           ContactOutput& out, Constraint* hit_out) noexcept {
  QueryStats st;
  const bool skip_new = excluded && excluded_at(*excluded, level);
  SweepHit hit =
      section_.first_hit(proxy_, target, level, skip_new ? &excluded->seg : nullptr, skip_new ? 1 : 0, budget, &st);
  int hit_level = level;
  if (transition_level_ >= 0) {
    // Just after a level change both levels are walls (see level_change_is_safe): the nearer one stops the move.
    QueryStats st2;
    const bool skip_old = excluded && excluded_at(*excluded, transition_level_);
    const SweepHit old_hit = section_.first_hit(proxy_, target, transition_level_, skip_old ? &excluded->seg : nullptr,
                                                skip_old ? 1 : 0, budget, &st2);
    st.box_tests += st2.box_tests;
    st.section_box_tests += st2.section_box_tests;
    st.segment_tests += st2.segment_tests;
    st.splits += st2.splits;
    st.merges += st2.merges;
    st.budget_exhausted = st.budget_exhausted || st2.budget_exhausted;
    const bool old_first = (old_hit.hit || old_hit.blocked) && (!(hit.hit || hit.blocked) || old_hit.t < hit.t);
    if (old_first) {
      hit = old_hit;
      hit_level = transition_level_;
    }
  }
  out.query.box_tests += st.box_tests;
  out.query.section_box_tests += st.section_box_tests;
  out.query.segment_tests += st.segment_tests;
  out.query.splits += st.splits;
  out.query.merges += st.merges;
  out.query.section_size = st.section_size;
  out.query.coarsest_answer_level = std::max(out.query.coarsest_answer_level, st.coarsest_answer_level);
  out.query.budget_exhausted = out.query.budget_exhausted || st.budget_exhausted;
  ++out.queries;
  if (hit.blocked) {
    // Unresolved within the budget: go only as far as the sweep is proven clear, less the skin. Never guess.
    const double len = distance(proxy_, target);
    const double t = len > 0.0 ? std::max(0.0, hit.t - params_.skin_m / len) : 0.0;
    proxy_ = proxy_ + t * (target - proxy_);
    if (out.path_count < ContactOutput::kMaxPath) out.path_m[out.path_count++] = proxy_;
    out.events |= kEventQueryBudget;
    return Move::Blocked;
  }
  if (!hit.hit) {
    proxy_ = target;
    if (out.path_count < ContactOutput::kMaxPath) out.path_m[out.path_count++] = proxy_;
    return Move::Clear;
  }
  // Stop where the proxy is a skin away from the wall's line, along the path already proven clear.
  const SegGeom g = geom(hit.segment, hit_level);
  double side = dot(g.n, proxy_ - g.a);
  side = side > 0.0 ? 1.0 : (side < 0.0 ? -1.0 : (dot(g.n, target - g.a) > 0.0 ? -1.0 : 1.0));
  const double dist0 = side * dot(g.n, proxy_ - g.a);
  const double closing = -side * dot(g.n, target - proxy_);
  double t = 0.0;
  if (closing > 0.0) t = std::clamp((dist0 - params_.skin_m) / closing, 0.0, hit.t);
  proxy_ = proxy_ + t * (target - proxy_);
  if (out.path_count < ContactOutput::kMaxPath) out.path_m[out.path_count++] = proxy_;
  hit_out->seg = hit.segment;
  hit_out->side = side;
  hit_out->level = hit_level;
  return Move::Hit;
}

void ContactSolver::update(const ContactInput& in, ContactOutput& out) noexcept {
  const ContactState before = state_;
  begin_step(in, out);
  Step s{in, out, in.budget};
  if (pop_due()) pop_through(s);
  bool rest = false;
  for (int iter = 0; iter < params_.max_iterations && !rest; ++iter) {
    switch (state_) {
      case ContactState::Free:
        rest = step_free(s);
        break;
      case ContactState::Edge:
        rest = step_edge(s);
        break;
      case ContactState::Vertex:
        rest = step_vertex(s);
        break;
    }
  }
  if (!rest) out.events |= kEventIterationLimit;
  out.budget_used = s.budget.box_tests_used;
  finish_step(before, release_force(contact_force(in)), out);
  count_press(in, out);
}

void ContactSolver::begin_step(const ContactInput& in, ContactOutput& out) noexcept {
  out.events = kEventNone;
  out.corner_turn_rad = 0.0;
  out.query = QueryStats{};
  out.queries = 0;
  out.path_count = 0;
  out.path_m[out.path_count++] = proxy_;
  if (in.level != level_) {
    // A level change (the caller checked level_change_is_safe): the old level stays a wall, with its
    // constraints, until the proxy no longer touches it, so the move onto the new level crosses neither.
    transition_level_ = level_;
    level_ = in.level;
  }
}

bool ContactSolver::step_free(Step& s) noexcept {
  Constraint hit;
  const Move m = move_to(s.in.handle_m, level_, nullptr, s.budget, s.out, &hit);
  if (m != Move::Hit) return true;
  state_ = ContactState::Edge;
  c_[0] = hit;
  sticking_ = false;  // the proxy arrives moving: judged against the dynamic cone first
  return false;
}

bool ContactSolver::step_edge(Step& s) noexcept {
  const Vec2 h = s.in.handle_m;
  const double side = c_[0].side;
  const SegGeom g = geom(c_[0]);
  if (side * dot(g.n, h - g.a) >= 0.0) {  // handle back on the proxy's side: contact released
    state_ = ContactState::Free;
    return false;
  }
  // Friction cone (see contact.hpp): inside it the proxy stays; outside, it slides to trail the
  // handle's foot point by μ_d · penetration.
  const double depth = -side * dot(g.n, h - g.a);  // > 0: the handle is behind the wall's line
  const double t_off = dot(g.u, h - proxy_);       // the handle's lead along the edge [m]
  const double mu = sticking_ ? params_.static_friction : params_.dynamic_friction;
  if (std::fabs(t_off) <= mu * depth) {
    // Inside the cone: the proxy stays. A sliding proxy sticks again only once the hand has all but
    // stopped along the edge (Karnopp's stick band): otherwise a press that deepens while sliding
    // would re-stick it every few ticks and each break-away would be a μ_s − μ_d force step, a buzz.
    if (!sticking_)
      sticking_ = mu > 0.0 && std::fabs(dot(g.u, s.in.handle_velocity_m_per_s)) <= params_.stick_speed_m_per_s;
    return true;
  }
  sticking_ = false;
  const double tau = dot(g.u, h - g.a) - std::copysign(params_.dynamic_friction * depth, t_off);
  const int clamped = tau < 0.0 ? -1 : (tau > g.len ? 1 : 0);
  const double tau_c = std::clamp(tau, 0.0, g.len);
  Constraint hit;
  const Move m = move_to(g.a + tau_c * g.u + (side * params_.skin_m) * g.n, level_, &c_[0], s.budget, s.out, &hit);
  if (m == Move::Blocked) return true;
  if (m == Move::Hit) {
    state_ = ContactState::Vertex;  // a second wall while sliding
    c_[1] = hit;
    s.out.events |= kEventVertexBegin;
    const SegGeom gh = geom(hit);  // the angle between the two walls' lines, in [0, π/2]
    s.out.corner_turn_rad =
        std::max(s.out.corner_turn_rad, std::atan2(std::fabs(cross(g.u, gh.u)), std::fabs(dot(g.u, gh.u))));
    return false;
  }
  if (clamped == 0) return true;
  return at_edge_vertex(s, clamped);
}

bool ContactSolver::at_edge_vertex(Step& s, int clamped) noexcept {
  const Vec2 h = s.in.handle_m;
  const double side = c_[0].side;
  const int wall_level = c_[0].level;
  const SegGeom g = geom(c_[0]);
  SegmentRef nb;
  if (!section_.wall_neighbour(c_[0].seg, wall_level, clamped, &nb)) {  // the open end of a curve: go round it
    state_ = ContactState::Free;
    return false;
  }
  const SegGeom gn = geom(nb, wall_level);
  const Vec2 v = clamped > 0 ? g.b : g.a;
  const Vec2 u_in = clamped > 0 ? g.u : gn.u;
  const Vec2 u_out = clamped > 0 ? gn.u : g.u;
  const double turn = side * cross(u_in, u_out);
  const bool pen_nb = side * dot(gn.n, h - gn.a) < 0.0;
  const double turn_rad = std::atan2(std::fabs(turn), dot(u_in, u_out));  // how sharply the curve turns at V
  if (turn > 0.0) {  // concave on the proxy's side: the two walls hold it
    if (!pen_nb) return true;
    state_ = ContactState::Vertex;
    c_[1] = Constraint{nb, side, wall_level};
    s.out.events |= kEventVertexBegin;
    s.out.corner_turn_rad = std::max(s.out.corner_turn_rad, turn_rad);
    return false;
  }
  // Convex (or straight): step round the corner to the bisector of the two normals, then go on
  // along the next edge if the handle is behind it, or leave it.
  if (turn < 0.0) {
    s.out.events |= kEventConvexCorner;
    s.out.corner_turn_rad = std::max(s.out.corner_turn_rad, turn_rad);
  }
  const Vec2 bis = normalized_or(g.n + gn.n, clamped > 0 ? g.u : -g.u);
  Constraint hit;
  const Move mc = move_to(v + (side * params_.skin_m) * bis, level_, nullptr, s.budget, s.out, &hit);
  if (mc == Move::Blocked) return true;
  if (mc == Move::Hit) {
    state_ = ContactState::Edge;
    c_[0] = hit;
    return false;
  }
  if (pen_nb) {
    c_[0] = Constraint{nb, side, wall_level};
  } else {
    state_ = ContactState::Free;
  }
  return false;
}

bool ContactSolver::step_vertex(Step& s) noexcept {
  const Vec2 h = s.in.handle_m;
  const SegGeom ga = geom(c_[0]);
  const SegGeom gb = geom(c_[1]);
  const double sa = c_[0].side, sb = c_[1].side;
  const bool pen_a = sa * dot(ga.n, h - ga.a) < 0.0;
  const bool pen_b = sb * dot(gb.n, h - gb.a) < 0.0;
  if (!pen_a && !pen_b) {
    state_ = ContactState::Free;
    return false;
  }
  if (!pen_a) {
    state_ = ContactState::Edge;
    c_[0] = c_[1];
    return false;
  }
  if (!pen_b) {
    state_ = ContactState::Edge;
    return false;
  }
  // Stable-contact rule (seed §4): sliding along an edge must not lead away from the other wall.
  const Vec2 pull = h - proxy_;
  const double along_a = dot(ga.u, pull), along_b = dot(gb.u, pull);
  const bool a_leaves_b = sb * dot(gb.n, along_a * ga.u) > 0.0;
  const bool b_leaves_a = sa * dot(ga.n, along_b * gb.u) > 0.0;
  if (a_leaves_b && (!b_leaves_a || std::abs(along_a) >= std::abs(along_b))) {
    state_ = ContactState::Edge;
    return false;
  }
  if (b_leaves_a) {
    state_ = ContactState::Edge;
    c_[0] = c_[1];
    return false;
  }
  return true;
}

Vec2 ContactSolver::contact_force(const ContactInput& in) const noexcept {
  // Spring from handle to proxy, damping along the contact normal, one clamp.
  const Vec2 h = in.handle_m;
  Vec2 f = params_.stiffness_n_per_m * (proxy_ - h);
  if (state_ != ContactState::Free && params_.damping_n_s_per_m > 0.0) {
    const SegGeom g = geom(c_[0]);
    f -= (params_.damping_n_s_per_m * dot(in.handle_velocity_m_per_s, g.n)) * g.n;
  }
  const double mag = length(f);
  if (mag > params_.max_force_n) f = (params_.max_force_n / mag) * f;
  if (!is_finite(f)) f = Vec2{0.0, 0.0};
  return f;
}

void ContactSolver::finish_step(ContactState before, Vec2 force_n, ContactOutput& out) noexcept {
  out.proxy_m = proxy_;
  out.force_n = force_n;
  out.state = state_;
  out.sticking = state_ == ContactState::Edge && sticking_;
  out.level = -1;
  out.constraint[0] = SegmentRef{};
  out.constraint[1] = SegmentRef{};
  if (state_ != ContactState::Free) {
    out.constraint[0] = c_[0].seg;
    out.level = c_[0].seg.level;
    if (state_ == ContactState::Vertex) out.constraint[1] = c_[1].seg;
  }
  if (transition_level_ >= 0) {  // the old level's walls go once the proxy rests on none of them
    const bool on_old = state_ != ContactState::Free &&
                        (section_.is_wall(c_[0].seg, transition_level_) ||
                         (state_ == ContactState::Vertex && section_.is_wall(c_[1].seg, transition_level_)));
    if (!on_old) transition_level_ = -1;
  }
  out.transition_level = transition_level_;
  if (before == ContactState::Free && state_ != ContactState::Free) out.events |= kEventContactBegin;
  if (before != ContactState::Free && state_ == ContactState::Free) out.events |= kEventContactEnd;
}

}  // namespace hk
