// Edge linking on drawn shapes whose true chains are known (a circle is one loop, a T is three
// branches) and on random pixel soup, where only the invariants can be known but every odd
// configuration (L-corners, 2x2 blocks, junction clusters, border pixels) turns up.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <opencv2/imgproc.hpp>

#include "chain_checks.hpp"
#include "hk/error.hpp"
#include "test_paths.hpp"
#include "vision/edges.hpp"
#include "vision/intake.hpp"
#include "vision/linking.hpp"

namespace hk::vision {
namespace {

using test::expect_edges_covered_once;
using test::expect_pixel_chains_valid;

cv::Mat blank(int w = 200, int h = 200) { return cv::Mat::zeros(h, w, CV_8UC1); }

bool has_end_at(const Chain& c, cv::Point2d p) { return c.points_px.front() == p || c.points_px.back() == p; }

void expect_all_invariants(const cv::Mat& edges) {
  const std::vector<Chain> chains = link_edges(edges, 0.0);
  expect_pixel_chains_valid(chains, edges);
  expect_edges_covered_once(chains, edges);
}

TEST(LinkEdges, CircleIsOneClosedChainOfCircumferenceLength) {
  for (const int r : {5, 20, 60, 90}) {
    SCOPED_TRACE("radius " + std::to_string(r));
    cv::Mat e = blank();
    cv::circle(e, {100, 100}, r, 255, 1, cv::LINE_8);
    const std::vector<Chain> chains = link_edges(e, 0.0);
    ASSERT_EQ(chains.size(), 1u);
    EXPECT_TRUE(chains[0].closed);
    expect_pixel_chains_valid(chains, e);
    expect_edges_covered_once(chains, e);
    // An 8-connected digital circle is longer than the true one: per octant it takes
    // r(sqrt2 - 1) straight and r(1 - 1/sqrt2) diagonal steps, 2r(sqrt2 - 1) = 1.055 * (pi r / 4).
    const double ratio = chain_length_px(chains[0]) / (2.0 * std::numbers::pi * r);
    EXPECT_GT(ratio, 0.97);
    EXPECT_LT(ratio, 1.08);
  }
}

TEST(LinkEdges, FourConnectedCircleWithLCornersIsStillOneLoop) {
  // LINE_4 puts an L-corner at every diagonal step: with plain 8-adjacency each would be a
  // 3-way junction.
  cv::Mat e = blank();
  cv::circle(e, {100, 100}, 50, 255, 1, cv::LINE_4);
  const std::vector<Chain> chains = link_edges(e, 0.0);
  ASSERT_EQ(chains.size(), 1u);
  EXPECT_TRUE(chains[0].closed);
  expect_pixel_chains_valid(chains, e);
  expect_edges_covered_once(chains, e);
}

TEST(LinkEdges, LineSegmentIsOneOpenChainBetweenItsEnds) {
  for (const int type : {cv::LINE_8, cv::LINE_4}) {
    SCOPED_TRACE(type == cv::LINE_8 ? "LINE_8" : "LINE_4");
    cv::Mat e = blank();
    const cv::Point a{20, 30};
    const cv::Point b{150, 90};
    cv::line(e, a, b, 255, 1, type);
    const std::vector<Chain> chains = link_edges(e, 0.0);
    ASSERT_EQ(chains.size(), 1u);
    EXPECT_FALSE(chains[0].closed);
    EXPECT_TRUE(has_end_at(chains[0], cv::Point2d(a)));
    EXPECT_TRUE(has_end_at(chains[0], cv::Point2d(b)));
    EXPECT_GE(chain_length_px(chains[0]), cv::norm(b - a) - 1e-9);
    expect_pixel_chains_valid(chains, e);
    expect_edges_covered_once(chains, e);
  }
}

TEST(LinkEdges, LinesAlongTheImageBorderAreLinked) {
  cv::Mat e = blank(50, 40);
  cv::rectangle(e, {0, 0}, {49, 39}, 255, 1);
  const std::vector<Chain> chains = link_edges(e, 0.0);
  ASSERT_EQ(chains.size(), 1u);
  EXPECT_TRUE(chains[0].closed);
  EXPECT_DOUBLE_EQ(chain_length_px(chains[0]), 2.0 * (49 + 39));
  expect_pixel_chains_valid(chains, e);
}

TEST(LinkEdges, TShapeSplitsIntoThreeBranchesAtTheJunction) {
  cv::Mat e = blank();
  cv::line(e, {20, 50}, {180, 50}, 255);
  cv::line(e, {100, 50}, {100, 150}, 255);
  const std::vector<Chain> chains = link_edges(e, 0.0);
  ASSERT_EQ(chains.size(), 3u);
  std::vector<double> lengths;
  for (const Chain& c : chains) {
    EXPECT_FALSE(c.closed);
    EXPECT_TRUE(has_end_at(c, {100, 50}));
    lengths.push_back(chain_length_px(c));
  }
  std::sort(lengths.begin(), lengths.end());
  EXPECT_DOUBLE_EQ(lengths[0], 80.0);
  EXPECT_DOUBLE_EQ(lengths[1], 80.0);
  EXPECT_DOUBLE_EQ(lengths[2], 100.0);
  expect_pixel_chains_valid(chains, e);
  expect_edges_covered_once(chains, e);
}

TEST(LinkEdges, XShapeSplitsIntoFourBranchesAtTheCrossing) {
  cv::Mat e = blank();
  cv::line(e, {20, 20}, {180, 180}, 255);
  cv::line(e, {20, 180}, {180, 20}, 255);
  const std::vector<Chain> chains = link_edges(e, 0.0);
  ASSERT_EQ(chains.size(), 4u);
  for (const Chain& c : chains) {
    EXPECT_FALSE(c.closed);
    EXPECT_TRUE(has_end_at(c, {100, 100}));
    EXPECT_NEAR(chain_length_px(c), 80.0 * std::numbers::sqrt2, 1e-9);
  }
  expect_pixel_chains_valid(chains, e);
  expect_edges_covered_once(chains, e);
}

TEST(LinkEdges, XCrossingBetweenPixelsGivesFourLongBranches) {
  // Diagonals crossing between pixel centres meet in a 2x2 block of four junction pixels.
  cv::Mat e = blank();
  cv::line(e, {20, 20}, {179, 179}, 255);
  cv::line(e, {20, 179}, {179, 20}, 255);
  expect_all_invariants(e);
  const std::vector<Chain> chains = link_edges(e, 5.0);
  ASSERT_EQ(chains.size(), 4u);
  for (const Chain& c : chains) EXPECT_GT(chain_length_px(c), 75.0 * std::numbers::sqrt2);
}

TEST(LinkEdges, LoopWithATailIsAClosedLoopAndAnOpenTail) {
  cv::Mat e = blank();
  cv::circle(e, {100, 100}, 30, 255, 1, cv::LINE_8);
  cv::line(e, {131, 100}, {190, 100}, 255);
  const std::vector<Chain> chains = link_edges(e, 0.0);
  expect_pixel_chains_valid(chains, e);
  expect_edges_covered_once(chains, e);
  ASSERT_EQ(chains.size(), 2u);
  const auto loop = std::find_if(chains.begin(), chains.end(), [](const Chain& c) { return c.closed; });
  ASSERT_NE(loop, chains.end());
  EXPECT_GT(chain_length_px(*loop), 2.0 * std::numbers::pi * 30 * 0.97);
  const Chain& tail = chains[loop == chains.begin() ? 1 : 0];
  EXPECT_FALSE(tail.closed);
  EXPECT_TRUE(has_end_at(tail, {190, 100}));
}

TEST(LinkEdges, TinyShapes) {
  EXPECT_TRUE(link_edges(blank(), 0.0).empty());
  EXPECT_TRUE(link_edges(cv::Mat(), 0.0).empty());

  cv::Mat dot = blank(10, 10);
  dot.at<std::uint8_t>(4, 7) = 255;
  const auto one = link_edges(dot, 0.0);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].points_px, std::vector<cv::Point2d>{cv::Point2d(7, 4)});
  EXPECT_FALSE(one[0].closed);
  EXPECT_TRUE(link_edges(dot, 0.5).empty());

