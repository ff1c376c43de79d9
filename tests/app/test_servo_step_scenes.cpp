// The servo thread's per-tick work: swapping pictures under a pressing hand without a force step, the
// hand-over of scenes between threads, cues and the display slot.
#include <gtest/gtest.h>

#include <cmath>

#include "curves.hpp"

#include <memory>
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

using test::square;

std::unique_ptr<SceneBundle> bundle(const ServoParams& sp, int id, double half = 0.02) {
  auto b = std::make_unique<SceneBundle>(std::make_unique<Scene>(Scene::build({square(half)}, 2)), sp);
  b->id = id;
  return b;
}

struct Rig {
  config::Settings s;
  ServoParams sp;
  SimulatedPantograph device;
  ModelHandParams hand;
  audio::SpscRing<audio::CueEvent> cues{1024};
  ServoStep core;
  Vec2 target{0.0, 0.0};  // the hand pulls towards the square's centre: it presses on the left wall
  std::vector<Vec2> forces, handles;
  ServoRunner runner{core, device};

  Rig() : sp(servo_params_from(s)), device(sim_params(s), {-0.03, 0.0}), core(CueTrackerParams{}, &cues) {
    device.open();
    hand.stiffness_n_per_m = s.hand.stiffness_n_per_m;
    hand.damping_n_s_per_m = s.hand.damping_n_s_per_m;
    hand.max_force_n = s.hand.max_force_n;
  }
  static SimPantographParams sim_params(const config::Settings& s) {
    SimPantographParams p;
    p.workspace_half_extent_m = {s.workspace.width_m / 2, s.workspace.height_m / 2};
    return p;
  }
  void run(double seconds) {
    const long n = static_cast<long>(seconds / sp.period_s + 0.5);
    for (long k = 0; k < n; ++k) {
      ServoTick t;
      runner.tick(t);  // read, step, write, as the servo thread
      core.publish_display();
      forces.push_back(core.last_output().force_n);
      handles.push_back(core.display().handle_m);
      device.step(sp.period_s, model_hand_force(hand, target, device.true_position_m(), device.velocity_m_per_s()));
    }
  }
};

TEST(ServoStep, SwappingPicturesUnderAPressingHandHasNoForceStep) {
  Rig r;
  r.core.publish(bundle(r.sp, 1));
  r.run(1.5);  // ramp in (0.5 s), then press steadily on the left wall
  const std::size_t swap_at = r.forces.size();
  r.core.publish(bundle(r.sp, 2));
  r.run(1.5);  // fade out (0.5 s), swap, ramp in (0.5 s), settle
  // Per tick, the force may change by the ramp's step plus what the hand's own motion does to a spring
  // wall (stiffness × handle displacement): nothing of the swap itself may show as a jump.
  const double ramp_step = r.sp.guard.max_force_n * r.sp.period_s / r.sp.guard.ramp_s;  // 3.5 N / 500 ticks
  const double k = r.sp.contact.stiffness_n_per_m;
  for (std::size_t i = swap_at; i < r.forces.size(); ++i) {
    const double allowed = ramp_step + k * length(r.handles[i] - r.handles[i - 1]) + 1e-9;
    ASSERT_LE(length(r.forces[i] - r.forces[i - 1]), allowed) << "tick " << i - swap_at << " after the publish";
  }
  EXPECT_EQ(r.core.display().scene_id, 2);
  EXPECT_EQ(r.core.collect_retired(), 1) << "the old picture came back to be freed here";
  // Without the fade the wall would vanish in one tick: the step would be the whole pressing force.
  EXPECT_GT(length(r.forces[swap_at - 1]), 100 * ramp_step);
}

