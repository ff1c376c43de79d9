#include "runtime/servo_runner.hpp"

#include <time.h>

#include <cerrno>

namespace hk::app {
namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

timespec to_timespec(std::int64_t ns) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(ns / kNsPerS);
  ts.tv_nsec = static_cast<long>(ns % kNsPerS);
  return ts;
}

}  // namespace

std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + ts.tv_nsec;
}

DeadlineClock::DeadlineClock(std::int64_t period_ns, const std::atomic<bool>& stop) noexcept
    : period_ns_(period_ns), stop_(stop), start_ns_(monotonic_ns()), deadline_ns_(start_ns_ + period_ns) {}

bool DeadlineClock::next(ServoTick& t) noexcept {
  if (stop_.load(std::memory_order_relaxed)) return false;
  const timespec ts = to_timespec(deadline_ns_);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
  t.woke_ns = monotonic_ns();
  t.late_ns = t.woke_ns - deadline_ns_;
  t.deadline_missed = t.late_ns >= period_ns_;
  t.index = index_++;
  t.t_s = static_cast<double>(deadline_ns_ - start_ns_ - period_ns_) / static_cast<double>(kNsPerS);
  return true;
}

void DeadlineClock::done(const ServoTick& t, std::int64_t done_ns) noexcept {
  // Skip ahead to the next deadline in the future rather than bursting ticks to catch up.
  if (t.deadline_missed) deadline_ns_ += ((done_ns - deadline_ns_) / period_ns_) * period_ns_;
  deadline_ns_ += period_ns_;
}

bool HeadlessClock::next(ServoTick& t) noexcept {
  if (index_ >= ticks_) return false;
  t.index = index_;
  t.t_s = static_cast<double>(index_) * period_s_;
  t.woke_ns = monotonic_ns();
  t.late_ns = 0;
  t.deadline_missed = false;
  ++index_;
  return true;
}

void ServoRunner::tick(ServoTick& t) noexcept {
  t.sample = device_.read();
  const std::int64_t t0 = monotonic_ns();
  t.result = core_.step(t.sample, t.deadline_missed, t.command);
  t.step_ns = monotonic_ns() - t0;
  device_.write_force(t.command.force_n);
}

std::int64_t ServoRunner::run(ServoClock& clock, const AfterTick& after_tick) {
  ServoTick t;
  std::int64_t n = 0;
  while (clock.next(t)) {
    tick(t);
    if (after_tick) after_tick(t);
    clock.done(t, monotonic_ns());
    ++n;
  }
  return n;
}

}  // namespace hk::app
