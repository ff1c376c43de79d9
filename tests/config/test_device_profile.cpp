// Device profiles: each [device] type brings a force budget its device can give, a stiffness it renders
// stably, and (for a Haply) a board whose encoder offsets and park place name one pose.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "config/device_profile.hpp"
#include "config/load.hpp"
#include "config_test_util.hpp"

namespace hk::config {
namespace {

using test::capture_error;

TEST(DeviceProfile, EveryProfilesDefaultsAreValidAndWithinWhatItsDeviceGives) {
  for (const DeviceProfile& p : device_profiles()) {
    const Settings s = profile_defaults(p.type);
    SCOPED_TRACE(std::string(p.type));
    EXPECT_EQ(s.device.type, p.type);
    EXPECT_NO_THROW(validate(s));
    EXPECT_EQ(profile_problem(s, p.type), "");
    const double everywhere = force_everywhere_n(s, p.type);
    EXPECT_LE(s.haptics.max_force_n, everywhere);
    EXPECT_GE(s.haptics.max_force_n, 0.85 * everywhere);      // the budget uses what the device has
    EXPECT_LT(s.haptics.pop_force_n, s.haptics.max_force_n);  // a visitor can press harder than the push-through force
    EXPECT_LT(s.haptics.tour_max_force_n, s.haptics.pop_force_n);
    EXPECT_LE(s.haptics.groove_depth_n, s.haptics.max_force_n);
    // The default stiffness keeps at least a factor 2 from the limit bench_stability --profiles measured.
    EXPECT_LE(2.0 * s.haptics.stiffness_n_per_m, p.stable_stiffness_n_per_m * 1.3);
    EXPECT_LE(s.haptics.stiffness_n_per_m, stiffness_limit_n_per_m(p.type, s.haptics.servo_rate_hz));
  }
}

TEST(DeviceProfile, TheForcesEachDeviceGivesEverywhereAgreeWithTheirDerivations) {
  // Simulated pantograph: pantograph.hpp's check of the default geometry (≥ 3.7 N at 0.5 N·m).
  EXPECT_NEAR(force_everywhere_n(Settings{}, "simulated"), 3.78, 0.01);
  // Haply 2DIY gen3 at the firmware's 0.123 N·m: 1.65 N, the figure the kiosk logs for this handle.
  EXPECT_NEAR(force_everywhere_n(profile_defaults("haply"), "haply"), 1.65, 0.01);
  // Twice the torque limit, twice the force (τ = Jᵀ·F is linear).
  Settings strong = profile_defaults("haply");
  strong.device.torque_limit_n_m *= 2.0;
  EXPECT_NEAR(force_everywhere_n(strong, "haply"), 2.0 * force_everywhere_n(profile_defaults("haply"), "haply"), 1e-9);
}

TEST(DeviceProfile, TheOriginal2DIYHasItsOwnBoard) {
  const Settings s = profile_defaults("haply-gen2");
  // hAPI examples, hardwareVersion 2: encoders (1, CCW, 241, 10752, port 2), (2, CW, -61, 10752, port 1);
  // actuators (1, CCW, port 2), (2, CW, port 1). Pantograph.java: coaxial motors (d = 0).
  EXPECT_EQ(s.device.motor_spacing_m, 0.0);
  EXPECT_EQ(s.device.encoder1_offset_deg, 241.0);
  EXPECT_EQ(s.device.encoder2_offset_deg, -61.0);
  EXPECT_EQ(s.device.encoder1_resolution, 10752.0);
  EXPECT_EQ(s.device.encoder2_dir, "cw");
  EXPECT_EQ(s.device.actuator1_dir, "ccw");
  EXPECT_EQ(s.device.actuator2_dir, "cw");
  EXPECT_EQ(s.device.actuator1_port, 2);
  EXPECT_EQ(s.device.encoder2_port, 1);
}

TEST(DeviceProfile, TheParkPlaceIsThePoseTheEncoderOffsetsName) {
  // gen3, offsets (180°, 0°): both arms stretched out sideways, elbows at (−l, 0) and (d + l, 0) in Haply's
  // frame, 2·(l + d/2) = 0.178 m apart; the handle midway, √(L² − 0.089²) = 0.013379 m from the motor line.
  // Workspace y = 1.25 · (0.088 − 0.013379) m (the 0.112 m rectangle at −0.088 m mapped onto 0.14 m).
  const Settings gen3 = profile_defaults("haply");
  EXPECT_NEAR(gen3.device.park_x_m, 0.0, 1e-9);
  EXPECT_NEAR(gen3.device.park_y_m, 1.25 * (0.088 - std::sqrt(0.09 * 0.09 - 0.089 * 0.089)), 1e-6);
  EXPECT_EQ(gen3.device.park_y_m, Settings{}.device.park_y_m);  // the shipped [device] is the gen3's
  double x = 0, y = 0;
  ASSERT_TRUE(home_park_place(gen3, &x, &y));
  EXPECT_NEAR(y, gen3.device.park_y_m, 1e-6);
  // gen2, offsets (241°, −61°), coaxial motors: elbows at l·(cos 241°, ±sin 241°)... mirrored about x = 0.
  const double ex = 0.07 * std::cos(241.0 * M_PI / 180.0), ey = 0.07 * std::sin(241.0 * M_PI / 180.0);
  const double handle_y = ey + std::sqrt(0.09 * 0.09 - ex * ex);
  const Settings gen2 = profile_defaults("haply-gen2");
  EXPECT_NEAR(gen2.device.park_x_m, 0.0, 1e-9);
  EXPECT_NEAR(gen2.device.park_y_m, 1.25 * (0.088 - handle_y), 1e-6);
}

TEST(DeviceProfile, AFileThatNamesAHaplyGetsItsBudget) {
  const Settings s = parse_settings("[device]\ntype = \"haply\"\n", "haply.toml");
  EXPECT_EQ(s.haptics.max_force_n, 1.5);
  EXPECT_EQ(s.haptics.pop_force_n, 1.2);
  EXPECT_EQ(s.haptics.stiffness_n_per_m, 500.0);
  // What the file says within the profile stays; the rest is the profile's.
  const Settings t =
      parse_settings("[haptics]\nstiffness_n_per_m = 700.0\n[device]\ntype = \"haply-gen2\"\n", "gen2.toml");
  EXPECT_EQ(t.haptics.stiffness_n_per_m, 700.0);
  EXPECT_EQ(t.haptics.max_force_n, 1.45);
  EXPECT_EQ(t.device.encoder1_offset_deg, 241.0);
  // The simulated pantograph keeps today's feel.
  EXPECT_EQ(parse_settings("[device]\ntype = \"simulated\"\n", "sim.toml").haptics.max_force_n, 3.5);
}

TEST(DeviceProfile, SettingsBeyondTheProfileAreRefusedWithTheLimitNamed) {
  auto e = capture_error(
      [] { (void)parse_settings("[haptics]\nmax_force_n = 3.5\n[device]\ntype = \"haply\"\n", "f.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "haptics.max_force_n");
  EXPECT_EQ(std::string(e->what()),
            "config 'f.toml': haptics.max_force_n = 3.5 is more than the Haply 2DIY gen3 gives everywhere in its "
            "rectangle (1.65 N)");
  e = capture_error(
      [] { (void)parse_settings("[haptics]\nstiffness_n_per_m = 2000.0\n[device]\ntype = \"haply\"\n", "k.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(std::string(e->what()),
            "config 'k.toml': haptics.stiffness_n_per_m = 2000 is above the stable limit of the Haply 2DIY gen3 (850 "
            "N/m at 1000 Hz)");
  e = capture_error(
      [] { (void)parse_settings("[haptics]\npop_force_n = 1.6\n[device]\ntype = \"haply\"\n", "p.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(std::string(e->what()),
            "config 'p.toml': haptics.pop_force_n = 1.6 must be <= haptics.max_force_n = 1.5 (no visitor could push "
            "through a wall)");
  // A slower servo loop holds a proportionally softer wall.
  e = capture_error(
      [] { (void)parse_settings("[haptics]\nservo_rate_hz = 500.0\n[device]\ntype = \"haply\"\n", "r.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "haptics.stiffness_n_per_m");
  EXPECT_NE(std::string(e->what()).find("(425 N/m at 500 Hz)"), std::string::npos) << e->what();
}

TEST(DeviceProfile, TheOperatorsPanelShowsEachLimit) {
  const Settings s = profile_defaults("haply");
  const std::optional<ProfileLimit> force = profile_limit(s, "haply", "haptics", "max_force_n");
  ASSERT_TRUE(force);
  EXPECT_EQ(force->kind, ProfileLimit::Kind::force_everywhere);
  EXPECT_NEAR(force->value, force_everywhere_n(s, "haply"), 1e-12);
  EXPECT_NEAR(force->value, 1.65, 0.005);
  EXPECT_EQ(force->device, "Haply 2DIY gen3");
  const std::optional<ProfileLimit> k = profile_limit(s, "haply", "haptics", "stiffness_n_per_m");
  ASSERT_TRUE(k);
  EXPECT_EQ(k->kind, ProfileLimit::Kind::stable_stiffness);
  EXPECT_DOUBLE_EQ(k->value, 850.0);
  EXPECT_DOUBLE_EQ(k->servo_rate_hz, 1000.0);
  const std::optional<ProfileLimit> pop = profile_limit(s, "haply", "haptics", "pop_force_n");
  ASSERT_TRUE(pop);
  EXPECT_EQ(pop->kind, ProfileLimit::Kind::within_max_force);
  EXPECT_DOUBLE_EQ(pop->value, s.haptics.max_force_n);
  EXPECT_FALSE(profile_limit(s, "haply", "haptics", "pop_hold_s"));
}

TEST(DeviceProfile, AnAutoKioskThatTakesABoardMovesIntoItsProfile) {
  std::vector<std::string> notes;
  // Untouched simulated defaults become the board's.
  const Settings fit = fit_to_profile(Settings{}, "haply", &notes);
  EXPECT_TRUE(notes.empty());
  EXPECT_EQ(fit.haptics.max_force_n, 1.5);
  EXPECT_EQ(fit.haptics.pop_force_n, 1.2);
  EXPECT_EQ(fit.haptics.tour_max_force_n, 0.5);
  EXPECT_EQ(fit.haptics.groove_depth_n, 0.45);
  EXPECT_EQ(fit.haptics.stiffness_n_per_m, 500.0);
  EXPECT_EQ(fit.device.type, "auto");
  EXPECT_NO_THROW(validate(fit));
  EXPECT_EQ(profile_problem(fit, "haply"), "");
  // The operator's choices stay when the board can give them, and are refused with the limit when not.
  Settings chosen;
  chosen.haptics.stiffness_n_per_m = 700.0;
  chosen.haptics.max_force_n = 3.0;
  const Settings fit2 = fit_to_profile(chosen, "haply", &notes);
  EXPECT_EQ(fit2.haptics.stiffness_n_per_m, 700.0);
  EXPECT_EQ(fit2.haptics.max_force_n, 1.5);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0],
            "haptics.max_force_n = 3 is more than the Haply 2DIY gen3 gives everywhere in its rectangle (1.65 N); "
            "Haply 2DIY gen3 uses its own value");
  EXPECT_EQ(profile_problem(fit2, "haply"), "");
}

}  // namespace
}  // namespace hk::config

namespace hk::config {
namespace {

TEST(UsbIds, TheDefaultListHoldsEveryIdHaplysBoardsEnumerateWith) {
  const std::vector<UsbId> ids = parse_usb_ids(Settings{}.device.usb_ids);
  const std::vector<UsbId> expected = {
      {0x2341, 0x003e}, {0x2341, 0x804d}, {0x2341, 0x004d}, {0x2341, 0x824d}, {0x2341, 0x024d}};
  EXPECT_EQ(ids, expected);
  EXPECT_EQ(parse_usb_ids(" 239A:8013 , 2341:804D"), (std::vector<UsbId>{{0x239a, 0x8013}, {0x2341, 0x804d}}));
}

TEST(UsbIds, AMalformedListIsRefusedWithItsKeyAndTheForm) {
  for (const char* bad : {"", "2341", "2341:80", "2341:804g", "2341:804d,", "2341-804d", "2341:804d;2341:003e"}) {
    std::string why;
    EXPECT_TRUE(parse_usb_ids(bad, &why).empty()) << bad;
    EXPECT_FALSE(why.empty()) << bad;
  }
  std::string many;
  for (int i = 0; i < 17; ++i) many += (i ? "," : "") + std::string("2341:804d");
  std::string why;
  EXPECT_TRUE(parse_usb_ids(many, &why).empty());
  EXPECT_EQ(why, "holds more than 16 USB ids");
  auto e = test::capture_error([] { (void)parse_settings("[device]\nusb_ids = \"2341:80\"\n", "ids.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "device.usb_ids");
  EXPECT_EQ(std::string(e->what()),
            "config 'ids.toml': device.usb_ids = \"2341:80\" must be USB ids \"VVVV:PPPP\" (four hex digits each), "
            "comma-separated, e.g. "
            "\"2341:804d,2341:003e\" (line 2)");
}

}  // namespace
}  // namespace hk::config
