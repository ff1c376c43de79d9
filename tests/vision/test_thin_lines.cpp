// Thin-line merging: strokes drawn with OpenCV go through the real pipeline
// (detect_edges + link_edges + merge_thin_lines) and the output is checked against the stroke's
// analytical centre line (segment, circle arc), which the pipeline never sees.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"
#include "test_paths.hpp"
#include "vision/edges.hpp"
#include "vision/intake.hpp"
#include "vision/linking.hpp"
#include "vision/thin_lines.hpp"

namespace hk::vision {
namespace {

namespace fs = std::filesystem;

constexpr double kWidthPx = 6.0;  // widest stroke merged (about 1 mm at the kiosk's usual scale)

/// Distance from p to the segment ab [px].
double to_segment(cv::Point2d p, cv::Point2d a, cv::Point2d b) {
  const cv::Point2d ab = b - a;
  const double l2 = ab.dot(ab);
  const double t = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return cv::norm(p - (a + t * ab));
}

/// Distance from p to a chain's polyline (with the closing segment when closed) [px].
double to_chain(cv::Point2d p, const Chain& c) {
  const auto& q = c.points_px;
  double d = q.empty() ? INFINITY : cv::norm(p - q[0]);
  for (std::size_t i = 1; i < q.size(); ++i) d = std::min(d, to_segment(p, q[i - 1], q[i]));
  if (c.closed && q.size() > 1) d = std::min(d, to_segment(p, q.back(), q.front()));
  return d;
}

/// A stroke's true centre line: distance to it, and points along it every 0.5 px.
struct CentreLine {
  std::function<double(cv::Point2d)> distance;
  std::vector<cv::Point2d> samples;
};

CentreLine polyline_centre(const std::vector<cv::Point2d>& v) {
  CentreLine c;
  c.distance = [v](cv::Point2d p) {
    double d = INFINITY;
    for (std::size_t i = 1; i < v.size(); ++i) d = std::min(d, to_segment(p, v[i - 1], v[i]));
    return d;
  };
  for (std::size_t i = 1; i < v.size(); ++i) {
    const int n = static_cast<int>(std::ceil(cv::norm(v[i] - v[i - 1]) / 0.5));
    for (int k = 0; k <= n; ++k) c.samples.push_back(v[i - 1] + (v[i] - v[i - 1]) * (static_cast<double>(k) / n));
  }
  return c;
}

/// Arc of the circle (centre, r) from a0 to a1 degrees, in cv::ellipse's sense (image axes, v down).
CentreLine arc_centre(cv::Point2d centre, double r, double a0, double a1) {
  const double t0 = a0 * std::numbers::pi / 180;
  const double t1 = a1 * std::numbers::pi / 180;
  CentreLine c;
  c.distance = [=](cv::Point2d p) {
    const cv::Point2d d = p - centre;
    double t = std::atan2(d.y, d.x);
    while (t < t0) t += 2 * std::numbers::pi;
    if (t <= t1) return std::abs(cv::norm(d) - r);
    const cv::Point2d e0 = centre + r * cv::Point2d(std::cos(t0), std::sin(t0));
    const cv::Point2d e1 = centre + r * cv::Point2d(std::cos(t1), std::sin(t1));
    return std::min(cv::norm(p - e0), cv::norm(p - e1));
  };
  const int n = static_cast<int>(std::ceil(r * (t1 - t0) / 0.5));
  for (int k = 0; k <= n; ++k) {
    const double t = t0 + (t1 - t0) * k / n;
    c.samples.push_back(centre + r * cv::Point2d(std::cos(t), std::sin(t)));
  }
  return c;
}

/// The real pipeline on a grey image: default Canny, linking, thin-line merging.
std::vector<Chain> pipeline(const cv::Mat& grey, double width_px, ThinLineStats* st,
                            std::vector<Chain>* linked = nullptr) {
  const EdgeMap em = detect_edges(grey, EdgeParams{});
  const std::vector<Chain> chains = link_edges(em.edges, 2.0);
  if (linked != nullptr) *linked = chains;
  return merge_thin_lines(chains, width_px, st);
}

/// Every point of `c` within 1 px of the centre line, and the centre line covered: at least 90 % of
/// its samples within 1.5 px of the chain's polyline.
void expect_on_centre_line(const Chain& c, const CentreLine& line) {
  double worst = 0;
  for (const cv::Point2d& p : c.points_px) worst = std::max(worst, line.distance(p));
  EXPECT_LE(worst, 1.0) << "an output point is off the stroke's centre line";
  std::size_t covered = 0;
  for (const cv::Point2d& s : line.samples) covered += to_chain(s, c) <= 1.5;
  EXPECT_GE(static_cast<double>(covered) / static_cast<double>(line.samples.size()), 0.9)
      << "the centre line is not covered";
}

cv::Mat white(int w, int h) { return cv::Mat(h, w, CV_8UC1, cv::Scalar(255)); }

TEST(MergeThinLines, StraightStrokeIsOneCurveOnItsCentreLine) {
  cv::Mat img = white(500, 360);
  cv::line(img, {60, 100}, {440, 260}, cv::Scalar(0), 3, cv::LINE_AA);
  ThinLineStats st;
  std::vector<Chain> linked;
  const std::vector<Chain> out = pipeline(img, kWidthPx, &st, &linked);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(st.pairs_merged, 1u);
  EXPECT_FALSE(out[0].closed);
  expect_on_centre_line(out[0], polyline_centre({{60, 100}, {440, 260}}));
  // Both sides were found (one loop around the stroke), one curve replaces them.
  std::size_t linked_points = 0;
  for (const Chain& c : linked) linked_points += c.points_px.size();
  EXPECT_EQ(st.points_in, linked_points);
  EXPECT_EQ(st.points_out, out[0].points_px.size());
  EXPECT_LT(st.points_out, st.points_in * 6 / 10);
}

TEST(MergeThinLines, CurvedStrokeIsOneCurveOnItsCentreArc) {
  cv::Mat img = white(500, 420);
  cv::ellipse(img, {250, 210}, {140, 140}, 0, 20, 250, cv::Scalar(0), 3, cv::LINE_AA);
  ThinLineStats st;
  const std::vector<Chain> out = pipeline(img, kWidthPx, &st);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(st.pairs_merged, 1u);
  expect_on_centre_line(out[0], arc_centre({250, 210}, 140, 20, 250));
}

TEST(MergeThinLines, LShapedStrokeIsOneCurveThroughItsCorner) {
  cv::Mat img = white(500, 360);
  const std::vector<cv::Point> corners{{80, 60}, {80, 280}, {420, 280}};
  cv::polylines(img, corners, false, cv::Scalar(0), 3, cv::LINE_AA);
  ThinLineStats st;
  const std::vector<Chain> out = pipeline(img, kWidthPx, &st);
  ASSERT_EQ(out.size(), 1u);
  expect_on_centre_line(out[0], polyline_centre({{80, 60}, {80, 280}, {420, 280}}));
  // The curve turns at the corner, not on a chord cutting it.
  EXPECT_LE(to_chain({80, 280}, out[0]), 1.0);
}

TEST(MergeThinLines, RingIsOneClosedCurve) {
  cv::Mat img = white(400, 400);
  cv::circle(img, {200, 200}, 120, cv::Scalar(0), 3, cv::LINE_AA);
  ThinLineStats st;
  std::vector<Chain> linked;
  const std::vector<Chain> out = pipeline(img, kWidthPx, &st, &linked);
  ASSERT_EQ(linked.size(), 2u) << "Canny gives the ring's outer and inner edges";
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].closed);
  expect_on_centre_line(out[0], arc_centre({200, 200}, 120, 0, 360));
}

