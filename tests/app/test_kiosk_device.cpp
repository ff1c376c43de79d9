// The kiosk's runtime and the USB pantograph, without its window: a board on a
// tty (the firmware emulator behind a pty, named in [device] serial_path) is opened, used by the servo
// thread and announced; when it stops answering the kiosk says so; with no board the simulated pantograph
// stands in and the kiosk says that, and why is kept for the operator.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include "audio/messages.hpp"
#include "haptics/hapi_emulator.hpp"
#include "haptics/pty_emulator.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/device_setup.hpp"
#include "runtime/runtime_params.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_runtime.hpp"

namespace fs = std::filesystem;

namespace hk::app {
namespace {

const fs::path kData = HK_TEST_DATA_DIR;

struct Library {
  Library() : dir(fs::temp_directory_path() / ("hk_kiosk_device_" + std::to_string(::getpid()))) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::copy_file(kData / "images" / "horse.png", dir / "horse.png");
  }
  ~Library() { fs::remove_all(dir); }
  fs::path dir;
};

RuntimeOptions options(const Library& lib) {
  RuntimeOptions ro;
  ro.library = lib.dir.string();
  ro.hotplug = false;
  ro.open_audio_output = false;
  ro.probe_usb_device = true;
  return ro;
}

// A USB pantograph looked for on a tty that does not exist.
config::Settings no_board_settings() {
  config::Settings s;
  s.device.type = "auto";
  s.device.transport = "tty";
  s.device.serial_path = "/dev/hk-no-such-board";
  return s;
}

const std::string& said(audio::MessageId id) {
  static std::string texts[audio::kMessageCount];
  std::string& t = texts[static_cast<int>(id)];
  if (t.empty()) t = audio::MessageCatalog::english().text(id);
  return t;
}

}  // namespace

TEST(KioskDevice, ABoardOnItsTtyIsUsedAnnouncedAndItsLossSpoken) {
  config::Settings s;
  s.device.type = "haply";
  s.device.transport = "tty";
  DeviceChoice unplug;
  unplug.kind = DeviceChoice::Kind::HaplyEmulator;
  unplug.faults.disconnect_at_s = 0.5;  // of the board's own time: 500 torque packets
  Vec2 home;                            // the board waits at its home pose, as one does for the kiosk to start
  const hapi::EmulatorParams at_rest = emulator_resting_at_park(s, unplug, &home);
  hapi::FirmwareEmulator board(at_rest, home, [](double, Vec2, Vec2) { return Vec2{}; });
  hapi::PtyEmulator pty(board);
  s.device.serial_path = pty.device_path();

  const Library lib;
  KioskRuntime rt(options(lib), s);
  ASSERT_NE(rt.devices().usb(), nullptr) << rt.devices().note();
  EXPECT_EQ(rt.devices().home_note(), "");
  EXPECT_EQ(&rt.devices().device(), rt.devices().usb());
  EXPECT_TRUE(rt.devices().note().empty());
  rt.start_servo();
  rt.announce_device();
  EXPECT_EQ(rt.voice().last_said(), said(audio::MessageId::device_ready));

  // The servo thread sends a packet every millisecond; the board stops answering after 500 of them.
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  double t = 0.0;
  while (rt.voice().last_said() != said(audio::MessageId::device_lost) && std::chrono::steady_clock::now() < give_up) {
    rt.poll(nullptr, t += 0.01);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));  // a frame; the outcome is the message, not the time
  }
  EXPECT_EQ(rt.voice().last_said(), said(audio::MessageId::device_lost));
  EXPECT_EQ(rt.devices().usb()->status(), DeviceStatus::Lost);
  EXPECT_GE(board.torque_commands(), 500);
  rt.devices().stop_servo();
  double tau1 = 1, tau2 = 1;
  rt.devices().usb()->last_torques_n_m(&tau1, &tau2);
  EXPECT_EQ(tau1, 0.0);
  EXPECT_EQ(tau2, 0.0);
}

