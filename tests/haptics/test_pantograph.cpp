/// @file test_pantograph.cpp
/// Five-bar kinematics and statics (pantograph.hpp), the simulated pantograph and the model hand
/// (sim_pantograph.hpp). Expected values come from independent computations (finite differences,
/// virtual work, closed-form steady states), never from a previous run.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "haptics/sim_pantograph.hpp"
#include "hk/error.hpp"
#include "kinematics/pantograph.hpp"

namespace hk {
namespace {

constexpr double kPi = std::numbers::pi;
// The usable rectangle of DESIGN.md (0.14 m × 0.09 m) and the stop box 1 cm outside it.
constexpr double kHalfW = 0.07;
constexpr double kHalfH = 0.045;
constexpr double kStop = 0.01;

/// Points of a jittered grid over [−hw, hw] × [−hh, hh]: one uniformly random point per cell, with
/// a fixed seed, plus the four corners (the worst places for reach and singularity).
std::vector<Vec2> jittered_grid(double hw, double hh, int nx, int ny, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec2> pts;
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      pts.push_back({-hw + 2.0 * hw * (i + u(rng)) / nx, -hh + 2.0 * hh * (j + u(rng)) / ny});
    }
  }
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) pts.push_back({sx * hw, sy * hh});
  }
  return pts;
}

Vec2 fk_or_die(const PantographGeometry& g, JointAngles q) {
  Vec2 p{NAN, NAN};
  EXPECT_TRUE(forward_kinematics(g, q, &p)) << q.theta1_rad << ", " << q.theta2_rad;
  return p;
}

JointAngles ik_or_die(const PantographGeometry& g, Vec2 p) {
  JointAngles q{NAN, NAN};
  EXPECT_TRUE(inverse_kinematics(g, p, &q)) << p.x << ", " << p.y;
  return q;
}

double max_abs(const Mat2& m) { return std::max({std::abs(m.a11), std::abs(m.a12), std::abs(m.a21), std::abs(m.a22)}); }

/// Singular values of a 2×2 matrix (largest first).
std::pair<double, double> singular_values(const Mat2& m) {
  const double f = m.a11 * m.a11 + m.a12 * m.a12 + m.a21 * m.a21 + m.a22 * m.a22;
  const double d = std::abs(det(m));
  const double s1 = std::sqrt(0.5 * (f + std::sqrt(std::max(0.0, f * f - 4.0 * d * d))));
  return {s1, s1 > 0.0 ? d / s1 : 0.0};
}

// ---------------------------------------------------------------------------------------------
// Kinematics

TEST(Pantograph, FkIkRoundTripOverRectangleAndStops) {
  const PantographGeometry g;
  for (const Vec2 p : jittered_grid(kHalfW + kStop, kHalfH + kStop, 40, 30, 20240611u)) {
    const JointAngles q = ik_or_die(g, p);
    const Vec2 back = fk_or_die(g, q);
    EXPECT_LT(distance(p, back), 1e-12) << "at (" << p.x << ", " << p.y << ")";

    // The documented branch: elbows outward, handle below the base and right of elbow1 → elbow2.
    const Elbows e = elbow_positions(g, q);
    EXPECT_LT(cross(p - motor1_position(g), e.elbow1_m - motor1_position(g)), 0.0);
    EXPECT_GT(cross(p - motor2_position(g), e.elbow2_m - motor2_position(g)), 0.0);
    EXPECT_LT(cross(e.elbow2_m - e.elbow1_m, p - e.elbow1_m), 0.0);
    EXPECT_LT(p.y, g.base_m.y);
    // Link lengths hold (an independent check of both directions).
    EXPECT_NEAR(distance(e.elbow1_m, p), g.distal_m, 1e-12);
    EXPECT_NEAR(distance(e.elbow2_m, p), g.distal_m, 1e-12);
    // Documented angle ranges.
    EXPECT_GE(q.theta1_rad, 0.0);
    EXPECT_LT(q.theta1_rad, 2.0 * kPi);
    EXPECT_GE(q.theta2_rad, -kPi);
    EXPECT_LT(q.theta2_rad, kPi);
  }
}