TEST(MergeThinLines, GridLinesRunStraightThroughTheirCrossings) {
  // Five horizontal and five vertical strokes: every white cell is a loop of its own, so each line
  // is found as pieces between crossings that must be joined straight on, not round the corners.
  cv::Mat img = white(300, 300);
  for (int k = 50; k < 300; k += 60) {
    cv::line(img, {k, 20}, {k, 280}, cv::Scalar(0), 3);
    cv::line(img, {20, k}, {280, k}, cv::Scalar(0), 3);
  }
  ThinLineStats st;
  const std::vector<Chain> out = pipeline(img, kWidthPx, &st);
  ASSERT_EQ(out.size(), 10u);
  std::vector<int> found(10, 0);
  for (const Chain& c : out) {
    // Which line is it? The one its first point lies on.
    int best = -1;
    double best_d = INFINITY;
    for (int i = 0; i < 10; ++i) {
      const double k = 50 + 60 * (i % 5);
      const double d = i < 5 ? std::abs(c.points_px.front().x - k) : std::abs(c.points_px.front().y - k);
      if (d < best_d) {
        best_d = d;
        best = i;
      }
    }
    ++found[static_cast<std::size_t>(best)];
    const double k = 50 + 60 * (best % 5);
    const CentreLine line = best < 5 ? polyline_centre({{k, 20}, {k, 280}}) : polyline_centre({{20, k}, {280, k}});
    expect_on_centre_line(c, line);
  }
  for (int i = 0; i < 10; ++i) EXPECT_EQ(found[static_cast<std::size_t>(i)], 1) << "line " << i;
}

