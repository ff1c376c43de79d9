// The framing guide's state machine on hand-made frame looks; the same guide on real frame
// sequences from the file source is tested end to end in tests/app/test_capture.cpp.

#include <gtest/gtest.h>

#include <limits>

#include <opencv2/imgproc.hpp>

#include <optional>
#include <stdexcept>
#include <vector>

#include "hk/error.hpp"
#include "synthetic_photo.hpp"
#include "vision/framing.hpp"

namespace hk::vision {
namespace {

constexpr int kW = 640, kH = 480;

/// A look at a 640 x 480 frame: a page of w x h px centred at (cx, cy) (no page when w = 0), lit, with detail.
FrameLook look(double t_s, double cx, double cy, double w = 300, double h = 220, double motion = 1.0,
               double corner_motion = 0.001) {
  FrameLook l;
  l.t_s = t_s;
  l.width_px = kW;
  l.height_px = kH;
  l.mean_grey = 120;
  l.detail = 40;
  l.motion = motion;
  if (w > 0) {
    l.page.found = true;
    l.page.corners_px = {cv::Point2d(cx - w / 2, cy - h / 2), cv::Point2d(cx + w / 2, cy - h / 2),
                         cv::Point2d(cx + w / 2, cy + h / 2), cv::Point2d(cx - w / 2, cy + h / 2)};
    l.corner_motion = corner_motion;
  }
  return l;
}

/// Feeds the looks until the guide captures (as a capture does) and returns what was said, in order, and the time
/// of the capture (if any).
struct Heard {
  std::vector<FramingAdvice> said;
  std::optional<double> captured_at_s;
};
Heard run(FramingGuide& g, const std::vector<FrameLook>& looks) {
  Heard h;
  for (const FrameLook& l : looks) {
    const FramingStep s = g.update(l);
    if (s.say) h.said.push_back(*s.say);
    if (s.capture) {
      h.captured_at_s = l.t_s;
      break;
    }
  }
  return h;
}

TEST(FramingGuide, AStillCentredPageIsCapturedAfterOneSecondAndNothingIsSaid) {
  FramingGuide g;
  std::vector<FrameLook> looks;
  for (int i = 0; i < 30; ++i)
    looks.push_back(look(i * 0.1, kW / 2.0, kH / 2.0, 300, 220, i == 0 ? -1.0 : 1.0, i == 0 ? -1.0 : 0.001));
  const Heard h = run(g, looks);
  EXPECT_TRUE(h.said.empty());
  ASSERT_TRUE(h.captured_at_s.has_value());
  // The first frame cannot be known still; still from t = 0.1 s, so captured at 1.1 s.
  EXPECT_NEAR(*h.captured_at_s, 1.1, 1e-9);
}

TEST(FramingGuide, EachProblemHasItsAdviceInOrderOfUrgency) {
  const FramingGuide g;
  FrameLook dark = look(0, kW / 2.0, kH / 2.0);
  dark.mean_grey = 20;
  dark.page.touches_frame[0] = true;  // dark wins over cut off
  EXPECT_EQ(g.advice_for(dark), FramingAdvice::TooDark);
  EXPECT_EQ(g.advice_for(look(0, 0, 0, 0, 0)), FramingAdvice::PlacePicture);
  FrameLook cut = look(0, kW / 2.0, 100);
  cut.page.touches_frame[0] = true;
  cut.motion = 30;  // cut off wins over moving
  EXPECT_EQ(g.advice_for(cut), FramingAdvice::CutOffTop);
  cut.page.touches_frame = {false, true, true, false};
  EXPECT_EQ(g.advice_for(cut), FramingAdvice::CutOffBottom);
  cut.page.touches_frame = {false, true, false, false};
  EXPECT_EQ(g.advice_for(cut), FramingAdvice::CutOffRight);
  cut.page.touches_frame = {false, false, false, true};
  EXPECT_EQ(g.advice_for(cut), FramingAdvice::CutOffLeft);
  // Off centre by more than 15 % of the frame: the page must go back towards the middle.
  EXPECT_EQ(g.advice_for(look(0, kW * 0.70, kH / 2.0)), FramingAdvice::MoveLeft);
  EXPECT_EQ(g.advice_for(look(0, kW * 0.30, kH / 2.0)), FramingAdvice::MoveRight);
  EXPECT_EQ(g.advice_for(look(0, kW / 2.0, kH * 0.70)), FramingAdvice::MoveUp);
  EXPECT_EQ(g.advice_for(look(0, kW / 2.0, kH * 0.30)), FramingAdvice::MoveDown);
  EXPECT_EQ(g.advice_for(look(0, kW * 0.60, kH * 0.40)), std::nullopt) << "within the tolerance";
  // The larger offset is named first.
  EXPECT_EQ(g.advice_for(look(0, kW * 0.75, kH * 0.30)), FramingAdvice::MoveLeft);
  // Moving: the frame changes, or a corner moves.
  EXPECT_EQ(g.advice_for(look(0, kW / 2.0, kH / 2.0, 300, 220, 10.0)), FramingAdvice::HoldStill);
  EXPECT_EQ(g.advice_for(look(0, kW / 2.0, kH / 2.0, 300, 220, 1.0, 0.02)), FramingAdvice::HoldStill);
  EXPECT_EQ(g.advice_for(look(0, kW / 2.0, kH / 2.0)), std::nullopt);
}

TEST(FramingGuide, APageBroughtInFromTheRightIsGuidedThenCaptured) {
  FramingGuide g;
  std::vector<FrameLook> looks;
  double t = 0;
  for (int i = 0; i < 5; ++i, t += 0.1) looks.push_back(look(t, 0, 0, 0, 0, i == 0 ? -1 : 1.0));  // empty table
  FrameLook cut = look(t, kW - 100.0, kH / 2.0, 300, 220, 20.0, -1.0);
  cut.page.touches_frame[1] = true;
  looks.push_back(cut);
  t += 0.1;
  for (double x = kW * 0.78; x > kW * 0.5; x -= 20, t += 0.1)
    looks.push_back(look(t, x, kH / 2.0, 300, 220, 8.0, 0.03));  // sliding left
  for (int i = 0; i < 3; ++i, t += 0.1)
    looks.push_back(look(t, kW * 0.5, kH / 2.0, 300, 220, 8.0, 0.02));  // still settling
  const double settled_s = t;
  for (int i = 0; i < 15; ++i, t += 0.1) looks.push_back(look(t, kW * 0.5, kH / 2.0));
  const Heard h = run(g, looks);
  const std::vector<FramingAdvice> expected = {FramingAdvice::PlacePicture, FramingAdvice::CutOffRight,
                                               FramingAdvice::MoveLeft, FramingAdvice::HoldStill};
  EXPECT_EQ(h.said, expected);
  ASSERT_TRUE(h.captured_at_s.has_value());
  EXPECT_NEAR(*h.captured_at_s, settled_s + 1.0, 1e-9);
}

TEST(FramingGuide, TheSameAdviceIsRepeatedOnlyAfterRepeatS) {
  FramingParams p;
  p.repeat_s = 3.0;
  FramingGuide g(p);
  std::vector<FrameLook> looks;
  for (int i = 0; i < 70; ++i) looks.push_back(look(i * 0.1, kW * 0.8, kH / 2.0));  // 7 s off to the right
  const Heard h = run(g, looks);
  EXPECT_EQ(h.said, std::vector<FramingAdvice>(3, FramingAdvice::MoveLeft)) << "at 0, 3 and 6 s";
  EXPECT_FALSE(h.captured_at_s.has_value());
}

TEST(FramingGuide, AMovingPageIsNeverCapturedAndAPauseShorterThanStillSIsNotEnough) {
  FramingGuide g;
  std::vector<FrameLook> looks;
  double t = 0;
  for (int round = 0; round < 5; ++round) {
    for (int i = 0; i < 9; ++i, t += 0.1) looks.push_back(look(t, kW / 2.0, kH / 2.0));  // 0.9 s still
    looks.push_back(look(t, kW / 2.0, kH / 2.0, 300, 220, 12.0, 0.02));                  // a jolt
    t += 0.1;
  }
  const Heard h = run(g, looks);
  EXPECT_FALSE(h.captured_at_s.has_value());
  ASSERT_FALSE(h.said.empty());
  EXPECT_EQ(h.said.front(), FramingAdvice::HoldStill);
}

TEST(FramingGuide, APictureFillingTheFrameIsCapturedWholeAfterWholeFrameAfterS) {
  FramingGuide g;
  std::vector<FrameLook> looks;
  for (int i = 0; i < 50; ++i) looks.push_back(look(i * 0.1, 0, 0, 0, 0, i == 0 ? -1.0 : 1.0));
  const Heard h = run(g, looks);
  EXPECT_EQ(h.said, std::vector<FramingAdvice>{FramingAdvice::PlacePicture})
      << "said once, not repeated while it waits";
  ASSERT_TRUE(h.captured_at_s.has_value());
  EXPECT_NEAR(*h.captured_at_s, 0.1 + 3.0, 1e-9);
  // An empty, even table is never captured: no detail.
  FramingGuide g2;
  std::vector<FrameLook> empty = looks;
  for (FrameLook& l : empty) l.detail = 3;
  const Heard h2 = run(g2, empty);
  EXPECT_FALSE(h2.captured_at_s.has_value());
  EXPECT_EQ(h2.said.size(), 2u) << "place, and again after repeat_s";
}

TEST(FramingGuide, BadParametersAreRefused) {
  FramingParams p;
  p.still_s = 0;
  EXPECT_THROW(FramingGuide{p}, hk::ArgumentError);
  p = {};
  p.centre_tolerance = 0.7;
  EXPECT_THROW(FramingGuide{p}, hk::ArgumentError);
  p = {};
  p.max_motion = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(FramingGuide{p}, hk::ArgumentError);
}

TEST(FrameLook, MotionAndDetailFromRealPixels) {
  cv::Mat a(480, 640, CV_8UC3, cv::Scalar(90, 90, 90));
  cv::rectangle(a, cv::Rect(200, 150, 240, 180), cv::Scalar(230, 230, 230), cv::FILLED);
  cv::Mat small;
  const FrameLook first = look_at_frame(a, 0.0, nullptr, small, {});
  EXPECT_LT(first.motion, 0.0) << "nothing to compare with";
  EXPECT_EQ(first.width_px, 640);
  EXPECT_NEAR(first.mean_grey, 90 + 140.0 * (240 * 180) / (640 * 480), 0.5);
  EXPECT_GT(first.detail, 20.0);
  const FrameLook same = look_at_frame(a, 0.1, &first, small, {});
  EXPECT_NEAR(same.motion, 0.0, 1e-9);
  cv::Mat b(480, 640, CV_8UC3, cv::Scalar(90, 90, 90));
  cv::rectangle(b, cv::Rect(260, 150, 240, 180), cv::Scalar(230, 230, 230), cv::FILLED);  // moved 60 px right
  const FrameLook moved = look_at_frame(b, 0.2, &same, small, {});
  EXPECT_GT(moved.motion, 4.0);
  EXPECT_THROW(look_at_frame(cv::Mat(), 0, nullptr, small, {}), hk::ArgumentError);
}

// Real frames of a page near the frame's bottom edge (turned, tilted, lit unevenly, noisy): lying whole 6 px (1.3 %)
// from it, the page is ready to capture (nothing to say); with a corner 6 px beyond it, it is cut off at the bottom.
TEST(FrameLook, APageWholeNearTheBottomIsReadyAndOneJustBeyondItIsCutOff) {
  const cv::Mat page = hk::test::text_page();
  const cv::Size size(kW, kH);
  for (const double gap_px : {6.0, -6.0}) {
    hk::test::PhotoConditions pc;
    pc.rotation_deg = 3;
    pc.perspective = 0.12;
    pc.blur_sigma_px = 0.8;
    pc.noise_sigma = 4;
    pc.uneven_light = true;
    pc.backdrop = hk::test::Backdrop::blobs;
    pc.seed = 43;
    pc.fill = 0.85;
    const cv::Mat frame =
        hk::test::synthetic_photo(page, size, hk::test::near_edge(page.size(), size, pc, 2, gap_px)).frame;
    cv::Mat small;
    const FrameLook first = look_at_frame(frame, 0.0, nullptr, small);
    const FrameLook still = look_at_frame(frame, 0.1, &first, small);
    ASSERT_TRUE(still.page.found) << gap_px;
    const FramingGuide g;
    if (gap_px > 0) {
      EXPECT_EQ(g.advice_for(still), std::nullopt) << "whole, " << gap_px << " px from the bottom";
    } else {
      EXPECT_EQ(g.advice_for(still), FramingAdvice::CutOffBottom) << -gap_px << " px beyond the bottom";
    }
  }
}

}  // namespace
}  // namespace hk::vision