TEST(Pantograph, IkOfFkRecoversAngles) {
  const PantographGeometry g;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> d(-0.05, 0.05);
  for (const Vec2 p : jittered_grid(kHalfW, kHalfH, 10, 8, 99u)) {
    // Perturb the angles of a known-good configuration, go forward, come back.
    const JointAngles q0 = ik_or_die(g, p);
    const JointAngles q{q0.theta1_rad + d(rng), q0.theta2_rad + d(rng)};
    const JointAngles q2 = ik_or_die(g, fk_or_die(g, q));
    EXPECT_NEAR(q2.theta1_rad, q.theta1_rad, 1e-9);
    EXPECT_NEAR(q2.theta2_rad, q.theta2_rad, 1e-9);
  }
}

TEST(Pantograph, FailuresAreReported) {
  const PantographGeometry g;
  JointAngles q{1.0, 2.0};
  EXPECT_FALSE(inverse_kinematics(g, {0.0, -1.0}, &q)) << "beyond L1 + L2";
  EXPECT_FALSE(inverse_kinematics(g, motor1_position(g), &q)) << "inside |L1 - L2|";
  EXPECT_FALSE(inverse_kinematics(g, {NAN, 0.0}, &q));
  EXPECT_EQ(q.theta1_rad, 1.0) << "output untouched on failure";

  PantographGeometry short_distal = g;
  short_distal.distal_m = 0.15;  // elbows pointing straight out are 0.32 m apart > 2·0.15 m
  Vec2 p{5.0, 5.0};
  EXPECT_FALSE(forward_kinematics(short_distal, {kPi, 0.0}, &p));
  EXPECT_EQ(p.x, 5.0) << "output untouched on failure";
  const Mat2 J = jacobian(short_distal, {kPi, 0.0});
  EXPECT_EQ(max_abs(J), 0.0) << "zero Jacobian where FK fails";
}

TEST(Pantograph, JacobianMatchesCentralDifferences) {
  const PantographGeometry g;
  const double h = 1e-6;  // rad; truncation O(h²) ~ 1e-12, round-off ~ 1e-16·0.2 m / h ~ 2e-11 m/rad
  for (const Vec2 p : jittered_grid(kHalfW + kStop, kHalfH + kStop, 15, 10, 4242u)) {
    const JointAngles q = ik_or_die(g, p);
    const Mat2 J = jacobian(g, q);
    const Vec2 d1 = (1.0 / (2.0 * h)) *
                    (fk_or_die(g, {q.theta1_rad + h, q.theta2_rad}) - fk_or_die(g, {q.theta1_rad - h, q.theta2_rad}));
    const Vec2 d2 = (1.0 / (2.0 * h)) *
                    (fk_or_die(g, {q.theta1_rad, q.theta2_rad + h}) - fk_or_die(g, {q.theta1_rad, q.theta2_rad - h}));
    const Mat2 fd{d1.x, d2.x, d1.y, d2.y};
    const double tol = 1e-6 * max_abs(fd);
    EXPECT_NEAR(J.a11, fd.a11, tol);
    EXPECT_NEAR(J.a12, fd.a12, tol);
    EXPECT_NEAR(J.a21, fd.a21, tol);
    EXPECT_NEAR(J.a22, fd.a22, tol);
  }
}

TEST(Pantograph, JointTorquesEqualVirtualWork) {
  // τ_i is the work the handle force does per unit rotation of joint i: τ_i = F·∂x/∂θi, measured here
  // from FK displacements alone (no Jacobian), and checked as τ·δθ = F·δx for a random small δθ.
  const PantographGeometry g;
  std::mt19937_64 rng(31337);
  std::uniform_real_distribution<double> uf(-3.0, 3.0);
  std::uniform_real_distribution<double> ua(-1.0, 1.0);
  const double h = 1e-7;
  for (const Vec2 p : jittered_grid(kHalfW, kHalfH, 12, 8, 555u)) {
    const Vec2 force{uf(rng), uf(rng)};
    const JointAngles q = ik_or_die(g, p);
    const Torques tau = joint_torques(jacobian(g, q), force);

    const JointAngles dq{h * ua(rng), h * ua(rng)};
    const Vec2 dx = 0.5 * (fk_or_die(g, {q.theta1_rad + dq.theta1_rad, q.theta2_rad + dq.theta2_rad}) -
                           fk_or_die(g, {q.theta1_rad - dq.theta1_rad, q.theta2_rad - dq.theta2_rad}));
    const double work_joints = tau.tau1_n_m * dq.theta1_rad + tau.tau2_n_m * dq.theta2_rad;
    const double work_handle = dot(force, dx);
    const double scale = length(force) * (std::abs(dq.theta1_rad) + std::abs(dq.theta2_rad)) * 0.2;  // ‖J‖ ≤ 0.2 m
    EXPECT_NEAR(work_joints, work_handle, 1e-6 * scale);
  }
}

