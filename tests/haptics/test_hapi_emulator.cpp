/// @file test_hapi_emulator.cpp
/// The firmware emulator (hapi_emulator.hpp) and its pty server (pty_emulator.hpp). Expected bytes and
/// motions come from the firmware source (Haply_M0_Firmware_V0_3.h) and from our kinematics, never from
/// a previous run.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "haptics/hapi_emulator.hpp"
#include "haptics/hapi_protocol.hpp"
#include "haptics/pty_emulator.hpp"
#include "hk/error.hpp"
#include "kinematics/haply_mechanism.hpp"
#include "kinematics/pantograph.hpp"

namespace hk::hapi {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr double kPi = std::numbers::pi;
/// One firmware count in degrees: 360 / (4880 / 2).
constexpr double kCountDeg = 360.0 / 2440.0;
const Vec2 kCenter{0.0, -0.088};

Bytes reset_pkt(std::uint8_t id = 5) {
  std::uint8_t b[2];
  encode_reset(id, b);
  return Bytes(b, b + 2);
}
Bytes setup_pkt(const BoardLayout& l = BoardLayout::haply_gen3()) {
  std::uint8_t b[kMaxPacketBytes];
  const int n = encode_setup(l, b, kMaxPacketBytes);
  return Bytes(b, b + n);
}
/// Torque command by actuator index (τ1 = actuator 1 = Haply joint 1 on gen3).
Bytes torque_pkt(double tau1, double tau2, const BoardLayout& l = BoardLayout::haply_gen3()) {
  const double t[4] = {tau1, tau2, 0, 0};
  std::uint8_t b[kMaxPacketBytes];
  const int n = encode_torques(l, t, 1.0, b, kMaxPacketBytes);
  return Bytes(b, b + n);
}
void send(FirmwareEmulator& e, const Bytes& b) { e.receive(b.data(), static_cast<int>(b.size())); }
Bytes drain(FirmwareEmulator& e) {
  std::uint8_t buf[4096];
  const int n = e.take_output(buf, sizeof buf);
  return Bytes(buf, buf + n);
}
FirmwareEmulator make(EmulatorParams p = {}, Vec2 start = kCenter, HandForce hand = {}) {
  return FirmwareEmulator(p, start, std::move(hand));
}
void start_gen3(FirmwareEmulator& e) {
  send(e, reset_pkt());
  send(e, setup_pkt());
}

TEST(HapiEmulator, RejectsBadParams) {
  EmulatorParams p;
  p.period_s = 0;
  EXPECT_THROW(make(p), hk::ArgumentError);
  p = {};
  p.port_joint[1] = 2;
  EXPECT_THROW(make(p), hk::ArgumentError);
  p = {};
  p.workspace_half_extent_m = {0.2, 0.2};  // far outside the linkage's reach
  EXPECT_THROW(make(p), hk::ArgumentError);
}

TEST(HapiEmulator, DefaultRectangleIsReachableAndWellConditioned) {
  // The stop box (usable 0.112 × 0.072 m centred at (0, −0.088), +5 mm) on the elbows-outward branch.
  const PantographGeometry g = geometry_of(HaplyMechanism{});
  const EmulatorParams p;
  const Vec2 half = p.workspace_half_extent_m + Vec2{p.stop_margin_m, p.stop_margin_m};
  EXPECT_NEAR(p.workspace_half_extent_m.x / p.workspace_half_extent_m.y, 14.0 / 9.0, 1e-12);
  double min_det = 1e9, min_distal = 1e9, max_distal = 0, min_elbow = 1e9, max_elbow = 0;
  const int n = 60;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const Vec2 pt = p.workspace_center_m + Vec2{-half.x + 2 * half.x * i / n, -half.y + 2 * half.y * j / n};
      JointAngles q;
      ASSERT_TRUE(inverse_kinematics(g, pt, &q)) << pt.x << ", " << pt.y;
      Vec2 back;
      ASSERT_TRUE(forward_kinematics(g, q, &back));
      ASSERT_LT(distance(back, pt), 1e-12);
      min_det = std::min(min_det, std::abs(det(jacobian(g, q))));
      const Elbows e = elbow_positions(g, q);
      auto angle = [](Vec2 a, Vec2 b) { return std::acos(dot(a, b) / (length(a) * length(b))) * 180 / kPi; };
      const double distal = angle(pt - e.elbow1_m, pt - e.elbow2_m);
      const double el1 = angle(e.elbow1_m - motor1_position(g), pt - e.elbow1_m);
      const double el2 = angle(e.elbow2_m - motor2_position(g), pt - e.elbow2_m);
      min_distal = std::min(min_distal, distal);
      max_distal = std::max(max_distal, distal);
      min_elbow = std::min({min_elbow, el1, el2});
      max_elbow = std::max({max_elbow, el1, el2});
    }
  }
  EXPECT_GE(min_det, 0.0026);
  EXPECT_GE(min_distal, 55.0);
  EXPECT_LE(max_distal, 147.0);
  EXPECT_GE(min_elbow, 35.0);   // far from a stretched chain
  EXPECT_LE(max_elbow, 150.0);  // far from a folded chain
}

