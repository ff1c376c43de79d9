// The scene budget: a cluttered photo stays within the segment budget, and the kept
// curves are the most salient ones (long and strong, tests/support/curve_salience.hpp) — checked against
// the unbudgeted scene with an independent greedy replay of the documented rule, on a synthetic
// picture where strength must beat length, and on a real photo.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <numeric>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "curve_salience.hpp"
#include "pictures/image_scene.hpp"
#include "test_paths.hpp"

namespace hk::app {
namespace {

using hk::test::curve_salience;

namespace fs = std::filesystem;

const std::string kImages = std::string(HK_TEST_DATA_DIR) + "/images/";

double length_m(const Polyline& p) {
  double l = 0;
  for (std::size_t i = 1; i < p.points_m.size(); ++i) l += distance(p.points_m[i - 1], p.points_m[i]);
  if (p.closed && p.points_m.size() > 1) l += distance(p.points_m.back(), p.points_m.front());
  return l;
}

/// The rule of image_scene.hpp (shape_salience), written out again: (length + closed · 2·√area) ·
/// max(strength, 0) / canny_high, the area by the shoelace formula.
double salience(const Polyline& p, double strength, double canny_high) {
  double twice_area = 0;
  for (std::size_t i = 0; p.closed && i < p.points_m.size(); ++i) {
    const Vec2 a = p.points_m[i], b = p.points_m[(i + 1) % p.points_m.size()];
    twice_area += a.x * b.y - b.x * a.y;
  }
  return (length_m(p) + 2 * std::sqrt(std::abs(twice_area) / 2)) * std::max(strength, 0.0) / canny_high;
}

/// Index in `in` of each of `of` (exact polyline equality), or npos.
std::vector<std::size_t> find_all(const std::vector<Polyline>& of, const std::vector<Polyline>& in) {
  std::vector<std::size_t> out;
  for (const Polyline& p : of) {
    const auto it = std::find_if(in.begin(), in.end(),
                                 [&](const Polyline& q) { return q.points_m == p.points_m && q.closed == p.closed; });
    out.push_back(it == in.end() ? std::string::npos : static_cast<std::size_t>(it - in.begin()));
  }
  return out;
}

TEST(SceneBudget, ClutteredPhotoStaysWithinBudgetKeepingTheMostSalientCurves) {
  for (const char* name : {"fruits.jpg", "sudoku.png"}) {
    SCOPED_TRACE(name);
    config::Settings full_s;
    full_s.vision.max_segments = 1000000;
    full_s.vision.max_shapes = 1000;  // the segment budget alone
    const ImageScene full = build_image_scene(kImages + name, full_s);
    config::Settings small_s;
    small_s.vision.max_segments = 2000;
    small_s.vision.max_shapes = 1000;  // the segment budget alone
    const ImageScene small = build_image_scene(kImages + name, small_s);
    ASSERT_GT(full.scene->total_segments(0), 2000u) << "the photo must be over the budget to test it";
    EXPECT_LE(small.scene->total_segments(0), 2000u);
    EXPECT_EQ(small.segments_before_budget, full.segments_before_budget);
    EXPECT_EQ(small.chains_along_border, full.chains_along_border);
    EXPECT_EQ(small.segments_after_budget, small.scene->total_segments(0));
    EXPECT_GT(small.chains_over_budget, 0u);
    EXPECT_EQ(small.chains_over_budget + small.polylines.size(), full.polylines.size());
    EXPECT_EQ(small.chains_after_gaps, small.chains_too_short + small.chains_along_border +
                                           small.chains_over_max_shapes + small.chains_over_budget +
                                           small.polylines.size());
    // Kept curves are full's curves, with full's strengths.
    const std::vector<std::size_t> where = find_all(small.polylines, full.polylines);
    for (std::size_t i = 0; i < where.size(); ++i) {
      ASSERT_NE(where[i], std::string::npos) << "kept curve " << i << " is not a curve of the unbudgeted scene";
      EXPECT_EQ(small.strength[i], full.strength[where[i]]);
    }
    std::vector<char> kept(full.polylines.size(), 0);
    for (const std::size_t i : where) kept[i] = 1;
    // Replay the rule on the full scene: most salient first, a curve is dropped only if it did not fit.
    std::vector<std::size_t> order(full.scene->curve_count());
    std::iota(order.begin(), order.end(), 0);
    const auto sal = [&](std::size_t c) {
      const std::size_t i = full.scene->source_index(c);
      return salience(full.polylines[i], full.strength[i], full.canny_high);
    };
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return sal(a) > sal(b); });
    std::size_t used = 0;
    for (std::size_t c : order) {
      const std::size_t i = full.scene->source_index(c);
      const std::size_t n = full.scene->curve(c).segment_count[0];
      if (kept[i]) {
        used += n;
      } else {
        EXPECT_GT(used + n, 2000u) << "a curve of salience " << sal(c) << " was dropped although it fitted";
      }
    }
    EXPECT_TRUE(kept[full.scene->source_index(order[0])]) << "the most salient curve is kept";
  }
}

