// Scene simplification in one call: vision::scene_chains on every test picture — the report
// accounts for every chain, the budgets keep the most salient curves and no more than they allow, traced
// outlines are left as they are.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "hk/error.hpp"
#include "test_paths.hpp"
#include "vision/scene_chains.hpp"

namespace hk::vision {
namespace {

namespace fs = std::filesystem;

/// A cost independent of the haptic model: one segment per point.
std::size_t points_cost(const SceneCurve& c) { return c.points_m.size(); }

std::vector<fs::path> pictures() {
  std::vector<fs::path> v;
  for (const auto& e : fs::directory_iterator(std::string(HK_TEST_DATA_DIR) + "/images")) v.push_back(e.path());
  std::sort(v.begin(), v.end());
  return v;
}

SimplifyParams defaults() {
  SimplifyParams p;
  p.thin_line_max_width_m = 0.002;
  p.gap_close_m = 0.001;
  p.min_chain_length_m = 0.002;
  return p;
}

TEST(SceneChains, TheReportAccountsForEveryChainAndTheBudgetsHold) {
  for (const fs::path& file : pictures()) {
    SCOPED_TRACE(file.filename().string());
    SimplifyParams p = defaults();
    p.max_shapes = 10;
    p.max_segments = 2000;
    const SceneChains sc = scene_chains(file.string(), ExtractParams{}, p, points_cost);
    const SimplifyReport& r = sc.report;
    EXPECT_EQ(r.chains_after_gaps, r.chains_too_short + r.chains_along_border + r.chains_over_max_shapes +
                                       r.chains_over_budget + sc.curves.size());
    EXPECT_LE(sc.curves.size(), p.max_shapes);
    std::size_t segments = 0;
    for (const SceneCurve& c : sc.curves) {
      segments += points_cost(c);
      EXPECT_GE(curve_length_m(c), p.min_chain_length_m);
      for (const cv::Point2d& q : c.points_m) {  // within the workspace, centred on the origin
        EXPECT_LE(std::abs(q.x), 0.5 * p.workspace_width_m + 1e-9);
        EXPECT_LE(std::abs(q.y), 0.5 * p.workspace_height_m + 1e-9);
      }
    }
    EXPECT_EQ(segments, r.segments_after_budget);
    EXPECT_LE(segments, p.max_segments);
    EXPECT_TRUE(sc.extraction.chains.empty()) << "moved into the curves";
    if (sc.extraction.detector_used == Detector::Outline) {
      EXPECT_EQ(r.thin_line_pairs_merged, 0u) << "a traced outline is left as it is";
      EXPECT_EQ(r.gaps_closed, 0u);
      EXPECT_EQ(r.chains_after_gaps, r.chains_found);
    }
  }
}

TEST(SceneChains, TheShapesKeptAreTheMostSalient) {
  // With no shape budget every curve long enough to feel is kept (but those along the frame); with a budget of
  // 5, exactly the 5 of them with the highest shape_salience.
  for (const char* name : {"coins.png", "fruits.jpg", "sudoku.png"}) {
    SCOPED_TRACE(name);
    const std::string file = std::string(HK_TEST_DATA_DIR) + "/images/" + name;
    SimplifyParams all = defaults();
    all.max_shapes = 100000;
    all.max_segments = 100000000;
    const SceneChains every = scene_chains(file, ExtractParams{}, all, points_cost);
    ASSERT_GT(every.curves.size(), 5u);
    std::vector<double> salience;
    for (const SceneCurve& c : every.curves)
      salience.push_back(
          shape_salience({curve_length_m(c), c.strength, c.closed, c.closed ? enclosed_area_m2(c.points_m) : 0.0},
                         every.extraction.edge_map.high));
    std::vector<double> sorted = salience;
    std::sort(sorted.rbegin(), sorted.rend());
    SimplifyParams five = all;
    five.max_shapes = 5;
    const SceneChains kept = scene_chains(file, ExtractParams{}, five, points_cost);
    ASSERT_EQ(kept.curves.size(), 5u);
    EXPECT_EQ(kept.report.chains_over_max_shapes, every.curves.size() - 5);
    for (const SceneCurve& c : kept.curves) {
      const auto it = std::find_if(every.curves.begin(), every.curves.end(),
                                   [&](const SceneCurve& e) { return e.points_m == c.points_m; });
      ASSERT_NE(it, every.curves.end()) << "a kept curve is one of all";
      EXPECT_GE(salience[static_cast<std::size_t>(it - every.curves.begin())], sorted[4])
          << "among the five most salient";
    }
  }
}

TEST(SceneChains, InvalidSettingsAreRefused) {
  const std::string file = std::string(HK_TEST_DATA_DIR) + "/images/coins.png";
  SimplifyParams p = defaults();
  p.max_shapes = 0;
  EXPECT_THROW(scene_chains(file, ExtractParams{}, p, points_cost), hk::ArgumentError);
  p = defaults();
  p.gap_close_m = -1.0;
  EXPECT_THROW(scene_chains(file, ExtractParams{}, p, points_cost), hk::ArgumentError);
  p = defaults();
  p.workspace_width_m = 0.0;
  EXPECT_THROW(scene_chains(file, ExtractParams{}, p, points_cost), hk::ArgumentError);
}

// chains_to_curves keeps a chain exactly when its length in metres is not below the minimum: at the
// minimum it stays, a pixel short it goes, a closed chain's closing segment counts, and a kept chain keeps
// every point. Lengths are exact here (2^-12 m per pixel, integer pixels), so the boundary is sharp.
TEST(SceneChains, ChainsToCurvesKeepsExactlyTheChainsNotShorterThanTheMinimum) {
  const double scale = std::ldexp(1.0, -12);  // [m/px], exact in binary
  const PxToM map{scale, 0.0, 0.0};
  const double min_m = 8 * scale;
  const auto straight = [](int px) {
    Chain c;
    for (int u = 0; u <= px; ++u) c.points_px.emplace_back(u, 0);
    return c;
  };
  const auto rectangle = [](int w) {  // w x 1 px, closed: w + 1 + w open, 1 closing
    Chain c;
    c.closed = true;
    c.points_px = {{0, 0}, {static_cast<double>(w), 0}, {static_cast<double>(w), 1}, {0, 1}};
    return c;
  };
  const std::vector<Chain> chains = {straight(8), straight(7), rectangle(3), rectangle(2), straight(1000)};
  const PointValues strengths = {{1.0, 3.0}, {}, {}, {}, {5.0}};
  std::size_t too_short = 0;
  const std::vector<SceneCurve> kept = chains_to_curves(chains, strengths, map, min_m, &too_short);
  ASSERT_EQ(kept.size(), 3u);  // 8 px (at the minimum), the 3 x 1 rectangle (7 + 1 closing), 1000 px
  EXPECT_EQ(too_short, 2u);    // 7 px, and the 2 x 1 rectangle (5 + 1 closing)
  EXPECT_EQ(kept[0].points_m.size(), 9u);
  EXPECT_DOUBLE_EQ(kept[0].strength, 2.0);
  EXPECT_TRUE(kept[1].closed);
  EXPECT_EQ(kept[1].points_m.size(), 4u);
  ASSERT_EQ(kept[2].points_m.size(), 1001u);
  EXPECT_EQ(kept[2].points_m.back(), cv::Point2d(1000 * scale, 0.0));
  EXPECT_DOUBLE_EQ(kept[2].strength, 5.0);
  for (const SceneCurve& c : kept) EXPECT_GE(curve_length_m(c), min_m);
}

}  // namespace
}  // namespace hk::vision