TEST(Pantograph, HandForceInvertsJointTorques) {
  const PantographGeometry g;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-4.0, 4.0);
  for (const Vec2 p : jittered_grid(kHalfW, kHalfH, 8, 6, 77u)) {
    const Mat2 J = jacobian(g, ik_or_die(g, p));
    const Vec2 f{u(rng), u(rng)};
    const Vec2 back = handle_force(J, joint_torques(J, f));
    EXPECT_NEAR(back.x, f.x, 1e-12 * 4.0);
    EXPECT_NEAR(back.y, f.y, 1e-12 * 4.0);
    const Torques tau{0.1 * u(rng), 0.1 * u(rng)};
    const Torques tau2 = joint_torques(J, handle_force(J, tau));
    EXPECT_NEAR(tau2.tau1_n_m, tau.tau1_n_m, 1e-12);
    EXPECT_NEAR(tau2.tau2_n_m, tau.tau2_n_m, 1e-12);
  }
  // Singular or invalid J: documented zero force.
  EXPECT_EQ(handle_force(Mat2{1.0, 2.0, 2.0, 4.0}, {0.1, 0.2}), (Vec2{}));
  EXPECT_EQ(handle_force(Mat2{}, {0.1, 0.2}), (Vec2{}));
  EXPECT_EQ(handle_force(Mat2{NAN, 0.0, 0.0, 1.0}, {0.1, 0.2}), (Vec2{}));
}

TEST(Pantograph, ReachableRectangleAwayFromSingularities) {
  // Requirements on the default geometry over the usable rectangle and the stop box:
  //  - serial singularity (a chain stretched or folded, det J → 0): |det J| ≥ kMinDetJ;
  //  - parallel singularity (distal links collinear, ‖J‖ → ∞): largest singular value ≤ kMaxSigma and
  //    an angle between the distal links inside [kMinAngle, 180° − kMinAngle].
  constexpr double kMinDetJ = 0.005;  // m²/rad²
  constexpr double kMaxSigma = 0.25;  // m/rad: 1 count of a 16384-count encoder ≤ 0.1 mm
  constexpr double kMinAngle = 30.0 * kPi / 180.0;
  const PantographGeometry g;
  for (const double margin : {0.0, kStop}) {
    double det_lo = 1e9, det_hi = 0.0, s_lo = 1e9, s_hi = 0.0, ang_lo = 10.0, ang_hi = 0.0;
    const double hw = kHalfW + margin, hh = kHalfH + margin;
    const int nx = 2 * static_cast<int>(std::lround(hw / 0.001)), ny = 2 * static_cast<int>(std::lround(hh / 0.001));
    for (int i = 0; i <= nx; ++i) {
      for (int j = 0; j <= ny; ++j) {  // a 1 mm grid, edges included
        const Vec2 p{-hw + 2.0 * hw * i / nx, -hh + 2.0 * hh * j / ny};
        JointAngles q;
        ASSERT_TRUE(inverse_kinematics(g, p, &q)) << "unreachable (" << p.x << ", " << p.y << ")";
        const Mat2 J = jacobian(g, q);
        const double d = std::abs(det(J));
        const auto [s1, s2] = singular_values(J);
        const Elbows e = elbow_positions(g, q);
        const double ang = std::acos(dot(e.elbow1_m - p, e.elbow2_m - p) / (g.distal_m * g.distal_m));
        det_lo = std::min(det_lo, d), det_hi = std::max(det_hi, d);
        s_lo = std::min(s_lo, s2), s_hi = std::max(s_hi, s1);
        ang_lo = std::min(ang_lo, ang), ang_hi = std::max(ang_hi, ang);
      }
    }
    EXPECT_GE(det_lo, kMinDetJ) << "margin " << margin;
    EXPECT_LE(s_hi, kMaxSigma) << "margin " << margin;
    EXPECT_GE(ang_lo, kMinAngle) << "margin " << margin;
    EXPECT_LE(ang_hi, kPi - kMinAngle) << "margin " << margin;
    std::printf(
        "[ info ] margin %.3f m: |det J| in [%.4g, %.4g] m^2/rad^2, sigma(J) in [%.4g, %.4g] m/rad, "
        "distal angle in [%.1f, %.1f] deg\n",
        margin, det_lo, det_hi, s_lo, s_hi, ang_lo * 180 / kPi, ang_hi * 180 / kPi);
  }
}

