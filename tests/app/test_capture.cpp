// Camera capture end to end: frame sequences written to a folder and served by the file source
// (`--source file:DIR`, 10 frames a second), through `haptic-kiosk capture` and `explore --source`: what the
// guide says, in order, when it captures, and what it writes; then the kiosk's runtime capturing from the same
// kind of source on its worker thread.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "kiosk_exe.hpp"
#include "pictures/capture.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;
using test::fresh_dir;
using test::quoted;
using test::run_kiosk;

constexpr int kW = 640, kH = 480;

/// A table top: a mid-grey wood-like texture (slanted stripes and noise), the same for every frame.
cv::Mat table() {
  cv::Mat t(kH, kW, CV_8UC3);
  cv::RNG rng(7);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const double v = 80 + 18 * std::sin(0.09 * x + 0.03 * y + 2.0 * std::sin(0.013 * y)) + rng.gaussian(4.0);
      const auto g = cv::saturate_cast<uchar>(v);
      t.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(v * 0.8), g, cv::saturate_cast<uchar>(v * 1.1));
    }
  return t;
}

/// The card the visitor holds: a test picture on white with a 10 px margin, 280 x 210 px.
cv::Mat card() {
  cv::Mat pic = cv::imread((fs::path(HK_TEST_DATA_DIR) / "images" / "horse.png").string(), cv::IMREAD_COLOR);
  cv::Mat c(210, 280, CV_8UC3, cv::Scalar(245, 245, 245));
  cv::resize(pic, pic, cv::Size(260, 190), 0, 0, cv::INTER_AREA);
  pic.copyTo(c(cv::Rect(10, 10, 260, 190)));
  return c;
}

/// A frame with the card's centre at (cx, cy) (parts outside the frame cut off), lit by `light`.
cv::Mat frame_with_card(const cv::Mat& bg, const cv::Mat& c, int cx, int cy, double light = 1.0) {
  cv::Mat f = bg.clone();
  const cv::Rect where(cx - c.cols / 2, cy - c.rows / 2, c.cols, c.rows);
  const cv::Rect inside = where & cv::Rect(0, 0, kW, kH);
  c(cv::Rect(inside.x - where.x, inside.y - where.y, inside.width, inside.height)).copyTo(f(inside));
  if (light != 1.0) f.convertTo(f, -1, light);
  return f;
}

/// Writes the frames as DIR/frame_000.png, frame_001.png, ...
void write_frames(const fs::path& dir, const std::vector<cv::Mat>& frames) {
  fs::create_directories(dir);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%03zu.png", i);
    ASSERT_TRUE(cv::imwrite((dir / name).string(), frames[i]));
  }
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream f(p);
  return nlohmann::json::parse(f);
}

std::vector<std::string> advice_of(const nlohmann::json& j) { return j.at("advice").get<std::vector<std::string>>(); }

