// The operator's PIN (config/operator_pin.hpp): the PIN rule, the argon2id hash, the lockout policy's
// golden values, the state file, and check_pin / set_pin on real files with explicit times.
#include <gtest/gtest.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>

#include "config/load.hpp"
#include "config/operator_pin.hpp"
#include "config_test_util.hpp"

#include "letter_dir.hpp"

namespace fs = std::filesystem;
using namespace hk::config;
using hk::config::test::capture_error;
using hk::config::test::is_one_line;
using hk::config::test::read_file;
using hk::config::test::write_file;

namespace {

/// A fresh folder named without digits (letter_dir.hpp).
class LetterDir : public hk::test::LetterDir {
 public:
  LetterDir() : hk::test::LetterDir("hk_operator_pin_") {}
};

/// Settings with a value other than the default in every table (and all of [operator] but the hash).
Settings non_default_settings() {
  Settings s;
  s.haptics.stiffness_n_per_m = 1234.5;
  s.haptics.level = 2;
  s.haptics.level_mode = "fixed";
  s.device.handle_mass_kg = 0.11;
  s.hand.raster_spacing_m = 0.0075;
  s.vision.max_segments = 12345;
  s.vision.canny_low = 20;
  s.vision.canny_high = 60;
  s.workspace.width_m = 0.2;
  s.audio.volume_default_step = 4;
  s.kiosk.timeout_s = 300;
  s.stick.max_depth = 5;
  s.keys.help = "F2";
  s.operator_.open_chord = "CTRL+SHIFT+P";
  s.operator_.idle_close_s = 90;
  s.operator_.audit_log = "panel.audit.log";
  return s;
}

constexpr std::int64_t kT0 = 1'700'000'000;

mode_t file_mode(const fs::path& p) {
  struct stat st {};
  EXPECT_EQ(::stat(p.c_str(), &st), 0) << p;
  return st.st_mode & 07777;
}

}  // namespace

// ---- the PIN rule ----------------------------------------------------------------------------------

TEST(OperatorPinRule, RefusesWhatIsNotFourToTwelveDigits) {
  EXPECT_EQ(pin_problem("123"), "a PIN is 4 to 12 digits (0-9); this one has 3");
  EXPECT_EQ(pin_problem("1234567890123"), "a PIN is 4 to 12 digits (0-9); this one has 13");
  EXPECT_EQ(pin_problem("abcd"), "a PIN is 4 to 12 digits (0-9); this one has other characters than digits");
  EXPECT_EQ(pin_problem("12a4"), "a PIN is 4 to 12 digits (0-9); this one has other characters than digits");
  EXPECT_EQ(pin_problem(""), "a PIN is 4 to 12 digits (0-9); this one is empty");
  EXPECT_NE(pin_problem("12 4"), "");
  EXPECT_NE(pin_problem("\xd9\xa1\xd9\xa2\xd9\xa3\xd9\xa4"), "");  // Arabic-Indic digits: not ASCII
}

TEST(OperatorPinRule, AcceptsFourAndTwelveDigits) {
  EXPECT_EQ(pin_problem("0000"), "");
  EXPECT_EQ(pin_problem("4711"), "");
  EXPECT_EQ(pin_problem("123456789012"), "");
}

TEST(OperatorPinRule, MessageIsOneLineAndNeverHoldsThePin) {
  for (const std::string pin : {"987", "9876543210987", "zyxw", "98a7", "98\n76", "secret-pin", "9\r8\t7"}) {
    const std::string why = pin_problem(pin);
    ASSERT_FALSE(why.empty()) << "a bad PIN was accepted";
    EXPECT_TRUE(is_one_line(why)) << why;
    EXPECT_EQ(why.find(pin), std::string::npos) << why;
  }
}

// ---- hash and verify -------------------------------------------------------------------------------

