// A scripted operator naming a shape at the real kiosk under Xvfb: the hand (the model hand, pulled by the script's
// cursor) is put on the horse's outline, the panel opened with the PIN, the Names tab clicked, the shape at the
// handle picked, "left wing" typed into the name box and saved. The script itself fails unless the panel then shows
// "names:saved"; afterwards the names folder holds horse.annotations.json, it parses, and read by the kiosk's own
// apply_names it gives that outline the name "left wing". Then its check box turns the kiosk's guesses off for the
// picture: the names folder's horse.toml says `guesses = false`, and the kiosk reads it so.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "config/load.hpp"
#include "formats/annotations.hpp"
#include "kiosk_exe.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/picture_names.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

namespace {

using hk::test::read_text;
using hk::test::sh;

const fs::path kData = HK_TEST_DATA_DIR;
const std::string kNoGlLeakCheck = "ASAN_OPTIONS=detect_leaks=0 ";  // Mesa's DRI driver (see test_kiosk_screen.cpp)

/// The curve with the most points among the closed ones of `is` (the horse's outline), and its point farthest from
/// every other curve: where the hand goes, so the shape at the handle cannot be another one.
std::pair<int, hk::Vec2> outline_and_lonely_point(const hk::app::ImageScene& is) {
  int best = -1;
  for (std::size_t i = 0; i < is.polylines.size(); ++i)
    if (is.polylines[i].closed &&
        (best < 0 || is.polylines[i].points_m.size() > is.polylines[static_cast<std::size_t>(best)].points_m.size()))
      best = static_cast<int>(i);
  if (best < 0) return {-1, {}};
  hk::Vec2 lonely;
  double farthest = -1;
  const std::vector<hk::Vec2>& own = is.polylines[static_cast<std::size_t>(best)].points_m;
  for (std::size_t k = 0; k < own.size(); k += 4) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < is.polylines.size(); ++j)
      if (static_cast<int>(j) != best)
        for (const hk::Vec2& q : is.polylines[j].points_m) nearest = std::min(nearest, hk::length(q - own[k]));
    if (nearest > farthest) {
      farthest = nearest;
      lonely = own[k];
    }
  }
  return {best, lonely};
}

TEST(OperatorNames, TheShapeAtTheHandleNamedLeftWingInTheNamesTabIsSavedAndReadBackUnderXvfb) {
  if (sh("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps.sh installs it)";
  const fs::path dir = fs::temp_directory_path() / ("hk_opnames_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "library");
  const fs::path horse = dir / "library" / "horse.png";
  fs::copy_file(kData / "images" / "horse.png", horse);
  const fs::path settings = dir / "kiosk.toml", names = dir / "names";
  hk::config::Settings s;
  s.stick.page_timeout_s = 60;         // generous under a loaded CI machine; not what is tested
  s.haptics.render = "grooves";        // the hand reaches the outline wherever it comes from (a wall would stop it)
  s.kiosk.names_dir = names.string();  // not there yet: the save makes it
  hk::config::save_settings_atomic(s, settings.string());
  ASSERT_EQ(sh("printf '90817263\\n' | " + std::string(HK_KIOSK_EXE) + " pin set --config '" + settings.string() +
               "' 2>/dev/null"),
            0);

  hk::app::ImageScene is = hk::app::build_image_scene(horse.string(), s);
  const auto [outline, hand] = outline_and_lonely_point(is);
  ASSERT_GE(outline, 0) << "the horse has a closed outline";

  std::ofstream(dir / "visit.txt") << "1 wait\n"
                                   << "2 cursor " << hand.x << " " << hand.y << "\n"
                                   << "10 press CTRL+ALT+O\n"
                                      "20 type 90817263\n"
                                      "21 press ENTER\n"
                                      "22 wait\n"
                                      "60 click tab:Names\n"
                                      "70 click Pick the shape at the handle\n"
                                      "80 click names.name\n"
                                      "90 type left wing\n"
                                      "100 click Save names\n"
                                      "110 shows names:saved\n"
                                      "112 click names.guesses\n";  // the kiosk's guesses off for this picture
  const fs::path png = dir / "names.png", log = dir / "log.txt";
  ASSERT_EQ(sh(kNoGlLeakCheck + "timeout 300 xvfb-run -a -s '-screen 0 1280x720x24' " + HK_KIOSK_EXE +
               " --no-hotplug --config '" + settings.string() + "' --library '" + (dir / "library").string() +
               "' --show '" + horse.string() + "' --script '" + (dir / "visit.txt").string() + "' --screenshot '" +
               png.string() + "' --frames 130 >'" + log.string() + "' 2>&1"),
            0)
      << read_text(log);

  const fs::path file = names / "horse.annotations.json";
  ASSERT_TRUE(fs::is_regular_file(file)) << read_text(log);
  const hk::app::AnnotationSet set = hk::app::read_annotations(file.string(), "horse.png");
  ASSERT_EQ(set.annotations.size(), 1u) << read_text(file);
  EXPECT_TRUE(set.problems.empty());
  EXPECT_EQ(set.annotations[0].name, "left wing");
  EXPECT_EQ(set.annotations[0].selector.kind, hk::app::AnnotationSelector::Kind::svg);
  hk::app::apply_names(is, hk::app::names_file_for(horse.string(), names.string()), "horse.png");
  ASSERT_EQ(is.shape_region.size(), is.polylines.size());
  const int region = is.shape_region[static_cast<std::size_t>(outline)];
  ASSERT_GE(region, 0) << "the outline at the hand has a name";
  EXPECT_EQ(is.regions[static_cast<std::size_t>(region)].name, "left wing");
  EXPECT_NE(read_text(log).find("names: saved 1 annotations to " + file.string()), std::string::npos) << read_text(log);
  EXPECT_NE(read_text(names / "horse.toml").find("guesses = false"), std::string::npos) << read_text(log);
  EXPECT_FALSE(hk::app::guesses_for(horse.string(), names.string(), true));
  fs::remove_all(dir);
}

}  // namespace
