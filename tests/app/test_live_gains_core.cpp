// Gains changed live on the kiosk's servo thread (ServoStep level): the simulated
// pantograph held by a model hand pressing on a wall with the kiosk's defaults (800 N/m, 2 N push,
// 0.05 N per tick, 1 kHz); ServoStep::set_gains doubles the stiffness between two ticks. The force never
// steps by more than the limit per tick (plus what the hand's own motion does to the wall), the display
// reports the new stiffness and the end of the transition, and a picture published afterwards with the
// old ServoParams renders with the new gains.
#include <gtest/gtest.h>

#include "curves.hpp"

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "haptics/hand_path.hpp"
#include "haptics/sim_pantograph.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/servo_runner.hpp"
#include "runtime/servo_step.hpp"
#include "runtime/simulation.hpp"

namespace hk::app {
namespace {

std::unique_ptr<SceneBundle> bundle(const ServoParams& sp, int id) {
  auto b = std::make_unique<SceneBundle>(std::make_unique<Scene>(Scene::build({test::square(0.02)}, 2)), sp);
  b->id = id;
  return b;
}

/// The kiosk's defaults; the model hand starts left of a 4 cm square and pulls towards its centre, so it
/// presses on the left wall with its full 2 N.
struct Rig {
  config::Settings s;
  ServoParams sp;
  SimulatedPantograph device;
  ModelHandParams hand;
  ServoStep core;
  std::vector<Vec2> forces, handles;
  std::vector<ServoDisplayState> shown;
  Vec2 target{0.0, 0.0};  // where the hand pulls to

