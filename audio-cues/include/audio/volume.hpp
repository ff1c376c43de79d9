#pragma once
/// @file volume.hpp
/// Master volume in steps a visitor can count: Volume up / down move one step, and
/// every new session starts again at the operator's default.

#include <atomic>

namespace hk::audio {

/// Stepped master volume. Step s ∈ [1, max_step] gives gain 10^(−(max_step − s)·step_db / 20), so the
/// top step is unity and each step is `step_db` quieter. The gain is read by the audio callback (atomic).
class Volume {
 public:
  /// @param default_step  operator's default, clamped to [1, max_step]
  /// @param max_step      number of steps [1, 30]; @param step_db  loudness change per step [dB] (0, 12]
  explicit Volume(int default_step = 7, int max_step = 10, double step_db = 3.0);

  /// One step louder. Returns false (and changes nothing) at the top step.
  bool up() noexcept;
  /// One step quieter. Returns false (and changes nothing) at step 1: never silent, a visitor who
  /// turned it all the way down must still hear the kiosk tell them so.
  bool down() noexcept;
  /// Back to the default step (a new session).
  void reset() noexcept;
  /// Changes the default (operator setting) and resets to it.
  void set_default(int step) noexcept;

  int step() const noexcept { return step_.load(std::memory_order_relaxed); }
  int default_step() const noexcept { return default_step_; }
  int max_step() const noexcept { return max_step_; }
  /// Linear gain of the current step (any thread; real-time safe).
  float gain() const noexcept { return gain_.load(std::memory_order_relaxed); }

 private:
  void set(int s) noexcept;
  int default_step_, max_step_;
  double step_db_;
  std::atomic<int> step_{0};
  std::atomic<float> gain_{1.0f};
};

}  // namespace hk::audio