/// Runs `capture` on the frames; returns capture.json.
nlohmann::json capture(const std::string& name, const std::vector<cv::Mat>& frames) {
  const fs::path dir = fresh_dir(name);
  write_frames(dir / "frames", frames);
  const test::ExeResult r =
      run_kiosk("capture --source file:" + (dir / "frames").string() + " --out " + quoted(dir / "out"), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  if (r.status != 0) return nlohmann::json::object();
  EXPECT_TRUE(fs::exists(dir / "out" / "capture.png"));
  return read_json(dir / "out" / "capture.json");
}

TEST(Capture, AStillWholePageIsCapturedAfterOneSecondRectified) {
  const cv::Mat bg = table(), c = card();
  const nlohmann::json j =
      capture("cap_still", {frame_with_card(bg, c, kW / 2, kH / 2)});  // one frame, served again and again
  ASSERT_FALSE(j.empty());
  EXPECT_TRUE(advice_of(j).empty()) << j.dump();
  EXPECT_EQ(j.at("captured_by"), "still");
  EXPECT_NEAR(j.at("captured_t_s").get<double>(), 1.1, 1e-9)
      << "still from the second frame (0.1 s), captured 1 s later";
  ASSERT_TRUE(j.at("rectified").get<bool>());
  ASSERT_EQ(j.at("corners_px").size(), 4u);
  // The corners are the card's, within 1 % of its diagonal.
  const double diag = std::hypot(280.0, 210.0);
  const cv::Point2d truth[4] = {
      {180 - 0.5, 135 - 0.5}, {460 - 0.5, 135 - 0.5}, {460 - 0.5, 345 - 0.5}, {180 - 0.5, 345 - 0.5}};
  for (int k = 0; k < 4; ++k) {
    const cv::Point2d got(j["corners_px"][k][0].get<double>(), j["corners_px"][k][1].get<double>());
    EXPECT_LT(cv::norm(got - truth[k]), 0.01 * diag) << "corner " << k << " at " << got;
  }
  EXPECT_NEAR(j.at("width_px").get<double>() / j.at("height_px").get<double>(), 280.0 / 210.0, 0.02);
}

/// A camera whose preview is `preview` (10 frames a second) and whose still is `full`, the same scene at a larger
/// size, as a libcamera or V4L2 camera gives them; counts the stills asked for.
struct TwoSizeCamera final : vision::FrameSource {
  cv::Mat preview, full;
  bool still_fails = false;
  int stills = 0;
  std::uint64_t n = 0;
  std::string name() const override { return "two-size camera"; }
  bool next(vision::Frame& out, double) override {
    out.bgr = preview.clone();
    out.t_s = 0.1 * static_cast<double>(n);
    out.index = n++;
    return true;
  }
  bool still(vision::Frame& out, double) override {
    ++stills;
    if (still_fails) throw vision::CameraError("camera 'two-size': cannot set the still's size");
    out.bgr = full.clone();
    out.t_s = 0.1 * static_cast<double>(n);
    out.index = n++;
    return true;
  }
};

TEST(Capture, ThePageIsRectifiedFromTheCamerasFullSizeStillNotThePreview) {
  const cv::Mat bg = table(), c = card();
  TwoSizeCamera cam;
  cam.preview = frame_with_card(bg, c, kW / 2, kH / 2);
  cv::resize(cam.preview, cam.full, cv::Size(2 * kW, 2 * kH), 0, 0, cv::INTER_CUBIC);
  CaptureParams params;
  const CaptureOutcome o = run_capture(cam, params);
  ASSERT_EQ(o.end, CaptureEnd::Still);
  EXPECT_EQ(cam.stills, 1) << "one still, when the guide captures";
  EXPECT_TRUE(o.from_still);
  EXPECT_EQ(o.frame.size(), cam.full.size());
  ASSERT_TRUE(o.rectified && o.corners_px);
  // The card's corners in the still's pixels (twice the preview's), and the page at the still's detail.
  const cv::Point2d truth[4] = {{359, 269}, {919, 269}, {919, 689}, {359, 689}};
  for (int k = 0; k < 4; ++k) EXPECT_LT(cv::norm((*o.corners_px)[k] - truth[k]), 0.01 * 2 * std::hypot(280.0, 210.0));
  EXPECT_NEAR(o.image.cols, 2 * 280, 0.05 * 2 * 280) << "rectified at the still's resolution";
  // A camera whose still fails keeps the preview frame: the capture is not lost.
  TwoSizeCamera broken = cam;
  broken.still_fails = true;
  broken.stills = 0;
  broken.n = 0;
  const CaptureOutcome kept = run_capture(broken, params);
  EXPECT_EQ(kept.end, CaptureEnd::Still);
  EXPECT_EQ(broken.stills, 1);
  EXPECT_FALSE(kept.from_still);
  EXPECT_EQ(kept.frame.size(), cam.preview.size());
  EXPECT_TRUE(kept.rectified);
}

TEST(Capture, OffCentreThenCentredSaysMoveLeftThenCaptures) {
  const cv::Mat bg = table(), c = card();
  std::vector<cv::Mat> frames;
  for (int i = 0; i < 8; ++i) frames.push_back(frame_with_card(bg, c, 470, kH / 2));           // well right of centre
  for (int x = 450; x > kW / 2; x -= 30) frames.push_back(frame_with_card(bg, c, x, kH / 2));  // slid left
  frames.push_back(frame_with_card(bg, c, kW / 2, kH / 2));                                    // then left there
  const nlohmann::json j = capture("cap_left", frames);
  ASSERT_FALSE(j.empty());
  const std::vector<std::string> said = advice_of(j);
  ASSERT_FALSE(said.empty());
  EXPECT_EQ(said.front(), "move_left");
  EXPECT_EQ(j.at("guidance")[0], "Move it left.");
  for (const std::string& a : said) EXPECT_TRUE(a == "move_left" || a == "hold_still") << a;
  EXPECT_EQ(j.at("captured_by"), "still");
  const double settled_s = 0.1 * static_cast<double>(frames.size() - 1);
  EXPECT_GT(j.at("captured_t_s").get<double>(), settled_s + 0.95);
  EXPECT_LT(j.at("captured_t_s").get<double>(), settled_s + 1.25);
}

TEST(Capture, CutOffAtTheTopIsSaidFirst) {
  const cv::Mat bg = table(), c = card();
  std::vector<cv::Mat> frames;
  for (int i = 0; i < 5; ++i) frames.push_back(frame_with_card(bg, c, kW / 2, 60));  // its top is off the frame
  frames.push_back(frame_with_card(bg, c, kW / 2, kH / 2));
  const nlohmann::json j = capture("cap_top", frames);
  ASSERT_FALSE(j.empty());
  const std::vector<std::string> said = advice_of(j);
  ASSERT_FALSE(said.empty());
  EXPECT_EQ(said.front(), "cut_off_top");
  EXPECT_EQ(j.at("captured_by"), "still");
}

TEST(Capture, TooDarkIsSaidUntilTheLightComesOn) {
  const cv::Mat bg = table(), c = card();
  std::vector<cv::Mat> frames;
  for (int i = 0; i < 5; ++i) frames.push_back(frame_with_card(bg, c, kW / 2, kH / 2, 0.15));
  frames.push_back(frame_with_card(bg, c, kW / 2, kH / 2));
  const nlohmann::json j = capture("cap_dark", frames);
  ASSERT_FALSE(j.empty());
  ASSERT_FALSE(advice_of(j).empty());
  EXPECT_EQ(advice_of(j).front(), "too_dark");
  EXPECT_EQ(j.at("guidance")[0], "It is too dark to see the picture.");
  EXPECT_EQ(j.at("captured_by"), "still");
  EXPECT_GE(j.at("captured_t_s").get<double>(), 0.5 + 1.0);
}

TEST(Capture, AShakingPageIsToldToHoldStill) {
  const cv::Mat bg = table(), c = card();
  std::vector<cv::Mat> frames;
  for (int i = 0; i < 12; ++i)
    frames.push_back(frame_with_card(bg, c, kW / 2 + (i % 2 ? 12 : -12), kH / 2 + (i % 3) * 6));
  frames.push_back(frame_with_card(bg, c, kW / 2, kH / 2));
  const nlohmann::json j = capture("cap_shake", frames);
  ASSERT_FALSE(j.empty());
  ASSERT_FALSE(advice_of(j).empty());
  EXPECT_EQ(advice_of(j).front(), "hold_still");
  EXPECT_GE(j.at("captured_t_s").get<double>(), 1.2 + 1.0) << "not while it shook";
}

TEST(Capture, AnEmptyTableIsNeverCapturedAndTheTimeOutKeepsTheLastFrame) {
  const fs::path dir = fresh_dir("cap_empty");
  write_frames(dir / "frames", {table()});
  std::ofstream(dir / "settings.toml") << "[camera]\ntimeout_s = 5\n";
  const test::ExeResult r = run_kiosk("capture --source file:" + (dir / "frames").string() + " --out " +
                                          quoted(dir / "out") + " --config " + quoted(dir / "settings.toml"),
                                      dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = read_json(dir / "out" / "capture.json");
  EXPECT_EQ(j.at("captured_by"), "timeout");
  EXPECT_FALSE(j.at("rectified").get<bool>());
  EXPECT_TRUE(j.at("corners_px").is_null());
  EXPECT_EQ(advice_of(j).front(), "place");
}

TEST(Capture, BadSourcesAreRefusedInOneLine) {
  const fs::path dir = fresh_dir("cap_bad");
  for (const std::string& src :
       {std::string("usb:1"), std::string("file:") + (dir / "missing").string(), std::string("v4l2:/dev/null")}) {
    const test::ExeResult r =
        run_kiosk("capture --source " + test::quoted(fs::path(src)) + " --out " + quoted(dir / "out"), dir);
    EXPECT_EQ(r.status, 1) << src;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("camera"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out" / "capture.png")) << src;
  }
}

TEST(Capture, CamerasListsNoneQuietlyOnAMachineWithout) {
  const fs::path dir = fresh_dir("cap_cameras");
  const std::string out = (dir / "out.txt").string();
  const int raw =
      std::system((std::string(HK_KIOSK_EXE) + " cameras >" + out + " 2>" + (dir / "err.txt").string()).c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  EXPECT_EQ(WEXITSTATUS(raw), 0);
  std::ifstream f(out);
  const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (vision::list_cameras().empty()) {
    EXPECT_EQ(text, "no camera found\n");
  }
  std::ifstream e(dir / "err.txt");
  const std::string err((std::istreambuf_iterator<char>(e)), std::istreambuf_iterator<char>());
  EXPECT_EQ(err, "") << "nothing printed besides the answer";
}

TEST(Capture, ExploreFromASourceBuildsTheSceneOfTheRectifiedPage) {
  const cv::Mat bg = table(), c = card();
  const fs::path dir = fresh_dir("cap_explore");
  write_frames(dir / "frames", {frame_with_card(bg, c, kW / 2, kH / 2)});
  const test::ExeResult r = run_kiosk(
      "explore --source file:" + (dir / "frames").string() + " --out " + quoted(dir / "out") + " --duration 1", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json scene = read_json(dir / "out" / "scene.json");
  const nlohmann::json cap = read_json(dir / "out" / "capture.json");
  EXPECT_TRUE(cap.at("rectified").get<bool>());
  EXPECT_EQ(scene.at("image").at("width_px"), cap.at("width_px"));
  // The horse is one closed outline, as from the file itself; the table's texture and the card's edge are not shapes.
  ASSERT_GE(scene.at("curves").size(), 1u);
  EXPECT_LE(scene.at("curves").size(), 3u) << scene.at("curves").size();
  EXPECT_TRUE(fs::exists(dir / "out" / "trace.csv"));
}

/// A runtime with no sound card, no USB watch and no USB pantograph, on the test pictures.
RuntimeOptions headless_options() {
  RuntimeOptions ro;
  ro.library = std::string(HK_TEST_DATA_DIR) + "/images";
  ro.hotplug = false;
  ro.open_audio_output = false;
  ro.probe_usb_device = false;
  return ro;
}

/// Waits (bounded) for the runtime's capture to end, polling its news into the flow as the window does.
void poll_until_done(KioskRuntime& rt, KioskFlow& flow) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  double t = 1.0;
  while (flow.view().capturing && std::chrono::steady_clock::now() < give_up) {
    rt.camera().poll(flow, t += 0.01);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

TEST(CaptureRuntime, TheKioskCapturesFromItsCameraAndPutsThePictureOnTheDevice) {
  const cv::Mat bg = table(), c = card();
  const fs::path dir = fresh_dir("cap_runtime");
  write_frames(dir / "frames", {frame_with_card(bg, c, 520, kH / 2), frame_with_card(bg, c, kW / 2, kH / 2)});
  config::Settings s;
  s.camera.source = "file:" + (dir / "frames").string();
  KioskRuntime rt(headless_options(), s);
  ASSERT_TRUE(rt.camera().available());
  KioskFlowParams fp;
  fp.camera = rt.camera().available();
  KioskFlow flow(rt.effects(), rt.audio().messages(), fp);
  flow.key(KioskKey::Other, 0.0);
  flow.key(KioskKey::Capture, 0.5);
  ASSERT_TRUE(flow.view().capturing);
  poll_until_done(rt, flow);
  ASSERT_FALSE(flow.view().capturing);
  EXPECT_EQ(rt.voice().last_said().rfind("Captured.", 0), 0u) << rt.voice().last_said();
  EXPECT_LE(rt.stage().shown_id(), -100) << "the capture is what is shown";
  EXPECT_FALSE(rt.stage().shown().picture.empty());
  EXPECT_GE(rt.stage().shown().polylines.size(), 1u);
  // A second capture, cancelled by a key at once: nothing more is said of it but "Capture stopped.".
  flow.key(KioskKey::Capture, 50.0);
  flow.key(KioskKey::Next, 50.1);
  EXPECT_EQ(rt.voice().last_said(), "Capture stopped.");
  rt.camera().poll(flow, 50.2);
  EXPECT_EQ(rt.voice().last_said(), "Capture stopped.");
}

TEST(CaptureRuntime, ScriptedRunsLookForNoCameraAndSayNothingOfIt) {
  config::Settings s;  // [camera] source = "auto"
  KioskRuntime rt(headless_options(), s);
  EXPECT_FALSE(rt.camera().available());
  rt.camera().announce(rt.settings().keys);
  EXPECT_EQ(rt.voice().last_said(), "");
  EXPECT_FALSE(rt.camera().start_capture());
}

}  // namespace
}  // namespace hk::app
