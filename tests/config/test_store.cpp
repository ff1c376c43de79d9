// Settings that are never lost: the .bak kept by the atomic save (with faults injected at every stage,
// crashes included), the start-up load that keeps a corrupt file aside, the audit log, and the operator
// panel's one-field edits checked exactly as the loader checks them.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/load.hpp"
#include "config/store.hpp"
#include "config_test_util.hpp"

namespace hk::config {
namespace {

namespace fs = std::filesystem;
using test::capture_error;
using test::data_dir;
using test::is_one_line;
using test::list_dir;
using test::read_file;
using test::TempDir;
using test::write_file;

constexpr std::int64_t kNov22 = 1795316645;  // 2026-11-22T03:04:05Z (date -u -d @1795316645)
const std::string kHash = "$argon2id$v=19$m=65536,t=2,p=1$c29tZXNhbHRzb21lc2FsdA$aGFzaGhhc2hoYXNoaGFzaGhhc2g";

Settings settings_a() {
  Settings s;
  s.haptics.stiffness_n_per_m = 1000;
  return s;
}
Settings settings_b() {
  Settings s;
  s.haptics.stiffness_n_per_m = 2000;
  s.keys.next = "N";
  return s;
}
Settings settings_c() {
  Settings s;
  s.audio.volume_default_step = 3;
  s.workspace.height_m = 0.0812345678901234;
  return s;
}

fs::perms mode_of(const fs::path& p) { return fs::status(p).permissions() & fs::perms::all; }

/// Sets the modification time of `p` (seconds since the epoch, UTC).
void set_mtime(const fs::path& p, std::int64_t unix_s) {
  const timespec times[2] = {{static_cast<time_t>(unix_s), 0}, {static_cast<time_t>(unix_s), 0}};
  if (::utimensat(AT_FDCWD, p.c_str(), times, 0) != 0) throw std::runtime_error("utimensat failed");
}

// ---------------------------------------------------------------------------------------------
// The .bak kept by save_settings_atomic

TEST(StoreBackup, EachSaveKeepsTheFileItReplacesAsBak) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  const fs::path bak = dir.path() / "settings.toml.bak";
  save_settings_atomic(settings_a(), path.string());
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"settings.toml"}) << "nothing to keep on the first save";
  fs::permissions(path, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);

  save_settings_atomic(settings_b(), path.string());
  EXPECT_EQ(load_settings(path.string()), settings_b());
  EXPECT_EQ(load_settings(bak.string()), settings_a());
  EXPECT_EQ(read_file(bak), to_toml(settings_a()));
  const auto rw_r = fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read;
  EXPECT_EQ(mode_of(path), rw_r) << "the new file keeps the mode";
  EXPECT_EQ(mode_of(bak), rw_r) << "the .bak is the old file, with its mode";
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"settings.toml", "settings.toml.bak"}));

  save_settings_atomic(settings_c(), path.string());
  EXPECT_EQ(load_settings(path.string()), settings_c());
  EXPECT_EQ(load_settings(bak.string()), settings_b());
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"settings.toml", "settings.toml.bak"}));
}

TEST(StoreBackup, WithoutKeepBackupNoBakIsWritten) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  save_settings_atomic(settings_a(), path.string(), {.keep_backup = false, .hook = {}});
  save_settings_atomic(settings_b(), path.string(), {.keep_backup = false, .hook = {}});
  EXPECT_EQ(load_settings(path.string()), settings_b());
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"settings.toml"});
}

TEST(StoreBackup, AFileWithAPinHashAndItsBakAre0600) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  Settings with_pin = settings_a();
  with_pin.operator_.pin_hash = kHash;
  save_settings_atomic(with_pin, path.string());
  EXPECT_EQ(mode_of(path), fs::perms::owner_read | fs::perms::owner_write);
  save_settings_atomic(settings_b(), path.string());  // the PIN removed: the old file (with the hash) is the .bak
  EXPECT_EQ(load_settings((dir.path() / "settings.toml.bak").string()), with_pin);
  EXPECT_EQ(mode_of(dir.path() / "settings.toml.bak"), fs::perms::owner_read | fs::perms::owner_write);
}

TEST(StoreBackup, ABakThatCannotBeReplacedStopsTheSaveAndChangesNothing) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  save_settings_atomic(settings_a(), path.string());
  fs::create_directory(dir.path() / "settings.toml.bak");
  write_file(dir.path() / "settings.toml.bak" / "keep", "k");
  auto e = capture_error([&] { save_settings_atomic(settings_b(), path.string()); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(is_one_line(e->what())) << e->what();
  EXPECT_NE(std::string(e->what()).find("settings.toml.bak"), std::string::npos) << e->what();
  EXPECT_NE(std::string(e->what()).find("not saved"), std::string::npos) << e->what();
  EXPECT_EQ(load_settings(path.string()), settings_a());
  EXPECT_EQ(read_file(dir.path() / "settings.toml.bak" / "keep"), "k");
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"settings.toml", "settings.toml.bak"}))
      << "temporary files left behind";
}

