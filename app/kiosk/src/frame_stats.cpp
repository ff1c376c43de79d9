#include "kiosk/frame_stats.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "formats/app_error.hpp"

namespace hk::app {
namespace {

double ms_between(FrameStats::Clock::time_point a, FrameStats::Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

/// `ms` to the microsecond, for the file.
double to_us(double ms) { return std::round(ms * 1000.0) / 1000.0; }

nlohmann::json summary_json(const FrameTimeSummary& s) {
  return {{"frames", s.frames},        {"p50_ms", to_us(s.p50_ms)}, {"p95_ms", to_us(s.p95_ms)},
          {"p99_ms", to_us(s.p99_ms)}, {"max_ms", to_us(s.max_ms)}, {"mean_ms", to_us(s.mean_ms)},
          {"over_20_ms", s.over_20_ms}};
}

}  // namespace

void FrameTimeHistogram::add_ms(double ms) {
  if (!(ms > 0)) ms = 0;  // also NaN
  const int bin = std::min(kBins - 1, static_cast<int>(ms / kBinMs));
  ++bins_[static_cast<std::size_t>(bin)];
  ++n_;
  if (ms > kSlowFrameMs) ++over_;
  max_ms_ = std::max(max_ms_, ms);
  sum_ms_ += ms;
}

double FrameTimeHistogram::percentile_ms(double p) const {
  if (n_ == 0) return 0;
  p = std::clamp(p, 0.0, 100.0);
  const auto rank =
      std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(p / 100.0 * static_cast<double>(n_) - 1e-9)));
  std::int64_t seen = 0;
  for (int b = 0; b < kBins; ++b) {
    seen += bins_[static_cast<std::size_t>(b)];
    if (seen >= rank) return b == kBins - 1 ? max_ms_ : std::min((b + 1) * kBinMs, max_ms_);
  }
  return max_ms_;
}

FrameTimeSummary FrameTimeHistogram::summary() const {
  FrameTimeSummary s;
  s.frames = n_;
  s.p50_ms = percentile_ms(50);
  s.p95_ms = percentile_ms(95);
  s.p99_ms = percentile_ms(99);
  s.max_ms = max_ms_;
  s.mean_ms = n_ ? sum_ms_ / static_cast<double>(n_) : 0;
  s.over_20_ms = over_;
  return s;
}

void FrameStats::frame_started(Clock::time_point t) {
  if (started_) {
    const double ms = ms_between(start_, t);
    interval_all_.add_ms(ms);
    if (this_changing_) interval_changing_.add_ms(ms);
  }
  started_ = true;
  start_ = t;
  this_changing_ = pending_;
}

void FrameStats::picture_key(const void* scene_at_start, int id_at_start) {
  this_changing_ = true;
  if (pending_) return;  // a second key before the first change was shown: one change, from the first key
  pending_ = true;
  pending_scene_ = scene_at_start;
  pending_id_ = id_at_start;
  pending_since_ = start_;
}

void FrameStats::frame_drawn(Clock::time_point t, const void* scene, int id) {
  const double ms = ms_between(start_, t);
  work_all_.add_ms(ms);
  if (this_changing_) work_changing_.add_ms(ms);
  if (!pending_) return;
  const double since_key_ms = ms_between(pending_since_, t);
  if (scene != pending_scene_ || id != pending_id_) {
    pending_ = false;
    ++changes_;
    max_change_ms_ = std::max(max_change_ms_, since_key_ms);
  } else if (since_key_ms > kMaxChangeS * 1000.0) {
    pending_ = false;
  }
}

nlohmann::json FrameStats::to_json(const std::string& measured) const {
  return {{"measured", measured},
          {"slow_frame_ms", kSlowFrameMs},
          {"bin_ms", FrameTimeHistogram::kBinMs},
          {"interval",
           {{"all", summary_json(interval_all_.summary())}, {"changing", summary_json(interval_changing_.summary())}}},
          {"work", {{"all", summary_json(work_all_.summary())}, {"changing", summary_json(work_changing_.summary())}}},
          {"changes", changes_},
          {"max_change_ms", to_us(max_change_ms_)}};
}

std::string FrameStats::log_line() const {
  const FrameTimeSummary a = interval_all_.summary(), c = interval_changing_.summary();
  const FrameTimeSummary w = work_all_.summary(), wc = work_changing_.summary();
  return fmt::format(
      "frame stats: {} frames, interval p50 {:.1f} p95 {:.1f} p99 {:.1f} max {:.1f} ms, {} over {:.0f} ms; "
      "while pictures changed ({} changes): {} frames, interval p99 {:.1f} max {:.1f} ms, {} over; "
      "work p99 {:.1f} ms (changing {:.1f} ms)",
      a.frames, a.p50_ms, a.p95_ms, a.p99_ms, a.max_ms, a.over_20_ms, kSlowFrameMs, changes_, c.frames, c.p99_ms,
      c.max_ms, c.over_20_ms, w.p99_ms, wc.p99_ms);
}

void write_frame_stats(const FrameStats& stats, const std::string& path, const std::string& measured) {
  std::ofstream f(path);
  f << stats.to_json(measured).dump(2) << "\n";
  f.close();
  if (!f) throw AppError("--frame-stats '" + path + "': cannot write the file");
}

}  // namespace hk::app
