// Soak: the kiosk without its window, run for a given wall-clock time with everything a
// day at a museum brings, while its process is watched.
//
// Every frame (60 Hz, wall clock) the loop does what app/kiosk/src/kiosk_app.cpp's frame loop does without
// drawing: poll sticks, device and tour, tick the visitor's flow, collect retired scenes, and pull the
// audio mix as a sound card would (800 frames at 48 kHz). Around it a script plays:
// - visitors: one wakes the kiosk, walks through the tutorial, presses a key every 3 s (next and previous
//   picture, describe, finer, coarser, volume, guide, help) while the hand circles over the picture, then
//   leaves after 45–90 s; the kiosk times out (timeout 20 s, warning 5 s) and waits 10 s for the next;
// - a USB stick (a folder of PDFs, tests/data/documents, through the stick service) put in every 150 s and
//   taken out 40 s later, its documents browsed by the visitor's Next key meanwhile;
// - the operator applying settings every 100 s (stiffness 800 ↔ 1200 N/m and the shape budget 30 ↔ 20,
//   which rebuilds the scene), as the operator's panel does (KioskRuntime::apply_settings);
// - the pantograph: by default the USB pantograph's driver on the firmware emulator behind a pty with
//   faults (dropped, garbled and wrongly addressed replies), or `--device sim`.
// Every --report-every-s it samples the process (resident set from /proc/self/status VmRSS, open file
// descriptors in /proc/self/fd, threads) and the servo thread (ticks and missed deadlines in the interval,
// worst lateness since the start, compute p99 since the last visitor), prints one line and appends it to
// --csv. At the end it writes --json: the figures after
// --warmup-s, the RSS growth per hour (least-squares slope of RSS over time after warm-up), and each target
// of the issue met or not (RSS growth < 1 MB/h, no fd or thread growth, 0 missed deadlines at 1 kHz).
// Exit status 0 unless --check is given and a target is missed. --level-mode sets [haptics] level_mode (default
// "auto"; "cut": the walls at the tolerance cut, whose masks every scene change computes again).
//
//   build/bench/bench_soak --duration-s 7200 --csv docs/bench/soak.csv --json docs/bench/soak.json

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "config/settings.hpp"
#include "runtime/device_setup.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"

namespace {

namespace fs = std::filesystem;
using hk::app::KioskKey;
using Clock = std::chrono::steady_clock;

constexpr double kFrameS = 1.0 / 60.0;     // window frame [s]
constexpr std::size_t kAudioFrames = 800;  // 48 kHz / 60 Hz [frames]
constexpr double kKeyEveryS = 3.0;         // a visitor's key presses [s]
constexpr double kStickEveryS = 150.0;     // a stick put in [s]
constexpr double kStickHeldS = 40.0;       // ... and taken out after [s]
constexpr double kOperatorEveryS = 100.0;  // settings applied [s]
constexpr double kGapBetweenVisitorsS = 10.0;

/// One look at the process.
struct ProcessSample {
  double t_s = 0;    ///< since the start [s]
  long rss_kib = 0;  ///< resident set [KiB]
  int fds = 0;       ///< open file descriptors
  int threads = 0;   ///< threads of the process
};

/// A number from /proc/self/status ("VmRSS:", "Threads:"), −1 when absent.
long status_field(const std::string& name) {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind(name, 0) == 0) return std::stol(line.substr(name.size()));
  return -1;
}

ProcessSample sample_process(double t_s) {
  ProcessSample s;
  s.t_s = t_s;
  s.rss_kib = status_field("VmRSS:");
  s.threads = static_cast<int>(status_field("Threads:"));
  for ([[maybe_unused]] const auto& e : fs::directory_iterator("/proc/self/fd")) ++s.fds;
  s.fds -= 1;  // the directory_iterator's own descriptor
  return s;
}

/// Least-squares slope of y over x (0 for fewer than two points).
double slope(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = x.size();
  if (n < 2) return 0.0;
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < n; ++i) mx += x[i], my += y[i];
  mx /= n, my /= n;
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < n; ++i) sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
  return sxx > 0 ? sxy / sxx : 0.0;
}

