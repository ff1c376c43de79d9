// Where first_hit's time goes: the servo path's query (the boundary section, seed §3) on the
// random-walk stream of bench_first_hit's tiled scenes, its queries sorted by kind, each query's cost the
// fastest of several replays of the whole stream, so the host's stalls and neighbours' cache traffic drop out
// and two builds can be compared on a noisy machine.
//
// Usage: bench_section_cost [--segments N ...] [--replays R] [--queries Q]
//   --segments  scene sizes, level-0 segments (default 100000)
//   --replays   replays of the stream per size; each query's fastest is kept (default 5)
//   --queries   sweeps in the stream (default 100000, as bench_first_hit)
//
// The same stream from a new section each replay, so every replay does the same work query for query
// (checked: the box tests per query agree), and the first replay's answers equal the R-tree's (else it stops with
// the query). Each query is timed on its own with steady_clock, so every figure
// includes one clock pair (the `clock` line: an empty region timed the same way). Kinds:
//   ball         answered by the free-space ball (no box test but, while full queries owe merge checks, one or two)
//   walls        answered by the ball's walls (a few segment tests; no box test but the merge checks, as a ball tick)
//   full         every other query; of those:
//     quiet        no split and no merge
//     split        at least one split (the section refined toward the sweep; the p99 lives here)
//     merge only   merges and no split
//   top 1 %      the slowest 1 % of all queries, whatever their kind; then those of them by kind (quiet, split and
//                merge only among the full queries, and the others)
// For each: how many, mean and p50 [ns], and the mean work (box tests, section entries scanned, splits, merges,
// section size, segment tests). Prints a markdown table per size, and how many full queries came right after a
// full query (the hand near walls tick after tick: work a full query leaves for the ticks after it lands on the
// next full query that often).
#include <benchmark/benchmark.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "bench_scenes.hpp"
#include "peers.hpp"

using namespace hk;
using namespace hk::bench;

namespace {

using Clock = std::chrono::steady_clock;

struct Sample {
  double ns = 0;  // fastest over the replays [ns]
  QueryStats st;  // the work (the same in every replay)
};

// Mean cost of an empty timed region [ns], the fastest of three rounds of 2^16.
double clock_pair_ns() {
  double best = 1e300;
  for (int round = 0; round < 3; ++round) {
    double sum = 0;
    for (int i = 0; i < (1 << 16); ++i) {
      const auto t0 = Clock::now();
      const auto t1 = Clock::now();
      sum += std::chrono::duration<double, std::nano>(t1 - t0).count();
    }
    best = std::min(best, sum / (1 << 16));
  }
  return best;
}

// A new section each replay (reset() keeps the tick count, which the merges' round robin reads). Every answer of
// the first replay is checked against the Boost R-tree over the level-0 segments (itself checked against brute
// force in the tests and in bench_first_hit): a build whose queries are fast because they are wrong stops here.
std::vector<Sample> replay(const Scene& scene, const std::vector<Sweep>& stream, int replays) {
  std::vector<Sample> out(stream.size());
  for (auto& s : out) s.ns = 1e300;
  const std::vector<std::pair<Vec2, Vec2>> segments = flat_segments(scene, 0);
  const RtreeIndex rtree(segments);  // keeps a reference to the segments
  for (int r = 0; r < replays; ++r) {
    BoundarySection section(scene);
    for (std::size_t i = 0; i < stream.size(); ++i) {
      QueryStats st;
      const auto t0 = Clock::now();
      const SweepHit h = section.first_hit(stream[i].a, stream[i].b, 0, nullptr, 0, QueryBudget{}, &st);
      const auto t1 = Clock::now();
      benchmark::DoNotOptimize(h);
      if (r == 0) {
        const PeerHit want = rtree.first_hit(stream[i].a, stream[i].b);
        if (h.hit != want.hit || (want.hit && h.t != want.t)) {
          std::fprintf(stderr, "bench_section_cost: query %zu answers %s t=%.17g, the R-tree %s t=%.17g\n", i,
                       h.hit ? "hit" : "clear", h.t, want.hit ? "hit" : "clear", want.t);
          std::exit(2);
        }
      }
      out[i].ns = std::min(out[i].ns, std::chrono::duration<double, std::nano>(t1 - t0).count());
      if (r > 0 && st.box_tests != out[i].st.box_tests) {
        std::fprintf(stderr, "bench_section_cost: replay %d does other work at query %zu\n", r, i);
        std::exit(1);
      }
      out[i].st = st;
    }
  }
  return out;
}

void print_row(const char* kind, const std::vector<Sample>& all, const std::function<bool(const Sample&)>& pick) {
  std::vector<double> ns;
  double box = 0, scanned = 0, splits = 0, merges = 0, size = 0, seg = 0;
  for (const Sample& s : all) {
    if (!pick(s)) continue;
    ns.push_back(s.ns);
    box += s.st.box_tests;
    scanned += s.st.section_box_tests;
    splits += s.st.splits;
    merges += s.st.merges;
    size += s.st.section_size;
    seg += s.st.segment_tests;
  }
  if (ns.empty()) return;
  const double n = static_cast<double>(ns.size());
  double mean = 0;
  for (double x : ns) mean += x;
  std::nth_element(ns.begin(), ns.begin() + static_cast<std::ptrdiff_t>(ns.size() / 2), ns.end());
  std::printf("| %s | %zu | %.0f | %.0f | %.1f | %.1f | %.2f | %.2f | %.1f | %.2f |\n", kind, ns.size(), mean / n,
              ns[ns.size() / 2], box / n, scanned / n, splits / n, merges / n, size / n, seg / n);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"first_hit's cost by query kind, each query's fastest of several replays"};
  std::vector<std::size_t> sizes{100000};
  int replays = 5;
  std::size_t queries = 100000;
  app.add_option("--segments", sizes, "scene sizes [level-0 segments]");
  app.add_option("--replays", replays, "replays of the stream; each query's fastest is kept")
      ->check(CLI::Range(1, 100));
  app.add_option("--queries", queries, "sweeps in the stream")->check(CLI::Range(1000, 10000000));
  CLI11_PARSE(app, argc, argv);