TEST(StoreBackup, WhereNoHardLinkIsAllowedTheOldFileIsCopiedToBak) {
  // The kernel refuses a hard link to another user's file that one may not write (fs.protected_hardlinks),
  // as a file system without hard links (vfat) does: EPERM. Staged as root: the directory is handed to
  // "nobody", the settings file stays root's (0644), and a child process saves as "nobody".
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to hand files to another user";
  if (read_file("/proc/sys/fs/protected_hardlinks").rfind('1', 0) != 0)
    GTEST_SKIP() << "fs.protected_hardlinks is off: the kernel would allow the link";
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  save_settings_atomic(settings_a(), path.string());
  constexpr uid_t kNobody = 65534;
  ASSERT_EQ(::chown(dir.path().c_str(), kNobody, kNobody), 0);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    int code = 1;
    if (::setgid(kNobody) == 0 && ::setuid(kNobody) == 0) {
      try {
        save_settings_atomic(settings_b(), path.string());
        code = 0;
      } catch (...) {
        code = 2;
      }
    }
    ::_exit(code);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 0) << "the save as nobody failed (1: could not become nobody, 2: it threw)";
  EXPECT_EQ(load_settings(path.string()), settings_b());
  const fs::path bak = dir.path() / "settings.toml.bak";
  EXPECT_EQ(read_file(bak), to_toml(settings_a()));
  EXPECT_EQ(mode_of(bak),
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read | fs::perms::others_read);
  struct stat st {};
  ASSERT_EQ(::stat(bak.c_str(), &st), 0);
  EXPECT_EQ(st.st_uid, kNobody) << "a copy, not a link to root's file";
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"settings.toml", "settings.toml.bak"}));
}

TEST(StoreBackup, InvalidSettingsAreRefusedBeforeAnyHook) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  save_settings_atomic(settings_a(), path.string());
  Settings bad;
  bad.haptics.level = 9;  // > max_levels
  int calls = 0;
  auto e = capture_error(
      [&] { save_settings_atomic(bad, path.string(), {.keep_backup = true, .hook = [&](SaveStage) { ++calls; }}); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "haptics.level");
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"settings.toml"});
}

TEST(StoreBackup, TheHookSeesTheStagesInOrder) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  save_settings_atomic(settings_a(), path.string());
  std::vector<SaveStage> seen;
  std::vector<std::string> path_then;
  save_settings_atomic(settings_b(), path.string(), {.keep_backup = true, .hook = [&](SaveStage s) {
                                                       seen.push_back(s);
                                                       path_then.push_back(read_file(path));
                                                     }});
  EXPECT_EQ(seen, (std::vector<SaveStage>{SaveStage::temp_written, SaveStage::backup_kept, SaveStage::renamed}));
  ASSERT_EQ(path_then.size(), 3u);
  EXPECT_EQ(path_then[0], to_toml(settings_a()));
  EXPECT_EQ(path_then[1], to_toml(settings_a()));
  EXPECT_EQ(path_then[2], to_toml(settings_b()));
}

// ---------------------------------------------------------------------------------------------
// Faults at every stage of the save: a crash (the hook _exits in a child process) or a throw.

constexpr const char* kCrashDirEnv = "HK_TEST_STORE_CRASH_DIR";

/// Unsets an environment variable at scope exit.
struct UnsetEnvAtExit {
  const char* name;
  ~UnsetEnvAtExit() { ::unsetenv(name); }
};

class StoreCrash : public ::testing::TestWithParam<SaveStage> {};

/// The names a save may leave after a crash: the file, its .bak, and ".settings.toml.tmp.*".
void expect_only_settings_bak_and_temporaries(const fs::path& dir) {
  for (const auto& name : list_dir(dir))
    EXPECT_TRUE(name == "settings.toml" || name == "settings.toml.bak" || name.rfind(".settings.toml.tmp.", 0) == 0)
        << name;
}

