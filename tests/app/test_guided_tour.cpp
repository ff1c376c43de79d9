// The guided tour: the planner (nearest untouched shape, side, closed and open outlines,
// speed, specks) and the servo side driven tick by tick through the simulated pantograph: on a picture
// with 5 shapes repeated Guide reaches each shape once, nearest first, the guide force never above its
// limit and the total never above max force; a hand holding still stops it, and so does a key, with the
// force faded out.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "config/device_profile.hpp"
#include "crossing_grid.hpp"
#include "curves.hpp"
#include "every_effect.hpp"
#include "haptics/sim_pantograph.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/guided_tour.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/servo_step.hpp"
#include "runtime/simulation.hpp"
#include "runtime_ticks.hpp"
#include "show_now.hpp"
#include "test_paths.hpp"
#include "test_pictures.hpp"
#include "tour_picture.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"
#include "wait_until.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;

// ── Independent geometry (brute force over the level-0 polyline) ─────────────────────────────────────
double dist_to_level0(const Scene& sc, std::size_t c, Vec2 p) {
  const Vec2* pts = sc.points(c, 0);
  const std::size_t n = sc.curve(c).point_count[0];
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = i + 1 < n ? i + 1 : 0;
    if (j == 0 && !sc.curve(c).closed) break;
    const Vec2 a = pts[i], b = pts[j], ab = b - a;
    const double l2 = ab.x * ab.x + ab.y * ab.y;
    double t = l2 > 0 ? ((p.x - a.x) * ab.x + (p.y - a.y) * ab.y) / l2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    best = std::min(best, std::hypot(p.x - (a.x + t * ab.x), p.y - (a.y + t * ab.y)));
  }
  return best;
}

/// Signed area of a closed polyline (> 0 counter-clockwise) and a point-in-polygon test (even-odd).
bool inside(const std::vector<Vec2>& poly, Vec2 p) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    if ((poly[i].y > p.y) != (poly[j].y > p.y) &&
        p.x < (poly[j].x - poly[i].x) * (p.y - poly[i].y) / (poly[j].y - poly[i].y) + poly[i].x)
      in = !in;
  }
  return in;
}

Scene scene_of(std::vector<Polyline> curves) { return Scene::build(curves, 3); }

// ── Planner ──────────────────────────────────────────────────────────────────────────────────────────
TEST(TourPlanner, StartsOffTheCurveOnTheHandlesSideAndPressesPastItRoundAClosedShape) {
  const Scene sc = scene_of({test::square(0.01)});
  const std::vector<Vec2> sq = test::square(0.01).points_m;
  TourParams p;
  VisitTouches none;
  none.reset(1, 1);
  for (const Vec2 handle : {Vec2{-0.03, 0.002}, Vec2{0.004, -0.002}}) {
    const bool handle_inside = inside(sq, handle);
    const auto plan = plan_tour(sc, 1, handle, none, p);
    ASSERT_TRUE(plan.has_value());
    EXPECT_EQ(plan->curve, 0);
    EXPECT_EQ(plan->scene_id, 1);
    std::size_t cur = 0;
    EXPECT_LT(distance(plan->at(0.0, cur).target_m, handle), 1e-12) << "the path starts at the handle";
    cur = 0;
    const Vec2 start = plan->at(plan->outline_start_s, cur).target_m;
    EXPECT_NEAR(dist_to_level0(sc, 0, start), p.offset_m, 1e-4);
    EXPECT_EQ(inside(sq, start), handle_inside) << "the start point is on the handle's side";
    // The outline: every target track_offset_m off the curve on the handle's side, pressed towards the
    // other side; back to where it began.
    int outline = 0;
    Vec2 first{}, last{};
    for (const TourPoint& tp : plan->points) {
      if (tp.t_s <= plan->outline_start_s + 1e-9 || tp.t_s >= plan->duration_s() - 1e-9) continue;
      const double d = dist_to_level0(sc, 0, tp.target_m);
      EXPECT_LT(d, p.offset_m + 1e-6) << "t " << tp.t_s;  // the track, or the 0.5 mm steps onto it and off it
      EXPECT_GT(d, p.track_offset_m - 1e-6) << "t " << tp.t_s;
      EXPECT_EQ(inside(sq, tp.target_m), handle_inside) << "t " << tp.t_s;
      EXPECT_LE(length(tp.press_n), p.press_force_n + 1e-9);
      if (length(tp.press_n) > 0.5 * p.press_force_n) {
        ++outline;
        const Vec2 pushed = tp.target_m + (0.003 / length(tp.press_n)) * tp.press_n;
        double to_corner = 1.0;
        for (const Vec2& c : sq) to_corner = std::min(to_corner, distance(c, tp.target_m));
        if (to_corner > 0.003) {  // (by a corner, pushing 3 mm along an edge's normal can miss the square)
          EXPECT_NE(inside(sq, pushed), handle_inside)
              << "t " << tp.t_s << ": the press points away from the handle's side";
        }
        if (first == Vec2{}) first = tp.target_m;
        last = tp.target_m;
      }
    }
    EXPECT_GT(outline, 100);
    EXPECT_LT(distance(first, last), 0.003)
        << "a closed shape is traced all the way round (the press ramps over 2 mm at each end)";
    // Let go off the wall on the handle's side.
    EXPECT_EQ(inside(sq, plan->points.back().target_m), handle_inside);
    EXPECT_NEAR(dist_to_level0(sc, 0, plan->points.back().target_m), p.offset_m, 1e-4);
    EXPECT_EQ(length(plan->points.back().press_n), 0.0) << "no press when it lets go";
    EXPECT_EQ(length(plan->points.front().press_n), 0.0) << "no press in the transit";
  }
}

