#pragma once
/// @file wait_until.hpp
/// Waiting in a test for another thread's work: on a condition, with a wall-clock deadline that only bounds
/// a hang (the outcome is the condition, never how long it took or how many polls it needed).

#include <chrono>
#include <thread>

namespace hk::test {

/// Calls `step()` then checks `done()`, again every `pause`, until `done()` holds or `timeout_s` [s] of
/// steady-clock time have passed. Returns whether it held.
template <class Done, class Step>
bool wait_until(Done&& done, Step&& step, double timeout_s = 60.0,
                std::chrono::milliseconds pause = std::chrono::milliseconds(10)) {
  const auto deadline =
      std::chrono::steady_clock::now() +
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(timeout_s));
  for (;;) {
    step();
    if (done()) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(pause);
  }
}

/// wait_until without a step: `done()` alone is polled.
template <class Done>
bool wait_until(Done&& done, double timeout_s = 60.0) {
  return wait_until(
      done, [] {}, timeout_s);
}

}  // namespace hk::test