TEST(HapiEmulator, RoundTripGivesTheFirmwareReply) {
  FirmwareEmulator e = make();
  start_gen3(e);
  EXPECT_EQ(e.output_pending(), 0);  // no reply to reset or setup
  send(e, torque_pkt(0, 0));
  const Bytes r = drain(e);
  ASSERT_EQ(r.size(), 9u);  // [id, f32 port 1, f32 port 2]
  EXPECT_EQ(r[0], 5);
  double th1 = 0, th2 = 0;
  e.true_haply_deg(&th1, &th2);
  // Port 1 carries encoder 2 (Haply joint 2), port 2 encoder 1 (joint 1). Each float is 360·count/2440
  // for an integer count (read_encoder_value), within one count of the true angle (offsets = reference).
  const float p1 = get_f32_le(&r[1]);
  const float p2 = get_f32_le(&r[5]);
  EXPECT_NEAR(p1, th2, kCountDeg);
  EXPECT_NEAR(p2, th1, kCountDeg);
  for (const float v : {p1, p2}) {
    const double count = v * 2440.0 / 360.0;
    EXPECT_NEAR(count, std::round(count), 1e-3);
    EXPECT_EQ(v, static_cast<float>(360.0 * std::round(count) / 2440.0f));
  }
  double a[4] = {};
  ASSERT_EQ(decode_reply(BoardLayout::haply_gen3(), r.data(), 9, a), ReplyStatus::Ok);
  EXPECT_NEAR(a[0], th1, kCountDeg);
  EXPECT_NEAR(a[1], th2, kCountDeg);
}

TEST(HapiEmulator, ExactReplyBytesAtAKnownPose) {
  // Pose chosen half-way between counter edges so the count is unambiguous: θ_h1 = 180° − 203.5 counts,
  // θ_h2 = 0° + 250.5 counts (one count = 360/2440°). Firmware, gen3 setup (offsets 180° and 0°):
  //   setup writes Enc->write(offset·(4880/2)/360): port 2 (encoder 1) 180·2440/360 = 1220, port 1 0;
  //   since then the counters moved by ⌊−203.5⌋ = −204 and ⌊250.5⌋ = 250 edges;
  //   read_encoder_value = 360.0·count/EncResolution → port 2: 360·1016/2440, port 1: 360·250/2440;
  //   read_states sends [id, port 1 float, port 2 float].
  const double th1 = 180.0 - 203.5 * kCountDeg;
  const double th2 = 0.0 + 250.5 * kCountDeg;
  Vec2 start;
  ASSERT_TRUE(forward_kinematics(geometry_of(HaplyMechanism{}), joints_from_haply_deg(th1, th2), &start));
  FirmwareEmulator e = make({}, start);
  ASSERT_EQ(e.handle_device_m(), start);  // inside the stop box, not clamped
  start_gen3(e);
  send(e, torque_pkt(0, 0));
  Bytes expected(9);
  expected[0] = 5;
  put_f32_le(static_cast<float>(360.0 * 250 / 2440.0f), &expected[1]);
  put_f32_le(static_cast<float>(360.0 * 1016 / 2440.0f), &expected[5]);
  EXPECT_EQ(drain(e), expected);
}

