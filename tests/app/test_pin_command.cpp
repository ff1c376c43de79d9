// `haptic-kiosk pin set|check --config FILE` run as the real executable (each run a new process, so the
// lockout must live in the state file), and the panel's PinVerifier (check_pin on a worker thread).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include "config/load.hpp"
#include "config/operator_pin.hpp"
#include "visit/pin_verifier.hpp"

#include "letter_dir.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using namespace hk;

namespace {

/// A fresh folder named without digits (letter_dir.hpp).
class LetterDir : public hk::test::LetterDir {
 public:
  LetterDir() : hk::test::LetterDir("hk_pin_command_") {}
};

std::string read_text(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

struct ExeResult {
  int status = -1;
  std::string err;
};

/// `printf '%s\n' PIN | haptic-kiosk pin ACTION --config CFG`, capturing stderr. `stdin_text` is put in
/// single quotes (the tests use digits and letters only).
ExeResult run_pin(const std::string& action, const std::string& stdin_text, const fs::path& cfg) {
  const fs::path err = cfg.parent_path() / "stderr.txt";
  const std::string cmd = "printf '%s\\n' '" + stdin_text + "' | " + std::string(HK_KIOSK_EXE) + " pin " + action +
                          " --config '" + cfg.string() + "' >/dev/null 2>'" + err.string() + "'";
  ExeResult r;
  const int raw = std::system(cmd.c_str());
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128;
  r.err = read_text(err);
  return r;
}

bool one_line(const std::string& err) {
  return !err.empty() && err.back() == '\n' && err.find('\n') == err.size() - 1 && err.find('\r') == std::string::npos;
}

/// Settings with a value other than the default in every table (and all of [operator] but the hash).
config::Settings non_default_settings() {
  config::Settings s;
  s.haptics.stiffness_n_per_m = 1234.5;
  s.haptics.level_mode = "fixed";
  s.device.max_torque_n_m = 0.6;  // strong enough for the 3.5 N walls over the taller workspace
  s.hand.max_force_n = 2.5;
  s.vision.max_segments = 12345;
  s.workspace.height_m = 0.1;
  s.audio.speech_rate_wpm = 200;
  s.kiosk.warning_s = 15;
  s.stick.max_documents = 77;
  s.keys.describe = "F5";
  s.operator_.open_chord = "CTRL+ALT+SHIFT+K";
  s.operator_.idle_close_s = 45;
  s.operator_.audit_log = "audit.txt";
  return s;
}

std::int64_t now_unix_s() {
  using namespace std::chrono;
  return duration_cast<seconds>(system_clock::now().time_since_epoch()).count();
}

/// Polls `v` until an outcome arrives (the wait only bounds a hang; it decides nothing).
std::optional<app::PinOutcome> wait_outcome(app::PinVerifier& v) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    if (auto o = v.poll()) return o;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return std::nullopt;
}

}  // namespace

// ---- the command -----------------------------------------------------------------------------------

TEST(PinCommand, SetThenCheckRightAndWrong) {
  LetterDir dir;
  const fs::path cfg = dir.path() / "kiosk.toml";
  ExeResult r = run_pin("set", "2468", cfg);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("2468"), std::string::npos) << r.err;
  r = run_pin("check", "2468", cfg);
  EXPECT_EQ(r.status, 0) << r.err;
  r = run_pin("check", "1357", cfg);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_EQ(r.err.find("1357"), std::string::npos) << r.err;
  EXPECT_EQ(config::read_lockout_state(cfg.string() + ".state", now_unix_s()).failures, 1);
}

