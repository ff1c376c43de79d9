#pragma once
/// @file sim_pantograph.hpp
/// The simulated pantograph (DESIGN.md "Devices"): the default device when no hardware is attached,
/// and the device of every headless run. Five-bar kinematics (pantograph.hpp), encoder quantisation,
/// per-motor torque limits, handle mass and viscous damping, mechanical stops; driven by a model hand
/// (`model_hand_force`, pulled along a HandPath, hand_path.hpp).
///
/// Physics simplification: the handle is a single point mass in Cartesian space with viscous damping.
/// The inertia of the four links and the motor rotors is folded into that one effective mass
/// (`handle_mass_kg`), taken as constant and isotropic; the true configuration-dependent mass matrix
/// Jᵀ⁻¹·M(θ)·J⁻¹ and the Coriolis terms are ignored. At hand speeds (< 0.3 m/s) and with the
/// lightweight links of a kiosk pantograph these terms are small next to the hand and wall forces,
/// and the servo loop under test only sees positions and forces, which this model reproduces with
/// the effects that matter to it: quantised position, saturated torque, mass, damping and stops.
///
/// This header does not depend on config/: the app maps config::DeviceSettings onto
/// SimPantographParams and config::HandSettings onto ModelHandParams (the defaults are the same).

#include <cstdint>
#include <string>

#include "haptics/device.hpp"
#include "hk/vec2.hpp"
#include "kinematics/pantograph.hpp"

namespace hk {

/// Physical parameters of the simulated pantograph. Defaults = config::DeviceSettings defaults.
struct SimPantographParams {
  PantographGeometry geometry;            ///< link lengths and motor placement [m]
  double handle_mass_kg = 0.08;           ///< effective handle mass, link inertia folded in [kg], > 0
  double handle_damping_n_s_per_m = 2.0;  ///< viscous damping of the mechanism [N·s/m], ≥ 0
  int encoder_counts_per_rev = 16384;     ///< encoder resolution per motor [counts/rev], ≥ 1
  double max_torque_n_m = 0.5;            ///< per-motor torque limit [N·m], ≥ 0
  int substeps = 8;                       ///< integration substeps per `step`, in [1, 100000]
  /// Half the usable rectangle [m] (config::WorkspaceSettings width/2, height/2).
  Vec2 workspace_half_extent_m{0.07, 0.045};
  /// The mechanical stops sit this far outside the usable rectangle [m], ≥ 0.
  double stop_margin_m = 0.01;
};

/// The simulated five-bar device. Owns its whole state; time only advances through `step`.
///
/// Real-time contract (device.hpp): `read`, `write_force`, `status`, `step` and the accessors do not
/// allocate, lock, block or throw. The constructor validates the parameters and may throw.
class SimulatedPantograph final : public Device {
 public:
  /// Builds the device at rest with the handle at `start_handle_m` [m] (clamped into the stop box),
  /// status Closed, zero commanded force, time 0.
  /// Throws hk::ArgumentError (one line) when a parameter is out of range or not finite, or when
  /// some point of the stop box (the usable rectangle enlarged by stop_margin_m) is not reachable by
  /// the linkage on its working branch (a sampled check on a 41 × 41 grid).
  SimulatedPantograph(const SimPantographParams& params, Vec2 start_handle_m);

  /// Starts "streaming": status Ok, motors enabled. Never fails for the simulation.
  void open() override;
  /// Handle position as the encoders report it: IK of the true position, each joint angle rounded to
  /// the nearest multiple of 2π/encoder_counts_per_rev, then FK [m]. time_ns = simulated time [ns].
  /// Works in any status (the encoders are passive); `status` tells the servo loop whether to trust it.
  DeviceSample read() noexcept override;
  /// Commands a handle force [N], held until the next call. A non-finite force is stored as zero.
  /// Torque saturation is applied in `step` at the configuration of that moment.
  void write_force(Vec2 force_n) noexcept override;
  /// Disables the motors (commanded force zeroed) and sets status Closed.
  void close() noexcept override;
  /// Closed before `open` and after `close`, Ok in between.
  DeviceStatus status() const noexcept override;
  /// "simulated pantograph".
  std::string name() const override;

