// Event-to-sound latency in the rendered timeline, and the cost of
// the mix. For each picture: the explore raster on the simulated pantograph (as `haptic-kiosk explore`),
// its cues rendered on the trace's timeline exactly as --audio-out does, then for every cue the time from
// its tick to the first onset the independent analysis of tests/support/audio_analysis.hpp finds at or
// after it (up to 50 ms; a cue with no onset in that time counts as missed). Also the CPU time of
// Mixer::render per 256-frame buffer with 0–32 voices sounding.
// Usage: bench_earcon_latency [--out FILE.json]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "audio/mixer.hpp"
#include "audio_analysis.hpp"
#include "haptics/hand_path.hpp"
#include "pictures/image_scene.hpp"
#include "runtime/cue_tracker.hpp"
#include "runtime/simulation.hpp"
#include "test_paths.hpp"

using namespace hk;

namespace {

double pct(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

}  // namespace

int main(int argc, char** argv) {
  std::string out_path;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--out") out_path = argv[i + 1];
  }
  const config::Settings s;
  nlohmann::json j;
  j["pictures"] = nlohmann::json::array();
  std::map<std::string, std::vector<double>> lag_ms;  // per cue kind, all pictures
  std::map<std::string, long> missed, total;
  for (const char* name : {"horse.png", "silhouette_3.png", "coins.png", "butterfly.jpg"}) {
    app::ImageScene is = app::build_image_scene(std::string(HK_TEST_DATA_DIR) + "/images/" + name, s);
    const HandPath hand =
        raster_path(s.workspace.width_m, s.workspace.height_m, s.hand.raster_spacing_m, s.hand.raster_speed_m_per_s);
    app::CueTrackerParams ctp;
    ctp.period_s = 1.0 / s.haptics.servo_rate_hz;
    ctp.workspace_half_extent_m = {s.workspace.width_m / 2, s.workspace.height_m / 2};
    app::CueTracker tracker(ctp);
    std::vector<audio::CueEvent> cues;
    const double duration = 20.0;
    app::run_simulation(*is.scene, s, hand, duration, [&](const app::ServoTick& r, const ServoOutput& so) {
      audio::CueEvent c[app::CueTracker::kMaxCuesPerTick];
      const int n = tracker.update(r.index, so, r.sample.handle_m, s.haptics.level, c);
      cues.insert(cues.end(), c, c + n);
    });
    const std::vector<float> x = audio::render_cue_timeline(cues, ctp.period_s, duration);
    const std::vector<std::size_t> on = test::onsets(x, 1e-3);
    long picture_cues = 0;
    for (const audio::CueEvent& e : cues) {
      if (e.kind == audio::CueKind::Slide || e.kind == audio::CueKind::ContactEnd)
        continue;  // continuous / soft by design
      const std::string kind = audio::cue_kind_name(e.kind);
      const double t = static_cast<double>(e.tick) * ctp.period_s * audio::kSampleRateHz;
      const auto it = std::lower_bound(on.begin(), on.end(), static_cast<std::size_t>(t));
      ++total[kind];
      ++picture_cues;
      if (it == on.end() || static_cast<double>(*it) - t > 0.050 * audio::kSampleRateHz) {
        ++missed[kind];
        continue;
      }
      lag_ms[kind].push_back((static_cast<double>(*it) - t) * 1000.0 / audio::kSampleRateHz);
    }
    j["pictures"].push_back({{"picture", name}, {"cues", cues.size()}, {"cues_checked", picture_cues}});
  }
  std::printf("| cue | count | missed | latency p50 ms | p99 ms | max ms |\n|---|---|---|---|---|---|\n");
  for (const auto& [kind, n] : total) {
    const auto& v = lag_ms[kind];
    const double mx = v.empty() ? 0 : *std::max_element(v.begin(), v.end());
    std::printf("| %s | %ld | %ld | %.2f | %.2f | %.2f |\n", kind.c_str(), n, missed[kind], pct(v, 0.5), pct(v, 0.99),
                mx);
    j["latency"][kind] = {
        {"count", n}, {"missed", missed[kind]}, {"p50_ms", pct(v, 0.5)}, {"p99_ms", pct(v, 0.99)}, {"max_ms", mx}};
  }

  // Cost of the mix: CPU time per 256-frame buffer (5.3 ms of audio) with `voices` sounding.
  std::printf("\n| voices | render µs per 256 frames | share of the buffer's 5333 µs |\n|---|---|---|\n");
  for (int voices : {0, 4, 16, 32}) {
    audio::Mixer m({}, nullptr, nullptr, nullptr);
    std::vector<float> buf(256);
    std::vector<double> us;
    for (int rep = 0; rep < 2000; ++rep) {
      for (int v = m.synth().active_voices(); v < voices; ++v) {  // keep exactly `voices` sounding
        audio::CueEvent e;
        e.kind = audio::CueKind::LevelFiner;
        m.trigger(e);
      }
      const auto t0 = std::chrono::steady_clock::now();
      m.render(buf.data(), buf.size());
      us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    }
    std::printf("| %d | %.1f (p99 %.1f) | %.2f %% |\n", voices, pct(us, 0.5), pct(us, 0.99),
                100.0 * pct(us, 0.5) / 5333.0);
    j["mixer_render_us"].push_back({{"voices", voices}, {"p50", pct(us, 0.5)}, {"p99", pct(us, 0.99)}});
  }
  if (!out_path.empty()) std::ofstream(out_path) << j.dump(2) << "\n";
  return 0;
}