struct SoakOptions {
  double duration_s = 600;
  double report_every_s = 30;
  double warmup_s = 300;
  std::string device = "haply-emulator:drop_every=997,garbage_every=1499,wrong_id_every=2003";
  std::string library = std::string(HK_DATA_DIR) + "/pictures";
  std::string stick = std::string(HK_TEST_DATA_DIR) + "/documents";
  std::string csv, json;
  unsigned seed = 1;
  std::string level_mode = "auto";  // [haptics] level_mode of the kiosk
  bool check = false;
};

/// The scripted day: visitors, stick, operator. Drives the flow and the runtime as the window would.
class Script {
 public:
  Script(hk::app::KioskRuntime& rt, hk::app::KioskFlow& flow, const hk::config::Settings& s, unsigned seed)
      : rt_(rt), flow_(flow), base_(s), rng_(seed) {}

  /// One frame at `now_s` [s].
  void frame(double now_s) {
    visitor(now_s);
    stick(now_s);
    operator_(now_s);
  }
  int visitors() const { return visitors_; }
  int sticks() const { return sticks_; }
  int applies() const { return applies_; }
  long keys() const { return keys_; }

 private:
  void visitor(double now_s) {
    if (!present_ && flow_.view().state == hk::app::KioskState::Attract && now_s >= next_visit_s_) {
      present_ = true;
      ++visitors_;
      leave_s_ = now_s + std::uniform_real_distribution<double>(45, 90)(rng_);
      press(KioskKey::Other, now_s);  // wakes: welcome and tutorial
      for (int i = 0; i < 3; ++i) press(KioskKey::Next, now_s);
      next_key_s_ = now_s + kKeyEveryS;
    }
    if (!present_) return;
    if (now_s >= leave_s_) {  // leaves; the kiosk times out, the next comes a while after
      present_ = false;
      next_visit_s_ = now_s + base_.kiosk.timeout_s + kGapBetweenVisitorsS;
      return;
    }
    const double w = 2 * 3.14159265358979 * 0.25 * now_s;  // a slow figure over the workspace
    rt_.tour().set_cursor({0.8 * rt_.half().x * std::sin(w), 0.8 * rt_.half().y * std::sin(1.7 * w)});
    flow_.handle_moved(now_s);  // the hand moves: the visit goes on
    if (now_s >= next_key_s_) {
      static constexpr KioskKey kKeys[] = {KioskKey::Next,    KioskKey::Previous, KioskKey::Describe,   KioskKey::Finer,
                                           KioskKey::Coarser, KioskKey::VolumeUp, KioskKey::VolumeDown, KioskKey::Guide,
                                           KioskKey::Help,    KioskKey::Next};
      press(kKeys[std::uniform_int_distribution<int>(0, 9)(rng_)], now_s);
      next_key_s_ = now_s + kKeyEveryS;
    }
  }

  void stick(double now_s) {
    const double phase = std::fmod(now_s, kStickEveryS);
    if (!stick_in_ && phase >= kStickEveryS / 2 && phase < kStickEveryS / 2 + kStickHeldS && now_s > kStickEveryS / 2) {
      rt_.sticks().insert_folder(stick_dir_);
      stick_in_ = true;
      ++sticks_;
    } else if (stick_in_ && phase >= kStickEveryS / 2 + kStickHeldS) {
      rt_.sticks().remove_folder();
      stick_in_ = false;
    }
  }

  void operator_(double now_s) {
    if (now_s < next_apply_s_) return;
    next_apply_s_ = now_s + kOperatorEveryS;
    hk::config::Settings s = rt_.settings();
    const bool odd = (applies_ % 2) == 0;
    s.haptics.stiffness_n_per_m = odd ? 1200.0 : base_.haptics.stiffness_n_per_m;
    s.vision.max_shapes = odd ? 20 : base_.vision.max_shapes;
    rt_.apply_settings(s, flow_);
    ++applies_;
  }

  void press(KioskKey k, double now_s) {
    flow_.key(k, now_s);  // the flow tells the runtime (KioskEffects::key_pressed)
    ++keys_;
  }

 public:
  std::string stick_dir_;

