// Thin lines in the scene: end to end on real pictures, build_image_scene with
// thin-line merging on gives fewer level-0 segments than with it off, and no two walls of the scene
// run side by side closer than vision.thin_line_max_width_m — checked on the output polylines by an
// independent search for parallel stretches, which finds plenty of them with merging off.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>
#include <unordered_map>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pictures/image_scene.hpp"
#include "test_paths.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;

const std::string kImages = std::string(HK_TEST_DATA_DIR) + "/images/";

/// A stretch where a curve runs alongside another curve (or a far part of itself).
struct Doubled {
  std::size_t curve = 0;
  double length_m = 0;  ///< along the curve
  Vec2 at{};            ///< where it starts
};

/// Stretches of the curves, longer than min_run_m, along which every point has a wall of another
/// curve (or of a part of the same curve more than 3 gaps away along it) within max_gap_m, running
/// within 20 degrees of parallel, across a gap within 30 degrees of the normal. Samples every
/// max_gap_m / 4; hashed into cells of max_gap_m.
std::vector<Doubled> parallel_stretches(const std::vector<Polyline>& curves, double max_gap_m, double min_run_m) {
  struct Sample {
    Vec2 p, t;
    std::size_t curve;
    double s;  // arc length from the curve's start
  };
  std::vector<Sample> samples;
  std::vector<double> total(curves.size(), 0.0);
  std::vector<std::vector<std::size_t>> of_curve(curves.size());
  const double step = max_gap_m / 4;
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const auto& q = curves[c].points_m;
    const std::size_t n = q.size();
    const std::size_t segs = curves[c].closed ? n : n - 1;
    double s = 0;
    for (std::size_t i = 0; n >= 2 && i < segs; ++i) {
      const Vec2 a = q[i];
      const Vec2 b = q[(i + 1) % n];
      const double l = distance(a, b);
      if (l <= 0) continue;
      const Vec2 t = (b - a) * (1.0 / l);
      const int parts = static_cast<int>(std::ceil(l / step));
      for (int k = 0; k < parts; ++k) {
        const double f = static_cast<double>(k) / parts;
        of_curve[c].push_back(samples.size());
        samples.push_back({a + (b - a) * f, t, c, s + l * f});
      }
      s += l;
    }
    total[c] = s;
  }
  const auto key = [&](double x, double y) {
    return (static_cast<long long>(std::floor(x / max_gap_m)) << 32) ^
           static_cast<long long>(std::floor(y / max_gap_m) + (1LL << 31));
  };
  std::unordered_map<long long, std::vector<std::size_t>> grid;
  for (std::size_t i = 0; i < samples.size(); ++i) grid[key(samples[i].p.x, samples[i].p.y)].push_back(i);
  const double cos_par = std::cos(20.0 * std::numbers::pi / 180.0);
  const double sin_norm = std::sin(30.0 * std::numbers::pi / 180.0);
  std::vector<char> doubled(samples.size(), 0);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Sample& a = samples[i];
    for (int dx = -1; dx <= 1 && !doubled[i]; ++dx) {
      for (int dy = -1; dy <= 1 && !doubled[i]; ++dy) {
        const auto it = grid.find(key(a.p.x + dx * max_gap_m, a.p.y + dy * max_gap_m));
        if (it == grid.end()) continue;
        for (const std::size_t j : it->second) {
          const Sample& b = samples[j];
          const double d = distance(a.p, b.p);
          if (d > max_gap_m || d < 1e-12) continue;
          if (a.curve == b.curve) {
            double sep = std::abs(a.s - b.s);
            if (curves[a.curve].closed) sep = std::min(sep, total[a.curve] - sep);
            if (sep < 3 * max_gap_m) continue;
          }
          const Vec2 u = (b.p - a.p) * (1.0 / d);
          if (std::abs(dot(a.t, b.t)) < cos_par) continue;
          if (std::abs(dot(u, a.t)) > sin_norm || std::abs(dot(u, b.t)) > sin_norm) continue;
          doubled[i] = 1;
          break;
        }
      }
    }
  }
  std::vector<Doubled> out;
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const auto& idx = of_curve[c];
    for (std::size_t k = 0; k < idx.size();) {
      if (!doubled[idx[k]]) {
        ++k;
        continue;
      }
      std::size_t e = k;
      while (e + 1 < idx.size() && doubled[idx[e + 1]]) ++e;
      const double len = samples[idx[e]].s - samples[idx[k]].s + step;
      if (len >= min_run_m) out.push_back({c, len, samples[idx[k]].p});
      k = e + 1;
    }
  }
  return out;
}