TEST(SceneBudget, AStrongEdgeBeatsALongerFaintOne) {
  // Two boundaries across a 1200 x 500 picture: at the top a straight, strong step (120 grey levels);
  // lower down a wavy, hence longer, step that is strong only at its left end (contrast 40, enough
  // to seed Canny's hysteresis) and faint (12) for the rest. A budget that fits only one of them
  // must keep the strong one, although "longest first" would keep the faint one.
  const fs::path path =
      fs::temp_directory_path() /
      ("hk_budget_faint_" + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + ".png");
  cv::Mat img(500, 1200, CV_8UC1);
  for (int v = 0; v < img.rows; ++v) {
    for (int u = 0; u < img.cols; ++u) {
      const double wave = 330 + 40 * std::sin(2 * std::numbers::pi * u / 150.0);
      const double contrast = 12 + 28 * std::exp(-u / 60.0);
      double g = v < 150 ? 220 : 100;
      if (v >= wave) g = 100 + contrast;
      img.at<std::uint8_t>(v, u) = cv::saturate_cast<std::uint8_t>(g);
    }
  }
  ASSERT_TRUE(cv::imwrite(path.string(), img));
  config::Settings s;
  s.vision.canny_high = 60;  // the strong edge (~250 units) is sure, the faint one (~25) is only linked
  s.vision.canny_low = 15;
  s.vision.max_segments = 1000000;
  s.vision.max_shapes = 1000;   // the segment budget alone
  s.vision.detector = "canny";  // the faint step is under the two-tone spread: "auto" would trace only the strong one
  const ImageScene full = build_image_scene(path.string(), s);
  // Which curve is which: the strong one lies on v = 150 (y of pixel row 149.5).
  const auto is_strong = [&](const Polyline& p) {
    return std::all_of(p.points_m.begin(), p.points_m.end(),
                       [&](const Vec2& q) { return std::abs(full.px_to_m.v_px(q.y) - 149.5) < 2; });
  };
  std::size_t strong = std::string::npos, faint = std::string::npos;
  for (std::size_t i = 0; i < full.polylines.size(); ++i) {
    if (is_strong(full.polylines[i])) {
      strong = i;
    } else if (faint == std::string::npos || length_m(full.polylines[i]) > length_m(full.polylines[faint])) {
      faint = i;
    }
  }
  ASSERT_NE(strong, std::string::npos);
  ASSERT_NE(faint, std::string::npos);
  // The premise: the faint curve is the longer one, its mean strength below canny_high, the strong one's above.
  ASSERT_GT(length_m(full.polylines[faint]), 1.1 * length_m(full.polylines[strong]));
  ASSERT_LT(full.strength[faint], 0.8 * s.vision.canny_high);
  ASSERT_GT(full.strength[strong], s.vision.canny_high);
  std::size_t n_strong = 0, n_faint = 0;
  for (std::size_t c = 0; c < full.scene->curve_count(); ++c) {
    if (full.scene->source_index(c) == strong) n_strong = full.scene->curve(c).segment_count[0];
    if (full.scene->source_index(c) == faint) n_faint = full.scene->curve(c).segment_count[0];
  }
  std::printf(
      "  strong: %.1f mm, strength %.0f, %zu segments; faint: %.1f mm, strength %.0f, %zu segments (canny_high %.0f)\n",
      length_m(full.polylines[strong]) * 1000, full.strength[strong], n_strong, length_m(full.polylines[faint]) * 1000,
      full.strength[faint], n_faint, full.canny_high);
  s.vision.max_segments = static_cast<int>(std::max(n_strong, n_faint));
  s.vision.max_shapes = 1000;  // the segment budget alone
  ASSERT_LT(static_cast<std::size_t>(s.vision.max_segments), n_strong + n_faint) << "the budget must fit only one";
  const ImageScene small = build_image_scene(path.string(), s);
  fs::remove(path);
  const std::vector<std::size_t> where = find_all(small.polylines, full.polylines);
  EXPECT_NE(std::find(where.begin(), where.end(), strong), where.end()) << "the strong edge was dropped";
  EXPECT_EQ(std::find(where.begin(), where.end(), faint), where.end()) << "the faint edge was kept";
}

