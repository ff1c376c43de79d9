// detect_edges and link_edges are optimised (own vectorised Sobel and Canny, histogram
// statistics, row stripes on OpenCV's threads, per-thread scratch buffers, a linker that visits
// only edge pixels). These tests pin down that they compute exactly what the straightforward
// versions compute: OpenCV's GaussianBlur + Sobel + Canny with the threshold rule written out
// naively, and the first implementation of the linker (reference_linker.hpp), on every test
// image, on random images and pixel soup, on submatrices, and whatever the number of threads.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "reference_linker.hpp"
#include "test_paths.hpp"
#include "vision/edges.hpp"
#include "vision/intake.hpp"
#include "vision/linking.hpp"

namespace hk::vision {
namespace {

namespace fs = std::filesystem;

/// detect_edges written out with OpenCV calls and the threshold rule of edges.hpp taken
/// literally (exact histogram percentile over floor(|g|), Immerkaer noise by filter2D).
EdgeMap reference_detect_edges(const cv::Mat& grey, const EdgeParams& p) {
  cv::Mat blurred;
  if (p.blur_sigma_px > 0.0) {
    cv::GaussianBlur(grey, blurred, cv::Size(0, 0), p.blur_sigma_px, p.blur_sigma_px, cv::BORDER_REPLICATE);
  } else {
    blurred = grey;
  }
  cv::Mat dx;
  cv::Mat dy;
  cv::Sobel(blurred, dx, CV_16S, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(blurred, dy, CV_16S, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
  EdgeMap out;
  if (p.canny_high > 0.0) {
    out.high = p.canny_high;
  } else {
    std::vector<std::int64_t> hist(1448, 0);
    for (int y = 0; y < dx.rows; ++y) {
      for (int x = 0; x < dx.cols; ++x) {
        const int gx = dx.at<std::int16_t>(y, x);
        const int gy = dy.at<std::int16_t>(y, x);
        const int m2 = gx * gx + gy * gy;
        if (m2 > 0) ++hist[static_cast<std::size_t>(std::sqrt(static_cast<double>(m2)))];
      }
    }
    std::int64_t nonzero = 0;
    double max = 0.0;
    for (std::size_t b = 0; b < hist.size(); ++b) {
      nonzero += hist[b];
      if (hist[b] > 0) max = static_cast<double>(b);
    }
    double percentile = 0.0;
    if (nonzero > 0) {
      const auto target = static_cast<std::int64_t>(std::ceil(0.9 * static_cast<double>(nonzero)));
      std::int64_t cumulative = 0;
      for (std::size_t b = 0; b < hist.size(); ++b) {
        cumulative += hist[b];
        if (cumulative >= target) {
          percentile = static_cast<double>(b) - 0.5;
          break;
        }
      }
    }
    double sigma_noise = 0.0;
    if (grey.rows >= 3 && grey.cols >= 3) {
      const cv::Mat kernel = (cv::Mat_<float>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
      cv::Mat response;
      cv::filter2D(grey, response, CV_32F, kernel);
      const cv::Rect inner(1, 1, grey.cols - 2, grey.rows - 2);
      sigma_noise = std::sqrt(CV_PI / 2.0) * cv::norm(response(inner), cv::NORM_L1) / (6.0 * inner.area());
    }
    const int half = static_cast<int>(std::ceil(4.0 * p.blur_sigma_px)) + 2;
    cv::Mat impulse = cv::Mat::zeros(2 * half + 1, 2 * half + 1, CV_32F);
    impulse.at<float>(half, half) = 1.0f;
    if (p.blur_sigma_px > 0.0) cv::GaussianBlur(impulse, impulse, cv::Size(0, 0), p.blur_sigma_px);
    cv::Mat gx;
    cv::Sobel(impulse, gx, CV_32F, 1, 0, 3);
    const double noise_floor = 5.0 * sigma_noise * cv::norm(gx, cv::NORM_L2);
    out.high = std::max({std::min(percentile, 0.5 * max), noise_floor, kMinAutoHigh});
  }
  out.low = p.canny_low > 0.0 ? p.canny_low : 0.4 * out.high;
  if (out.low > out.high) std::swap(out.low, out.high);
  cv::Canny(dx, dy, out.edges, out.low, out.high, true);
  return out;
}

void expect_same_edges(const cv::Mat& grey, const EdgeParams& p, const std::string& what) {
  SCOPED_TRACE(what);
  const EdgeMap got = detect_edges(grey, p);
  const EdgeMap want = reference_detect_edges(grey, p);
  EXPECT_EQ(got.low, want.low);
  EXPECT_EQ(got.high, want.high);
  ASSERT_EQ(got.edges.size(), want.edges.size());
  ASSERT_EQ(got.edges.type(), CV_8UC1);
  EXPECT_EQ(cv::norm(got.edges, want.edges, cv::NORM_INF), 0.0);
}

void expect_same_chains(const cv::Mat& edges, double min_length_px, const std::string& what) {
  SCOPED_TRACE(what + ", min length " + std::to_string(min_length_px));
  const std::vector<Chain> got = link_edges(edges, min_length_px);
  const std::vector<Chain> want = test::reference::link_edges(edges, min_length_px);
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(got[i].closed, want[i].closed) << "chain " << i;
    ASSERT_EQ(got[i].points_px, want[i].points_px) << "chain " << i;
  }
}

std::vector<fs::path> test_images() {
  std::vector<fs::path> paths;
  for (const auto& entry : fs::directory_iterator(std::string(HK_TEST_DATA_DIR) + "/images"))
    paths.push_back(entry.path());
  std::sort(paths.begin(), paths.end());
  return paths;
}

/// Restores OpenCV's thread count when a test changed it.
struct ThreadsGuard {
  int saved = cv::getNumThreads();
  ~ThreadsGuard() { cv::setNumThreads(saved); }
};

TEST(Reference, DetectEdgesMatchesOpenCVOnEveryTestImage) {
  for (const fs::path& path : test_images()) {
    const cv::Mat bgr = load_image(path.string(), {});
    for (const int side : {800, 97}) {
      const cv::Mat grey = to_grey(bgr, side, nullptr);
      const std::string name = path.filename().string() + " at " + std::to_string(side) + " px";
      for (const double sigma : {1.5, 0.0, 0.7, 2.5}) {
        EdgeParams p;
        p.blur_sigma_px = sigma;
        expect_same_edges(grey, p, name + ", sigma " + std::to_string(sigma));
      }
      EdgeParams given;
      given.canny_high = 80;
      expect_same_edges(grey, given, name + ", high 80");
      given.canny_low = 100;  // above high: swapped
      expect_same_edges(grey, given, name + ", low 100 high 80");
      // A submatrix: filters see the parent's pixels beyond its edges.
      const cv::Mat roi = grey(cv::Rect(3, 5, grey.cols - 10, grey.rows - 12));
      expect_same_edges(roi, {}, name + ", submatrix");
      EdgeParams unblurred;
      unblurred.blur_sigma_px = 0.0;
      expect_same_edges(roi, unblurred, name + ", submatrix, sigma 0");
    }
  }
}

TEST(Reference, DetectEdgesMatchesOpenCVOnRandomImages) {
  std::mt19937 rng(2024);
  for (int rep = 0; rep < 200; ++rep) {
    const int w = rep % 10 == 0 ? 1 + static_cast<int>(rng() % 4) : 1 + static_cast<int>(rng() % 90);
    const int h = 1 + static_cast<int>(rng() % 70);
    cv::Mat g(h, w, CV_8UC1);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        int v = 0;
        switch (rep % 4) {
          case 0:
            v = static_cast<int>(rng() % 256);
            break;  // noise
          case 1:
            v = 128 + static_cast<int>(rng() % 7) - 3;
            break;  // faint noise
          case 2:
            v = (x / 7 + y / 5) % 2 != 0 ? 200 : 40;
            break;  // blocks
          default:
            v = (3 * x + 2 * y + static_cast<int>(rng() % 20)) % 256;
            break;  // ramps
        }
        g.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(v);
      }
    }
    for (const double sigma : {1.5, 0.0}) {
      EdgeParams p;
      p.blur_sigma_px = sigma;
      expect_same_edges(g, p, std::to_string(w) + "x" + std::to_string(h) + " image " + std::to_string(rep));
    }
  }
}

TEST(Reference, DetectEdgesDoesNotDependOnTheNumberOfThreads) {
  const ThreadsGuard guard;
  const cv::Mat grey = to_grey(load_image(std::string(HK_TEST_DATA_DIR) + "/images/fruits.jpg", {}), 800, nullptr);
  cv::setNumThreads(1);
  const EdgeMap serial = detect_edges(grey, {});
  for (const int threads : {2, 3, 8}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    cv::setNumThreads(threads);
    const EdgeMap e = detect_edges(grey, {});
    EXPECT_EQ(e.high, serial.high);
    EXPECT_EQ(cv::norm(e.edges, serial.edges, cv::NORM_INF), 0.0);
  }
}

TEST(Reference, LinkEdgesMatchesTheFirstImplementationOnPixelSoup) {
  std::mt19937 rng(99);
  for (int rep = 0; rep < 300; ++rep) {
    const int w = rep % 10 == 0 ? 1 + static_cast<int>(rng() % 4) : 1 + static_cast<int>(rng() % 70);
    const int h = 1 + static_cast<int>(rng() % 70);
    for (const double density : {0.05, 0.2, 0.4, 0.7, 0.95}) {
      cv::Mat e(h, w, CV_8UC1);
      std::bernoulli_distribution on(density);
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) e.at<std::uint8_t>(y, x) = on(rng) ? static_cast<std::uint8_t>(1 + rng() % 255) : 0;
      }
      const std::string what = std::to_string(w) + "x" + std::to_string(h) + " density " + std::to_string(density);
      for (const double min_length : {0.0, 2.0, 5.0}) expect_same_chains(e, min_length, what);
    }
  }
}

