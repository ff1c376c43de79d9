// The window's frame-time statistics (frame_stats.hpp): nearest-rank percentiles to the histogram's bin,
// never below the time they stand for and never above the longest; exact maximum and slow-frame count;
// and which frames count as "while a picture changes", on a made-up clock.
#include <gtest/gtest.h>

#include <chrono>

#include "kiosk/frame_stats.hpp"

namespace hk::app {
namespace {

using Clock = FrameStats::Clock;
using std::chrono::microseconds;

TEST(FrameTimeHistogram, PercentilesOfAHundredFramesAreTheUpperEdgesOfTheirBins) {
  FrameTimeHistogram h;
  for (int k = 99; k >= 0; --k) h.add_ms(k + 0.05);  // 0.05, 1.05, ..., 99.05 ms, added in any order
  const FrameTimeSummary s = h.summary();
  EXPECT_EQ(s.frames, 100);
  EXPECT_NEAR(s.p50_ms, 49.1, 1e-9);  // the 50th shortest, 49.05, lies in [49.0, 49.1)
  EXPECT_NEAR(s.p95_ms, 94.1, 1e-9);
  EXPECT_NEAR(s.p99_ms, 98.1, 1e-9);
  EXPECT_DOUBLE_EQ(s.max_ms, 99.05);
  EXPECT_NEAR(s.mean_ms, 49.55, 1e-9);
  EXPECT_EQ(s.over_20_ms, 80);  // 20.05 ... 99.05
}

TEST(FrameTimeHistogram, OneSlowFrameInAHundredIsTheP99OnlyWhenItIsMoreThanOnePercent) {
  FrameTimeHistogram h;
  for (int i = 0; i < 99; ++i) h.add_ms(16.75);
  h.add_ms(250.0);
  EXPECT_NEAR(h.percentile_ms(99), 16.8, 1e-9);  // rank 99 of 100: still a 16.75 ms frame
  EXPECT_DOUBLE_EQ(h.percentile_ms(100), 250.0);
  h.add_ms(250.0);  // 2 of 101: rank ⌈99.99⌉ = 100 is a slow one
  EXPECT_DOUBLE_EQ(h.percentile_ms(99), 250.0);
  EXPECT_EQ(h.summary().over_20_ms, 2);
}

TEST(FrameTimeHistogram, APercentileIsNeverAboveTheLongestFrame) {
  FrameTimeHistogram h;
  h.add_ms(3.02);
  EXPECT_DOUBLE_EQ(h.percentile_ms(50), 3.02);
  EXPECT_DOUBLE_EQ(h.percentile_ms(99), 3.02);
}

TEST(FrameTimeHistogram, FramesBeyondTheRangeKeepTheirExactLength) {
  FrameTimeHistogram h;
  h.add_ms(1.05);
  h.add_ms(1500.0);
  EXPECT_NEAR(h.percentile_ms(50), 1.1, 1e-9);
  EXPECT_DOUBLE_EQ(h.percentile_ms(99), 1500.0);
  EXPECT_DOUBLE_EQ(h.max_ms(), 1500.0);
}

TEST(FrameTimeHistogram, EmptyAndOddInputs) {
  FrameTimeHistogram h;
  EXPECT_EQ(h.summary().frames, 0);
  EXPECT_EQ(h.percentile_ms(99), 0.0);
  h.add_ms(-2.0);  // a clock going back counts as 0
  h.add_ms(20.0);  // exactly the limit is not over it
  EXPECT_EQ(h.frames(), 2);
  EXPECT_EQ(h.summary().over_20_ms, 0);
  EXPECT_NEAR(h.percentile_ms(50), 0.1, 1e-9);  // the 0 ms frame, to its bin's upper edge
}

TEST(FrameStats, FramesFromTheKeyToTheNewSceneDrawnAreTheChangingOnes) {
  FrameStats st;
  int a = 0, b = 0;  // two scenes, told apart by address
  Clock::time_point t{};
  // Frame: starts at t, drawn after `work_us`, next one starts `gap_us` later.
  auto frame = [&](int work_us, int gap_us, const void* drawn, bool key, const void* at_start) {
    st.frame_started(t);
    if (key) st.picture_key(at_start, 0);
    st.frame_drawn(t + microseconds(work_us), drawn, 0);
    t += microseconds(work_us + gap_us);
  };
  frame(2000, 14000, &a, false, &a);   // 16 ms
  frame(2000, 14000, &a, false, &a);   // 16 ms
  frame(90000, 10000, &a, true, &a);   // key: 100 ms, the new scene not drawn yet
  frame(30000, 10000, &b, false, &a);  // 40 ms: the new scene drawn
  frame(2000, 14000, &b, false, &b);   // 16 ms
  st.frame_started(t);                 // closes the last interval

  EXPECT_EQ(st.interval_all().frames(), 5);
  EXPECT_EQ(st.interval_changing().frames(), 2);
  EXPECT_DOUBLE_EQ(st.interval_changing().max_ms(), 100.0);
  EXPECT_EQ(st.interval_changing().summary().over_20_ms, 2);
  EXPECT_EQ(st.interval_all().summary().over_20_ms, 2);
  EXPECT_EQ(st.work_all().frames(), 5);
  EXPECT_EQ(st.work_changing().frames(), 2);
  EXPECT_DOUBLE_EQ(st.work_changing().max_ms(), 90.0);
  EXPECT_EQ(st.changes(), 1);
  EXPECT_DOUBLE_EQ(st.max_change_ms(), 130.0);  // key frame's start to the end of the drawing of the new scene

  const nlohmann::json j = st.to_json("test");
  EXPECT_EQ(j["interval"]["changing"]["frames"], 2);
  EXPECT_EQ(j["interval"]["all"]["over_20_ms"], 2);
  EXPECT_EQ(j["changes"], 1);
  EXPECT_EQ(j["measured"], "test");
}

TEST(FrameStats, AKeyWhoseSceneNeverComesStopsCountingAfterTheLimit) {
  FrameStats st;
  int a = 0;
  Clock::time_point t{};
  st.frame_started(t);
  st.picture_key(&a, 0);
  st.frame_drawn(t + microseconds(1000), &a, 0);
  const int frames = static_cast<int>(FrameStats::kMaxChangeS * 60) + 120;  // 2 s past the limit at 60 Hz
  for (int i = 0; i < frames; ++i) {
    t += microseconds(16000);
    st.frame_started(t);
    st.frame_drawn(t + microseconds(1000), &a, 0);
  }
  EXPECT_EQ(st.changes(), 0);
  EXPECT_LT(st.work_changing().frames(), frames);
  EXPECT_GT(st.work_changing().frames(), static_cast<int>(FrameStats::kMaxChangeS * 60) - 1);
}

}  // namespace
}  // namespace hk::app
