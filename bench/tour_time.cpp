// Time to touch every shape once with the guided tour: on the five-shape test picture
// (tests/support/tour_picture.hpp) and on pictures of tests/data/images, the handle starts where the kiosk
// parks it (bottom centre), the visitor's hand is relaxed (no force) and Guide is pressed again as soon as
// a tour ends, until every shape is touched. Servo time (1 kHz ticks through the simulated pantograph with
// the kiosk's default settings), not wall time. A shape counts as touched when the proxy is in contact
// with it (as the kiosk counts) or its tour is done.
//
//   build/bench/bench_tour_time [picture ...]     (no argument: the five-shape picture and three others)
// Prints one row per picture: shapes, tours, tours stopped (the hand is relaxed, so a stop means the
// tour could not go on: the handle held by another shape's wall), total time, time per shape, the longest
// tour, the peak guide force and the peak total force; and on stderr a line per stopped tour.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "haptics/sim_pantograph.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/guided_tour.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/servo_runner.hpp"
#include "runtime/servo_step.hpp"
#include "runtime/simulation.hpp"
#include "test_paths.hpp"
#include "tour_picture.hpp"

using namespace hk;
using namespace hk::app;
namespace fs = std::filesystem;

namespace {

struct Row {
  std::string name;
  int shapes = 0, tours = 0, stopped = 0;
  double total_s = 0, longest_s = 0, max_guide_n = 0, max_total_n = 0;
};

Row run(const std::string& name, const std::string& path, const config::Settings& s) {
  Row row;
  row.name = name;
  ImageScene is = build_image_scene(path, s);
  const ServoParams sp = servo_params_from(s);
  const TourParams tp = tour_params_from(s);
  SimulatedPantograph dev(sim_params_from(s), {0.0, -0.9 * s.workspace.height_m / 2});
  dev.open();
  ServoStep core(CueTrackerParams{}, nullptr);
  auto bundle = std::make_unique<SceneBundle>(std::move(is.scene), sp);
  bundle->id = 1;
  const Scene& sc = *bundle->scene;
  core.publish(std::move(bundle));
  ServoRunner runner(core, dev);
  const auto tick = [&] {
    ServoTick t;
    runner.tick(t);
    core.publish_display();
    row.max_guide_n = std::max(row.max_guide_n, length(core.last_guide_force()));
    row.max_total_n = std::max(row.max_total_n, length(t.command.force_n));
    dev.step(sp.period_s, {});
  };
  for (int k = 0; k < 600; ++k) tick();  // taken, force ramped in
  VisitTouches touches;
  touches.reset(1, static_cast<int>(sc.curve_count()));
  row.shapes = shapes_remaining(sc, touches, tp);
  for (int id = 1;; ++id) {
    auto plan = plan_tour(sc, 1, dev.read().handle_m, touches, tp);
    if (!plan) break;
    plan->id = id;
    const int curve = plan->curve;
    core.publish_tour(std::make_unique<TourPath>(std::move(*plan)));
    long ticks = 0;
    int last_contact = -1;
    for (;; ++ticks) {
      tick();
      const ServoDisplayState& d = core.display();
      if (d.curve >= 0) touches.touch(1, d.curve);
      if (d.tour_id == id && tour_ended(d.tour_phase)) {
        row.stopped += d.tour_phase != TourPhase::Done;
        if (d.tour_phase != TourPhase::Done)
          std::fprintf(
              stderr,
              "%s: tour %d to shape %d (%.1f mm long) %s after %.2f s: handle (%.1f, %.1f) mm, in contact with %d\n",
              name.c_str(), id, curve, 1000 * curve_length_m(sc, static_cast<std::size_t>(curve)),
              d.tour_phase == TourPhase::Stuck ? "stuck" : "stopped", ticks * sp.period_s, 1000 * d.handle_m.x,
              1000 * d.handle_m.y, last_contact);
        break;
      }
      if (d.curve >= 0) last_contact = d.curve;
    }
    touches.touch(1, curve);
    core.collect_retired();
    ++row.tours;
    row.total_s += ticks * sp.period_s;
    row.longest_s = std::max(row.longest_s, ticks * sp.period_s);
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  const config::Settings s;
  std::vector<std::pair<std::string, std::string>> pictures;
  const fs::path tmp = fs::temp_directory_path() / ("hk_tour_time_" + std::to_string(::getpid()));
  if (argc > 1) {
    for (int i = 1; i < argc; ++i) pictures.emplace_back(fs::path(argv[i]).filename().string(), argv[i]);
  } else {
    fs::create_directories(tmp);
    const std::string five = (tmp / "five_shapes.png").string();
    if (!hk::test::write_five_shapes_png(five)) {
      std::fprintf(stderr, "cannot write %s\n", five.c_str());
      return 1;
    }
    pictures.emplace_back("five shapes (test picture)", five);
    for (const char* p : {"silhouette_1.png", "LinuxLogo.jpg", "apple.jpg"})
      pictures.emplace_back(p, std::string(HK_TEST_DATA_DIR) + "/images/" + p);
  }
  std::printf("tour_speed %.3f m/s, tour_max_force %.2f N, max_force %.2f N, relaxed hand, start at the park place\n",
              s.haptics.tour_speed_m_per_s, s.haptics.tour_max_force_n, s.haptics.max_force_n);
  std::printf(
      "| picture | shapes | tours | stopped | time to touch all [s] | per shape [s] | longest tour [s] | peak guide "
      "force [N] | peak total force [N] |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& [name, path] : pictures) {
    const Row r = run(name, path, s);
    std::printf("| %s | %d | %d | %d | %.1f | %.1f | %.1f | %.2f | %.2f |\n", r.name.c_str(), r.shapes, r.tours,
                r.stopped, r.total_s, r.shapes ? r.total_s / r.shapes : 0.0, r.longest_s, r.max_guide_n, r.max_total_n);
    std::fflush(stdout);
  }
  std::error_code ec;
  fs::remove_all(tmp, ec);
  return 0;
}