TEST(MergeThinLines, ThickStrokeKeepsBothSides) {
  cv::Mat img = white(500, 300);
  cv::line(img, {60, 150}, {440, 150}, cv::Scalar(0), 20);  // 21 px: far wider than kWidthPx
  ThinLineStats st;
  std::vector<Chain> linked;
  const std::vector<Chain> out = pipeline(img, kWidthPx, &st, &linked);
  EXPECT_EQ(st.pairs_merged, 0u);
  ASSERT_EQ(out.size(), linked.size());
  for (std::size_t k = 0; k < out.size(); ++k) EXPECT_EQ(out[k].points_px, linked[k].points_px);
  // Both long sides are still there, about 10 px either side of the middle.
  std::size_t above = 0, below = 0;
  for (const Chain& c : out) {
    for (const cv::Point2d& p : c.points_px) {
      if (p.x < 100 || p.x > 400) continue;
      above += p.y < 150 - 8;
      below += p.y > 150 + 8;
    }
  }
  EXPECT_GT(above, 250u);
  EXPECT_GT(below, 250u);
}

TEST(MergeThinLines, TwoStrokesThirtyPixelsApartStayTwoCurves) {
  cv::Mat img = white(500, 300);
  cv::line(img, {60, 120}, {440, 120}, cv::Scalar(0), 3, cv::LINE_AA);
  cv::line(img, {60, 150}, {440, 150}, cv::Scalar(0), 3, cv::LINE_AA);
  ThinLineStats st;
  const std::vector<Chain> out = pipeline(img, kWidthPx, &st);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(st.pairs_merged, 2u);
  const CentreLine upper = polyline_centre({{60, 120}, {440, 120}});
  const CentreLine lower = polyline_centre({{60, 150}, {440, 150}});
  const bool first_is_upper = out[0].points_px.front().y < 135;
  EXPECT_NE(first_is_upper, out[1].points_px.front().y < 135) << "one curve per stroke";
  expect_on_centre_line(out[0], first_is_upper ? upper : lower);
  expect_on_centre_line(out[1], first_is_upper ? lower : upper);
}

TEST(MergeThinLines, CarriesPointValuesAsTheMeanOfTheTwoSides) {
  cv::Mat img = white(400, 400);
  cv::circle(img, {200, 200}, 120, cv::Scalar(0), 3, cv::LINE_AA);
  const EdgeMap em = detect_edges(img, EdgeParams{});
  const std::vector<Chain> chains = link_edges(em.edges, 2.0);
  ASSERT_EQ(chains.size(), 2u);
  PointValues in(2);
  in[0].assign(chains[0].points_px.size(), 10.0);
  in[1].assign(chains[1].points_px.size(), 30.0);
  PointValues values;
  const std::vector<Chain> out = merge_thin_lines(chains, kWidthPx, nullptr, in, &values);
  ASSERT_EQ(out.size(), 1u);
  ASSERT_EQ(values.size(), 1u);
  ASSERT_EQ(values[0].size(), out[0].points_px.size());
  for (const double v : values[0]) EXPECT_DOUBLE_EQ(v, 20.0);
  // Untouched chains keep their values.
  EXPECT_EQ(merge_thin_lines(chains, 0.0, nullptr, in, &values).size(), chains.size());
  EXPECT_EQ(values, in);
  EXPECT_THROW(merge_thin_lines(chains, kWidthPx, nullptr, PointValues(1), &values), hk::ArgumentError);
}

