// The kiosk under Xvfb: it starts full screen, shows a picture with its
// curves, and writes a screenshot in which the curves are where scene.json says they are, through the
// documented view mapping (kiosk_app.hpp), checked from the pixels.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>
#include "kiosk_exe.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

namespace {

using hk::test::sh;

const fs::path kData = HK_TEST_DATA_DIR;

// The kiosk under Xvfb loads Mesa's DRI driver, which leaks 112 bytes and is unloaded at exit (LeakSanitizer
// then reports an "<unknown module>"). Leak checking stays on for everything else in the suite; only the
// GL process runs without it.
const std::string kNoGlLeakCheck = "ASAN_OPTIONS=detect_leaks=0 ";

bool yellow_near(const cv::Mat& img, int x, int y, int r) {
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const int u = x + dx, v = y + dy;
      if (u < 0 || v < 0 || u >= img.cols || v >= img.rows) continue;
      const cv::Vec3b p = img.at<cv::Vec3b>(v, u);  // BGR
      if (p[2] > 200 && p[1] > 160 && p[0] < 90) return true;
    }
  }
  return false;
}

TEST(KioskScreen, CurvesAreDrawnWhereSceneJsonSaysFullScreenUnderXvfb) {
  if (sh("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps.sh installs it)";
  const fs::path dir = fs::temp_directory_path() / ("hk_screen_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "library");
  fs::copy_file(kData / "images" / "horse.png", dir / "library" / "horse.png");
  const std::string exe = HK_KIOSK_EXE;
  ASSERT_EQ(sh(exe + " explore '" + (dir / "library" / "horse.png").string() + "' --out '" +
               (dir / "explore").string() + "' --duration 0.01 >/dev/null 2>&1"),
            0);
  const fs::path png = dir / "screen.png";
  ASSERT_EQ(sh(kNoGlLeakCheck + "timeout 120 xvfb-run -a -s '-screen 0 1280x720x24' " + exe + " --library '" +
               (dir / "library").string() + "' --show '" + (dir / "library" / "horse.png").string() +
               "' --screenshot '" + png.string() + "' --frames 20 >'" + (dir / "log.txt").string() + "' 2>&1"),
            0)
      << std::ifstream(dir / "log.txt").rdbuf();
  const cv::Mat img = cv::imread(png.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.cols, 1280) << "full screen on the 1280 x 720 Xvfb screen";
  EXPECT_EQ(img.rows, 720);

  std::ifstream sf(dir / "explore" / "scene.json");
  const nlohmann::json scene = nlohmann::json::parse(sf);
  const int level = scene["level_in_use"];
  const double s = 0.9 * std::min(1280 / 0.14, 0.8 * 720 / 0.09);  // the documented view mapping, default workspace
  long points = 0, hits = 0, shifted_hits = 0;
  for (const auto& c : scene["curves"]) {
    const auto& lv = c["levels"][std::min<std::size_t>(static_cast<std::size_t>(level), c["levels"].size() - 1)];
    for (const auto& p : lv["points_m"]) {
      const double x = 640 + s * p[0].get<double>(), y = 0.43 * 720 - s * p[1].get<double>();
      ++points;
      hits += yellow_near(img, static_cast<int>(std::lround(x)), static_cast<int>(std::lround(y)), 2);
      shifted_hits += yellow_near(img, static_cast<int>(std::lround(x + 25)), static_cast<int>(std::lround(y + 25)), 2);
    }
  }
  ASSERT_GT(points, 100);
  EXPECT_GT(static_cast<double>(hits) / points, 0.95)
      << hits << " of " << points << " curve points have a curve pixel within 2 px";
  EXPECT_LT(static_cast<double>(shifted_hits) / points, 0.2)
      << "control: 25 px off the curves there should be little yellow";
  fs::remove_all(dir);
}

// A scripted run looks for the USB pantograph only when the settings name it: with [device] type "haply" and no
// such board it says so (logged, and spoken: the simulated handle stands in); with "auto" it stays simulated
// without looking (documentation runs never depend on what is plugged in).
TEST(KioskScreen, AScriptedRunLooksForADeviceTheSettingsName) {
  if (sh("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps.sh installs it)";
  const fs::path dir = fs::temp_directory_path() / ("hk_named_device_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "library");
  fs::copy_file(kData / "images" / "horse.png", dir / "library" / "a_horse.png");
  std::ofstream(dir / "script.txt") << "1 move\n";
  const std::string exe = HK_KIOSK_EXE;
  auto run = [&](const std::string& type) {
    // An id no board has, so that a pantograph plugged into the machine running the tests is not found either.
    std::ofstream(dir / "kiosk.toml") << "[device]\ntype = \"" << type << "\"\nusb_ids = \"ffff:ffff\"\n";
    EXPECT_EQ(sh(kNoGlLeakCheck + "timeout 300 xvfb-run -a -s '-screen 0 1280x720x24' " + exe +
                 " --no-hotplug --config '" + (dir / "kiosk.toml").string() + "' --library '" +
                 (dir / "library").string() + "' --script '" + (dir / "script.txt").string() + "' --screenshot '" +
                 (dir / "end.png").string() + "' --frames 10 >'" + (dir / "log.txt").string() + "' 2>&1"),
              0)
        << std::ifstream(dir / "log.txt").rdbuf();
    std::stringstream log;
    log << std::ifstream(dir / "log.txt").rdbuf();
    return log.str();
  };
  const std::string named = run("haply");
  EXPECT_NE(named.find("device: no USB pantograph ("), std::string::npos) << named;
  EXPECT_NE(named.find("say: No handle is connected. The kiosk runs on its simulated handle."), std::string::npos)
      << named;
  const std::string automatic = run("auto");
  EXPECT_EQ(automatic.find("no USB pantograph"), std::string::npos) << automatic;
  EXPECT_EQ(automatic.find("No handle is connected"), std::string::npos) << automatic;
  fs::remove_all(dir);
}

}  // namespace

namespace {

// Scripted keys walk attract → tutorial → picture → next picture → time-out → attract; what the kiosk
// said (its speech log, one "say:" line per message) must follow the flow.
TEST(KioskScreen, ScriptedVisitWalksTheFlowAndSaysEachStep) {
  if (sh("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps.sh installs it)";
  const fs::path dir = fs::temp_directory_path() / ("hk_flow_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "library");
  fs::copy_file(kData / "images" / "horse.png", dir / "library" / "a_horse.png");
  fs::copy_file(kData / "images" / "silhouette_3.png", dir / "library" / "b_silhouette.png");
  std::ofstream(dir / "kiosk.toml") << "[kiosk]\ntimeout_s = 20\nwarning_s = 10\n";
  std::ofstream(dir / "script.txt") << "# frame action\n1 move\n30 key next\n60 key next\n90 key next\n120 key next\n";
  const std::string exe = HK_KIOSK_EXE;
  ASSERT_EQ(sh(kNoGlLeakCheck + "timeout 300 xvfb-run -a -s '-screen 0 1280x720x24' " + exe + " --config '" +
               (dir / "kiosk.toml").string() + "' --library '" + (dir / "library").string() + "' --script '" +
               (dir / "script.txt").string() + "' --screenshot '" + (dir / "end.png").string() + "' --frames 1400 >'" +
               (dir / "log.txt").string() + "' 2>&1"),
            0)
      << std::ifstream(dir / "log.txt").rdbuf();
  std::ifstream log(dir / "log.txt");
  std::vector<std::string> said;
  for (std::string line; std::getline(log, line);) {
    const auto at = line.find("say: ");
    if (at != std::string::npos) said.push_back(line.substr(at + 5));
  }
  const std::vector<std::string> want_prefix{"Welcome.",
                                             "A circle.",
                                             "A triangle.",
                                             "Well done. Press the D key to hear about a picture, the R key to hear it "
                                             "again. Here is the first picture. Picture 1 of 2.",
                                             "Picture 2 of 2.",
                                             "Still there? Press any key for more time. In 10 seconds this visit ends",
                                             "Thank you for visiting. Goodbye."};
  ASSERT_EQ(said.size(), want_prefix.size()) << std::ifstream(dir / "log.txt").rdbuf();
  for (std::size_t i = 0; i < said.size(); ++i) EXPECT_EQ(said[i].rfind(want_prefix[i], 0), 0u) << said[i];
  fs::remove_all(dir);
}

}  // namespace
