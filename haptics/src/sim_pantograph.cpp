/// @file sim_pantograph.cpp
/// The simulated pantograph and the model hand. See sim_pantograph.hpp for the physics model.

#include "haptics/sim_pantograph.hpp"
#include "hk/error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace hk {

namespace {

/// One axis of a rigid, perfectly inelastic stop: the position clamped to [lo, hi] [m] and the velocity into
/// the stop killed [m/s].
void stop_axis(double lo, double hi, double& position, double& velocity) noexcept {
  if (position < lo) {
    position = lo;
    velocity = std::max(velocity, 0.0);
  } else if (position > hi) {
    position = hi;
    velocity = std::min(velocity, 0.0);
  }
}

[[noreturn]] void bad_param(const std::string& what) { throw hk::ArgumentError("simulated pantograph: " + what); }

bool finite_nonneg(double v) { return std::isfinite(v) && v >= 0.0; }

/// Rounds an angle to the nearest encoder count. Rounding (not truncation) keeps the error unbiased
/// and within half a count; a real encoder's truncation and index offset are a constant bias the
/// servo loop cannot tell from a calibration offset.
double quantise(double angle_rad, double step_rad) { return std::nearbyint(angle_rad / step_rad) * step_rad; }

}  // namespace

SimulatedPantograph::SimulatedPantograph(const SimPantographParams& params, Vec2 start_handle_m) : params_(params) {
  const PantographGeometry& g = params.geometry;
  if (!(std::isfinite(g.proximal_m) && g.proximal_m > 0.0) || !(std::isfinite(g.distal_m) && g.distal_m > 0.0) ||
      !finite_nonneg(g.motor_half_spacing_m) || !is_finite(g.base_m)) {
    bad_param("geometry lengths must be finite and positive");
  }
  if (!(std::isfinite(params.handle_mass_kg) && params.handle_mass_kg > 0.0)) {
    bad_param("handle_mass_kg must be finite and > 0");
  }
  if (!finite_nonneg(params.handle_damping_n_s_per_m)) bad_param("handle_damping_n_s_per_m must be finite and >= 0");
  if (params.encoder_counts_per_rev < 1) bad_param("encoder_counts_per_rev must be >= 1");
  if (!finite_nonneg(params.max_torque_n_m)) bad_param("max_torque_n_m must be finite and >= 0");
  if (params.substeps < 1 || params.substeps > 100000) bad_param("substeps must be in [1, 100000]");
  if (!(std::isfinite(params.workspace_half_extent_m.x) && params.workspace_half_extent_m.x > 0.0 &&
        std::isfinite(params.workspace_half_extent_m.y) && params.workspace_half_extent_m.y > 0.0)) {
    bad_param("workspace_half_extent_m must be finite and > 0");
  }
  if (!finite_nonneg(params.stop_margin_m)) bad_param("stop_margin_m must be finite and >= 0");
  if (!is_finite(start_handle_m)) bad_param("start handle position must be finite");

  const Vec2 half = params.workspace_half_extent_m + Vec2{params.stop_margin_m, params.stop_margin_m};
  stop_min_m_ = -half;
  stop_max_m_ = half;

  // The stops are the only thing that keeps the handle on the working branch, so the whole stop box
  // must be reachable there (sampled; the reachable set is an intersection of two annuli, so a fine
  // grid misses nothing but slivers far thinner than a grid cell).
  constexpr int kGrid = 40;
  for (int i = 0; i <= kGrid; ++i) {
    for (int j = 0; j <= kGrid; ++j) {
      const Vec2 p{stop_min_m_.x + (stop_max_m_.x - stop_min_m_.x) * i / kGrid,
                   stop_min_m_.y + (stop_max_m_.y - stop_min_m_.y) * j / kGrid};
      JointAngles q;
      Vec2 back;
      if (!inverse_kinematics(g, p, &q) || !forward_kinematics(g, q, &back) || distance(p, back) > 1e-9 ||
          det(jacobian(g, q)) == 0.0) {
        bad_param("stop box point (" + std::to_string(p.x) + ", " + std::to_string(p.y) +
                  ") m is not reachable by the linkage");
      }
    }
  }

  encoder_step_rad_ = 2.0 * std::numbers::pi / params.encoder_counts_per_rev;
  position_m_ = start_handle_m;
  apply_stops();
}