  const config::Settings settings;
  const auto pictures = picture_curves(settings);
  std::printf("clock pair: %.1f ns (in every figure below)\n", clock_pair_ns());
  for (const std::size_t n : sizes) {
    Vec2 plane;
    const auto curves = tiled_scene(pictures, n, settings.haptics.max_levels, &plane);
    const Scene scene = Scene::build(curves, settings.haptics.max_levels);
    const std::vector<Sample> all = replay(scene, random_walk_stream(plane, queries), replays);
    std::vector<double> sorted;
    for (const Sample& s : all) sorted.push_back(s.ns);
    std::sort(sorted.begin(), sorted.end());
    const auto pct = [&](double p) {
      return sorted[std::min(sorted.size() - 1, static_cast<std::size_t>(p * static_cast<double>(sorted.size())))];
    };
    double mean = 0;
    for (double x : sorted) mean += x;
    mean /= static_cast<double>(sorted.size());
    const double p99 = pct(0.99);
    std::printf(
        "\n%zu segments, %zu queries, fastest of %d: mean %.0f ns, p50 %.0f, p90 %.0f, p99 %.0f, p99.9 %.0f\n\n",
        scene.total_segments(0), all.size(), replays, mean, pct(0.5), pct(0.9), p99, pct(0.999));
    std::printf(
        "| kind | queries | mean ns | p50 ns | box tests | entries scanned | splits | merges | section | segment tests "
        "|\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
    const auto full = [](const Sample& s) { return s.st.section_box_tests > 0; };
    print_row("ball", all, [&](const Sample& s) { return !full(s) && !s.st.ball_walls; });
    print_row("walls", all, [](const Sample& s) { return s.st.ball_walls; });
    print_row("full", all, full);
    print_row("full: quiet", all, [&](const Sample& s) { return full(s) && s.st.splits == 0 && s.st.merges == 0; });
    print_row("full: split", all, [](const Sample& s) { return s.st.splits > 0; });
    print_row("full: merge only", all, [&](const Sample& s) { return full(s) && s.st.splits == 0 && s.st.merges > 0; });
    print_row("top 1 %", all, [&](const Sample& s) { return s.ns >= p99; });
    print_row("top 1 %: quiet", all,
              [&](const Sample& s) { return s.ns >= p99 && full(s) && s.st.splits == 0 && s.st.merges == 0; });
    print_row("top 1 %: split", all, [&](const Sample& s) { return s.ns >= p99 && s.st.splits > 0; });
    print_row("top 1 %: merge only", all,
              [&](const Sample& s) { return s.ns >= p99 && full(s) && s.st.splits == 0 && s.st.merges > 0; });
    print_row("top 1 %: not full", all, [&](const Sample& s) { return s.ns >= p99 && !full(s); });
    std::size_t after_full = 0, full_count = 0;
    for (std::size_t i = 1; i < all.size(); ++i) {
      if (!full(all[i])) continue;
      ++full_count;
      after_full += full(all[i - 1]) ? 1 : 0;
    }
    std::printf("\nfull queries right after a full query: %zu of %zu\n", after_full, full_count);
  }
  return 0;
}