TEST_P(StoreCrash, ACrashLeavesTheOldOrTheNewFileAndALoadableBak) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const SaveStage stage = GetParam();
  const Settings previous = settings_a(), old = settings_b(), fresh = settings_c();
  // The "threadsafe" death test re-runs this test in a child process; the child must crash in the
  // parent's directory, which the parent names in the environment (set up only once, by the parent).
  std::optional<TempDir> own;
  fs::path dir;
  if (const char* parents = std::getenv(kCrashDirEnv)) {
    dir = parents;
  } else {
    own.emplace();
    dir = own->path();
    save_settings_atomic(previous, (dir / "settings.toml").string());
    save_settings_atomic(old, (dir / "settings.toml").string());
    ::setenv(kCrashDirEnv, dir.c_str(), 1);
  }
  UnsetEnvAtExit unset{kCrashDirEnv};
  const std::string path = (dir / "settings.toml").string();

  EXPECT_EXIT(save_settings_atomic(fresh, path,
                                   {.keep_backup = true,
                                    .hook =
                                        [stage](SaveStage s) {
                                          if (s == stage) ::_exit(42);
                                        }}),
              ::testing::ExitedWithCode(42), "");

  const Settings now = load_settings(path);
  const Settings bak = load_settings(path + ".bak");
  switch (stage) {
    case SaveStage::temp_written:
      EXPECT_EQ(now, old);
      EXPECT_EQ(bak, previous);
      break;
    case SaveStage::backup_kept:
      EXPECT_EQ(now, old);
      EXPECT_EQ(bak, old);
      break;
    case SaveStage::renamed:
      EXPECT_EQ(now, fresh);
      EXPECT_EQ(bak, old);
      break;
  }
  expect_only_settings_bak_and_temporaries(dir);
  // The next save after the crash works and rotates as usual.
  save_settings_atomic(previous, path);
  EXPECT_EQ(load_settings(path), previous);
  EXPECT_EQ(load_settings(path + ".bak"), now);
}

TEST_P(StoreCrash, AThrowingHookLeavesNoTemporaryFiles) {
  const SaveStage stage = GetParam();
  TempDir dir;
  const std::string path = (dir.path() / "settings.toml").string();
  save_settings_atomic(settings_a(), path);
  save_settings_atomic(settings_b(), path);
  struct Injected : std::runtime_error {
    Injected() : std::runtime_error("injected") {}
  };
  EXPECT_THROW(save_settings_atomic(settings_c(), path,
                                    {.keep_backup = true,
                                     .hook =
                                         [stage](SaveStage s) {
                                           if (s == stage) throw Injected();
                                         }}),
               Injected);
  EXPECT_EQ(load_settings(path), stage == SaveStage::renamed ? settings_c() : settings_b());
  EXPECT_EQ(load_settings(path + ".bak"), stage == SaveStage::temp_written ? settings_a() : settings_b());
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"settings.toml", "settings.toml.bak"}))
      << "temporary file left behind";
}

INSTANTIATE_TEST_SUITE_P(EveryStage, StoreCrash,
                         ::testing::Values(SaveStage::temp_written, SaveStage::backup_kept, SaveStage::renamed),
                         [](const ::testing::TestParamInfo<SaveStage>& info) {
                           switch (info.param) {
                             case SaveStage::temp_written:
                               return std::string("temp_written");
                             case SaveStage::backup_kept:
                               return std::string("backup_kept");
                             case SaveStage::renamed:
                               return std::string("renamed");
                           }
                           return std::string("unknown");
                         });

// ---------------------------------------------------------------------------------------------
// load_settings_with_fallback

/// The message load_settings gives for the file at `path` (which must fail).
std::string loader_message(const fs::path& path) {
  auto e = capture_error([&] { (void)load_settings(path.string()); });
  return e ? e->what() : "";
}

const std::string kCorruptSuffix = ".corrupt-20261122T030405Z";
constexpr std::int64_t kBakTime = 1795284000;  // 2026-11-21T18:00:00Z

struct CorruptCase {
  const char* name;
  std::string bytes;
};

class StoreCorrupt : public ::testing::TestWithParam<CorruptCase> {};

TEST_P(StoreCorrupt, IsKeptAsideAndTheBakRuns) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  const std::string& bytes = GetParam().bytes;
  write_file(path, bytes);
  write_file(dir.path() / "settings.toml.bak", to_toml(settings_a()));
  set_mtime(dir.path() / "settings.toml.bak", kBakTime);
  const std::string problem = loader_message(path);
  ASSERT_FALSE(problem.empty());

  const LoadedSettings r = load_settings_with_fallback(path.string(), kNov22);
  EXPECT_EQ(r.settings, settings_a());
  EXPECT_EQ(r.from, LoadedSettings::From::backup);
  EXPECT_EQ(r.corrupt_path, path.string() + kCorruptSuffix);
  EXPECT_EQ(read_file(r.corrupt_path), bytes) << "the bad file is kept byte for byte";
  EXPECT_FALSE(fs::exists(path)) << "the .bak is not copied over the file: the next save writes it";
  EXPECT_EQ(read_file(dir.path() / "settings.toml.bak"), to_toml(settings_a()));
  EXPECT_TRUE(is_one_line(r.notice)) << r.notice;
  EXPECT_EQ(r.notice, problem + "; the file is kept as '" + r.corrupt_path +
                          "'; running the .bak of 2026-11-21T18:00:00Z instead");
}

