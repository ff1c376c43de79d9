// The hAPI pantograph driver (haptics/io/haply_device.hpp) against the firmware emulator, in process: a
// loopback transport hands the driver's bytes to FirmwareEmulator::receive and its replies back, so every
// tick is deterministic. Positions, torques through the cross-wired ports, the torque clamp, lost and
// stalled boards, garbage and dropped replies, and calibration.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "haptics/hapi_emulator.hpp"
#include "haptics/io/haply_device.hpp"

using namespace hk;

namespace {

/// A transport straight into the emulator (no pty, no thread): write feeds it, read takes its output.
class LoopbackTransport final : public io::ByteTransport {
 public:
  explicit LoopbackTransport(hapi::FirmwareEmulator& e) : emu_(e) {}
  void open() override { open_ = true; }
  void close() noexcept override { open_ = false; }
  int write(const std::uint8_t* data, int n, int) noexcept override {
    emu_.receive(data, n);
    return n;
  }
  int read(std::uint8_t* buf, int capacity, int) noexcept override { return emu_.take_output(buf, capacity); }
  void flush_input() noexcept override {
    std::uint8_t sink[256];
    while (emu_.take_output(sink, sizeof sink) > 0) {
    }
  }
  bool is_open() const noexcept override { return open_; }
  std::string name() const override { return "loopback"; }

 private:
  hapi::FirmwareEmulator& emu_;
  bool open_ = false;
};

struct Rig {
  explicit Rig(hapi::EmulatorParams ep = {}, Vec2 start_ws = {0.01, -0.005}, io::HaplyDeviceParams p = {})
      : dp(p),
        emu(fill(ep, dp), device_of(dp, start_ws),
            [](double, Vec2, Vec2) {
              return Vec2{0.0, 0.0};
            }),
        dev(dp, [this] { return std::make_unique<LoopbackTransport>(emu); }) {}
  static hapi::EmulatorParams fill(hapi::EmulatorParams ep, const io::HaplyDeviceParams& dp) {
    ep.mechanism = dp.mechanism;
    ep.torque_limit_n_m = dp.torque_limit_n_m;
    ep.workspace_half_extent_m = 0.5 * dp.rect_size_device_m;
    ep.workspace_center_m = dp.rect_center_device_m;
    return ep;
  }
  static Vec2 device_of(const io::HaplyDeviceParams& dp, Vec2 ws) {
    return (1.0 / io::workspace_scale(dp)) * ws + dp.rect_center_device_m;
  }
  io::HaplyDeviceParams dp;
  hapi::FirmwareEmulator emu;
  io::HaplyDevice dev;
};

// One encoder count of the gen3 board is 360 / (4880 / 2) degrees; through links of 0.07 m and 0.09 m and
// the workspace scale (1.4) that moves the handle well under a millimetre.
constexpr double kPositionTolerance_m = 1e-3;

}  // namespace

TEST(HaplyDevice, ReadsTheHandleWhereTheEmulatedLinkageHoldsIt) {
  Rig r;
  r.dev.open();
  EXPECT_EQ(r.dev.status(), DeviceStatus::Ok);
  for (int k = 0; k < 20; ++k) {
    r.dev.write_force({0.0, 0.0});
    const DeviceSample s = r.dev.read();
    ASSERT_EQ(s.status, DeviceStatus::Ok);
    const Vec2 truth = r.dev.to_workspace(r.emu.handle_device_m());
    EXPECT_NEAR(s.handle_m.x, truth.x, kPositionTolerance_m) << k;
    EXPECT_NEAR(s.handle_m.y, truth.y, kPositionTolerance_m) << k;
  }
  EXPECT_NEAR(r.dev.read().handle_m.x, 0.01, kPositionTolerance_m);
  EXPECT_NEAR(r.dev.read().handle_m.y, -0.005, kPositionTolerance_m);
}