TEST(PinCommand, LockoutSurvivesBetweenProcesses) {
  LetterDir dir;
  const fs::path cfg = dir.path() / "kiosk.toml";
  ASSERT_EQ(run_pin("set", "2468", cfg).status, 0);
  for (int i = 1; i <= 3; ++i) {
    const ExeResult r = run_pin("check", "1111", cfg);
    EXPECT_EQ(r.status, 1) << r.err;
    // Each run is a new process: the count lives in the state file.
    EXPECT_EQ(config::read_lockout_state(cfg.string() + ".state", now_unix_s()).failures, i);
  }
  // 30 s of real time must pass before the next attempt is heard: the right PIN is refused unheard.
  const ExeResult r = run_pin("check", "2468", cfg);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("pin: locked for "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" s after 3 failed attempts"), std::string::npos) << r.err;
  EXPECT_EQ(config::read_lockout_state(cfg.string() + ".state", now_unix_s()).failures, 3);

  // pin set resets the count.
  ASSERT_EQ(run_pin("set", "97531", cfg).status, 0);
  EXPECT_EQ(run_pin("check", "97531", cfg).status, 0);
}

TEST(PinCommand, BadPinIsRefusedAndTheFileIsUnchanged) {
  LetterDir dir;
  const fs::path cfg = dir.path() / "kiosk.toml";
  ASSERT_EQ(run_pin("set", "2468", cfg).status, 0);
  const std::string before = read_text(cfg);
  for (const std::string bad : {"abcd", "123", "12a4", "9876543210987"}) {
    const ExeResult r = run_pin("set", bad, cfg);
    EXPECT_EQ(r.status, 1) << bad;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_EQ(r.err.rfind("pin: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find("4 to 12 digits"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find(bad), std::string::npos) << r.err;
    EXPECT_EQ(read_text(cfg), before) << bad;
  }
  EXPECT_EQ(run_pin("check", "2468", cfg).status, 0);

  // No file yet: a bad PIN creates none.
  const fs::path fresh = dir.path() / "fresh.toml";
  EXPECT_EQ(run_pin("set", "abcd", fresh).status, 1);
  EXPECT_FALSE(fs::exists(fresh));
}

TEST(PinCommand, SetKeepsEveryOtherValueWithMode0600) {
  LetterDir dir;
  const fs::path cfg = dir.path() / "kiosk.toml";
  const config::Settings before = non_default_settings();
  config::save_settings_atomic(before, cfg.string());
  ASSERT_EQ(::chmod(cfg.c_str(), 0644), 0);
  const ExeResult r = run_pin("set", "2468", cfg);
  ASSERT_EQ(r.status, 0) << r.err;
  struct stat st {};
  ASSERT_EQ(::stat(cfg.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0600u);
  config::Settings after = config::load_settings(cfg.string());
  EXPECT_TRUE(config::verify_pin(after.operator_.pin_hash, "2468"));
  after.operator_.pin_hash.clear();
  EXPECT_EQ(after, before);
}

TEST(PinCommand, CheckWithoutPinOrSettingsIsThree) {
  LetterDir dir;
  const fs::path cfg = dir.path() / "kiosk.toml";
  config::save_settings_atomic(config::Settings{}, cfg.string());
  ExeResult r = run_pin("check", "2468", cfg);
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("no PIN is set"), std::string::npos) << r.err;

  r = run_pin("check", "2468", dir.path() / "missing.toml");
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("missing.toml"), std::string::npos) << r.err;
}

TEST(PinCommand, SettingsThatDoNotParseAreLeftAlone) {
  LetterDir dir;
  const fs::path cfg = dir.path() / "kiosk.toml";
  const std::string text = "[kiosk]\ntimeout_s = oops\n";
  std::ofstream(cfg) << text;
  ExeResult r = run_pin("set", "2468", cfg);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_EQ(read_text(cfg), text);
  r = run_pin("check", "2468", cfg);
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_TRUE(one_line(r.err)) << r.err;
}

TEST(PinCommand, ActionAndConfigAreRequired) {
  LetterDir dir;
  const fs::path cfg = dir.path() / "kiosk.toml";
  EXPECT_NE(run_pin("reset", "2468", cfg).status, 0);
  const std::string cmd = std::string(HK_KIOSK_EXE) + " pin check </dev/null >/dev/null 2>&1";
  const int raw = std::system(cmd.c_str());
  EXPECT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) != 0);
  EXPECT_FALSE(fs::exists(cfg));
}

