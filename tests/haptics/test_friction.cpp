// Friction on the god-object: the proxy sticks inside the static cone and slides on the
// dynamic cone (golden offsets μ_s·d and μ_d·d from Coulomb's law), re-sticks only when the hand stops,
// is frictionless with both coefficients 0, and never creates energy round a closed loop.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "curves.hpp"
#include "haptics/contact.hpp"

using namespace hk;

namespace {

constexpr double kK = 800.0;      // stiffness [N/m]
constexpr double kDepth = 0.002;  // press depth [m]
constexpr double kDt = 0.001;     // tick [s]

ContactParams friction(double mu_s, double mu_d) {
  ContactParams p;
  p.stiffness_n_per_m = kK;
  p.max_force_n = 10.0;  // no clamp in these tests
  p.static_friction = mu_s;
  p.dynamic_friction = mu_d;
  return p;
}

/// One tick with the handle at h, moving at v [m/s].
ContactOutput tick(ContactSolver& s, Vec2 h, Vec2 v) {
  ContactInput in;
  in.handle_m = h;
  in.handle_velocity_m_per_s = v;
  in.level = 0;
  ContactOutput out;
  s.update(in, out);
  return out;
}

/// A long horizontal wall y = 0, the solver's proxy pressed into it from above to depth kDepth at x = 0.
struct PressedWall {
  Scene scene;
  ContactSolver solver;
  explicit PressedWall(const ContactParams& p) : scene(make()), solver(scene, p) {
    solver.reset({0.0, 0.01}, 0);
    for (int i = 0; i <= 100; ++i) tick(solver, {0.0, 0.01 - (0.01 + kDepth) * i / 100.0}, {0.0, -0.012});
    for (int i = 0; i < 10; ++i) tick(solver, {0.0, -kDepth}, {0.0, 0.0});  // at rest on the wall
  }
  static Scene make() {
    Polyline wall;
    wall.points_m = {{-0.06, 0.0}, {0.06, 0.0}};
    return Scene::build({wall}, 2);
  }
};

}  // namespace

TEST(Friction, StaticConeHoldsThenDynamicConeTrails) {
  const double mu_s = 0.4, mu_d = 0.3;
  PressedWall w(friction(mu_s, mu_d));
  ASSERT_EQ(w.solver.state(), ContactState::Edge);
  const double x0 = w.solver.proxy().x;
  ASSERT_NEAR(x0, 0.0, 1e-9);
  // Slide the handle right at 10 mm/s, 10 µm per tick.
  const double v = 0.01;
  double first_slip_x = -1.0;
  for (int i = 1; i <= 300; ++i) {
    const double hx = v * kDt * i;
    const ContactOutput out = tick(w.solver, {hx, -kDepth}, {v, 0.0});
    ASSERT_EQ(out.state, ContactState::Edge) << i;
    if (hx < mu_s * kDepth - 1e-9) {
      // Inside the static cone: the proxy does not move and the tangential force grows with the offset.
      EXPECT_EQ(out.proxy_m.x, x0) << "hand at " << hx;
      EXPECT_TRUE(out.sticking);
      EXPECT_NEAR(out.force_n.x, -kK * hx, 1e-9);
    } else if (first_slip_x < 0.0 && out.proxy_m.x != x0) {
      first_slip_x = hx;
    }
    if (hx > mu_s * kDepth + 0.0005) {
      // Sliding: the proxy trails by μ_d·d, so tangential / normal force = μ_d (Coulomb).
      EXPECT_NEAR(hx - out.proxy_m.x, mu_d * kDepth, 1e-9);
      // (the normal force is measured from the proxy, which rests a skin off the wall)
      EXPECT_NEAR(-out.force_n.x / out.force_n.y, mu_d * kDepth / (kDepth + ContactParams{}.skin_m), 1e-9);
      EXPECT_FALSE(out.sticking);
    }
  }
  // It breaks away exactly where the static cone ends (within one 10 µm step).
  EXPECT_NEAR(first_slip_x, mu_s * kDepth, 1e-5 + 1e-12);
}