INSTANTIATE_TEST_SUITE_P(
    RealGarbage, StoreCorrupt,
    ::testing::Values(CorruptCase{"png", read_file(data_dir() / "images" / "coins.png")},
                      CorruptCase{"out_of_range", read_file(data_dir() / "bad" / "config_out_of_range.toml")},
                      CorruptCase{"syntax", read_file(data_dir() / "bad" / "config_syntax.toml")},
                      CorruptCase{"cross_field", "[haptics]\nlevel = 9\n"}, CorruptCase{"empty_table_name", "[]\n"},
                      CorruptCase{"too_large", std::string(kMaxConfigFileBytes + 1, '#')}),
    [](const ::testing::TestParamInfo<CorruptCase>& info) { return std::string(info.param.name); });

TEST(StoreFallback, AGoodFileLoadsAndNothingIsMoved) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  save_settings_atomic(settings_a(), path.string());
  save_settings_atomic(settings_b(), path.string());
  const LoadedSettings r = load_settings_with_fallback(path.string(), kNov22);
  EXPECT_EQ(r.settings, settings_b());
  EXPECT_EQ(r.from, LoadedSettings::From::file);
  EXPECT_TRUE(r.corrupt_path.empty());
  EXPECT_TRUE(r.notice.empty());
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"settings.toml", "settings.toml.bak"}));
}

TEST(StoreFallback, WithoutABakTheDefaultsRun) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  const std::string png = read_file(data_dir() / "images" / "coins.png");
  write_file(path, png);
  const std::string problem = loader_message(path);
  const LoadedSettings r = load_settings_with_fallback(path.string(), kNov22);
  EXPECT_EQ(r.settings, Settings{});
  EXPECT_EQ(r.from, LoadedSettings::From::defaults);
  EXPECT_EQ(read_file(path.string() + kCorruptSuffix), png);
  EXPECT_EQ(r.notice, problem + "; the file is kept as '" + path.string() + kCorruptSuffix +
                          "'; running the defaults (there is no .bak)");
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"settings.toml" + kCorruptSuffix});
}

TEST(StoreFallback, ACorruptBakMeansTheDefaultsAndTheBakIsLeftAlone) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  write_file(path, "[haptics]\nstiffness_n_per_m = -5\n");
  write_file(dir.path() / "settings.toml.bak", "[haptics\nbroken");
  const LoadedSettings r = load_settings_with_fallback(path.string(), kNov22);
  EXPECT_EQ(r.settings, Settings{});
  EXPECT_EQ(r.from, LoadedSettings::From::defaults);
  EXPECT_EQ(r.corrupt_path, path.string() + kCorruptSuffix);
  EXPECT_TRUE(is_one_line(r.notice)) << r.notice;
  EXPECT_NE(r.notice.find("haptics.stiffness_n_per_m = -5 is out of range"), std::string::npos) << r.notice;
  EXPECT_NE(r.notice.find(r.corrupt_path), std::string::npos) << r.notice;
  EXPECT_NE(r.notice.find("running the defaults (the .bak does not load either)"), std::string::npos) << r.notice;
  EXPECT_EQ(read_file(dir.path() / "settings.toml.bak"), "[haptics\nbroken");
}

TEST(StoreFallback, AnExistingCorruptNameIsNeverReused) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  const std::string taken = path.string() + kCorruptSuffix;
  write_file(taken, "earlier bad file");
  write_file(taken + "-1", "another earlier bad file");
  write_file(path, "garbage = = =");
  write_file(dir.path() / "settings.toml.bak", to_toml(settings_b()));

  const LoadedSettings r = load_settings_with_fallback(path.string(), kNov22);
  EXPECT_EQ(r.corrupt_path, taken + "-2");
  EXPECT_EQ(read_file(r.corrupt_path), "garbage = = =");
  EXPECT_EQ(read_file(taken), "earlier bad file");
  EXPECT_EQ(read_file(taken + "-1"), "another earlier bad file");
  EXPECT_EQ(r.settings, settings_b());
  EXPECT_NE(r.notice.find(taken + "-2"), std::string::npos) << r.notice;
}

TEST(StoreFallback, TheNextSaveWritesTheFileAndLeavesTheBak) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  write_file(path, "\x89PNG\r\n\x1a\n");
  write_file(dir.path() / "settings.toml.bak", to_toml(settings_a()));
  const LoadedSettings r = load_settings_with_fallback(path.string(), kNov22);
  ASSERT_EQ(r.from, LoadedSettings::From::backup);
  save_settings_atomic(r.settings, path.string());
  EXPECT_EQ(load_settings(path.string()), settings_a());
  EXPECT_EQ(load_settings((dir.path() / "settings.toml.bak").string()), settings_a());
  EXPECT_EQ(read_file(r.corrupt_path), "\x89PNG\r\n\x1a\n");
  EXPECT_EQ(load_settings_with_fallback(path.string(), kNov22 + 1).from, LoadedSettings::From::file);
}

