#pragma once
/// @file servo_thread.hpp
/// The kiosk's servo thread: the servo loop (ServoRunner: read the device, ServoStep::step, write the force)
/// on its own thread at the configured rate on a DeadlineClock (absolute deadlines; a tick a whole period
/// late is a missed deadline, sent zero force, and the schedule skips ahead), SCHED_FIFO where the system
/// permits it (a logged warning where not), with histograms of wake-up lateness and tick work for the
/// operator's panel and the soak's accounting.

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <thread>

#include "runtime/servo_runner.hpp"
#include "runtime/servo_step.hpp"

namespace hk::app {

/// Servo thread settings. Units in names.
struct ServoThreadParams {
  double rate_hz = 1000.0;  ///< servo rate [Hz], [100, 10000]
  bool realtime = true;     ///< ask for SCHED_FIFO
  int fifo_priority = 80;   ///< SCHED_FIFO priority [1, 99]
};

/// Wake-up lateness and deadlines so far.
struct ServoTimingStats {
  std::int64_t ticks = 0;
  std::int64_t missed_deadlines = 0;
  double lateness_p50_us = 0, lateness_p99_us = 0, lateness_max_us = 0;  ///< wake-up minus deadline [µs]
  double compute_p50_us = 0, compute_p99_us = 0;                         ///< tick work [µs]
};

/// Runs a ServoStep on its own thread. Start and stop from one (non-real-time) thread.
class ServoThread {
 public:
  /// The plant's step, called in the servo thread after each tick with the period [s] (e.g. the simulated pantograph's
  /// physics). Must be real-time safe.
  using PlantStep = std::function<void(double period_s)>;

  /// Starts the thread, which reads `device` and writes its force each tick. `core` and `device` (open)
  /// must outlive the thread. @throws hk::ArgumentError for a rate outside [100, 10000] Hz.
  ServoThread(ServoStep& core, Device& device, const ServoThreadParams& params, PlantStep plant_step = {});
  /// Stops and joins.
  ~ServoThread();
  ServoThread(const ServoThread&) = delete;
  ServoThread& operator=(const ServoThread&) = delete;

  void stop();
  /// True if SCHED_FIFO was granted.
  bool realtime() const { return realtime_.load(); }
  /// Timing so far (reads the servo thread's histograms; any thread).
  ServoTimingStats stats() const;
  /// Timing since the last call (or the start), then starts counting afresh: one report per visitor's
  /// session. Counts racing with the servo thread's increments may be off by a tick.
  ServoTimingStats take_stats();
  /// Since the thread started, never reset by take_stats() (a soak's accounting while the kiosk takes its
  /// per-visitor reports): ticks, missed deadlines, and the worst lateness [µs].
  struct Totals {
    std::int64_t ticks = 0;
    std::int64_t missed_deadlines = 0;
    double lateness_max_us = 0;
  };
  Totals totals() const;

 private:
  void run();
  void ask_for_fifo();
  /// Real-time: the tick's timing into the display state (published) and the histograms.
  void record(const ServoTick& t, std::int64_t work_ns) noexcept;
  static constexpr int kBins = 2048;  // 1 µs bins up to 2 ms; the last bin holds everything later
  ServoStep& core_;
  Device& device_;
  ServoThreadParams params_;
  PlantStep plant_step_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> realtime_{false};
  std::atomic<std::int64_t> ticks_{0}, missed_{0}, max_late_ns_{0};
  std::atomic<std::int64_t> total_ticks_{0}, total_missed_{0}, total_max_late_ns_{0};  // never reset
  std::array<std::atomic<std::uint32_t>, kBins> late_{}, compute_{};
  std::thread thread_;
};

}  // namespace hk::app