TEST(OperatorPinHash, RoundTripsAndRefusesAWrongPin) {
  const std::string h = hash_pin("2468");
  EXPECT_EQ(h.rfind("$argon2id$", 0), 0u) << h;
  EXPECT_LT(h.size(), static_cast<std::size_t>(crypto_pwhash_STRBYTES));
  EXPECT_TRUE(verify_pin(h, "2468"));
  EXPECT_FALSE(verify_pin(h, "2469"));
  EXPECT_FALSE(verify_pin(h, "24680"));
  EXPECT_FALSE(verify_pin(h, ""));
  EXPECT_FALSE(pin_hash_needs_rehash(h));
  // The field check of the settings loader accepts what hash_pin writes.
  Settings s;
  s.operator_.pin_hash = h;
  EXPECT_NO_THROW(validate(s));
}

TEST(OperatorPinHash, TwoHashesOfOnePinDiffer) {
  const std::string a = hash_pin("2468"), b = hash_pin("2468");
  EXPECT_NE(a, b);  // a fresh salt each time
  EXPECT_TRUE(verify_pin(a, "2468"));
  EXPECT_TRUE(verify_pin(b, "2468"));
}

TEST(OperatorPinHash, EmptyOrMalformedHashVerifiesNothing) {
  EXPECT_FALSE(verify_pin("", "2468"));
  EXPECT_FALSE(verify_pin("$argon2id$v=19$m=65536,t=2,p=1$garbage", "2468"));
  EXPECT_FALSE(verify_pin(std::string(500, 'x'), "2468"));
  EXPECT_TRUE(pin_hash_needs_rehash(""));
  EXPECT_TRUE(pin_hash_needs_rehash("not a hash"));
}