TEST(TourPlanner, AnOpenCurveGoesFromItsNearerEndToTheFarEnd) {
  Polyline line;
  line.points_m = {{-0.02, 0.0}, {-0.01, 0.001}, {0.0, 0.0}, {0.01, -0.001}, {0.02, 0.0}};
  const Scene sc = scene_of({line});
  VisitTouches none;
  none.reset(1, 1);
  const auto plan = plan_tour(sc, 1, {0.03, 0.004}, none, TourParams{});
  ASSERT_TRUE(plan.has_value());
  std::size_t cur = 0;
  const Vec2 start = plan->at(plan->outline_start_s, cur).target_m;
  EXPECT_NEAR(start.x, 0.02, 0.001) << "starts at the right end, the one nearer the handle";
  EXPECT_GT(start.y, 0.0) << "on the handle's side";
  const Vec2 end = plan->points.back().target_m;
  EXPECT_NEAR(end.x, -0.02, 0.001) << "ends at the far end";
  EXPECT_GT(end.y, 0.0);
  EXPECT_EQ(plan->direction, -1)
      << "from the last point to the first: decreasing segment indices (the servo follows walls that way)";
  const auto from_left = plan_tour(sc, 1, {-0.03, 0.004}, none, TourParams{});
  ASSERT_TRUE(from_left.has_value());
  EXPECT_EQ(from_left->direction, 1) << "from the first point: increasing segment indices";
}

TEST(TourPlanner, MovesAtTourSpeedAlongTheOutlineAndAtMostTwiceItInTransit) {
  const Scene sc = scene_of({test::square(0.012)});
  VisitTouches none;
  none.reset(1, 1);
  for (const double v : {0.01, 0.03, 0.08}) {
    TourParams p;
    p.speed_m_per_s = v;
    const auto plan = plan_tour(sc, 1, {-0.05, 0.03}, none, p);
    ASSERT_TRUE(plan.has_value());
    double len = 0.0, t0 = -1.0, t1 = 0.0, transit_max = 0.0;
    for (std::size_t i = 1; i < plan->points.size(); ++i) {
      const TourPoint& a = plan->points[i - 1];
      const TourPoint& b = plan->points[i];
      ASSERT_GT(b.t_s, a.t_s) << "times increase";
      if (b.t_s <= plan->outline_start_s + 1e-12) {
        transit_max = std::max(transit_max, distance(a.target_m, b.target_m) / (b.t_s - a.t_s));
        continue;
      }
      if (t0 < 0) t0 = a.t_s;
      len += distance(a.target_m, b.target_m);
      t1 = b.t_s;
    }
    EXPECT_NEAR(len / (t1 - t0), v, 0.05 * v) << "outline speed";
    EXPECT_GT(len, 8 * 0.012) << "round the square";
    EXPECT_LE(transit_max, 2.0 * v) << "transit speed";
    EXPECT_GT(transit_max, v) << "the transit moves (minimum-jerk peak 1.875 v)";
  }
}

TEST(TourPlanner, NearestUntouchedShapeFirstSpecksNever) {
  Polyline speck;  // a 1.5 mm triangle: 4.5 mm round, below min_shape_length_m
  speck.closed = true;
  speck.points_m = {{0.0, 0.0}, {0.0015, 0.0}, {0.00075, 0.0013}};
  Polyline a = test::square(0.005), b = test::square(0.005);
  for (Vec2& q : a.points_m) q.x -= 0.02;
  for (Vec2& q : b.points_m) q.x += 0.03;
  const Scene sc = scene_of({speck, a, b});
  TourParams p;
  EXPECT_FALSE(is_tour_shape(sc, 0, p));
  VisitTouches t;
  t.reset(5, 3);
  EXPECT_EQ(shapes_remaining(sc, t, p), 2);
  auto plan = plan_tour(sc, 5, {0.001, 0.0005}, t, p);  // on the speck
  ASSERT_TRUE(plan.has_value());
  EXPECT_EQ(plan->curve, 1) << "the speck is no shape; the left square is nearer than the right";
  t.touch(5, 1);
  t.touch(4, 2);  // another picture: ignored
  EXPECT_EQ(t.count(), 1);
  plan = plan_tour(sc, 5, {-0.02, 0.0}, t, p);
  ASSERT_TRUE(plan.has_value());
  EXPECT_EQ(plan->curve, 2);
  t.touch(5, 2);
  EXPECT_EQ(shapes_remaining(sc, t, p), 0);
  EXPECT_FALSE(plan_tour(sc, 5, {0.0, 0.0}, t, p).has_value());
  t.reset(6, 3);
  EXPECT_EQ(t.count(), 0);
}

// ── Servo side ───────────────────────────────────────────────────────────────────────────────────────
/// The kiosk's defaults with the simulated pantograph; the model hand is relaxed (no force) unless
/// `hand_stiff` holds it at a fixed target. The caller does what ServoThread does each tick.
struct TourRig {
  config::Settings s;
  ServoParams sp;
  TourParams tp;
  SimulatedPantograph device;
  audio::SpscRing<audio::CueEvent> cues{4096};
  ServoStep core;
  const Scene* scene = nullptr;
  int scene_id = 7;
  bool hand_stiff = false;
  Vec2 hand_target;
  ModelHandParams stiff_hand{3000.0, 30.0, 5.0};
  // Per tick checks and records.
  double max_guide_n = 0.0, max_total_n = 0.0, max_guide_step_n = 0.0;
  Vec2 last_guide;
  std::vector<Vec2> guides;  // every tick's guide force [N]
  int tour_starts = 0;
  std::vector<int> tour_start_curves;

