// Anytime chart (box-test budgets): with box-test budgets from 8 to 4096
// (QueryBudget: the servo's work limit, no clock), which level does a cold query reach, what does that
// level cost in accuracy, and how long does it take? "Cold" = the boundary section starts at the scene
// root, as after a new picture or a level change; a warm section (every other tick) rarely needs
// refining and no budget bites. Queries sweep 2–20 mm from a random point towards a point of the
// curves, so almost all of them end in a wall.
// Output JSON: per scene and budget — fraction answered exactly at level 0, mean level reached,
// mean and max of the reached level's max error [mm], p50/p99 query time [ns], mean box tests per query,
// and ns per box test (total time / total box tests): the figure ServoParams::query_box_budget's default
// is chosen from (kDefaultQueryBoxBudget, haptics/servo.hpp).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "bench_scenes.hpp"

using namespace hk;
using namespace hk::bench;

namespace {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::vector<Sweep> cold_sweeps(const Scene& sc, std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> pick_curve(0, sc.curve_count() - 1);
  std::uniform_real_distribution<double> len(0.002, 0.02), ang(0.0, 2 * M_PI);
  std::vector<Sweep> out;
  while (out.size() < n) {
    const std::size_t c = pick_curve(rng);
    const CurveInfo& ci = sc.curve(c);
    std::uniform_int_distribution<std::uint32_t> pick_pt(0, ci.point_count[0] - 1);
    const Vec2 target = sc.points(c, 0)[pick_pt(rng)];
    const double a = ang(rng), l = len(rng);
    const Vec2 start = target + l * Vec2{std::cos(a), std::sin(a)};
    out.push_back({start, target + 0.0005 * Vec2{-std::cos(a), -std::sin(a)}});  // end just past the curve
  }
  return out;
}

nlohmann::json run(const std::string& name, const Scene& sc, const std::vector<Sweep>& sweeps) {
  nlohmann::json rows = nlohmann::json::array();
  BoundarySection section(sc);
  for (std::int32_t box_budget : {8, 16, 32, 64, 128, 256, 512, 1024, 4096, 0}) {
    std::vector<double> ns;
    double level_sum = 0, err_sum = 0, err_max = 0, ns_total = 0, boxes_total = 0;
    std::size_t exact = 0;
    for (const Sweep& s : sweeps) {
      section.reset();
      QueryBudget budget;
      budget.max_box_tests = box_budget;
      QueryStats st;
      const std::int64_t t0 = now_ns();
      const SweepHit h = section.first_hit(s.a, s.b, 0, nullptr, 0, budget, &st);
      ns.push_back(static_cast<double>(now_ns() - t0));
      ns_total += ns.back();
      boxes_total += st.box_tests;
      // Level reached: 0 when exact; otherwise the level of the box the answer stopped at (a box above
      // every curve counts as one level above the curve's coarsest).
      int level = 0;
      double err_m = 0.0;
      if (h.blocked) {
        if (h.segment.curve >= 0) {
          const CurveInfo& ci = sc.curve(static_cast<std::size_t>(h.segment.curve));
          level = std::min(h.segment.level, ci.levels - 1);
          err_m = ci.max_error_bound_m[level];
        } else {
          level = Scene::kMaxLevels;
          err_m = 0.01;  // no curve reached: the answer knows only a region (counted as 10 mm)
        }
      } else {
        ++exact;
      }
      level_sum += level;
      err_sum += err_m * 1e3;
      err_max = std::max(err_max, err_m * 1e3);
    }
    std::sort(ns.begin(), ns.end());
    const double n = static_cast<double>(sweeps.size());
    const double ns_per_box = boxes_total > 0 ? ns_total / boxes_total : 0.0;
    rows.push_back({{"box_budget", box_budget},
                    {"exact_fraction", exact / n},
                    {"mean_level", level_sum / n},
                    {"mean_error_mm", err_sum / n},
                    {"max_error_mm", err_max},
                    {"p50_ns", ns[ns.size() / 2]},
                    {"p99_ns", ns[static_cast<std::size_t>(0.99 * (n - 1))]},
                    {"mean_box_tests", boxes_total / n},
                    {"ns_per_box_test", ns_per_box}});
    std::fprintf(stderr,
                 "anytime %s budget %d box tests: exact %.3f, mean level %.2f, mean error %.3f mm, %.0f box tests, "
                 "%.1f ns per box test\n",
                 name.c_str(), box_budget, exact / n, level_sum / n, err_sum / n, boxes_total / n, ns_per_box);
  }
  return {{"scene", name}, {"segments", sc.total_segments(0)}, {"rows", rows}};
}

}  // namespace

int main(int argc, char** argv) {
  std::string out_path = "anytime.json";
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--out") out_path = argv[i + 1];
  }
  const config::Settings s;
  const auto pictures = picture_curves(s);
  nlohmann::json all = nlohmann::json::array();
  const auto paths = picture_paths();
  for (std::size_t i = 0; i < paths.size(); ++i) {
    if (paths[i].stem() != "sudoku" && paths[i].stem() != "horse") continue;
    const Scene sc = Scene::build(pictures[i], s.haptics.max_levels);
    all.push_back(run(paths[i].stem().string(), sc, cold_sweeps(sc, 20000, 3)));
  }
  for (std::size_t n : {100000u, 1000000u}) {
    Vec2 plane;
    const Scene sc = Scene::build(tiled_scene(pictures, n, s.haptics.max_levels, &plane), s.haptics.max_levels);
    all.push_back(run("tiled " + std::to_string(n), sc, cold_sweeps(sc, 20000, 4)));
  }
  std::ofstream(out_path) << all.dump(2) << "\n";
  return 0;
}
