// God-object contact solver: the proxy never crosses a wall (independent crossing test), convex corners
// release, concave corners hold, force = stiffness · |proxy − handle| up to the clamp, walls from both sides.
#include <gtest/gtest.h>

#include <random>

#include "curves.hpp"
#include "haptics/contact.hpp"

using namespace hk;

namespace {

using test::square;

struct Trajectory {
  std::vector<Vec2> proxies;
  std::vector<ContactState> states;
  std::vector<Vec2> forces;
  std::vector<Vec2> handles;
};

Trajectory drive(ContactSolver& solver, const std::vector<Vec2>& handle_path, int level) {
  Trajectory r;
  ContactOutput out;
  for (const Vec2& h : handle_path) {
    ContactInput in;
    in.handle_m = h;
    in.level = level;
    solver.update(in, out);
    r.proxies.push_back(out.proxy_m);
    r.states.push_back(out.state);
    r.forces.push_back(out.force_n);
    r.handles.push_back(h);
  }
  return r;
}

std::vector<Vec2> line_path(Vec2 a, Vec2 b, int n) {
  std::vector<Vec2> p;
  for (int i = 0; i <= n; ++i) p.push_back(lerp(a, b, static_cast<double>(i) / n));
  return p;
}

}  // namespace

TEST(Contact, PushIntoWallStopsProxyOnItsSide) {
  const Scene sc = Scene::build({square(0.02)}, 0);
  ContactParams cp;
  ContactSolver solver(sc, cp);
  solver.reset({0.0, 0.03}, 0);  // above the top edge
  const Trajectory r = drive(solver, line_path({0.0, 0.03}, {0.0, 0.017}, 100), 0);
  EXPECT_EQ(r.states.back(), ContactState::Edge);
  EXPECT_GT(r.proxies.back().y, 0.02);          // outside
  EXPECT_NEAR(r.proxies.back().y, 0.02, 1e-5);  // on the wall
  EXPECT_NEAR(r.proxies.back().x, 0.0, 1e-9);
  // Force pushes the handle back out: stiffness · penetration.
  EXPECT_NEAR(r.forces.back().y, cp.stiffness_n_per_m * (r.proxies.back().y - 0.017), 1e-9);
}

TEST(Contact, WallsWorkFromInsideToo) {
  const Scene sc = Scene::build({square(0.02)}, 0);
  ContactSolver solver(sc, ContactParams{});
  solver.reset({0.0, 0.0}, 0);  // inside
  const Trajectory r = drive(solver, line_path({0.0, 0.0}, {0.0, 0.023}, 100), 0);
  EXPECT_EQ(r.states.back(), ContactState::Edge);
  EXPECT_LT(r.proxies.back().y, 0.02);
  EXPECT_LT(r.forces.back().y, 0.0);
}

TEST(Contact, SlidingFollowsTangentialMotion) {
  const Scene sc = Scene::build({square(0.02)}, 0);
  ContactSolver solver(sc, ContactParams{});
  solver.reset({-0.01, 0.03}, 0);
  auto path = line_path({-0.01, 0.03}, {-0.01, 0.019}, 50);
  const auto slide = line_path({-0.01, 0.019}, {0.01, 0.019}, 200);
  path.insert(path.end(), slide.begin(), slide.end());
  const Trajectory r = drive(solver, path, 0);
  EXPECT_EQ(r.states.back(), ContactState::Edge);
  EXPECT_NEAR(r.proxies.back().x, 0.01, 1e-9);  // frictionless: proxy under the handle's tangential position
}

TEST(Contact, ConvexCornerReleasesTheProxy) {
  const Scene sc = Scene::build({square(0.02)}, 0);
  ContactSolver solver(sc, ContactParams{});
  solver.reset({0.0, 0.03}, 0);
  // Press on the top edge, then slide right past the top-right corner while still pressing down.
  auto path = line_path({0.0, 0.03}, {0.0, 0.019}, 50);
  const auto slide = line_path({0.0, 0.019}, {0.03, 0.019}, 300);
  path.insert(path.end(), slide.begin(), slide.end());
  const Trajectory r = drive(solver, path, 0);
  for (ContactState s : r.states) EXPECT_NE(s, ContactState::Vertex);  // never held at a convex corner
  EXPECT_EQ(r.states.back(), ContactState::Free);
  EXPECT_NEAR(distance(r.proxies.back(), r.handles.back()), 0.0, 1e-12);
}