TEST(OperatorPinHash, BadPinIsRefusedWithoutNamingIt) {
  const auto e = capture_error([] { (void)hash_pin("98a7"); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(is_one_line(e->what()));
  EXPECT_EQ(std::string(e->what()).find("98a7"), std::string::npos) << e->what();
  EXPECT_NE(std::string(e->what()).find("other characters than digits"), std::string::npos) << e->what();
}

TEST(OperatorPinHash, OutdatedParametersNeedARehash) {
  ASSERT_GE(sodium_init(), 0);
  char weak[crypto_pwhash_STRBYTES];
  ASSERT_EQ(crypto_pwhash_str_alg(weak, "2468", 4, crypto_pwhash_argon2id_OPSLIMIT_MIN,
                                  crypto_pwhash_argon2id_MEMLIMIT_MIN, crypto_pwhash_ALG_ARGON2ID13),
            0);
  EXPECT_TRUE(verify_pin(weak, "2468"));
  EXPECT_TRUE(pin_hash_needs_rehash(weak));
}

// ---- the lockout policy ----------------------------------------------------------------------------

TEST(OperatorPinLockout, GoldenValuesOfTheDefaultPolicy) {
  const auto wait_at = [](int failures, std::int64_t since_last_failure_s) {
    return lockout_wait_s(LockoutState{failures, kT0}, kT0 + since_last_failure_s);
  };
  EXPECT_EQ(wait_at(0, 0), 0.0);
  EXPECT_EQ(wait_at(1, 0), 0.0);
  EXPECT_EQ(wait_at(2, 0), 0.0);
  EXPECT_EQ(wait_at(3, 0), 30.0);
  EXPECT_EQ(wait_at(3, 20), 10.0);
  EXPECT_EQ(wait_at(3, 30), 0.0);
  EXPECT_EQ(wait_at(3, 1000), 0.0);
  EXPECT_EQ(wait_at(4, 0), 60.0);
  EXPECT_EQ(wait_at(5, 0), 120.0);
  EXPECT_EQ(wait_at(6, 0), 240.0);
  EXPECT_EQ(wait_at(7, 0), 480.0);
  EXPECT_EQ(wait_at(8, 0), 900.0);  // 960 capped
  EXPECT_EQ(wait_at(99, 0), 900.0);
  EXPECT_EQ(wait_at(99, 900), 0.0);
  EXPECT_EQ(wait_at(100, 0), kLockedUntilPinSet);
  EXPECT_TRUE(std::isinf(wait_at(100, 1'000'000'000)));
  EXPECT_EQ(wait_at(100000, 0), kLockedUntilPinSet);
}

TEST(OperatorPinLockout, ClockGoneBackCountsAsJustNow) {
  EXPECT_EQ(lockout_wait_s(LockoutState{3, kT0}, kT0 - 5), 30.0);
  EXPECT_EQ(lockout_wait_s(LockoutState{5, kT0}, kT0 - 1'000'000), 120.0);
  EXPECT_EQ(lockout_wait_s(LockoutState{8, kT0}, 0), 900.0);
}

TEST(OperatorPinLockout, PolicyIsAParameter) {
  const LockoutPolicy p{1, 2.0, 10.0, 5};
  EXPECT_EQ(lockout_wait_s(LockoutState{0, kT0}, kT0, p), 0.0);
  EXPECT_EQ(lockout_wait_s(LockoutState{1, kT0}, kT0, p), 2.0);
  EXPECT_EQ(lockout_wait_s(LockoutState{2, kT0}, kT0, p), 4.0);
  EXPECT_EQ(lockout_wait_s(LockoutState{4, kT0}, kT0, p), 10.0);
  EXPECT_EQ(lockout_wait_s(LockoutState{5, kT0}, kT0, p), kLockedUntilPinSet);
}

// ---- the state file --------------------------------------------------------------------------------

TEST(OperatorPinState, PathIsBesideTheSettingsUnlessConfigured) {
  Settings s;
  EXPECT_EQ(state_file_path(s, "/etc/hk/kiosk.toml"), "/etc/hk/kiosk.toml.state");
  s.operator_.state_file = "/var/lib/hk/pin.state";
  EXPECT_EQ(state_file_path(s, "/etc/hk/kiosk.toml"), "/var/lib/hk/pin.state");
  s.operator_.state_file = "state/pin.state";  // relative: to the settings file's folder
  EXPECT_EQ(state_file_path(s, "/etc/hk/kiosk.toml"), "/etc/hk/state/pin.state");
}

TEST(OperatorPinState, RoundTripsWithMode0600) {
  LetterDir dir;
  const std::string path = (dir.path() / "k.toml.state").string();
  std::string note = "stale";
  EXPECT_EQ(read_lockout_state(path, kT0, &note), (LockoutState{0, 0}));  // missing file
  EXPECT_EQ(note, "");
  write_lockout_state(path, LockoutState{7, kT0 + 3});
  EXPECT_EQ(read_lockout_state(path, kT0 + 100, &note), (LockoutState{7, kT0 + 3}));
  EXPECT_EQ(note, "");
  EXPECT_EQ(file_mode(path), 0600u);
  write_lockout_state(path, LockoutState{0, 0});
  EXPECT_EQ(read_lockout_state(path, kT0), (LockoutState{0, 0}));
  // Only the state file (and no temporary) is left.
  EXPECT_EQ(hk::config::test::list_dir(dir.path()), std::vector<std::string>{"k.toml.state"});
}

TEST(OperatorPinState, CorruptFileCountsAsThreeFailuresNow) {
  LetterDir dir;
  const fs::path path = dir.path() / "k.toml.state";
  const std::string garbage("\xff\xfe\x00\x01\x9c\x80 failures = \x07\xc3\x28\x00\xa0\xa1\x8f\x0d\x0a\xf0\x28\x8c\xbc",
                            24);
  write_file(path, garbage);
  std::string note;
  EXPECT_EQ(read_lockout_state(path.string(), kT0 + 5, &note), (LockoutState{3, kT0 + 5}));
  EXPECT_FALSE(note.empty());
  EXPECT_TRUE(is_one_line(note)) << note;
  EXPECT_NE(note.find("fail safe"), std::string::npos) << note;
  EXPECT_EQ(lockout_wait_s(read_lockout_state(path.string(), kT0 + 5), kT0 + 5), 30.0);

  // Nonsense that parses is as untrusted as garbage.
  for (const std::string text :
       {"failures = -1\nlast_failure_unix_s = 0\n", "failures = 2\n", "failures = \"2\"\nlast_failure_unix_s = 0\n",
        "failures = 2\nlast_failure_unix_s = 0\nextra = 1\n", "",
        "failures = 99999999999\nlast_failure_unix_s = 0\n"}) {
    write_file(path, text);
    EXPECT_EQ(read_lockout_state(path.string(), kT0, &note), (LockoutState{3, kT0})) << text;
    EXPECT_FALSE(note.empty()) << text;
  }
}

TEST(OperatorPinState, UnwritableFolderIsAOneLineError) {
  const auto e = capture_error([] { write_lockout_state("/nonexistent-hk-folder/k.state", LockoutState{1, kT0}); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(is_one_line(e->what()));
  EXPECT_NE(std::string(e->what()).find("/nonexistent-hk-folder/k.state"), std::string::npos) << e->what();
}

// ---- check_pin / pin_status / set_pin --------------------------------------------------------------

TEST(OperatorPinCheck, ThreeWrongThenLockedThenRightAfterTheDelay) {
  LetterDir dir;
  const std::string cfg = (dir.path() / "k.toml").string();
  set_pin(cfg, "2468");
  const std::string state = cfg + ".state";

  PinAttempt a = check_pin(cfg, "1111", kT0);
  EXPECT_EQ(a.verdict, PinVerdict::wrong);
  EXPECT_EQ(a.failures, 1);
  EXPECT_EQ(a.wait_s, 0.0);
  a = check_pin(cfg, "2222", kT0 + 1);
  EXPECT_EQ(a.verdict, PinVerdict::wrong);
  EXPECT_EQ(a.failures, 2);
  a = check_pin(cfg, "3333", kT0 + 2);
  EXPECT_EQ(a.verdict, PinVerdict::wrong);
  EXPECT_EQ(a.failures, 3);
  EXPECT_EQ(a.wait_s, 30.0);
  EXPECT_EQ(read_lockout_state(state, kT0 + 2), (LockoutState{3, kT0 + 2}));

  // Inside the 30 s: the right PIN is not heard, and nothing is counted.
  a = check_pin(cfg, "2468", kT0 + 12);
  EXPECT_EQ(a.verdict, PinVerdict::locked);
  EXPECT_EQ(a.failures, 3);
  EXPECT_EQ(a.wait_s, 20.0);
  a = check_pin(cfg, "9999", kT0 + 31);
  EXPECT_EQ(a.verdict, PinVerdict::locked);
  EXPECT_EQ(a.wait_s, 1.0);
  EXPECT_EQ(read_lockout_state(state, kT0 + 31), (LockoutState{3, kT0 + 2}));
  const PinAttempt st = pin_status(cfg, kT0 + 31);
  EXPECT_EQ(st.verdict, PinVerdict::locked);
  EXPECT_EQ(st.failures, 3);
  EXPECT_EQ(st.wait_s, 1.0);

  // After the 30 s: heard, right, counter reset.
  EXPECT_EQ(pin_status(cfg, kT0 + 32).verdict, PinVerdict::right);
  a = check_pin(cfg, "2468", kT0 + 32);
  EXPECT_EQ(a.verdict, PinVerdict::right);
  EXPECT_EQ(a.failures, 0);
  EXPECT_EQ(a.wait_s, 0.0);
  EXPECT_EQ(read_lockout_state(state, kT0 + 32), (LockoutState{0, 0}));
}

TEST(OperatorPinCheck, FourthFailureDoublesTheDelay) {
  LetterDir dir;
  const std::string cfg = (dir.path() / "k.toml").string();
  set_pin(cfg, "2468");
  write_lockout_state(cfg + ".state", LockoutState{3, kT0});
  const PinAttempt a = check_pin(cfg, "abcd", kT0 + 30);  // heard (the 30 s are over), not a PIN: wrong
  EXPECT_EQ(a.verdict, PinVerdict::wrong);
  EXPECT_EQ(a.failures, 4);
  EXPECT_EQ(a.wait_s, 60.0);
}

TEST(OperatorPinCheck, CorruptStateFileLocksThenItsDelayEnds) {
  LetterDir dir;
  const std::string cfg = (dir.path() / "k.toml").string();
  set_pin(cfg, "2468");
  write_file(cfg + ".state", std::string("\x80\x81\xfe\xff\x00junk", 9));
  PinAttempt a = check_pin(cfg, "2468", kT0);
  EXPECT_EQ(a.verdict, PinVerdict::locked);
  EXPECT_EQ(a.failures, 3);
  EXPECT_EQ(a.wait_s, 30.0);
  // The fail-safe reading was written down, so the delay counts from the first look and ends.
  EXPECT_EQ(read_lockout_state(cfg + ".state", kT0 + 5), (LockoutState{3, kT0}));
  a = check_pin(cfg, "2468", kT0 + 30);
  EXPECT_EQ(a.verdict, PinVerdict::right);
}

TEST(OperatorPinCheck, NoPinSetAndMissingSettings) {
  LetterDir dir;
  const std::string cfg = (dir.path() / "k.toml").string();
  save_settings_atomic(Settings{}, cfg);
  PinAttempt a = check_pin(cfg, "2468", kT0);
  EXPECT_EQ(a.verdict, PinVerdict::no_pin);
  EXPECT_EQ(pin_status(cfg, kT0).verdict, PinVerdict::no_pin);
  EXPECT_FALSE(fs::exists(cfg + ".state"));  // nothing counted

  const std::string missing = (dir.path() / "missing.toml").string();
  const auto e = capture_error([&] { (void)check_pin(missing, "2468", kT0); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(is_one_line(e->what()));
  EXPECT_NE(std::string(e->what()).find("missing.toml"), std::string::npos);
}

TEST(OperatorPinCheck, RightPinRehashesAnOutdatedHashKeepingEverythingElse) {
  LetterDir dir;
  const std::string cfg = (dir.path() / "k.toml").string();
  ASSERT_GE(sodium_init(), 0);
  char weak[crypto_pwhash_STRBYTES];
  ASSERT_EQ(crypto_pwhash_str_alg(weak, "2468", 4, crypto_pwhash_argon2id_OPSLIMIT_MIN,
                                  crypto_pwhash_argon2id_MEMLIMIT_MIN, crypto_pwhash_ALG_ARGON2ID13),
            0);
  Settings s = non_default_settings();
  s.operator_.pin_hash = weak;
  save_settings_atomic(s, cfg);

  EXPECT_EQ(check_pin(cfg, "1357", kT0).verdict, PinVerdict::wrong);
  EXPECT_EQ(load_settings(cfg).operator_.pin_hash, weak);  // a wrong PIN changes no hash
  EXPECT_EQ(check_pin(cfg, "2468", kT0 + 1).verdict, PinVerdict::right);
  Settings after = load_settings(cfg);
  EXPECT_NE(after.operator_.pin_hash, weak);
  EXPECT_FALSE(pin_hash_needs_rehash(after.operator_.pin_hash));
  EXPECT_TRUE(verify_pin(after.operator_.pin_hash, "2468"));
  after.operator_.pin_hash = weak;
  EXPECT_EQ(after, s);
}

TEST(OperatorPinSet, KeepsEveryOtherValueWithMode0600) {
  LetterDir dir;
  const std::string cfg = (dir.path() / "k.toml").string();
  const Settings before = non_default_settings();
  save_settings_atomic(before, cfg);
  ::chmod(cfg.c_str(), 0644);
  set_pin(cfg, "2468");
  Settings after = load_settings(cfg);
  EXPECT_TRUE(verify_pin(after.operator_.pin_hash, "2468"));
  EXPECT_EQ(file_mode(cfg), 0600u);
  after.operator_.pin_hash.clear();
  EXPECT_EQ(after, before);
  // A second pin set replaces the hash: the old PIN no longer opens.
  set_pin(cfg, "97531");
  after = load_settings(cfg);
  EXPECT_TRUE(verify_pin(after.operator_.pin_hash, "97531"));
  EXPECT_FALSE(verify_pin(after.operator_.pin_hash, "2468"));
}

TEST(OperatorPinSet, MissingFileStartsFromTheDefaults) {
  LetterDir dir;
  const std::string cfg = (dir.path() / "new.toml").string();
  set_pin(cfg, "2468");
  Settings s = load_settings(cfg);
  EXPECT_TRUE(verify_pin(s.operator_.pin_hash, "2468"));
  EXPECT_EQ(file_mode(cfg), 0600u);
  s.operator_.pin_hash.clear();
  EXPECT_EQ(s, Settings{});
}

TEST(OperatorPinSet, FileThatDoesNotParseIsRefusedAndLeftAsItWas) {
  LetterDir dir;
  const fs::path cfg = dir.path() / "k.toml";
  const std::string text = "[haptics]\nstiffness_n_per_m = = 900\n# hand-written\n";
  write_file(cfg, text);
  const auto e = capture_error([&] { set_pin(cfg.string(), "2468"); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(is_one_line(e->what()));
  EXPECT_NE(std::string(e->what()).find("k.toml"), std::string::npos) << e->what();
  EXPECT_EQ(std::string(e->what()).find("2468"), std::string::npos) << e->what();
  EXPECT_EQ(read_file(cfg), text);
  EXPECT_FALSE(fs::exists(cfg.string() + ".state"));
}

TEST(OperatorPinSet, BadPinIsRefusedAndNothingChanges) {
  LetterDir dir;
  const fs::path cfg = dir.path() / "k.toml";
  save_settings_atomic(non_default_settings(), cfg.string());
  const std::string text = read_file(cfg);
  for (const std::string pin : {"987", "zyxw", "98a7", "9876543210987"}) {
    const auto e = capture_error([&] { set_pin(cfg.string(), pin); });
    ASSERT_TRUE(e);
    EXPECT_TRUE(is_one_line(e->what()));
    EXPECT_EQ(std::string(e->what()).find(pin), std::string::npos) << e->what();
    EXPECT_EQ(read_file(cfg), text);
  }
  const fs::path missing = dir.path() / "missing.toml";
  EXPECT_TRUE(capture_error([&] { set_pin(missing.string(), "12"); }));
  EXPECT_FALSE(fs::exists(missing));
}

TEST(OperatorPinSet, UnlocksAPinLockedForGood) {
  LetterDir dir;
  const std::string cfg = (dir.path() / "k.toml").string();
  set_pin(cfg, "2468");
  write_lockout_state(cfg + ".state", LockoutState{100, kT0});
  PinAttempt a = check_pin(cfg, "2468", kT0 + 1'000'000);
  EXPECT_EQ(a.verdict, PinVerdict::locked);
  EXPECT_EQ(a.wait_s, kLockedUntilPinSet);
  EXPECT_EQ(a.failures, 100);

  set_pin(cfg, "8642");
  EXPECT_EQ(read_lockout_state(cfg + ".state", kT0), (LockoutState{0, 0}));
  EXPECT_EQ(pin_status(cfg, kT0 + 1'000'001).verdict, PinVerdict::right);
  a = check_pin(cfg, "8642", kT0 + 1'000'001);
  EXPECT_EQ(a.verdict, PinVerdict::right);
}

TEST(OperatorPinSet, ConfiguredStateFileIsTheOneUsed) {
  LetterDir dir;
  const std::string cfg = (dir.path() / "k.toml").string();
  Settings s;
  s.operator_.state_file = "lockout.state";  // relative to the settings file's folder
  save_settings_atomic(s, cfg);
  set_pin(cfg, "2468");
  EXPECT_EQ(check_pin(cfg, "1111", kT0).verdict, PinVerdict::wrong);
  EXPECT_EQ(read_lockout_state((dir.path() / "lockout.state").string(), kT0), (LockoutState{1, kT0}));
  EXPECT_FALSE(fs::exists(cfg + ".state"));
}

TEST(OperatorPinCheck, LockFileBesideTheStateFile) {
  LetterDir dir;
  const std::string cfg = (dir.path() / "k.toml").string();
  set_pin(cfg, "2468");
  EXPECT_EQ(check_pin(cfg, "1111", kT0).verdict, PinVerdict::wrong);
  EXPECT_TRUE(fs::is_regular_file(cfg + ".state"));
  EXPECT_TRUE(fs::is_regular_file(cfg + ".state.lock"));
  EXPECT_EQ(file_mode(cfg + ".state.lock"), 0600u);
}