TEST(HapiEmulator, ReportedAnglesEqualTrueHaplyAnglesAcrossTheWorkspace) {
  const Vec2 starts[] = {kCenter, {0.05, -0.06}, {-0.05, -0.115}, {0.02, -0.12}, {-0.055, -0.055}};
  for (const Vec2 s : starts) {
    FirmwareEmulator e = make({}, s);
    start_gen3(e);
    send(e, torque_pkt(0, 0));
    const Bytes r = drain(e);
    double a[4] = {};
    ASSERT_EQ(decode_reply(BoardLayout::haply_gen3(), r.data(), static_cast<int>(r.size()), a), ReplyStatus::Ok);
    double th1 = 0, th2 = 0;
    e.true_haply_deg(&th1, &th2);
    EXPECT_NEAR(a[0], th1, kCountDeg) << s.x << ", " << s.y;
    EXPECT_NEAR(a[1], th2, kCountDeg) << s.x << ", " << s.y;
    // And the handle is where Haply's angles put it (our FK of the reported angles).
    Vec2 p;
    ASSERT_TRUE(forward_kinematics(geometry_of(HaplyMechanism{}), joints_from_haply_deg(a[0], a[1]), &p));
    EXPECT_LT(distance(p, e.handle_device_m()), 5e-4);
  }
}

TEST(HapiEmulator, CalibrationErrorAndWrongDirectionShowInTheAngles) {
  EmulatorParams p;
  p.calibration_error_deg[0] = 2.0;
  FirmwareEmulator e = make(p);
  BoardLayout l = BoardLayout::haply_gen3();
  l.encoders[1].direction = Rotation::CW;  // encoder 2 (port 1) declared against its wiring
  send(e, setup_pkt(l));
  send(e, torque_pkt(0, 0));
  const Bytes r = drain(e);
  double a[4] = {};
  ASSERT_EQ(decode_reply(l, r.data(), static_cast<int>(r.size()), a), ReplyStatus::Ok);
  double th1 = 0, th2 = 0;
  e.true_haply_deg(&th1, &th2);
  EXPECT_NEAR(a[0], th1 + 2.0, kCountDeg);
  EXPECT_NEAR(a[1], 0.0 - (th2 - 0.0), kCountDeg);  // offset 0 − (θ − reference 0)
}

TEST(HapiEmulator, ReplyOnlyAfterTorqueCommand) {
  FirmwareEmulator e = make();
  send(e, reset_pkt());
  EXPECT_EQ(e.output_pending(), 0);
  send(e, setup_pkt());
  EXPECT_EQ(e.output_pending(), 0);
  // An incomplete torque command waits for its last byte.
  Bytes t = torque_pkt(0, 0);
  e.receive(t.data(), 9);
  EXPECT_EQ(e.output_pending(), 0);
  EXPECT_EQ(e.torque_commands(), 0);
  e.receive(t.data() + 9, 1);
  EXPECT_EQ(e.output_pending(), 9);
  EXPECT_EQ(e.torque_commands(), 1);
}

TEST(HapiEmulator, WrongIdRepliesIdAloneAndReparsesTheFloats) {
  FirmwareEmulator e = make();
  start_gen3(e);
  // [0x02, 6, 8 zero bytes]: id 6 matches no actuator, so no float is read and the reply is [6]; the
  // eight zero bytes are then four reset commands [0x00, 0x00], which clear every assignment.
  Bytes wrong = torque_pkt(0, 0);
  wrong[1] = 6;
  send(e, wrong);
  EXPECT_EQ(drain(e), (Bytes{6}));
  EXPECT_EQ(e.input_pending(), 0);
  // Device 5 is unassigned now: its torque command reads no float either and replies [5] alone; its
  // zero floats are again executed as resets.
  send(e, torque_pkt(0, 0));
  EXPECT_EQ(drain(e), (Bytes{5}));
  // After a new setup the full reply is back.
  send(e, setup_pkt());
  send(e, torque_pkt(0, 0));
  EXPECT_EQ(drain(e).size(), 9u);
}

