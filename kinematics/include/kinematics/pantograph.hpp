#pragma once
/// @file pantograph.hpp
/// Kinematics and statics of a five-bar (pantograph) haptic handle in the workspace frame
/// (DESIGN.md "Frames and units", "Devices").
///
/// Geometry (all in the workspace frame, metres; origin at the centre of the usable rectangle,
/// x to the user's right, y away from the user):
///
///          motor1 ----- base ----- motor2        y = base.y, motors at base ∓ (half_spacing, 0)
///          /                            \        proximal links, length L1, angle θi from +x (CCW)
///     elbow1                           elbow2
///          \                            /        distal links, length L2
///            `-------- handle ---------'         handle below the base (handle.y < base.y)
///
/// Motor 1 is the LEFT motor (base − (half_spacing, 0)), motor 2 the RIGHT one. The assembly branch
/// used everywhere here is "elbows outward, handle below": elbow 1 lies clockwise of the ray
/// motor1 → handle, elbow 2 counter-clockwise of motor2 → handle, and the handle lies to the right of
/// the directed line elbow1 → elbow2 (i.e. on the side away from the motors).
///
/// Angle ranges returned by `inverse_kinematics`: θ1 ∈ [0, 2π) (elbow 1 points roughly left, so the
/// ±π wrap never falls inside the workspace), θ2 ∈ [−π, π) (elbow 2 points roughly right).
/// `forward_kinematics` and `jacobian` accept any angle (they only use sin/cos).
///
/// Sources: the five-bar closed-form kinematics and the velocity relation A·ẋ = B·θ̇ are standard,
/// e.g. Campion, Wang & Hayward, "The Pantograph Mk-II: a haptic instrument" (IROS 2005), and
/// Gosselin & Angeles, "Singularity analysis of closed-loop kinematic chains" (IEEE TRA 1990) for the
/// two singularity types (det B = 0: a chain fully stretched or folded; det A = 0: the distal links
/// collinear).
///
/// Default geometry check (tests/haptics/test_pantograph.cpp, "ReachableRectangle…"): with the defaults
/// below every point of the usable rectangle [−0.07, 0.07] × [−0.045, 0.045] m is reachable on this
/// branch with |det J| ∈ [0.0114, 0.0146] m²/rad², singular values of J in [0.069, 0.166] m/rad and
/// 84°…135° between the two distal links (far from both singularity types); on the mechanical-stop box
/// 1 cm outside it |det J| ≥ 0.0104 m²/rad² and 75°…139°. With a 0.5 N·m torque limit that leaves at
/// least 3.7 N in every direction. The defaults are the ones of the brief; no change was needed.
///
/// All functions are real-time safe: no allocation, no locks, no exceptions.

#include "hk/vec2.hpp"