TEST(KioskDevice, WithNoBoardTheSimulatedPantographStandsInAndSaysSo) {
  const Library lib;
  KioskRuntime rt(options(lib), no_board_settings());
  EXPECT_EQ(rt.devices().usb(), nullptr);
  EXPECT_NE(rt.devices().note().find("/dev/hk-no-such-board"), std::string::npos) << rt.devices().note();
  rt.start_servo();
  rt.announce_device();
  EXPECT_EQ(rt.voice().last_said(), said(audio::MessageId::device_simulated));
  double o1 = 0, o2 = 0;
  std::string why;
  EXPECT_FALSE(rt.devices().calibrate(&o1, &o2, &why));
  EXPECT_NE(why.find("no USB pantograph"), std::string::npos) << why;
  rt.devices().stop_servo();
}

// Probed every 10 s for months without a board: the warning is logged once per reason, not each time.
TEST(KioskDevice, AMissingBoardIsLoggedOncePerReason) {
  auto ring = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(256);
  ring->set_level(spdlog::level::warn);
  spdlog::default_logger()->sinks().push_back(ring);
  const auto count_warnings = [&] {
    int n = 0;
    for (const std::string& line : ring->last_formatted()) n += line.find("no USB pantograph") != std::string::npos;
    return n;
  };
  {
    const Library lib;
    KioskRuntime rt(options(lib), no_board_settings());
    EXPECT_EQ(count_warnings(), 1) << "the first probe says why";
    for (double t = 0.0; t < 120.0; t += 1.0) rt.poll(nullptr, t);  // 12 more probes, the same reason
    EXPECT_EQ(rt.devices().usb(), nullptr);
    EXPECT_EQ(count_warnings(), 1);
  }
  spdlog::default_logger()->sinks().pop_back();
}

TEST(KioskDevice, ChosenSimulatedIsNotAnnounced) {
  config::Settings s;
  s.device.type = "simulated";
  const Library lib;
  KioskRuntime rt(options(lib), s);
  EXPECT_EQ(rt.devices().usb(), nullptr);
  EXPECT_TRUE(rt.devices().note().empty());
  rt.announce_device();
  EXPECT_TRUE(rt.voice().last_said().empty()) << rt.voice().last_said();
}

}  // namespace hk::app

namespace hk::app {

TEST(KioskDevice, TheEmulatedBoardOptionDrivesTheDriverThroughAPty) {
  const Library lib;
  RuntimeOptions ro = options(lib);
  ro.probe_usb_device = false;   // a scripted run: no hardware looked for...
  ro.device = "haply-emulator";  // ...but the emulated board asked for
  config::Settings s;
  KioskRuntime rt(ro, s);
  ASSERT_NE(rt.devices().usb(), nullptr);
  EXPECT_NE(rt.devices().usb()->name().find("tty /dev/"), std::string::npos) << rt.devices().usb()->name();
  rt.announce_device();
  EXPECT_EQ(rt.voice().last_said(), said(audio::MessageId::device_ready));
  rt.start_servo();
  // The handle follows the cursor through the board's model hand: the servo sees it arrive.
  rt.tour().set_cursor({0.03, 0.01});
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (distance(rt.core().display().handle_m, Vec2{0.03, 0.01}) > 0.004 && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_LT(distance(rt.core().display().handle_m, Vec2{0.03, 0.01}), 0.004);
  rt.devices().stop_servo();

  RuntimeOptions bad = options(lib);
  bad.device = "sim";
  EXPECT_THROW(KioskRuntime(bad, s), DeviceChoiceError);
}

}  // namespace hk::app

namespace hk::app {
namespace {

// What run_stall saw: whether the kiosk took the emulated board, whether `done` came within the deadline, and
// everything said, in order.
struct StallRun {
  bool board = false;
  bool done = false;
  std::vector<std::string> said;
};

// A kiosk on an emulated board that stalls at 0.3 s of its time for `stall_s`; polls the device on the
// real clock until `done` (the 20 s deadline only bounds a hang).
StallRun run_stall(double stall_s, const std::function<bool(KioskRuntime&)>& done) {
  config::Settings s;
  DeviceChoice stall;
  stall.kind = DeviceChoice::Kind::HaplyEmulator;
  stall.faults.stall_at_s = 0.3;
  stall.faults.stall_s = stall_s;
  hapi::FirmwareEmulator board(emulator_params_from(s, stall), haply_params_from(s).rect_center_device_m,
                               [](double, Vec2, Vec2) { return Vec2{}; });
  hapi::PtyEmulator pty(board);
  s.device.type = "haply";
  s.device.transport = "tty";
  s.device.serial_path = pty.device_path();
  const Library lib;
  KioskRuntime rt(options(lib), s);
  StallRun run;
  run.board = rt.devices().usb() != nullptr;
  if (!run.board) return run;
  rt.start_servo();
  const auto t0 = std::chrono::steady_clock::now();
  std::string last;
  while (!(run.done = done(rt)) && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20)) {
    rt.poll(nullptr, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (rt.voice().last_said() != last) run.said.push_back(last = rt.voice().last_said());
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  rt.devices().stop_servo();
  return run;
}

}  // namespace

TEST(KioskDevice, ALongLossIsSpokenAndSoIsTheReturn) {
  const StallRun run = run_stall(1.5, [](KioskRuntime& rt) {
    return rt.devices().usb()->counters().reconnects >= 1 &&
           rt.voice().last_said() == said(audio::MessageId::device_back);
  });
  ASSERT_TRUE(run.board) << "the kiosk took the emulated board";
  ASSERT_TRUE(run.done) << "the board was lost and came back within 20 s";
  const std::vector<std::string>& s = run.said;
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0], said(audio::MessageId::device_lost));
  EXPECT_EQ(s[1], said(audio::MessageId::device_back));
}

TEST(KioskDevice, AShortLossIsNotSpoken) {
  const StallRun run = run_stall(0.02, [](KioskRuntime& rt) { return rt.devices().usb()->counters().reconnects >= 1; });
  ASSERT_TRUE(run.board) << "the kiosk took the emulated board";
  ASSERT_TRUE(run.done) << "the stall cost the driver a reconnect within 20 s";
  EXPECT_TRUE(run.said.empty()) << run.said.front();
}

}  // namespace hk::app

