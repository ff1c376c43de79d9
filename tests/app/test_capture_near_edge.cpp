// A page that fills the camera's frame, captured end to end: a page of a shipped PDF (pdftoppm at 300 dpi) warped
// into 3264 x 2448 camera frames (perspective, uneven light, sensor noise that differs from frame to frame, a
// wooden table), lying whole with its bottom corner 40 px (1.6 %) from the frame's bottom edge, served by the file
// source at 10 frames a second. It is not cut off: the guide says nothing, run_capture takes it by stillness within
// 3 s of frame time with the page's own corners, and OCR of the rectified page (outcome.image, full resolution)
// reads at least 90 % of the words pdftotext gives for that page; `explore --source` on the same frames writes
// those text blocks ("source": "ocr") in scene.json.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "kiosk_exe.hpp"
#include "pictures/capture.hpp"
#include "scans.hpp"
#include "synthetic_photo.hpp"
#include "test_paths.hpp"
#include "vision/frame_source.hpp"
#include "vision/ocr.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;

const fs::path kSpec = fs::path(HK_TEST_DATA_DIR) / "documents" / "shared-mime-info-spec.pdf";
constexpr int kPage = 3;
const cv::Size kCamera(3264, 2448);

TEST(CaptureNearTheEdge, AWholePageFillingTheFrameIsCapturedByStillnessAndItsTextRead) {
  if (!test::have_poppler_utils())
    GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  if (const std::string problem = vision::ocr_languages_problem({}); !problem.empty()) GTEST_SKIP() << problem;
  const fs::path dir = test::fresh_dir("capture_near_edge");
  const cv::Mat page = test::draw_page(kSpec, kPage, 300, dir);
  ASSERT_FALSE(page.empty());
  const std::vector<std::string> truth = test::words_of(test::pdftotext_page(kSpec, kPage, dir));
  ASSERT_GT(truth.size(), 200u);

  // The page on a wooden table, turned 3°, in perspective, lit unevenly, its lowest corner 40 px above the bottom.
  test::PhotoConditions pc;
  pc.rotation_deg = 3;
  pc.perspective = 0.06;
  pc.blur_sigma_px = 1.0;
  pc.uneven_light = true;
  pc.backdrop = test::Backdrop::wood;
  pc.seed = 5;
  pc.fill = 0.95;
  const test::SyntheticPhoto photo =
      test::synthetic_photo(page, kCamera, test::near_edge(page.size(), kCamera, pc, 2, 40.0));
  double lowest = -1e300;
  for (const cv::Point2d& c : photo.corners_px) {
    ASSERT_TRUE(c.x > -0.5 && c.y > -0.5 && c.x < kCamera.width - 0.5 && c.y < kCamera.height - 0.5)
        << "the page lies whole in the frame: " << c;
    lowest = std::max(lowest, c.y);
  }
  ASSERT_NEAR(kCamera.height - 0.5 - lowest, 40.0, 1e-6);
  // Held still: the same scene in every frame, each with its own sensor noise (seeded), as JPEG from the camera.
  const fs::path frames = dir / "frames";
  fs::create_directories(frames);
  for (int i = 0; i < 5; ++i) {
    cv::Mat noise(kCamera, CV_16SC3), noisy;
    cv::RNG rng(700 + static_cast<std::uint64_t>(i));
    rng.fill(noise, cv::RNG::NORMAL, 0, 4);
    photo.frame.convertTo(noisy, CV_16SC3);
    noisy += noise;
    noisy.convertTo(noisy, CV_8UC3);
    char name[32];
    std::snprintf(name, sizeof name, "frame_%03d.jpg", i);
    ASSERT_TRUE(cv::imwrite((frames / name).string(), noisy, {cv::IMWRITE_JPEG_QUALITY, 92}));
  }

  vision::FrameSourceParams sp;
  sp.file_fps = 10.0;
  const auto source = vision::open_frame_source(vision::parse_source_spec("file:" + frames.string()), sp);
  CaptureParams params;
  params.timeout_s = 6.0;  // twice the time it may take: a page told it is cut off fails here, not after a minute
  const CaptureOutcome o = run_capture(*source, params);
  std::string said;
  for (vision::FramingAdvice a : o.advice) said += std::string(vision::advice_name(a)) + " ";
  EXPECT_EQ(o.end, CaptureEnd::Still) << capture_end_name(o.end) << "; said: " << said;
  EXPECT_TRUE(o.advice.empty()) << "said: " << said;
  const double taken_after_s = o.captured_t_s - o.first_frame_t_s;
  EXPECT_LE(taken_after_s, 3.0);
  ASSERT_TRUE(o.rectified);
  ASSERT_TRUE(o.corners_px.has_value());
  double worst_px = 0.0;
  for (std::size_t k = 0; k < 4; ++k) worst_px = std::max(worst_px, cv::norm((*o.corners_px)[k] - photo.corners_px[k]));
  EXPECT_LE(worst_px, 3.0) << "the page's own corners";

  cv::Mat grey;
  cv::cvtColor(o.image, grey, cv::COLOR_BGR2GRAY);
  const vision::OcrResult r = vision::recognise_text(grey, "capture", {});
  std::string text;
  for (const vision::OcrBlock& b : r.blocks) text += b.text + "\n";
  const double recall = test::word_recall(truth, test::words_of(text));
  std::printf(
      "[capture near edge] captured by %s after %.1f s of frame time (%d frames, %zu things said), corners within %.2f "
      "px, "
      "page %d x %d px, OCR recall %.3f of %zu words\n",
      capture_end_name(o.end), taken_after_s, o.frames, o.advice.size(), worst_px, o.image.cols, o.image.rows, recall,
      truth.size());
  EXPECT_GE(recall, 0.9) << text.substr(0, 600);

  // The same frames through `explore --source`: the capture's text blocks in scene.json, read by OCR.
  const test::ExeResult run = test::run_kiosk("explore --source " + test::quoted("file:" + frames.string()) +
                                                  " --out " + test::quoted(dir / "out") + " --duration 0.5",
                                              dir);
  ASSERT_EQ(run.status, 0) << run.err;
  std::ifstream sf(dir / "out" / "summary.json"), jf(dir / "out" / "scene.json");
  const nlohmann::json summary = nlohmann::json::parse(sf), scene = nlohmann::json::parse(jf);
  EXPECT_EQ(summary["ocr"]["ran"], true) << summary["ocr"].dump();
  EXPECT_EQ(summary["ocr"]["why"], "a page of text");
  ASSERT_GE(scene["text_blocks"].size(), 3u);
  std::string explored;
  for (const auto& b : scene["text_blocks"]) {
    EXPECT_EQ(b["source"], "ocr");
    explored += b["text"].get<std::string>() + "\n";
  }
  EXPECT_GE(test::word_recall(truth, test::words_of(explored)), 0.9);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace hk::app
