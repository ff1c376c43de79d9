// Levels from hand speed on real pictures: a raster whose rows alternate slow
// and fast makes the level change many times; no move of the proxy crosses the polyline of the level in
// force, no level change leaves the proxy on the other side of the new polyline than it was of the old
// one (an independent between-region test), and the force never jumps at a change by more than the limit.
// Every picture of tests/data/images, in each level mode, not a sample of them: a picture outside a sample
// (camera) left the proxy between two cut steps' polylines at an open curve's shared end.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "crossing_grid.hpp"
#include "haptics/explorer_hand.hpp"
#include "haptics/hand_path.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/simulation.hpp"
#include "test_paths.hpp"
#include "test_pictures.hpp"

namespace hk {
namespace {

namespace fs = std::filesystem;

/// True when p lies strictly between curve c's polylines at level ids `lo` and `ln` (test::polyline_at: a
/// level's points, or a cut step's joined polyline): an odd number of crossings of the ray p → +x with the loop
/// old polyline → new polyline reversed; for an open curve the loop is closed by the two short joins between
/// the polylines' end points. Brute force over all segments, independent of the solver's trees.
bool between_levels(const Scene& sc, std::size_t c, int lo, int ln, Vec2 p) {
  const CurveInfo& ci = sc.curve(c);
  const std::vector<Vec2> po = test::polyline_at(sc, c, lo);
  const std::vector<Vec2> pn = test::polyline_at(sc, c, ln);
  if (po == pn) return false;
  int crossings = 0;
  auto edge = [&](Vec2 a, Vec2 b) {
    if ((a.y > p.y) == (b.y > p.y)) return;
    const double x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
    if (x > p.x) ++crossings;
  };
  for (const std::vector<Vec2>* pts : {&po, &pn}) {
    const std::size_t n = pts->size();
    for (std::size_t i = 0; i + 1 < n; ++i) edge((*pts)[i], (*pts)[i + 1]);
    if (ci.closed && n > 1) edge((*pts)[n - 1], (*pts)[0]);
  }
  if (!ci.closed) {
    edge(po.front(), pn.front());
    edge(po.back(), pn.back());
  }
  return crossings % 2 == 1;
}

class LevelChanges : public ::testing::TestWithParam<const char*> {};

/// The model hand of a run: the raster whose rows alternate slow and fast, or the visitor-like explorer
/// (sweeps, traces outlines, pushes through walls; haptics/explorer_hand.hpp), 60 s of it.
enum class Hand { Raster, Explorer };

// A run over picture `name` with levels from hand speed (`level_mode` "auto": levels; "tolerance":
// tolerance steps, each curve at its own level; "cut": cut steps), checked as the file's comment says. A
// push-through (the explorer presses through walls) is a crossing on purpose: its tick's moves are not
// counted, nor the force's fade after it (pop_release_s, steeper than the level-change step by design).
void level_changes_hold(const char* name, const std::string& level_mode, Hand which) {
  config::Settings s;
  s.haptics.level_mode = level_mode;
  s.hand.max_force_n = 2.0;  // a visitor's push, under the device's clamp, so force steps are visible
  s.vision.ocr = "off";      // the level policy is under test: every curve of a page stays, whatever OCR reads
  const std::string path = std::string(HK_TEST_DATA_DIR) + "/images/" + name;
  const app::ImageScene is = app::build_image_scene(path, s);
  const Scene& sc = *is.scene;
  ASSERT_GT(sc.curve_count(), 0u);
  const HandPath hand =
      raster_path_with_line_speeds(s.workspace.width_m, s.workspace.height_m, 0.008, {0.03, 0.3}, 0.03);
  ExplorerHand explorer(app::explorer_params_from(s, 7));
  const long release_ticks = std::lround(s.haptics.pop_release_s * s.haptics.servo_rate_hz);

  // One crossing grid per level id in force (levels, tolerance steps or cut steps), built when first needed.
  std::map<int, std::unique_ptr<test::CrossingGrid>> grid_of;
  auto grid = [&](int id) -> test::CrossingGrid& {
    auto& g = grid_of[id];
    if (!g) g = std::make_unique<test::CrossingGrid>(sc, id);
    return *g;
  };
  long tolerance_ticks = 0, cut_ticks = 0;
  const double k = s.haptics.stiffness_n_per_m;
  const double step = s.haptics.level_max_force_step_n;

  int prev_transition = -1;
  long transition_ticks = 0, waiting = 0, changes = 0, finer = 0, coarser = 0, crossings = 0, wrong_side = 0,
       force_steps = 0, contact_changes = 0;
  int prev_level = -1;
  Vec2 prev_force, prev_handle, prev_gap;
  bool prev_unclamped = false;
  long pops = 0, release_left = 0;
  const app::TickObserver observe = [&](const app::ServoTick& r, const ServoOutput& so) {
    const ContactOutput& c = so.contact;
    const bool pop = (c.events & kEventPopThrough) != 0;
    pops += pop;
    release_left = pop ? release_ticks + 1 : std::max(0L, release_left - 1);  // the fade's ticks and the one it ends on
    // Every move of the proxy this tick, against the polyline of the level in force this tick.
    // Just after a change the old level is a wall too, until the proxy has left it: nor may it be crossed.
    const int old_wall = so.level_changed ? prev_level : prev_transition;
    for (int m = 1; m < c.path_count && !pop; ++m) {
      crossings += grid(so.level).crossings(c.path_m[m - 1], c.path_m[m]);
      if (old_wall >= 0) crossings += grid(old_wall).crossings(c.path_m[m - 1], c.path_m[m]);
    }
    tolerance_ticks += is_tolerance_level(so.level);
    cut_ticks += is_cut_level(so.level);
    transition_ticks += old_wall >= 0;
    prev_transition = c.transition_level;
    waiting += so.level != so.level_wanted;
    if (so.level_changed) {
      ++changes;
      (so.level < prev_level ? finer : coarser) += 1;
      contact_changes += c.state != ContactState::Free;
      // Where the proxy was when the change was made: on the same side of the new polyline as of the old.
      for (std::size_t cv = 0; cv < sc.curve_count(); ++cv)
        wrong_side += between_levels(sc, cv, prev_level, so.level, c.path_m[0]);
    }
    // The force may jump at a change by no more than the configured step (plus what the hand's own motion
    // does: stiffness × its displacement) ...
    if (so.level_changed && r.index > 0 && release_left == 0) {
      if (distance(so.force_n, prev_force) > step + k * distance(r.sample.handle_m, prev_handle) + 1e-9) ++force_steps;
    }
    // ... and the force leaves the spring law of the new level (stiffness × (proxy − handle)) only by a
    // difference made at the change tick that then shrinks by at most the step per tick (unclamped ticks
    // after the start-up ramp).
    const Vec2 spring = k * (c.proxy_m - r.sample.handle_m);
    const Vec2 gap = so.force_n - spring;
    const bool unclamped =
        length(spring) < s.haptics.max_force_n - 1e-6 && length(so.force_n) < s.haptics.max_force_n - 1e-6;
    if (!so.level_changed && unclamped && prev_unclamped && release_left == 0 && r.t_s > s.haptics.force_ramp_s &&
        distance(gap, prev_gap) > step + 1e-9) {
      ++force_steps;
    }
    prev_gap = gap;
    prev_unclamped = unclamped;
    prev_level = so.level;
    prev_force = so.force_n;
    prev_handle = r.sample.handle_m;
  };
  const long ticks = which == Hand::Explorer ? app::run_simulation(sc, s, explorer, 60.0, observe)
                                             : app::run_simulation(sc, s, hand, hand.duration_s(), observe);
  ::testing::Test::RecordProperty("level_changes", std::to_string(changes));
  ::testing::Test::RecordProperty("ticks_waiting", std::to_string(waiting));
  ::testing::Test::RecordProperty("ticks_with_two_levels", std::to_string(transition_ticks));
  EXPECT_GE(changes, 10) << "the fast rows must coarsen and the slow rows refine the level";
  EXPECT_GT(finer, 3);
  EXPECT_GT(coarser, 3);
  // LinuxLogo (six outlines far apart) in cut mode makes every change while the proxy is free.
  if (!(fs::path(path).stem() == "LinuxLogo" && level_mode == "cut")) {
    EXPECT_GT(contact_changes, 0) << "some changes must happen while the proxy is on a wall";
  }
  EXPECT_EQ(crossings, 0);
  EXPECT_EQ(wrong_side, 0);
  EXPECT_EQ(force_steps, 0);
  if (which == Hand::Explorer) {
    EXPECT_GT(pops, 0) << "the explorer pushes through walls";
  }
  // The mode decides what the policy picks: tolerance steps (or cut steps) on every tick, or never.
  EXPECT_EQ(tolerance_ticks, level_mode == "tolerance" ? ticks : 0) << "level_mode " << level_mode;
  EXPECT_EQ(cut_ticks, level_mode == "cut" ? ticks : 0) << "level_mode " << level_mode;
}

TEST_P(LevelChanges, FastAndSlowRasterChangesLevelsWithoutCrossingOrForceSteps) {
  level_changes_hold(GetParam(), "auto", Hand::Raster);
}

// The policy picks a tolerance instead of a level; the same crossing checks stay at 0.
TEST_P(LevelChanges, FastAndSlowRasterChangesToleranceStepsWithoutCrossingOrForceSteps) {
  level_changes_hold(GetParam(), "tolerance", Hand::Raster);
}

// The policy picks a tolerance and the walls are its cut, refined per segment and joined where the
// level changes; the same crossing checks stay at 0 (against the joined polylines).
TEST_P(LevelChanges, FastAndSlowRasterChangesCutStepsWithoutCrossingOrForceSteps) {
  level_changes_hold(GetParam(), "cut", Hand::Raster);
}

// The visitor-like explorer in each mode: it reaches level changes the raster does not (on sudoku, one that
// left the proxy between two levels of a curve crossing the one it slid on).
TEST_P(LevelChanges, ExplorerChangesLevelsWithoutCrossingOrForceSteps) {
  level_changes_hold(GetParam(), "auto", Hand::Explorer);
}
TEST_P(LevelChanges, ExplorerChangesToleranceStepsWithoutCrossingOrForceSteps) {
  level_changes_hold(GetParam(), "tolerance", Hand::Explorer);
}
TEST_P(LevelChanges, ExplorerChangesCutStepsWithoutCrossingOrForceSteps) {
  level_changes_hold(GetParam(), "cut", Hand::Explorer);
}

INSTANTIATE_TEST_SUITE_P(RealImages, LevelChanges, ::testing::ValuesIn(test::kPictures),
                         [](const auto& info) { return fs::path(info.param).stem().string(); });

}  // namespace
}  // namespace hk