TEST(ThinLineScene, SudokuLinesAreFeltOnceWithFewerSegments) {
  config::Settings on;  // defaults: thin_line_max_width_m = 1 mm
  on.vision.max_segments = 1000000;
  config::Settings off = on;
  off.vision.thin_line_max_width_m = 0.0;
  const ImageScene merged = build_image_scene(kImages + "sudoku.png", on);
  const ImageScene plain = build_image_scene(kImages + "sudoku.png", off);
  const double w = on.vision.thin_line_max_width_m;
  EXPECT_GT(merged.thin_line_pairs_merged, 10u);
  EXPECT_EQ(plain.thin_line_pairs_merged, 0u);
  EXPECT_EQ(merged.chains_found, plain.chains_found);
  EXPECT_LT(merged.scene->total_segments(0), plain.scene->total_segments(0) * 8 / 10);
  // The check finds the doubled walls of the unmerged scene (so it is not vacuous) ...
  const std::vector<Doubled> before = parallel_stretches(plain.polylines, w, 3 * w);
  EXPECT_GT(before.size(), 20u);
  // ... and none are left after merging.
  const std::vector<Doubled> after = parallel_stretches(merged.polylines, w, 3 * w);
  for (const Doubled& d : after) {
    ADD_FAILURE() << "curve " << d.curve << " runs alongside another wall for " << d.length_m * 1000 << " mm from ("
                  << d.at.x << ", " << d.at.y << ")";
  }
  std::printf("  sudoku.png: level-0 segments %zu -> %zu with merging, parallel stretches %zu -> %zu\n",
              plain.scene->total_segments(0), merged.scene->total_segments(0), before.size(), after.size());
}

TEST(ThinLineScene, ALineDrawingIsOneCurvePerStroke) {
  // A drawing of three strokes (a line, an arc, an L) 0.5 mm wide at the kiosk's scale, end to end
  // through the file, the app's unit conversion and the scale-back from a shrunk image: one curve
  // per stroke, on the stroke's centre line.
  const fs::path path =
      fs::temp_directory_path() /
      ("hk_thin_drawing_" + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + ".png");
  cv::Mat img(1000, 1600, CV_8UC3, cv::Scalar(255, 255, 255));  // shrunk to 800 x 500 for edges
  cv::line(img, {200, 150}, {1400, 250}, cv::Scalar(0, 0, 0), 6, cv::LINE_AA);
  cv::ellipse(img, {500, 600}, {250, 250}, 0, 200, 340, cv::Scalar(0, 0, 0), 6, cv::LINE_AA);
  const std::vector<cv::Point> l{{1000, 400}, {1000, 850}, {1450, 850}};
  cv::polylines(img, l, false, cv::Scalar(0, 0, 0), 6, cv::LINE_AA);
  ASSERT_TRUE(cv::imwrite(path.string(), img));
  const ImageScene is = build_image_scene(path.string(), config::Settings{});
  fs::remove(path);
  EXPECT_EQ(is.chains_found, 3u);  // one loop round each stroke
  EXPECT_EQ(is.thin_line_pairs_merged, 3u);
  ASSERT_EQ(is.polylines.size(), 3u);
  // Each stroke's centre line in metres, as a distance function.
  const vision::PxToM& m = is.px_to_m;
  const auto seg = [&](Vec2 p, cv::Point2d a, cv::Point2d b) {
    const Vec2 am{m.x_m(a.x), m.y_m(a.y)};
    const Vec2 bm{m.x_m(b.x), m.y_m(b.y)};
    const Vec2 ab = bm - am;
    const double t = std::clamp(dot(p - am, ab) / dot(ab, ab), 0.0, 1.0);
    return distance(p, am + ab * t);
  };
  const auto on_arc = [&](Vec2 p) {
    const Vec2 c{m.x_m(500), m.y_m(600)};
    return std::abs(distance(p, c) - 250 * m.scale_m_per_px);
  };
  const auto nearest = [&](Vec2 p) {
    return std::min({seg(p, {200, 150}, {1400, 250}), on_arc(p),
                     std::min(seg(p, {1000, 400}, {1000, 850}), seg(p, {1000, 850}, {1450, 850}))});
  };
  // 1 processed pixel = 2 original pixels.
  const double tol_m = 2.0 * m.scale_m_per_px;
  for (const Polyline& p : is.polylines) {
    for (const Vec2& q : p.points_m) ASSERT_LE(nearest(q), tol_m);
  }
  EXPECT_TRUE(parallel_stretches(is.polylines, config::Settings{}.vision.thin_line_max_width_m, 0.003).empty());
}

