// The grooves rendering mode end to end: on real pictures the force stays continuous
// (no step beyond stiffness × the handle's own motion, plus the per-tick jump allowance where the closest
// point jumps), levels still follow the hand's speed, and `explore` with [haptics] render = "grooves"
// writes a trace whose proxy columns hold the closest point, with contact 1 exactly within the capture
// radius (checked against a brute-force distance to scene.json's polylines) and no force in free space.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "cli/explore.hpp"
#include "haptics/hand_path.hpp"
#include "pictures/image_scene.hpp"
#include "runtime/simulation.hpp"
#include "test_paths.hpp"
#include "test_pictures.hpp"

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace hk;

namespace {

const std::string kImages = std::string(HK_TEST_DATA_DIR) + "/images/";

config::Settings groove_settings() {
  config::Settings s;
  s.haptics.render = "grooves";
  s.haptics.level_mode = "auto";
  return s;
}

struct Continuity {
  long ticks = 0, contact_ticks = 0, over_limit = 0, level_changes = 0;
  double worst_excess_n = 0;  // max over ticks of |ΔF| − k·|Δh| [N]
};

Continuity run_and_check(const Scene& sc, const config::Settings& s, const HandPath& hand, double seconds) {
  const double k = s.haptics.stiffness_n_per_m, jump = s.haptics.level_max_force_step_n;
  Continuity c;
  Vec2 prev_f{0, 0}, prev_h;
  bool first = true;
  app::run_simulation(sc, s, hand, seconds, [&](const app::ServoTick& r, const ServoOutput& so) {
    if (first) prev_h = r.sample.handle_m;
    first = false;
    const double df = distance(so.force_n, prev_f), lip = k * distance(r.sample.handle_m, prev_h);
    c.over_limit += df > lip + jump + 1e-9;
    c.worst_excess_n = std::max(c.worst_excess_n, df - lip);
    c.contact_ticks += so.contact.state != ContactState::Free;
    c.level_changes += so.level_changed;
    ++c.ticks;
    prev_f = so.force_n;
    prev_h = r.sample.handle_m;
  });
  return c;
}

}  // namespace

TEST(GroovesOnPictures, ForceContinuousOnRastersFastAndSlow) {
  for (const char* name : {"horse.png", "sudoku.png"}) {
    config::Settings s = groove_settings();
    s.haptics.force_ramp_s = 0.0;  // the start-up ramp grows the guard's clamp: keep it out of the force steps measured
    const app::ImageScene is = app::build_image_scene(kImages + name, s);
    ASSERT_GT(is.scene->curve_count(), 0u) << name;
    const double w = s.workspace.width_m, h = s.workspace.height_m;
    const HandPath fast = raster_path(w, h, s.hand.raster_spacing_m, 0.08);
    const Continuity cf = run_and_check(*is.scene, s, fast, fast.duration_s());
    EXPECT_GT(cf.contact_ticks, 500) << name;
    EXPECT_EQ(cf.over_limit, 0) << name << " at 0.08 m/s: worst |ΔF| − k|Δh| = " << cf.worst_excess_n << " N";
    const HandPath slow = raster_path(w, h, 0.011, 0.01);
    const Continuity cs = run_and_check(*is.scene, s, slow, 25.0);
    EXPECT_GT(cs.contact_ticks, 500) << name;
    EXPECT_EQ(cs.over_limit, 0) << name << " at 0.01 m/s: worst |ΔF| − k|Δh| = " << cs.worst_excess_n << " N";
  }
}

TEST(GroovesOnPictures, LevelsFollowHandSpeed) {
  const config::Settings s = groove_settings();
  const app::ImageScene is = app::build_image_scene(kImages + "horse.png", s);
  const HandPath hand =
      raster_path_with_line_speeds(s.workspace.width_m, s.workspace.height_m, 0.008, {0.03, 0.3}, 0.03);
  const Continuity c = run_and_check(*is.scene, s, hand, std::min(40.0, hand.duration_s()));
  EXPECT_GE(c.level_changes, 2) << "auto levels change with hand speed in grooves mode";
  EXPECT_GT(c.contact_ticks, 0);
  EXPECT_EQ(c.over_limit, 0) << "worst |ΔF| − k|Δh| = " << c.worst_excess_n << " N";
}

namespace {

double seg_distance(double px, double py, double ax, double ay, double bx, double by) {
  const double dx = bx - ax, dy = by - ay, l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / l2 : 0.0;
  t = std::max(0.0, std::min(1.0, t));
  return std::hypot(px - (ax + t * dx), py - (ay + t * dy));
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> v;
  std::stringstream ss(line);
  std::string f;
  while (std::getline(ss, f, ',')) v.push_back(f);
  return v;
}

}  // namespace