  explicit TourRig(Vec2 start = {0.0, -0.035}, const config::Settings& settings = {})
      : s(settings),
        sp(servo_params_from(s)),
        tp(tour_params_from(s)),
        device(sim_params_from(s), start),
        core(CueTrackerParams{}, &cues) {
    device.open();
  }
  void publish(std::unique_ptr<Scene> sc) {
    auto b = std::make_unique<SceneBundle>(std::move(sc), sp);
    b->id = scene_id;
    scene = b->scene.get();
    core.publish(std::move(b));
  }
  void tick() {
    const DeviceSample sample = device.read();
    ServoCommand cmd;
    core.step(sample, false, cmd);
    core.publish_display();
    device.write_force(cmd.force_n);
    const Vec2 g = core.last_guide_force();
    max_guide_n = std::max(max_guide_n, length(g));
    max_total_n = std::max(max_total_n, length(cmd.force_n));
    max_guide_step_n = std::max(max_guide_step_n, length(g - last_guide));
    last_guide = g;
    guides.push_back(g);
    const Vec2 hand =
        hand_stiff ? model_hand_force(stiff_hand, hand_target, device.true_position_m(), device.velocity_m_per_s())
                   : Vec2{};
    device.step(sp.period_s, hand);
    audio::CueEvent e;
    while (cues.try_pop(e)) {
      if (e.kind == audio::CueKind::TourStart) {
        ++tour_starts;
        tour_start_curves.push_back(e.curve);
      }
    }
  }
  void run(double seconds) {
    for (long k = 0, n = static_cast<long>(seconds / sp.period_s + 0.5); k < n; ++k) tick();
  }
  Vec2 handle() { return device.read().handle_m; }
  /// Largest change of the guide force from one tick to the next over the last `n` ticks [N].
  double max_step_last(long n) const {
    double m = 0.0;
    for (std::size_t i = guides.size() - static_cast<std::size_t>(n); i < guides.size(); ++i)
      m = std::max(m, length(guides[i] - guides[i - 1]));
    return m;
  }
};

/// The five-shape picture's scene (built through the image pipeline from a PNG written here).
std::unique_ptr<Scene> five_shapes(const config::Settings& s) {
  const fs::path dir = fs::temp_directory_path() / ("hk_tour_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path png = dir / "five_shapes.png";
  EXPECT_TRUE(test::write_five_shapes_png(png.string()));
  ImageScene is = build_image_scene(png.string(), s);
  fs::remove_all(dir);
  return std::move(is.scene);
}

/// Guide pressed five times on the five-shape picture with `s`: each shape once, nearest first, the guide
/// never above tour_max_force_n, the whole force never above max_force_n.
void tour_five_shapes(const config::Settings& s) {
  TourRig r({0.0, -0.035}, s);
  r.publish(five_shapes(r.s));
  r.run(0.6);  // taken, force ramped in
  const Scene& sc = *r.scene;
  ASSERT_EQ(sc.curve_count(), 5u) << "the picture must give 5 curves for this test to mean anything";
  for (std::size_t c = 0; c < 5; ++c) ASSERT_TRUE(is_tour_shape(sc, c, r.tp));
  VisitTouches touches;  // fed only by contact, as the kiosk feeds it from the display state
  touches.reset(r.scene_id, 5);
  std::set<int> visited;
  double total_s = 0.0;
  for (int press = 1; press <= 5; ++press) {
    const Vec2 h = r.handle();
    // The independent check of "nearest untouched": brute force over the level-0 polylines.
    int nearest = -1;
    double nearest_d = std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < 5; ++c) {
      if (touches.touched(static_cast<int>(c))) continue;
      const double d = dist_to_level0(sc, c, h);
      if (d < nearest_d) {
        nearest_d = d;
        nearest = static_cast<int>(c);
      }
    }
    auto plan = plan_tour(sc, r.scene_id, h, touches, r.tp);
    ASSERT_TRUE(plan.has_value()) << "press " << press;
    EXPECT_EQ(plan->curve, nearest) << "press " << press << ": the nearest untouched shape";
    EXPECT_TRUE(visited.insert(plan->curve).second) << "shape " << plan->curve << " a second time";
    plan->id = press;
    const int curve = plan->curve;
    const int before = touches.count();
    r.core.publish_tour(std::make_unique<TourPath>(std::move(*plan)));
    long ticks = 0, outline_contact = 0;
    std::set<int> touched_now;
    for (;; ++ticks) {
      r.tick();
      const ServoDisplayState& d = r.core.display();
      if (d.curve >= 0) {
        touches.touch(r.scene_id, d.curve);
        touched_now.insert(d.curve);
        if (d.tour_phase == TourPhase::Outline && d.curve == curve) ++outline_contact;
      }
      if (std::getenv("HK_TOUR_DEBUG") && ticks % 50 == 0)
        std::printf("press %d t %ld phase %d handle %.4f %.4f guide %.3f %.3f curve %d level %d state %d\n", press,
                    ticks, static_cast<int>(d.tour_phase), d.handle_m.x, d.handle_m.y, d.guide_force_n.x,
                    d.guide_force_n.y, d.curve, d.level, static_cast<int>(d.state));
      if (d.tour_id == press && tour_ended(d.tour_phase)) break;
      ASSERT_LT(ticks, 60000) << "press " << press << ": the tour did not end within 60 s; phase "
                              << static_cast<int>(d.tour_phase) << " handle " << d.handle_m.x << ", " << d.handle_m.y
                              << " guide " << d.guide_force_n.x << ", " << d.guide_force_n.y << " contact " << d.curve
                              << " level " << d.level;
    }
    EXPECT_EQ(r.core.display().tour_phase, TourPhase::Done) << "press " << press;
    total_s += static_cast<double>(ticks) * r.sp.period_s;
    EXPECT_GT(outline_contact, 500) << "press " << press << ": the outline is traced against the wall";
    EXPECT_EQ(touches.count(), before + 1) << "press " << press << ": exactly one more shape touched";
    EXPECT_TRUE(touched_now.count(curve) == 1 && touched_now.size() == 1)
        << "press " << press << ": only the shape toured";
    EXPECT_LT(dist_to_level0(sc, static_cast<std::size_t>(curve), r.handle()), 0.004)
        << "press " << press << ": the handle ends by the shape";
    r.core.collect_retired();
  }
  EXPECT_EQ(visited.size(), 5u);
  EXPECT_EQ(r.tour_starts, 5) << "one TourStart earcon per tour";
  EXPECT_EQ(shapes_remaining(sc, touches, r.tp), 0);
  EXPECT_FALSE(plan_tour(sc, r.scene_id, r.handle(), touches, r.tp).has_value()) << "the 6th Guide: all touched";
  EXPECT_LE(r.max_guide_n, r.tp.max_force_n + 1e-9) << "the guide force above tour_max_force_n";
  EXPECT_GT(r.max_guide_n, 0.2) << "the guide must pull for the limit to mean anything";
  EXPECT_LE(r.max_total_n, r.s.haptics.max_force_n + 1e-9);
  ::testing::Test::RecordProperty("time_to_touch_all_s", std::to_string(total_s));
  std::printf("time to touch every shape once with the guided tour (%s profile): %.1f s\n", s.device.type.c_str(),
              total_s);
}