TEST(StoreFallback, AMissingFileIsAnErrorNotTheDefaults) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.tolm";
  write_file(dir.path() / "settings.tolm.bak", to_toml(settings_a()));
  auto e = capture_error([&] { (void)load_settings_with_fallback(path.string(), kNov22); });
  ASSERT_TRUE(e);
  EXPECT_EQ(std::string(e->what()), loader_message(path));
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"settings.tolm.bak"});
}

TEST(StoreFallback, ADirectoryIsAnErrorAndIsNotMoved) {
  TempDir dir;
  fs::create_directory(dir.path() / "settings.toml");
  auto e = capture_error([&] { (void)load_settings_with_fallback((dir.path() / "settings.toml").string(), kNov22); });
  ASSERT_TRUE(e);
  EXPECT_EQ(std::string(e->what()), loader_message(dir.path() / "settings.toml"));
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"settings.toml"});
}

TEST(StoreFallback, ABadFileThatCannotBeMovedStaysAndTheNoticeSaysSo) {
  TempDir dir;
  const fs::path path = dir.path() / "settings.toml";
  write_file(path, "[haptics]\nstiffness_n_per_m = -5\n");
  write_file(dir.path() / "settings.toml.bak", to_toml(settings_a()));
  fs::permissions(dir.path(), fs::perms::owner_read | fs::perms::owner_exec);
  if (::access(dir.path().c_str(), W_OK) == 0)
    GTEST_SKIP() << "running with permission to write into a read-only directory (root?)";
  const LoadedSettings r = load_settings_with_fallback(path.string(), kNov22);
  EXPECT_EQ(r.settings, settings_a());
  EXPECT_EQ(r.from, LoadedSettings::From::backup);
  EXPECT_TRUE(r.corrupt_path.empty());
  EXPECT_TRUE(is_one_line(r.notice)) << r.notice;
  EXPECT_NE(r.notice.find("could not be moved aside (Permission denied) and stays at '" + path.string() + "'"),
            std::string::npos)
      << r.notice;
  EXPECT_EQ(read_file(path), "[haptics]\nstiffness_n_per_m = -5\n");
}

// ---------------------------------------------------------------------------------------------
// The audit log

TEST(StoreAudit, DiffGivesEachChangedFieldAsTomlText) {
  Settings before;
  Settings after;
  after.haptics.stiffness_n_per_m = 1200;
  after.keys.next = "N";
  EXPECT_EQ(diff_settings(before, after), (std::vector<SettingChange>{{"haptics.stiffness_n_per_m", "800.0", "1200.0"},
                                                                      {"keys.next", "\"RIGHT\"", "\"N\""}}));
  EXPECT_TRUE(diff_settings(after, after).empty());
  after.haptics.max_levels = 8;
  after.vision.max_file_bytes = 2048;
  const auto changes = diff_settings(before, after);
  ASSERT_EQ(changes.size(), 4u);
  EXPECT_EQ(changes[1], (SettingChange{"haptics.max_levels", "6", "8"}));
  EXPECT_EQ(changes[2], (SettingChange{"vision.max_file_bytes", "67108864", "2048"}));
}

TEST(StoreAudit, AppendWritesTheGoldenLines) {
  TempDir dir;
  const fs::path log = dir.path() / "settings.toml.audit.log";
  Settings after;
  after.haptics.stiffness_n_per_m = 1200;
  after.keys.next = "N";
  append_audit(log.string(), kNov22, "panel", diff_settings(Settings{}, after));
  EXPECT_EQ(read_file(log),
            "2026-11-22T03:04:05Z panel haptics.stiffness_n_per_m 800.0 -> 1200.0\n"
            "2026-11-22T03:04:05Z panel keys.next \"RIGHT\" -> \"N\"\n");
  EXPECT_EQ(mode_of(log), fs::perms::owner_read | fs::perms::owner_write);
  append_audit_event(log.string(), kNov22 + 60, "panel", "saved");
  append_audit(log.string(), kNov22 + 61, "panel", {});  // nothing changed: nothing written
  EXPECT_EQ(read_file(log),
            "2026-11-22T03:04:05Z panel haptics.stiffness_n_per_m 800.0 -> 1200.0\n"
            "2026-11-22T03:04:05Z panel keys.next \"RIGHT\" -> \"N\"\n"
            "2026-11-22T03:05:05Z panel saved\n");
}

TEST(StoreAudit, NoChangesCreateNoLog) {
  TempDir dir;
  append_audit((dir.path() / "a.log").string(), kNov22, "panel", {});
  EXPECT_TRUE(list_dir(dir.path()).empty());
}

