// The USB pantograph's driver in the loop, on the Haply firmware
// emulator behind a pty, reached through the tty transport and the hAPI driver exactly as a board on
// /dev/ttyACM0 would be:
//  1. Round trip at 1 kHz: from just before a torque packet is written (HaplyDevice::write_force) to its
//     reply decoded (HaplyDevice::read waiting for it): p50 / p99 / max over the run.
//  2. The kiosk's servo thread with the device in the loop (ServoThread: read the previous tick's reply,
//     step, write the next packet) on butterfly.jpg with a still handle: wake-up lateness, tick work,
//     missed deadlines, replies missing, and the servo thread's CPU use (CLOCK_THREAD_CPUTIME_ID), next to
//     the same run on the simulated pantograph. The emulator's own thread is the "board" and is not counted.
//  3. The servo step's calls alone, paced at 1 kHz and never waiting (read, then write_force): their p50 /
//     p99 / max times, and the writes skipped while a packet's reply was not yet in.
//  4. Plug-in to force: a new board's tty asked until it answers hAPI (io::open_first_board), ten boards;
//     the force then ramps in over [haptics] force_ramp_s.
// Usage: bench_device_loop [--seconds S] [--out FILE.json]
#include <pthread.h>
#include <spdlog/spdlog.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "haptics/hapi_emulator.hpp"
#include "haptics/io/haply_device.hpp"
#include "haptics/io/tty_transport.hpp"
#include "haptics/pty_emulator.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/device_setup.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/servo_thread.hpp"
#include "runtime/simulation.hpp"
#include "test_paths.hpp"

using namespace hk;

namespace {

double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double pct(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5))];
}

/// Sleeps until one millisecond after `*next` (CLOCK_MONOTONIC) and moves `*next` there: a 1 kHz pace.
void sleep_until_next_ms(timespec* next) {
  next->tv_nsec += 1000000;
  if (next->tv_nsec >= 1000000000) {
    next->tv_nsec -= 1000000000;
    ++next->tv_sec;
  }
  clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, next, nullptr);
}

struct Board {
  explicit Board(const config::Settings& s) {
    dp = app::haply_params_from(s);
    emulator = std::make_unique<hapi::FirmwareEmulator>(app::emulator_params_from(s, {}), dp.rect_center_device_m,
                                                        [](double, Vec2, Vec2) {
                                                          return Vec2{0.0, 0.0};
                                                        });
    pty = std::make_unique<hapi::PtyEmulator>(*emulator);
    const std::string path = pty->device_path();
    device = std::make_unique<io::HaplyDevice>(dp, [path] { return std::make_unique<io::TtyTransport>(path); });
    device->open();
  }
  ~Board() {
    device->close();
    pty->stop();
  }
  io::HaplyDeviceParams dp;
  std::unique_ptr<hapi::FirmwareEmulator> emulator;
  std::unique_ptr<hapi::PtyEmulator> pty;
  std::unique_ptr<io::HaplyDevice> device;
};

nlohmann::json round_trip(const config::Settings& s, double seconds) {
  Board b(s);
  std::vector<double> us;
  const long n = static_cast<long>(seconds * 1000);
  us.reserve(static_cast<std::size_t>(n));
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  long missing = 0;
  for (long k = 0; k < n; ++k) {
    sleep_until_next_ms(&next);
    const auto t0 = std::chrono::steady_clock::now();
    b.device->write_force({0.0, 0.0});
    const auto before = b.device->counters().replies;
    b.device->wait_reply(5000);
    b.device->read();
    const auto t1 = std::chrono::steady_clock::now();
    if (b.device->counters().replies == before) {
      ++missing;
      continue;
    }
    us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
  }
  std::printf("| round trip tick → torque packet → reply over the pty | %ld | %.0f | %.0f | %.0f | %ld |\n", n,
              pct(us, 0.5), pct(us, 0.99), pct(us, 1.0), missing);
  return {{"ticks", n},
          {"round_trip_us", {{"p50", pct(us, 0.5)}, {"p99", pct(us, 0.99)}, {"max", pct(us, 1.0)}}},
          {"missing", missing}};
}

