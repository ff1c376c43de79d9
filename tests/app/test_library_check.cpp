// `haptic-kiosk library check DIR`, run as staff run it before a roll-out: the shipped library passes; a library of
// real bad files (tests/data/bad) gets one `FILE: reason` line per problem, each naming what is wrong, and exit 1;
// the settings' limits apply; a hidden sync-tool file is passed over; a folder that cannot be read, or bad
// settings, exit 2 with one line; an empty library is a problem of its own.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "kiosk_exe.hpp"
#include "test_paths.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;

struct CheckRun {
  int status = -1;
  std::vector<std::string> out;  ///< standard output, a line each
  std::string err;
};

CheckRun library_check(const std::string& args, const fs::path& tmp) {
  const fs::path out = tmp / "out.txt", err = tmp / "err.txt";
  CheckRun r;
  r.status =
      hk::test::sh(std::string(HK_KIOSK_EXE) + " library check " + args + " >" + out.string() + " 2>" + err.string());
  std::istringstream lines(hk::test::read_text(out));
  for (std::string l; std::getline(lines, l);) r.out.push_back(l);
  r.err = hk::test::read_text(err);
  return r;
}

/// The one output line about `file`, "" when there is none (and a failure when there are several).
std::string line_about(const CheckRun& r, const std::string& file) {
  std::vector<std::string> found;
  for (const std::string& l : r.out)
    if (l.rfind(file + ": ", 0) == 0) found.push_back(l);
  EXPECT_LE(found.size(), 1u) << file;
  return found.empty() ? std::string() : found[0];
}

TEST(LibraryCheck, TheShippedLibraryPasses) {
  const fs::path tmp = hk::test::fresh_dir("library_check_shipped");
  const CheckRun r = library_check(hk::test::quoted(HK_SHIPPED_PICTURES_DIR), tmp);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out.front();
  EXPECT_NE(r.err.find(": 4 pictures, 0 problems"), std::string::npos) << r.err;
  fs::remove_all(tmp);
}

TEST(LibraryCheck, EachBadFileIsOneLineSayingWhatIsWrong) {
  const fs::path tmp = hk::test::fresh_dir("library_check_bad");
  const fs::path lib = tmp / "library", bad = fs::path(HK_TEST_DATA_DIR) / "bad";
  fs::create_directories(lib);
  for (const char* f : {"horse.png", "horse.toml"}) fs::copy_file(fs::path(HK_SHIPPED_PICTURES_DIR) / f, lib / f);
  for (const char* f : {"truncated.jpg", "not_an_image.png", "huge_declared.png", "empty.png"})
    fs::copy_file(bad / f, lib / f);
  fs::copy_file(bad / "annotations_mixed.json", lib / "horse.annotations.json");
  std::ofstream(lib / "truncated.toml") << "title = \"A truncated picture\"\ncolour = \"red\"\n";
  std::ofstream(lib / "hrose.annotations.json") << "{}";  // a misspelt name
  std::ofstream(lib / ".syncthing.coins.png.tmp") << "half a picture";
  std::ofstream(lib / "README.txt") << "pictures for gallery 2";

  const CheckRun r = library_check(hk::test::quoted(lib), tmp);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(line_about(r, "truncated.jpg").find("end-of-image marker"), std::string::npos);
  EXPECT_NE(line_about(r, "not_an_image.png").find("unknown image format"), std::string::npos);
  EXPECT_NE(line_about(r, "huge_declared.png").find("exceeds the limit"), std::string::npos);
  EXPECT_NE(line_about(r, "empty.png").find("empty"), std::string::npos);
  EXPECT_NE(line_about(r, "truncated.toml").find("unknown key 'colour'"), std::string::npos);
  EXPECT_NE(line_about(r, "hrose.annotations.json").find("no picture named 'hrose.*'"), std::string::npos);
  EXPECT_EQ(line_about(r, "horse.png"), "") << "the good picture has no line";
  EXPECT_EQ(line_about(r, "horse.toml"), "");
  int annotation_lines = 0;
  for (const std::string& l : r.out) {
    EXPECT_EQ(l.find(lib.string()), std::string::npos) << "the file is named once, by its name: " << l;
    EXPECT_EQ(l.find(".syncthing"), std::string::npos) << l;
    EXPECT_EQ(l.find("README"), std::string::npos) << l;
    if (l.rfind("horse.annotations.json: annotation ", 0) == 0) ++annotation_lines;
  }
  EXPECT_GE(annotation_lines, 2) << "each annotation left out of the mixed file is a line";
  EXPECT_EQ(r.out.size(), 6u + static_cast<std::size_t>(annotation_lines));
  EXPECT_NE(r.err.find(": 5 pictures, " + std::to_string(r.out.size()) + " problems"), std::string::npos) << r.err;
  fs::remove_all(tmp);
}

TEST(LibraryCheck, TheSettingsLimitsApply) {
  const fs::path tmp = hk::test::fresh_dir("library_check_limits");
  std::ofstream(tmp / "small.toml") << "[vision]\nmax_pixels = 10000\n";
  const CheckRun r = library_check(
      hk::test::quoted(HK_SHIPPED_PICTURES_DIR) + " --config " + hk::test::quoted(tmp / "small.toml"), tmp);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out.size(), 4u) << "every shipped picture is over 10000 pixels";
  EXPECT_NE(line_about(r, "horse.png").find("exceeds the limit of 10000 pixels"), std::string::npos);
  fs::remove_all(tmp);
}

TEST(LibraryCheck, AFolderOrSettingsThatCannotBeReadExit2AndAnEmptyLibraryIsAProblem) {
  const fs::path tmp = hk::test::fresh_dir("library_check_unreadable");
  CheckRun r = library_check(hk::test::quoted(tmp / "missing"), tmp);
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty());
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find((tmp / "missing").string()), std::string::npos) << r.err;
  r = library_check(hk::test::quoted(HK_SHIPPED_PICTURES_DIR) + " --config " +
                        hk::test::quoted(fs::path(HK_TEST_DATA_DIR) / "bad" / "config_syntax.toml"),
                    tmp);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  fs::create_directories(tmp / "empty");
  r = library_check(hk::test::quoted(tmp / "empty"), tmp);
  EXPECT_EQ(r.status, 1);
  ASSERT_EQ(r.out.size(), 1u);
  EXPECT_NE(r.out[0].find("holds no picture"), std::string::npos) << r.out[0];
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace hk::app
