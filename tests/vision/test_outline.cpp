// Two-tone pictures traced from a threshold: classify_two_tone and trace_outlines on synthetic
// masks whose outlines are known, and on the shipped pictures.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"
#include "test_paths.hpp"
#include "vision/outline.hpp"

namespace hk::vision {
namespace {

namespace fs = std::filesystem;
const fs::path kImages = fs::path(HK_TEST_DATA_DIR) / "images";

cv::Mat blank(int w = 200, int h = 150) { return cv::Mat(h, w, CV_8UC1, cv::Scalar(255)); }

/// Distance from p to the nearest crack between a dark (< 128) and a light pixel, 4-neighbours, by brute force.
double to_crack(const cv::Mat& g, cv::Point2d p) {
  double best = 1e9;
  for (int y = 0; y < g.rows; ++y)
    for (int x = 0; x < g.cols; ++x) {
      const bool d = g.at<std::uint8_t>(y, x) < 128;
      if (x + 1 < g.cols && d != (g.at<std::uint8_t>(y, x + 1) < 128))
        best = std::min(best, cv::norm(p - cv::Point2d(x + 0.5, y)));
      if (y + 1 < g.rows && d != (g.at<std::uint8_t>(y + 1, x) < 128))
        best = std::min(best, cv::norm(p - cv::Point2d(x, y + 0.5)));
    }
  return best;
}

}  // namespace

TEST(TwoTone, ABlackShapeOnWhiteIsTwoToneAndGradientsAndNoiseAreNot) {
  cv::Mat g = blank();
  cv::circle(g, {100, 75}, 40, cv::Scalar(0), cv::FILLED, cv::LINE_AA);  // anti-aliased rim: a few mid greys
  const TwoTone t = classify_two_tone(g);
  EXPECT_TRUE(t.two_tone);
  EXPECT_GT(t.threshold, 20);
  EXPECT_LT(t.threshold, 235);
  EXPECT_NEAR(t.dark_mean, 0.0, 10.0);
  EXPECT_NEAR(t.light_mean, 255.0, 10.0);

  cv::Mat ramp(150, 256, CV_8UC1);
  for (int y = 0; y < ramp.rows; ++y)
    for (int x = 0; x < ramp.cols; ++x) ramp.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(x);
  EXPECT_FALSE(classify_two_tone(ramp).two_tone) << "a ramp has every grey";

  cv::Mat noise(150, 200, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  EXPECT_FALSE(classify_two_tone(noise).two_tone);

  cv::Mat low_contrast = blank();
  low_contrast.setTo(150);
  cv::circle(low_contrast, {100, 75}, 40, cv::Scalar(100), cv::FILLED);
  EXPECT_FALSE(classify_two_tone(low_contrast).two_tone) << "tones 50 levels apart: shading, not ink";

  EXPECT_FALSE(classify_two_tone(blank()).two_tone) << "one tone: nothing to trace";
  EXPECT_THROW(classify_two_tone(cv::Mat()), hk::ArgumentError);
  EXPECT_THROW(classify_two_tone(cv::Mat(10, 10, CV_8UC3)), hk::ArgumentError);
}

TEST(TwoTone, TheShippedSilhouettesAreTwoToneAndThePhotographsAreNot) {
  for (const char* name : {"silhouette_1.png", "silhouette_5.png", "silhouette_9.png", "horse.png", "pic1.png"}) {
    const cv::Mat g = cv::imread((kImages / name).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(g.empty()) << name;
    EXPECT_TRUE(classify_two_tone(g).two_tone) << name;
  }
  for (const char* name :
       {"apple.jpg", "butterfly.jpg", "fruits.jpg", "camera.png", "coins.png", "sudoku.png", "HappyFish.jpg"}) {
    const cv::Mat g = cv::imread((kImages / name).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(g.empty()) << name;
    EXPECT_FALSE(classify_two_tone(g).two_tone) << name;
  }
}

TEST(TwoTone, InkWidthIsAStrokesWidthAndADiscsRadius) {
  // 2 · area / boundary: a w x L bar gives 2wL / (2L + 2w) = w / (1 + w/L); a disc of radius r gives r (its
  // boundary of 4-neighbour cracks is the digital perimeter, longer than 2πr by up to 4/π: r·π/4 at worst).
  cv::Mat bars = blank(400, 300);
  for (int k = 0; k < 5; ++k) cv::rectangle(bars, cv::Rect(40, 30 + 50 * k, 300, 4), cv::Scalar(0), cv::FILLED);
  EXPECT_NEAR(classify_two_tone(bars).ink_width_px, 4.0 / (1.0 + 4.0 / 300.0), 1e-9);
  cv::Mat disc = blank(400, 300);
  cv::circle(disc, {200, 150}, 100, cv::Scalar(0), cv::FILLED);
  const double w = classify_two_tone(disc).ink_width_px;
  EXPECT_GT(w, 100.0 * std::numbers::pi / 4.0 - 1.0);
  EXPECT_LT(w, 100.0 + 1.0);
  // A white line drawing on black: the foreground is the white ink (off the frame), 2 px wide.
  cv::Mat inverse(300, 400, CV_8UC1, cv::Scalar(0));
  cv::rectangle(inverse, cv::Rect(50, 100, 300, 2), cv::Scalar(255), cv::FILLED);
  EXPECT_NEAR(classify_two_tone(inverse).ink_width_px, 2.0 / (1.0 + 2.0 / 300.0), 1e-9);
  EXPECT_EQ(classify_two_tone(blank()).ink_width_px, 0.0) << "one tone: no ink";
}

TEST(TraceOutlines, ARingGivesTwoClosedChainsOnTheCrackAndTwoBlobsTwoMore) {
  cv::Mat g = blank();
  cv::circle(g, {60, 75}, 40, cv::Scalar(0), cv::FILLED);
  cv::circle(g, {60, 75}, 15, cv::Scalar(255), cv::FILLED);  // the hole
  cv::rectangle(g, cv::Rect(130, 30, 40, 25), cv::Scalar(0), cv::FILLED);
  cv::rectangle(g, cv::Rect(130, 90, 50, 30), cv::Scalar(0), cv::FILLED);
  const std::vector<Chain> chains = trace_outlines(g, 127);
  ASSERT_EQ(chains.size(), 4u) << "outer rim, hole, two rectangles";
  for (const Chain& c : chains) {
    EXPECT_TRUE(c.closed);
    for (std::size_t i = 0; i < c.points_px.size(); ++i) {
      const cv::Point2d a = c.points_px[i], b = c.points_px[(i + 1) % c.points_px.size()];
      ASSERT_LE(std::max(std::abs(a.x - b.x), std::abs(a.y - b.y)), 1.0) << "8-adjacent, closing point included";
      ASSERT_LE(to_crack(g, a), std::sqrt(0.5) + 1e-9)
          << "a boundary pixel's centre is at most a half diagonal off the crack";
    }
  }
}

TEST(TraceOutlines, AShapeCutByTheFrameIsOpenAndHasNoPointOnTheFrame) {
  cv::Mat g = blank();
  cv::circle(g, {0, 75}, 50, cv::Scalar(0), cv::FILLED);   // cut by the left edge
  cv::circle(g, {199, 0}, 30, cv::Scalar(0), cv::FILLED);  // the top right corner
  const std::vector<Chain> chains = trace_outlines(g, 127);
  ASSERT_EQ(chains.size(), 2u);
  for (const Chain& c : chains) {
    EXPECT_FALSE(c.closed);
    for (const cv::Point2d& p : c.points_px) {
      EXPECT_GT(p.x, 0);
      EXPECT_GT(p.y, 0);
      EXPECT_LT(p.x, g.cols - 1);
      EXPECT_LT(p.y, g.rows - 1);
    }
  }
}

TEST(TraceOutlines, TheForegroundIsTheToneOffTheFrameWhicheverItIs) {
  // White on black gives the same outline as black on white.
  cv::Mat dark_on_light = blank();
  cv::rectangle(dark_on_light, cv::Rect(50, 40, 60, 50), cv::Scalar(0), cv::FILLED);
  const cv::Mat light_on_dark = 255 - dark_on_light;
  const std::vector<Chain> a = trace_outlines(dark_on_light, 127), b = trace_outlines(light_on_dark, 127);
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(a[0].points_px.size(), b[0].points_px.size());
  EXPECT_TRUE(a[0].closed && b[0].closed);
}

TEST(TraceOutlines, RefusesBadInput) {
  EXPECT_THROW(trace_outlines(cv::Mat(), 127), hk::ArgumentError);
  EXPECT_THROW(trace_outlines(cv::Mat(10, 10, CV_32F), 127), hk::ArgumentError);
  EXPECT_THROW(trace_outlines(blank(), 127, 0), hk::ArgumentError);
  EXPECT_TRUE(trace_outlines(blank(), 127).empty()) << "one tone: no outline";
}

}  // namespace hk::vision