TEST(ThinLineScene, ShippedPicturesSegmentsBeforeAndAfter) {
  // Every shipped picture with merging off and on (default settings otherwise): merging never adds
  // level-0 segments beyond a few corner points, the accounting of dropped chains adds up, and the
  // budget holds. Prints the figures.
  for (const auto& entry : fs::directory_iterator(kImages)) {
    const std::string name = entry.path().filename().string();
    SCOPED_TRACE(name);
    config::Settings on;
    config::Settings off = on;
    off.vision.thin_line_max_width_m = 0.0;
    const ImageScene a = build_image_scene(entry.path().string(), off);
    const ImageScene b = build_image_scene(entry.path().string(), on);
    for (const ImageScene* s : {&a, &b}) {
      EXPECT_EQ(s->chains_after_gaps, s->chains_too_short + s->chains_along_border + s->chains_over_max_shapes +
                                          s->chains_over_budget + s->polylines.size());
      EXPECT_EQ(s->strength.size(), s->polylines.size());
      EXPECT_EQ(s->segments_after_budget, s->scene->total_segments(0));
      EXPECT_LE(s->segments_after_budget, static_cast<std::size_t>(on.vision.max_segments));
      EXPECT_LE(s->polylines.size(), static_cast<std::size_t>(on.vision.max_shapes));
      EXPECT_LE(s->segments_after_budget, s->segments_before_budget);
    }
    EXPECT_EQ(a.chains_after_thin_lines, a.chains_found);
    EXPECT_LE(b.segments_before_budget, a.segments_before_budget + 8);
    const double w = on.vision.thin_line_max_width_m;
    std::printf(
        "  %-18s chains %4zu, centre lines %3zu, level-0 segments %6zu -> %6zu, doubled stretches %3zu -> %3zu, merge "
        "%.2f ms\n",
        name.c_str(), b.chains_found, b.thin_line_pairs_merged, a.segments_before_budget, b.segments_before_budget,
        parallel_stretches(a.polylines, w, 3 * w).size(), parallel_stretches(b.polylines, w, 3 * w).size(),
        b.times.thin_lines_ms);
    for (const Doubled& d : parallel_stretches(b.polylines, w, 3 * w)) {
      std::printf("    doubled: %.1f mm from pixel (%.0f, %.0f)\n", d.length_m * 1000, b.px_to_m.u_px(d.at.x),
                  b.px_to_m.v_px(d.at.y));
    }
  }
}

}  // namespace
}  // namespace hk::app