TEST(GuidedTour, RepeatedGuideReachesEachOfFiveShapesOnceNearestFirstWithinItsForceLimit) {
  tour_five_shapes(config::Settings{});
}

TEST(GuidedTour, WithTheHaplyProfilesForcesTheTourStillReachesEveryShape) {
  // The tour's pull (0.5 N), the walls (500 N/m, 1.5 N) and the fades of the gen3 board: all within what it
  // gives everywhere (1.65 N), and the tour still leads the hand round each shape.
  const config::Settings s = config::profile_defaults("haply");
  ASSERT_LE(s.haptics.max_force_n, config::force_everywhere_n(s, "haply"));
  tour_five_shapes(s);
}

TEST(GuidedTour, AHandHoldingStillAgainstItStopsItWithinASecondAndTheForceFades) {
  TourRig r;
  r.publish(five_shapes(r.s));
  r.hand_stiff = true;
  r.hand_target = r.handle();
  r.run(0.6);
  VisitTouches none;
  none.reset(r.scene_id, static_cast<int>(r.scene->curve_count()));
  auto plan = plan_tour(*r.scene, r.scene_id, r.handle(), none, r.tp);
  ASSERT_TRUE(plan.has_value());
  plan->id = 1;
  r.core.publish_tour(std::make_unique<TourPath>(std::move(*plan)));
  long ticks = 0;
  for (; ticks < 3000; ++ticks) {
    r.tick();
    if (r.core.display().tour_phase == TourPhase::Stopped) break;
  }
  EXPECT_EQ(r.core.display().tour_phase, TourPhase::Stopped);
  EXPECT_LE(ticks, 1200) << "held still: stopped within ~1 s";
  EXPECT_GT(r.max_guide_n, 0.95 * r.tp.max_force_n) << "it pulled at its limit against the hand";
  EXPECT_LE(r.max_guide_n, r.tp.max_force_n + 1e-9);
  EXPECT_EQ(length(r.core.last_guide_force()), 0.0);
  // Faded from its limit, not cut (a cut would change it by > 1 N in one tick): over the fade no tick
  // changed it by more than 0.1 N (the fade's own 1.2 N / 50 ticks plus the spring's and damper's change
  // as the handle gives a little and the encoder steps).
  const long fade = static_cast<long>(r.tp.fade_s / r.sp.period_s + 0.5);
  EXPECT_GT(length(r.guides[r.guides.size() - static_cast<std::size_t>(fade) - 2]), 0.9 * r.tp.max_force_n);
  EXPECT_LE(r.max_step_last(fade + 2), 0.1);
  EXPECT_LT(distance(r.handle(), r.hand_target), 0.002) << "the hand kept the handle";
}

TEST(GuidedTour, AKeyStopsItAndTheForceFadesOut) {
  TourRig r;
  r.publish(five_shapes(r.s));
  r.run(0.6);
  VisitTouches none;
  none.reset(r.scene_id, static_cast<int>(r.scene->curve_count()));
  auto plan = plan_tour(*r.scene, r.scene_id, r.handle(), none, r.tp);
  ASSERT_TRUE(plan.has_value());
  plan->id = 3;
  r.core.publish_tour(std::make_unique<TourPath>(std::move(*plan)));
  for (long k = 0; k < 20000 && r.core.display().tour_phase != TourPhase::Outline; ++k) r.tick();
  r.run(0.5);
  ASSERT_EQ(r.core.display().tour_phase, TourPhase::Outline);
  const double at_key = length(r.core.last_guide_force());
  EXPECT_GT(at_key, 0.15) << "pressing on the wall when the key comes";
  r.core.cancel_tour();
  const long fade = static_cast<long>(r.tp.fade_s / r.sp.period_s + 0.5);
  long ticks = 0;
  for (; ticks < 1000 && r.core.display().tour_phase != TourPhase::Stopped; ++ticks) r.tick();
  EXPECT_EQ(r.core.display().tour_phase, TourPhase::Stopped);
  EXPECT_EQ(r.core.display().tour_id, 3);
  EXPECT_LE(ticks, fade + 1);
  EXPECT_EQ(length(r.core.last_guide_force()), 0.0);
  // Faded, not cut: its size falls by less than half in any tick and stays under the fade's straight line
  // from the force limit (its direction may turn meanwhile: the press follows the wall round a corner).
  double max_drop = 0.0;
  for (std::size_t i = r.guides.size() - static_cast<std::size_t>(ticks), k = 1; i < r.guides.size(); ++i, ++k) {
    max_drop = std::max(max_drop, length(r.guides[i - 1]) - length(r.guides[i]));
    EXPECT_LE(length(r.guides[i]), (1.0 - static_cast<double>(k) / static_cast<double>(fade)) * r.tp.max_force_n + 1e-9)
        << "tick " << k << " of the fade";
  }
  EXPECT_LE(max_drop, 0.5 * at_key) << "faded, not cut";
  EXPECT_EQ(r.tour_starts, 1);
}