TEST(HaplyDevice, AForceComesOutAsThatForceThroughTheCrossWiredPorts) {
  // Jᵀ·F per joint, sent in port order (port 1 = actuator 2), turned back into a handle force by the
  // emulator's own Jacobian: the same vector comes out only if every index and port is mapped right.
  for (Vec2 f : {Vec2{0.4, 0.0}, Vec2{0.0, 0.4}, Vec2{-0.3, 0.2}, Vec2{0.1, -0.35}}) {
    Rig r;
    r.dev.open();
    r.dev.read();
    r.dev.write_force(f);
    r.dev.read();  // the emulator has executed the packet
    const Vec2 out = r.emu.applied_force_device_n();
    EXPECT_NEAR(out.x, f.x, 0.03 * length(f)) << f.x << "," << f.y;
    EXPECT_NEAR(out.y, f.y, 0.03 * length(f)) << f.x << "," << f.y;
  }
}

TEST(HaplyDevice, TorquesAreClampedAndANonFiniteForceSendsZero) {
  Rig r;
  r.dev.open();
  r.dev.read();
  double t1 = 0, t2 = 0;
  r.dev.write_force({500.0, -300.0});
  r.dev.last_torques_n_m(&t1, &t2);
  EXPECT_LE(std::fabs(t1), r.dp.torque_limit_n_m);
  EXPECT_LE(std::fabs(t2), r.dp.torque_limit_n_m);
  EXPECT_TRUE(std::fabs(t1) == r.dp.torque_limit_n_m || std::fabs(t2) == r.dp.torque_limit_n_m);
  r.dev.read();
  r.dev.write_force({NAN, 1.0});
  r.dev.last_torques_n_m(&t1, &t2);
  EXPECT_EQ(t1, 0.0);
  EXPECT_EQ(t2, 0.0);
}

TEST(HaplyDevice, ADisconnectedBoardIsLostAfterLostAfterTicksAndGetsZeroTorque) {
  hapi::EmulatorParams ep;
  ep.faults.disconnect_at_s = 0.2;
  Rig r(ep);
  r.dev.open();
  const double lim = r.dp.torque_limit_n_m;
  long first_lost = -1, answered_ticks = 0;
  for (long k = 0; k < 600; ++k) {
    const DeviceSample s = r.dev.read();
    if (s.status == DeviceStatus::Lost && first_lost < 0) first_lost = k;
    if (s.status == DeviceStatus::Ok) ++answered_ticks;
    r.dev.write_force({0.5, 0.5});  // a force the servo would send if the guard let it
    double t1 = 0, t2 = 0;
    r.dev.last_torques_n_m(&t1, &t2);
    if (first_lost >= 0) {
      EXPECT_EQ(t1, 0.0) << k;
      EXPECT_EQ(t2, 0.0) << k;
    } else {
      EXPECT_LE(std::fabs(t1), lim);
    }
  }
  ASSERT_GE(first_lost, 0) << "the board never counted as lost";
  // The emulator stops at 0.2 s of its time (200 torque packets, one of them sent by open()); the driver
  // notices lost_after_ticks = 3 ticks later.
  EXPECT_LE(first_lost, 200 + r.dp.lost_after_ticks + 1);
  EXPECT_GE(first_lost, 200 - 1);
  EXPECT_EQ(r.dev.status(), DeviceStatus::Lost);
  EXPECT_GE(r.dev.counters().replies_missing, 600 - first_lost);
}

TEST(HaplyDevice, AStalledBoardIsLostThenBackWithOneReconnect) {
  hapi::EmulatorParams ep;
  ep.faults.stall_at_s = 0.1;
  ep.faults.stall_s = 0.05;
  Rig r(ep);
  r.dev.open();
  bool was_lost = false;
  for (long k = 0; k < 400; ++k) {
    const DeviceSample s = r.dev.read();
    was_lost = was_lost || s.status == DeviceStatus::Lost;
    r.dev.write_force({0.1, 0.0});
  }
  EXPECT_TRUE(was_lost);
  EXPECT_EQ(r.dev.status(), DeviceStatus::Ok);
  EXPECT_EQ(r.dev.counters().reconnects, 1);
}

