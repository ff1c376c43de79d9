// A scripted operator's visit to the real kiosk under Xvfb: the key chord,
// a wrong PIN, the right PIN, stiffness 800 → 1200 N/m typed into the panel, Apply, Save. Every key and
// click goes through the kiosk's input routing and Dear ImGui, as a real one would. Afterwards the settings
// file has 1200, its .bak 800, the audit log the change, and neither PIN appears in anything the kiosk wrote.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "config/load.hpp"
#include "config/operator_pin.hpp"
#include "kiosk_exe.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

namespace {

using hk::test::read_text;
using hk::test::sh;

const fs::path kData = HK_TEST_DATA_DIR;
const std::string kNoGlLeakCheck = "ASAN_OPTIONS=detect_leaks=0 ";  // Mesa's DRI driver (see test_kiosk_screen.cpp)

/// Saves `s` as `settings` and sets the operator's PIN 90817263 in it with `haptic-kiosk pin set`, as an
/// operator would; true when it worked.
bool settings_with_pin(const hk::config::Settings& s, const fs::path& settings) {
  hk::config::save_settings_atomic(s, settings.string());
  return sh("printf '90817263\\n' | " + std::string(HK_KIOSK_EXE) + " pin set --config '" + settings.string() +
            "' 2>/dev/null") == 0;
}

TEST(OperatorVisit, WrongPinRightPinStiffness800To1200ApplySaveUnderXvfb) {
  if (sh("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps.sh installs it)";
  const fs::path dir = fs::temp_directory_path() / ("hk_opvisit_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "library");
  fs::copy_file(kData / "images" / "horse.png", dir / "library" / "horse.png");
  const fs::path settings = dir / "kiosk.toml";
  hk::config::Settings s;
  s.stick.page_timeout_s = 60;  // generous under a loaded CI machine; not what is tested
  ASSERT_TRUE(settings_with_pin(s, settings));
  const std::string exe = HK_KIOSK_EXE;
  const std::string hash = hk::config::load_settings(settings.string()).operator_.pin_hash;

  std::ofstream(dir / "visit.txt") << "# the operator's visit\n"
                                      "10 press CTRL+ALT+O\n"
                                      "20 type 55443322\n"
                                      "21 press ENTER\n"
                                      "22 wait\n"
                                      "40 type 90817263\n"
                                      "41 press ENTER\n"
                                      "42 wait\n"
                                      "60 click tab:Haptics\n"
                                      "70 click haptics.stiffness_n_per_m\n"
                                      "80 type 1200\n"
                                      "81 press ENTER\n"
                                      "90 click Apply\n"
                                      "100 click Save\n";
  const fs::path png = dir / "panel.png", log = dir / "log.txt";
  ASSERT_EQ(sh(kNoGlLeakCheck + "timeout 300 xvfb-run -a -s '-screen 0 1280x720x24' " + exe +
               " --no-hotplug --config '" + settings.string() + "' --library '" + (dir / "library").string() +
               "' --show '" + (dir / "library" / "horse.png").string() + "' --script '" + (dir / "visit.txt").string() +
               "' --screenshot '" + png.string() + "' --frames 130 >'" + log.string() + "' 2>&1"),
            0)
      << read_text(log);

  const hk::config::Settings saved = hk::config::load_settings(settings.string());
  EXPECT_EQ(saved.haptics.stiffness_n_per_m, 1200.0) << read_text(log);
  EXPECT_EQ(saved.operator_.pin_hash, hash) << "the PIN survives the panel's save";
  EXPECT_EQ(hk::config::load_settings(settings.string() + ".bak").haptics.stiffness_n_per_m, 800.0);
  const std::string audit = read_text(dir / "kiosk.toml.audit.log");
  EXPECT_NE(audit.find("PIN refused, 1 failed attempts"), std::string::npos) << audit;
  EXPECT_NE(audit.find("panel opened"), std::string::npos) << audit;
  EXPECT_NE(audit.find("panel haptics.stiffness_n_per_m 800.0 -> 1200.0"), std::string::npos) << audit;
  EXPECT_NE(audit.find("saved"), std::string::npos) << audit;
  // The lockout counted the wrong PIN and the right one reset it.
  EXPECT_EQ(hk::config::read_lockout_state(settings.string() + ".state", 0).failures, 0);
  // No PIN in the log, the audit or the settings.
  for (const std::string& text : {read_text(log), audit, read_text(settings)}) {
    EXPECT_EQ(text.find("90817263"), std::string::npos);
    EXPECT_EQ(text.find("55443322"), std::string::npos);
  }
  const cv::Mat img = cv::imread(png.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.cols, 1280);
  fs::remove_all(dir);
}

}  // namespace

namespace {

// Finish pressed twice while a stick's page is still being drawn, then a scripted `wait`: the run goes on (the
// wait returns: nothing of the forgotten stick is awaited), and the operator's panel, opened with the PIN,
// says on its Status tab that the sticks are idle, not "working".
TEST(OperatorVisit, FinishWhileAStickPageIsDrawnLeavesThePanelsStatusIdle) {
  if (sh("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps.sh installs it)";
  const fs::path dir = fs::temp_directory_path() / ("hk_opfinish_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "library");
  fs::create_directories(dir / "stick");
  fs::copy_file(kData / "images" / "horse.png", dir / "library" / "horse.png");
  fs::copy_file(kData / "documents" / "shared-mime-info-spec.pdf", dir / "stick" / "spec.pdf");  // 17 pages to draw
  const fs::path settings = dir / "kiosk.toml";
  hk::config::Settings s;
  s.kiosk.prefetch_mb = 0;  // page 2 is drawn when Next asks for it, not ahead
  ASSERT_TRUE(settings_with_pin(s, settings));
  const std::string exe = HK_KIOSK_EXE;
  std::ofstream(dir / "visit.txt") << "1 stick " << (dir / "stick").string()
                                   << "\n"
                                      "2 wait\n"
                                      "3 key next\n"    // page 2 is drawn...
                                      "4 key finish\n"  // ...and Finish, twice, meanwhile
                                      "5 key finish\n"
                                      "6 wait\n"
                                      "10 press CTRL+ALT+O\n"
                                      "20 type 90817263\n"
                                      "21 press ENTER\n"
                                      "22 wait\n"
                                      "40 shows sticks:idle\n";
  const fs::path png = dir / "panel.png", log = dir / "log.txt";
  ASSERT_EQ(sh(kNoGlLeakCheck + "timeout 300 xvfb-run -a -s '-screen 0 1280x720x24' " + exe +
               " --no-hotplug --config '" + settings.string() + "' --library '" + (dir / "library").string() +
               "' --script '" + (dir / "visit.txt").string() + "' --screenshot '" + png.string() + "' --frames 50 >'" +
               log.string() + "' 2>&1"),
            0)
      << read_text(log);
  const std::string said = read_text(log);
  EXPECT_NE(said.find("say: Thank you for visiting. Goodbye."), std::string::npos) << said;
  fs::remove_all(dir);
}

}  // namespace