TEST(HapiEmulator, WrongIdFollowedByAValidCommandInOneWrite) {
  FirmwareEmulator e = make();
  start_gen3(e);
  Bytes b = {0x02, 0x07};
  const Bytes t = torque_pkt(0, 0);
  b.insert(b.end(), t.begin(), t.end());
  send(e, b);
  const Bytes r = drain(e);
  ASSERT_EQ(r.size(), 10u);
  EXPECT_EQ(r[0], 7);
  EXPECT_EQ(r[1], 5);
}

TEST(HapiEmulator, MotorDirectionsStoredByCountIndex) {
  // Only port 2 used, declared CCW: the firmware stores that byte in actuators[0] (port 1's slot), so
  // port 2 keeps its power-up direction 0 = CW, which matches its CW wiring: the torque is NOT inverted.
  BoardLayout l = BoardLayout::haply_gen3();
  l.actuator_count = 1;
  l.actuators[0] = {1, Rotation::CCW, 2};
  FirmwareEmulator e = make();
  send(e, setup_pkt(l));
  send(e, torque_pkt(0.05, 0, l));
  double h1 = 0, h2 = 0;
  e.applied_haply_torques_n_m(&h1, &h2);
  EXPECT_GT(h1, 0.0);  // port 2 → joint 1, positive
  EXPECT_NEAR(h1, 0.05, 0.123 / 1023);
  EXPECT_EQ(h2, 0.0);
  // With both ports declared, port 2's byte lands in its own slot and CCW inverts it.
  BoardLayout both = BoardLayout::haply_gen3();
  both.actuators[0].direction = Rotation::CCW;
  send(e, setup_pkt(both));
  send(e, torque_pkt(0.05, 0, both));
  e.applied_haply_torques_n_m(&h1, &h2);
  EXPECT_LT(h1, 0.0);
}

TEST(HapiEmulator, FirmwareClampsAndQuantisesTorque) {
  FirmwareEmulator e = make();
  start_gen3(e);
  send(e, torque_pkt(0.5, -0.06));
  double h1 = 0, h2 = 0;
  e.applied_haply_torques_n_m(&h1, &h2);
  EXPECT_DOUBLE_EQ(h1, 0.123);                                             // duty 1023
  EXPECT_DOUBLE_EQ(h2, -std::floor(1023 * 0.06f / 0.123) * 0.123 / 1023);  // duty ⌊1023·0.06/0.123⌋
}

TEST(HapiEmulator, StaysPutWithoutForces) {
  FirmwareEmulator e = make();
  start_gen3(e);
  const Vec2 p0 = e.handle_device_m();
  for (int i = 0; i < 200; ++i) send(e, torque_pkt(0, 0));
  EXPECT_EQ(e.handle_device_m(), p0);
  EXPECT_EQ(e.torque_commands(), 200);
  EXPECT_NEAR(e.time_s(), 0.2, 1e-12);
  EXPECT_EQ(drain(e).size(), 200u * 9);
}

