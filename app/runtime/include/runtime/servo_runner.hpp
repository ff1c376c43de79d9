#pragma once
/// @file servo_runner.hpp
/// The one servo loop of haptic-kiosk (DESIGN.md "Data flow", "Real-time rules", "Headless runs"): each tick
/// read the device, ServoStep::step, write the force. The kiosk's servo thread (servo_thread.hpp) runs it
/// on a DeadlineClock at the servo rate; every headless run (explore, the tests, the benchmarks:
/// simulation.hpp) runs the same loop on a HeadlessClock, tick after tick as fast as the machine goes. So
/// what the headless checks measure is what the visitor feels: the picture swaps and their fades, live
/// gains, the guided tour and a device's return all happen inside ServoStep::step.
///
/// The split follows ruckig / libfranka: the runner owns the clock, the device I/O and the loop; the step
/// maps a device sample to a force command and owns none of them. The clock says when a tick starts and
/// whether it is late; the runner's `after_tick` hook runs after each write (the simulated plant's physics,
/// the trace, timing statistics) and is the caller's.
///
/// Real-time: ServoRunner::tick and the clocks' next/done do not allocate, lock, log or throw, and
/// DeadlineClock::next sleeps only until the tick's deadline (clock_nanosleep TIMER_ABSTIME).

#include <atomic>
#include <cstdint>
#include <functional>

#include "haptics/device.hpp"
#include "haptics/servo.hpp"
#include "runtime/servo_step.hpp"

namespace hk::app {

/// CLOCK_MONOTONIC now [ns] (the clock every servo timing uses).
std::int64_t monotonic_ns() noexcept;

/// One tick as the runner ran it (the clock fills the timing, ServoRunner::tick the rest).
struct ServoTick {
  std::int64_t index = 0;    ///< ticks since the run began
  double t_s = 0.0;          ///< the tick's scheduled time since the run began: index · period [s]
  std::int64_t woke_ns = 0;  ///< monotonic_ns() when the tick started [ns]
  std::int64_t late_ns = 0;  ///< start minus the tick's deadline [ns] (0 on a HeadlessClock)
  std::int64_t step_ns = 0;  ///< time of ServoStep::step alone [ns]
  DeviceSample sample;       ///< what the device read
  ServoCommand command;      ///< the force written to the device [N]
  TickResult result = TickResult::Ok;
  bool deadline_missed = false;  ///< started a whole period late: the step sent zero force
  /// Motor torques the device was commanded this tick [N·m]: the simulated pantograph's (left, right motor),
  /// or the USB pantograph's (actuator 1, actuator 2) as sent in the torque packet. Filled by a headless run
  /// after the write (simulation.hpp); 0 where nothing fills them (the kiosk's servo thread).
  double motor_torque_n_m[2] = {0.0, 0.0};
};

/// When ticks start. next() waits for the next one (or returns false: the run is over); done() is told
/// when its work ended, so a real-time clock can skip deadlines already gone.
class ServoClock {
 public:
  virtual ~ServoClock() = default;
  /// Waits for the next tick and fills `t`'s index, t_s, woke_ns, late_ns and deadline_missed. False when
  /// the run is over (`t` untouched). Real-time.
  virtual bool next(ServoTick& t) noexcept = 0;
  /// The tick `t` ended at `done_ns` (monotonic_ns). Real-time.
  virtual void done(const ServoTick& t, std::int64_t done_ns) noexcept = 0;
};

/// Real time: ticks at absolute deadlines period_ns apart on CLOCK_MONOTONIC (clock_nanosleep
/// TIMER_ABSTIME: lateness does not accumulate), until `stop` is set. A tick that starts a whole period
/// late is a missed deadline (the step sends zero force) and the schedule skips ahead to the next deadline
/// in the future instead of bursting ticks to catch up.
class DeadlineClock final : public ServoClock {
 public:
  /// `period_ns` > 0 [ns]; `stop` outlives the clock. The first deadline is one period from now.
  DeadlineClock(std::int64_t period_ns, const std::atomic<bool>& stop) noexcept;
  bool next(ServoTick& t) noexcept override;
  void done(const ServoTick& t, std::int64_t done_ns) noexcept override;

 private:
  std::int64_t period_ns_;
  const std::atomic<bool>& stop_;
  std::int64_t start_ns_ = 0, deadline_ns_ = 0, index_ = 0;
};

/// Headless: `ticks` ticks back to back, tick k at t = k · period_s; never late, never waits.
class HeadlessClock final : public ServoClock {
 public:
  /// `ticks` ≥ 0, `period_s` > 0 [s].
  HeadlessClock(std::int64_t ticks, double period_s) noexcept : ticks_(ticks), period_s_(period_s) {}
  bool next(ServoTick& t) noexcept override;
  void done(const ServoTick&, std::int64_t) noexcept override {}

 private:
  std::int64_t ticks_, index_ = 0;
  double period_s_;
};

/// The servo loop: read, step, write, at the clock's times.
class ServoRunner {
 public:
  /// Called after each tick's write with the tick: the simulated plant's physics, a trace, statistics, or
  /// the owner's scripted calls in a headless run. On the servo thread of the kiosk it must be real-time safe.
  using AfterTick = std::function<void(ServoTick& tick)>;

  /// `core` and `device` (open) outlive the runner.
  ServoRunner(ServoStep& core, Device& device) noexcept : core_(core), device_(device) {}

  /// Real-time: one tick: the device's sample, ServoStep::step (timed into t.step_ns), the command's force
  /// written to the device. `t` carries the clock's fields in (deadline_missed) and the tick's out.
  void tick(ServoTick& t) noexcept;

  /// Runs ticks at `clock`'s times until it says the run is over, calling `after_tick` (may be empty)
  /// after each. Returns the ticks run.
  std::int64_t run(ServoClock& clock, const AfterTick& after_tick);

  ServoStep& core() noexcept { return core_; }
  Device& device() noexcept { return device_; }

 private:
  ServoStep& core_;
  Device& device_;
};

}  // namespace hk::app