// ---- the panel's verifier --------------------------------------------------------------------------

TEST(PinVerifier, RightWrongAndOneAttemptAtATime) {
  LetterDir dir;
  const std::string cfg = (dir.path() / "kiosk.toml").string();
  config::set_pin(cfg, "2468");
  const std::int64_t t0 = 1'700'000'000;
  app::PinVerifier v(cfg);
  EXPECT_FALSE(v.busy());
  EXPECT_FALSE(v.poll());

  // Hold the state's lock, so the first attempt is certainly still under way when the second comes.
  const int fd = ::open((cfg + ".state.lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  ASSERT_TRUE(v.submit("1111", t0));
  EXPECT_TRUE(v.busy());
  EXPECT_FALSE(v.submit("2468", t0));  // ignored: one at a time
  EXPECT_FALSE(v.poll());
  ::close(fd);  // releases the lock

  auto o = wait_outcome(v);
  ASSERT_TRUE(o);
  EXPECT_EQ(o->error, "");
  EXPECT_EQ(o->attempt.verdict, config::PinVerdict::wrong);
  EXPECT_EQ(o->attempt.failures, 1);
  EXPECT_FALSE(v.poll());  // once
  EXPECT_FALSE(v.busy());

  ASSERT_TRUE(v.submit("2468", t0 + 1));
  o = wait_outcome(v);
  ASSERT_TRUE(o);
  EXPECT_EQ(o->attempt.verdict, config::PinVerdict::right);
  EXPECT_EQ(o->attempt.failures, 0);
}

TEST(PinVerifier, LockedAndTooLong) {
  LetterDir dir;
  const std::string cfg = (dir.path() / "kiosk.toml").string();
  config::set_pin(cfg, "2468");
  const std::int64_t t0 = 1'700'000'000;
  config::write_lockout_state(cfg + ".state", config::LockoutState{4, t0});
  app::PinVerifier v(cfg);
  ASSERT_TRUE(v.submit("2468", t0 + 10));
  auto o = wait_outcome(v);
  ASSERT_TRUE(o);
  EXPECT_EQ(o->attempt.verdict, config::PinVerdict::locked);
  EXPECT_EQ(o->attempt.wait_s, 50.0);
  // A long string that starts with the PIN is still no PIN.
  ASSERT_TRUE(v.submit("2468" + std::string(1000, '0'), t0 + 60));
  o = wait_outcome(v);
  ASSERT_TRUE(o);
  EXPECT_EQ(o->attempt.verdict, config::PinVerdict::wrong);
  EXPECT_EQ(o->attempt.failures, 5);
}

TEST(PinVerifier, ConfigErrorBecomesAnOutcome) {
  LetterDir dir;
  app::PinVerifier v((dir.path() / "missing.toml").string());
  ASSERT_TRUE(v.submit("2468", 1'700'000'000));
  const auto o = wait_outcome(v);
  ASSERT_TRUE(o);
  EXPECT_NE(o->error, "");
  EXPECT_EQ(o->error.find('\n'), std::string::npos);
  EXPECT_NE(o->error.find("missing.toml"), std::string::npos) << o->error;
}

TEST(PinVerifier, DestructorFinishesTheAttemptUnderWay) {
  LetterDir dir;
  const std::string cfg = (dir.path() / "kiosk.toml").string();
  config::set_pin(cfg, "2468");
  {
    app::PinVerifier v(cfg);
    ASSERT_TRUE(v.submit("1111", 1'700'000'000));
  }
  // The attempt was heard and counted before the worker stopped.
  EXPECT_EQ(config::read_lockout_state(cfg + ".state", 1'700'000'000), (config::LockoutState{1, 1'700'000'000}));
}

namespace {

/// `printf '%s\n' TEXT | haptic-kiosk pin ACTION [--config CFG]`: exit status, stdout and stderr.
struct ExeOutput {
  int status = -1;
  std::string out, err;
};
ExeOutput run_pin_out(const std::string& action, const std::string& stdin_text, const fs::path& dir,
                      const std::string& cfg) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = "printf '%s\\n' '" + stdin_text + "' | " + std::string(HK_KIOSK_EXE) + " pin " + action +
                          (cfg.empty() ? std::string() : " --config '" + cfg + "'") + " >'" + out.string() + "' 2>'" +
                          err.string() + "'";
  ExeOutput r;
  const int raw = std::system(cmd.c_str());
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128;
  r.out = read_text(out);
  r.err = read_text(err);
  return r;
}

TEST(PinCommand, HashPrintsAHashThatSetHashPutsIntoTheFileOnceAndThePinThenOpens) {
  LetterDir dir;
  const fs::path cfg = dir.path() / "kiosk.toml";
  config::Settings s = non_default_settings();
  config::save_settings_atomic(s, cfg.string());
  const ExeOutput h = run_pin_out("hash", "8642", dir.path(), "");
  ASSERT_EQ(h.status, 0) << h.err;
  const std::string hash = h.out.substr(0, h.out.find('\n'));
  EXPECT_EQ(hash.rfind("$argon2id$", 0), 0u) << h.out;
  EXPECT_TRUE(config::verify_pin(hash, "8642"));
  EXPECT_EQ(h.out.find("8642"), std::string::npos);
  // set-hash: written once, "unchanged" the second time (a roll-out run twice changes nothing).
  const ExeOutput first = run_pin_out("set-hash", hash, dir.path(), cfg.string());
  ASSERT_EQ(first.status, 0) << first.err;
  EXPECT_EQ(first.out, "set\n");
  const auto mtime = fs::last_write_time(cfg);
  const ExeOutput second = run_pin_out("set-hash", hash, dir.path(), cfg.string());
  ASSERT_EQ(second.status, 0) << second.err;
  EXPECT_EQ(second.out, "unchanged\n");
  EXPECT_EQ(fs::last_write_time(cfg), mtime);
  config::Settings after = config::load_settings(cfg.string());
  EXPECT_EQ(after.operator_.pin_hash, hash);
  after.operator_.pin_hash = s.operator_.pin_hash;
  EXPECT_EQ(after, s);  // every other value kept
  EXPECT_EQ(run_pin("check", "8642", cfg).status, 0);
}

TEST(PinCommand, SetHashRefusesWhatIsNoHashAndHashRefusesWhatIsNoPin) {
  LetterDir dir;
  const fs::path cfg = dir.path() / "kiosk.toml";
  config::save_settings_atomic(config::Settings{}, cfg.string());
  const std::string before = read_text(cfg);
  const ExeOutput bad = run_pin_out("set-hash", "1234", dir.path(), cfg.string());
  EXPECT_EQ(bad.status, 1);
  EXPECT_TRUE(one_line(bad.err)) << bad.err;
  EXPECT_NE(bad.err.find("not an argon2id hash"), std::string::npos) << bad.err;
  EXPECT_EQ(read_text(cfg), before);
  const ExeOutput short_pin = run_pin_out("hash", "12", dir.path(), "");
  EXPECT_EQ(short_pin.status, 1);
  EXPECT_TRUE(short_pin.out.empty());
  EXPECT_TRUE(one_line(short_pin.err)) << short_pin.err;
  const ExeOutput no_config = run_pin_out("set", "1234", dir.path(), "");
  EXPECT_EQ(no_config.status, 1);
  EXPECT_NE(no_config.err.find("--config FILE is needed"), std::string::npos) << no_config.err;
}

}  // namespace