/// Plug-in to force: from the moment the kiosk asks a board that just arrived (its tty, through
/// io::open_first_board: reset, setup, zero-torque packets until a well-formed reply) to the board taken and
/// answering; the servo then ramps the force in over [haptics] force_ramp_s. `runs` boards, each new.
nlohmann::json plug_in_to_force(const config::Settings& s, int runs) {
  std::vector<double> ms;
  for (int k = 0; k < runs; ++k) {
    hapi::FirmwareEmulator emulator(app::emulator_params_from(s, {}), app::haply_params_from(s).rect_center_device_m,
                                    [](double, Vec2, Vec2) {
                                      return Vec2{0.0, 0.0};
                                    });
    hapi::PtyEmulator pty(emulator);
    const std::string path = pty.device_path();
    const auto t0 = std::chrono::steady_clock::now();
    std::unique_ptr<io::HaplyDevice> board =
        io::open_first_board(app::haply_params_from(s),
                             {{"tty " + path, [path] { return std::make_unique<io::TtyTransport>(path); }}}, nullptr);
    const auto t1 = std::chrono::steady_clock::now();
    if (board) ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    if (board) board->close();
    pty.stop();
  }
  std::printf(
      "| plug-in to the board answering (open_first_board on its tty) | %d | %.1f ms | %.1f ms | %.1f ms | %d |\n",
      runs, pct(ms, 0.5), pct(ms, 0.99), pct(ms, 1.0), runs - static_cast<int>(ms.size()));
  return {{"runs", runs},
          {"answered", ms.size()},
          {"open_ms", {{"p50", pct(ms, 0.5)}, {"max", pct(ms, 1.0)}}},
          {"force_ramp_s", s.haptics.force_ramp_s}};
}

/// The driver's calls as the servo thread makes them (read, then write_force, paced at 1 kHz, never waiting):
/// how long each took at most, and how many writes were skipped because the last packet's reply was not in.
nlohmann::json step_calls(const config::Settings& s, double seconds) {
  Board b(s);
  // On a thread scheduled as the kiosk's servo thread is (SCHED_FIFO where allowed), so that the times are
  // the calls' own and not the scheduler's.
  int old_policy = 0;
  sched_param old_param{};
  pthread_getschedparam(pthread_self(), &old_policy, &old_param);
  sched_param fifo{};
  fifo.sched_priority = app::ServoThreadParams{}.fifo_priority;
  const bool realtime = pthread_setschedparam(pthread_self(), SCHED_FIFO, &fifo) == 0;
  std::vector<double> read_us, write_us;
  const long n = static_cast<long>(seconds * 1000);
  read_us.reserve(static_cast<std::size_t>(n));
  write_us.reserve(static_cast<std::size_t>(n));
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  for (long k = 0; k < n; ++k) {
    sleep_until_next_ms(&next);
    const auto t0 = std::chrono::steady_clock::now();
    b.device->read();
    const auto t1 = std::chrono::steady_clock::now();
    b.device->write_force({0.0, 0.0});
    const auto t2 = std::chrono::steady_clock::now();
    read_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    write_us.push_back(std::chrono::duration<double, std::micro>(t2 - t1).count());
  }
  if (realtime) pthread_setschedparam(pthread_self(), old_policy, &old_param);
  const io::HaplyCounters c = b.device->counters();
  std::printf(
      "| servo step's read / write_force, never waiting (%s) | %ld | %.0f / %.0f | %.0f / %.0f | %.0f / %.0f | %lld "
      "skipped, %lld late |\n",
      realtime ? "SCHED_FIFO" : "normal priority", n, pct(read_us, 0.5), pct(write_us, 0.5), pct(read_us, 0.99),
      pct(write_us, 0.99), pct(read_us, 1.0), pct(write_us, 1.0), static_cast<long long>(c.writes_skipped),
      static_cast<long long>(c.replies_missing));
  return {{"ticks", n},
          {"read_us", {{"p50", pct(read_us, 0.5)}, {"p99", pct(read_us, 0.99)}, {"max", pct(read_us, 1.0)}}},
          {"write_us", {{"p50", pct(write_us, 0.5)}, {"p99", pct(write_us, 0.99)}, {"max", pct(write_us, 1.0)}}},
          {"sched_fifo", realtime},
          {"packets_sent", c.ticks},
          {"writes_skipped", c.writes_skipped},
          {"ticks_without_reply", c.replies_missing}};
}

