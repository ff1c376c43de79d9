// Time from a still page under the camera to its scene being felt.
//
// Each picture is photographed synthetically (tests/support/synthetic_photo.hpp: on a wooden table, turned
// 12 degrees, a little keystone, blur, noise and uneven light) at the camera's default 1280 x 960, written as a
// one-frame folder, and captured through the file source exactly as `haptic-kiosk capture` does (run_capture:
// look_at_frame on every frame, the framing guide, rectify_page), then built into a scene
// (build_image_scene_from_picture). The guide waits [camera] still_s (1 s) of frame time after the first still
// frame; the rest is wall time on this machine:
//
//   felt_s = still_s + one frame period (30 fps camera: the frame that ends the wait) + look_ms of that frame
//            + rectify_ms + build_ms;
// the new scene's force then ramps in over [haptics] force_ramp_s, felt from its first tick.
//
//   build/bench/bench_capture_latency [--out FILE.json]     prints a Markdown table (one row per picture)
//   build/bench/bench_capture_latency --write-frame DIR     writes the horse's photo as DIR/frame.jpg and stops
//                                                          (tests/data/camera/still, the README's example)
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pictures/capture.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/runtime_params.hpp"
#include "synthetic_photo.hpp"
#include "test_paths.hpp"

using namespace hk;
using namespace hk::app;
namespace fs = std::filesystem;

int main(int argc, char** argv) {
  std::string out_json, write_frame;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--out") out_json = argv[i + 1];
    if (std::string(argv[i]) == "--write-frame") write_frame = argv[i + 1];
  }
  constexpr double kCameraFrameS = 1.0 / 30.0;
  const config::Settings s;
  const fs::path tmp = fs::temp_directory_path() / ("hk_bench_capture_" + std::to_string(::getpid()));
  nlohmann::json rows = nlohmann::json::array();
  std::printf(
      "| picture | frame | found | look ms/frame | rectify ms | build ms | shapes | still page → felt s "
      "|\n|---|---|---|---|---|---|---|---|\n");
  for (const char* name :
       {"horse.png", "coins.png", "page.png", "apple.jpg", "butterfly.jpg", "silhouette_3.png", "sudoku.png"}) {
    const cv::Mat picture = cv::imread((fs::path(HK_TEST_DATA_DIR) / "images" / name).string(), cv::IMREAD_COLOR);
    test::PhotoConditions c;
    c.rotation_deg = 12;
    c.perspective = 0.06;
    c.blur_sigma_px = 0.8;
    c.noise_sigma = 3;
    c.uneven_light = true;
    const test::SyntheticPhoto photo = test::synthetic_photo(picture, cv::Size(1280, 960), c);
    if (!write_frame.empty()) {
      fs::create_directories(write_frame);
      return cv::imwrite((fs::path(write_frame) / "frame.jpg").string(), photo.frame, {cv::IMWRITE_JPEG_QUALITY, 90})
                 ? 0
                 : 1;
    }
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    cv::imwrite((tmp / "frame.png").string(), photo.frame);
    std::unique_ptr<vision::FrameSource> src =
        vision::open_frame_source(vision::parse_source_spec("file:" + tmp.string()), frame_source_params_from(s));
    const CaptureOutcome o = run_capture(*src, capture_params_from(s));
    const auto t0 = std::chrono::steady_clock::now();
    const ImageScene is = build_image_scene_from_picture(o.image, name, s);
    const double build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const double look_ms = o.frames > 0 ? o.look_ms / o.frames : 0.0;
    const double felt_s = s.camera.still_s + kCameraFrameS + (look_ms + o.rectify_ms + build_ms) / 1000.0;
    std::printf("| %s | 1280 x 960 | %s | %.1f | %.1f | %.1f | %zu | %.2f |\n", name, o.rectified ? "yes" : "no",
                look_ms, o.rectify_ms, build_ms, is.scene->curve_count(), felt_s);
    rows.push_back({{"picture", name},
                    {"found", o.rectified},
                    {"look_ms", look_ms},
                    {"rectify_ms", o.rectify_ms},
                    {"build_ms", build_ms},
                    {"shapes", is.scene->curve_count()},
                    {"still_s", s.camera.still_s},
                    {"felt_s", felt_s}});
  }
  fs::remove_all(tmp);
  if (!out_json.empty()) std::ofstream(out_json) << rows.dump(2) << "\n";
  return 0;
}
