#pragma once
/// @file haply_mechanism.hpp
/// The Haply 2DIY five-bar (gen3) expressed in OUR frames (pantograph.hpp), and the maps between
/// Haply's joint angles/torques and ours.
///
/// Source of the dimensions and of Haply's frame: HaplyHaptics/Haply-API-Java, Pantograph.java,
/// `Pantograph(hardwareVersion)` with hardwareVersion 3 (l = 0.07 m, L = 0.09 m, d = 0.038 m) and its
/// `forwardKinematics` (motor 1 at (0, 0), motor 2 at (d, 0), elbows at motor + l·(cos θ, sin θ), the
/// handle at the intersection of the distal circles with +y_h, i.e. to the left of elbow1 → elbow2).
///
/// Our device frame: x to the user's right, y away from the user, origin midway between the motor
/// axes, the handle at y < 0. It is Haply's frame rotated by π about the mid-point of the motors:
///   x_ours = d/2 − x_h,   y_ours = −y_h.
/// So Haply motor 1 (θ_h1) is OUR RIGHT motor (JointAngles::theta2_rad) and Haply motor 2 is our LEFT
/// motor (theta1_rad), with θ_ours = θ_h + π (a rotation keeps the sense of rotation); a positive Haply
/// torque is a positive torque of ours on the same motor (τ = Jᵀ·F holds in both frames).

#include "hk/vec2.hpp"
#include "kinematics/pantograph.hpp"

namespace hk::hapi {

/// Link lengths of the Haply five-bar [m] (Pantograph.java, hardwareVersion 3).
struct HaplyMechanism {
  double proximal_m = 0.07;        ///< motor-to-elbow link, Haply's l [m]
  double distal_m = 0.09;          ///< elbow-to-handle link, Haply's L [m]
  double motor_spacing_m = 0.038;  ///< distance between the motor axes, Haply's d [m]
};

/// Our PantographGeometry of the mechanism in the device frame: motor_half_spacing = d/2,
/// base = (0, 0), proximal = l, distal = L.
PantographGeometry geometry_of(const HaplyMechanism& m) noexcept;

/// Our joint angles [rad] for Haply's angles θ_h1, θ_h2 [deg] (as the encoders report them):
/// theta2 (right motor) = θ_h1 + π wrapped to [−π, π); theta1 (left motor) = θ_h2 + π wrapped to [0, 2π).
/// Non-finite inputs give non-finite outputs.
JointAngles joints_from_haply_deg(double th1_deg, double th2_deg) noexcept;

/// Haply's angles [deg] of our joint angles: θ_h1 = theta2 − π wrapped to [0, 360) (motor 1 points to
/// −x_h, near 180°), θ_h2 = theta1 − π wrapped to [−180, 180) (motor 2 points to +x_h, near 0°).
/// Both pointers must be non-null.
void haply_deg_from_joints(JointAngles q, double* th1_deg, double* th2_deg) noexcept;

/// Haply torques [N·m] of our torques: τ_h1 = tau2 (right motor), τ_h2 = tau1 (left motor).
/// Both pointers must be non-null.
void haply_torques_from(Torques ours, double* tau_h1, double* tau_h2) noexcept;

/// Our torques [N·m] of Haply's: tau1 (left) = τ_h2, tau2 (right) = τ_h1.
Torques torques_from_haply(double tau_h1, double tau_h2) noexcept;

/// A point of Haply's frame [m] in our device frame: (d/2 − x_h, −y_h).
Vec2 device_from_haply_m(const HaplyMechanism& m, Vec2 haply_m) noexcept;

/// A point of our device frame [m] in Haply's frame: (d/2 − x, −y).
Vec2 haply_from_device_m(const HaplyMechanism& m, Vec2 device_m) noexcept;

}  // namespace hk::hapi
