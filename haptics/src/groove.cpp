// The grooves rendering mode. See groove.hpp for the model and the profile.
#include "haptics/groove.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace hk {

double groove_profile_n(const GrooveParams& p, double r_m) noexcept {
  const double R = p.capture_radius_m;
  if (!(r_m >= 0.0) || !(r_m < R) || !std::isfinite(r_m)) return 0.0;
  const double k = p.stiffness_n_per_m;
  const double f = std::min({k * r_m, p.depth_n, k * (R - r_m)});
  return std::clamp(f, 0.0, std::max(0.0, p.max_force_n));
}

GrooveSolver::GrooveSolver(const Scene& scene, const GrooveParams& params)
    : GrooveSolver(scene, params, params.cut_walls ? make_cut_walls(scene) : nullptr) {}

GrooveSolver::GrooveSolver(const Scene& scene, const GrooveParams& params, std::shared_ptr<const CutWalls> cuts)
    : scene_(&scene), params_(params), section_(scene, 3e-4, std::move(cuts)) {}

void GrooveSolver::reset(Vec2 p_m, int level) noexcept {
  proxy_ = p_m;
  state_ = ContactState::Free;
  seg_ = SegmentRef{};
  level_ = level;
  last_force_ = {0.0, 0.0};
  last_handle_ = p_m;
  section_.reset();
}

// The phases of update, in order.

// The closest point of the polylines at the level in use within the capture radius (closest_point on the
// tick's budget): there the state is Edge and the proxy that point; nothing within it, Free with the proxy at
// the handle. Unknown within the budget: the groove is followed from where it was while the handle stays
// within the radius of last tick's closest point (a point of the curve, so the pull is towards the curve).
void GrooveSolver::find_groove(Vec2 h, QueryBudget& budget, ContactOutput& out) noexcept {
  const std::int32_t used_before = budget.box_tests_used;
  const double R = params_.capture_radius_m;
  Vec2 q;
  SegmentRef s;
  const bool found = section_.closest_point(h, level_, R, &q, &s, -1, &budget);
  out.queries = 1;
  out.query.box_tests = budget.box_tests_used - used_before;
  out.query.section_size = static_cast<std::int32_t>(section_.section().size());
  out.query.coarsest_answer_level = level_;
  out.query.budget_exhausted = budget.exhausted();
  if (found && distance(h, q) < R) {
    state_ = ContactState::Edge;
    proxy_ = q;
    seg_ = s;
  } else if (!found && budget.ran_out) {
    out.events |= kEventQueryBudget;
    out.query.budget_exhausted = true;
    if (!(state_ == ContactState::Edge && distance(h, proxy_) < R)) {
      state_ = ContactState::Free;
      proxy_ = h;
    }
  } else {
    state_ = ContactState::Free;
    proxy_ = h;
  }
}

// The pull of the profile towards the closest point, then the per-tick limit (groove.hpp): it binds only where
// the closest point jumps (the medial axis) or the law changes (level, gains); along a lone curve the target
// moves by at most k·|Δh| and passes as is. Clamped to max_force_n; a non-finite force is zero.
Vec2 GrooveSolver::groove_force(Vec2 h) noexcept {
  Vec2 target{0.0, 0.0};
  if (state_ == ContactState::Edge) {
    const double r = distance(h, proxy_);
    if (r > 0.0) target = (groove_profile_n(params_, r) / r) * (proxy_ - h);
  }
  const double allowed = params_.stiffness_n_per_m * distance(h, last_handle_) + params_.jump_step_n;
  const Vec2 delta = target - last_force_;
  const double dn = length(delta);
  Vec2 f = dn > allowed && dn > 0.0 ? last_force_ + (allowed / dn) * delta : target;
  const double mag = length(f);
  if (mag > params_.max_force_n) f = mag > 0.0 ? (params_.max_force_n / mag) * f : Vec2{0.0, 0.0};
  if (!is_finite(f)) f = Vec2{0.0, 0.0};
  last_force_ = f;
  last_handle_ = h;
  return f;
}

void GrooveSolver::update(const ContactInput& in, ContactOutput& out) noexcept {
  const Vec2 h = in.handle_m;
  const ContactState before = state_;
  out.events = kEventNone;
  out.corner_turn_rad = 0.0;
  out.sticking = false;
  out.transition_level = -1;
  out.press_s = 0.0;  // grooves never block, so nothing is pushed through
  out.query = QueryStats{};
  out.queries = 0;
  out.path_count = 0;
  out.path_m[out.path_count++] = proxy_;
  level_ = in.level;

  QueryBudget budget = in.budget;
  find_groove(h, budget, out);
  const Vec2 f = groove_force(h);

  out.path_m[out.path_count++] = proxy_;
  out.proxy_m = proxy_;
  out.force_n = f;
  out.state = state_;
  out.constraint[0] = state_ == ContactState::Edge ? seg_ : SegmentRef{};
  out.constraint[1] = SegmentRef{};
  out.level = level_;
  out.budget_used = budget.box_tests_used;
  if (before == ContactState::Free && state_ != ContactState::Free) out.events |= kEventContactBegin;
  if (before != ContactState::Free && state_ == ContactState::Free) out.events |= kEventContactEnd;
}

}  // namespace hk