TEST(StoreAudit, ThePinHashNeverReachesTheLog) {
  TempDir dir;
  const fs::path log = dir.path() / "audit.log";
  Settings none, set, changed;
  set.operator_.pin_hash = kHash;
  changed.operator_.pin_hash = kHash + "x";
  EXPECT_EQ(diff_settings(none, set), (std::vector<SettingChange>{{"operator.pin_hash", "\"\"", "(set)"}}));
  EXPECT_EQ(diff_settings(set, changed), (std::vector<SettingChange>{{"operator.pin_hash", "(set)", "(changed)"}}));
  EXPECT_EQ(diff_settings(changed, none), (std::vector<SettingChange>{{"operator.pin_hash", "(set)", "(removed)"}}));
  append_audit(log.string(), kNov22, "pin", diff_settings(none, set));
  append_audit(log.string(), kNov22, "pin", diff_settings(set, changed));
  append_audit(log.string(), kNov22, "pin", diff_settings(changed, none));
  const std::string text = read_file(log);
  EXPECT_EQ(text,
            "2026-11-22T03:04:05Z pin operator.pin_hash \"\" -> (set)\n"
            "2026-11-22T03:04:05Z pin operator.pin_hash (set) -> (changed)\n"
            "2026-11-22T03:04:05Z pin operator.pin_hash (set) -> (removed)\n");
  EXPECT_EQ(text.find("argon2"), std::string::npos);
}

TEST(StoreAudit, ControlCharactersStayOnOneLine) {
  TempDir dir;
  const fs::path log = dir.path() / "audit.log";
  Settings before, after;
  after.operator_.audit_log = "/var/log/a\nb";  // invalid, but the diff must still be safe
  append_audit(log.string(), kNov22, "panel", diff_settings(before, after));
  append_audit(log.string(), kNov22, "pa\nnel", {{"x.y", "\"a\r\nb\"", "c\td\x01"}});
  append_audit_event(log.string(), kNov22, "panel", "opened\nforged line");
  EXPECT_EQ(read_file(log),
            "2026-11-22T03:04:05Z panel operator.audit_log \"\" -> \"/var/log/a\\nb\"\n"
            "2026-11-22T03:04:05Z pa\\x0Anel x.y \"a\\x0D\\x0Ab\" -> c\\x09d\\x01\n"
            "2026-11-22T03:04:05Z panel opened\\x0Aforged line\n");
}

TEST(StoreAudit, AnUnwritableLogThrowsOneLineNamingIt) {
  TempDir dir;
  const std::string log = (dir.path() / "no_such_dir" / "audit.log").string();
  for (int event = 0; event < 2; ++event) {
    auto e = capture_error([&] {
      if (event)
        append_audit_event(log, kNov22, "panel", "saved");
      else
        append_audit(log, kNov22, "panel", {{"a.b", "1", "2"}});
    });
    ASSERT_TRUE(e);
    EXPECT_TRUE(is_one_line(e->what())) << e->what();
    EXPECT_EQ(e->source(), log);
    EXPECT_EQ(std::string(e->what()),
              "audit log '" + log + "': not written: cannot open it: No such file or directory");
  }
}

TEST(StoreAudit, LogPathIsTheSettingOrBesideTheSettingsFile) {
  Settings s;
  EXPECT_EQ(audit_log_path(s, "/etc/hk/settings.toml"), "/etc/hk/settings.toml.audit.log");
  s.operator_.audit_log = "/var/log/hk-audit.log";
  EXPECT_EQ(audit_log_path(s, "/etc/hk/settings.toml"), "/var/log/hk-audit.log");
}

// ---------------------------------------------------------------------------------------------
// The operator panel's one-field edits

const FieldDescriptor& field(std::string_view table, std::string_view key) {
  const FieldDescriptor* d = find_field(table, key);
  if (!d) throw std::logic_error("no field " + std::string(table) + "." + std::string(key));
  return *d;
}

/// The message parse_settings gives for `toml`, re-attributed to the panel: "config 'operator panel': "
/// becomes "operator panel: " and the " (line N)" suffix goes.
std::string loader_message_as_panel(const std::string& toml) {
  auto e = capture_error([&] { (void)parse_settings(toml, "operator panel"); });
  if (!e) return "(the loader accepted it)";
  std::string m = e->what();
  const std::string file_prefix = "config 'operator panel': ";
  EXPECT_EQ(m.rfind(file_prefix, 0), 0u) << m;
  m = "operator panel: " + m.substr(file_prefix.size());
  // Drop a trailing " (line N)" (std::regex is avoided: GCC 12 warns about it under the sanitizers).
  if (const std::size_t at = m.rfind(" (line "); at != std::string::npos && m.back() == ')' &&
                                                 m.find_first_not_of("0123456789", at + 7) == m.size() - 1 &&
                                                 m.size() > at + 8)
    m.erase(at);
  return m;
}