// ---------------------------------------------------------------------------------------------
// Simulated pantograph

double kinetic_energy(const SimulatedPantograph& s) {
  return 0.5 * s.params().handle_mass_kg * length_sq(s.velocity_m_per_s());
}

TEST(SimPantograph, StatusAndTime) {
  SimulatedPantograph sim({}, {0.0, 0.0});
  EXPECT_EQ(sim.status(), DeviceStatus::Closed);
  EXPECT_EQ(sim.read().status, DeviceStatus::Closed);
  sim.open();
  EXPECT_EQ(sim.read().status, DeviceStatus::Ok);
  for (int i = 0; i < 250; ++i) sim.step(1e-3, {});
  EXPECT_EQ(sim.read().time_ns, 250'000'000);
  sim.step(-1.0, {});
  sim.step(NAN, {1.0, 1.0});
  EXPECT_EQ(sim.read().time_ns, 250'000'000) << "invalid dt does nothing";
  EXPECT_EQ(sim.true_position_m(), (Vec2{0.0, 0.0}));
  sim.close();
  EXPECT_EQ(sim.status(), DeviceStatus::Closed);
  EXPECT_FALSE(sim.name().empty());
}

TEST(SimPantograph, DampingDissipatesEnergyMonotonically) {
  SimulatedPantograph sim({}, {-0.02, -0.01});
  sim.open();
  for (int i = 0; i < 30; ++i) sim.step(1e-3, {0.6, 0.3});  // throw the handle
  double e = kinetic_energy(sim);
  const double e0 = e;
  ASSERT_GT(e0, 0.0);
  for (int i = 0; i < 400; ++i) {  // 10 time constants m/b = 0.04 s
    sim.step(1e-3, {});
    const double e_next = kinetic_energy(sim);
    ASSERT_LT(e_next, e) << "tick " << i;
    e = e_next;
  }
  EXPECT_LT(e, 1e-6 * e0);
  EXPECT_EQ(sim.applied_force_n(), (Vec2{})) << "no force commanded";
}

TEST(SimPantograph, ConstantForceGivesSteadyVelocityForceOverDamping) {
  for (const double b : {2.0, 5.0}) {
    SimPantographParams params;
    params.handle_damping_n_s_per_m = b;
    SimulatedPantograph sim(params, {-0.05, -0.02});
    sim.open();
    const Vec2 f{0.15, 0.05};
    const double tau_s = params.handle_mass_kg / b;
    const int ticks = static_cast<int>(std::ceil(12.0 * tau_s / 1e-3));  // e^-12 of the transient left
    for (int i = 0; i < ticks; ++i) sim.step(1e-3, f);
    const Vec2 v = sim.velocity_m_per_s();
    EXPECT_NEAR(v.x, f.x / b, 1e-4 * f.x / b) << "b = " << b;
    EXPECT_NEAR(v.y, f.y / b, 1e-4 * f.x / b) << "b = " << b;
    // Still inside the rectangle: the stops played no part.
    EXPECT_LT(sim.true_position_m().x, kHalfW);
  }
}

TEST(SimPantograph, MotorForceMovesHandleLikeAHandForce) {
  // Below the torque limit the motors deliver the commanded force: same steady velocity F/b.
  SimulatedPantograph sim({}, {0.03, 0.02});
  sim.open();
  const Vec2 f{-0.2, -0.1};
  sim.write_force(f);
  for (int i = 0; i < 500; ++i) sim.step(1e-3, {});
  EXPECT_NEAR(sim.applied_force_n().x, f.x, 1e-12);
  EXPECT_NEAR(sim.applied_force_n().y, f.y, 1e-12);
  EXPECT_NEAR(sim.velocity_m_per_s().x, f.x / 2.0, 1e-4);
  EXPECT_NEAR(sim.velocity_m_per_s().y, f.y / 2.0, 1e-4);
}