TEST(HapiEmulator, TorqueMovesTheHandleAsTransposeJacobianPredicts) {
  const PantographGeometry g = geometry_of(HaplyMechanism{});
  const double cases[][2] = {{0.03, 0.0}, {0.0, 0.03}, {-0.02, 0.04}};
  for (const auto& c : cases) {
    FirmwareEmulator e = make();
    start_gen3(e);
    const Vec2 p0 = e.handle_device_m();
    double th1 = 0, th2 = 0;
    e.true_haply_deg(&th1, &th2);
    // Predicted force: F = J⁻ᵀ·τ with Haply torques (τ_h1 = c[0] on actuator 1, τ_h2 = c[1]) mapped to ours.
    JointAngles q;
    ASSERT_TRUE(inverse_kinematics(g, p0, &q));
    const Vec2 F = handle_force(jacobian(g, q), torques_from_haply(c[0], c[1]));
    for (int i = 0; i < 5; ++i) send(e, torque_pkt(c[0], c[1]));
    const Vec2 dp = e.handle_device_m() - p0;
    ASSERT_GT(length(dp), 1e-6);
    EXPECT_GT(dot(dp, F) / (length(dp) * length(F)), 0.999) << c[0] << ", " << c[1];
    // And Jᵀ: the joint with positive torque turns positively (virtual work: τ·Δθ = F·Δx > 0).
    double n1 = 0, n2 = 0;
    e.true_haply_deg(&n1, &n2);
    EXPECT_GT(c[0] * (n1 - th1) + c[1] * (n2 - th2), 0.0);
  }
}

TEST(HapiEmulator, HandForceIsApplied) {
  FirmwareEmulator e = make({}, kCenter, [](double, Vec2, Vec2) { return Vec2{0.5, 0.0}; });
  start_gen3(e);
  for (int i = 0; i < 20; ++i) send(e, torque_pkt(0, 0));
  EXPECT_GT(e.handle_device_m().x, kCenter.x + 1e-5);
  EXPECT_NEAR(e.handle_device_m().y, kCenter.y, 1e-12);
}

// ---- Faults --------------------------------------------------------------------------------------

TEST(HapiEmulatorFaults, Disconnect) {
  EmulatorParams p;
  p.faults.disconnect_at_s = 0.003;
  FirmwareEmulator e = make(p);
  start_gen3(e);
  for (int i = 0; i < 6; ++i) send(e, torque_pkt(0, 0));
  EXPECT_EQ(drain(e).size(), 2u * 9);  // replies at t = 1 ms and 2 ms only
  EXPECT_TRUE(e.disconnected());
  EXPECT_EQ(e.torque_commands(), 3);  // input ignored from then on
  send(e, setup_pkt());
  send(e, torque_pkt(0, 0));
  EXPECT_EQ(e.output_pending(), 0);
}

TEST(HapiEmulatorFaults, DropEvery) {
  EmulatorParams p;
  p.faults.drop_every = 3;
  FirmwareEmulator e = make(p);
  start_gen3(e);
  std::vector<std::size_t> sizes;
  for (int i = 0; i < 6; ++i) {
    send(e, torque_pkt(0, 0));
    sizes.push_back(drain(e).size());
  }
  EXPECT_EQ(sizes, (std::vector<std::size_t>{9, 9, 0, 9, 9, 0}));
  EXPECT_EQ(e.replies_produced(), 6);
}

TEST(HapiEmulatorFaults, WrongIdEvery) {
  EmulatorParams p;
  p.faults.wrong_id_every = 2;
  FirmwareEmulator e = make(p);
  start_gen3(e);
  std::vector<int> ids;
  for (int i = 0; i < 4; ++i) {
    send(e, torque_pkt(0, 0));
    const Bytes r = drain(e);
    ASSERT_EQ(r.size(), 9u);
    ids.push_back(r[0]);
  }
  EXPECT_EQ(ids, (std::vector<int>{5, 6, 5, 6}));
}

TEST(HapiEmulatorFaults, GarbageEveryIsDeterministicAndDesyncs) {
  EmulatorParams p;
  p.faults.garbage_every = 2;
  p.faults.seed = 42;
  FirmwareEmulator a = make(p);
  FirmwareEmulator b = make(p);
  FirmwareEmulator clean = make();
  for (FirmwareEmulator* e : {&a, &b, &clean}) start_gen3(*e);
  std::vector<std::size_t> sizes;
  Bytes all_a, all_b, all_clean;
  for (int i = 0; i < 6; ++i) {
    for (FirmwareEmulator* e : {&a, &b, &clean}) send(*e, torque_pkt(0, 0));
    const Bytes ra = drain(a);
    sizes.push_back(ra.size());
    all_a.insert(all_a.end(), ra.begin(), ra.end());
    const Bytes rb = drain(b);
    all_b.insert(all_b.end(), rb.begin(), rb.end());
    const Bytes rc = drain(clean);
    all_clean.insert(all_clean.end(), rc.begin(), rc.end());
  }
  EXPECT_EQ(all_a, all_b);
  for (int i = 0; i < 6; ++i) {
    if (i % 2 == 0) {
      EXPECT_EQ(sizes[i], 9u);
    } else {
      EXPECT_GE(sizes[i], 10u);
      EXPECT_LE(sizes[i], 17u);
    }
  }
  // The garbage precedes the reply: the reply itself is intact at the end of the chunk.
  EXPECT_EQ(Bytes(all_a.end() - 9, all_a.end()), Bytes(all_clean.end() - 9, all_clean.end()));
  EXPECT_NE(all_a.size(), all_clean.size());
}

