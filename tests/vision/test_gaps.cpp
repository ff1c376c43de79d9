// Closing small gaps in outlines: close_gaps on synthetic chains whose gaps are known.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "hk/error.hpp"
#include "vision/gaps.hpp"

namespace hk::vision {
namespace {

constexpr double kPxPerMm = 8.0;  // 0.125 mm per pixel, the kiosk's scale on an 800 px wide picture

/// Points about 1 px apart on the circle of radius r [px] round c, from angle a0 to a1 [rad] (a1 > a0).
Chain arc(cv::Point2d c, double r, double a0, double a1) {
  Chain ch;
  const int n = std::max(2, static_cast<int>(std::ceil(r * (a1 - a0))) + 1);
  for (int k = 0; k < n; ++k) {
    const double a = a0 + (a1 - a0) * k / (n - 1);
    ch.points_px.emplace_back(c.x + r * std::cos(a), c.y + r * std::sin(a));
  }
  return ch;
}

/// A circle of radius r cut by `cuts` gaps, each a chord of exactly gap_px between the two ends: `cuts` open
/// arcs.
std::vector<Chain> cut_circle(double r, double gap_px, int cuts) {
  const double g = 2.0 * std::asin(gap_px / (2.0 * r));  // the angle a chord of gap_px spans
  std::vector<Chain> out;
  const double step = 2.0 * std::numbers::pi / cuts;
  for (int k = 0; k < cuts; ++k) out.push_back(arc({200, 200}, r, k * step + g / 2, (k + 1) * step - g / 2));
  return out;
}

GapParams at_one_mm() {
  GapParams p;
  p.max_gap_px = 1.0 * kPxPerMm;
  p.direction_span_px = 2.0 * p.max_gap_px;
  return p;
}

TEST(CloseGaps, AnOutlineCutByHalfAMillimetreOrOneIsClosedAndByTwoIsNot) {
  for (const int cuts : {1, 3}) {
    for (const double gap_mm : {0.5, 1.0, 2.0}) {
      SCOPED_TRACE(testing::Message() << cuts << " cuts of " << gap_mm << " mm");
      const std::vector<Chain> in = cut_circle(150.0, gap_mm * kPxPerMm - 1e-9, cuts);
      GapStats st;
      const std::vector<Chain> out = close_gaps(in, at_one_mm(), &st);
      if (gap_mm <= 1.0) {
        ASSERT_EQ(out.size(), 1u);
        EXPECT_TRUE(out[0].closed);
        EXPECT_EQ(st.joins, static_cast<std::size_t>(cuts));
        EXPECT_EQ(st.chains_closed, 1u);
        // Every point of every arc is in it, in order, and the filled points are at most 1 px apart.
        std::size_t points = 0;
        for (const Chain& c : in) points += c.points_px.size();
        EXPECT_GE(out[0].points_px.size(), points);
        const auto& q = out[0].points_px;
        for (std::size_t i = 0; i < q.size(); ++i) EXPECT_LE(cv::norm(q[(i + 1) % q.size()] - q[i]), 1.0 + 1e-9) << i;
      } else {
        EXPECT_EQ(out.size(), static_cast<std::size_t>(cuts));
        EXPECT_EQ(st.joins, 0u);
        for (const Chain& c : out) EXPECT_FALSE(c.closed);
      }
    }
  }
}

TEST(CloseGaps, EndsSideBySideOrTurnedTooFarAreNotJoined) {
  // Two parallel strokes 4 px apart, ends level with each other (each end beside the other, not facing it):
  // no join.
  Chain a, b;
  for (int x = 0; x <= 60; ++x) a.points_px.emplace_back(x, 10);
  for (int x = 0; x <= 60; ++x) b.points_px.emplace_back(x, 14);
  GapStats st;
  EXPECT_EQ(close_gaps({a, b}, at_one_mm(), &st).size(), 2u);
  EXPECT_EQ(st.joins, 0u);
  // An L with a gap across its corner: e ends at (50, 60) heading +x, f starts at (54, 64) and leaves it
  // heading -y. The join turns 45 degrees from each: joined when 45 are allowed, not when 30 are.
  Chain e, f;
  for (int x = 0; x <= 50; ++x) e.points_px.emplace_back(x, 60);
  for (int y = 64; y <= 110; ++y) f.points_px.emplace_back(54, y);
  GapParams strict = at_one_mm();
  strict.max_turn_deg = 30.0;
  EXPECT_EQ(close_gaps({e, f}, strict, &st).size(), 2u);
  EXPECT_EQ(st.joins, 0u);
  EXPECT_EQ(close_gaps({e, f}, at_one_mm(), &st).size(), 1u);
  EXPECT_EQ(st.joins, 1u);
  // Two strokes on one line with their first points facing each other across 4 px: joined, one reversed.
  Chain c, d;
  for (int x = 50; x >= 0; --x) c.points_px.emplace_back(x, 30);    // first point (50, 30), leaving it +x
  for (int x = 54; x <= 100; ++x) d.points_px.emplace_back(x, 30);  // first point (54, 30), leaving it -x
  const auto cd = close_gaps({c, d}, at_one_mm(), &st);
  ASSERT_EQ(cd.size(), 1u);
  EXPECT_EQ(st.joins, 1u);
  EXPECT_EQ(cd[0].points_px.size(), c.points_px.size() + d.points_px.size() + 3);  // 3 filled, 1 px apart
}

TEST(CloseGaps, AShortStrokeIsNotBentIntoALoop) {
  // A hook whose two ends are 6 px apart (under the gap) but which is only 15 px long (< 3 x the gap): open.
  const Chain hook = arc({100, 100}, 3.5, 0.0, 2.0 * std::numbers::pi - 2.0 * std::asin(6.0 / 7.0));
  ASSERT_LT(cv::norm(hook.points_px.front() - hook.points_px.back()), 6.01);
  GapStats st;
  const auto out = close_gaps({hook}, at_one_mm(), &st);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_FALSE(out[0].closed);
  EXPECT_EQ(st.joins, 0u);
}

TEST(CloseGaps, TheNearestFacingEndIsTakenAndValuesFollowTheirPoints) {
  // Three strokes on one line, x in [0, 40], [44, 80] and [86, 120]: both gaps are under the limit, each end
  // joins once, so all three become one chain; a closed chain passes through untouched.
  Chain a, b, c;
  for (int x = 0; x <= 40; ++x) a.points_px.emplace_back(x, 5);
  for (int x = 80; x >= 44; --x) b.points_px.emplace_back(x, 5);  // stored right to left: entered reversed
  for (int x = 86; x <= 120; ++x) c.points_px.emplace_back(x, 5);
  const Chain ring = arc({60, 60}, 20, 0, 2 * std::numbers::pi);
  Chain loop = ring;
  loop.points_px.pop_back();
  loop.closed = true;
  PointValues v(4);
  for (const Chain* ch : {&a, &b, &c, &loop}) {
    auto& vals = v[static_cast<std::size_t>(ch == &a ? 0 : ch == &b ? 1 : ch == &c ? 2 : 3)];
    for (const cv::Point2d& q : ch->points_px) vals.push_back(q.x);  // the value is the point's x
  }
  GapStats st;
  PointValues vout;
  const auto out = close_gaps({a, b, c, loop}, at_one_mm(), &st, v, &vout);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(st.joins, 2u);
  EXPECT_EQ(st.chains_closed, 0u);
  EXPECT_FALSE(out[0].closed);
  ASSERT_EQ(vout.size(), 2u);
  ASSERT_EQ(vout[0].size(), out[0].points_px.size());
  for (std::size_t i = 0; i < out[0].points_px.size(); ++i) {
    EXPECT_NEAR(vout[0][i], out[0].points_px[i].x, 1e-9) << i;  // values follow; filled ones interpolate
    if (i > 0) {
      EXPECT_GT(out[0].points_px[i].x, out[0].points_px[i - 1].x) << "in order along the line";
    }
  }
  EXPECT_DOUBLE_EQ(out[0].points_px.front().x, 0.0);
  EXPECT_DOUBLE_EQ(out[0].points_px.back().x, 120.0);
  EXPECT_TRUE(out[1].closed);
  EXPECT_EQ(out[1].points_px, loop.points_px);
}

TEST(CloseGaps, RefusesBadInput) {
  GapParams p = at_one_mm();
  p.max_gap_px = -1;
  EXPECT_THROW(close_gaps({}, p), hk::ArgumentError);
  p = at_one_mm();
  p.max_turn_deg = 0;
  EXPECT_THROW(close_gaps({}, p), hk::ArgumentError);
  p.max_turn_deg = 91;
  EXPECT_THROW(close_gaps({}, p), hk::ArgumentError);
  EXPECT_THROW(close_gaps({Chain{}}, at_one_mm()), hk::ArgumentError);
  Chain a;
  a.points_px = {{0, 0}, {1, 0}};
  EXPECT_THROW(close_gaps({a}, at_one_mm(), nullptr, PointValues{{1.0}}), hk::ArgumentError);
  EXPECT_TRUE(close_gaps({}, at_one_mm()).empty());
}

}  // namespace
}  // namespace hk::vision