TEST(Contact, ConcaveCornerHoldsInVertexContact) {
  const Scene sc = Scene::build({square(0.02)}, 0);
  ContactSolver solver(sc, ContactParams{});
  solver.reset({0.0, 0.0}, 0);  // inside: every corner is concave
  const Trajectory r = drive(solver, line_path({0.0, 0.0}, {0.023, 0.024}, 300), 0);
  EXPECT_EQ(r.states.back(), ContactState::Vertex);
  EXPECT_NEAR(r.proxies.back().x, 0.02, 1e-5);
  EXPECT_NEAR(r.proxies.back().y, 0.02, 1e-5);
  // Pulled back along one edge (away from the other wall) it leaves the corner for that edge.
  ContactOutput out;
  ContactInput in;
  in.handle_m = {0.01, 0.021};  // behind the top edge, away from the right edge
  solver.update(in, out);
  EXPECT_EQ(out.state, ContactState::Edge);
  EXPECT_NEAR(out.proxy_m.x, 0.01, 1e-9);
}

TEST(Contact, ForceIsStiffnessTimesSeparationUpToClamp) {
  std::mt19937 rng(30);
  const Scene sc = Scene::build({test::random_blob(rng, {0, 0}, 0.02, 300), square(0.035)}, 4);
  ContactParams cp;
  cp.stiffness_n_per_m = 900.0;
  cp.max_force_n = 3.0;
  ContactSolver solver(sc, cp);
  solver.reset({0.05, 0.0}, 1);
  std::uniform_real_distribution<double> step(-0.0006, 0.0006);
  Vec2 h{0.05, 0.0};
  ContactOutput out;
  int clamped = 0, contact = 0;
  for (int i = 0; i < 20000; ++i) {
    // Drift towards the centre so the handle keeps meeting walls.
    h = {std::clamp(h.x + step(rng) - 0.00002 * h.x / 0.05, -0.07, 0.07), std::clamp(h.y + step(rng), -0.045, 0.045)};
    ContactInput in;
    in.handle_m = h;
    in.level = 1;
    solver.update(in, out);
    const double expected = std::min(cp.stiffness_n_per_m * distance(out.proxy_m, h), cp.max_force_n);
    ASSERT_NEAR(length(out.force_n), expected, 1e-9);
    if (out.state != ContactState::Free) ++contact;
    if (expected == cp.max_force_n) ++clamped;
    // Force points from the handle to the proxy.
    if (length(out.force_n) > 1e-9) {
      ASSERT_GT(dot(out.force_n, out.proxy_m - h), 0.0);
    }
  }
  EXPECT_GT(contact, 1000);
  EXPECT_GT(clamped, 10);
}

TEST(Contact, ProxyNeverCrossesOnRandomWalks) {
  std::mt19937 rng(31);
  std::vector<Polyline> curves;
  for (int i = 0; i < 6; ++i)
    curves.push_back(test::random_blob(rng, {-0.04 + 0.016 * i, 0.005 * (i % 3)}, 0.012, 120));
  for (int i = 0; i < 4; ++i) curves.push_back(test::random_stroke(rng, {-0.05 + 0.03 * i, -0.03}, 0.0004, 150));
  curves.push_back(test::staircase_circle({0, 0}, 0.03, 0.00025));
  struct Case {
    int level;
    int max_box_tests;
  };
  for (const Case cs : {Case{0, 0}, Case{1, 0}, Case{3, 0}, Case{1, 3}, Case{0, 12}}) {
    const int level = cs.level;
    const Scene sc = Scene::build(curves, 5);
    ContactSolver solver(sc, ContactParams{});
    Vec2 h{0.0, 0.044};
    solver.reset(h, level);
    Vec2 prev = solver.proxy();
    std::uniform_real_distribution<double> step(-0.0008, 0.0008);
    int crossings = 0, contacts = 0, vertices = 0;
    ContactOutput out;
    for (int i = 0; i < 15000; ++i) {
      h = {std::clamp(h.x + step(rng), -0.07, 0.07), std::clamp(h.y + step(rng), -0.045, 0.045)};
      ContactInput in;
      in.handle_m = h;
      in.level = level;
      in.budget.max_box_tests = cs.max_box_tests;  // starved budgets: the anytime path must stay safe too
      solver.update(in, out);
      // Every move of the tick, checked with the independent predicate.
      ASSERT_EQ(out.path_m[0], prev);
      for (int m = 1; m < out.path_count; ++m)
        crossings += test::count_crossings(sc, out.path_m[m - 1], out.path_m[m], level);
      ASSERT_EQ(out.path_m[out.path_count - 1], out.proxy_m);
      contacts += out.state != ContactState::Free;
      vertices += out.state == ContactState::Vertex;
      prev = out.proxy_m;
    }
    EXPECT_EQ(crossings, 0) << "level " << level << " budget " << cs.max_box_tests;
    EXPECT_GT(contacts, 500) << "level " << level << " budget " << cs.max_box_tests;
  }
}

