// The servo tick on large scenes: the tick in the headless run, whose target is p99.9 ≤ 10 µs on a tiled
// scene of 10^6 segments.
//
// Usage: bench_servo_tick [--sizes 1000,10000,100000,1000000] [--seconds S] [--repeats R] [--cpu N]
//                         [--level-mode auto|tolerance|cut|fixed] [--out FILE.json]   (prints a markdown table)
//
// Each size is a tiled scene (bench_scenes.hpp: whole test pictures side by side at the workspace scale,
// at least that many level-0 segments, centred on the workspace origin), built with the default settings'
// levels. On it runs the headless servo loop of `explore` (app::run_simulation: the simulated pantograph,
// a model hand, the servo step timed alone by steady_clock, exactly as trace.csv's tick_ns), for S seconds
// of simulated time at 1 kHz, with two hands:
//   raster    the default explore hand: a boustrophedon over the workspace, pushing blind into walls;
//   explorer  the visitor-like hand (`--hand explorer`): sweeps, traces outlines, pushes through.
// The pantograph reaches the workspace (the middle of the plane); the rest of the scene is in the tree the
// tick descends. Each (size, hand) runs R times with the same seed: the runs are the same ticks on the same
// inputs (checked: every tick's handle position must repeat bit for bit, else the bench fails). The table
// gives each run's tick time p50 / p99 / p99.9 / max, and a last row "min of R" whose tick times are each
// tick's fastest of the R runs: what the tick costs without the host's interrupts, preemptions and the
// other core's cache traffic, which land on different ticks in each run (a single run's p99.9 is its
// 30th-worst tick of 30 000, and on this shared VM one interrupt costs 20-100 µs). Both are written down;
// the target is judged on both. --cpu pins the thread to one CPU (sched_setaffinity). --level-mode sets
// [haptics] level_mode (default "auto", the target's; "cut": the walls at the tolerance cut). Before the runs of
// each size it times the servo loop's setup on that scene (SceneStep's constructor, fastest of R), printed on
// stderr and written to the JSON as loop_setup_ms.
#include <sched.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench_scenes.hpp"
#include "haptics/explorer_hand.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/runtime_params.hpp"

using namespace hk;
using namespace hk::bench;

namespace {

/// Tick times and what the ticks did, of one run.
struct RunFigures {
  long ticks = 0;
  double p50_ns = 0, p99_ns = 0, p999_ns = 0, max_ns = 0;
  double contact_fraction = 0;  ///< ticks in edge or vertex contact / ticks
  double mean_level = 0;        ///< level in use, averaged over ticks
};

double quantile(std::vector<std::int64_t>& v, double q) {
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return static_cast<double>(v[k]);
}

/// One run's tick times [ns] and handle positions [m], tick by tick.
struct RunTrace {
  std::vector<std::int64_t> ns;
  std::vector<Vec2> handle_m;
  RunFigures figures;
};

/// Quantiles of tick times `ns` [ns] (reordered), with the contact and level figures left as they are.
void fill_quantiles(std::vector<std::int64_t> ns, RunFigures& f) {
  f.ticks = static_cast<long>(ns.size());
  if (ns.empty()) return;
  f.max_ns = static_cast<double>(*std::max_element(ns.begin(), ns.end()));
  f.p50_ns = quantile(ns, 0.5);
  f.p99_ns = quantile(ns, 0.99);
  f.p999_ns = quantile(ns, 0.999);
}

RunTrace run_once(const Scene& scene, const config::Settings& s, const std::string& hand, double seconds,
                  std::uint64_t seed) {
  RunTrace t;
  std::vector<std::int64_t>& ns = t.ns;
  ns.reserve(static_cast<std::size_t>(seconds * 1000.0) + 1);
  t.handle_m.reserve(ns.capacity());
  long contact = 0;
  double level_sum = 0;
  const app::TickObserver observe = [&](const app::ServoTick& r, const ServoOutput& so) {
    ns.push_back(r.step_ns);
    t.handle_m.push_back(r.sample.handle_m);
    contact += so.contact.state != ContactState::Free ? 1 : 0;
    level_sum += so.level;
  };
  if (hand == "raster") {
    const HandPath path =
        raster_path(s.workspace.width_m, s.workspace.height_m, s.hand.raster_spacing_m, s.hand.raster_speed_m_per_s);
    app::run_simulation(scene, s, path, std::min(seconds, path.duration_s()), observe);
  } else {
    ExplorerHand explorer(app::explorer_params_from(s, seed));
    app::run_simulation(scene, s, explorer, seconds, observe);
  }
  RunFigures& f = t.figures;
  if (!ns.empty()) {
    f.contact_fraction = static_cast<double>(contact) / static_cast<double>(ns.size());
    f.mean_level = level_sum / static_cast<double>(ns.size());
  }
  fill_quantiles(ns, f);
  return t;
}

void print_row(std::size_t segments, const std::string& hand, const std::string& run, const RunFigures& f) {
  std::printf("| %zu | %s | %s | %ld | %.0f %% | %.2f | %.2f | %.2f | %.2f | %.1f |\n", segments, hand.c_str(),
              run.c_str(), f.ticks, 100.0 * f.contact_fraction, f.mean_level, f.p50_ns / 1e3, f.p99_ns / 1e3,
              f.p999_ns / 1e3, f.max_ns / 1e3);
  std::fflush(stdout);
}

nlohmann::json to_json(const RunFigures& f) {
  return {{"ticks", f.ticks},           {"contact_fraction", f.contact_fraction},
          {"mean_level", f.mean_level}, {"p50_ns", f.p50_ns},
          {"p99_ns", f.p99_ns},         {"p999_ns", f.p999_ns},
          {"max_ns", f.max_ns}};
}

/// Time to set up the servo loop on `scene` with the settings' servo parameters (its two solvers' boundary
/// sections, and in cut mode the cut masks), the fastest of `repeats` [ms]: what a scene change costs the
/// servo thread's setup before the first tick.
double loop_setup_ms(const Scene& scene, const config::Settings& s, int repeats) {
  const ServoParams params = app::servo_params_from(s);
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const SceneStep loop(scene, params);
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"Servo tick time of the headless run on tiled scenes of growing size"};
  std::vector<std::size_t> sizes{1000, 10000, 100000, 1000000};
  double seconds = 30.0;
  int repeats = 3, cpu = -1;
  std::string out_path;
  std::string level_mode = "auto";
  cli.add_option("--sizes", sizes, "level-0 segments of each tiled scene")->delimiter(',')->check(CLI::PositiveNumber);
  cli.add_option("--seconds", seconds, "simulated seconds per run (the raster stops at its path's end)")
      ->check(CLI::Range(0.1, 3600.0));
  cli.add_option("--repeats", repeats, "runs per size and hand")->check(CLI::Range(1, 100));
  cli.add_option("--cpu", cpu, "pin to this CPU (-1: leave it to the scheduler)");
  cli.add_option("--out", out_path, "JSON results");
  cli.add_option("--level-mode", level_mode, "[haptics] level_mode of the runs")
      ->check(CLI::IsMember({"auto", "tolerance", "cut", "fixed"}));
  CLI11_PARSE(cli, argc, argv);
  if (cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    if (sched_setaffinity(0, sizeof set, &set) != 0)
      std::fprintf(stderr, "bench_servo_tick: cannot pin to CPU %d; running unpinned\n", cpu);
  }