TEST(ServoStep, TheOldPictureFadesOnlyAsLongAsItsForceNeeds) {
  // The fade takes one ramp step of force a tick: a hand in free space (no force) gets the new picture at
  // the next tick; a hand pressing with F waits ceil(F / ramp step) ticks, never the whole ramp for less.
  Rig free_hand;
  free_hand.target = {-0.05, 0.0};  // outside the square: no contact, no force
  free_hand.core.publish(bundle(free_hand.sp, 1));
  free_hand.run(0.6);
  free_hand.core.publish(bundle(free_hand.sp, 2));
  free_hand.run(0.001);
  EXPECT_EQ(free_hand.core.display().scene_id, 2) << "taken at the first tick after the publish";

  Rig pressing;
  pressing.core.publish(bundle(pressing.sp, 1));
  pressing.run(1.5);
  const double f_n = length(pressing.forces.back());
  const double ramp_step = pressing.sp.guard.max_force_n * pressing.sp.period_s / pressing.sp.guard.ramp_s;
  ASSERT_GT(f_n, 10 * ramp_step);
  const long expected = static_cast<long>(std::ceil(f_n / ramp_step));
  pressing.core.publish(bundle(pressing.sp, 2));
  long ticks = 0;
  while (pressing.core.display().scene_id != 2 && ticks < 1000) {
    pressing.run(0.001);
    ++ticks;
  }
  // The force at the publish and at the swap's first tick differ by what the hand's motion does meanwhile.
  EXPECT_NEAR(static_cast<double>(ticks), static_cast<double>(expected), 0.1 * static_cast<double>(expected) + 2.0);
  EXPECT_LT(ticks, static_cast<long>(pressing.sp.guard.ramp_s / pressing.sp.period_s))
      << "less than the whole ramp for less than the clamp";
}

TEST(ServoStep, NewPictureStartsWithTheProxyAtTheHandle) {
  Rig r;
  r.target = {-0.05, 0.0};  // stay outside the square, no contact
  r.core.publish(bundle(r.sp, 1));
  r.run(0.2);
  r.core.publish(bundle(r.sp, 2, 0.01));
  r.run(0.6);
  const ServoDisplayState& d = r.core.display();
  EXPECT_EQ(d.scene_id, 2);
  EXPECT_EQ(d.state, ContactState::Free);
  EXPECT_LT(length(d.proxy_m - d.handle_m), 1e-9);
}

TEST(ServoStep, APictureReplacedBeforeItWasTakenIsFreedAndTheLastOneWins) {
  Rig r;
  r.core.publish(bundle(r.sp, 1));
  r.core.publish(bundle(r.sp, 2));  // 1 never reaches the servo thread (ASan: no leak)
  r.core.publish(bundle(r.sp, 3));
  r.run(0.01);
  EXPECT_EQ(r.core.display().scene_id, 3);
  EXPECT_EQ(r.core.collect_retired(), 0);
}

TEST(ServoStep, ContactCuesReachTheRing) {
  Rig r;
  r.core.publish(bundle(r.sp, 1));
  r.run(1.0);
  audio::CueEvent e;
  bool contact = false;
  while (r.cues.try_pop(e)) contact = contact || e.kind == audio::CueKind::ContactBegin;
  EXPECT_TRUE(contact);
}

TEST(ServoStep, NoPictureMeansNoForce) {
  Rig r;
  r.run(0.1);
  EXPECT_EQ(length(r.forces.back()), 0.0);
  EXPECT_EQ(r.core.display().scene_id, -1);
}

TEST(ServoStep, LevelRequestsFixTheLevelOrHandItBackToTheHandsSpeed) {
  Rig r;
  ASSERT_EQ(r.s.haptics.level_mode, "auto");
  r.core.publish(bundle(r.sp, 1));
  r.run(0.2);
  EXPECT_TRUE(r.core.display().auto_level);
  r.core.request_level(0);  // the visitor asked for the finest level
  r.run(0.5);
  EXPECT_FALSE(r.core.display().auto_level);
  EXPECT_EQ(r.core.display().level, 0);
  r.core.request_level(ServoStep::kAutoLevel);  // a new session: back to the hand's speed
  r.run(0.2);
  EXPECT_TRUE(r.core.display().auto_level);
}

}  // namespace
}  // namespace hk::app