  cv::Mat block = blank(10, 10);
  block(cv::Rect(3, 3, 2, 2)).setTo(255);
  const auto square = link_edges(block, 0.0);
  ASSERT_EQ(square.size(), 1u);
  EXPECT_TRUE(square[0].closed);
  EXPECT_EQ(square[0].points_px.size(), 4u);
  EXPECT_DOUBLE_EQ(chain_length_px(square[0]), 4.0);
}

TEST(LinkEdges, RandomPixelSoupKeepsEveryInvariant) {
  std::mt19937 rng(12345);
  for (const double density : {0.05, 0.2, 0.4, 0.7}) {
    for (int rep = 0; rep < 3; ++rep) {
      SCOPED_TRACE("density " + std::to_string(density) + " rep " + std::to_string(rep));
      cv::Mat e = blank(61, 47);
      std::bernoulli_distribution on(density);
      for (int y = 0; y < e.rows; ++y) {
        for (int x = 0; x < e.cols; ++x) e.at<std::uint8_t>(y, x) = on(rng) ? 255 : 0;
      }
      expect_all_invariants(e);
    }
  }
}

TEST(LinkEdges, RealCannyOutputKeepsEveryInvariant) {
  for (const char* name : {"fruits.jpg", "page.png", "horse.png", "sudoku.png"}) {
    SCOPED_TRACE(name);
    const cv::Mat grey = to_grey(load_image(std::string(HK_TEST_DATA_DIR) + "/images/" + name, {}), 800, nullptr);
    const cv::Mat e = detect_edges(grey, {}).edges;
    expect_all_invariants(e);
  }
}