TEST(Friction, StoppedHandSticksAgainAndMustTravelBothConesBack) {
  const double mu_s = 0.4, mu_d = 0.3;
  PressedWall w(friction(mu_s, mu_d));
  double hx = 0.0;
  for (int i = 0; i < 200; ++i) tick(w.solver, {hx += 1e-5, -kDepth}, {0.01, 0.0});  // slide 2 mm right
  const double px = w.solver.proxy().x;
  ASSERT_NEAR(hx - px, mu_d * kDepth, 1e-9);
  for (int i = 0; i < 20; ++i) tick(w.solver, {hx, -kDepth}, {0.0, 0.0});  // the hand stops
  // Coming back, the proxy stays until the offset has crossed zero and reached the static cone on the other
  // side: the hand travels μ_d·d + μ_s·d = 1.4 mm.
  double moved_at = -1.0;
  for (int i = 1; i <= 250 && moved_at < 0.0; ++i) {
    const double back = 1e-5 * i;
    const ContactOutput out = tick(w.solver, {hx - back, -kDepth}, {-0.01, 0.0});
    if (out.proxy_m.x != px) moved_at = back;
  }
  EXPECT_NEAR(moved_at, (mu_d + mu_s) * kDepth, 1e-5 + 1e-12);
}

TEST(Friction, HandStillMovingDoesNotStickSlip) {
  // A press that deepens while the hand slides would re-stick a proxy with a plain two-cone rule and each
  // break-away would jump the force by (μ_s − μ_d)·k·d; with the stick band the force stays smooth.
  const double mu_s = 0.6, mu_d = 0.3;
  PressedWall w(friction(mu_s, mu_d));
  double prev_fx = 0.0;
  double max_jump = 0.0;
  for (int i = 1; i <= 2000; ++i) {
    const double hx = 2e-5 * i;                                      // 20 mm/s
    const double depth = kDepth * (1.0 + 0.3 * std::sin(i * 0.05));  // pressing harder and softer
    const ContactOutput out = tick(w.solver, {hx, -depth}, {0.02, 0.0});
    if (i > 200) max_jump = std::max(max_jump, std::fabs(out.force_n.x - prev_fx));
    prev_fx = out.force_n.x;
  }
  // Smooth: per tick the force changes by at most k·(hand step + μ_d·depth change) ≈ 0.016 + 0.005 N,
  // far below a stick-slip break-away of (μ_s − μ_d)·k·d = 0.48 N.
  EXPECT_LT(max_jump, 0.03);
}

TEST(Friction, BothZeroIsFrictionless) {
  PressedWall w(friction(0.0, 0.0));
  for (int i = 1; i <= 100; ++i) {
    const double hx = 3e-5 * i;
    const ContactOutput out = tick(w.solver, {hx, -kDepth}, {0.03, 0.0});
    EXPECT_NEAR(out.proxy_m.x, hx, 1e-12);  // the proxy sits over the handle: no tangential force
    EXPECT_NEAR(out.force_n.x, 0.0, 1e-9);
    EXPECT_FALSE(out.sticking);
  }
}

namespace {

/// Work the hand does on the device round a closed loop about a circle of radius R [J]: the handle starts
/// outside, presses in to radius R − depth, goes once round, and returns to its start. Trapezoidal rule on
/// the force along the path (the sampled force is piecewise constant; the trapezoid is the path integral
/// of the spring, which is conservative, so only dissipation remains).
double loop_work(const ContactParams& p, double depth, double* proxy_path_out) {
  const double R = 0.02;
  Polyline circle;
  circle.closed = true;
  for (int k = 0; k < 400; ++k)
    circle.points_m.push_back({R * std::cos(2 * M_PI * k / 400), R * std::sin(2 * M_PI * k / 400)});
  const Scene sc = Scene::build({circle}, 3);
  ContactSolver s(sc, p);
  std::vector<Vec2> path;
  const Vec2 start{0.0, R + 0.01};
  for (int i = 0; i <= 200; ++i) path.push_back(lerp(start, {0.0, R - depth}, i / 200.0));
  for (int i = 1; i <= 8000; ++i) {
    const double th = M_PI / 2 + 2 * M_PI * i / 8000;
    path.push_back({(R - depth) * std::cos(th), (R - depth) * std::sin(th)});
  }
  for (int i = 1; i <= 200; ++i) path.push_back(lerp({0.0, R - depth}, start, i / 200.0));
  s.reset(start, 0);
  double work = 0.0, proxy_path = 0.0;
  Vec2 prev_f, prev_h = start, prev_p = s.proxy();
  for (std::size_t i = 0; i < path.size(); ++i) {
    const Vec2 v = i ? (1.0 / kDt) * (path[i] - path[i - 1]) : Vec2{};
    const ContactOutput out = tick(s, path[i], v);
    if (i) work -= dot(0.5 * (out.force_n + prev_f), path[i] - prev_h);
    if (out.state != ContactState::Free) proxy_path += distance(out.proxy_m, prev_p);  // slid along the wall
    prev_f = out.force_n;
    prev_h = path[i];
    prev_p = out.proxy_m;
  }
  if (proxy_path_out) *proxy_path_out = proxy_path;
  return work;
}

}  // namespace

