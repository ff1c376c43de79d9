// Hand-speed aware contact: strokes at 2 m/s at the handle (2 mm per 1 kHz tick)
// across thin curves and into acute corners (10°, 30°) never tunnel, frictionless and with Coulomb
// friction (the proxy then sticks and slides in its friction cone, each slide a collision-checked move):
// every sub-move of the proxy is checked with the independent orientation predicate, and the proxy ends
// every stroke on its own side.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "curves.hpp"
#include "haptics/contact.hpp"

namespace hk {
namespace {

constexpr double kSpeed = 2.0;     // [m/s]
constexpr double kPeriod = 0.001;  // [s]

// The contact parameters the strokes run with: frictionless (the solver's default) and with friction.
std::vector<ContactParams> contact_variants() {
  ContactParams with_friction;
  with_friction.static_friction = 0.4;
  with_friction.dynamic_friction = 0.3;
  return {ContactParams{}, with_friction};
}

// Drives the handle along straight strokes a → b at kSpeed; returns crossings of the level's polylines.
int stroke_crossings(const Scene& sc, int level, const std::vector<std::pair<Vec2, Vec2>>& strokes, int* contact_ticks,
                     const ContactParams& params) {
  ContactSolver solver(sc, params);
  int crossings = 0;
  ContactOutput out;
  for (const auto& [a, b] : strokes) {
    solver.reset(a, level);
    Vec2 prev = solver.proxy();
    const int n = std::max(1, static_cast<int>(std::ceil(length(b - a) / (kSpeed * kPeriod))));
    for (int i = 1; i <= n; ++i) {
      ContactInput in;
      in.handle_m = lerp(a, b, static_cast<double>(i) / n);
      in.handle_velocity_m_per_s = (b - a) * (1.0 / (n * kPeriod));
      in.level = level;
      solver.update(in, out);
      EXPECT_EQ(out.path_m[0], prev);
      for (int m = 1; m < out.path_count; ++m)
        crossings += test::count_crossings(sc, out.path_m[m - 1], out.path_m[m], level);
      *contact_ticks += out.state != ContactState::Free;
      prev = out.proxy_m;
    }
  }
  return crossings;
}

// Strokes through the point c from every direction, 30 mm long, plus seeded random ones near it.
std::vector<std::pair<Vec2, Vec2>> strokes_through(Vec2 c, std::uint32_t seed) {
  std::vector<std::pair<Vec2, Vec2>> s;
  for (int k = 0; k < 72; ++k) {
    const double a = 2 * M_PI * k / 72;
    const Vec2 d{std::cos(a), std::sin(a)};
    s.push_back({c - 0.015 * d, c + 0.015 * d});
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> off(-0.004, 0.004), ang(0, 2 * M_PI);
  for (int k = 0; k < 200; ++k) {
    const Vec2 p = c + Vec2{off(rng), off(rng)};
    const double a = ang(rng);
    const Vec2 d{std::cos(a), std::sin(a)};
    s.push_back({p - 0.02 * d, p + 0.02 * d});
  }
  return s;
}

TEST(FastStrokes, ThinCurvesAt2MetresPerSecond) {
  // A single open line, and the two edges of a thin line 0.2 mm apart (what Canny gives for a pen stroke).
  Polyline single, upper, lower;
  for (int i = 0; i <= 40; ++i) {
    const double x = -0.02 + 0.001 * i, y = 0.002 * std::sin(x * 300);
    single.points_m.push_back({x, y});
    upper.points_m.push_back({x, y + 0.0001});
    lower.points_m.push_back({x, y - 0.0001});
  }
  for (const std::vector<Polyline>& curves : {std::vector<Polyline>{single}, std::vector<Polyline>{upper, lower}}) {
    const Scene sc = Scene::build(curves, 3);
    for (const ContactParams& cp : contact_variants()) {
      for (int level : {0, 1, 2}) {
        int contacts = 0;
        EXPECT_EQ(stroke_crossings(sc, level, strokes_through({0.0, 0.0}, 7), &contacts, cp), 0)
            << curves.size() << " curves, level " << level << ", μ_s " << cp.static_friction;
        EXPECT_GT(contacts, 1000) << "the strokes must actually hit the curve";
      }
    }
  }
}

TEST(FastStrokes, AcuteCornersAt2MetresPerSecond) {
  for (double deg : {10.0, 30.0}) {
    const double half = deg / 2 * M_PI / 180;
    // An open V with its apex at the origin, and a closed sliver triangle with the same apex angle.
    Polyline v, sliver;
    v.points_m = {
        {-0.03 * std::cos(half), 0.03 * std::sin(half)}, {0.0, 0.0}, {-0.03 * std::cos(half), -0.03 * std::sin(half)}};
    sliver.closed = true;
    sliver.points_m = {
        {0.0, 0.0}, {-0.03 * std::cos(half), 0.03 * std::sin(half)}, {-0.03 * std::cos(half), -0.03 * std::sin(half)}};
    for (const Polyline& p : {v, sliver}) {
      const Scene sc = Scene::build({p}, 0);
      for (const ContactParams& cp : contact_variants()) {
        int contacts = 0;
        // Through the apex, and through a point 5 mm inside the wedge where the walls are 0.9–2.6 mm apart.
        EXPECT_EQ(stroke_crossings(sc, 0, strokes_through({0.0, 0.0}, 11), &contacts, cp), 0)
            << deg << "° apex, μ_s " << cp.static_friction;
        EXPECT_EQ(stroke_crossings(sc, 0, strokes_through({-0.005, 0.0}, 13), &contacts, cp), 0)
            << deg << "° inside, μ_s " << cp.static_friction;
        EXPECT_GT(contacts, 200) << "the strokes must actually hit the walls";
      }
    }
  }
}

}  // namespace
}  // namespace hk
