#pragma once
/// @file servo.hpp
/// The servo tick (DESIGN.md "Data flow", "Real-time rules"): device sample → collision query and
/// contact solver at the level in use → force guard → force command, plus haptic events.
/// The tick is `update(input, output) -> TickResult`: a function of (state, sample, scene), with no
/// allocation, lock, throw, I/O or logging. Status enums here; exceptions only at setup.

#include <cstdint>

#include "haptics/contact.hpp"
#include "haptics/device.hpp"
#include "haptics/scene.hpp"

namespace hk {

/// Why a tick's force was zeroed or limited. `Ok` means the solver's force went out (maybe ramped).
enum class TickResult : std::uint8_t {
  Ok,
  DeviceNotOk,     ///< the device reported Lost/Fault/Closed: zero force
  NonFinite,       ///< the sample or the force was NaN/inf: zero force, state kept
  DeadlineMissed,  ///< the caller said this tick is late: zero force
};

/// The one gate every force passes (DESIGN.md "Real-time rules"): finite, clamped, ramped in at
/// start-up, zero on a missed deadline or a device that is not Ok.
struct ForceGuard {
  double max_force_n = 4.0;  ///< clamp on |F| [N]
  double ramp_s = 0.5;       ///< time for the clamp to grow linearly from 0 to max_force_n after start [s]

  /// Returns the force to send. `since_start_s` is the time since the loop (or a new scene) started.
  Vec2 apply(Vec2 force_n, double since_start_s, DeviceStatus status, bool deadline_missed, TickResult* why) const;
};

/// Parameters of the servo loop.
struct ServoParams {
  double period_s = 0.001;          ///< servo period = 1 / servo rate [s]
  int level = 1;                    ///< resolution level rendered
  double query_deadline_s = 200e-6; ///< anytime budget of one tick's collision work [s]; 0 = none
  double velocity_cutoff_hz = 100;  ///< low-pass on the finite-difference handle velocity [Hz]
  ContactParams contact;
  ForceGuard guard;
};

/// Input of one tick.
struct ServoInput {
  DeviceSample sample;         ///< handle position [m] and status
  std::int64_t now_ns = 0;     ///< steady-clock time at the start of the tick [ns] (for the deadline)
  bool deadline_missed = false;
};

/// Output of one tick.
struct ServoOutput {
  Vec2 force_n;                ///< force to write to the device [N] (after the guard)
  Vec2 handle_velocity_m_per_s;
  ContactOutput contact;       ///< proxy, state, constraints, events, query stats
  TickResult result = TickResult::Ok;
};

/// The haptic servo loop state for one scene. Construct at setup; call update() once per tick.
class ServoLoop {
 public:
  /// `scene` must outlive the loop. Allocates (setup only).
  ServoLoop(const Scene& scene, const ServoParams& params);
  /// Starts (or restarts) at the handle position: proxy placed there, force ramp from zero.
  void start(Vec2 handle_m);
  /// One servo tick. Real-time safe.
  TickResult update(const ServoInput& in, ServoOutput& out);
  const ServoParams& params() const { return params_; }
  /// Changes the rendered level (takes effect next tick).
  void set_level(int level) { params_.level = level; }
  std::int64_t ticks() const { return ticks_; }
  /// The contact solver (its proxy and boundary section), for display snapshots taken in the servo thread.
  const ContactSolver& solver() const { return solver_; }

 private:
  const Scene* scene_;
  ServoParams params_;
  ContactSolver solver_;
  Vec2 last_handle_;
  Vec2 velocity_;
  std::int64_t ticks_ = 0;
};

}  // namespace hk