TEST(MergeThinLines, ZeroWidthIsOffAndOutputIsDeterministic) {
  cv::Mat img = white(500, 360);
  cv::line(img, {60, 100}, {440, 260}, cv::Scalar(0), 3, cv::LINE_AA);
  cv::circle(img, {250, 180}, 60, cv::Scalar(0), 2, cv::LINE_AA);
  const std::vector<Chain> chains = link_edges(detect_edges(img, EdgeParams{}).edges, 2.0);
  ThinLineStats st;
  const std::vector<Chain> off = merge_thin_lines(chains, 0.0, &st);
  ASSERT_EQ(off.size(), chains.size());
  for (std::size_t k = 0; k < off.size(); ++k) EXPECT_EQ(off[k].points_px, chains[k].points_px);
  EXPECT_EQ(st.pairs_merged, 0u);
  EXPECT_EQ(st.points_in, st.points_out);
  const std::vector<Chain> a = merge_thin_lines(chains, kWidthPx);
  const std::vector<Chain> b = merge_thin_lines(chains, kWidthPx);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].points_px, b[k].points_px);
    EXPECT_EQ(a[k].closed, b[k].closed);
  }
  EXPECT_TRUE(merge_thin_lines({}, kWidthPx).empty());
}

TEST(MergeThinLines, RejectsABadWidthWithOneLineNamingIt) {
  const std::vector<Chain> chains{Chain{{{0, 0}, {1, 0}, {2, 0}}, false}};
  for (const double w : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    try {
      merge_thin_lines(chains, w);
      ADD_FAILURE() << "no exception for width " << w;
    } catch (const hk::ArgumentError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("max_width_px"), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  const std::vector<Chain> bad{Chain{{{0, 0}, {std::numeric_limits<double>::quiet_NaN(), 0}}, false}};
  EXPECT_THROW(merge_thin_lines(bad, kWidthPx), hk::ArgumentError);
}

TEST(MergeThinLines, RealImagesStayInsideTheImageAndShrink) {
  // Every shipped picture at the kiosk's default resolution (1 mm in processed pixels for the
  // default 0.14 m x 0.09 m workspace): the output stays on the image, never has more points than
  // went in, and merging is fast next to edge detection (printed per image).
  for (const auto& entry : fs::directory_iterator(std::string(HK_TEST_DATA_DIR) + "/images")) {
    const std::string name = entry.path().filename().string();
    SCOPED_TRACE(name);
    const cv::Mat bgr = load_image(entry.path().string(), {});
    double px_scale = 1;
    const cv::Mat grey = to_grey(bgr, 800, &px_scale);
    const double width_px = 0.001 / (std::min(0.14 / bgr.cols, 0.09 / bgr.rows) * px_scale);
    const std::vector<Chain> chains = link_edges(detect_edges(grey, EdgeParams{}).edges, 2.0);
    ThinLineStats st;
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<Chain> out = merge_thin_lines(chains, width_px, &st);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::printf("  %-20s width %5.2f px: chains %4zu -> %4zu, points %6zu -> %6zu, centre lines %3zu, %.2f ms\n",
                name.c_str(), width_px, chains.size(), out.size(), st.points_in, st.points_out, st.pairs_merged, ms);
    EXPECT_LE(st.points_out, st.points_in);
    for (const Chain& c : out) {
      ASSERT_FALSE(c.points_px.empty());
      for (const cv::Point2d& p : c.points_px) {
        ASSERT_TRUE(p.x >= -0.5 && p.y >= -0.5 && p.x <= grey.cols - 0.5 && p.y <= grey.rows - 0.5) << p;
      }
    }
  }
}

}  // namespace
}  // namespace hk::vision
