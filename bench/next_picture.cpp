// Picture chosen -> felt: the kiosk's own runtime, headless, with its servo thread at 1 kHz on the simulated
// pantograph (the handle at rest in free space), driven by the visitor's flow. Each Next press is timed from
// the key to the first servo tick on the new scene (ServoDisplayState::scene_id). The window thread is
// played as the kiosk plays it: the flow's key, then the library's and the sticks' poll once a frame (60 Hz), so a
// scene built off the window thread waits up to one frame to be put on the device, as at the kiosk. The
// screen is a 1920 x 1080 one: pictures are shrunk to the size it draws them (picture_side_px), as there.
//
// Three ways a picture can be at hand:
//   cold       nothing built ahead, no scene cache ([kiosk] prefetch_mb = 0, scene_cache off);
//   prefetched the visitor lingers on each picture until its neighbours are built ahead (prefetch_mb 256);
//   cached     a fresh runtime (a reboot) over a scene cache filled by an earlier run, nothing built ahead.
// Pictures: every picture of tests/data/images, and generated real-size stand-ins for what visitors bring:
// 24-megapixel phone photos (6000 x 4000 JPEG q92: fruits.jpg and butterfly.jpg upscaled, with sensor-like
// noise), a 12-megapixel one (4000 x 3000), and a 13-megapixel PNG (3723 x 3595) as a photo and as a
// chessboard. Stick pages: a 51-page PDF (shared-mime-info-spec.pdf three times, pdfunite) on a folder
// standing in for a stick, paged through with Next, cold and with the pages Next leads to built ahead.
// Usage: bench_next_picture [--repeats N] [--out FILE.md] [--quick]
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <spdlog/spdlog.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pictures/view_geometry.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"

using namespace hk;
using namespace hk::app;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kFrame_s = 1.0 / 60.0;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

/// fruits.jpg (or another) upscaled to w x h with a little Gaussian noise, as a phone's sensor leaves it.
cv::Mat photo(const std::string& name, int w, int h) {
  const cv::Mat src = cv::imread(std::string(HK_TEST_DATA_DIR) + "/images/" + name, cv::IMREAD_COLOR);
  cv::Mat big, noise(cv::Size(w, h), CV_16SC3), wide;
  cv::resize(src, big, {w, h}, 0, 0, cv::INTER_CUBIC);
  cv::randn(noise, 0, 4);
  big.convertTo(wide, CV_16SC3);
  wide += noise;
  wide.convertTo(big, CV_8UC3);
  return big;
}