TEST(HapiEmulatorFaults, StallWithholdsThenBursts) {
  EmulatorParams p;
  p.faults.stall_at_s = 0.003;
  p.faults.stall_s = 0.003;
  FirmwareEmulator e = make(p);
  start_gen3(e);
  std::vector<std::size_t> sizes;
  for (int i = 0; i < 8; ++i) {
    send(e, torque_pkt(0, 0));
    sizes.push_back(drain(e).size());
  }
  // Commands ending at t = 3, 4, 5 ms are withheld; the one ending at 6 ms releases all four replies.
  EXPECT_EQ(sizes, (std::vector<std::size_t>{9, 9, 0, 0, 0, 36, 9, 9}));
}

// ---- The pty server ------------------------------------------------------------------------------

/// Reads until `want` bytes arrived or `timeout` passed (poll-based; the timeout only bounds failure).
Bytes read_some(int fd, std::size_t want, std::chrono::milliseconds timeout) {
  Bytes got;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (got.size() < want) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd pfd{fd, POLLIN, 0};
    if (::poll(&pfd, 1, static_cast<int>(left.count())) <= 0) break;
    std::uint8_t buf[256];
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) break;
    got.insert(got.end(), buf, buf + n);
  }
  return got;
}

TEST(PtyEmulator, AnswersSetupAndTorqueOnTheSlaveTty) {
  FirmwareEmulator e = make();
  PtyEmulator pty(e);
  const std::string path = pty.device_path();
  ASSERT_FALSE(path.empty());
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY);
  ASSERT_GE(fd, 0) << path;
  termios tio{};
  ASSERT_EQ(tcgetattr(fd, &tio), 0);
  cfmakeraw(&tio);
  ASSERT_EQ(tcsetattr(fd, TCSANOW, &tio), 0);

  Bytes out = reset_pkt();
  for (const Bytes& b : {setup_pkt(), torque_pkt(0, 0)}) out.insert(out.end(), b.begin(), b.end());
  ASSERT_EQ(::write(fd, out.data(), out.size()), static_cast<ssize_t>(out.size()));
  const Bytes r = read_some(fd, 9, std::chrono::milliseconds(2000));
  ASSERT_EQ(r.size(), 9u);
  double a[4] = {};
  EXPECT_EQ(decode_reply(BoardLayout::haply_gen3(), r.data(), 9, a), ReplyStatus::Ok);
  double th1 = 0, th2 = 0;
  pty.with_emulator([&](FirmwareEmulator& em) {
    em.true_haply_deg(&th1, &th2);
    EXPECT_EQ(em.torque_commands(), 1);
  });
  EXPECT_NEAR(a[0], th1, kCountDeg);
  EXPECT_NEAR(a[1], th2, kCountDeg);

  // A second command gets a second reply (bytes with 0x0A/0x0D values pass untranslated in raw mode).
  const Bytes t = torque_pkt(0.01, -0.01);
  ASSERT_EQ(::write(fd, t.data(), t.size()), static_cast<ssize_t>(t.size()));
  EXPECT_EQ(read_some(fd, 9, std::chrono::milliseconds(2000)).size(), 9u);
  ::close(fd);
  pty.stop();
}

}  // namespace
}  // namespace hk::hapi
