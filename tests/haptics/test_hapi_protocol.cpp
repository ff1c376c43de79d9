/// @file test_hapi_protocol.cpp
/// hAPI packet encoding (hapi_protocol.hpp) and the Haply mechanism in our frames (haply_mechanism.hpp).
/// Golden bytes are derived by hand below from the firmware (HaplyHaptics/Haply-Arduino-Firmware-Versions
/// Haply_M0_Firmware_V0_3.h) and host (HaplyHaptics/Haply-API-Java Device.java, Board.java) sources.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include "haptics/device.hpp"
#include "haptics/hapi_protocol.hpp"
#include "kinematics/haply_mechanism.hpp"
#include "kinematics/pantograph.hpp"

namespace hk::hapi {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes setup_bytes(const BoardLayout& l) {
  std::uint8_t buf[kMaxPacketBytes];
  const int n = encode_setup(l, buf, kMaxPacketBytes);
  EXPECT_GT(n, 0);
  return Bytes(buf, buf + (n > 0 ? n : 0));
}

// Float constants used below, by hand (IEEE-754 binary32, sign | 8-bit exponent (bias 127) | 23-bit
// fraction), then written little-endian (Board.java FloatToBytes: segments[0] = low byte):
//   0.0f      = 0x00000000                                        → 00 00 00 00
//   180.0f    = 1.40625·2^7:  exp 134 = 0x86, fraction .40625·2^23 = 0x340000 → 0x43340000 → 00 00 34 43
//   4880.0f   = 1.19140625·2^12: exp 139 = 0x8B, fraction 0x188000 → 0x45988000   → 00 80 98 45
//   0.0625f   = 2^-4:  exp 123 = 0x7B → 0x3D800000                                → 00 00 80 3D
//   -0.03125f = -2^-5: sign 1, exp 122 = 0x7A → 0xBD000000                        → 00 00 00 BD
TEST(HapiProtocol, FloatBytesAreLittleEndianBinary32) {
  std::uint8_t b[4];
  put_f32_le(180.0f, b);
  EXPECT_EQ(Bytes(b, b + 4), (Bytes{0x00, 0x00, 0x34, 0x43}));
  put_f32_le(4880.0f, b);
  EXPECT_EQ(Bytes(b, b + 4), (Bytes{0x00, 0x80, 0x98, 0x45}));
  put_f32_le(-0.03125f, b);
  EXPECT_EQ(Bytes(b, b + 4), (Bytes{0x00, 0x00, 0x00, 0xBD}));
  const std::uint8_t c[4] = {0x00, 0x00, 0x80, 0x3D};
  EXPECT_EQ(get_f32_le(c), 0.0625f);
}

TEST(HapiProtocol, Gen3SetupGoldenBytes) {
  // Device.java device_set_parameters: for each port i = 0..3 the mask is shifted right and bit 3 set
  // when the port is used, so port p ends at bit p − 1. Gen3 uses ports 1 and 2 → mask 0b0011 = 0x03,
  // for both actuators and encoders. Direction bytes and encoder float pairs follow in port order:
  //   port 1 = actuator 2 (CW = 0), encoder 2 (CCW = 1, offset 0°, 4880);
  //   port 2 = actuator 1 (CW = 0), encoder 1 (CCW = 1, offset 180°, 4880).
  // Then sensor count 0 and pwm count 0 (none declared). Board.transmit puts [type = 1, id = 5] first.
  const Bytes expected = {
      0x01, 0x05,              // setup, device 5
      0x03, 0x00, 0x00,        // motor mask, dir port 1 (act 2 CW), dir port 2 (act 1 CW)
      0x03, 0x01, 0x01,        // encoder mask, dir port 1 (enc 2 CCW), dir port 2 (enc 1 CCW)
      0x00,                    // sensors
      0x00,                    // pwms
      0x00, 0x00, 0x00, 0x00,  // port 1 (encoder 2) offset 0.0f
      0x00, 0x80, 0x98, 0x45,  // port 1 resolution 4880.0f
      0x00, 0x00, 0x34, 0x43,  // port 2 (encoder 1) offset 180.0f
      0x00, 0x80, 0x98, 0x45,  // port 2 resolution 4880.0f
  };
  EXPECT_EQ(setup_bytes(BoardLayout::haply_gen3()), expected);
  std::uint8_t small[25];
  EXPECT_EQ(encode_setup(BoardLayout::haply_gen3(), small, 25), -1);
}

TEST(HapiProtocol, ResetBytes) {
  std::uint8_t b[2];
  EXPECT_EQ(encode_reset(5, b), 2);
  EXPECT_EQ(Bytes(b, b + 2), (Bytes{0x00, 0x05}));
}

TEST(HapiProtocol, SetupMaskForSparsePorts) {
  // One actuator on port 3, encoders on ports 4 and 1 (declared out of order): motor mask 0b0100,
  // encoder mask 0b1001; encoder directions and floats in port order (port 1 first).
  BoardLayout l;
  l.actuator_count = 1;
  l.actuators[0] = {1, Rotation::CCW, 3};
  l.encoder_count = 2;
  l.encoders[0] = {1, Rotation::CW, 180.0, 4880.0, 4};
  l.encoders[1] = {2, Rotation::CCW, 0.0, 4880.0, 1};
  validate(l);
  const Bytes b = setup_bytes(l);
  ASSERT_EQ(b.size(), 2u + 2 + 3 + 1 + 1 + 16);
  EXPECT_EQ(b[2], 0x04);
  EXPECT_EQ(b[3], 0x01);  // CCW
  EXPECT_EQ(b[4], 0x09);
  EXPECT_EQ(b[5], 0x01);                   // port 1: encoder 2 CCW
  EXPECT_EQ(b[6], 0x00);                   // port 4: encoder 1 CW
  EXPECT_EQ(get_f32_le(&b[9]), 0.0f);      // port 1 offset (after 7 sensor, 8 pwm counts)
  EXPECT_EQ(get_f32_le(&b[17]), 180.0f);   // port 4 offset
  EXPECT_EQ(get_f32_le(&b[21]), 4880.0f);  // port 4 resolution
}

TEST(HapiProtocol, Gen3TorqueGoldenBytes) {
  // Device.java device_write_torques: torques of the actuators in port order; gen3 port 1 carries
  // actuator 2, port 2 actuator 1 → [0x02, 5, f32(τ_act2), f32(τ_act1)], no pwm bytes.
  const double tau[4] = {0.0625, -0.03125, 0, 0};
  std::uint8_t b[kMaxPacketBytes];
  const BoardLayout l = BoardLayout::haply_gen3();
  ASSERT_EQ(torque_packet_length(l), 10);
  ASSERT_EQ(encode_torques(l, tau, 0.123, b, kMaxPacketBytes), 10);
  EXPECT_EQ(Bytes(b, b + 10), (Bytes{0x02, 0x05, 0x00, 0x00, 0x00, 0xBD, 0x00, 0x00, 0x80, 0x3D}));
  EXPECT_EQ(encode_torques(l, tau, 0.123, b, 9), -1);
}

TEST(HapiProtocol, TorquesClampedAndNonFiniteZeroed) {
  const BoardLayout l = BoardLayout::haply_gen3();
  const double tau[4] = {1.0, std::numeric_limits<double>::quiet_NaN(), 0, 0};
  std::uint8_t b[kMaxPacketBytes];
  ASSERT_EQ(encode_torques(l, tau, 0.123, b, kMaxPacketBytes), 10);
  EXPECT_EQ(get_f32_le(b + 2), 0.0f);    // actuator 2 (NaN) on port 1
  EXPECT_EQ(get_f32_le(b + 6), 0.123f);  // actuator 1 clamped
  const double neg[4] = {-5.0, std::numeric_limits<double>::infinity(), 0, 0};
  ASSERT_EQ(encode_torques(l, neg, 0.1, b, kMaxPacketBytes), 10);
  EXPECT_EQ(get_f32_le(b + 2), 0.0f);
  EXPECT_EQ(get_f32_le(b + 6), -0.1f);
}

TEST(HapiProtocol, ReplyDecodedByEncoderIndexAcrossCrossedPorts) {
  // Firmware read_states: [id, encoder floats in port order]; port 1 = encoder 2, port 2 = encoder 1.
  const BoardLayout l = BoardLayout::haply_gen3();
  ASSERT_EQ(reply_length(l), 9);
  std::uint8_t r[9] = {0x05};
  put_f32_le(12.5f, r + 1);   // port 1 → encoder 2
  put_f32_le(170.0f, r + 5);  // port 2 → encoder 1
  double a[4] = {-1, -1, -1, -1};
  ASSERT_EQ(decode_reply(l, r, 9, a), ReplyStatus::Ok);
  EXPECT_EQ(a[0], 170.0);
  EXPECT_EQ(a[1], 12.5);
  EXPECT_EQ(a[2], -1);

  double b[4] = {-1, -1, -1, -1};
  EXPECT_EQ(decode_reply(l, r, 8, b), ReplyStatus::Short);
  r[0] = 6;
  EXPECT_EQ(decode_reply(l, r, 9, b), ReplyStatus::WrongId);
  r[0] = 5;
  put_f32_le(std::numeric_limits<float>::quiet_NaN(), r + 1);
  EXPECT_EQ(decode_reply(l, r, 9, b), ReplyStatus::NonFinite);
  put_f32_le(2e5f, r + 1);
  EXPECT_EQ(decode_reply(l, r, 9, b), ReplyStatus::OutOfRange);
  EXPECT_EQ(b[0], -1);  // untouched unless Ok
}

TEST(HapiProtocol, ValidateRejectsBadLayouts) {
  EXPECT_NO_THROW(validate(BoardLayout::haply_gen3()));
  auto expect_bad = [](BoardLayout l, const char* field) {
    try {
      validate(l);
      ADD_FAILURE() << "accepted a layout with bad " << field;
    } catch (const hk::DeviceError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  BoardLayout l = BoardLayout::haply_gen3();
  l.actuators[1].port = 2;
  expect_bad(l, "actuators[1].port");
  l = BoardLayout::haply_gen3();
  l.encoders[0].index = 2;
  expect_bad(l, "encoders[1].index duplicates");  // encoders[1] (index 2) now duplicates encoders[0]
  l = BoardLayout::haply_gen3();
  l.encoders[0].resolution = 0;
  expect_bad(l, "resolution");
  l.encoders[0].resolution = std::numeric_limits<double>::infinity();
  expect_bad(l, "resolution");
  l = BoardLayout::haply_gen3();
  l.actuators[0].port = 5;
  expect_bad(l, "actuators[0].port");
  l = BoardLayout::haply_gen3();
  l.actuators[0].index = 0;
  expect_bad(l, "actuators[0].index");
  l = BoardLayout::haply_gen3();
  l.actuator_count = 5;
  expect_bad(l, "actuator_count");
  l = BoardLayout::haply_gen3();
  l.encoder_count = -1;
  expect_bad(l, "encoder_count");
  l = BoardLayout::haply_gen3();
  l.device_id = 0;
  expect_bad(l, "device_id");
}

// ---- The mechanism -------------------------------------------------------------------------------

constexpr double kPi = std::numbers::pi;

/// Haply's forward kinematics, re-derived from the geometry of Pantograph.java (hardwareVersion 3) in
/// Haply's frame: motor 1 at (0, 0), motor 2 at (d, 0), elbows A = l·(cos θ1, sin θ1),
/// B = (d, 0) + l·(cos θ2, sin θ2); the handle is the intersection of the circles of radius L about A
/// and B that lies to the LEFT of A → B (their `lx = −…·h1y, ly = +…·h1x`: +y_h for the usual pose).
Vec2 haply_fk(double th1_deg, double th2_deg, double l = 0.07, double L = 0.09, double d = 0.038) {
  const double t1 = th1_deg * kPi / 180.0;
  const double t2 = th2_deg * kPi / 180.0;
  const Vec2 A{l * std::cos(t1), l * std::sin(t1)};
  const Vec2 B{d + l * std::cos(t2), l * std::sin(t2)};
  const Vec2 AB = B - A;
  const double c = length(AB);
  const double along = c / 2.0;  // equal distal links: the foot of the handle is the mid-point
  const double h = std::sqrt(L * L - along * along);
  const Vec2 u = (1.0 / c) * AB;
  return A + along * u + h * Vec2{-u.y, u.x};
}

TEST(HaplyMechanism, GeometryMatchesPantographJava) {
  const PantographGeometry g = geometry_of(HaplyMechanism{});
  EXPECT_DOUBLE_EQ(g.motor_half_spacing_m, 0.019);
  EXPECT_EQ(g.base_m, (Vec2{0, 0}));
  EXPECT_DOUBLE_EQ(g.proximal_m, 0.07);
  EXPECT_DOUBLE_EQ(g.distal_m, 0.09);
}

TEST(HaplyMechanism, OurForwardKinematicsEqualsHaplysRotated) {
  const HaplyMechanism m;
  const PantographGeometry g = geometry_of(m);
  const double poses[][2] = {{150, 30}, {120, 60}, {170, 10}, {135, 20}, {160, 45}, {110, -5}, {185, 70}};
  for (const auto& p : poses) {
    const Vec2 h = haply_fk(p[0], p[1]);
    const Vec2 expected{0.019 - h.x, -h.y};
    Vec2 ours{NAN, NAN};
    ASSERT_TRUE(forward_kinematics(g, joints_from_haply_deg(p[0], p[1]), &ours)) << p[0] << ", " << p[1];
    EXPECT_NEAR(ours.x, expected.x, 1e-9) << p[0] << ", " << p[1];
    EXPECT_NEAR(ours.y, expected.y, 1e-9) << p[0] << ", " << p[1];
    EXPECT_LT(ours.y, 0.0);
    const Vec2 back = device_from_haply_m(m, h);
    EXPECT_NEAR(back.x, expected.x, 1e-15);
    const Vec2 fwd = haply_from_device_m(m, expected);
    EXPECT_NEAR(fwd.x, h.x, 1e-15);
    EXPECT_NEAR(fwd.y, h.y, 1e-15);
  }
}

TEST(HaplyMechanism, AngleMapsRoundTripAndWrap) {
  const JointAngles q = joints_from_haply_deg(180.0, 0.0);
  EXPECT_NEAR(q.theta2_rad, 0.0, 1e-12);  // Haply motor 1 at 180° points to our +x: right motor
  EXPECT_NEAR(q.theta1_rad, kPi, 1e-12);  // Haply motor 2 at 0° points to our −x: left motor
  const JointAngles q2 = joints_from_haply_deg(150.0, 30.0);
  EXPECT_GE(q2.theta1_rad, 0.0);
  EXPECT_LT(q2.theta1_rad, 2 * kPi);
  EXPECT_GE(q2.theta2_rad, -kPi);
  EXPECT_LT(q2.theta2_rad, kPi);
  double a = 0, b = 0;
  haply_deg_from_joints(q2, &a, &b);
  EXPECT_NEAR(a, 150.0, 1e-9);
  EXPECT_NEAR(b, 30.0, 1e-9);
  haply_deg_from_joints(joints_from_haply_deg(-170.0, 200.0), &a, &b);
  EXPECT_NEAR(a, 190.0, 1e-9);
  EXPECT_NEAR(b, -160.0, 1e-9);
}

TEST(HaplyMechanism, TransposeJacobianTorquesEqualHaplys) {
  // Haply's Jacobian by central differences of its own FK (in its frame), τ_h = J_hᵀ·F_h, against
  // our τ = Jᵀ·F mapped with haply_torques_from. F_h is F rotated by π.
  const HaplyMechanism m;
  const PantographGeometry g = geometry_of(m);
  const double poses[][2] = {{150, 30}, {120, 60}, {165, 40}};
  const Vec2 forces[] = {{1.0, 0.0}, {0.0, 1.0}, {-0.7, 0.4}};
  for (const auto& p : poses) {
    const double hd = 1e-6;  // [deg]
    const Vec2 d1 = (1.0 / (2 * hd * kPi / 180)) * (haply_fk(p[0] + hd, p[1]) - haply_fk(p[0] - hd, p[1]));
    const Vec2 d2 = (1.0 / (2 * hd * kPi / 180)) * (haply_fk(p[0], p[1] + hd) - haply_fk(p[0], p[1] - hd));
    const Mat2 J = jacobian(g, joints_from_haply_deg(p[0], p[1]));
    for (const Vec2 F : forces) {
      const Vec2 Fh = -F;
      const double th1 = dot(d1, Fh);
      const double th2 = dot(d2, Fh);
      double h1 = 0, h2 = 0;
      haply_torques_from(joint_torques(J, F), &h1, &h2);
      EXPECT_NEAR(h1, th1, 1e-7) << p[0] << ", " << p[1];
      EXPECT_NEAR(h2, th2, 1e-7) << p[0] << ", " << p[1];
      const Torques back = torques_from_haply(h1, h2);
      EXPECT_EQ(back.tau1_n_m, joint_torques(J, F).tau1_n_m);
    }
  }
}

}  // namespace
}  // namespace hk::hapi