cv::Mat chessboard(int w, int h, int square_px) {
  cv::Mat m(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      m.at<cv::Vec3b>(y, x) = ((y / square_px + x / square_px) % 2) ? cv::Vec3b(255, 255, 255) : cv::Vec3b(0, 0, 0);
  return m;
}

/// The library: tests/data/images, then the generated big pictures (names sort after the small ones).
void make_library(const fs::path& lib, bool quick) {
  fs::create_directories(lib);
  for (const auto& e : fs::directory_iterator(fs::path(HK_TEST_DATA_DIR) / "images"))
    if (!quick || e.path().filename() == "horse.png" || e.path().filename() == "fruits.jpg")
      fs::copy_file(e.path(), lib / e.path().filename());
  cv::imwrite((lib / "zz_phone24_fruits.jpg").string(), photo("fruits.jpg", 6000, 4000),
              {cv::IMWRITE_JPEG_QUALITY, 92});
  if (quick) return;
  cv::imwrite((lib / "zz_phone24_butterfly.jpg").string(), photo("butterfly.jpg", 6000, 4000),
              {cv::IMWRITE_JPEG_QUALITY, 92});
  cv::imwrite((lib / "zz_phone12_apple.jpg").string(), photo("apple.jpg", 4000, 3000), {cv::IMWRITE_JPEG_QUALITY, 92});
  cv::imwrite((lib / "zz_png13_photo.png").string(), photo("fruits.jpg", 3723, 3595));
  cv::imwrite((lib / "zz_png13_chessboard.png").string(), chessboard(3723, 3595, 400));
}

struct Rig {
  std::unique_ptr<KioskRuntime> rt;
  std::unique_ptr<KioskFlow> flow;
  double now_s = 0;
  Rig(const fs::path& lib, int prefetch_mb, const std::string& cache_dir) {
    RuntimeOptions ro;
    ro.library = lib.string();
    ro.hotplug = false;
    ro.open_audio_output = false;
    ro.probe_usb_device = false;
    ro.scene_cache_dir = cache_dir;
    config::Settings s;
    s.kiosk.prefetch_mb = prefetch_mb;
    s.kiosk.timeout_s = 3600;
    rt = std::make_unique<KioskRuntime>(ro, s);
    // Pictures shrunk to what a full-HD kiosk screen draws, as the kiosk's window sets it.
    rt->set_screen_picture_side_px(picture_side_px(make_view(1920, 1080, rt->half()), rt->half()));
    flow = std::make_unique<KioskFlow>(rt->effects(), rt->audio().messages(), KioskFlowParams{});
    rt->start_servo();
  }
  ~Rig() {
    rt->devices().stop_servo();
    flow.reset();
    rt.reset();
  }
  /// One frame of the window thread's polling.
  void frame() {
    now_s += kFrame_s;
    rt->library().poll(flow.get(), now_s);
    rt->sticks().poll(*flow, now_s);
    rt->stage().poll_text(now_s);
    rt->core().collect_retired();
  }
  /// Presses `key` and returns the ms until the first servo tick on scene `id` (frames played meanwhile).
  double press_until_felt(KioskKey key, int id) {
    const Clock::time_point t0 = Clock::now();
    flow->key(key, now_s);
    Clock::time_point next_frame = t0;
    for (;;) {
      if (rt->core().display().scene_id == id) return ms_between(t0, Clock::now());
      const Clock::time_point now = Clock::now();
      if (now >= next_frame) {
        frame();
        next_frame += std::chrono::microseconds(16667);
      }
      if (ms_between(t0, now) > 60000) return -1;
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
  }
  /// Frames until nothing waits (a picture asked for, its neighbours built ahead).
  void linger(double max_s) {
    const Clock::time_point t0 = Clock::now();
    while (ms_between(t0, Clock::now()) < max_s * 1000) {
      frame();
      std::this_thread::sleep_for(std::chrono::microseconds(16667));
      if (!rt->library().busy() && rt->library().ahead().size() >= 2) return;
    }
  }
};

struct Row {
  std::string name;
  std::uintmax_t bytes = 0;
  int w = 0, h = 0;
  std::vector<double> cold, prefetched, cached;
};

double median(std::vector<double> v) {
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double p95(std::vector<double> v) {
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(0.95 * static_cast<double>(v.size() - 1) + 0.999))];
}

/// Walks the whole library with Next from picture 1 (the tutorial first), `repeats` times; each press's
/// time goes to the picture shown by it. `linger`: wait on each picture until its neighbours are built ahead.
void walk(Rig& r, int pictures, int repeats, bool linger, std::vector<std::vector<double>>& out) {
  r.flow->key(KioskKey::Other, r.now_s);
  for (int i = 0; i < 2; ++i) r.flow->key(KioskKey::Next, r.now_s);  // square -> circle -> triangle
  r.press_until_felt(KioskKey::Next, 0);                             // picture 1
  for (int rep = 0; rep < repeats; ++rep) {
    for (int i = 1; i <= pictures; ++i) {
      if (linger) r.linger(30.0);
      const int id = i % pictures;
      out[static_cast<std::size_t>(id)].push_back(r.press_until_felt(KioskKey::Next, id));
      r.frame();
    }
  }
}

/// Pages 2-51 of the stick's PDF paged through with Next from page 1, each timed key -> felt. With
/// prefetch_mb > 0 the visitor lingers on each page until the pages Next and Previous lead to are built ahead.
std::vector<double> stick_walk(const fs::path& lib, const fs::path& stick, int prefetch_mb) {
  std::vector<double> out;
  Rig r(lib, prefetch_mb, "");
  r.flow->key(KioskKey::Other, r.now_s);
  r.rt->sticks().insert_folder(stick.string());
  const Clock::time_point t0 = Clock::now();
  while (r.rt->core().display().scene_id != 1000 + 1 && ms_between(t0, Clock::now()) < 60000) {
    r.frame();
    std::this_thread::sleep_for(std::chrono::microseconds(16667));
  }
  for (int page = 2; page <= 51; ++page) {
    const Clock::time_point l0 = Clock::now();
    while (prefetch_mb > 0 && r.rt->sticks().service().pages_ahead() < 2 && ms_between(l0, Clock::now()) < 30000) {
      r.frame();
      std::this_thread::sleep_for(std::chrono::microseconds(16667));
    }
    out.push_back(r.press_until_felt(KioskKey::Next, 1000 + page));
    r.linger(0.0);
  }
  return out;
}

std::string ms_text(double ms) {
  char b[32];
  std::snprintf(b, sizeof b, "%.0f", ms);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out_path;
  int repeats = 3;
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) out_path = argv[++i];
    if (a == "--repeats" && i + 1 < argc) repeats = std::max(1, std::atoi(argv[++i]));
    if (a == "--quick") quick = true;
  }
  spdlog::set_level(spdlog::level::warn);
  const fs::path tmp = fs::temp_directory_path() / ("hk_bench_next_" + std::to_string(::getpid()));
  fs::remove_all(tmp);
  const fs::path lib = tmp / "library", cache = tmp / "cache";
  make_library(lib, quick);
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(lib)) files.push_back(e.path().filename().string());
  std::sort(files.begin(), files.end());
  const int n = static_cast<int>(files.size());
  std::vector<Row> rows(files.size());
  for (int i = 0; i < n; ++i) {
    rows[static_cast<std::size_t>(i)].name = files[static_cast<std::size_t>(i)];
    rows[static_cast<std::size_t>(i)].bytes = fs::file_size(lib / files[static_cast<std::size_t>(i)]);
    const cv::Mat m = cv::imread((lib / files[static_cast<std::size_t>(i)]).string(), cv::IMREAD_UNCHANGED);
    rows[static_cast<std::size_t>(i)].w = m.cols;
    rows[static_cast<std::size_t>(i)].h = m.rows;
  }
  std::vector<std::vector<double>> cold(files.size()), ahead(files.size()), cached(files.size());
  const auto peak_kb = [] {
    struct rusage u {};
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss;
  };
  {
    Rig r(lib, 0, "");
    walk(r, n, repeats, false, cold);
  }
  const long rss_cold_kb = peak_kb();
  {
    Rig r(lib, 256, "");
    walk(r, n, repeats, true, ahead);
  }
  const long rss_prefetch_kb = peak_kb();
  {
    Rig fill(lib, 0, cache.string());
    walk(fill, n, 1, false, cached);
  }  // fills the cache
  for (auto& v : cached) v.clear();
  {
    Rig r(lib, 0, cache.string());
    walk(r, n, repeats, false, cached);
  }  // a fresh start over it

  // Stick: a 51-page PDF paged through with Next, cold and built ahead.
  std::vector<double> stick_cold, stick_ahead;
  const fs::path stick = tmp / "stick";
  fs::create_directories(stick);
  const std::string spec = std::string(HK_TEST_DATA_DIR) + "/documents/shared-mime-info-spec.pdf";
  const std::string cmd =
      "pdfunite '" + spec + "' '" + spec + "' '" + spec + "' '" + (stick / "long.pdf").string() + "' 2>/dev/null";
  if (!quick && std::system(cmd.c_str()) == 0) {
    stick_cold = stick_walk(lib, stick, 0);
    stick_ahead = stick_walk(lib, stick, 256);
  }

  std::ostringstream md;
  md << "Generated by `build/bench/bench_next_picture --repeats " << repeats
     << "` (bench/next_picture.cpp): Next pressed, key -> first servo tick on the new scene [ms], median of " << repeats
     << " walks through the library; the window thread polls at 60 Hz.\n\n";
  md << "| picture | bytes | pixels | cold | cold, slowest walk | prefetched | cached "
        "|\n|---|---|---|---|---|---|---|\n";
  std::vector<double> all_cold, all_ahead, all_cached, small_cold, big_cold;
  for (int i = 0; i < n; ++i) {
    const Row& r = rows[static_cast<std::size_t>(i)];
    const std::size_t k = static_cast<std::size_t>(i);
    md << "| " << r.name << " | " << r.bytes << " | " << r.w << " x " << r.h << " | " << ms_text(median(cold[k]))
       << " | " << ms_text(*std::max_element(cold[k].begin(), cold[k].end())) << " | " << ms_text(median(ahead[k]))
       << " | " << ms_text(median(cached[k])) << " |\n";
    for (double v : cold[k]) (r.name.rfind("zz_png13", 0) == 0 ? big_cold : small_cold).push_back(v);
    all_ahead.insert(all_ahead.end(), ahead[k].begin(), ahead[k].end());
    all_cached.insert(all_cached.end(), cached[k].begin(), cached[k].end());
  }
  md << "\n| set | presses | p50 [ms] | p95 [ms] | max [ms] |\n|---|---|---|---|---|\n";
  const auto line = [&](const char* what, const std::vector<double>& v) {
    if (v.empty()) return;
    md << "| " << what << " | " << v.size() << " | " << ms_text(median(v)) << " | " << ms_text(p95(v)) << " | "
       << ms_text(*std::max_element(v.begin(), v.end())) << " |\n";
  };
  line("cold: tests/data pictures and JPEG phone photos", small_cold);
  line("cold: 13 MP PNGs", big_cold);
  line("cold: pages 2-51 of a 51-page PDF on a stick", stick_cold);
  line("prefetched", all_ahead);
  line("prefetched: pages 2-51 of a 51-page PDF on a stick", stick_ahead);
  line("cached (after a restart)", all_cached);
  md << "\nPeak resident memory of the process: " << rss_cold_kb / 1024 << " MiB after the cold walk, "
     << rss_prefetch_kb / 1024 << " MiB after the prefetched walk ([kiosk] prefetch_mb = 256).\n";
  std::fputs(md.str().c_str(), stdout);
  if (!out_path.empty()) std::ofstream(out_path) << md.str();
  fs::remove_all(tmp);
  return 0;
}