TEST(SimPantograph, TorqueLimitShapesHugeForce) {
  const SimPantographParams params;
  const PantographGeometry& g = params.geometry;
  for (const Vec2 start : jittered_grid(kHalfW, kHalfH, 5, 4, 8u)) {
    for (const Vec2 huge : {Vec2{1000.0, -700.0}, Vec2{0.0, 1e6}, Vec2{-3e4, 1.0}}) {
      SimulatedPantograph sim(params, start);
      sim.open();
      sim.write_force(huge);
      sim.step(1e-3, {});
      // Torques the applied force needs at the configuration it was computed at (the start).
      const Torques tau = joint_torques(jacobian(g, ik_or_die(g, start)), sim.applied_force_n());
      const double lim = params.max_torque_n_m;
      EXPECT_LE(std::abs(tau.tau1_n_m), lim * (1.0 + 1e-9));
      EXPECT_LE(std::abs(tau.tau2_n_m), lim * (1.0 + 1e-9));
      EXPECT_NEAR(std::max(std::abs(tau.tau1_n_m), std::abs(tau.tau2_n_m)), lim, 1e-9) << "saturated";
      EXPECT_NEAR(tau.tau1_n_m, sim.applied_torques_n_m().tau1_n_m, 1e-9);
      EXPECT_NEAR(tau.tau2_n_m, sim.applied_torques_n_m().tau2_n_m, 1e-9);
      // Per-motor clamping keeps each torque's sign: no motor ever pushes against the command.
      const Torques wanted = joint_torques(jacobian(g, ik_or_die(g, start)), huge);
      EXPECT_GE(tau.tau1_n_m * wanted.tau1_n_m, 0.0);
      EXPECT_GE(tau.tau2_n_m * wanted.tau2_n_m, 0.0);
      EXPECT_LT(length(sim.applied_force_n()), 20.0);
    }
  }
}

TEST(SimPantograph, NoMotorForceUnlessOpen) {
  SimulatedPantograph sim({}, {0.0, 0.0});
  sim.write_force({1.0, 0.0});
  sim.step(1e-3, {});
  EXPECT_EQ(sim.applied_force_n(), (Vec2{}));
  sim.open();
  sim.write_force({NAN, 1.0});
  sim.step(1e-3, {});
  EXPECT_EQ(sim.applied_force_n(), (Vec2{})) << "non-finite command stored as zero";
  sim.write_force({1.0, 0.0});
  sim.close();
  sim.step(1e-3, {});
  EXPECT_EQ(sim.applied_force_n(), (Vec2{}));
}

TEST(SimPantograph, EncoderQuantisationWithinHandleResolution) {
  // Each angle is off by at most half a count q/2, so the handle is off by at most
  // (‖∂x/∂θ1‖ + ‖∂x/∂θ2‖)·q/2 (to first order; second-order terms are ~ q² · 0.2 m ≈ 3e-8 m).
  for (const int counts : {16384, 1 << 20}) {
    SimPantographParams params;
    params.encoder_counts_per_rev = counts;
    const double q = 2.0 * kPi / counts;
    double worst_ratio = 0.0, worst_err = 0.0, worst_bound = 0.0;
    for (const Vec2 p : jittered_grid(kHalfW, kHalfH, 20, 15, 2718u)) {
      SimulatedPantograph sim(params, p);
      sim.open();
      const DeviceSample s = sim.read();
      const Mat2 J = jacobian(params.geometry, ik_or_die(params.geometry, p));
      const double bound = (std::hypot(J.a11, J.a21) + std::hypot(J.a12, J.a22)) * 0.5 * q;
      const double err = distance(s.handle_m, sim.true_position_m());
      EXPECT_LE(err, bound * 1.001 + 1e-12) << "at (" << p.x << ", " << p.y << ")";
      worst_ratio = std::max(worst_ratio, err / bound);
      worst_err = std::max(worst_err, err);
      worst_bound = std::max(worst_bound, bound);
    }
    // Quantisation is really applied: some sample lands well away from the true position.
    EXPECT_GT(worst_ratio, 0.3) << counts << " counts";
    std::printf("[ info ] %d counts/rev: worst handle error %.3g um, bound up to %.3g um\n", counts, worst_err * 1e6,
                worst_bound * 1e6);
  }
}

