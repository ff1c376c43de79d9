// A guided tour always ends. On every picture of tests/data/images and of the shipped library
// (data/pictures), the kiosk's own runtime is asked for a tour again and again until every shape has been
// led to, with the model hand limp as the kiosk makes it during a tour (nobody holds the handle): each tour
// must end within its bound — one and a half times its planned duration, or the 3 s without progress, plus
// the fade — with one of the lines that say how it ended ("That was …", "Tour stopped.", or that the
// guide could not go on and let go), followed by what remains. The shipped horse's tour once held the
// handle pinned in the tip of the tail for good, saying nothing more.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "audio/messages.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/guided_tour.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/simulation.hpp"
#include "runtime_ticks.hpp"
#include "show_now.hpp"
#include "test_paths.hpp"
#include "test_pictures.hpp"
#include "visit/kiosk_runtime.hpp"

namespace fs = std::filesystem;

namespace hk::app {
namespace {

/// The kiosk's runtime with one picture in its library, driven tick by tick as the servo thread and the
/// window thread drive it (a window frame every 16 ticks).
struct OnePictureKiosk {
  fs::path dir;
  config::Settings s;
  std::unique_ptr<KioskRuntime> rt;
  long ticks = 0;

  explicit OnePictureKiosk(const fs::path& picture)
      : dir(fs::temp_directory_path() /
            ("hk_tour_ends_" + picture.stem().string() + "_" + std::to_string(::getpid()))) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::copy_file(picture, dir / picture.filename());
    rt = std::make_unique<KioskRuntime>(test::headless_runtime_options(dir), s);
  }
  ~OnePictureKiosk() {
    rt.reset();
    fs::remove_all(dir);
  }
  /// `seconds` of servo ticks; nobody holds the handle (no hand force).
  void run(double seconds) {
    const double dt = 1.0 / s.haptics.servo_rate_hz;
    for (long k = 0, n = static_cast<long>(seconds / dt + 0.5); k < n; ++k, ++ticks) {
      test::runtime_tick(*rt, dt, nullptr);
      if (ticks % 16 == 0) rt->tour().poll();
    }
    rt->tour().poll();
  }
  double now_s() const { return static_cast<double>(ticks) / s.haptics.servo_rate_hz; }
};

bool starts_with(const std::string& s, const std::string& head) { return s.rfind(head, 0) == 0; }

class EveryTourEnds : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryTourEnds, OnEveryShapeWithASpokenLineWithinItsBound) {
  OnePictureKiosk k(GetParam());
  const int shapes = test::show_now(*k.rt, 0);
  ASSERT_GE(shapes, 0) << "the picture builds";
  k.run(0.6);
  const audio::MessageCatalog& m = audio::MessageCatalog::english();
  const TourParams tp = tour_params_from(k.s);
  int tours = 0, done = 0;
  for (int press = 0; press <= shapes + 1; ++press) {
    k.rt->tour().key_pressed();
    k.rt->tour().guide();
    if (!k.rt->tour().running()) {  // nothing left to lead to: said so
      const std::string said = k.rt->voice().last_said();
      EXPECT_TRUE(said == m.text(audio::MessageId::tour_all_touched) || said == m.text(audio::MessageId::tour_nothing))
          << said;
      break;
    }
    for (int i = 0; i < 200 && k.rt->tour().announced(); ++i) k.run(0.05);  // "I will guide your hand…"
    ASSERT_FALSE(k.rt->tour().announced());
    if (!k.rt->tour().running()) continue;  // touched meanwhile: nothing to lead to
    // What the runtime planned as it handed the tour over, planned again from (almost) the same place.
    const std::optional<TourPath> plan = plan_tour(*k.rt->stage().shown().scene, k.rt->stage().shown_id(),
                                                   k.rt->core().display().handle_m, k.rt->tour().touches(), tp);
    ASSERT_TRUE(plan.has_value());
    const double bound_s = std::max(tp.stall_s, tp.overrun_factor * plan->duration_s()) + tp.fade_s + 0.1;
    const double from_s = k.now_s();
    while (k.rt->tour().running() && k.now_s() - from_s < bound_s + 5.0) k.run(0.02);
    const double took_s = k.now_s() - from_s;
    ++tours;
    ASSERT_FALSE(k.rt->tour().running()) << "tour " << tours << " to shape " << plan->curve << " still running after "
                                         << took_s << " s";
    EXPECT_LE(took_s, bound_s) << "tour " << tours << " to shape " << plan->curve << " (planned " << plan->duration_s()
                               << " s)";
    const std::string said = k.rt->voice().last_said();
    const bool traced = starts_with(said, "That was ");
    done += traced;
    EXPECT_TRUE(traced || starts_with(said, m.text(audio::MessageId::tour_stopped)) ||
                starts_with(said, m.text(audio::MessageId::tour_stuck)))
        << "tour " << tours << " ended with: " << said;
  }
  if (shapes > 0 && tours > 0) {
    EXPECT_GT(done, 0) << "at least one tour traced its shape to the end";
  }
}

std::vector<std::string> every_picture() {
  std::vector<std::string> out;
  for (const char* name : test::kPictures) out.push_back(std::string(HK_TEST_DATA_DIR) + "/images/" + name);
  for (const auto& e : fs::directory_iterator(HK_SHIPPED_PICTURES_DIR)) {
    const std::string ext = e.path().extension().string();
    if (ext == ".png" || ext == ".jpg") out.push_back(e.path().string());
  }
  return out;
}

INSTANTIATE_TEST_SUITE_P(TestAndShippedPictures, EveryTourEnds, ::testing::ValuesIn(every_picture()),
                         [](const auto& info) {
                           const fs::path p(info.param);
                           return (p.parent_path().filename() == "pictures" ? "shipped_" : "") + p.stem().string();
                         });

}  // namespace
}  // namespace hk::app