TEST(HaplyDevice, GarbageDropsAndWrongIdsNeverGiveABadTorqueOrAJump) {
  hapi::EmulatorParams ep;
  ep.faults.garbage_every = 7;
  ep.faults.drop_every = 11;
  ep.faults.wrong_id_every = 13;
  ep.faults.seed = 42;
  Rig r(ep);
  r.dev.open();
  Vec2 last = r.dev.read().handle_m;
  long ok_ticks = 0;
  for (long k = 0; k < 3000; ++k) {
    const DeviceSample s = r.dev.read();
    ASSERT_TRUE(is_finite(s.handle_m)) << k;
    ok_ticks += s.status == DeviceStatus::Ok;
    // The handle barely moves (no hand, small forces): a misread reply would show as a jump.
    EXPECT_LT(distance(s.handle_m, last), 0.005) << k;
    last = s.handle_m;
    r.dev.write_force({0.2 * std::sin(k * 0.01), 0.2 * std::cos(k * 0.01)});
    double t1 = 0, t2 = 0;
    r.dev.last_torques_n_m(&t1, &t2);
    ASSERT_TRUE(std::isfinite(t1) && std::isfinite(t2)) << k;
    ASSERT_LE(std::fabs(t1), r.dp.torque_limit_n_m);
    ASSERT_LE(std::fabs(t2), r.dp.torque_limit_n_m);
  }
  EXPECT_GT(r.dev.counters().malformed, 100);
  EXPECT_GT(ok_ticks, 2500) << "faults one tick in seven must not lose the board";
}

TEST(HaplyDevice, CalibrationRemovesAnEncoderZeroError) {
  hapi::EmulatorParams ep;
  ep.calibration_error_deg[0] = 3.0;
  ep.calibration_error_deg[1] = -2.0;
  const Vec2 park{0.0, 0.0};
  Rig r(ep, park);
  r.dev.open();
  r.dev.write_force({0, 0});
  const DeviceSample before = r.dev.read();
  EXPECT_GT(distance(before.handle_m, park), 2e-3) << "3 degrees of error must show";
  double a1 = 0, a2 = 0;
  r.dev.joint_angles_deg(&a1, &a2);
  double o1 = 0, o2 = 0;
  ASSERT_TRUE(io::calibrated_offsets(r.dp, park, a1, a2, &o1, &o2));
  EXPECT_NEAR(o1, 180.0 - 3.0, 0.3);
  EXPECT_NEAR(o2, 0.0 + 2.0, 0.3);

  // The running board, calibrated in place, reads the park place at once...
  double c1 = 0, c2 = 0;
  ASSERT_TRUE(r.dev.calibrate(park, &c1, &c2));
  EXPECT_DOUBLE_EQ(c1, o1);
  EXPECT_DOUBLE_EQ(c2, o2);
  r.dev.write_force({0, 0});
  const DeviceSample corrected = r.dev.read();
  EXPECT_NEAR(corrected.handle_m.x, park.x, kPositionTolerance_m);
  EXPECT_NEAR(corrected.handle_m.y, park.y, kPositionTolerance_m);
  EXPECT_EQ(corrected.status, DeviceStatus::Ok);
  // Calibrating again where it already reads right changes nothing.
  ASSERT_TRUE(r.dev.calibrate(park, &c1, &c2));
  EXPECT_NEAR(c1, o1, 0.2);
  EXPECT_NEAR(c2, o2, 0.2);

  // ...and so does a board set up with the new offsets.
  io::HaplyDeviceParams fixed = r.dp;
  for (int i = 0; i < fixed.layout.encoder_count; ++i)
    fixed.layout.encoders[i].offset_deg = fixed.layout.encoders[i].index == 1 ? o1 : o2;
  Rig again(ep, park, fixed);
  again.dev.open();
  again.dev.write_force({0, 0});
  const DeviceSample after = again.dev.read();
  EXPECT_NEAR(after.handle_m.x, park.x, kPositionTolerance_m);
  EXPECT_NEAR(after.handle_m.y, park.y, kPositionTolerance_m);
}