TEST(GuidedTour, ATourForAnotherPictureIsDropped) {
  TourRig r;
  r.publish(std::make_unique<Scene>(Scene::build({test::square(0.01)}, 3)));
  r.run(0.1);
  const Scene other = Scene::build({test::square(0.01)}, 3);
  VisitTouches none;
  none.reset(99, 1);
  auto plan = plan_tour(other, 99, r.handle(), none, r.tp);
  ASSERT_TRUE(plan.has_value());
  plan->id = 4;
  r.core.publish_tour(std::make_unique<TourPath>(std::move(*plan)));
  r.run(0.01);
  EXPECT_EQ(r.core.display().tour_phase, TourPhase::Stopped);
  EXPECT_EQ(r.max_guide_n, 0.0);
  r.core.collect_retired();
}

// ── The flow: the Guide key, and any key stops a tour ─────────────────────────────────────────────────
struct GuideRecorder final : hk::test::EveryEffect {
  int guides = 0, keys = 0;
  std::vector<std::string> said;
  void say(const std::string& t) override { said.push_back(t); }
  void show_tutorial(TutorialShape) override {}
  int show_picture(int) override { return 5; }
  int picture_count() const override { return 2; }
  std::string describe() override { return "five shapes"; }
  bool change_level(int) override { return true; }
  bool change_volume(int) override { return true; }
  void new_session() override {}
  void show_document(int, int) override {}
  void forget_stick() override {}
  void key_pressed() override { ++keys; }
  void guide() override { ++guides; }
};

TEST(GuidedTour, TheFlowSendsGuideAndTellsOfEveryKey) {
  GuideRecorder fx;
  KioskFlow flow(fx, audio::MessageCatalog::english());
  flow.key(KioskKey::Guide, 0.0);  // wakes the kiosk: no tour yet
  EXPECT_EQ(fx.guides, 0);
  flow.key(KioskKey::Guide, 1.0);  // on a tutorial shape
  EXPECT_EQ(fx.guides, 1);
  for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, 2.0);
  ASSERT_EQ(flow.view().state, KioskState::Picture);
  flow.key(KioskKey::Guide, 3.0);
  flow.key(KioskKey::Describe, 4.0);
  EXPECT_EQ(fx.guides, 2);
  EXPECT_EQ(fx.keys, 6) << "every key after the wake is reported (a running tour stops)";
}

}  // namespace
}  // namespace hk::app

// ── The kiosk runtime, its servo core stepped by hand (no servo thread, no sleeps) ─────────────────────
namespace hk::app {
namespace {

struct RuntimeRig {
  fs::path dir = fs::temp_directory_path() / ("hk_tour_rt_" + std::to_string(::getpid()));
  config::Settings s;
  std::unique_ptr<KioskRuntime> rt;
  RuntimeRig() {
    fs::remove_all(dir);
    fs::create_directories(dir);
    EXPECT_TRUE(test::write_five_shapes_png((dir / "five.png").string()));
    rt = std::make_unique<KioskRuntime>(test::headless_runtime_options(dir), s);
  }
  ~RuntimeRig() {
    rt.reset();
    fs::remove_all(dir);
  }
  /// What the servo thread does, with the limp model hand the runtime asks for during a tour (no hand
  /// force unless `hand_target_m` is given: then the model hand pulls the handle there), then the window
  /// thread's poll. Each tick's guide force is kept in guide_n (the trace).
  void run(double seconds, std::optional<Vec2> hand_target_m = std::nullopt) {
    const double dt = 1.0 / s.haptics.servo_rate_hz;
    const ModelHandParams hand = hand_params_from(s);
    const auto hand_force = [&](const SimulatedPantograph& sim) {
      return hand_target_m ? model_hand_force(hand, *hand_target_m, sim.true_position_m(), sim.velocity_m_per_s())
                           : Vec2{};
    };
    for (long k = 0, n = static_cast<long>(seconds / dt + 0.5); k < n; ++k) {
      test::runtime_tick(*rt, dt, hand_force);
      guide_n.push_back(length(rt->core().display().guide_force_n));
      if (k % 16 == 0) {  // a frame: the window thread's poll, and 16 ms of sound heard (48 kHz, mono)
        rt->tour().poll();
        rt->audio().render(heard.data(), heard.size());
      }
    }
    rt->tour().poll();
  }
  /// Pulls the mix until nothing is being said (the speech worker synthesises in its own time).
  bool listen_to_the_end() {
    return test::wait_until([&] { return !rt->voice().speaking(); },
                            [&] { rt->audio().render(heard.data(), heard.size()); });
  }
  std::vector<double> guide_n;                         // every tick's guide force [N], from the first run
  std::vector<float> heard = std::vector<float>(768);  // one frame's sound
  std::string text(audio::MessageId id, std::initializer_list<audio::MessageArg> args = {}) {
    return audio::MessageCatalog::english().text(id, args);
  }
};

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

TEST(GuidedTourRuntime, GuideLeadsToEachShapeThenSaysWhatRemainsAndAKeyStopsIt) {
  RuntimeRig r;
  ASSERT_EQ(test::show_now(*r.rt, 0), 5);
  r.run(0.6);
  r.rt->tour().key_pressed();
  r.rt->tour().guide();
  ASSERT_TRUE(r.rt->tour().running()) << r.rt->voice().last_said();
  EXPECT_EQ(r.rt->voice().last_said(), r.text(audio::MessageId::tour_ask));
  for (int i = 0; i < 60 && r.rt->tour().running(); ++i) r.run(0.5);
  EXPECT_FALSE(r.rt->tour().running());
  EXPECT_EQ(r.rt->tour().touches().count(), 1);
  EXPECT_EQ(r.rt->voice().last_said().rfind("That was ", 0), 0u)
      << "it names what it traced: " << r.rt->voice().last_said();
  EXPECT_TRUE(
      ends_with(r.rt->voice().last_said(), audio::MessageCatalog::english().text(audio::MessageId::tour_remaining, 4)))
      << r.rt->voice().last_said();
  // A key during the next tour stops it, quietly; the Guide key stopping it says so.
  r.rt->tour().key_pressed();
  r.rt->tour().guide();
  r.run(5.0);  // past the announcement: the tour runs
  ASSERT_TRUE(r.rt->tour().running());
  ASSERT_FALSE(r.rt->tour().announced());
  r.rt->tour().key_pressed();  // e.g. Describe: its own answer is what the visitor hears
  r.run(0.2);
  EXPECT_FALSE(r.rt->tour().running());
  EXPECT_EQ(r.rt->voice().last_said(), r.text(audio::MessageId::tour_ask)) << "nothing said of a tour a key stopped";
  r.rt->tour().key_pressed();
  r.rt->tour().guide();
  r.run(5.0);
  r.rt->tour().key_pressed();
  r.rt->tour().guide();  // the Guide key again: stops it
  EXPECT_EQ(r.rt->voice().last_said(), r.text(audio::MessageId::tour_stopped));
  r.run(0.2);
  EXPECT_FALSE(r.rt->tour().running());
  // A key while the tour is being announced: it never starts.
  r.rt->tour().key_pressed();
  r.rt->tour().guide();
  r.run(0.5);
  r.rt->tour().key_pressed();
  const std::size_t from = r.guide_n.size();
  r.run(8.0);
  EXPECT_FALSE(r.rt->tour().running());
  EXPECT_EQ(*std::max_element(r.guide_n.begin() + static_cast<std::ptrdiff_t>(from), r.guide_n.end()), 0.0);
  // The rest, one Guide after another.
  // (A shape may be touched on the way to another: then fewer tours are needed.)
  for (int tours = 0; tours < 4 && r.rt->tour().touches().count() < 5; ++tours) {
    r.rt->tour().key_pressed();
    r.rt->tour().guide();
    ASSERT_TRUE(r.rt->tour().running()) << tours;
    for (int i = 0; i < 60 && r.rt->tour().running(); ++i) r.run(0.5);
    EXPECT_FALSE(r.rt->tour().running());
  }
  EXPECT_EQ(r.rt->tour().touches().count(), 5);
  EXPECT_TRUE(ends_with(r.rt->voice().last_said(), r.text(audio::MessageId::tour_all_touched)))
      << r.rt->voice().last_said();
  r.rt->tour().key_pressed();
  r.rt->tour().guide();
  EXPECT_FALSE(r.rt->tour().running());
  EXPECT_EQ(r.rt->voice().last_said(), r.text(audio::MessageId::tour_all_touched));
  // A new visitor: nothing touched.
  r.rt->effects().session.new_session();
  EXPECT_EQ(r.rt->tour().touches().count(), 0);
}

/// Staff names for the five shapes: the circle "sun" and the triangle "roof" (boxes around them, in pixels).
void name_sun_and_roof(const fs::path& dir) {
  std::ofstream(dir / "five.annotations.json") << R"({"type": "AnnotationPage", "items": [
    {"type": "Annotation", "motivation": "identifying", "body": {"type": "TextualBody", "value": "sun"},
     "target": {"source": "five.png", "selector": {"type": "FragmentSelector", "value": "xywh=50,40,140,140"}}},
    {"type": "Annotation", "motivation": "identifying", "body": {"type": "TextualBody", "value": "roof"},
     "target": {"source": "five.png", "selector": {"type": "FragmentSelector", "value": "xywh=510,40,160,160"}}}]})";
}

