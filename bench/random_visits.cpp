// Long seeded random visits (tests/support/random_visit.hpp): every key, bursts, stray keys and chords,
// learning mode, sticks of damaged files put in and taken out, the operator's settings, a wandering hand, for
// --frames frames per seed (60 a second of kiosk time; the default 360 000 is 100 minutes of kiosk time), seeds
// --first-seed .. --first-seed + --seeds - 1. Prints one line per seed and writes --json: what each run did, the
// keys that went unanswered, what a new visitor would have found after Finish, and the sorry lines. Exit 1 when
// any run found a fault.
//
//   build/bench/bench_random_visits --seeds 4 --json docs/bench/random_visits.json > docs/bench/random_visits.txt

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <unistd.h>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "random_visit.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App cli("Long seeded random visits to the kiosk without its window");
  int frames = 360000, seeds = 4;
  unsigned first_seed = 1000;
  std::string json_path;
  cli.add_option("--frames", frames, "Frames per run (60 a second of kiosk time)")->check(CLI::Range(1000, 100000000));
  cli.add_option("--seeds", seeds, "Runs, one seed each")->check(CLI::Range(1, 1000));
  cli.add_option("--first-seed", first_seed, "The first run's seed");
  cli.add_option("--json", json_path, "Write the runs' reports here");
  CLI11_PARSE(cli, argc, argv);
  spdlog::set_level(spdlog::level::err);  // the kiosk's log of thousands of keys is not the report

  const fs::path data = HK_TEST_DATA_DIR;
  const fs::path work = fs::temp_directory_path() / ("hk_bench_random_visits_" + std::to_string(::getpid()));
  fs::remove_all(work);
  fs::create_directories(work / "library");
  for (const char* name : {"horse.png", "coins.png", "silhouette_2.png", "butterfly.jpg"})
    if (fs::exists(data / "images" / name)) fs::copy_file(data / "images" / name, work / "library" / name);

  nlohmann::json runs = nlohmann::json::array();
  bool faults = false;
  for (int i = 0; i < seeds; ++i) {
    hk::test::RandomVisitParams p;
    p.seed = first_seed + static_cast<unsigned>(i);
    p.frames = frames;
    p.library = work / "library";
    p.data = data;
    p.work = work / ("run" + std::to_string(i));
    p.leave_per_frame = 0.0002;  // now and then a visitor walks away for 150 s
    const auto t0 = std::chrono::steady_clock::now();
    const hk::test::RandomVisitReport r = hk::test::run_random_visit(p);
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const bool fault = !r.unanswered.empty() || !r.left_behind.empty() || r.failures != 0;
    faults = faults || fault;
    std::cout << "seed " << p.seed << ": " << frames << " frames (" << frames / 3600.0 << " min of kiosk time) in "
              << wall_s << " s; " << r.keys << " keys, " << r.bursts << " bursts, " << r.sticks_in << " sticks in, "
              << r.sticks_out << " out, " << r.panel_applies << " settings applied, " << r.sessions_ended
              << " visits ended; " << r.unanswered.size() << " unanswered, " << r.left_behind.size() << " left behind, "
              << r.failures << " sorry lines" << std::endl;
    for (const std::string& u : r.unanswered) std::cout << "  unanswered: " << u << "\n";
    for (const std::string& l : r.left_behind) std::cout << "  left behind: " << l << "\n";
    runs.push_back({{"seed", p.seed},
                    {"frames", frames},
                    {"wall_s", wall_s},
                    {"keys", r.keys},
                    {"bursts", r.bursts},
                    {"sticks_in", r.sticks_in},
                    {"sticks_out", r.sticks_out},
                    {"panel_applies", r.panel_applies},
                    {"learning", r.learning},
                    {"sessions_ended", r.sessions_ended},
                    {"unanswered", r.unanswered},
                    {"left_behind", r.left_behind},
                    {"failures", r.failures}});
  }
  if (!json_path.empty()) std::ofstream(json_path) << nlohmann::json{{"runs", runs}}.dump(2) << "\n";
  fs::remove_all(work);
  return faults ? 1 : 0;
}
