// The headless pipeline through the Haply firmware emulator behind a pty:
// the same crossing and force-law checks as the simulated device on real pictures; a board that is
// unplugged mid-run gets zero force and torque from lost_after_ticks ticks on and the run ends well with
// device.status "lost"; garbage and dropped replies never give a non-finite or over-limit torque; bad
// --device values end in one line; `calibrate` writes offsets that undo an encoder zero error.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "config/load.hpp"
#include "crossing_grid.hpp"
#include "haptics/hand_path.hpp"
#include "pictures/image_scene.hpp"
#include "runtime/device_setup.hpp"
#include "runtime/simulation.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace hk;

namespace {

const fs::path kData = HK_TEST_DATA_DIR;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hk_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

struct ExeResult {
  int status = -1;
  std::string out, err;
};

ExeResult run_exe(const std::string& args, const fs::path& tmp) {
  const fs::path out = tmp / "stdout.txt", err = tmp / "stderr.txt";
  const std::string cmd = std::string(HK_KIOSK_EXE) + " " + args + " >" + out.string() + " 2>" + err.string();
  ExeResult r;
  const int raw = std::system(cmd.c_str());
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128;
  auto slurp = [](const fs::path& p) {
    std::ifstream f(p);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  };
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

struct RunChecks {
  long ticks = 0, crossings = 0, bad_force = 0, contact_ticks = 0, bad_torque = 0;
  double torque_limit = 0;
};

// Runs `choice` on `image` with a pushing raster hand for `duration_s`; counts crossings (independent grid),
// force-law violations (Ok ticks after the ramp) and torques that are non-finite or over the limit.
RunChecks run_checked(const std::string& image, const std::string& device, double duration_s, app::DeviceReport* report,
                      const std::function<void(const app::ServoTick&, const ServoOutput&)>& extra = {}) {
  config::Settings s;
  s.hand.raster_spacing_m = 0.008;
  s.hand.raster_speed_m_per_s = 0.12;
  s.haptics.level_mode = "fixed";
  const app::ImageScene is = app::build_image_scene((kData / "images" / image).string(), s);
  const Scene& sc = *is.scene;
  const HandPath path =
      raster_path(s.workspace.width_m, s.workspace.height_m, s.hand.raster_spacing_m, s.hand.raster_speed_m_per_s);
  test::CrossingGrid grid(sc, s.haptics.level);
  RunChecks rc;
  rc.torque_limit = device == "sim" ? s.device.max_torque_n_m : s.device.torque_limit_n_m;
  double ok_since_s = 0.0;
  app::run_simulation(
      sc, s, path, duration_s,
      [&](const app::ServoTick& r, const ServoOutput& so) {
        ++rc.ticks;
        const ContactOutput& c = so.contact;
        for (int m = 1; m < c.path_count; ++m) rc.crossings += grid.crossings(c.path_m[m - 1], c.path_m[m]);
        rc.contact_ticks += c.state != ContactState::Free;
        if (r.sample.status != DeviceStatus::Ok) ok_since_s = r.t_s + s.haptics.force_ramp_s;
        const double expect =
            std::min(s.haptics.stiffness_n_per_m * distance(c.proxy_m, r.sample.handle_m), s.haptics.max_force_n);
        if (r.sample.status == DeviceStatus::Ok && r.t_s > std::max(ok_since_s, s.haptics.force_ramp_s) &&
            std::abs(length(so.force_n) - expect) > 1e-6)
          ++rc.bad_force;
        for (double t : r.motor_torque_n_m)
          if (!std::isfinite(t) || std::fabs(t) > rc.torque_limit + 1e-12) ++rc.bad_torque;
        if (extra) extra(r, so);
      },
      app::parse_device_choice(device), report);
  return rc;
}

}  // namespace

class EmulatedNeverCrosses : public ::testing::TestWithParam<std::string> {};

TEST_P(EmulatedNeverCrosses, SameChecksAsTheSimulatedDevice) {
  app::DeviceReport rep;
  const RunChecks rc = run_checked(GetParam(), "haply-emulator", 4.0, &rep);
  EXPECT_EQ(rc.ticks, 4000);
  EXPECT_EQ(rc.crossings, 0);
  EXPECT_EQ(rc.bad_force, 0);
  EXPECT_EQ(rc.bad_torque, 0);
  EXPECT_GT(rc.contact_ticks, 100) << "the sweep should touch the picture's curves";
  EXPECT_EQ(rep.status, "ok");
  EXPECT_NE(rep.name.find("haply-emulator"), std::string::npos) << rep.name;
  EXPECT_LT(rep.replies_missing, 40) << "a healthy emulator answers (nearly) every tick";
}

INSTANTIATE_TEST_SUITE_P(RealImages, EmulatedNeverCrosses, ::testing::Values("horse.png", "coins.png"),
                         [](const auto& info) { return info.param.substr(0, info.param.find('.')); });

TEST(EmulatedDevice, UnpluggedMidRunGetsZeroForceAndTorqueAndEndsLost) {
  constexpr double kT = 1.0;
  const config::Settings defaults;
  const double period = 1.0 / defaults.haptics.servo_rate_hz;
  const double quiet_after = kT + (defaults.device.lost_after_ticks + 1) * period;
  long late_force = 0, late_torque = 0, late_ticks = 0;
  app::DeviceReport rep;
  const RunChecks rc = run_checked("horse.png", "haply-emulator:disconnect_at_s=1", 2.0, &rep,
                                   [&](const app::ServoTick& r, const ServoOutput& so) {
                                     if (r.t_s <= quiet_after) return;
                                     ++late_ticks;
                                     late_force += so.force_n.x != 0.0 || so.force_n.y != 0.0;
                                     late_torque += r.motor_torque_n_m[0] != 0.0 || r.motor_torque_n_m[1] != 0.0;
                                   });
  EXPECT_GT(late_ticks, 900);
  EXPECT_EQ(late_force, 0);
  EXPECT_EQ(late_torque, 0);
  EXPECT_EQ(rc.bad_torque, 0);
  EXPECT_EQ(rep.status, "lost");
  EXPECT_GE(rep.replies_missing, late_ticks);

  // The same through the command line: exit 0, the trace's force 0 from then on, summary says lost.
  const fs::path out = fresh_dir("emu_unplug");
  const ExeResult r = run_exe("explore '" + (kData / "images" / "horse.png").string() + "' --out '" + out.string() +
                                  "' --duration 2 --device haply-emulator:disconnect_at_s=1",
                              out);
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream mf(out / "summary.json");
  const json sum = json::parse(mf);
  EXPECT_EQ(sum["device"]["status"], "lost");
  EXPECT_GT(sum["device"]["replies_missing"].get<long>(), 900);
  std::ifstream tf(out / "trace.csv");
  std::string line;
  std::getline(tf, line);
  long rows = 0, nonzero_late = 0;
  while (std::getline(tf, line)) {
    double t = 0, hx, hy, px, py, fx = 0, fy = 0;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf", &t, &hx, &hy, &px, &py, &fx, &fy) != 7) continue;
    ++rows;
    if (t > quiet_after && (fx != 0.0 || fy != 0.0)) ++nonzero_late;
  }
  EXPECT_EQ(rows, 2000);
  EXPECT_EQ(nonzero_late, 0);
  fs::remove_all(out);
}

TEST(EmulatedDevice, GarbageAndDropsNeverGiveABadTorqueOrACrossing) {
  app::DeviceReport rep;
  const RunChecks rc =
      run_checked("horse.png", "haply-emulator:garbage_every=5,drop_every=9,wrong_id_every=17,seed=3", 3.0, &rep);
  EXPECT_EQ(rc.bad_torque, 0);
  EXPECT_EQ(rc.crossings, 0);
  EXPECT_GT(rep.malformed, 50);
  EXPECT_GT(rep.replies_missing, 50);
}

TEST(EmulatedDevice, AStallIsLostThenBackWithTheForceRampedIn) {
  app::DeviceReport rep;
  long lost = 0;
  const RunChecks rc =
      run_checked("horse.png", "haply-emulator:stall_at_s=1,stall_s=0.05", 2.5, &rep,
                  [&](const app::ServoTick& r, const ServoOutput&) { lost += r.sample.status == DeviceStatus::Lost; });
  EXPECT_GT(lost, 0);
  EXPECT_EQ(rep.status, "ok");
  EXPECT_EQ(rep.reconnects, 1);
  EXPECT_EQ(rc.bad_force, 0) << "after the stall the force law holds again once the ramp is over";
  EXPECT_EQ(rc.bad_torque, 0);
}

TEST(EmulatedDevice, BadDeviceValuesEndInOneLine) {
  const fs::path tmp = fresh_dir("emu_bad");
  const std::string img = (kData / "images" / "horse.png").string();
  struct Case {
    const char* device;
    const char* must_name;
  };
  for (const Case& c : {Case{"usb", "--device 'usb'"}, Case{"haply-emulator:drop_every=-1", "drop_every=-1"},
                        Case{"haply-emulator:fly=1", "unknown fault 'fly'"},
                        Case{"haply-emulator:stall_s", "KEY=VALUE"}, Case{"haply-emulatorx", "must be 'sim'"}}) {
    const ExeResult r = run_exe(
        "explore '" + img + "' --out '" + (tmp / "o").string() + "' --duration 0.1 --device '" + c.device + "'", tmp);
    EXPECT_NE(r.status, 0) << c.device;
    EXPECT_NE(r.err.find(c.must_name), std::string::npos) << c.device << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  fs::remove_all(tmp);
}

TEST(EmulatedDevice, CalibrateWritesOffsetsThatUndoAnEncoderZeroError) {
  const fs::path tmp = fresh_dir("emu_calibrate");
  const fs::path cfg = tmp / "settings.toml";
  config::Settings s;
  s.haptics.stiffness_n_per_m = 654;  // a value that must survive the rewrite
  config::save_settings_atomic(s, cfg.string());
  const ExeResult r = run_exe(
      "calibrate --config '" + cfg.string() + "' --device haply-emulator:calib_error1_deg=3,calib_error2_deg=-2", tmp);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("encoder 1 offset 180.000 ->"), std::string::npos) << r.out;
  const config::Settings back = config::load_settings(cfg.string());
  // One count is 360 / 2440 deg; the mean of 50 readings of a still handle lands within it.
  EXPECT_NEAR(back.device.encoder1_offset_deg, 177.0, 0.2);
  EXPECT_NEAR(back.device.encoder2_offset_deg, 2.0, 0.2);
  EXPECT_EQ(back.haptics.stiffness_n_per_m, 654);
  fs::remove_all(tmp);
}

TEST(EmulatedDevice, DevicesListsWithoutFailingWhereThereIsNoUsb) {
  const fs::path tmp = fresh_dir("emu_devices");
  const ExeResult r = run_exe("devices", tmp);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("USB devices:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Serial devices"), std::string::npos) << r.out;
  fs::remove_all(tmp);
}