// On a picture with named parts, Guide offers them in turn, the largest first ("I will guide your hand to the
// roof."), a press during the announcement offers the next, the tour ends saying what it traced by its name; then
// the first touch of the other named shape says its name, once; once every part has been offered, Guide leads to
// the nearest shape not yet touched, as on any picture.
TEST(GuidedTourRuntime, GuideOffersEachNamedPartInTurnAndTheFirstTouchOfANamedShapeSaysItsNameOnce) {
  RuntimeRig r;
  name_sun_and_roof(r.dir);
  ASSERT_EQ(test::show_now(*r.rt, 0), 5);
  r.run(0.6);
  r.rt->tour().key_pressed();
  r.rt->tour().guide();
  EXPECT_EQ(r.rt->voice().last_said(), r.text(audio::MessageId::tour_ask_part, {{"name", "the roof"}}));
  r.run(0.3);
  r.rt->tour().key_pressed();
  r.rt->tour().guide();  // while it is announced: the next part
  EXPECT_EQ(r.rt->voice().last_said(), r.text(audio::MessageId::tour_ask_part, {{"name", "the sun"}}));
  for (int i = 0; i < 60 && r.rt->tour().running(); ++i) r.run(0.5);
  ASSERT_FALSE(r.rt->tour().running());
  EXPECT_EQ(r.rt->voice().last_said().rfind("That was the sun.", 0), 0u) << r.rt->voice().last_said();
  ASSERT_TRUE(r.listen_to_the_end());
  // The hand over the top of the picture, clear of the square, then down into the triangle: it meets the
  // roof's edge.
  const vision::PxToM& px = r.rt->stage().shown().px_to_m;
  const Vec2 roof{px.x_m(590), px.y_m(150)};
  r.run(2.0, Vec2{px.x_m(230), px.y_m(22)});
  r.run(2.0, Vec2{px.x_m(590), px.y_m(22)});
  r.run(3.0, roof);
  EXPECT_EQ(r.rt->voice().last_said(), r.text(audio::MessageId::touch_name, {{"name", "The roof"}}));
  ASSERT_TRUE(r.listen_to_the_end());
  const std::uint64_t said = r.rt->voice().texts_said();
  r.run(2.0, Vec2{px.x_m(590), px.y_m(22)});  // off it
  r.run(3.0, roof);                           // and back on
  EXPECT_EQ(r.rt->voice().texts_said(), said) << "a name is said once a visit: " << r.rt->voice().last_said();
  // Every part offered: the nearest shape not yet touched.
  r.rt->tour().key_pressed();
  r.rt->tour().guide();
  EXPECT_EQ(r.rt->voice().last_said(), r.text(audio::MessageId::tour_ask));
}

