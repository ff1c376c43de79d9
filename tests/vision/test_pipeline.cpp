// The whole vision pipeline on every real test image, and the scale-back of chains found on a
// shrunk image, which must land on the original image's boundaries.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "chain_checks.hpp"
#include "hk/error.hpp"
#include "test_paths.hpp"
#include "vision/pipeline.hpp"

namespace hk::vision {
namespace {

namespace fs = std::filesystem;

TEST(ExtractChains, SucceedsOnEveryTestImage) {
  int images = 0;
  for (const auto& entry : fs::directory_iterator(std::string(HK_TEST_DATA_DIR) + "/images")) {
    SCOPED_TRACE(entry.path().filename().string());
    const ExtractParams p;
    const auto t0 = std::chrono::steady_clock::now();
    const Extraction ex = extract_chains(entry.path().string(), p);
    const double outer_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ++images;
    const cv::Mat decoded = cv::imread(entry.path().string(), cv::IMREAD_COLOR);
    EXPECT_EQ(ex.width_px, decoded.cols);
    EXPECT_EQ(ex.height_px, decoded.rows);
    EXPECT_GE(ex.px_scale, 1.0);
    EXPECT_LE(std::max(ex.edge_map.edges.cols, ex.edge_map.edges.rows), p.max_image_side_px);
    ASSERT_GE(ex.chains.size(), 1u);
    test::expect_chains_sane(ex.chains, ex.width_px, ex.height_px, ex.detector_used == Detector::Outline);
    for (const Chain& c : ex.chains) EXPECT_GE(chain_length_px(c) / ex.px_scale, p.min_chain_length_px - 1e-9);
    // The stage times are wall-clock milliseconds of stages that ran one after the other inside the
    // call: each that ran took some time (decoding, filtering and linking an image are never free), a
    // two-tone picture's outlines are traced without an edge detector (edges_ms exactly 0), and together
    // they fit within the call as timed from outside (a stage timed in µs or counted twice would not).
    EXPECT_GT(ex.times.load_ms, 0.0);
    if (ex.detector_used == Detector::Outline) {
      EXPECT_EQ(ex.times.edges_ms, 0.0);
    } else {
      EXPECT_GT(ex.times.edges_ms, 0.0);
    }
    EXPECT_GT(ex.times.linking_ms, 0.0);
    EXPECT_LE(ex.times.load_ms + ex.times.edges_ms + ex.times.linking_ms, outer_ms);
  }
  EXPECT_GE(images, 20);
}

TEST(ExtractChains, SilhouetteOutlinesHaveNoDanglingEnds) {
  // In a binary image every boundary is a closed curve or runs into the image border. Canny can
  // leave a gap of a pixel or two at a sharp notch, but an open chain must not end anywhere else:
  // each end lies at the border or next to another chain end.
  for (int i = 1; i <= 10; ++i) {
    const std::string name = "silhouette_" + std::to_string(i) + ".png";
    SCOPED_TRACE(name);
    const Extraction ex = extract_chains(std::string(HK_TEST_DATA_DIR) + "/images/" + name, {});
    std::vector<cv::Point2d> ends;
    for (const Chain& c : ex.chains) {
      if (c.closed) continue;
      ends.push_back(c.points_px.front());
      ends.push_back(c.points_px.back());
    }
    for (std::size_t k = 0; k < ends.size(); ++k) {
      const cv::Point2d e = ends[k];
      const double to_border = std::min({e.x, e.y, ex.width_px - 1 - e.x, ex.height_px - 1 - e.y});
      double to_end = INFINITY;
      for (std::size_t m = 0; m < ends.size(); ++m) {
        if (m != k) to_end = std::min(to_end, cv::norm(ends[m] - e));
      }
      EXPECT_TRUE(to_border <= 2.0 || to_end <= 5.0) << "dangling end " << e;
    }
  }
}

TEST(ExtractChains, ChainsOfAShrunkImageAreInOriginalPixels) {
  // A 1600 x 1200 picture of a disc, processed at 800 x 600: the loop must come back around the
  // disc's true outline in original pixels.
  const fs::path path =
      fs::temp_directory_path() /
      ("hk_vision_disc_" + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + ".png");
  const cv::Point2d centre(830.0, 570.0);
  const double r = 400.0;
  cv::Mat img(1200, 1600, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::circle(img, cv::Point(830, 570), 400, cv::Scalar(0, 0, 0), cv::FILLED, cv::LINE_AA);
  ASSERT_TRUE(cv::imwrite(path.string(), img));
  const Extraction ex = extract_chains(path.string(), {});
  fs::remove(path);

  EXPECT_EQ(ex.width_px, 1600);
  EXPECT_EQ(ex.height_px, 1200);
  EXPECT_DOUBLE_EQ(ex.px_scale, 2.0);
  EXPECT_EQ(ex.edge_map.edges.size(), cv::Size(800, 600));
  ASSERT_EQ(ex.chains.size(), 1u);
  const Chain& c = ex.chains[0];
  EXPECT_TRUE(c.closed);
  test::expect_chains_sane(ex.chains, ex.width_px, ex.height_px);
  for (const cv::Point2d& q : c.points_px) EXPECT_NEAR(cv::norm(q - centre), r, 2.0 * ex.px_scale);
  EXPECT_NEAR(chain_length_px(c) / (2 * std::numbers::pi * r), 1.0, 0.08);
}

TEST(ExtractChains, PointStrengthIsTheGradientMagnitudeCannyThresholded) {
  // Recomputed independently with OpenCV's own blur and Sobel on the processed grey image, at each
  // chain point mapped back to processed pixels; every edge pixel passed Canny's low threshold.
  // And a picture bigger than max_image_side_px, so the chains are scaled back from a shrunk image.
  const fs::path shrunk =
      fs::temp_directory_path() /
      ("hk_vision_strength_" + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + ".png");
  cv::Mat big(1000, 1700, CV_8UC3, cv::Scalar(230, 230, 230));
  cv::circle(big, cv::Point(600, 500), 300, cv::Scalar(20, 20, 20), cv::FILLED, cv::LINE_AA);
  cv::rectangle(big, cv::Rect(1100, 200, 400, 500), cv::Scalar(150, 150, 150), cv::FILLED);
  ASSERT_TRUE(cv::imwrite(shrunk.string(), big));
  const std::string images = std::string(HK_TEST_DATA_DIR) + "/images/";
  for (const std::string& path : {images + "fruits.jpg", images + "horse.png", images + "sudoku.png",
                                  images + "butterfly.jpg", shrunk.string()}) {
    SCOPED_TRACE(path);
    const ExtractParams p;
    const Extraction ex = extract_chains(path, p);
    const cv::Mat grey = to_grey(load_image(path, p.limits), p.max_image_side_px, nullptr);
    cv::Mat blurred, dx, dy;
    cv::GaussianBlur(grey, blurred, cv::Size(0, 0), p.edges.blur_sigma_px, p.edges.blur_sigma_px, cv::BORDER_REPLICATE);
    cv::Sobel(blurred, dx, CV_16S, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
    cv::Sobel(blurred, dy, CV_16S, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
    const double sx = static_cast<double>(ex.width_px) / grey.cols;
    const double sy = static_cast<double>(ex.height_px) / grey.rows;
    ASSERT_EQ(ex.point_strength.size(), ex.chains.size());
    std::size_t checked = 0;
    for (std::size_t k = 0; k < ex.chains.size(); ++k) {
      ASSERT_EQ(ex.point_strength[k].size(), ex.chains[k].points_px.size());
      for (std::size_t i = 0; i < ex.chains[k].points_px.size(); ++i) {
        const cv::Point2d q = ex.chains[k].points_px[i];
        const int u = static_cast<int>(std::lround((q.x + 0.5) / sx - 0.5));
        const int v = static_cast<int>(std::lround((q.y + 0.5) / sy - 0.5));
        const double gx = dx.at<std::int16_t>(v, u);
        const double gy = dy.at<std::int16_t>(v, u);
        ASSERT_NEAR(ex.point_strength[k][i], std::hypot(gx, gy), 1e-9) << "chain " << k << " point " << i;
        ASSERT_GT(ex.point_strength[k][i], ex.edge_map.low) << "chain " << k << " point " << i;
        ++checked;
      }
    }
    EXPECT_GT(checked, 500u);
  }
  fs::remove(shrunk);
}

TEST(ExtractChains, RefusesBadFilesWithInputError) {
  const std::string bad = std::string(HK_TEST_DATA_DIR) + "/bad/";
  for (const char* name : {"not_an_image.png", "empty.png", "truncated.jpg", "huge_declared.png", "missing.png"}) {
    EXPECT_THROW(extract_chains(bad + name, {}), InputError) << name;
  }
}

TEST(ExtractChains, RejectsBadParameters) {
  const std::string img = std::string(HK_TEST_DATA_DIR) + "/images/horse.png";
  ExtractParams p;
  p.max_image_side_px = 0;
  EXPECT_THROW(extract_chains(img, p), hk::ArgumentError);
  p = {};
  p.min_chain_length_px = -1;
  EXPECT_THROW(extract_chains(img, p), hk::ArgumentError);
}

}  // namespace
}  // namespace hk::vision