TEST(SceneBudget, KeptCurvesOfARealPhotoAreStrongerAndLongerThanTheDropped) {
  config::Settings full_s;
  full_s.vision.max_segments = 1000000;
  full_s.vision.max_shapes = 1000;  // the segment budget alone
  const ImageScene full = build_image_scene(kImages + "fruits.jpg", full_s);
  config::Settings small_s;
  small_s.vision.max_segments = 1500;
  small_s.vision.max_shapes = 1000;  // the segment budget alone
  const ImageScene small = build_image_scene(kImages + "fruits.jpg", small_s);
  ASSERT_GT(small.chains_over_budget, 0u);
  std::vector<char> kept(full.polylines.size(), 0);
  for (const std::size_t i : find_all(small.polylines, full.polylines)) {
    ASSERT_NE(i, std::string::npos);
    kept[i] = 1;
  }
  double kept_sum = 0, dropped_sum = 0;
  std::size_t kept_n = 0, dropped_n = 0;
  for (std::size_t i = 0; i < full.polylines.size(); ++i) {
    const double sl = full.strength[i] * length_m(full.polylines[i]);
    (kept[i] ? kept_sum : dropped_sum) += sl;
    ++(kept[i] ? kept_n : dropped_n);
  }
  ASSERT_GT(kept_n, 0u);
  ASSERT_GT(dropped_n, 0u);
  EXPECT_GE(kept_sum / kept_n, dropped_sum / dropped_n) << "mean strength x length of the kept curves";
  std::printf("  fruits.jpg, budget 1500: %zu kept, mean strength x length %.3g; %zu dropped, %.3g\n", kept_n,
              kept_sum / kept_n, dropped_n, dropped_sum / dropped_n);
}

TEST(SceneBudget, DefaultBudgetKeepsEveryCurveOfASimplePicture) {
  const ImageScene s = build_image_scene(kImages + "horse.png", config::Settings{});
  EXPECT_EQ(s.chains_over_budget, 0u);
  EXPECT_EQ(s.segments_before_budget, s.segments_after_budget);
}

TEST(SceneBudget, SalienceRule) {
  EXPECT_DOUBLE_EQ(curve_salience(0.05, 300, 100), 0.05);  // sure edges: length alone
  EXPECT_DOUBLE_EQ(curve_salience(0.05, 50, 100), 0.025);  // half as strong as sure: half the weight
  EXPECT_DOUBLE_EQ(curve_salience(0.05, -1, 100), 0.0);
  EXPECT_DOUBLE_EQ(curve_salience(0.05, 50, 0), 0.0);
  EXPECT_DOUBLE_EQ(curve_salience(0.05, NAN, 100), 0.0);
}

}  // namespace
}  // namespace hk::app