// With [kiosk] say_names_on_touch "off", touching a named shape says nothing.
TEST(GuidedTourRuntime, WithSayNamesOnTouchOffATouchSaysNothing) {
  RuntimeRig r;
  r.s.kiosk.say_names_on_touch = "off";
  r.rt.reset();
  r.rt = std::make_unique<KioskRuntime>(test::headless_runtime_options(r.dir), r.s);
  name_sun_and_roof(r.dir);
  ASSERT_EQ(test::show_now(*r.rt, 0), 5);
  ASSERT_TRUE(r.listen_to_the_end());  // the picture's announcement
  const std::uint64_t said = r.rt->voice().texts_said();
  const vision::PxToM& px = r.rt->stage().shown().px_to_m;
  r.run(2.0, Vec2{px.x_m(590), px.y_m(22)});
  r.run(3.0, Vec2{px.x_m(590), px.y_m(150)});
  ASSERT_EQ(r.rt->stage().shown().names.shape_name.size(), 5u);
  int roof = -1;
  for (int c = 0; c < 5; ++c)
    if (r.rt->stage().shown().names.shape_name[static_cast<std::size_t>(c)] == "the roof") roof = c;
  ASSERT_GE(roof, 0);
  EXPECT_TRUE(r.rt->tour().touches().touched(roof)) << "the roof was touched";
  EXPECT_EQ(r.rt->voice().texts_said(), said) << r.rt->voice().last_said();
}

// The tour asks first: "I will guide your hand to a shape. Hold the handle lightly." is said, and the trace
// of the guide force stays at zero for as long as that takes to say (synthesised at the kiosk's voice and
// rate), so the pull never comes before the words.
TEST(GuidedTourRuntime, TheTourAsksFirstAndPullsOnlyOnceThatHasBeenSaid) {
  RuntimeRig r;
  ASSERT_EQ(test::show_now(*r.rt, 0), 5);
  r.run(0.6);
  const std::size_t asked = r.guide_n.size();
  r.rt->tour().key_pressed();
  r.rt->tour().guide();
  ASSERT_EQ(r.rt->voice().last_said(), r.text(audio::MessageId::tour_ask));
  ASSERT_TRUE(r.rt->tour().announced());
  const double ask_s = r.rt->audio().speech_duration_s(r.rt->voice().last_said());
  ASSERT_GT(ask_s, 2.0) << "the announcement is spoken (espeak-ng present)";
  for (int i = 0; i < 60 && r.rt->tour().running(); ++i) r.run(0.5);
  const auto first = std::find_if(r.guide_n.begin() + static_cast<std::ptrdiff_t>(asked), r.guide_n.end(),
                                  [](double f) { return f > 0.0; });
  ASSERT_NE(first, r.guide_n.end()) << "the tour pulled at some point";
  const double first_force_s =
      static_cast<double>(first - (r.guide_n.begin() + static_cast<std::ptrdiff_t>(asked))) / r.s.haptics.servo_rate_hz;
  EXPECT_GE(first_force_s, ask_s) << "the first guide force came " << first_force_s << " s after the announcement of "
                                  << ask_s << " s began";
  EXPECT_LE(first_force_s, ask_s + TourDesk::kAskMargin_s + 0.1) << "and not much later";
  EXPECT_EQ(r.rt->tour().touches().count(), 1);
}

// "What is here": the handle pressed against the square from below. Where names it by its number, size and
// kind, and the hand's place in near / far terms; Describe starts from it.
TEST(GuidedTourRuntime, WhereNamesTheShapeUnderTheHandAndDescribeStartsThere) {
  RuntimeRig r;
  ASSERT_EQ(test::show_now(*r.rt, 0), 5);
  const vision::PxToM& px = r.rt->stage().shown().px_to_m;
  auto at = [&](double u, double v) { return Vec2{px.x_m(u), px.y_m(v)}; };
  // Up the free corridor between the ellipse and the rotated rectangle, then into the square's bottom side.
  r.run(2.0, at(360, 230));
  r.run(1.5, at(355, 100));
  const ServoDisplayState& d = r.rt->core().display();
  ASSERT_GE(d.curve, 0) << "the handle rests against a shape";
  int square = -1;
  for (std::size_t c = 0; c < r.rt->stage().shown().polylines.size(); ++c) {
    Vec2 lo{1e9, 1e9}, hi{-1e9, -1e9};
    for (Vec2 p : r.rt->stage().shown().polylines[c].points_m) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    }
    if (length(0.5 * (lo + hi) - at(355, 105)) < 0.003) square = static_cast<int>(c);
  }
  ASSERT_GE(square, 0);
  EXPECT_EQ(d.curve, square) << "it is the square the hand presses on";
  const std::string where = r.rt->stage().where();
  EXPECT_EQ(where,
            "On shape " + std::to_string(square + 1) + " of 5: a medium black square. Your hand is in the far middle.")
      << "the hand's place: below the square, in the far third";
  const std::string describe = r.rt->stage().describe();
  EXPECT_EQ(describe.rfind("5 shapes. Nearest your hand, a medium black square in the far middle", 0), 0u) << describe;
  // The hand away from every shape, near the visitor: the nearest shape, and where the hand is.
  r.run(2.0, at(360, 230));
  const std::string near = r.rt->stage().where();
  EXPECT_EQ(near, "Your hand is in the middle. Shape " + std::to_string(square + 1) +
                      ", a medium black square, is 1 cm farther away.");
}

