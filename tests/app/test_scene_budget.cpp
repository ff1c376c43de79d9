// The scene budget (issue 6, item 4): a cluttered photo stays within the segment budget, and the kept
// curves are the long ones — checked against the unbudgeted scene with an independent greedy replay.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <string>

#include "image_scene.hpp"

namespace hk::app {
namespace {

const std::string kImages = std::string(HK_TEST_DATA_DIR) + "/images/";

double length_m(const Polyline& p) {
  double l = 0;
  for (std::size_t i = 1; i < p.points_m.size(); ++i) l += distance(p.points_m[i - 1], p.points_m[i]);
  return l;
}

TEST(SceneBudget, ClutteredPhotoStaysWithinBudgetKeepingTheLongestCurves) {
  for (const char* name : {"fruits.jpg", "sudoku.png"}) {
    SCOPED_TRACE(name);
    config::Settings full_s;
    full_s.vision.max_segments = 1000000;
    const ImageScene full = build_image_scene(kImages + name, full_s);
    config::Settings small_s;
    small_s.vision.max_segments = 2000;
    const ImageScene small = build_image_scene(kImages + name, small_s);
    ASSERT_GT(full.scene->total_segments(0), 2000u) << "the photo must be over the budget to test it";
    EXPECT_LE(small.scene->total_segments(0), 2000u);
    EXPECT_GT(small.chains_over_budget, 0u);
    EXPECT_EQ(small.chains_over_budget + small.polylines.size(), full.polylines.size());
    // Replay the rule on the full scene: longest first, a curve is dropped only if it did not fit.
    std::vector<std::size_t> order(full.scene->curve_count());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return length_m(full.polylines[full.scene->source_index(a)]) > length_m(full.polylines[full.scene->source_index(b)]);
    });
    auto kept = [&](const Polyline& p) {
      return std::any_of(small.polylines.begin(), small.polylines.end(), [&](const Polyline& q) { return q.points_m == p.points_m; });
    };
    std::size_t used = 0;
    for (std::size_t c : order) {
      const Polyline& p = full.polylines[full.scene->source_index(c)];
      const std::size_t n = full.scene->curve(c).segment_count[0];
      if (kept(p)) {
        used += n;
      } else {
        EXPECT_GT(used + n, 2000u) << "a curve of " << length_m(p) << " m was dropped although it fitted";
      }
    }
    EXPECT_TRUE(kept(full.polylines[full.scene->source_index(order[0])])) << "the longest curve is kept";
  }
}

TEST(SceneBudget, DefaultBudgetKeepsEveryCurveOfASimplePicture) {
  const ImageScene s = build_image_scene(kImages + "horse.png", config::Settings{});
  EXPECT_EQ(s.chains_over_budget, 0u);
}

}  // namespace
}  // namespace hk::app
