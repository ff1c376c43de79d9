/// @file pantograph.cpp
/// Five-bar kinematics and statics. See pantograph.hpp for the frame, the branch and the sources.

#include "kinematics/pantograph.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace hk {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

bool finite_geometry(const PantographGeometry& g) {
  return std::isfinite(g.motor_half_spacing_m) && is_finite(g.base_m) && std::isfinite(g.proximal_m) &&
         std::isfinite(g.distal_m) && g.proximal_m > 0.0 && g.distal_m > 0.0;
}

/// Wraps an angle into [lo, lo + 2π).
double wrap_from(double angle_rad, double lo_rad) {
  double a = std::fmod(angle_rad - lo_rad, kTwoPi);
  if (a < 0.0) a += kTwoPi;
  // fmod can return exactly 2π after the += for tiny negative inputs; keep the half-open range.
  if (a >= kTwoPi) a -= kTwoPi;
  return lo_rad + a;
}

/// Angle at the motor between the ray motor → handle and the proximal link (law of cosines), or NaN
/// when the handle is outside the chain's annulus.
double elbow_offset_rad(double l1, double l2, double d) {
  if (!(d > 0.0)) return std::nan("");
  const double c = (l1 * l1 + d * d - l2 * l2) / (2.0 * l1 * d);
  if (c > 1.0 || c < -1.0) return std::nan("");
  return std::acos(c);
}

}  // namespace

Elbows elbow_positions(const PantographGeometry& g, JointAngles q) noexcept {
  const Vec2 m1 = motor1_position(g);
  const Vec2 m2 = motor2_position(g);
  return {m1 + g.proximal_m * Vec2{std::cos(q.theta1_rad), std::sin(q.theta1_rad)},
          m2 + g.proximal_m * Vec2{std::cos(q.theta2_rad), std::sin(q.theta2_rad)}};
}

bool forward_kinematics(const PantographGeometry& g, JointAngles q, Vec2* handle_m) noexcept {
  if (!finite_geometry(g) || !std::isfinite(q.theta1_rad) || !std::isfinite(q.theta2_rad)) return false;
  const Elbows e = elbow_positions(g, q);
  const Vec2 u = e.elbow2_m - e.elbow1_m;
  const double d = length(u);
  const double l2 = g.distal_m;
  // Coincident elbows: every point of the circle is a solution, the handle is undetermined.
  if (!(d > 1e-12 * l2) || d > 2.0 * l2) return false;
  const double half = 0.5 * d;
  const double h = std::sqrt(std::max(0.0, l2 * l2 - half * half));
  const Vec2 u_hat{u.x / d, u.y / d};
  // Right of elbow1 → elbow2 is the side away from the motors: the "handle below" branch.
  *handle_m = e.elbow1_m + half * u_hat - h * left_perp(u_hat);
  return true;
}

bool inverse_kinematics(const PantographGeometry& g, Vec2 handle_m, JointAngles* out) noexcept {
  if (!finite_geometry(g) || !is_finite(handle_m)) return false;
  const Vec2 r1 = handle_m - motor1_position(g);
  const Vec2 r2 = handle_m - motor2_position(g);
  const double a1 = elbow_offset_rad(g.proximal_m, g.distal_m, length(r1));
  const double a2 = elbow_offset_rad(g.proximal_m, g.distal_m, length(r2));
  if (std::isnan(a1) || std::isnan(a2)) return false;
  // Elbows outward: the left elbow turns clockwise from its motor → handle ray, the right one
  // counter-clockwise.
  out->theta1_rad = wrap_from(std::atan2(r1.y, r1.x) - a1, 0.0);
  out->theta2_rad = wrap_from(std::atan2(r2.y, r2.x) + a2, -std::numbers::pi);
  return true;
}

Mat2 jacobian(const PantographGeometry& g, JointAngles q) noexcept {
  Vec2 p;
  if (!forward_kinematics(g, q, &p)) return {};
  const Elbows e = elbow_positions(g, q);
  const Vec2 r1 = p - e.elbow1_m;
  const Vec2 r2 = p - e.elbow2_m;
  // ∂e_i/∂θi: the proximal link rotated by +90°.
  const Vec2 t1 = g.proximal_m * Vec2{-std::sin(q.theta1_rad), std::cos(q.theta1_rad)};
  const Vec2 t2 = g.proximal_m * Vec2{-std::sin(q.theta2_rad), std::cos(q.theta2_rad)};
  const double b1 = dot(r1, t1);
  const double b2 = dot(r2, t2);
  const double det_a = cross(r1, r2);
  // det A is |r1||r2| sin(angle between the distal links), |r_i| = L2: relative threshold on L2².
  if (!(std::abs(det_a) > 1e-12 * g.distal_m * g.distal_m)) return {};
  // J = A⁻¹·B with A⁻¹ = [[r2.y, −r1.y], [−r2.x, r1.x]] / det A.
  return {r2.y * b1 / det_a, -r1.y * b2 / det_a, -r2.x * b1 / det_a, r1.x * b2 / det_a};
}

Torques joint_torques(const Mat2& J, Vec2 force_n) noexcept {
  const Vec2 t = mul(transpose(J), force_n);
  return {t.x, t.y};
}

Vec2 handle_force(const Mat2& J, Torques tau) noexcept {
  const double d = det(J);
  const double scale = std::max({std::abs(J.a11), std::abs(J.a12), std::abs(J.a21), std::abs(J.a22)});
  if (!std::isfinite(d) || !std::isfinite(scale) || !(std::abs(d) > 1e-12 * scale * scale)) return {};
  // Solve Jᵀ·F = τ; (Jᵀ)⁻¹ = [[a22, −a21], [−a12, a11]] / det J.
  const Vec2 f{(J.a22 * tau.tau1_n_m - J.a21 * tau.tau2_n_m) / d, (-J.a12 * tau.tau1_n_m + J.a11 * tau.tau2_n_m) / d};
  return is_finite(f) ? f : Vec2{};
}

double min_force_everywhere_n(const PantographGeometry& g, Vec2 rect_center_m, Vec2 rect_size_m,
                              double torque_limit_n_m) noexcept {
  if (!is_finite(rect_center_m) || !is_finite(rect_size_m) || !(rect_size_m.x > 0.0) || !(rect_size_m.y > 0.0) ||
      !(torque_limit_n_m > 0.0) || !std::isfinite(torque_limit_n_m))
    return 0.0;
  constexpr int kGrid = 21, kDirections = 72;
  double least = std::numeric_limits<double>::infinity();
  for (int iy = 0; iy < kGrid; ++iy)
    for (int ix = 0; ix < kGrid; ++ix) {
      const Vec2 at =
          rect_center_m + Vec2{(ix / (kGrid - 1.0) - 0.5) * rect_size_m.x, (iy / (kGrid - 1.0) - 0.5) * rect_size_m.y};
      JointAngles q;
      if (!inverse_kinematics(g, at, &q)) return 0.0;
      const Mat2 J = jacobian(g, q);
      for (int k = 0; k < kDirections; ++k) {
        const double a = 2.0 * std::numbers::pi * k / kDirections;
        const Torques t = joint_torques(J, {std::cos(a), std::sin(a)});  // torques per newton along u
        const double worst = std::max(std::fabs(t.tau1_n_m), std::fabs(t.tau2_n_m));
        if (worst > 0.0) least = std::min(least, torque_limit_n_m / worst);
      }
    }
  return std::isfinite(least) ? least : 0.0;
}

}  // namespace hk