 private:
  hk::app::KioskRuntime& rt_;
  hk::app::KioskFlow& flow_;
  hk::config::Settings base_;
  std::mt19937 rng_;
  bool present_ = false, stick_in_ = false;
  double next_visit_s_ = 1.0, leave_s_ = 0, next_key_s_ = 0, next_apply_s_ = kOperatorEveryS;
  int visitors_ = 0, sticks_ = 0, applies_ = 0;
  long keys_ = 0;
};

int run(const SoakOptions& o) {
  hk::config::Settings s;
  s.kiosk.timeout_s = 20;
  s.kiosk.warning_s = 10;
  s.haptics.level_mode = o.level_mode;
  hk::app::RuntimeOptions ro;
  ro.library = o.library;
  ro.hotplug = false;
  ro.open_audio_output = false;
  ro.probe_usb_device = false;
  ro.device = o.device == "sim" ? std::string() : o.device;
  hk::app::KioskRuntime rt(ro, s);
  const hk::app::KioskFlowParams fp = hk::app::flow_params_from(s, false);
  hk::app::KioskFlow flow(rt.effects(), rt.audio().messages(), fp);
  Script script(rt, flow, s, o.seed);
  script.stick_dir_ = o.stick;
  rt.start_servo();
  rt.announce_device();

  std::ofstream csv;
  if (!o.csv.empty()) {
    csv.open(o.csv);
    csv << "t_s,rss_kib,fds,threads,ticks,missed_deadlines,lateness_max_us,compute_p99_us,visitors,sticks,applies,"
           "device\n";
  }
  std::vector<ProcessSample> samples;
  std::int64_t ticks = 0, missed = 0;
  double worst_late_us = 0, worst_compute_p99_us = 0;
  std::int64_t missed_after_warmup = 0;
  std::vector<float> audio(kAudioFrames);
  const auto t0 = Clock::now();
  auto next_frame = t0;
  double next_report_s = o.report_every_s;
  for (;;) {
    const double now_s = std::chrono::duration<double>(Clock::now() - t0).count();
    if (now_s >= o.duration_s) break;
    script.frame(now_s);
    rt.poll(&flow, now_s);
    rt.poll_after_input();
    flow.tick(now_s);
    rt.audio().render(audio.data(), audio.size());
    if (now_s >= next_report_s) {
      next_report_s += o.report_every_s;
      // Totals since the start, not take_stats(): the runtime takes its own report at every new visitor.
      const hk::app::ServoThread::Totals tot = rt.devices().servo()->totals();
      hk::app::ServoTimingStats st = rt.devices().servo()->stats();  // since the last visitor: for the compute p99
      st.ticks = tot.ticks - ticks;
      st.missed_deadlines = tot.missed_deadlines - missed;
      st.lateness_max_us = tot.lateness_max_us;
      const ProcessSample p = sample_process(now_s);
      samples.push_back(p);
      ticks = tot.ticks;
      missed = tot.missed_deadlines;
      if (now_s >= o.warmup_s) missed_after_warmup += st.missed_deadlines;
      worst_late_us = tot.lateness_max_us;
      worst_compute_p99_us = std::max(worst_compute_p99_us, st.compute_p99_us);
      const std::string dev = hk::app::device_status_name(rt.core().display().device_status);
      char line[256];
      std::snprintf(line, sizeof line, "%.0f,%ld,%d,%d,%lld,%lld,%.0f,%.1f,%d,%d,%d,%s", p.t_s, p.rss_kib, p.fds,
                    p.threads, static_cast<long long>(st.ticks), static_cast<long long>(st.missed_deadlines),
                    st.lateness_max_us, st.compute_p99_us, script.visitors(), script.sticks(), script.applies(),
                    dev.c_str());
      std::cout << "soak " << line << std::endl;
      if (csv) csv << line << "\n" << std::flush;
    }
    next_frame += std::chrono::microseconds(16667);
    std::this_thread::sleep_until(next_frame);
  }
  rt.devices().stop_servo();

  // After warm-up: growth and ranges.
  std::vector<double> t_h, rss_kib;
  int fd_min = 1 << 30, fd_max = 0, th_min = 1 << 30, th_max = 0;
  const ProcessSample* first = nullptr;
  const ProcessSample* last = nullptr;
  for (const ProcessSample& p : samples) {
    if (p.t_s < o.warmup_s) continue;
    if (!first) first = &p;
    last = &p;
    t_h.push_back(p.t_s / 3600.0);
    rss_kib.push_back(static_cast<double>(p.rss_kib));
    fd_min = std::min(fd_min, p.fds), fd_max = std::max(fd_max, p.fds);
    th_min = std::min(th_min, p.threads), th_max = std::max(th_max, p.threads);
  }
  nlohmann::json j;
  j["duration_s"] = o.duration_s;
  j["warmup_s"] = o.warmup_s;
  j["device"] = o.device;
  j["level_mode"] = o.level_mode;
  j["visitors"] = script.visitors();
  j["keys"] = script.keys();
  j["sticks"] = script.sticks();
  j["operator_applies"] = script.applies();
  j["servo"] = {{"ticks", ticks},
                {"missed_deadlines", missed},
                {"missed_after_warmup", missed_after_warmup},
                {"lateness_max_us", worst_late_us},
                {"compute_p99_max_us", worst_compute_p99_us}};
  bool ok = first != nullptr;
  if (first) {
    const double growth_kib_per_h = slope(t_h, rss_kib);
    j["rss_kib"] = {{"after_warmup", first->rss_kib}, {"end", last->rss_kib}, {"growth_kib_per_h", growth_kib_per_h}};
    j["fds"] = {{"after_warmup", first->fds}, {"end", last->fds}, {"min", fd_min}, {"max", fd_max}};
    j["threads"] = {{"after_warmup", first->threads}, {"end", last->threads}, {"min", th_min}, {"max", th_max}};
    const bool rss_ok = growth_kib_per_h < 1024.0;
    const bool fd_ok = last->fds <= first->fds;
    const bool th_ok = last->threads <= first->threads;
    const bool dl_ok = missed_after_warmup == 0;
    j["targets"] = {{"rss_growth_under_1_mb_per_h", rss_ok},
                    {"no_fd_growth", fd_ok},
                    {"no_thread_growth", th_ok},
                    {"no_missed_deadlines_after_warmup", dl_ok}};
    ok = rss_ok && fd_ok && th_ok && dl_ok;
  }
  std::cout << j.dump(2) << std::endl;
  if (!o.json.empty()) std::ofstream(o.json) << j.dump(2) << "\n";
  return o.check && !ok ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  SoakOptions o;
  CLI::App cli{
      "Runs the kiosk headless with scripted visitors, sticks, operator and device faults; watches RSS, fds, threads, "
      "deadlines"};
  cli.add_option("--duration-s", o.duration_s, "Wall-clock run time [s]")->check(CLI::Range(10.0, 7.0 * 24 * 3600));
  cli.add_option("--report-every-s", o.report_every_s, "Sampling period [s]")->check(CLI::Range(1.0, 3600.0));
  cli.add_option("--warmup-s", o.warmup_s, "Samples before this are not judged [s]")
      ->check(CLI::Range(0.0, 7.0 * 24 * 3600));
  cli.add_option("--device", o.device,
                 "sim, or haply-emulator[:FAULT=V,...] (the default has dropped, garbled, misaddressed replies)");
  cli.add_option("--library", o.library, "Picture folder");
  cli.add_option("--stick", o.stick, "Folder put in as a USB stick every 150 s");
  cli.add_option("--csv", o.csv, "Write the samples here");
  cli.add_option("--json", o.json, "Write the summary here");
  cli.add_option("--seed", o.seed, "The visitors' seed");
  cli.add_option("--level-mode", o.level_mode, "[haptics] level_mode of the kiosk")
      ->check(CLI::IsMember({"auto", "tolerance", "cut", "fixed"}));
  cli.add_flag("--check", o.check, "Exit 1 when a target is missed");
  CLI11_PARSE(cli, argc, argv);
  if (o.warmup_s >= o.duration_s) o.warmup_s = o.duration_s / 2;
  try {
    return run(o);
  } catch (const std::exception& e) {
    std::cerr << "bench_soak: " << e.what() << "\n";
    return 2;
  }
}
