#pragma once
/// @file metrics.hpp
/// What a museum's Prometheus scrapes of a kiosk (GET /metrics, metrics_server.hpp): counts and times only, nothing
/// a visitor said, chose or brought.
///
/// | metric | type | labels | what |
/// |---|---|---|---|
/// | `haptic_kiosk_build_info` | gauge | `version` | 1; the kiosk's version |
/// | `haptic_kiosk_device_connected` | gauge | `device` | 1 while the device in use answers (`haply`, `haply-gen2`,
/// `simulated`, `emulator`), 0 while it is lost | | `haptic_kiosk_servo_rate_hz` | gauge | | the servo rate set [Hz] |
/// | `haptic_kiosk_servo_ticks_total` | counter | | servo ticks since the start |
/// | `haptic_kiosk_servo_missed_deadlines_total` | counter | | ticks that started a whole period late (zero force sent)
/// | | `haptic_kiosk_visit_active` | gauge | | 1 while a visitor is on a visit, 0 while the kiosk waits (attract):
/// roll-outs restart it only at 0 | | `haptic_kiosk_visits_started_total` | counter | | visitors who woke the kiosk |
/// | `haptic_kiosk_visits_finished_total` | counter | | visits ended by Finish or the time-out |
/// | `haptic_kiosk_pictures_explored_total` | counter | | pictures, stick pages and captures put under a visitor's hand
/// | | `haptic_kiosk_contact_seconds_total` | counter | | time the proxy touched a shape [s], sampled each frame | |
/// `haptic_kiosk_sticks_read_total` | counter | | USB sticks read | | `haptic_kiosk_copies_made_total` | counter | |
/// take-home copies printed or saved on a stick | | `haptic_kiosk_settings_applied_total` | counter | | settings
/// applied at the operator's panel | | `haptic_kiosk_library_pictures` | gauge | | pictures in the library now | |
/// `haptic_kiosk_scene_build_seconds` | histogram | | scene builds of library pictures [s] | |
/// `haptic_kiosk_ocr_seconds` | histogram | | readings of a picture's or page's text [s] | |
/// `haptic_kiosk_errors_total` | counter | `kind` | `device_lost`, `stick_refused`, `copy_failed`, `settings_refused`,
/// `picture_unreadable`, `library_refused`, `visitor_action` |
///
/// One registry a process (kiosk_metrics()); every update is a relaxed atomic, so any thread but the servo's may
/// count (the servo's own counts are read from ServoThread::totals by the window thread each frame).

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>

namespace hk::app {

/// Counters that rise by one event at a time.
enum class KioskCount : std::uint8_t {
  visits_started,
  visits_finished,
  pictures_explored,
  sticks_read,
  copies_made,
  settings_applied,
};
inline constexpr int kKioskCountCount = 6;

/// The `kind` label of haptic_kiosk_errors_total.
enum class KioskError : std::uint8_t {
  device_lost,
  stick_refused,
  copy_failed,
  settings_refused,
  picture_unreadable,  ///< a picture or page the visitor asked for could not be built
  library_refused,     ///< a picture put in the library folder does not decode
  visitor_action,      ///< a visitor's key or motion failed inside the flow (the sorry line)
};
inline constexpr int kKioskErrorCount = 7;

/// The histograms.
enum class KioskTiming : std::uint8_t { scene_build, ocr };
inline constexpr int kKioskTimingCount = 2;

/// The kiosk's metrics (see the table above). Thread-safe.
class KioskMetrics {
 public:
  /// Histogram bucket upper bounds [s] (the +Inf bucket is added), the same for both histograms.
  static constexpr std::array<double, 10> kBuckets_s{0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10, 30, 60};

  void add(KioskCount c) noexcept { counts_[static_cast<int>(c)].fetch_add(1, std::memory_order_relaxed); }
  void error(KioskError k) noexcept { errors_[static_cast<int>(k)].fetch_add(1, std::memory_order_relaxed); }
  /// One observation of `seconds` (negative or NaN ignored).
  void observe(KioskTiming t, double seconds) noexcept;
  /// Time in contact [s] (negative or NaN ignored).
  void add_contact(double seconds) noexcept;
  /// The servo thread's totals since it started (ServoThread::totals) and its rate [Hz]. A servo thread started
  /// anew (its ticks fewer than last seen) carries on from the last totals, so the counters only rise. One thread
  /// calls it (the window thread, each frame).
  void set_servo(std::int64_t ticks, std::int64_t missed_deadlines, double rate_hz) noexcept;
  /// The device in use (`name`, the label) and whether it answers. Not for the servo thread (locks).
  void set_device(std::string name, bool connected);
  void set_library_pictures(int n) noexcept { library_pictures_.store(n, std::memory_order_relaxed); }
  void set_visit_active(bool active) noexcept { visit_active_.store(active, std::memory_order_relaxed); }

  std::uint64_t count(KioskCount c) const noexcept {
    return counts_[static_cast<int>(c)].load(std::memory_order_relaxed);
  }
  std::uint64_t errors(KioskError k) const noexcept {
    return errors_[static_cast<int>(k)].load(std::memory_order_relaxed);
  }

  /// Every metric in the Prometheus text exposition format 0.0.4 (HELP and TYPE lines, families in the table's
  /// order), `version` as build_info's label.
  std::string exposition(std::string_view version) const;

 private:
  struct Histogram {
    std::array<std::atomic<std::uint64_t>, kBuckets_s.size() + 1> counts{};  // per bucket, not cumulative; +Inf last
    std::atomic<std::uint64_t> sum_us{0};                                    // [µs]
  };
  std::array<std::atomic<std::uint64_t>, kKioskCountCount> counts_{};
  std::array<std::atomic<std::uint64_t>, kKioskErrorCount> errors_{};
  std::array<Histogram, kKioskTimingCount> timings_{};
  std::atomic<std::uint64_t> contact_us_{0};  // [µs]
  std::atomic<int> library_pictures_{0};
  std::atomic<bool> visit_active_{false};
  std::atomic<double> rate_hz_{0.0};
  std::atomic<std::int64_t> servo_ticks_{0}, servo_missed_{0};  // as published, carried over restarts
  std::int64_t base_ticks_ = 0, base_missed_ = 0, last_ticks_ = 0, last_missed_ = 0;  // set_servo's caller's own
  mutable std::mutex device_mu_;                                                      // the device's name and state
  std::string device_;
  bool device_connected_ = false;
};

/// The process's metrics.
KioskMetrics& kiosk_metrics();

}  // namespace hk::app