TEST(LinkEdges, LengthFilterDropsExactlyTheShortChainsAndKeepsOrder) {
  std::mt19937 rng(7);
  cv::Mat e = blank(80, 60);
  std::bernoulli_distribution on(0.15);
  for (int y = 0; y < e.rows; ++y) {
    for (int x = 0; x < e.cols; ++x) e.at<std::uint8_t>(y, x) = on(rng) ? 255 : 0;
  }
  const std::vector<Chain> all = link_edges(e, 0.0);
  const std::vector<Chain> kept = link_edges(e, 4.0);
  std::vector<Chain> expected;
  for (const Chain& c : all) {
    if (chain_length_px(c) >= 4.0) expected.push_back(c);
  }
  ASSERT_EQ(kept.size(), expected.size());
  ASSERT_LT(kept.size(), all.size());
  for (std::size_t i = 0; i < kept.size(); ++i) {
    EXPECT_EQ(kept[i].points_px, expected[i].points_px);
    EXPECT_EQ(kept[i].closed, expected[i].closed);
  }
}

TEST(LinkEdges, OutputIsDeterministicAndInRasterOrderOfFirstPoints) {
  cv::Mat e = blank();
  cv::circle(e, {60, 140}, 25, 255);
  cv::line(e, {10, 10}, {190, 40}, 255);
  cv::line(e, {100, 30}, {120, 180}, 255);
  cv::rectangle(e, {140, 120}, {180, 170}, 255);
  const auto a = link_edges(e, 0.0);
  const auto b = link_edges(e, 0.0);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].points_px, b[i].points_px);
  for (std::size_t i = 1; i < a.size(); ++i) {
    const cv::Point2d p = a[i - 1].points_px.front();
    const cv::Point2d q = a[i].points_px.front();
    EXPECT_TRUE(p.y < q.y || (p.y == q.y && p.x <= q.x)) << p << " then " << q;
  }
}

TEST(LinkEdges, RejectsBadArguments) {
  EXPECT_THROW(link_edges(cv::Mat::zeros(5, 5, CV_32F), 0.0), hk::ArgumentError);
  EXPECT_THROW(link_edges(blank(), -1.0), hk::ArgumentError);
  EXPECT_THROW(link_edges(blank(), std::nan("")), hk::ArgumentError);
}

}  // namespace
}  // namespace hk::vision