TEST(HaplyDevice, BadParametersAreRefusedInOneLine) {
  io::HaplyDeviceParams p;
  p.layout.actuators[1].port = p.layout.actuators[0].port;
  EXPECT_THROW(io::HaplyDevice(p, [] { return std::unique_ptr<io::ByteTransport>(); }), DeviceError);
  io::HaplyDeviceParams q;
  q.rect_size_device_m = {0.0, 0.05};
  try {
    io::HaplyDevice d(q, [] { return std::unique_ptr<io::ByteTransport>(); });
    FAIL() << "a zero-width rectangle was accepted";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("rectangle"), std::string::npos) << e.what();
  }
}

TEST(HaplyDevice, ABoardThatNeverAnswersFailsToOpenNamingTheTransport) {
  hapi::EmulatorParams ep;
  ep.faults.disconnect_at_s = 0.0;
  io::HaplyDeviceParams p;
  p.open_timeout_ms = 50;
  Rig r(ep, {0.0, 0.0}, p);
  try {
    r.dev.open();
    FAIL() << "open succeeded without a reply";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("loopback"), std::string::npos) << e.what();
  }
  EXPECT_EQ(r.dev.status(), DeviceStatus::Closed);
}

TEST(HaplyDevice, TheGen3CanGiveAboutOneAndAHalfNewtonsEverywhere) {
  // The reachability scan that chose the rectangle found σ(J) ≤ 0.094 m/rad over its stop box, so at
  // least 0.123 / 0.094 = 1.3 N in every direction (per motor the bound is looser still); the default
  // max_force_n (4 N) is more than the gen3 can give everywhere.
  const io::HaplyDeviceParams p;
  const double f = io::min_force_capability_n(p);
  EXPECT_GE(f, 1.3);
  EXPECT_LT(f, 4.0);
  // Twice the torque limit, twice the force; a rectangle out of reach, none.
  io::HaplyDeviceParams strong = p;
  strong.torque_limit_n_m *= 2;
  EXPECT_NEAR(io::min_force_capability_n(strong), 2 * f, 1e-9);
  io::HaplyDeviceParams far = p;
  far.rect_center_device_m = {0.0, -0.5};
  EXPECT_EQ(io::min_force_capability_n(far), 0.0);
}

namespace {

/// A loopback whose board answers a tick late: what the emulator says reaches the driver one read() later.
class LateLoopback final : public io::ByteTransport {
 public:
  explicit LateLoopback(hapi::FirmwareEmulator& e) : emu_(e) {}
  void open() override { open_ = true; }
  void close() noexcept override { open_ = false; }
  int write(const std::uint8_t* data, int n, int) noexcept override {
    emu_.receive(data, n);
    return n;
  }
  int read(std::uint8_t* buf, int capacity, int) noexcept override {
    const int n = std::min(capacity, held_);
    std::copy(held_bytes_, held_bytes_ + n, buf);
    std::copy(held_bytes_ + n, held_bytes_ + held_, held_bytes_);
    held_ -= n;
    held_ += emu_.take_output(held_bytes_ + held_,
                              static_cast<int>(sizeof held_bytes_) - held_);  // heard now, delivered next read
    return n;
  }
  void flush_input() noexcept override {}
  bool is_open() const noexcept override { return open_; }
  std::string name() const override { return "late loopback"; }

 private:
  hapi::FirmwareEmulator& emu_;
  std::uint8_t held_bytes_[512] = {};
  int held_ = 0;
  bool open_ = false;
};

/// A loopback whose output buffer takes at most `per_write` bytes per call: a transport that is full.
class NarrowLoopback final : public io::ByteTransport {
 public:
  NarrowLoopback(hapi::FirmwareEmulator& e, int per_write) : emu_(e), per_write_(per_write) {}
  void open() override { open_ = true; }
  void close() noexcept override { open_ = false; }
  int write(const std::uint8_t* data, int n, int timeout_us) noexcept override {
    max_timeout_us = std::max(max_timeout_us, timeout_us);
    const int k = std::min(n, per_write_);
    emu_.receive(data, k);
    return k;
  }
  int read(std::uint8_t* buf, int capacity, int) noexcept override { return emu_.take_output(buf, capacity); }
  void flush_input() noexcept override {}
  bool is_open() const noexcept override { return open_; }
  std::string name() const override { return "narrow loopback"; }
  int max_timeout_us = 0;  ///< the longest wait any write asked for [µs]

