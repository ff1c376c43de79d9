// Settings changed by the operator while the kiosk runs, on the kiosk's runtime without
// its window: servo gains reach the servo thread's core, keys and the session's timing change in the flow,
// level settings rebuild the scene shown, and what needs a restart is listed and kept as it runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "runtime/servo_runner.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"

namespace fs = std::filesystem;

namespace hk::app {
namespace {

const fs::path kData = HK_TEST_DATA_DIR;

bool listed(const std::vector<std::string>& v, const std::string& key) {
  return std::find(v.begin(), v.end(), key) != v.end();
}

TEST(ApplySettings, EachChangeTakesEffectWhereItsFieldSays) {
  const fs::path lib = fs::temp_directory_path() / ("hk_apply_" + std::to_string(::getpid()));
  fs::remove_all(lib);
  fs::create_directories(lib);
  fs::copy_file(kData / "images" / "horse.png", lib / "horse.png");
  RuntimeOptions ro;
  ro.library = lib.string();
  ro.hotplug = false;
  ro.open_audio_output = false;
  ro.probe_usb_device = false;
  config::Settings s;
  KioskRuntime rt(ro, s);
  KioskFlowParams fp;
  KioskFlow flow(rt.effects(), rt.audio().messages(), fp);
  flow.key(KioskKey::Other, 0.0);  // wake: the tutorial's square is shown
  ServoRunner runner(rt.core(), rt.devices().device());
  const auto tick = [&] {  // the servo thread's part (no servo thread in this test)
    ServoTick t;
    runner.tick(t);
    rt.core().publish_display();
  };
  tick();  // the servo's core takes the square
  ASSERT_EQ(rt.core().display().scene_id, rt.stage().shown_id());
  EXPECT_EQ(rt.core().display().stiffness_n_per_m, 800.0);
  const Scene* before = rt.stage().shown().scene;

  config::Settings next = s;
  next.haptics.stiffness_n_per_m = 1200;  // live
  next.keys.help = "H";                   // live
  next.kiosk.timeout_s = 300;             // live
  next.haptics.max_levels = 4;            // scene
  next.haptics.servo_rate_hz = 500;       // restart
  next.device.handle_mass_kg = 0.2;       // restart
  next.audio.volume_default_step = 5;     // next visitor
  const ApplyReport r = rt.apply_settings(next, flow);
  EXPECT_TRUE(r.gains);
  EXPECT_TRUE(r.keys);
  EXPECT_TRUE(r.timing);
  EXPECT_TRUE(r.scene_rebuilt);
  EXPECT_TRUE(listed(r.restart, "haptics.servo_rate_hz"));
  EXPECT_TRUE(listed(r.restart, "device.handle_mass_kg"));
  EXPECT_EQ(r.restart.size(), 2u);
  EXPECT_TRUE(listed(r.next_session, "audio.volume_default_step"));

  // In use: everything but what needs a restart.
  EXPECT_EQ(rt.settings().haptics.stiffness_n_per_m, 1200.0);
  EXPECT_EQ(rt.settings().haptics.max_levels, 4);
  EXPECT_EQ(rt.settings().haptics.servo_rate_hz, 1000.0) << "the servo thread runs at the rate it started with";
  EXPECT_EQ(rt.settings().device.handle_mass_kg, s.device.handle_mass_kg);
  // The scene was rebuilt (a new one published) and the servo's core renders it with the new stiffness.
  EXPECT_NE(rt.stage().shown().scene, before);
  tick();
  EXPECT_EQ(rt.core().display().stiffness_n_per_m, 1200.0) << "the gains reach the scene in use at the next tick";
  const int fade_ticks = static_cast<int>(s.haptics.force_ramp_s * s.haptics.servo_rate_hz);
  for (int i = 0; i < fade_ticks + 10; ++i) tick();  // the old scene's force fades, then the rebuilt one is taken
  EXPECT_EQ(rt.core().display().scene_id, rt.stage().shown_id());
  EXPECT_EQ(rt.core().display().stiffness_n_per_m, 1200.0);
  EXPECT_LE(rt.stage().shown().scene->max_curve_levels(), 5) << "levels 0..max_levels";
  // The keys changed: the help names the new key.
  flow.key(KioskKey::Help, 1.0);
  EXPECT_NE(rt.voice().last_said().find("H key again gives every key"), std::string::npos) << rt.voice().last_said();
  EXPECT_EQ(rt.voice().last_said().find("F1"), std::string::npos) << rt.voice().last_said();
  fs::remove_all(lib);
}

// level_mode = "tolerance": the servo renders at a tolerance step, and the visitor's Finer /
// Coarser keys move along the steps (a step is never compared with a level), stopping at the ends.
TEST(ApplySettings, ToleranceModeRendersAtAStepAndTheKeysMoveAlongTheSteps) {
  RuntimeOptions ro;
  ro.library = (kData / "images").string();
  ro.hotplug = false;
  ro.open_audio_output = false;
  ro.probe_usb_device = false;
  config::Settings s;
  s.haptics.level_mode = "tolerance";
  KioskRuntime rt(ro, s);
  KioskFlowParams fp;
  KioskFlow flow(rt.effects(), rt.audio().messages(), fp);
  flow.key(KioskKey::Other, 0.0);  // wake: the tutorial's square is shown
  ServoRunner runner(rt.core(), rt.devices().device());
  const auto tick = [&] {
    ServoTick t;
    runner.tick(t);
    rt.core().publish_display();
  };
  for (int i = 0; i < 5; ++i) tick();
  ASSERT_EQ(rt.core().display().scene_id, rt.stage().shown_id());
  const int start = rt.stage().level();
  ASSERT_TRUE(is_tolerance_level(start)) << start;
  EXPECT_TRUE(rt.core().display().auto_level);
  const auto settle =
      [&](int want) {  // a change waits for a tick at which it is safe: the handle rests in the air here
        for (int i = 0; i < 400 && rt.stage().level() != want; ++i) tick();
        return rt.stage().level();
      };
  if (start - kToleranceLevelBase < kToleranceSteps - 1) {
    ASSERT_TRUE(rt.stage().change_level(+1));
    EXPECT_EQ(settle(start + 1), start + 1) << "Coarser: the next step";
    EXPECT_FALSE(rt.core().display().auto_level) << "the visitor's choice holds";
    ASSERT_TRUE(rt.stage().change_level(-1));
    EXPECT_EQ(settle(start), start) << "Finer: back";
  }
  // To the finest step, then no further; to the loosest, then no further.
  while (rt.stage().level() > kToleranceLevelBase) {
    const int now = rt.stage().level();
    ASSERT_TRUE(rt.stage().change_level(-1));
    ASSERT_EQ(settle(now - 1), now - 1);
  }
  EXPECT_FALSE(rt.stage().change_level(-1)) << "no step is finer than the first";
  while (rt.stage().level() < kToleranceLevelBase + kToleranceSteps - 1) {
    const int now = rt.stage().level();
    ASSERT_TRUE(rt.stage().change_level(+1));
    ASSERT_EQ(settle(now + 1), now + 1);
  }
  EXPECT_FALSE(rt.stage().change_level(+1)) << "no step is looser than the last";
}

}  // namespace
}  // namespace hk::app