TEST(StorePanelEdit, AcceptsAValueAndSetsIt) {
  Settings s;
  EXPECT_EQ(set_field_from_text(s, field("haptics", "stiffness_n_per_m"), "1200"), "");
  Settings expected;
  expected.haptics.stiffness_n_per_m = 1200;
  EXPECT_EQ(s, expected);
  EXPECT_EQ(set_field_from_text(s, field("haptics", "stiffness_n_per_m"), "  1250.5\t"), "");
  EXPECT_EQ(s.haptics.stiffness_n_per_m, 1250.5);
  EXPECT_EQ(set_field_from_text(s, field("haptics", "damping_n_s_per_m"), "+2e-1"), "");
  EXPECT_EQ(s.haptics.damping_n_s_per_m, 0.2);
  EXPECT_EQ(set_field_from_text(s, field("keys", "next"), "N"), "");
  EXPECT_EQ(s.keys.next, "N");
  EXPECT_EQ(set_field_from_text(s, field("haptics", "level_mode"), "fixed"), "");
  EXPECT_EQ(s.haptics.level_mode, "fixed");
  EXPECT_EQ(set_field_from_text(s, field("vision", "max_file_bytes"), "2147483648"), "");
  EXPECT_EQ(s.vision.max_file_bytes, 2147483648LL);
  EXPECT_EQ(set_field_from_text(s, field("operator", "open_chord"), "CTRL+SHIFT+F12"), "");
  EXPECT_EQ(s.operator_.open_chord, "CTRL+SHIFT+F12");
}

struct LoaderCase {
  const char* table;
  const char* key;
  const char* typed;      ///< as typed in the panel
  const char* toml_text;  ///< the same value in a TOML file
};

class StorePanelRefusal : public ::testing::TestWithParam<LoaderCase> {};

TEST_P(StorePanelRefusal, GivesTheLoadersMessageAndChangesNothing) {
  const LoaderCase& c = GetParam();
  Settings s = settings_b();
  const Settings before = s;
  const std::string msg = set_field_from_text(s, field(c.table, c.key), c.typed);
  EXPECT_EQ(msg, loader_message_as_panel("[" + std::string(c.table) + "]\n" + c.key + " = " + c.toml_text + "\n"));
  EXPECT_TRUE(is_one_line(msg)) << msg;
  EXPECT_EQ(s, before);
}

INSTANTIATE_TEST_SUITE_P(
    SameAsTheLoader, StorePanelRefusal,
    ::testing::Values(LoaderCase{"haptics", "stiffness_n_per_m", "9000", "9000"},
                      LoaderCase{"haptics", "stiffness_n_per_m", " -5 ", "-5"},
                      LoaderCase{"haptics", "stiffness_n_per_m", "1e4", "1e4"},
                      LoaderCase{"haptics", "stiffness_n_per_m", "9000.0", "9000.0"},
                      LoaderCase{"haptics", "stiffness_n_per_m", "inf", "inf"},
                      LoaderCase{"haptics", "stiffness_n_per_m", "nan", "nan"},
                      LoaderCase{"haptics", "max_levels", "13", "13"},
                      LoaderCase{"haptics", "level", "7", "7"},                // cross-field: level <= max_levels (6)
                      LoaderCase{"haptics", "static_friction", "0.1", "0.1"},  // cross-field: dynamic (0.3) <= static
                      LoaderCase{"vision", "max_file_bytes", "2147483649", "2147483649"},
                      LoaderCase{"keys", "next", "FOO", "\"FOO\""}, LoaderCase{"keys", "next", "right", "\"right\""},
                      LoaderCase{"haptics", "level_mode", "sometimes", "\"sometimes\""},
                      LoaderCase{"device", "type", "phantom", "\"phantom\""},
                      LoaderCase{"operator", "open_chord", "O", "\"O\""},
                      LoaderCase{"operator", "audit_log", "/tmp/a\tb", "\"/tmp/a\\tb\""}),
    [](const ::testing::TestParamInfo<LoaderCase>& info) { return "case_" + std::to_string(info.index); });

TEST(StorePanelEdit, CannyLowAboveCannyHighIsRefusedWithTheCrossFieldMessage) {
  Settings s;
  s.vision.canny_high = 40;
  const Settings before = s;
  const std::string msg = set_field_from_text(s, field("vision", "canny_low"), "50");
  EXPECT_EQ(msg, loader_message_as_panel("[vision]\ncanny_high = 40\ncanny_low = 50\n"));
  EXPECT_EQ(s, before);
}

