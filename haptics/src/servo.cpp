// The servo tick and its force guard (DESIGN.md "Real-time rules").
#include "haptics/servo.hpp"

#include <algorithm>
#include <cmath>

namespace hk {

Vec2 ForceGuard::apply(Vec2 f, double since_start_s, DeviceStatus status, bool deadline_missed, TickResult* why) const {
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

ServoLoop::ServoLoop(const Scene& scene, const ServoParams& params)
    : scene_(&scene), params_(params), solver_(scene, params.contact) {}

void ServoLoop::start(Vec2 handle_m) {
  solver_.reset(handle_m, params_.level);
  last_handle_ = handle_m;
  velocity_ = {0.0, 0.0};
  ticks_ = 0;
}

TickResult ServoLoop::update(const ServoInput& in, ServoOutput& out) {
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

  ContactInput ci;
  ci.handle_m = h;
  ci.handle_velocity_m_per_s = velocity_;
  ci.level = params_.level;
  if (params_.query_deadline_s > 0.0 && in.now_ns > 0) {
    ci.budget.deadline_ns = in.now_ns + static_cast<std::int64_t>(params_.query_deadline_s * 1e9);
  }
  solver_.update(ci, out.contact);
  if (out.contact.state == ContactState::Free) out.contact.level = params_.level;

  const double since_start = static_cast<double>(ticks_) * dt;
  ++ticks_;
  TickResult why = TickResult::Ok;
  out.force_n = params_.guard.apply(out.contact.force_n, since_start, in.sample.status, in.deadline_missed, &why);
  out.handle_velocity_m_per_s = velocity_;
  out.result = why;
  return why;
}

}  // namespace hk