namespace hk {

/// Physical dimensions of the five-bar [m]. The defaults fit the 0.14 m × 0.09 m usable rectangle.
struct PantographGeometry {
  double motor_half_spacing_m = 0.04;  ///< half the distance between the two motor axes [m]
  Vec2 base_m{0.0, 0.16};              ///< mid-point between the motor axes, workspace frame [m]
  double proximal_m = 0.12;            ///< motor-to-elbow link length L1 [m]
  double distal_m = 0.16;              ///< elbow-to-handle link length L2 (both distal links) [m]
};

/// The two motor (joint) angles [rad], each measured from +x, counter-clockwise.
struct JointAngles {
  double theta1_rad = 0.0;  ///< left motor (motor 1)
  double theta2_rad = 0.0;  ///< right motor (motor 2)
};

/// A 2×2 matrix, row-major: [[a11, a12], [a21, a22]]. As a Jacobian: column j = ∂handle/∂θj [m/rad].
struct Mat2 {
  double a11 = 0.0, a12 = 0.0, a21 = 0.0, a22 = 0.0;
};

/// Motor torques [N·m], positive counter-clockwise (increasing θi).
struct Torques {
  double tau1_n_m = 0.0;  ///< left motor (motor 1)
  double tau2_n_m = 0.0;  ///< right motor (motor 2)
};

/// Positions of the two elbows for given joint angles, workspace frame [m].
struct Elbows {
  Vec2 elbow1_m;  ///< end of the left proximal link
  Vec2 elbow2_m;  ///< end of the right proximal link
};

/// Determinant a11·a22 − a12·a21.
constexpr double det(const Mat2& m) { return m.a11 * m.a22 - m.a12 * m.a21; }
/// Matrix-vector product m·v.
constexpr Vec2 mul(const Mat2& m, Vec2 v) { return {m.a11 * v.x + m.a12 * v.y, m.a21 * v.x + m.a22 * v.y}; }
/// Transpose.
constexpr Mat2 transpose(const Mat2& m) { return {m.a11, m.a21, m.a12, m.a22}; }

/// Axis of the left motor, base − (half_spacing, 0) [m].
constexpr Vec2 motor1_position(const PantographGeometry& g) {
  return {g.base_m.x - g.motor_half_spacing_m, g.base_m.y};
}
/// Axis of the right motor, base + (half_spacing, 0) [m].
constexpr Vec2 motor2_position(const PantographGeometry& g) {
  return {g.base_m.x + g.motor_half_spacing_m, g.base_m.y};
}

/// Elbow positions e_i = m_i + L1·(cos θi, sin θi) [m]. Always defined.
Elbows elbow_positions(const PantographGeometry& g, JointAngles q) noexcept;

/// Forward kinematics: handle position [m] for joint angles [rad], on the "handle below" branch
/// (the handle lies to the right of elbow1 → elbow2).
/// Returns false, leaving *handle_m untouched, when the two distal circles (radius L2 around each
/// elbow) do not meet (elbows farther apart than 2·L2), when the elbows coincide (the handle is then
/// undetermined), or when an input is not finite. `handle_m` must not be null.
bool forward_kinematics(const PantographGeometry& g, JointAngles q, Vec2* handle_m) noexcept;

/// Inverse kinematics: joint angles [rad] that put the handle at `handle_m` [m], on the
/// "elbows outward" branch. θ1 is returned in [0, 2π), θ2 in [−π, π).
/// Returns false, leaving *out untouched, when the handle is outside either chain's annulus
/// |L1 − L2| ≤ |handle − motor_i| ≤ L1 + L2, or an input is not finite. `out` must not be null.
bool inverse_kinematics(const PantographGeometry& g, Vec2 handle_m, JointAngles* out) noexcept;

/// Analytic Jacobian J = ∂handle/∂θ [m/rad] at joint angles q (column j = ∂handle/∂θj).
/// From the loop constraints |handle − e_i|² = L2²: A·ẋ = B·θ̇ with rows A_i = (handle − e_i)ᵀ and
/// B = diag((handle − e_i)·∂e_i/∂θi), so J = A⁻¹B and det J = det B / det A.
/// Returns the zero matrix when forward kinematics fails or at a parallel singularity (distal links
/// collinear, det A ≈ 0, where J is unbounded); callers then get zero torque and zero force.
Mat2 jacobian(const PantographGeometry& g, JointAngles q) noexcept;

/// Motor torques that produce the handle force `force_n` [N]: τ = Jᵀ·F [N·m] (virtual work:
/// τ·δθ = F·δx with δx = J·δθ). J in m/rad as returned by `jacobian`.
Torques joint_torques(const Mat2& J, Vec2 force_n) noexcept;

/// Handle force [N] produced by motor torques τ [N·m]: F = J⁻ᵀ·τ, the inverse of `joint_torques`.
/// When J is singular or not finite (|det J| ≤ 1e-12·max|J_ij|², including the zero matrix returned
/// by `jacobian` on failure) there is no unique force: returns the zero vector.
Vec2 handle_force(const Mat2& J, Torques tau) noexcept;

/// The force a five-bar can give in every direction everywhere in a rectangle [N]: at each point of a
/// 21 × 21 grid over the rectangle (centre `rect_center_m`, size `rect_size_m`, frame of `g`) and each of
/// 72 directions u, the largest f with |(Jᵀ·f·u)_i| ≤ `torque_limit_n_m` for both motors; the minimum over
/// all. Above it a wall saturates somewhere: a force clamp beyond it cannot be felt everywhere.
/// 0 when some grid point is out of reach or an input is not finite or not positive.
double min_force_everywhere_n(const PantographGeometry& g, Vec2 rect_center_m, Vec2 rect_size_m,
                              double torque_limit_n_m) noexcept;

}  // namespace hk
