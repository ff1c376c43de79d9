// The kiosk's metrics (metrics.hpp).
#include "runtime/metrics.hpp"

#include <fmt/format.h>

#include <cmath>
#include <iterator>

namespace hk::app {
namespace {

constexpr std::array<const char*, kKioskCountCount> kCountNames{
    "visits_started_total", "visits_finished_total", "pictures_explored_total",
    "sticks_read_total",    "copies_made_total",     "settings_applied_total",
};
constexpr std::array<const char*, kKioskCountCount> kCountHelp{
    "Visitors who woke the kiosk.",
    "Visits ended by Finish or the time-out.",
    "Pictures, stick pages and captures put under a visitor's hand.",
    "USB sticks read.",
    "Take-home copies printed or saved on a stick.",
    "Settings applied at the operator's panel.",
};
constexpr std::array<const char*, kKioskErrorCount> kErrorKinds{
    "device_lost",        "stick_refused",   "copy_failed",    "settings_refused",
    "picture_unreadable", "library_refused", "visitor_action",
};
constexpr std::array<const char*, kKioskTimingCount> kTimingNames{"scene_build_seconds", "ocr_seconds"};
constexpr std::array<const char*, kKioskTimingCount> kTimingHelp{
    "Scene builds of the library's pictures (asked for or built ahead, and rebuilt after Apply), in seconds.",
    "Readings of a picture's or page's text, in seconds.",
};

std::uint64_t to_us(double seconds) { return static_cast<std::uint64_t>(std::llround(seconds * 1e6)); }

/// A label value escaped as the text format asks (backslash, double quote, line feed).
std::string escaped(std::string_view v) {
  std::string out;
  for (char c : v) {
    if (c == '\\' || c == '"') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out;
}

/// A number as the text format writes it: integers without a fraction, others with up to 17 digits.
std::string number(double v) {
  if (std::isinf(v)) return v > 0 ? "+Inf" : "-Inf";
  return fmt::format("{}", v);
}

void family(std::string& out, std::string_view name, std::string_view type, std::string_view help) {
  fmt::format_to(std::back_inserter(out), "# HELP haptic_kiosk_{} {}\n# TYPE haptic_kiosk_{} {}\n", name, help, name,
                 type);
}

}  // namespace

void KioskMetrics::observe(KioskTiming t, double seconds) noexcept {
  if (!(seconds >= 0.0)) return;
  Histogram& h = timings_[static_cast<int>(t)];
  std::size_t b = 0;
  while (b < kBuckets_s.size() && seconds > kBuckets_s[b]) ++b;
  h.counts[b].fetch_add(1, std::memory_order_relaxed);
  h.sum_us.fetch_add(to_us(seconds), std::memory_order_relaxed);
}

void KioskMetrics::add_contact(double seconds) noexcept {
  if (seconds >= 0.0) contact_us_.fetch_add(to_us(seconds), std::memory_order_relaxed);
}

void KioskMetrics::set_servo(std::int64_t ticks, std::int64_t missed_deadlines, double rate_hz) noexcept {
  if (ticks < last_ticks_ || missed_deadlines < last_missed_) {  // a new servo thread: carry the old one's totals
    base_ticks_ += last_ticks_;
    base_missed_ += last_missed_;
  }
  last_ticks_ = ticks;
  last_missed_ = missed_deadlines;
  servo_ticks_.store(base_ticks_ + ticks, std::memory_order_relaxed);
  servo_missed_.store(base_missed_ + missed_deadlines, std::memory_order_relaxed);
  rate_hz_.store(rate_hz, std::memory_order_relaxed);
}

void KioskMetrics::set_device(std::string name, bool connected) {
  std::lock_guard lock(device_mu_);
  device_ = std::move(name);
  device_connected_ = connected;
}

std::string KioskMetrics::exposition(std::string_view version) const {
  std::string out;
  out.reserve(4096);
  auto line = [&out](std::string_view name, std::string_view labels, double v) {
    fmt::format_to(std::back_inserter(out), "haptic_kiosk_{}{} {}\n", name, labels, number(v));
  };
  family(out, "build_info", "gauge", "The kiosk's version, as a label; the value is 1.");
  line("build_info", fmt::format("{{version=\"{}\"}}", escaped(version)), 1);
  {
    std::string device;
    bool connected = false;
    {
      std::lock_guard lock(device_mu_);
      device = device_;
      connected = device_connected_;
    }
    family(out, "device_connected", "gauge", "1 while the device in use answers, 0 while it is lost.");
    if (!device.empty()) line("device_connected", fmt::format("{{device=\"{}\"}}", escaped(device)), connected ? 1 : 0);
  }
  family(out, "servo_rate_hz", "gauge", "The servo rate set, in hertz.");
  line("servo_rate_hz", "", rate_hz_.load(std::memory_order_relaxed));
  family(out, "servo_ticks_total", "counter", "Servo ticks since the kiosk started.");
  line("servo_ticks_total", "", static_cast<double>(servo_ticks_.load(std::memory_order_relaxed)));
  family(out, "servo_missed_deadlines_total", "counter", "Servo ticks that started a whole period late.");
  line("servo_missed_deadlines_total", "", static_cast<double>(servo_missed_.load(std::memory_order_relaxed)));
  family(out, "visit_active", "gauge", "1 while a visitor is on a visit, 0 while the kiosk waits for one.");
  line("visit_active", "", visit_active_.load(std::memory_order_relaxed) ? 1 : 0);
  for (int i = 0; i < kKioskCountCount; ++i) {
    family(out, kCountNames[i], "counter", kCountHelp[i]);
    line(kCountNames[i], "", static_cast<double>(counts_[i].load(std::memory_order_relaxed)));
  }
  family(out, "contact_seconds_total", "counter", "Time the proxy touched a shape, in seconds.");
  line("contact_seconds_total", "", static_cast<double>(contact_us_.load(std::memory_order_relaxed)) / 1e6);
  family(out, "library_pictures", "gauge", "Pictures in the library.");
  line("library_pictures", "", library_pictures_.load(std::memory_order_relaxed));
  for (int t = 0; t < kKioskTimingCount; ++t) {
    const Histogram& h = timings_[t];
    const std::string name = kTimingNames[t];
    family(out, name, "histogram", kTimingHelp[t]);
    std::uint64_t cumulative = 0;
    for (std::size_t b = 0; b <= kBuckets_s.size(); ++b) {
      cumulative += h.counts[b].load(std::memory_order_relaxed);
      const double le = b < kBuckets_s.size() ? kBuckets_s[b] : INFINITY;
      line(name + "_bucket", fmt::format("{{le=\"{}\"}}", number(le)), static_cast<double>(cumulative));
    }
    line(name + "_sum", "", static_cast<double>(h.sum_us.load(std::memory_order_relaxed)) / 1e6);
    line(name + "_count", "", static_cast<double>(cumulative));
  }
  family(out, "errors_total", "counter", "Errors, by kind.");
  for (int k = 0; k < kKioskErrorCount; ++k)
    line("errors_total", fmt::format("{{kind=\"{}\"}}", kErrorKinds[k]),
         static_cast<double>(errors_[k].load(std::memory_order_relaxed)));
  return out;
}

KioskMetrics& kiosk_metrics() {
  static KioskMetrics m;
  return m;
}

}  // namespace hk::app
