// save_settings_atomic: round trip, and on every failure the old file stays as it was.

#include <gtest/gtest.h>

#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "config/load.hpp"
#include "config_test_util.hpp"
#include "without_file_override.hpp"

namespace hk::config {
namespace {

namespace fs = std::filesystem;
using test::capture_error;
using test::is_one_line;
using test::list_dir;
using test::read_file;
using test::TempDir;
using test::write_file;

Settings some_settings() {
  Settings s;
  s.haptics.stiffness_n_per_m = 1500.25;
  s.vision.canny_low = 40;
  s.vision.canny_high = 120;
  s.workspace.height_m = 0.0812345678901234;
  return s;
}

TEST(ConfigSave, SaveThenLoadRoundTrip) {
  TempDir dir;
  const std::string path = (dir.path() / "settings.toml").string();
  const Settings s = some_settings();
  save_settings_atomic(s, path);
  EXPECT_EQ(load_settings(path), s);
  EXPECT_EQ(read_file(path), to_toml(s));
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"settings.toml"}) << "temporary file left behind";
  EXPECT_EQ(fs::status(path).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read | fs::perms::others_read);
}

TEST(ConfigSave, OverwritesAnExistingFileAndKeepsItsMode) {
  TempDir dir;
  const auto path = dir.path() / "settings.toml";
  save_settings_atomic(Settings{}, path.string());
  fs::permissions(path, fs::perms::owner_read | fs::perms::owner_write);
  const Settings s = some_settings();
  save_settings_atomic(s, path.string());
  EXPECT_EQ(load_settings(path.string()), s);
  EXPECT_EQ(fs::status(path).permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write);
  // The replaced file is kept as .bak (test_store.cpp); no temporary file is left.
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"settings.toml", "settings.toml.bak"}));
}

TEST(ConfigSave, RelativePathInTheCurrentDirectory) {
  TempDir dir;
  const fs::path old_cwd = fs::current_path();
  fs::current_path(dir.path());
  EXPECT_NO_THROW(save_settings_atomic(Settings{}, "plain.toml"));
  fs::current_path(old_cwd);
  EXPECT_EQ(load_settings((dir.path() / "plain.toml").string()), Settings{});
}

TEST(ConfigSave, InvalidSettingsAreNotSavedAndTheFileIsUntouched) {
  TempDir dir;
  const auto path = dir.path() / "settings.toml";
  write_file(path, "# operator's file\n[haptics]\nlevel = 2\n");
  Settings bad;
  bad.haptics.max_force_n = -1;
  auto e = capture_error([&] { save_settings_atomic(bad, path.string()); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "haptics.max_force_n");
  EXPECT_EQ(std::string(e->what()),
            "config '" + path.string() + "': haptics.max_force_n = -1 is out of range [0.1, 20] N; not saved");
  EXPECT_EQ(read_file(path), "# operator's file\n[haptics]\nlevel = 2\n");
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"settings.toml"});
}

TEST(ConfigSave, MissingDirectoryThrowsAndCreatesNothing) {
  TempDir dir;
  const auto path = dir.path() / "no_such_dir" / "settings.toml";
  auto e = capture_error([&] { save_settings_atomic(Settings{}, path.string()); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(is_one_line(e->what())) << e->what();
  EXPECT_NE(std::string(e->what()).find(path.string()), std::string::npos) << e->what();
  EXPECT_NE(std::string(e->what()).find("No such file or directory"), std::string::npos) << e->what();
  EXPECT_FALSE(fs::exists(dir.path() / "no_such_dir"));
  EXPECT_TRUE(list_dir(dir.path()).empty());
}

TEST(ConfigSave, ParentThatIsAFileThrows) {
  TempDir dir;
  write_file(dir.path() / "notadir", "x");
  auto e = capture_error([&] { save_settings_atomic(Settings{}, (dir.path() / "notadir" / "s.toml").string()); });
  ASSERT_TRUE(e);
  EXPECT_EQ(read_file(dir.path() / "notadir"), "x");
}

TEST(ConfigSave, TargetThatIsADirectoryThrowsAndLeavesNoTemporary) {
  TempDir dir;
  fs::create_directory(dir.path() / "settings.toml");
  write_file(dir.path() / "settings.toml" / "keep", "k");
  auto e = capture_error([&] { save_settings_atomic(Settings{}, (dir.path() / "settings.toml").string()); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(is_one_line(e->what())) << e->what();
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"settings.toml"});
  EXPECT_EQ(read_file(dir.path() / "settings.toml" / "keep"), "k");
}

TEST(ConfigSave, ReadOnlyDirectoryThrowsAndLeavesTheFileUnchanged) {
  TempDir dir;
  const auto path = dir.path() / "settings.toml";
  const std::string original = "# operator's file\n[hand]\nmax_force_n = 1.5\n";
  write_file(path, original);
  fs::permissions(dir.path(), fs::perms::owner_read | fs::perms::owner_exec);
  // The save runs as the kiosk's service user would: root's override of file modes (CAP_DAC_OVERRIDE)
  // dropped, so the read-only directory refuses it under root (CI) too.
  auto e = hk::test::without_file_override(
      [&] { return capture_error([&] { save_settings_atomic(some_settings(), path.string()); }); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(is_one_line(e->what())) << e->what();
  EXPECT_NE(std::string(e->what()).find("Permission denied"), std::string::npos) << e->what();
  EXPECT_EQ(read_file(path), original);
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"settings.toml"});
}

/// Limits the size of files this process may write (RLIMIT_FSIZE), restoring it at scope exit.
/// Writes past the limit fail with EFBIG (SIGXFSZ is ignored meanwhile). Works for root too.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &old_);
    old_handler_ = ::signal(SIGXFSZ, SIG_IGN);
    rlimit lim = old_;
    lim.rlim_cur = bytes;
    ok_ = ::setrlimit(RLIMIT_FSIZE, &lim) == 0;
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &old_);
    ::signal(SIGXFSZ, old_handler_);
  }
  bool ok() const { return ok_; }

 private:
  rlimit old_{};
  void (*old_handler_)(int) = nullptr;
  bool ok_ = false;
};

TEST(ConfigSave, WriteFailureLeavesTheFileUnchanged) {
  // Stands in for a full disk: the temporary file can't be written completely.
  TempDir dir;
  const auto path = dir.path() / "settings.toml";
  const std::string original = to_toml(Settings{});  // larger than the limit below
  write_file(path, original);
  std::optional<ConfigError> e;
  {
    FileSizeLimit limit(256);
    ASSERT_TRUE(limit.ok());
    e = capture_error([&] { save_settings_atomic(some_settings(), path.string()); });
  }
  ASSERT_TRUE(e);
  EXPECT_TRUE(is_one_line(e->what())) << e->what();
  EXPECT_NE(std::string(e->what()).find("not saved: cannot write"), std::string::npos) << e->what();
  EXPECT_EQ(read_file(path), original);
  EXPECT_EQ(load_settings(path.string()), Settings{});
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"settings.toml"}) << "temporary file left behind";
}

}  // namespace
}  // namespace hk::config
