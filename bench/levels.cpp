// Levels from hand speed, and what a scene costs: for every shipped
// picture, a raster whose rows cycle through hand speeds from 1 cm/s to 40 cm/s is run on the simulated
// pantograph with levels chosen from the hand's speed; per tick the handle speed and the level in use are
// binned. Also per picture: level-0 segments before and after the scene budget (and thin lines merged),
// and the servo tick time at the level in use against the picture's size.
// Usage: bench_levels [--images DIR] [--out FILE.json] [--quick]    (prints two markdown tables)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "haptics/hand_path.hpp"
#include "pictures/image_scene.hpp"
#include "runtime/simulation.hpp"
#include "test_paths.hpp"

using namespace hk;
namespace fs = std::filesystem;

namespace {

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

}  // namespace

int main(int argc, char** argv) {
  std::string images = std::string(HK_TEST_DATA_DIR) + "/images", out_path;
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--images" && i + 1 < argc) images = argv[++i];
    if (a == "--out" && i + 1 < argc) out_path = argv[++i];
    if (a == "--quick") quick = true;
  }
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(images)) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  if (quick) files.resize(std::min<std::size_t>(files.size(), 4));

  const std::vector<double> speeds{0.01, 0.02, 0.05, 0.1, 0.2, 0.4};
  const std::vector<double> bin_edges{0.0, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.4, 1e9};  // [m/s]
  config::Settings s;
  s.haptics.level_mode = "auto";
  nlohmann::json pictures = nlohmann::json::array();
  // The same pictures with nothing simplified, and with a budget ten times tighter than the default.
  config::Settings raw = s;
  raw.vision.thin_line_max_width_m = 0.0;
  raw.vision.min_chain_length_m = 0.0;
  raw.vision.max_segments = 1000000;
  config::Settings tight = s;
  tight.vision.max_segments = 3000;
  std::printf(
      "| picture | chains found | thin-line pairs merged | too short | level-0 segments, nothing simplified | after "
      "merging and dropping | after the budget (%d) | after a %d budget (chains dropped) | level changes | ticks "
      "waiting for a safe change | wait per change p50 / p90 ms | tick p50 µs | p99 µs | max µs |\n",
      s.vision.max_segments, tight.vision.max_segments);
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const fs::path& f : files) {
    const app::ImageScene is = app::build_image_scene(f.string(), s);
    const std::size_t raw_segments = app::build_image_scene(f.string(), raw).scene->total_segments(0);
    const app::ImageScene tight_is = app::build_image_scene(f.string(), tight);
    const Scene& sc = *is.scene;
    const HandPath hand = raster_path_with_line_speeds(s.workspace.width_m, s.workspace.height_m, 0.006, speeds, 0.02);
    const int levels = s.haptics.max_levels + 1;
    std::vector<std::vector<long>> hist(bin_edges.size() - 1, std::vector<long>(static_cast<std::size_t>(levels), 0));
    std::vector<double> tick_us;
    long changes = 0, waiting = 0, episode = 0;
    std::vector<double> waits_ms;  // how long each wanted change waited for a safe moment [ms]
    std::vector<long> level_ticks(static_cast<std::size_t>(levels), 0);
    app::run_simulation(sc, s, hand, hand.duration_s(), [&](const app::ServoTick& r, const ServoOutput& so) {
      const double v = length(so.handle_velocity_m_per_s);
      std::size_t b = 0;
      while (b + 2 < bin_edges.size() && v >= bin_edges[b + 1]) ++b;
      const auto l = static_cast<std::size_t>(std::clamp(so.level, 0, levels - 1));
      ++hist[b][l];
      ++level_ticks[l];
      tick_us.push_back(1e-3 * static_cast<double>(r.step_ns));
      changes += so.level_changed;
      waiting += so.level != so.level_wanted;
      if (so.level != so.level_wanted) {
        ++episode;
      } else if (episode > 0 || so.level_changed) {
        waits_ms.push_back(static_cast<double>(episode));  // 1 tick = 1 ms; 0 = made at once
        episode = 0;
      }
    });
    nlohmann::json pj;
    pj["picture"] = f.filename().string();
    pj["chains_found"] = is.chains_found;
    pj["thin_line_pairs_merged"] = is.thin_line_pairs_merged;
    pj["chains_too_short"] = is.chains_too_short;
    pj["chains_over_budget"] = is.chains_over_budget;
    pj["segments_before_budget"] = is.segments_before_budget;
    pj["segments_after_budget"] = is.segments_after_budget;
    pj["level0_segments"] = sc.total_segments(0);
    pj["segments_nothing_simplified"] = raw_segments;
    pj["segments_tight_budget"] = tight_is.segments_after_budget;
    pj["chains_over_tight_budget"] = tight_is.chains_over_budget;
    std::vector<double> level_error;  // the policy's error ladder
    for (int l = 0; l < levels; ++l) level_error.push_back(sc.max_error_bound_m(l));
    pj["level_error_m"] = level_error;
    pj["speed_bin_edges_m_per_s"] = bin_edges;
    pj["level_ticks_per_speed_bin"] = hist;
    pj["level_ticks"] = level_ticks;
    pj["level_changes"] = changes;
    pj["ticks"] = tick_us.size();
    pj["ticks_waiting"] = waiting;
    pj["change_wait_ms"] = {
        {"p50", percentile(waits_ms, 0.5)}, {"p90", percentile(waits_ms, 0.9)}, {"max", percentile(waits_ms, 1.0)}};
    pj["tick_us"] = {
        {"p50", percentile(tick_us, 0.5)}, {"p99", percentile(tick_us, 0.99)}, {"max", percentile(tick_us, 1.0)}};
    pictures.push_back(pj);
    std::printf(
        "| %s | %zu | %zu | %zu | %zu | %zu | %zu | %zu (%zu) | %ld | %.0f %% | %.0f / %.0f | %.1f | %.1f | %.0f |\n",
        f.filename().c_str(), is.chains_found, is.thin_line_pairs_merged, is.chains_too_short, raw_segments,
        is.segments_before_budget, is.segments_after_budget, tight_is.segments_after_budget,
        tight_is.chains_over_budget, changes,
        100.0 * static_cast<double>(waiting) / static_cast<double>(std::max<std::size_t>(1, tick_us.size())),
        percentile(waits_ms, 0.5), percentile(waits_ms, 0.9), percentile(tick_us, 0.5), percentile(tick_us, 0.99),
        percentile(tick_us, 1.0));
  }
  // Second table: share of ticks at each level per speed bin, all pictures together.
  std::printf("\n| hand speed | ticks |");
  for (int l = 0; l <= s.haptics.max_levels; ++l) std::printf(" level %d |", l);
  std::printf("\n|---|---|");
  for (int l = 0; l <= s.haptics.max_levels; ++l) std::printf("---|");
  std::printf("\n");
  for (std::size_t b = 0; b + 1 < bin_edges.size(); ++b) {
    std::vector<long> sum(static_cast<std::size_t>(s.haptics.max_levels + 1), 0);
    long total = 0;
    for (const auto& pj : pictures) {
      const auto h = pj["level_ticks_per_speed_bin"][b].get<std::vector<long>>();
      for (std::size_t l = 0; l < h.size(); ++l) {
        sum[l] += h[l];
        total += h[l];
      }
    }
    if (b + 2 < bin_edges.size()) {
      std::printf("| %.0f–%.0f mm/s | %ld |", 1e3 * bin_edges[b], 1e3 * bin_edges[b + 1], total);
    } else {
      std::printf("| ≥ %.0f mm/s | %ld |", 1e3 * bin_edges[b], total);
    }
    for (long n : sum)
      std::printf(" %.0f %% |", total ? 100.0 * static_cast<double>(n) / static_cast<double>(total) : 0.0);
    std::printf("\n");
  }
  nlohmann::json j;
  j["speeds_m_per_s"] = speeds;
  j["pictures"] = pictures;
  j["policy"] = {{"error_at_rest_m", s.haptics.level_error_at_rest_m},
                 {"blur_time_s", s.haptics.level_blur_time_s},
                 {"hysteresis", s.haptics.level_hysteresis},
                 {"min_dwell_s", s.haptics.level_min_dwell_s}};
  if (!out_path.empty()) std::ofstream(out_path) << j.dump(1) << "\n";
  return 0;
}