  /// Advances the simulation by one servo period dt_s [s] under the hand force `hand_force_n` [N]
  /// (held over the period). The motor force is computed once at the start of the period (the driver
  /// computes torques from the configuration at write time and holds them for the period):
  /// τ = Jᵀ·F_cmd, each τ_i clamped to ±max_torque_n_m, F_motor = J⁻ᵀ·τ; zero unless status is Ok.
  /// Then `substeps` semi-implicit Euler substeps of m·v̇ = F_hand + F_motor − b·v (damping taken
  /// implicitly, so any b/m is stable), each followed by the mechanical stops: the position is clamped
  /// into the stop box and the velocity component into a stop is zeroed. A non-finite hand force
  /// counts as zero; dt_s ≤ 0 or non-finite does nothing. Simulated time advances by round(dt_s·1e9) ns.
  void step(double dt_s, Vec2 hand_force_n) noexcept;

  /// True (unquantised) handle position [m].
  Vec2 true_position_m() const noexcept { return position_m_; }
  /// Handle velocity [m/s].
  Vec2 velocity_m_per_s() const noexcept { return velocity_m_per_s_; }
  /// Motor force applied during the last `step`, after torque limits [N] (zero before the first step).
  Vec2 applied_force_n() const noexcept { return applied_force_n_; }
  /// Motor torques applied during the last `step`, after clamping [N·m].
  Torques applied_torques_n_m() const noexcept { return applied_torques_n_m_; }
  /// The force last passed to `write_force` (zero when it was not finite) [N].
  Vec2 commanded_force_n() const noexcept { return commanded_force_n_; }
  /// Simulated time [ns].
  std::int64_t time_ns() const noexcept { return time_ns_; }
  /// The parameters the device was built with.
  const SimPantographParams& params() const noexcept { return params_; }
  /// Lower-left corner of the stop box [m].
  Vec2 stop_min_m() const noexcept { return stop_min_m_; }
  /// Upper-right corner of the stop box [m].
  Vec2 stop_max_m() const noexcept { return stop_max_m_; }

 private:
  /// Clamps the position into the stop box and removes the velocity component into a stop.
  void apply_stops() noexcept;

  SimPantographParams params_;
  Vec2 stop_min_m_;
  Vec2 stop_max_m_;
  double encoder_step_rad_ = 0.0;
  Vec2 position_m_;
  Vec2 velocity_m_per_s_;
  Vec2 commanded_force_n_;
  Vec2 applied_force_n_;
  Torques applied_torques_n_m_;
  std::int64_t time_ns_ = 0;
  DeviceStatus status_ = DeviceStatus::Closed;
};

/// The model hand: a spring-damper that pulls the handle towards a target (a visitor's hand that
/// follows a path). Defaults = config::HandSettings defaults.
struct ModelHandParams {
  double stiffness_n_per_m = 200.0;  ///< spring from handle to target [N/m]
  double damping_n_s_per_m = 4.0;    ///< damping on the handle velocity [N·s/m]
  double max_force_n = 2.0;          ///< the most a visitor pushes with [N]
};

/// Force the model hand puts on the handle [N]: F = k·(target − handle) − b·v, with |F| clamped to
/// max_force_n (direction kept). The clamp is what lets a wall stop the hand: at the 800 N/m default
/// wall stiffness, 2 N of push is balanced after 2.5 mm of penetration, however far the target has
/// run ahead. Returns zero when any input is not finite. Real-time safe.
Vec2 model_hand_force(const ModelHandParams& p, Vec2 target_m, Vec2 handle_m, Vec2 handle_velocity_m_per_s) noexcept;

}  // namespace hk