TEST(Contact, StartOnAWallIsPushedOff) {
  Polyline wall;
  wall.points_m = {{-0.02, 0.0}, {0.02, 0.0}};
  const Scene sc = Scene::build({wall}, 3);
  ContactSolver solver(sc, ContactParams{});
  solver.reset({0.001, 0.0}, 0);
  EXPECT_NE(solver.proxy().y, 0.0);
  // Then moving through the wall is blocked.
  ContactOutput out;
  ContactInput in;
  in.handle_m = {0.001, solver.proxy().y > 0 ? -0.005 : 0.005};
  solver.update(in, out);
  EXPECT_EQ(out.state, ContactState::Edge);
  EXPECT_EQ(out.proxy_m.y > 0, solver.proxy().y > 0);
}

// A level change at a sharp corner (found by bench_stability's strokes with auto levels): a coarse level
// rounds a 30° wedge's apex off, so its apex lies 1.4 mm inside the original's, farther from it than any
// error box is wide: the original runs on past the coarse segment's end, inside the box's reach past it, not
// across it. A proxy held in the apex at level 2 is behind the coarser levels' polylines there, so a change
// to any of them must wait. Judged independently: the parity of crossings of each level's polyline on the
// line from a point deep inside the wedge to the proxy.
TEST(Contact, NoLevelChangePutsTheProxyBehindACoarserApex) {
  const double half = 15.0 * M_PI / 180.0;
  const Vec2 apex{0.01, 0.0}, arm_a{-std::cos(half), std::sin(half)}, arm_b{-std::cos(half), -std::sin(half)};
  Polyline v;
  for (int i = 100; i >= 1; --i) v.points_m.push_back(apex + (0.05 * i / 100.0) * arm_a);
  v.points_m.push_back(apex);
  for (int i = 1; i <= 100; ++i) v.points_m.push_back(apex + (0.05 * i / 100.0) * arm_b);
  const Scene sc = Scene::build({v}, 7);
  ContactSolver solver(sc, ContactParams{});
  const int held = 2;
  const Vec2 inside{-0.02, 0.000037};
  solver.reset(inside, held);
  ContactOutput out;
  for (int k = 1; k <= 200; ++k) {  // into the apex and 10 mm past it, 0.2 mm a tick
    ContactInput in;
    in.handle_m = inside + Vec2{0.0002 * k, 0.0};
    in.level = held;
    solver.update(in, out);
  }
  ASSERT_EQ(out.state, ContactState::Vertex) << "the proxy is held in the apex";
  ASSERT_EQ(test::count_crossings(sc, inside, solver.proxy(), held) % 2, 0) << "on the inside of the level it renders";
  int behind = 0;
  for (int level = 0; level < sc.curve(0).levels; ++level) {
    const bool same_side = test::count_crossings(sc, inside, solver.proxy(), level) % 2 == 0;
    behind += !same_side;
    if (!same_side) {
      EXPECT_FALSE(solver.level_change_is_safe(level)) << "level " << level << ": the proxy is behind its apex";
    }
  }
  EXPECT_GT(behind, 0) << "some coarser level's apex lies inside the proxy, or the test tests nothing";
}
