/// @file haply_mechanism.cpp
/// Haply five-bar in our frames. See haply_mechanism.hpp.

#include "kinematics/haply_mechanism.hpp"

#include <cmath>
#include <numbers>

namespace hk::hapi {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegPerRad = 180.0 / kPi;

/// x wrapped into [lo, lo + period).
double wrap(double x, double lo, double period) noexcept {
  double r = std::fmod(x - lo, period);
  if (r < 0.0) r += period;
  if (r >= period) r -= period;  // fmod of a tiny negative plus period can round up to period
  return lo + r;
}

}  // namespace

PantographGeometry geometry_of(const HaplyMechanism& m) noexcept {
  PantographGeometry g;
  g.motor_half_spacing_m = 0.5 * m.motor_spacing_m;
  g.base_m = {0.0, 0.0};
  g.proximal_m = m.proximal_m;
  g.distal_m = m.distal_m;
  return g;
}

JointAngles joints_from_haply_deg(double th1_deg, double th2_deg) noexcept {
  JointAngles q;
  q.theta2_rad = wrap(th1_deg / kDegPerRad + kPi, -kPi, 2.0 * kPi);
  q.theta1_rad = wrap(th2_deg / kDegPerRad + kPi, 0.0, 2.0 * kPi);
  return q;
}

void haply_deg_from_joints(JointAngles q, double* th1_deg, double* th2_deg) noexcept {
  *th1_deg = wrap(q.theta2_rad * kDegPerRad - 180.0, 0.0, 360.0);
  *th2_deg = wrap(q.theta1_rad * kDegPerRad - 180.0, -180.0, 360.0);
}

void haply_torques_from(Torques ours, double* tau_h1, double* tau_h2) noexcept {
  *tau_h1 = ours.tau2_n_m;
  *tau_h2 = ours.tau1_n_m;
}

Torques torques_from_haply(double tau_h1, double tau_h2) noexcept { return Torques{tau_h2, tau_h1}; }

Vec2 device_from_haply_m(const HaplyMechanism& m, Vec2 h) noexcept { return {0.5 * m.motor_spacing_m - h.x, -h.y}; }

Vec2 haply_from_device_m(const HaplyMechanism& m, Vec2 p) noexcept { return {0.5 * m.motor_spacing_m - p.x, -p.y}; }

}  // namespace hk::hapi
