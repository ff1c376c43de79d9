// The servo thread under load: it must keep its rate with the second core loaded.
// Runs the kiosk's servo thread (ServoThread + ServoStep + the simulated pantograph driven by the raster
// hand) on a real picture for a few seconds at 1 kHz, first on an idle machine, then with a busy thread
// spinning on the other core, and reports wake-up lateness (p50/p99/max), tick work and missed deadlines.
// Usage: bench_servo_rate [--seconds S] [--out FILE.json]
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "haptics/hand_path.hpp"
#include "haptics/sim_pantograph.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/servo_thread.hpp"
#include "runtime/simulation.hpp"
#include "test_paths.hpp"

using namespace hk;

int main(int argc, char** argv) {
  double seconds = 5.0;
  std::string out_path;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--seconds") seconds = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--out") out_path = argv[i + 1];
  }
  const config::Settings s;
  nlohmann::json j = nlohmann::json::array();
  std::printf(
      "| load | realtime | ticks | missed | lateness p50 µs | p99 µs | max µs | tick work p50 µs | p99 µs "
      "|\n|---|---|---|---|---|---|---|---|---|\n");
  for (const bool loaded : {false, true}) {
    app::ImageScene is = app::build_image_scene(std::string(HK_TEST_DATA_DIR) + "/images/butterfly.jpg", s);
    const HandPath hand =
        raster_path(s.workspace.width_m, s.workspace.height_m, s.hand.raster_spacing_m, s.hand.raster_speed_m_per_s);
    SimPantographParams dp;
    dp.workspace_half_extent_m = {s.workspace.width_m / 2, s.workspace.height_m / 2};
    SimulatedPantograph device(dp, hand.at(0.0));
    device.open();
    ModelHandParams hp;
    hp.max_force_n = s.hand.max_force_n;
    app::ServoStep core(app::CueTrackerParams{}, nullptr);
    const ServoParams sp = app::servo_params_from(s);
    core.publish(std::make_unique<app::SceneBundle>(std::move(is.scene), sp));
    std::atomic<bool> spin{loaded};
    std::thread loader([&] {
      volatile double x = 1.0;
      while (spin.load(std::memory_order_relaxed)) x = std::sqrt(x + 1.0);
    });
    double t_s = 0.0;
    {
      app::ServoThread thread(core, device, {}, [&](double dt) {
        device.step(dt, model_hand_force(hp, hand.at(t_s), device.true_position_m(), device.velocity_m_per_s()));
        t_s += dt;
      });
      std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
      thread.stop();
      const app::ServoTimingStats st = thread.stats();
      std::printf("| %s | %s | %lld | %lld | %.0f | %.0f | %.0f | %.0f | %.0f |\n", loaded ? "other core busy" : "idle",
                  thread.realtime() ? "SCHED_FIFO" : "normal", static_cast<long long>(st.ticks),
                  static_cast<long long>(st.missed_deadlines), st.lateness_p50_us, st.lateness_p99_us,
                  st.lateness_max_us, st.compute_p50_us, st.compute_p99_us);
      j.push_back(
          {{"loaded", loaded},
           {"realtime", thread.realtime()},
           {"ticks", st.ticks},
           {"missed", st.missed_deadlines},
           {"lateness_us", {{"p50", st.lateness_p50_us}, {"p99", st.lateness_p99_us}, {"max", st.lateness_max_us}}},
           {"compute_us", {{"p50", st.compute_p50_us}, {"p99", st.compute_p99_us}}},
           {"seconds", seconds}});
    }
    spin = false;
    loader.join();
    core.collect_retired();
  }
  if (!out_path.empty()) std::ofstream(out_path) << j.dump(2) << "\n";
  return 0;
}