TEST(GroovesExplore, TraceHoldsTheClosestPointAndContactWithinTheRadius) {
  const fs::path dir = fs::temp_directory_path() / ("hk_test_grooves_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path cfg = dir / "grooves.toml";
  std::ofstream(cfg) << "[haptics]\nrender = \"grooves\"\n";
  app::ExploreOptions o;
  o.image_path = kImages + "horse.png";
  o.out_dir = (dir / "out").string();
  o.config_path = cfg.string();
  o.duration_s = 12.0;
  const app::ExploreSummary sum = app::run_explore(o);
  EXPECT_GT(sum.edge_ticks, 0);
  EXPECT_EQ(sum.vertex_ticks, 0) << "grooves have no vertex contact";

  const config::Settings defaults;
  const double R = defaults.haptics.groove_capture_radius_m;
  json scene;
  std::ifstream(dir / "out" / "scene.json") >> scene;
  // Per level: every segment of every curve at that level (clamped to the curve's coarsest), as in the solver.
  struct Seg {
    double ax, ay, bx, by;
  };
  std::vector<std::vector<Seg>> segs(16);
  for (int l = 0; l < 16; ++l) {
    for (const json& c : scene["curves"]) {
      const int top = static_cast<int>(c["levels"].size()) - 1;
      const json& pts = c["levels"][std::min(l, top)]["points_m"];
      const std::size_t n = pts.size();
      for (std::size_t i = 0; i + 1 < n + (c["closed"].get<bool>() ? 1 : 0); ++i) {
        const json& a = pts[i];
        const json& b = pts[(i + 1) % n];
        segs[static_cast<std::size_t>(l)].push_back(
            {a[0].get<double>(), a[1].get<double>(), b[0].get<double>(), b[1].get<double>()});
      }
    }
  }

  std::ifstream trace(dir / "out" / "trace.csv");
  std::string line;
  std::getline(trace, line);
  const std::vector<std::string> head = split(line);
  ASSERT_GE(head.size(), 11u);
  ASSERT_EQ(head[3], "proxy_x_m");
  ASSERT_EQ(head[7], "contact");
  long pops = 0, rows = 0, contact_rows = 0, wrong_contact = 0, wrong_proxy = 0, free_force = 0, checked = 0;
  while (std::getline(trace, line)) {
    const std::vector<std::string> f = split(line);
    ASSERT_GE(f.size(), 11u);
    ++rows;
    const double hx = std::stod(f[1]), hy = std::stod(f[2]), px = std::stod(f[3]), py = std::stod(f[4]);
    const double fx = std::stod(f[5]), fy = std::stod(f[6]);
    const int contact = std::stoi(f[7]), level = std::stoi(f[9]);
    ASSERT_TRUE(level >= 0 && level < 16) << line;
    contact_rows += contact == 1;
    if (head.size() > 11 && head[11] == "pop") pops += std::stoi(f[11]);
    ASSERT_NE(contact, 2) << line;
    if (contact == 0) {
      free_force += std::hypot(fx, fy) > 1e-9;
      if (!(px == hx && py == hy)) ++wrong_proxy;  // free: the proxy is the handle
    }
    if (rows % 3 != 0) continue;  // the brute-force distance on every third row
    double d = 1e9;
    for (const Seg& s : segs[static_cast<std::size_t>(level)])
      d = std::min(d, seg_distance(hx, hy, s.ax, s.ay, s.bx, s.by));
    if (std::fabs(d - R) < 1e-7) continue;  // on the rim, within the trace's rounding
    ++checked;
    if ((contact == 1) != (d < R)) ++wrong_contact;
    if (contact == 1 && std::fabs(std::hypot(hx - px, hy - py) - d) > 1e-7) ++wrong_proxy;  // the closest point
  }
  EXPECT_GT(rows, 11000);
  EXPECT_GT(contact_rows, 100);
  EXPECT_GT(checked, 3000);
  EXPECT_EQ(wrong_contact, 0) << "contact == 1 iff the handle is within the capture radius of the level's polylines";
  EXPECT_EQ(wrong_proxy, 0) << "proxy columns: the closest point in contact, the handle when free";
  EXPECT_EQ(free_force, 0) << "no force in free space";
  EXPECT_EQ(pops, 0) << "nothing is pushed through a groove";

  json summary;
  std::ifstream(dir / "out" / "summary.json") >> summary;
  EXPECT_EQ(summary["contact_ticks"]["edge"].get<long>(), contact_rows);
  EXPECT_TRUE(fs::exists(dir / "out" / "overlay.png"));
  fs::remove_all(dir);
}

// Grooves under every level mode that moves with the hand's speed (levels, tolerance steps, the
// tolerance cut), on every picture: the raster whose rows alternate slow and fast changes the level (or step)
// many times, and the force stays within stiffness × the handle's own motion plus the per-tick jump
// allowance throughout (3.5 s for the 66 runs).
class GroovesLevelModes : public ::testing::TestWithParam<std::tuple<const char*, const char*>> {};

TEST_P(GroovesLevelModes, ForceContinuousWhileLevelsFollowHandSpeed) {
  config::Settings s = groove_settings();
  s.haptics.level_mode = std::get<1>(GetParam());
  s.haptics.force_ramp_s = 0.0;  // as above: the start-up ramp is not a force step
  const app::ImageScene is = app::build_image_scene(kImages + std::get<0>(GetParam()), s);
  ASSERT_GT(is.scene->curve_count(), 0u);
  const HandPath hand =
      raster_path_with_line_speeds(s.workspace.width_m, s.workspace.height_m, 0.008, {0.03, 0.3}, 0.03);
  const Continuity c = run_and_check(*is.scene, s, hand, hand.duration_s());
  RecordProperty("level_changes", std::to_string(c.level_changes));
  EXPECT_GE(c.level_changes, 10) << "the fast rows coarsen and the slow rows refine";
  EXPECT_GT(c.contact_ticks, 1000) << "the raster crosses the grooves";
  EXPECT_EQ(c.over_limit, 0) << "worst |ΔF| − k|Δh| = " << c.worst_excess_n << " N";
}

INSTANTIATE_TEST_SUITE_P(RealImages, GroovesLevelModes,
                         ::testing::Combine(::testing::ValuesIn(test::kPictures),
                                            ::testing::Values("auto", "tolerance", "cut")),
                         [](const auto& info) {
                           return fs::path(std::get<0>(info.param)).stem().string() + "_" + std::get<1>(info.param);
                         });
