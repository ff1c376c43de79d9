// Edge detection: automatic thresholds must put edges where the boundaries are and nowhere else,
// on a synthetic image with known boundaries and noise, and give a plausible amount of edges on
// every kind of real test image (photos, a document, binary silhouettes).

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"
#include "test_paths.hpp"
#include "vision/edges.hpp"
#include "vision/intake.hpp"

namespace hk::vision {
namespace {

namespace fs = std::filesystem;

/// Dark rectangle and disc on a light background with Gaussian noise, and the ideal boundary.
struct Scene {
  cv::Mat grey;
  cv::Mat boundary;  // CV_8UC1, 255 on the true boundary curves
};

Scene noisy_scene(double noise_sigma) {
  Scene s;
  cv::Mat clean(240, 320, CV_8UC1, cv::Scalar(190));
  cv::rectangle(clean, cv::Rect(40, 50, 120, 90), cv::Scalar(60), cv::FILLED);
  cv::circle(clean, {230, 150}, 50, cv::Scalar(110), cv::FILLED);
  cv::Mat noise(clean.size(), CV_32F);
  cv::RNG rng(42);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
  cv::Mat f;
  clean.convertTo(f, CV_32F);
  cv::Mat(f + noise).convertTo(s.grey, CV_8U);
  // The boundary: pixels whose 4-neighbourhood is not uniform in the clean image.
  cv::Mat eroded;
  cv::Mat dilated;
  cv::erode(clean, eroded, cv::getStructuringElement(cv::MORPH_CROSS, {3, 3}));
  cv::dilate(clean, dilated, cv::getStructuringElement(cv::MORPH_CROSS, {3, 3}));
  s.boundary = (dilated != eroded);
  return s;
}

/// Distance of every pixel to the nearest non-zero pixel of mask.
cv::Mat distance_to(const cv::Mat& mask) {
  cv::Mat dist;
  cv::distanceTransform(mask == 0, dist, cv::DIST_L2, 3);
  return dist;
}

TEST(DetectEdges, FindsTheBoundariesOfANoisyImageAndNothingElse) {
  for (const double noise : {0.0, 4.0, 8.0}) {
    SCOPED_TRACE("noise sigma " + std::to_string(noise));
    const Scene s = noisy_scene(noise);
    const EdgeMap e = detect_edges(s.grey, {});
    ASSERT_EQ(e.edges.type(), CV_8UC1);
    ASSERT_EQ(e.edges.size(), s.grey.size());
    EXPECT_GT(e.high, e.low);
    EXPECT_NEAR(e.low, 0.4 * e.high, 1e-9);
    const cv::Mat to_boundary = distance_to(s.boundary);
    const cv::Mat to_edge = distance_to(e.edges);
    int edge_px = 0;
    int stray = 0;
    for (int y = 0; y < e.edges.rows; ++y) {
      for (int x = 0; x < e.edges.cols; ++x) {
        const std::uint8_t v = e.edges.at<std::uint8_t>(y, x);
        ASSERT_TRUE(v == 0 || v == 255);
        if (v == 0) continue;
        ++edge_px;
        if (to_boundary.at<float>(y, x) > 2.0f) ++stray;
      }
    }
    int boundary_px = 0;
    int found = 0;
    for (int y = 0; y < s.boundary.rows; ++y) {
      for (int x = 0; x < s.boundary.cols; ++x) {
        if (s.boundary.at<std::uint8_t>(y, x) == 0) continue;
        ++boundary_px;
        if (to_edge.at<float>(y, x) <= 2.0f) ++found;
      }
    }
    EXPECT_GT(edge_px, 0);
    EXPECT_EQ(stray, 0) << "edge pixels more than 2 px from any true boundary";
    EXPECT_GT(found, 0.97 * boundary_px) << found << " of " << boundary_px << " boundary pixels found";
  }
}

TEST(DetectEdges, FlatAndFaintImagesGiveNoEdges) {
  const cv::Mat flat(100, 100, CV_8UC1, cv::Scalar(128));
  const EdgeMap e = detect_edges(flat, {});
  EXPECT_EQ(cv::countNonZero(e.edges), 0);
  EXPECT_GE(e.high, kMinAutoHigh);

  cv::Mat faint(100, 100, CV_8UC1);
  cv::RNG rng(1);
  rng.fill(faint, cv::RNG::NORMAL, 128, 1.5);  // sensor noise only
  EXPECT_EQ(cv::countNonZero(detect_edges(faint, {}).edges), 0);
}

TEST(DetectEdges, UsesGivenThresholds) {
  const Scene s = noisy_scene(2.0);
  EdgeParams p;
  p.canny_low = 30;
  p.canny_high = 90;
  const EdgeMap e = detect_edges(s.grey, p);
  EXPECT_EQ(e.low, 30);
  EXPECT_EQ(e.high, 90);
  p.canny_low = 0;
  EXPECT_NEAR(detect_edges(s.grey, p).low, 36, 1e-9);
  // A threshold above every gradient leaves nothing.
  p.canny_low = p.canny_high = 5000;
  EXPECT_EQ(cv::countNonZero(detect_edges(s.grey, p).edges), 0);
}

TEST(DetectEdges, GivesAPlausibleEdgeDensityOnEveryTestImage) {
  for (const auto& entry : fs::directory_iterator(std::string(HK_TEST_DATA_DIR) + "/images")) {
    SCOPED_TRACE(entry.path().filename().string());
    const cv::Mat grey = to_grey(load_image(entry.path().string(), {}), 800, nullptr);
    const EdgeMap e = detect_edges(grey, {});
    const double density = cv::countNonZero(e.edges) / static_cast<double>(grey.total());
    // Silhouettes are a single outline (~0.5 %); busy photos have texture, but a Canny map
    // that marks a fifth of all pixels would be noise.
    EXPECT_GT(density, 0.001);
    EXPECT_LT(density, 0.20);
    EXPECT_GE(e.high, kMinAutoHigh);
  }
}

TEST(DetectEdges, LeavesItsInputUntouched) {
  const Scene s = noisy_scene(4.0);
  const cv::Mat before = s.grey.clone();
  detect_edges(s.grey, {});
  EXPECT_EQ(cv::norm(before, s.grey, cv::NORM_INF), 0.0);
}

TEST(DetectEdges, RejectsBadArguments) {
  EXPECT_THROW(detect_edges(cv::Mat(), {}), hk::ArgumentError);
  EXPECT_THROW(detect_edges(cv::Mat(5, 5, CV_8UC3), {}), hk::ArgumentError);
  EdgeParams p;
  p.blur_sigma_px = -1;
  EXPECT_THROW(detect_edges(cv::Mat(5, 5, CV_8UC1), p), hk::ArgumentError);
  p = {};
  p.canny_high = std::numeric_limits<double>::infinity();
  EXPECT_THROW(detect_edges(cv::Mat(5, 5, CV_8UC1), p), hk::ArgumentError);
}

}  // namespace
}  // namespace hk::vision
