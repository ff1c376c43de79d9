#include "runtime/servo_thread.hpp"

#include <pthread.h>
#include <sched.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <string>

#include "hk/error.hpp"

namespace hk::app {
namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

double percentile_us(const std::array<std::atomic<std::uint32_t>, 2048>& h, double q) {
  std::uint64_t total = 0;
  for (const auto& b : h) total += b.load(std::memory_order_relaxed);
  if (total == 0) return 0;
  const auto want = static_cast<std::uint64_t>(q * static_cast<double>(total - 1)) + 1;
  std::uint64_t seen = 0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    seen += h[i].load(std::memory_order_relaxed);
    if (seen >= want) return static_cast<double>(i);
  }
  return static_cast<double>(h.size() - 1);
}

}  // namespace

ServoThread::ServoThread(ServoStep& core, Device& device, const ServoThreadParams& params, PlantStep plant_step)
    : core_(core), device_(device), params_(params), plant_step_(std::move(plant_step)) {
  if (!(params.rate_hz >= 100 && params.rate_hz <= 10000)) {
    throw hk::ArgumentError("servo rate " + std::to_string(params.rate_hz) + " Hz is outside [100, 10000] Hz");
  }
  thread_ = std::thread([this] { run(); });
}

ServoThread::~ServoThread() { stop(); }

void ServoThread::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void ServoThread::run() {
  if (params_.realtime) ask_for_fifo();
  const auto period_ns = static_cast<std::int64_t>(static_cast<double>(kNsPerS) / params_.rate_hz + 0.5);
  const double period_s = static_cast<double>(period_ns) / static_cast<double>(kNsPerS);
  DeadlineClock clock(period_ns, stop_);
  ServoRunner runner(core_, device_);
  runner.run(clock, [this, period_s](ServoTick& t) {
    if (plant_step_) plant_step_(period_s);
    record(t, monotonic_ns() - t.woke_ns);
  });
}

void ServoThread::ask_for_fifo() {
  sched_param sp{};
  sp.sched_priority = params_.fifo_priority;
  const int err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  if (err == 0) {
    realtime_.store(true);
    spdlog::info("servo: SCHED_FIFO priority {} at {} Hz", params_.fifo_priority, params_.rate_hz);
  } else {
    spdlog::warn(
        "servo: SCHED_FIFO refused ({}); running at normal priority at {} Hz (grant CAP_SYS_NICE or an rtprio limit)",
        std::strerror(err), params_.rate_hz);
  }
}

void ServoThread::record(const ServoTick& t, std::int64_t work_ns) noexcept {
  ServoDisplayState& d = core_.display_back();
  d.tick_compute_ns = work_ns;
  d.period_error_ns = t.late_ns;
  d.missed_deadlines = missed_.load(std::memory_order_relaxed) + (t.deadline_missed ? 1 : 0);
  core_.publish_display();

  late_[static_cast<std::size_t>(std::clamp<std::int64_t>(t.late_ns / 1000, 0, kBins - 1))].fetch_add(
      1, std::memory_order_relaxed);
  compute_[static_cast<std::size_t>(std::clamp<std::int64_t>(work_ns / 1000, 0, kBins - 1))].fetch_add(
      1, std::memory_order_relaxed);
  if (t.late_ns > max_late_ns_.load(std::memory_order_relaxed))
    max_late_ns_.store(t.late_ns, std::memory_order_relaxed);
  if (t.late_ns > total_max_late_ns_.load(std::memory_order_relaxed))
    total_max_late_ns_.store(t.late_ns, std::memory_order_relaxed);
  ticks_.fetch_add(1, std::memory_order_relaxed);
  total_ticks_.fetch_add(1, std::memory_order_relaxed);
  if (t.deadline_missed) {
    missed_.fetch_add(1, std::memory_order_relaxed);
    total_missed_.fetch_add(1, std::memory_order_relaxed);
  }
}

ServoTimingStats ServoThread::stats() const {
  ServoTimingStats s;
  s.ticks = ticks_.load();
  s.missed_deadlines = missed_.load();
  s.lateness_p50_us = percentile_us(late_, 0.5);
  s.lateness_p99_us = percentile_us(late_, 0.99);
  s.lateness_max_us = static_cast<double>(max_late_ns_.load()) / 1000.0;
  s.compute_p50_us = percentile_us(compute_, 0.5);
  s.compute_p99_us = percentile_us(compute_, 0.99);
  return s;
}

ServoThread::Totals ServoThread::totals() const {
  Totals t;
  t.ticks = total_ticks_.load();
  t.missed_deadlines = total_missed_.load();
  t.lateness_max_us = static_cast<double>(total_max_late_ns_.load()) / 1000.0;
  return t;
}

ServoTimingStats ServoThread::take_stats() {
  const ServoTimingStats s = stats();
  for (auto& b : late_) b.store(0, std::memory_order_relaxed);
  for (auto& b : compute_) b.store(0, std::memory_order_relaxed);
  ticks_.store(0);
  missed_.store(0);
  max_late_ns_.store(0);
  return s;
}

}  // namespace hk::app