TEST(StorePanelEdit, ANonNumberIsRefusedWithOneLine) {
  Settings s = settings_b();
  const Settings before = s;
  EXPECT_EQ(set_field_from_text(s, field("haptics", "stiffness_n_per_m"), "abc"),
            "operator panel: haptics.stiffness_n_per_m = \"abc\" is not a number; expected a number in [10, 5000] N/m");
  EXPECT_EQ(set_field_from_text(s, field("haptics", "stiffness_n_per_m"), ""),
            "operator panel: haptics.stiffness_n_per_m = \"\" is not a number; expected a number in [10, 5000] N/m");
  EXPECT_EQ(
      set_field_from_text(s, field("haptics", "stiffness_n_per_m"), "1_000"),
      "operator panel: haptics.stiffness_n_per_m = \"1_000\" is not a number; expected a number in [10, 5000] N/m");
  EXPECT_EQ(
      set_field_from_text(s, field("haptics", "stiffness_n_per_m"), "12\n00"),
      "operator panel: haptics.stiffness_n_per_m = \"12\\x0A00\" is not a number; expected a number in [10, 5000] N/m");
  EXPECT_EQ(set_field_from_text(s, field("haptics", "level"), "two"),
            "operator panel: haptics.level = \"two\" is not a number; expected an integer in [0, 12]");
  EXPECT_EQ(s, before);
}

TEST(StorePanelEdit, AFractionIsRefusedForAnIntegerField) {
  Settings s = settings_b();
  const Settings before = s;
  EXPECT_EQ(set_field_from_text(s, field("haptics", "level"), "2.5"),
            "operator panel: haptics.level = 2.5 is not an integer; expected an integer in [0, 12]");
  EXPECT_EQ(set_field_from_text(s, field("haptics", "level"), "2.0"),
            "operator panel: haptics.level = 2.0 is not an integer; expected an integer in [0, 12]")
      << "as in the file, where 2.0 is a float";
  EXPECT_EQ(set_field_from_text(s, field("audio", "buffer_frames"), "99999999999999999999"),
            "operator panel: audio.buffer_frames = 99999999999999999999 is out of range [32, 4096] frames");
  EXPECT_EQ(s, before);
}

TEST(StorePanelEdit, CrossFieldRulesUseTheOtherValuesOfTheSettings) {
  Settings s;
  s.haptics.max_levels = 3;
  EXPECT_EQ(set_field_from_text(s, field("haptics", "level"), "3"), "");
  const Settings before = s;
  EXPECT_EQ(
      set_field_from_text(s, field("haptics", "level"), "4"),
      "operator panel: haptics.level = 4 must be <= haptics.max_levels = 3 (only levels 0..max_levels are built)");
  EXPECT_EQ(
      set_field_from_text(s, field("haptics", "max_levels"), "2"),
      "operator panel: haptics.level = 3 must be <= haptics.max_levels = 2 (only levels 0..max_levels are built)");
  EXPECT_EQ(s, before);
}

TEST(StorePanelEdit, FieldTextShowsValuesForEditing) {
  const Settings d;
  EXPECT_EQ(field_text(d, field("haptics", "stiffness_n_per_m")), "800");
  EXPECT_EQ(field_text(d, field("haptics", "level_error_at_rest_m")), "0.0001");
  EXPECT_EQ(field_text(d, field("hand", "raster_spacing_m")), "0.006");
  EXPECT_EQ(field_text(d, field("haptics", "max_levels")), "6");
  EXPECT_EQ(field_text(d, field("vision", "max_file_bytes")), "67108864");
  EXPECT_EQ(field_text(d, field("keys", "next")), "RIGHT");
  EXPECT_EQ(field_text(d, field("operator", "open_chord")), "CTRL+ALT+O");
  EXPECT_EQ(field_text(d, field("operator", "pin_hash")), "");
}

TEST(StorePanelEdit, FieldTextRoundTripsForEveryField) {
  Settings odd = settings_c();
  odd.haptics.level_error_at_rest_m = 0.1 + 0.2 - 0.3 + 1e-4;  // not a short decimal
  odd.hand.raster_spacing_m = 0.0005000000000000001;
  odd.stick.page_max_pixels = 12345678.9;
  odd.audio.duck_db = -13.25;
  odd.operator_.pin_hash = kHash;
  odd.operator_.audit_log = "/var/log/with space.log";
  for (const Settings& base : {Settings{}, odd}) {
    for (const auto& d : field_descriptors()) {
      const std::string text = field_text(base, d);
      Settings t = base;
      EXPECT_EQ(set_field_from_text(t, d, text), "") << d.table << "." << d.key << " = " << text;
      EXPECT_EQ(t, base) << d.table << "." << d.key << " = " << text;
    }
  }
}

}  // namespace
}  // namespace hk::config