  Rig()
      : sp(servo_params_from(s)),
        device(sim_params_from(s), {-0.03, 0.0}),
        hand(hand_params_from(s)),
        core(CueTrackerParams{}, nullptr) {
    device.open();
  }
  ServoRunner runner{core, device};
  void tick() {
    ServoTick t;
    runner.tick(t);  // read, step, write, as the servo thread
    core.publish_display();
    forces.push_back(core.last_output().force_n);
    const ServoDisplayState& d = core.display();
    handles.push_back(d.handle_m);
    shown.push_back(d);
    device.step(sp.period_s, model_hand_force(hand, target, device.true_position_m(), device.velocity_m_per_s()));
  }
  void run(double seconds) {
    for (long k = 0, n = static_cast<long>(seconds / sp.period_s + 0.5); k < n; ++k) tick();
  }
};

TEST(LiveGainsCore, StiffnessDoublesUnderAPressingHandWithoutAForceStep) {
  Rig r;
  ASSERT_EQ(servo_gains_from(r.s), gains_of(r.sp)) << "servo_params_from agrees with servo_gains_from";
  r.core.publish(bundle(r.sp, 1));
  r.run(1.5);  // ramp in (0.5 s), then press steadily on the left wall
  const double k0 = r.s.haptics.stiffness_n_per_m, k1 = 2.0 * k0, step = r.s.haptics.level_max_force_step_n;
  const double push = r.s.hand.max_force_n, clamp = r.s.haptics.max_force_n;
  ASSERT_EQ(k0, 800.0);
  ASSERT_EQ(step, 0.05);
  ServoDisplayState d = r.core.display();
  ASSERT_NE(d.state, ContactState::Free);
  EXPECT_EQ(d.stiffness_n_per_m, k0);
  EXPECT_FALSE(d.gains_transition);
  EXPECT_NEAR(length(d.force_n), push, 0.05) << "the hand's 2 N press";
  EXPECT_NEAR(d.penetration_m, push / k0, 0.1e-3) << "2 N / 800 N/m = 2.5 mm";
  EXPECT_NEAR(length(d.force_n), k0 * d.penetration_m, 1e-9) << "F = k · penetration";

  ServoGains g = servo_gains_from(r.s);
  g.stiffness_n_per_m = k1;
  r.core.set_gains(g);  // between two ticks, as the panel's Apply does
  const std::size_t at = r.forces.size();
  r.run(1.0);

  // What the change asks at its tick: the new spring at the penetration there (clamped), against the last force.
  const ServoDisplayState& first = r.shown[at];
  const Vec2 f_new = k1 * (first.proxy_m - first.handle_m);
  const double diff = distance(r.forces[at - 1], length(f_new) > clamp ? (clamp / length(f_new)) * f_new : f_new);
  const long derived = static_cast<long>(std::ceil(diff / step - 1e-9));
  // A priori: 1600 N/m × 2.5 mm = 4 N, clamped to 3.5 N, against 2 N: 1.5 N, 30 ticks.
  const long derived_a_priori = static_cast<long>(std::ceil((std::min(k1 * push / k0, clamp) - push) / step - 1e-9));
  EXPECT_EQ(derived_a_priori, 30);
  EXPECT_LE(std::labs(derived - derived_a_priori), 1) << "diff " << diff << " N";

  long in_force = -1;  // ticks from set_gains until the new stiffness is fully in force
  for (std::size_t i = at; i < r.forces.size(); ++i) {
    const double allowed = step + k1 * distance(r.handles[i], r.handles[i - 1]) + 1e-9;
    ASSERT_LE(distance(r.forces[i], r.forces[i - 1]), allowed) << "tick " << i - at << " after set_gains";
    EXPECT_EQ(r.shown[i].stiffness_n_per_m, k1) << "the display shows the new stiffness from the first tick";
    if (in_force < 0 && !r.shown[i].gains_transition) in_force = static_cast<long>(i - at) + 1;
    if (in_force > 0) {
      EXPECT_FALSE(r.shown[i].gains_transition) << "tick " << i - at;
    }
  }
  EXPECT_EQ(in_force, derived);
  const double ms = static_cast<double>(in_force) * r.sp.period_s * 1e3;
  std::printf(
      "[ live gains ] 800 -> 1600 N/m under a %.1f N press, %.2f N/tick at %.0f Hz: new stiffness fully in force "
      "%ld ticks (%.0f ms) after set_gains; derived %ld ticks (a priori %ld)\n",
      push, step, 1.0 / r.sp.period_s, in_force, ms, derived, derived_a_priori);
  RecordProperty("apply_to_full_stiffness_ticks", std::to_string(in_force));
  RecordProperty("apply_to_full_stiffness_ms", std::to_string(ms));

  // Settled on the new wall: the hand's 2 N now needs half the penetration, F = 1600 N/m × 1.25 mm.
  d = r.core.display();
  EXPECT_NEAR(length(d.force_n), k1 * d.penetration_m, 1e-9);
  EXPECT_NEAR(d.penetration_m, push / k1, 0.1e-3);
  // Without the limit the step would have been the whole difference.
  EXPECT_GT(diff, 20 * step);
}

TEST(LiveGainsCore, APictureBuiltWithTheOldParamsRendersWithTheNewGains) {
  Rig r;
  r.core.publish(bundle(r.sp, 1));
  r.run(1.0);
  ServoGains g = servo_gains_from(r.s);
  g.stiffness_n_per_m = 1600.0;
  r.core.set_gains(g);
  r.run(0.1);
  ASSERT_EQ(r.core.display().stiffness_n_per_m, 1600.0);

  // Built before the change, from the settings that still say 800 N/m, and published after it. The hand
  // steps out of the square for the swap (a new picture starts with the proxy at the handle), then presses again.
  ASSERT_EQ(r.sp.contact.stiffness_n_per_m, 800.0);
  r.target = {-0.05, 0.0};
  r.core.publish(bundle(r.sp, 2));
  r.run(0.6);  // fade out (0.5 s), swap
  ASSERT_EQ(r.core.display().scene_id, 2);
  r.target = {0.0, 0.0};
  r.run(1.0);  // ramp in (0.5 s), settle
  ServoDisplayState d = r.core.display();
  ASSERT_EQ(d.scene_id, 2);
  ASSERT_NE(d.state, ContactState::Free);
  EXPECT_EQ(d.stiffness_n_per_m, 1600.0);
  EXPECT_FALSE(d.gains_transition);
  EXPECT_NEAR(length(d.force_n), 1600.0 * d.penetration_m, 1e-9) << "F = 1600 N/m × penetration";
  EXPECT_EQ(r.core.collect_retired(), 1);

  // A picture published before a change but taken after it (it waits while the old force fades) too.
  r.target = {-0.05, 0.0};
  r.core.publish(bundle(r.sp, 3));
  r.run(0.1);
  ASSERT_EQ(r.core.display().scene_id, 2) << "still fading the old picture";
  g.stiffness_n_per_m = 1200.0;
  r.core.set_gains(g);
  r.run(0.5);
  ASSERT_EQ(r.core.display().scene_id, 3);
  r.target = {0.0, 0.0};
  r.run(1.0);
  d = r.core.display();
  ASSERT_EQ(d.scene_id, 3);
  ASSERT_NE(d.state, ContactState::Free);
  EXPECT_EQ(d.stiffness_n_per_m, 1200.0);
  EXPECT_NEAR(length(d.force_n), 1200.0 * d.penetration_m, 1e-9);
}

TEST(LiveGainsCore, DisplayBeforeAPictureAndInFreeSpace) {
  Rig r;
  r.run(0.01);
  EXPECT_EQ(r.core.display().stiffness_n_per_m, 0.0);
  EXPECT_EQ(r.core.display().penetration_m, 0.0);
  EXPECT_FALSE(r.core.display().gains_transition);
  r.core.publish(bundle(r.sp, 1));
  r.run(0.005);  // the hand has not reached the wall yet
  EXPECT_EQ(r.core.display().state, ContactState::Free);
  EXPECT_EQ(r.core.display().penetration_m, 0.0);
  EXPECT_EQ(r.core.display().stiffness_n_per_m, 800.0);
}

}  // namespace
}  // namespace hk::app
