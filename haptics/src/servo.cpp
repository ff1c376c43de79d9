// The servo tick and its force guard (DESIGN.md "Real-time rules").
#include "haptics/servo.hpp"

#include <algorithm>
#include <cmath>

namespace hk {

Vec2 ForceGuard::apply(Vec2 f, double since_start_s, DeviceStatus status, bool deadline_missed,
                       TickResult* why) const noexcept {
  *why = TickResult::Ok;
  if (status != DeviceStatus::Ok) {
    *why = TickResult::DeviceNotOk;
    return {0.0, 0.0};
  }
  if (deadline_missed) {
    *why = TickResult::DeadlineMissed;
    return {0.0, 0.0};
  }
  if (!is_finite(f)) {
    *why = TickResult::NonFinite;
    return {0.0, 0.0};
  }
  // Ramp the clamp, not the force, so a visitor resting on a wall feels it come back smoothly.
  const double ramp = ramp_s > 0.0 ? std::clamp(since_start_s / ramp_s, 0.0, 1.0) : 1.0;
  const double limit = max_force_n * ramp;
  const double mag = length(f);
  if (mag > limit) f = mag > 0.0 ? (limit / mag) * f : Vec2{0.0, 0.0};
  return f;
}

namespace {

// The policy's ladder: the level ids it chooses from, finest first, and the scene's error bound at each
// (the worst curve's, so the id chosen keeps every curve within tolerance). Levels: every level of the
// scene. Tolerance steps or cut steps (ServoParams::steps): every step (LevelPolicy
// keeps the bounds non-decreasing, as a curve's bound need not grow with its level); a cut step's bound is
// its cut's (CutBounds: the largest segment bound plus the largest join shift). Also writes the scene's bound
// at every level id to `id_bound` (kLevelIds entries), for placing an id that is not on the ladder. Returns
// the ladder's length.
int level_ladder(const Scene& scene, const CutBounds& cuts, const ServoParams& p, int* ids, double* err,
                 double* id_bound) {
  for (int id = 0; id < kLevelIds; ++id) {
    id_bound[id] = is_cut_level(id) && p.steps == LevelSteps::Cuts ? cuts.error_bound_m[tolerance_step_of(id)]
                                                                   : scene.max_error_bound_m(id);
  }
  if (p.steps == LevelSteps::Cuts) {
    for (int t = 0; t < kToleranceSteps; ++t) {
      ids[t] = kCutLevelBase + t;
      err[t] = id_bound[ids[t]];
    }
    return kToleranceSteps;
  }
  if (p.steps == LevelSteps::Levels) {
    const int levels = std::min(scene.max_curve_levels(), LevelPolicy::kMaxLevels);
    for (int l = 0; l < levels; ++l) {
      ids[l] = l;
      err[l] = scene.max_error_bound_m(l);
    }
    return levels;
  }
  static_assert(kToleranceSteps <= LevelPolicy::kMaxLevels, "the policy's ladder holds every tolerance step");
  for (int t = 0; t < kToleranceSteps; ++t) {
    ids[t] = kToleranceLevelBase + t;
    err[t] = scene.max_error_bound_m(ids[t]);
  }
  return kToleranceSteps;
}

// The solver's parameters, stepped at the loop's period. (Its cut masks come from the loop: SceneStep::cuts_.)
ContactParams contact_params(const ServoParams& p) {
  ContactParams c = p.contact;
  c.period_s = p.period_s;
  return c;
}

LevelPolicyParams policy_params(const ServoParams& p) {
  LevelPolicyParams pp = p.policy;
  pp.fixed_level = -1;  // fixing the level is the loop's business (auto_level off)
  return pp;
}

// `v` one fade step shorter: its length less `step` [N], or zero when that is (within rounding) all of it.
Vec2 fade(Vec2 v, double step) noexcept {
  const double r = length(v);
  return r - step > 1e-12 ? ((r - step) / r) * v : Vec2{0.0, 0.0};
}

}  // namespace

ServoGains gains_of(const ServoParams& p) noexcept {
  ServoGains g;
  g.stiffness_n_per_m = p.contact.stiffness_n_per_m;
  g.damping_n_s_per_m = p.contact.damping_n_s_per_m;
  g.max_force_n = p.contact.max_force_n;
  g.static_friction = p.contact.static_friction;
  g.dynamic_friction = p.contact.dynamic_friction;
  g.max_force_step_n = p.max_force_step_n;
  g.query_box_budget = p.query_box_budget;
  g.pop_force_n = p.contact.pop_force_n;
  g.pop_hold_s = p.contact.pop_hold_s;
  g.pop_release_s = p.contact.pop_release_s;
  return g;
}

void apply_gains(ServoParams& p, const ServoGains& g) noexcept {
  p.contact.stiffness_n_per_m = g.stiffness_n_per_m;
  p.contact.damping_n_s_per_m = g.damping_n_s_per_m;
  p.contact.max_force_n = g.max_force_n;
  p.contact.static_friction = g.static_friction;
  p.contact.dynamic_friction = g.dynamic_friction;
  p.guard.max_force_n = g.max_force_n;
  p.max_force_step_n = g.max_force_step_n;
  p.query_box_budget = g.query_box_budget;
  p.contact.pop_force_n = g.pop_force_n;
  p.contact.pop_hold_s = g.pop_hold_s;
  p.contact.pop_release_s = g.pop_release_s;
  p.groove.stiffness_n_per_m = g.stiffness_n_per_m;
  p.groove.max_force_n = g.max_force_n;
  p.groove.jump_step_n = g.max_force_step_n;
}

SceneStep::SceneStep(const Scene& scene, const ServoParams& params)
    : params_(params),
      cuts_(params.steps == LevelSteps::Cuts ? make_cut_walls(scene)
                                             : nullptr),  // the cut masks only where the policy can pick a cut step
      solver_(scene, contact_params(params), cuts_),
      groove_(scene, params.groove, cuts_),
      levels_(level_ladder(scene, solver_.section().cut_bounds(), params, ladder_id_, level_error_m_, id_bound_m_)),
      policy_(policy_params(params), level_error_m_, levels_,
              ladder_index(params.level)),  // the ladder's members are set by now
      level_(params.level),
      guard_max_force_n_(params.guard.max_force_n) {}

int SceneStep::ladder_index(int id) const noexcept {
  for (int i = 0; i < levels_; ++i) {
    if (ladder_id_[i] == id) return i;
  }
  // A level on a ladder of tolerance steps (or the reverse): the coarsest rung no looser than its bound.
  const double bound = id_bound_m_[std::clamp(id, 0, kLevelIds - 1)];
  int index = 0;
  for (int i = 0; i < levels_; ++i) {
    if (level_error_m_[i] <= bound) index = i;
  }
  return index;
}

void SceneStep::start(Vec2 handle_m) noexcept {
  level_ = params_.auto_level ? ladder_id_[policy_.level()] : params_.level;
  if (params_.render == RenderMode::Grooves) {
    groove_.reset(handle_m, level_);
  } else {
    solver_.reset(handle_m, level_, params_.query_box_budget);
  }
  last_handle_ = handle_m;
  velocity_ = {0.0, 0.0};
  force_residual_ = {0.0, 0.0};
  guard_max_force_n_ = params_.guard.max_force_n;  // the start-up ramp brings the force in from zero
  gains_changed_ = false;
  last_force_ = {0.0, 0.0};
  ticks_ = 0;
}

void SceneStep::set_gains(const ServoGains& g) noexcept {
  if (g == gains()) return;
  apply_gains(params_, g);
  solver_.set_params(contact_params(params_));
  groove_.set_params(params_.groove);
  gains_changed_ = true;
}

bool SceneStep::transition_active() const noexcept {
  return force_residual_.x != 0.0 || force_residual_.y != 0.0 || guard_max_force_n_ != params_.guard.max_force_n;
}

void SceneStep::set_auto_level(bool on) noexcept {
  // The policy starts again from the level in use, its speed filter from rest (the ladder is kept: no
  // walk over the scene in the servo thread).
  if (on && !params_.auto_level)
    policy_ = LevelPolicy(policy_params(params_), level_error_m_, levels_, ladder_index(level_));
  params_.auto_level = on;
  if (!on) params_.level = level_;
}

TickResult SceneStep::update(const ServoInput& in, ServoOutput& out) noexcept {
  const Vec2 h = in.sample.handle_m;
  if (!is_finite(h)) {
    out.force_n = {0.0, 0.0};
    out.result = TickResult::NonFinite;
    return out.result;
  }
  // Finite-difference velocity through a first-order low-pass (encoder steps make raw differences noisy).
  const double dt = params_.period_s;
  const Vec2 raw = (1.0 / dt) * (h - last_handle_);
  const double alpha = 1.0 - std::exp(-2.0 * M_PI * params_.velocity_cutoff_hz * dt);
  velocity_ = velocity_ + alpha * (raw - velocity_);
  last_handle_ = h;

  // Level: from the hand's speed or fixed; changed only when the proxy can move to it without crossing.
  const int wanted = params_.auto_level ? ladder_id_[policy_.update(velocity_, dt)] : params_.level;
  // One box-test budget for the whole tick: the level-change check first, then every query of the solver.
  QueryBudget budget;
  budget.max_box_tests = params_.query_box_budget;
  out.level_changed = false;
  const bool grooves = params_.render == RenderMode::Grooves;
  if (wanted != level_) {
    if (grooves || solver_.level_change_is_safe(
                       wanted, &budget)) {  // grooves: no wall to cross; walls: else it waits (level_wanted)
      out.level_changed = true;
      level_ = wanted;
    }
  }
  out.level = level_;
  out.level_wanted = wanted;

  ContactInput ci;
  ci.handle_m = h;
  ci.handle_velocity_m_per_s = velocity_;
  ci.level = level_;
  ci.budget = budget;
  ci.press_counts = in.press_counts && static_cast<double>(ticks_) * params_.period_s >=
                                           params_.guard.ramp_s;  // not while the force ramps in
  if (grooves) {
    groove_.update(ci, out.contact);
  } else {
    solver_.update(ci, out.contact);
  }
  if (out.contact.state == ContactState::Free) out.contact.level = level_;

  // Force-step limit at level and gains changes: the difference between the last tick's force and the new
  // level's (or gains') force fades out at max_force_step_n per tick instead of arriving at once. The tick
  // of the change already takes the first step.
  const double step = params_.max_force_step_n;
  Vec2 f = out.contact.force_n;
  // Grooves: the groove solver already limits every change per tick (GrooveParams::jump_step_n).
  if ((out.level_changed || gains_changed_) && ticks_ > 0 && !grooves) force_residual_ = last_force_ - f;
  gains_changed_ = false;
  if (force_residual_.x != 0.0 || force_residual_.y != 0.0) {
    force_residual_ = fade(force_residual_, step);
    f = f + force_residual_;
  }
  if (!is_finite(f)) f = Vec2{0.0, 0.0};
  last_force_ = f;
  // The guard's clamp walks to a new max force at the same rate.
  const double clamp_gap = params_.guard.max_force_n - guard_max_force_n_;
  guard_max_force_n_ = std::fabs(clamp_gap) - step > 1e-12 ? guard_max_force_n_ + std::copysign(step, clamp_gap)
                                                           : params_.guard.max_force_n;
  ForceGuard guard = params_.guard;
  guard.max_force_n = guard_max_force_n_;

  const double since_start = static_cast<double>(ticks_) * dt;
  ++ticks_;
  TickResult why = TickResult::Ok;
  out.force_n = guard.apply(f, since_start, in.sample.status, in.deadline_missed, &why);
  out.handle_velocity_m_per_s = velocity_;
  out.result = why;
  return why;
}

}  // namespace hk
