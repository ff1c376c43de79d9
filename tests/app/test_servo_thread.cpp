// The servo thread: it ticks the core, counts a deadline it missed (and the guard zeroes that tick's
// force), refuses a bad rate, and stops cleanly. Its timing is measured in bench/servo_rate.cpp.
#include <gtest/gtest.h>

#include "curves.hpp"

#include <chrono>
#include <thread>

#include "haptics/sim_pantograph.hpp"
#include "hk/error.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/servo_thread.hpp"
#include "runtime/simulation.hpp"

namespace hk::app {
namespace {

using test::square;

TEST(ServoThread, TicksCountsAMissedDeadlineAndStops) {
  const config::Settings s;
  const ServoParams sp = servo_params_from(s);
  SimPantographParams dp;
  SimulatedPantograph device(dp, {-0.03, 0.0});
  device.open();
  ServoStep core(CueTrackerParams{}, nullptr);
  auto b = std::make_unique<SceneBundle>(std::make_unique<Scene>(Scene::build({square(0.02)}, 2)), sp);
  b->id = 7;
  core.publish(std::move(b));
  std::atomic<int> after{0};
  {
    ServoThread t(core, device, {}, [&](double period_s) {
      EXPECT_DOUBLE_EQ(period_s, 0.001);
      if (++after == 50) std::this_thread::sleep_for(std::chrono::milliseconds(3));  // a stall: the next tick is late
    });
    while (t.stats().ticks < 100) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    const ServoTimingStats st = t.stats();
    EXPECT_GE(st.missed_deadlines, 1) << "the 3 ms stall must count as a missed deadline";
    EXPECT_GE(st.lateness_max_us, 1000.0);
    EXPECT_GE(core.display().missed_deadlines, 1) << "the display state carries the count";
    const ServoTimingStats taken = t.take_stats();  // a session's report, then counting afresh
    EXPECT_GE(taken.ticks, 100);
    EXPECT_LT(t.stats().ticks, taken.ticks);
    const ServoThread::Totals total = t.totals();  // ... while the totals since the start are kept
    EXPECT_GE(total.ticks, taken.ticks);
    EXPECT_GE(total.missed_deadlines, taken.missed_deadlines);
    EXPECT_GE(total.lateness_max_us, 1000.0);
    t.stop();
    const std::int64_t ticks = t.stats().ticks;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_EQ(t.stats().ticks, ticks) << "stopped means stopped";
  }
  EXPECT_EQ(core.display().scene_id, 7);
}

TEST(ServoThread, RefusesARateOutsideItsRange) {
  SimPantographParams dp;
  SimulatedPantograph device(dp, {0.0, 0.0});
  ServoStep core(CueTrackerParams{}, nullptr);
  ServoThreadParams p;
  p.rate_hz = 50;
  EXPECT_THROW(ServoThread(core, device, p), hk::ArgumentError);
}

}  // namespace
}  // namespace hk::app