// The practice shapes are named ("a square"), and Where on one says what far and near mean; Describe names it
// too, and a tour round it says what it traced by that name.
TEST(GuidedTourRuntime, PracticeShapesAreNamedAndWhereExplainsFarAndNear) {
  RuntimeRig r;
  r.rt->stage().show_tutorial(TutorialShape::Circle);
  r.run(0.6);  // the handle at rest, off the circle
  r.rt->tour().key_pressed();
  r.rt->tour().guide();
  ASSERT_TRUE(r.rt->tour().running()) << r.rt->voice().last_said();
  for (int i = 0; i < 80 && r.rt->tour().running(); ++i) r.run(0.5);
  EXPECT_FALSE(r.rt->tour().running());
  EXPECT_EQ(r.rt->voice().last_said().rfind("That was a circle.", 0), 0u) << r.rt->voice().last_said();
  r.run(1.5, Vec2{0.0, 0.0});  // the hand pulled towards the middle, against the circle's wall
  const std::string where = r.rt->stage().where();
  EXPECT_EQ(where.rfind("On shape 1 of 1: a circle. Your hand is ", 0), 0u) << where;
  EXPECT_TRUE(ends_with(where, ". Far means away from you, near means towards you.")) << where;
  EXPECT_EQ(r.rt->stage().where().find("Far means"), std::string::npos) << "said once a visit";
  r.rt->effects().session.new_session();
  EXPECT_NE(r.rt->stage().where().find("Far means"), std::string::npos) << "and again for the next visitor";
  EXPECT_EQ(r.rt->stage().describe(), "A circle, in the middle.");
  // A picture is described by its shapes again.
  ASSERT_EQ(test::show_now(*r.rt, 0), 5);
  r.run(0.5, Vec2{0.0, 0.0});
  EXPECT_EQ(r.rt->stage().where().find("Far means"), std::string::npos) << r.rt->stage().where();
}

// Tours on real pictures: a tour must not stop while the hand is relaxed (13 tours on 9 of the 22 pictures
// once did). The press keeps the handle on the wall, so it follows the wall into narrow pockets, slots and
// hooks of the rendered polyline that the planned track passes outside: the horse's ear, the gap between
// the apple's stem and leaf (silhouette_1), a curl of the bat's wing (silhouette_3). There the spring pulls
// into the wall, the handle stops and the tour took it for a hand holding still. Now the guide follows the
// wall out of such a pocket (ServoStep::track_trap). With the handle relaxed, Guide pressed up to four times
// on each picture in each level mode: every tour ends Done, no move of the proxy in an outline crosses a wall
// of the level in force (the independent crossing grid), and the forces stay within their limits. sudoku is
// the exception: a grid line traced out and back (a doubled stroke, walls on both sides of a 0.2 mm gap) can
// still hold the handle on the far side of the track, and one of its four tours may stop.
class GuidedTourOnPictures : public ::testing::TestWithParam<std::tuple<const char*, const char*>> {};

TEST_P(GuidedTourOnPictures, ToursEndDoneWithARelaxedHandAndTheProxyCrossesNoWall) {
  const std::string name = std::get<0>(GetParam());
  TourRig r;
  r.s.haptics.level_mode = std::get<1>(GetParam());
  r.sp = servo_params_from(r.s);
  ImageScene is = build_image_scene(std::string(HK_TEST_DATA_DIR) + "/images/" + name, r.s);
  r.publish(std::move(is.scene));
  r.run(0.6);  // taken, force ramped in
  const Scene& sc = *r.scene;
  ASSERT_GT(sc.curve_count(), 0u);
  VisitTouches touches;  // fed by contact, as the kiosk feeds it
  touches.reset(r.scene_id, static_cast<int>(sc.curve_count()));
  std::map<int, std::unique_ptr<test::CrossingGrid>> grids;
  auto grid = [&](int id) -> test::CrossingGrid& {
    auto& g = grids[id];
    if (!g) g = std::make_unique<test::CrossingGrid>(sc, id);
    return *g;
  };
  int tours = 0, done = 0, crossings = 0, prev_level = -1;
  for (int press = 1; press <= 4; ++press) {
    auto plan = plan_tour(sc, r.scene_id, r.handle(), touches, r.tp);
    if (!plan) break;
    plan->id = press;
    const int curve = plan->curve;
    r.core.publish_tour(std::make_unique<TourPath>(std::move(*plan)));
    ++tours;
    for (long ticks = 0;; ++ticks) {
      r.tick();
      const ServoDisplayState& d = r.core.display();
      const ServoOutput& so = r.core.last_output();
      // Walls are on in the outline: no move across the level in force, nor the old level while it is a wall.
      const int old_wall = so.level_changed ? prev_level : so.contact.transition_level;
      for (int m = 1; d.tour_phase == TourPhase::Outline && m < so.contact.path_count; ++m) {
        crossings += grid(so.level).crossings(so.contact.path_m[m - 1], so.contact.path_m[m]);
        if (old_wall >= 0) crossings += grid(old_wall).crossings(so.contact.path_m[m - 1], so.contact.path_m[m]);
      }
      prev_level = so.level;
      if (d.curve >= 0) touches.touch(r.scene_id, d.curve);
      if (d.tour_id == press && tour_ended(d.tour_phase)) break;
      ASSERT_LT(ticks, 120000) << "tour " << press << " did not end within 120 s";
    }
    done += r.core.display().tour_phase == TourPhase::Done;
    touches.touch(r.scene_id, curve);
    r.core.collect_retired();
  }
  ASSERT_GT(tours, 0);
  if (name == "sudoku.png") {
    EXPECT_GE(done, tours - 1) << "a doubled stroke may hold one tour";
  } else {
    EXPECT_EQ(done, tours) << "a tour stopped with the hand relaxed";
  }
  EXPECT_EQ(crossings, 0);
  EXPECT_LE(r.max_guide_n, r.tp.max_force_n + 1e-9);
  EXPECT_LE(r.max_total_n, r.s.haptics.max_force_n + 1e-9);
}

INSTANTIATE_TEST_SUITE_P(RealImages, GuidedTourOnPictures,
                         ::testing::Combine(::testing::ValuesIn(test::kPictures),
                                            ::testing::Values("auto", "tolerance", "cut")),
                         [](const auto& info) {
                           return fs::path(std::get<0>(info.param)).stem().string() + "_" + std::get<1>(info.param);
                         });
}  // namespace
}  // namespace hk::app