void SimulatedPantograph::open() { status_ = DeviceStatus::Ok; }

DeviceSample SimulatedPantograph::read() noexcept {
  DeviceSample s;
  s.time_ns = time_ns_;
  s.status = status_;
  s.handle_m = position_m_;  // fallback only; the stop box is checked reachable in the constructor
  JointAngles q;
  if (inverse_kinematics(params_.geometry, position_m_, &q)) {
    const JointAngles qq{quantise(q.theta1_rad, encoder_step_rad_), quantise(q.theta2_rad, encoder_step_rad_)};
    Vec2 p;
    if (forward_kinematics(params_.geometry, qq, &p)) s.handle_m = p;
  }
  return s;
}

void SimulatedPantograph::write_force(Vec2 force_n) noexcept {
  commanded_force_n_ = is_finite(force_n) ? force_n : Vec2{};
}

void SimulatedPantograph::close() noexcept {
  commanded_force_n_ = {};
  status_ = DeviceStatus::Closed;
}

DeviceStatus SimulatedPantograph::status() const noexcept { return status_; }

std::string SimulatedPantograph::name() const { return "simulated pantograph"; }

void SimulatedPantograph::step(double dt_s, Vec2 hand_force_n) noexcept {
  if (!(std::isfinite(dt_s) && dt_s > 0.0)) return;
  if (!is_finite(hand_force_n)) hand_force_n = {};

  // Motor force: torques from the commanded force at the current configuration, saturated per motor
  // as the amplifiers would, then mapped back, so saturation bends the force as on real hardware.
  Torques tau{};
  Vec2 motor_force{};
  JointAngles q;
  if (status_ == DeviceStatus::Ok && inverse_kinematics(params_.geometry, position_m_, &q)) {
    const Mat2 J = jacobian(params_.geometry, q);
    tau = joint_torques(J, commanded_force_n_);
    const double lim = params_.max_torque_n_m;
    tau.tau1_n_m = std::clamp(tau.tau1_n_m, -lim, lim);
    tau.tau2_n_m = std::clamp(tau.tau2_n_m, -lim, lim);
    motor_force = handle_force(J, tau);
    if (motor_force == Vec2{}) tau = {};  // singular J: nothing is transmitted, report no torque either
  }
  applied_torques_n_m_ = tau;
  applied_force_n_ = motor_force;

  const Vec2 force = hand_force_n + motor_force;
  const double h = dt_s / params_.substeps;
  const double inv_m = 1.0 / params_.handle_mass_kg;
  // Implicit damping: v' = (v + h·F/m) / (1 + h·b/m) is stable for any b/m and still converges to the
  // exact steady state F/b.
  const double damp = 1.0 / (1.0 + h * params_.handle_damping_n_s_per_m * inv_m);
  for (int i = 0; i < params_.substeps; ++i) {
    velocity_m_per_s_ = damp * (velocity_m_per_s_ + (h * inv_m) * force);
    position_m_ += h * velocity_m_per_s_;
    apply_stops();
  }
  time_ns_ += static_cast<std::int64_t>(std::llround(dt_s * 1e9));
}

void SimulatedPantograph::apply_stops() noexcept {
  stop_axis(stop_min_m_.x, stop_max_m_.x, position_m_.x, velocity_m_per_s_.x);
  stop_axis(stop_min_m_.y, stop_max_m_.y, position_m_.y, velocity_m_per_s_.y);
}

Vec2 model_hand_force(const ModelHandParams& p, Vec2 target_m, Vec2 handle_m, Vec2 handle_velocity_m_per_s) noexcept {
  if (!is_finite(target_m) || !is_finite(handle_m) || !is_finite(handle_velocity_m_per_s) ||
      !std::isfinite(p.stiffness_n_per_m) || !std::isfinite(p.damping_n_s_per_m) || !std::isfinite(p.max_force_n)) {
    return {};
  }
  const Vec2 f = p.stiffness_n_per_m * (target_m - handle_m) - p.damping_n_s_per_m * handle_velocity_m_per_s;
  const double mag = length(f);
  const double limit = std::max(p.max_force_n, 0.0);
  if (!std::isfinite(mag)) return {};
  return mag > limit ? (limit / mag) * f : f;
}

}  // namespace hk