 private:
  hapi::FirmwareEmulator& emu_;
  int per_write_;
  bool open_ = false;
};

}  // namespace

TEST(HaplyDeviceNeverWaits, AReplyOneTickLateIsTakenOnTheNextTickAndTheWriteBetweenIsSkipped) {
  const io::HaplyDeviceParams dp;
  hapi::FirmwareEmulator emu(Rig::fill({}, dp), Rig::device_of(dp, {0.01, -0.005}), [](double, Vec2, Vec2) {
    return Vec2{0.0, 0.0};
  });
  io::HaplyDevice dev(dp, [&emu] { return std::make_unique<LateLoopback>(emu); });
  dev.open();  // its zero-torque packets until the first (late) reply
  // Settle: whatever open() left outstanding is answered or given up.
  for (int k = 0; k < 4; ++k) {
    dev.read();
    dev.write_force({0.0, 0.0});
  }
  const io::HaplyCounters before = dev.counters();
  const long commands_before = emu.torque_commands();
  for (int k = 0; k < 100; ++k) {
    const DeviceSample s = dev.read();
    EXPECT_EQ(s.status, DeviceStatus::Ok) << k;  // a tick late is not lost
    dev.write_force({0.1, 0.0});
  }
  const io::HaplyCounters after = dev.counters();
  // Lock-step with a board a tick late: a packet every other tick, each reply taken, the tick between skipped.
  EXPECT_EQ(after.ticks - before.ticks, 50);
  EXPECT_EQ(after.replies - before.replies, 50);
  EXPECT_EQ(after.writes_skipped - before.writes_skipped, 50);
  EXPECT_EQ(after.malformed, 0);
  EXPECT_EQ(emu.torque_commands() - commands_before, after.ticks - before.ticks);  // nothing sent twice, nothing lost
}

TEST(HaplyDeviceNeverWaits, AFullTransportSkipsTheWriteAndNeverCutsAPacket) {
  const io::HaplyDeviceParams dp;
  hapi::FirmwareEmulator emu(Rig::fill({}, dp), Rig::device_of(dp, {0.0, 0.0}), [](double, Vec2, Vec2) {
    return Vec2{0.0, 0.0};
  });
  NarrowLoopback* narrow = nullptr;
  io::HaplyDevice dev(dp, [&emu, &narrow] {
    auto t = std::make_unique<NarrowLoopback>(emu, 4);  // a 10-byte torque packet takes three ticks to go out
    narrow = t.get();
    return t;
  });
  dev.open();
  narrow->max_timeout_us = 0;  // open() may wait; the servo step's calls may not
  const io::HaplyCounters before = dev.counters();
  const long commands_before = emu.torque_commands();
  for (int k = 0; k < 300; ++k) {
    const DeviceSample s = dev.read();
    EXPECT_NE(s.status, DeviceStatus::Closed) << k;
    dev.write_force({0.0, 0.2});
  }
  const io::HaplyCounters after = dev.counters();
  EXPECT_EQ(narrow->max_timeout_us, 0);                          // no call in the step waited for room
  EXPECT_GT(after.writes_skipped - before.writes_skipped, 100);  // most ticks found the last packet still going out
  EXPECT_GT(after.ticks - before.ticks, 50);
  EXPECT_EQ(after.malformed, 0);  // the board never saw a packet cut by another:
  EXPECT_GE(emu.torque_commands() - commands_before,
            after.ticks - before.ticks - 1);      // every packet but one on its way, whole
  EXPECT_GT(after.replies - before.replies, 50);  // and answered
}
