// A library change as a roll-out makes it: 100 pictures copied into the kiosk's watched library folder while the
// kiosk runs (headless, its servo thread at 1 kHz on the simulated pantograph, the window thread played at 60 Hz as
// the kiosk plays it: the runtime's poll once a frame). Each file arrives as Ansible and Syncthing write one: a
// hidden temporary file, then renamed to its name. Timed: from the last rename (the folder complete) to the
// library listing all 100 (the kiosk waiting in attract takes a listing at once; during a visit Next would take
// it), with the real quiet time (2 s); and every frame's work on the window thread meanwhile.
// Pictures: tests/data/images, cycled under 100 names.
// Usage: bench_library_reload [--out FILE.md] [--repeats N]
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "pictures/picture_library.hpp"
#include "runtime_ticks.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"

using namespace hk;
using namespace hk::app;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kFrame_s = 1.0 / 60.0;
constexpr int kPictures = 100;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

struct Run {
  double live_ms = 0;       // last rename -> all 100 listed
  double frame_max_ms = 0;  // the window thread's longest frame of work meanwhile
  double frame_p99_ms = 0;
  std::uint64_t bytes = 0;  // copied
  int frames = 0;
};

Run one_run(const fs::path& work) {
  const fs::path lib = work / "library";
  fs::remove_all(lib);
  fs::create_directories(lib);
  fs::copy_file(fs::path(HK_TEST_DATA_DIR) / "images" / "horse.png", lib / "000_horse.png");
  fs::last_write_time(lib / "000_horse.png", fs::file_time_type::clock::now() - std::chrono::hours(1));
  std::vector<fs::path> sources;
  for (const auto& e : fs::directory_iterator(fs::path(HK_TEST_DATA_DIR) / "images"))
    if (is_picture_name(e.path().filename().string())) sources.push_back(e.path());
  std::sort(sources.begin(), sources.end());

  config::Settings s;
  s.kiosk.names_dir = "off";
  RuntimeOptions ro = hk::test::headless_runtime_options(lib);
  ro.library_settle_s = kLibrarySettle_s;
  ro.shipped_library = std::string(HK_DATA_DIR) + "/pictures";
  KioskRuntime rt(ro, s);
  rt.start_servo();
  KioskFlow flow(rt.effects(), rt.audio().messages(), flow_params_from(s, false));

  // The copy, on its own thread (as rsync or Syncthing is its own process).
  Run r;
  Clock::time_point complete{};
  std::atomic<bool> copied{false};
  std::thread copier([&] {
    for (int i = 0; i < kPictures; ++i) {
      const fs::path& src = sources[static_cast<std::size_t>(i) % sources.size()];
      char name[64];
      std::snprintf(name, sizeof name, "%03d_%s", i + 1, src.filename().c_str());
      const fs::path tmp = lib / (std::string(".") + name + ".tmp");
      fs::copy_file(src, tmp);
      r.bytes += fs::file_size(tmp);
      fs::rename(tmp, lib / name);
    }
    complete = Clock::now();
    copied = true;
  });
  std::vector<double> frames_ms;
  double now_s = 0.0;
  const Clock::time_point start = Clock::now();
  for (;;) {
    const Clock::time_point f0 = Clock::now();
    rt.poll(&flow, now_s);
    rt.poll_after_input();
    const Clock::time_point f1 = Clock::now();
    frames_ms.push_back(ms_between(f0, f1));
    if (copied && rt.library().picture_count() == kPictures + 1) {
      r.live_ms = ms_between(complete, f1);
      break;
    }
    if (ms_between(start, f1) > 60000) {
      std::fprintf(stderr, "library_reload: not live after 60 s (%d pictures listed)\n", rt.library().picture_count());
      break;
    }
    now_s += kFrame_s;
    std::this_thread::sleep_until(f0 + std::chrono::microseconds(16667));
  }
  copier.join();
  std::sort(frames_ms.begin(), frames_ms.end());
  r.frames = static_cast<int>(frames_ms.size());
  r.frame_max_ms = frames_ms.back();
  r.frame_p99_ms = frames_ms[static_cast<std::size_t>(0.99 * static_cast<double>(frames_ms.size() - 1))];
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out;
  int repeats = 3;
  CLI::App cli("100 pictures copied into the watched library of a running kiosk");
  cli.add_option("--out", out, "Write the table (Markdown) to this file too");
  cli.add_option("--repeats", repeats, "Runs (each a fresh kiosk and folder)")->check(CLI::PositiveNumber);
  CLI11_PARSE(cli, argc, argv);
  spdlog::set_level(spdlog::level::warn);
  const fs::path work = fs::temp_directory_path() / ("hk_bench_reload_" + std::to_string(::getpid()));
  std::vector<Run> runs;
  for (int i = 0; i < repeats; ++i) runs.push_back(one_run(work));
  fs::remove_all(work);
  std::string md =
      "# A library change of 100 pictures\n\n"
      "`build/bench/bench_library_reload` (bench/library_reload.cpp): 100 pictures (tests/data/images cycled) copied "
      "into the watched library folder of a running kiosk (headless, servo at 1 kHz, window thread at 60 Hz), each "
      "as a hidden temporary file renamed to its name. *Live* is from the last rename to all 100 listed (quiet "
      "time 2 s included); *frame* is the window thread's work per frame meanwhile. Target: live within 5 s, no "
      "frame over 20 ms.\n\n"
      "| run | copied [MB] | live [ms] | frames | frame p99 [ms] | frame max [ms] |\n|---|---|---|---|---|---|\n";
  char line[256];
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const Run& r = runs[i];
    std::snprintf(line, sizeof line, "| %zu | %.1f | %.0f | %d | %.2f | %.2f |\n", i + 1,
                  static_cast<double>(r.bytes) / 1e6, r.live_ms, r.frames, r.frame_p99_ms, r.frame_max_ms);
    md += line;
  }
  std::fputs(md.c_str(), stdout);
  if (!out.empty()) std::ofstream(out) << md;
  return 0;
}