TEST(SimPantograph, MechanicalStopHoldsHandle) {
  SimulatedPantograph sim({}, {0.0, 0.0});
  sim.open();
  for (int i = 0; i < 2000; ++i) sim.step(1e-3, {2.0, -1.0});
  const Vec2 p = sim.true_position_m();
  EXPECT_DOUBLE_EQ(p.x, kHalfW + kStop);
  EXPECT_DOUBLE_EQ(p.y, -(kHalfH + kStop));
  EXPECT_EQ(sim.velocity_m_per_s(), (Vec2{}));
  // Pulling back leaves the stop at once.
  sim.step(1e-3, {-1.0, 0.0});
  EXPECT_LT(sim.velocity_m_per_s().x, 0.0);
  EXPECT_LT(sim.true_position_m().x, kHalfW + kStop);
  // A start outside the stops is clamped in.
  SimulatedPantograph outside({}, {1.0, 0.0});
  EXPECT_DOUBLE_EQ(outside.true_position_m().x, kHalfW + kStop);
}

TEST(SimPantograph, RejectsBadParameters) {
  SimPantographParams p;
  p.handle_mass_kg = 0.0;
  EXPECT_THROW(SimulatedPantograph(p, {}), hk::ArgumentError);
  p = {};
  p.substeps = 0;
  EXPECT_THROW(SimulatedPantograph(p, {}), hk::ArgumentError);
  p = {};
  p.encoder_counts_per_rev = 0;
  EXPECT_THROW(SimulatedPantograph(p, {}), hk::ArgumentError);
  p = {};
  p.max_torque_n_m = NAN;
  EXPECT_THROW(SimulatedPantograph(p, {}), hk::ArgumentError);
  p = {};
  p.geometry.proximal_m = 0.05;  // too short to reach the far corners of the stop box
  EXPECT_THROW(SimulatedPantograph(p, {}), hk::ArgumentError);
  EXPECT_THROW(SimulatedPantograph({}, {NAN, 0.0}), hk::ArgumentError);
}

// ---------------------------------------------------------------------------------------------
// Model hand

TEST(ModelHand, SpringDamperBelowTheClamp) {
  const ModelHandParams p;
  const Vec2 target{0.01, 0.0}, handle{0.005, 0.002}, v{0.02, -0.01};
  const Vec2 f = model_hand_force(p, target, handle, v);
  EXPECT_NEAR(f.x, p.stiffness_n_per_m * (target.x - handle.x) - p.damping_n_s_per_m * v.x, 1e-12);
  EXPECT_NEAR(f.y, p.stiffness_n_per_m * (target.y - handle.y) - p.damping_n_s_per_m * v.y, 1e-12);
  EXPECT_LT(length(f), p.max_force_n);
}

TEST(ModelHand, ClampKeepsDirection) {
  const ModelHandParams p;
  const Vec2 target{0.05, 0.03}, handle{-0.04, -0.02}, v{0.1, 0.0};
  const Vec2 raw = p.stiffness_n_per_m * (target - handle) - p.damping_n_s_per_m * v;
  ASSERT_GT(length(raw), p.max_force_n);
  const Vec2 f = model_hand_force(p, target, handle, v);
  EXPECT_NEAR(length(f), p.max_force_n, 1e-12);
  EXPECT_NEAR(cross(f, raw), 0.0, 1e-12);
  EXPECT_GT(dot(f, raw), 0.0);
  EXPECT_EQ(model_hand_force(p, {NAN, 0.0}, handle, v), (Vec2{}));
}

TEST(ModelHand, HandFollowsTargetThroughTheSimulation) {
  // Closed loop: the model hand drags the handle to a fixed target; it settles there.
  SimulatedPantograph sim({}, {-0.03, 0.01});
  sim.open();
  const ModelHandParams hand;
  const Vec2 target{0.02, -0.015};
  for (int i = 0; i < 3000; ++i) {
    sim.step(1e-3, model_hand_force(hand, target, sim.read().handle_m, sim.velocity_m_per_s()));
  }
  // The hand spring sees the quantised position: the rest point is within one encoder resolution.
  EXPECT_LT(distance(sim.true_position_m(), target), 1e-4);
}

}  // namespace
}  // namespace hk