TEST(Friction, ClosedLoopRoundACurveCreatesNoEnergy) {
  const double depth = 0.001;
  double proxy_path = 0.0;
  const double w_friction = loop_work(friction(0.4, 0.3), depth, &proxy_path);
  const double w_free = loop_work(friction(0.0, 0.0), depth, nullptr);
  // Work done by the hand is never negative: the device gave back no more than it took.
  EXPECT_GE(w_free, -1e-6) << "frictionless loop";
  EXPECT_GE(w_friction, 0.0);
  // With friction the hand pays Coulomb's μ_d · N · (distance slid), N = k·depth on the wall (golden,
  // independent of the solver: 0.3 · 0.8 N · 2π · 20 mm ≈ 30 mJ).
  const double expected = 0.3 * kK * depth * proxy_path;
  EXPECT_NEAR(w_friction, expected, 0.1 * expected);
  // Frictionless, the loop costs next to nothing.
  EXPECT_LT(std::fabs(w_free), 0.05 * expected);
}

TEST(Friction, DefaultsKeepAHandPushingSlightlyAskewOnTheCurve) {
  // Seed §5: frictionless walls "cause the handle to easily slip off the curve being explored". A hand
  // pressing on a circle 15° off its normal: without friction the proxy slides round the curve; with the
  // coefficients the settings ship ([haptics] static_friction 0.4, dynamic_friction 0.3: μ_s = 0.4 holds
  // pushes up to atan 0.4 ≈ 22° off the normal) it stays put.
  Polyline circle;
  circle.closed = true;
  const double R = 0.02;
  for (int k = 0; k < 256; ++k)
    circle.points_m.push_back({R * std::cos(2 * M_PI * k / 256), R * std::sin(2 * M_PI * k / 256)});
  const Scene sc = Scene::build({circle}, 3);
  const double tilt = 15.0 * M_PI / 180.0;
  double slide[2] = {0.0, 0.0};
  int i = 0;
  for (const auto& [mu_s, mu_d] : {std::pair{0.0, 0.0}, std::pair{0.4, 0.3}}) {
    ContactSolver s(sc, friction(mu_s, mu_d));
    const Vec2 top{0.0, R + 0.005};
    s.reset(top, 0);
    // Come straight down onto the top of the circle, then push 1.5 mm in along a line 15° off the normal.
    for (int k = 0; k <= 100; ++k) tick(s, lerp(top, {0.0, R - 0.0001}, k / 100.0), {0.0, -0.05});
    const Vec2 touch = s.proxy();
    const Vec2 push{std::sin(tilt), -std::cos(tilt)};
    for (int k = 1; k <= 300; ++k) tick(s, Vec2{0.0, R - 0.0001} + (0.0015 * k / 300.0) * push, 0.005 * push);
    slide[i++] = distance(s.proxy(), touch);
  }
  EXPECT_GT(slide[0], 0.0003) << "frictionless: the proxy slides away from where the hand pushes";
  EXPECT_LT(slide[1], 1e-5) << "with the shipped friction it holds";
}