namespace hk::app {

TEST(KioskDevice, AHandleThatDidNotStartAtHomeIsToldToTheStaffAtStartAndNeverToAVisitor) {
  // The board was set up with its handle 8 degrees of joint 1 away from home: every position reads wrong.
  const Library lib;
  RuntimeOptions ro = options(lib);
  ro.device = "haply-emulator:rest_at_park=1,calib_error1_deg=8";
  auto sink = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(64);
  auto logger = std::make_shared<spdlog::logger>("home", sink);
  auto before = spdlog::default_logger();
  spdlog::set_default_logger(logger);
  KioskRuntime rt(ro, config::Settings{});
  spdlog::set_default_logger(before);
  ASSERT_NE(rt.devices().usb(), nullptr);
  // The operator: one logged line, kept for the panel, naming the distance and the fix.
  EXPECT_NE(rt.devices().home_note().find("from its home pose at the park place"), std::string::npos)
      << rt.devices().home_note();
  EXPECT_NE(rt.devices().home_note().find("press Calibrate in the operator's panel, or run 'haptic-kiosk calibrate'"),
            std::string::npos);
  int logged = 0;
  for (const std::string& line : sink->last_formatted())
    logged += line.find("device: the handle reads") != std::string::npos && line.find("[warning]") != std::string::npos;
  EXPECT_EQ(logged, 1);
  // Spoken once, with the start's announcement, before any visitor.
  rt.announce_device();
  EXPECT_EQ(rt.voice().last_said(),
            said(audio::MessageId::device_ready) + " " + said(audio::MessageId::device_not_home));
  // A visitor who comes later does not hear it: not again with the device, not in the picture's description.
  rt.announce_device();
  EXPECT_EQ(rt.voice().last_said(), said(audio::MessageId::device_ready));
  EXPECT_EQ(rt.stage().describe().find(said(audio::MessageId::device_not_home)), std::string::npos);
  // Calibrated where it rests: the note is gone.
  double o1 = 0, o2 = 0;
  std::string why;
  ASSERT_TRUE(rt.devices().calibrate(&o1, &o2, &why)) << why;
  EXPECT_EQ(rt.devices().home_note(), "");
}

TEST(KioskDevice, AHandleAtHomeIsNotMentioned) {
  const Library lib;
  RuntimeOptions ro = options(lib);
  ro.device = "haply-emulator:rest_at_park=1";
  KioskRuntime rt(ro, config::Settings{});
  ASSERT_NE(rt.devices().usb(), nullptr);
  EXPECT_EQ(rt.devices().home_note(), "");
  rt.announce_device();
  EXPECT_EQ(rt.voice().last_said(), said(audio::MessageId::device_ready));
}

}  // namespace hk::app