  config::Settings settings;
  settings.haptics.level_mode = level_mode;
  const auto pictures = picture_curves(settings);
  nlohmann::json out = nlohmann::json::array();
  std::printf(
      "| segments | hand | run | ticks | in contact | mean level | tick p50 µs | p99 µs | p99.9 µs | max µs |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::size_t n : sizes) {
    Vec2 plane{};
    const Scene scene =
        Scene::build(tiled_scene(pictures, n, settings.haptics.max_levels, &plane), settings.haptics.max_levels);
    const std::size_t level0 = scene.total_segments(0);
    const double setup_ms = loop_setup_ms(scene, settings, repeats);
    std::fprintf(stderr, "bench_servo_tick: %zu segments, level_mode %s: SceneStep setup %.1f ms (fastest of %d)\n",
                 level0, level_mode.c_str(), setup_ms, repeats);
    for (const std::string hand : {"raster", "explorer"}) {
      std::vector<double> p999s;
      nlohmann::json runs = nlohmann::json::array();
      RunTrace first;
      std::vector<std::int64_t> fastest;
      for (int r = 0; r < repeats; ++r) {
        RunTrace t = run_once(scene, settings, hand, seconds, 1);
        p999s.push_back(t.figures.p999_ns);
        print_row(level0, hand, std::to_string(r + 1), t.figures);
        runs.push_back(to_json(t.figures));
        if (r == 0) {
          fastest = t.ns;
          first = std::move(t);
          continue;
        }
        if (t.handle_m != first.handle_m) {
          std::fprintf(stderr, "bench_servo_tick: run %d of %s on %zu segments did not repeat run 1's ticks\n", r + 1,
                       hand.c_str(), level0);
          return 1;
        }
        for (std::size_t k = 0; k < fastest.size(); ++k) fastest[k] = std::min(fastest[k], t.ns[k]);
      }
      RunFigures min_f = first.figures;
      fill_quantiles(fastest, min_f);
      print_row(level0, hand, "min of " + std::to_string(repeats), min_f);
      std::sort(p999s.begin(), p999s.end());
      out.push_back({{"segments", level0},
                     {"requested_segments", n},
                     {"plane_m", {plane.x, plane.y}},
                     {"hand", hand},
                     {"level_mode", level_mode},
                     {"hot_bytes", scene.hot_bytes()},
                     {"loop_setup_ms", setup_ms},
                     {"median_p999_ns", p999s[p999s.size() / 2]},
                     {"runs", runs},
                     {"per_tick_min", to_json(min_f)}});
    }
  }
  if (!out_path.empty()) {
    std::ofstream f(out_path);
    if (!f) {
      std::fprintf(stderr, "bench_servo_tick: cannot write %s\n", out_path.c_str());
      return 1;
    }
    f << out.dump(1) << "\n";
  }
  return 0;
}
