// Each Haply profile's defaults on the firmware emulator (the board's bytes, its torque limit, its
// five-bar): a model hand pressing with the profile's maximum force meets walls the board can hold — the
// torque packets stay under the board's limit — and a visitor pushing with no more than the board gives
// everywhere can push through a wall. The simulated pantograph's budget on the same board is the control:
// it asks for torques the board cannot give.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "config/device_profile.hpp"
#include "haptics/contact.hpp"
#include "haptics/hand_path.hpp"
#include "pictures/image_scene.hpp"
#include "runtime/device_setup.hpp"
#include "runtime/simulation.hpp"
#include "test_paths.hpp"

namespace hk::app {
namespace {

/// What one run on the emulated board showed.
struct BoardRun {
  long force_ticks = 0;  ///< ticks whose force was more than 0.05 N
  long saturated = 0;    ///< ... whose torque packet sat at the board's limit on a motor
  long pops = 0;         ///< pushes through a wall
  double max_force_n = 0.0;
  double saturated_fraction() const {
    return force_ticks ? static_cast<double>(saturated) / static_cast<double>(force_ticks) : 0.0;
  }
};

/// A raster over the horse picture on the emulated board of `s`, the hand pushing with `hand_force_n`.
BoardRun raster_on_board(config::Settings s, double hand_force_n, double seconds) {
  s.hand.max_force_n = hand_force_n;
  ImageScene is = build_image_scene(std::string(HK_TEST_DATA_DIR) + "/images/horse.png", s);
  DeviceChoice board;
  board.kind = DeviceChoice::Kind::HaplyEmulator;
  const HandPath path =
      raster_path(s.workspace.width_m, s.workspace.height_m, s.hand.raster_spacing_m, s.hand.raster_speed_m_per_s);
  BoardRun r;
  const double limit = s.device.torque_limit_n_m;
  run_simulation(
      *is.scene, s, path, seconds,
      [&](const ServoTick& rec, const ServoOutput& so) {
        const double f = length(so.force_n);
        r.max_force_n = std::max(r.max_force_n, f);
        if (f > 0.05) {
          ++r.force_ticks;
          r.saturated +=
              std::max(std::fabs(rec.motor_torque_n_m[0]), std::fabs(rec.motor_torque_n_m[1])) >= 0.999 * limit;
        }
        r.pops += (so.contact.events & kEventPopThrough) != 0;
      },
      board);
  return r;
}

class HaplyProfileOnTheBoard : public ::testing::TestWithParam<const char*> {};

TEST_P(HaplyProfileOnTheBoard, AHandPressingWithTheMaximumForceMeetsWallsTheBoardHolds) {
  config::Settings s = config::profile_defaults(GetParam());
  s.haptics.pop_force_n = 0.0;  // walls never give way: the hand leans on them as hard as it can
  const BoardRun r = raster_on_board(s, s.haptics.max_force_n, 8.0);
  ASSERT_GT(r.force_ticks, 1000) << "the raster must press on walls for this to mean anything";
  EXPECT_LE(r.saturated_fraction(), 0.05)
      << r.saturated << " of " << r.force_ticks << " force ticks at the torque limit";
  std::printf("%s: %ld of %ld force ticks at the torque limit (%.1f %%), largest force %.2f N\n", GetParam(),
              r.saturated, r.force_ticks, 100.0 * r.saturated_fraction(), r.max_force_n);
  EXPECT_LE(r.max_force_n, config::force_everywhere_n(s, GetParam()));
}

TEST_P(HaplyProfileOnTheBoard, AVisitorPushesThroughAWallWithinWhatTheBoardGives) {
  const config::Settings s = config::profile_defaults(GetParam());
  const BoardRun r = raster_on_board(s, config::force_everywhere_n(s, GetParam()), 8.0);
  EXPECT_GT(r.pops, 0) << "no push-through with the hand at the board's own force";
  std::printf("%s: %ld pushes through with the hand at %.2f N\n", GetParam(), r.pops,
              config::force_everywhere_n(s, GetParam()));
}

INSTANTIATE_TEST_SUITE_P(Profiles, HaplyProfileOnTheBoard, ::testing::Values("haply", "haply-gen2"),
                         [](const ::testing::TestParamInfo<const char*>& i) {
                           return std::string(i.param) == "haply" ? "gen3" : "gen2";
                         });

TEST(HaplyProfileOnTheBoard_, TheSimulatedPantographsBudgetAsksTheBoardForTorquesItCannotGive) {
  // The control: gen3's board, but the walls of the simulated pantograph (3.5 N, 800 N/m), the hand at 3.5 N.
  config::Settings s = config::profile_defaults("haply");
  const config::Settings sim;
  s.haptics.max_force_n = sim.haptics.max_force_n;
  s.haptics.stiffness_n_per_m = sim.haptics.stiffness_n_per_m;
  s.haptics.pop_force_n = 0.0;
  const BoardRun r = raster_on_board(s, sim.haptics.max_force_n, 8.0);
  EXPECT_GT(r.saturated_fraction(), 0.10) << "the check above could not fail";
  std::printf("simulated budget on the gen3 board: %ld of %ld force ticks at the torque limit (%.1f %%)\n", r.saturated,
              r.force_ticks, 100.0 * r.saturated_fraction());
}

}  // namespace
}  // namespace hk::app