nlohmann::json servo_run(const config::Settings& s, double seconds, bool usb) {
  app::ImageScene is = app::build_image_scene(std::string(HK_TEST_DATA_DIR) + "/images/butterfly.jpg", s);
  app::ServoStep core(app::CueTrackerParams{}, nullptr);
  core.publish(std::make_unique<app::SceneBundle>(std::move(is.scene), app::servo_params_from(s)));
  std::unique_ptr<Board> board;
  std::unique_ptr<SimulatedPantograph> sim;
  Device* device = nullptr;
  if (usb) {
    board = std::make_unique<Board>(s);
    device = board->device.get();
  } else {
    sim = std::make_unique<SimulatedPantograph>(app::sim_params_from(s), Vec2{0.0, 0.0});
    sim->open();
    device = sim.get();
  }
  double cpu_first = -1, cpu_last = 0;
  long ticks = 0;
  app::ServoTimingStats st;
  bool realtime = false;
  {
    app::ServoThread thread(core, *device, {}, [&](double dt) {
      if (sim) sim->step(dt, {0.0, 0.0});
      const double c = thread_cpu_s();
      if (cpu_first < 0) cpu_first = c;
      cpu_last = c;
      ++ticks;
    });
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    thread.stop();
    st = thread.stats();
    realtime = thread.realtime();
  }
  const double cpu_pct =
      ticks > 1 ? 100.0 * (cpu_last - cpu_first) / (static_cast<double>(ticks - 1) / s.haptics.servo_rate_hz) : 0.0;
  long long missing = 0;
  if (board) missing = board->device->counters().replies_missing;
  core.collect_retired();
  std::printf("| servo thread, %s | %lld | %.0f | %.0f | %.0f | %.1f | %.1f | %lld | %lld | %.1f %% | %s |\n",
              usb ? "USB pantograph (emulated board on a pty)" : "simulated pantograph",
              static_cast<long long>(st.ticks), st.lateness_p50_us, st.lateness_p99_us, st.lateness_max_us,
              st.compute_p50_us, st.compute_p99_us, static_cast<long long>(st.missed_deadlines), missing, cpu_pct,
              realtime ? "SCHED_FIFO" : "normal");
  return {{"device", usb ? "haply-emulator" : "simulated"},
          {"ticks", st.ticks},
          {"realtime", realtime},
          {"lateness_us", {{"p50", st.lateness_p50_us}, {"p99", st.lateness_p99_us}, {"max", st.lateness_max_us}}},
          {"compute_us", {{"p50", st.compute_p50_us}, {"p99", st.compute_p99_us}}},
          {"missed_deadlines", st.missed_deadlines},
          {"replies_missing", missing},
          {"servo_thread_cpu_percent", cpu_pct},
          {"seconds", seconds}};
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 5.0;
  std::string out_path;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--seconds") seconds = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--out") out_path = argv[i + 1];
  }
  spdlog::set_level(spdlog::level::warn);  // the tables alone on stdout
  const config::Settings s;
  nlohmann::json j;
  std::printf("| measurement | ticks | p50 µs | p99 µs | max µs | missing |\n|---|---|---|---|---|---|\n");
  j["round_trip"] = round_trip(s, seconds);
  j["step_calls"] = step_calls(s, seconds);
  j["plug_in"] = plug_in_to_force(s, 10);
  std::printf(
      "\n| run | ticks | lateness p50 µs | p99 µs | max µs | tick work p50 µs | p99 µs | missed | replies missing | "
      "servo thread CPU | priority |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|\n");
  j["servo"] = {servo_run(s, seconds, false), servo_run(s, seconds, true)};
  if (!out_path.empty()) std::ofstream(out_path) << j.dump(2) << "\n";
  return 0;
}