TEST(Reference, LinkEdgesMatchesTheFirstImplementationOnDrawnShapes) {
  cv::Mat rings = cv::Mat::zeros(300, 300, CV_8UC1);
  for (int r = 3; r < 150; r += 4) cv::circle(rings, {150, 150}, r, 255, 1, r % 8 == 3 ? cv::LINE_4 : cv::LINE_8);
  cv::line(rings, {0, 0}, {299, 299}, 255);
  cv::line(rings, {0, 299}, {299, 0}, 255, 1, cv::LINE_4);
  expect_same_chains(rings, 0.0, "rings and crossing diagonals");
  expect_same_chains(rings(cv::Rect(10, 20, 200, 150)), 0.0, "submatrix of them");
  expect_same_chains(cv::Mat(40, 50, CV_8UC1, cv::Scalar(255)), 0.0, "all set");
  cv::Mat frame = cv::Mat::zeros(40, 50, CV_8UC1);
  cv::rectangle(frame, {0, 0}, {49, 39}, 255, 1);
  expect_same_chains(frame, 0.0, "frame along the image border");
}

TEST(Reference, LinkEdgesMatchesTheFirstImplementationOnEveryTestImage) {
  for (const fs::path& path : test_images()) {
    const cv::Mat grey = to_grey(load_image(path.string(), {}), 800, nullptr);
    const cv::Mat e = detect_edges(grey, {}).edges;
    for (const double min_length : {0.0, 2.0, 20.0}) expect_same_chains(e, min_length, path.filename().string());
  }
}

TEST(Reference, BuffersKeptBetweenCallsDoNotLeakIntoResults) {
  // Large, small, large again, and a different shape: scratch reused across sizes.
  const cv::Mat big = to_grey(load_image(std::string(HK_TEST_DATA_DIR) + "/images/sudoku.png", {}), 800, nullptr);
  const cv::Mat small = to_grey(load_image(std::string(HK_TEST_DATA_DIR) + "/images/horse.png", {}), 120, nullptr);
  const cv::Mat wide = big(cv::Rect(0, 0, big.cols, 40)).clone();
  for (const cv::Mat* g : {&big, &small, &big, &wide, &small}) {
    expect_same_edges(*g, {}, std::to_string(g->cols) + "x" + std::to_string(g->rows));
    expect_same_chains(detect_edges(*g, {}).edges, 2.0, std::to_string(g->cols) + "x" + std::to_string(g->rows));
  }
}

}  // namespace
}  // namespace hk::vision
