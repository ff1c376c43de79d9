// The operator's panel's logic without its drawing: the chord asks for the PIN, a
// wrong PIN is refused and counted, the right one opens the panel, edits are checked as the loader checks
// them, Apply hands the copy over and audits it, Save keeps the .bak, and the panel closes itself when idle.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "audio/messages.hpp"
#include "config/load.hpp"
#include "config/operator_pin.hpp"
#include "visit/fleet_settings.hpp"
#include "visit/operator_session.hpp"

namespace fs = std::filesystem;

namespace hk::app {
namespace {

constexpr std::int64_t kT0 = 1795316645;  // 2026-11-22T03:04:05Z

std::string read(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

const config::FieldDescriptor& field(const char* table, const char* key) {
  const config::FieldDescriptor* d = config::find_field(table, key);
  EXPECT_NE(d, nullptr) << table << "." << key;
  return *d;
}

class OperatorSessionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("hk_opsession_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    path_ = (dir_ / "kiosk.toml").string();
    config::save_settings_atomic(config::Settings{}, path_);
    config::set_pin(path_, "2468");
    in_use_ = config::load_settings(path_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Waits (bounded) for the PIN check on the worker thread to finish; the frame clock stands still.
  void finish_check(OperatorSession& s, double now_s) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (s.state() == PanelState::checking && std::chrono::steady_clock::now() < until) {
      s.tick(now_s, kT0);
      std::this_thread::yield();
    }
    ASSERT_NE(s.state(), PanelState::checking) << "the PIN check did not finish within 60 s";
  }

  fs::path dir_;
  std::string path_;
  config::Settings in_use_;
};

TEST_F(OperatorSessionTest, WrongPinIsRefusedAndCountedTheRightOneOpensThePanel) {
  int applied = 0;
  OperatorSession s(path_, in_use_, "", [&](const config::Settings&) {
    ++applied;
    return ApplyReport{};
  });
  EXPECT_EQ(s.state(), PanelState::closed);
  EXPECT_FALSE(captures_keyboard(s.state()));
  s.chord(1.0, kT0);
  ASSERT_EQ(s.state(), PanelState::pin_entry);
  EXPECT_TRUE(captures_keyboard(s.state()));
  s.submit_pin("1357", 1.5, kT0);
  EXPECT_EQ(s.state(), PanelState::checking);
  finish_check(s, 2.0);
  EXPECT_EQ(s.state(), PanelState::pin_entry);
  EXPECT_NE(s.message().find("Wrong PIN (1 failed attempt)."), std::string::npos) << s.message();
  EXPECT_EQ(s.message().find("1357"), std::string::npos) << "the PIN is never shown";
  s.submit_pin("2468", 2.5, kT0);
  finish_check(s, 3.0);
  ASSERT_EQ(s.state(), PanelState::open) << s.message();
  EXPECT_EQ(s.working(), in_use_);
  EXPECT_EQ(applied, 0);
  // The audit has the refusal and the opening, never a PIN.
  const std::string audit = read(dir_ / "kiosk.toml.audit.log");
  EXPECT_NE(audit.find("PIN refused, 1 failed attempts"), std::string::npos) << audit;
  EXPECT_NE(audit.find("panel opened"), std::string::npos) << audit;
  EXPECT_EQ(audit.find("1357"), std::string::npos);
  EXPECT_EQ(audit.find("2468"), std::string::npos);
}

TEST_F(OperatorSessionTest, NoPinSetMeansANoticeNotAPrompt) {
  config::Settings no_pin = in_use_;
  no_pin.operator_.pin_hash.clear();
  config::save_settings_atomic(no_pin, path_);
  OperatorSession s(path_, no_pin, "", {});
  s.chord(1.0, kT0);
  EXPECT_EQ(s.state(), PanelState::notice);
  EXPECT_FALSE(captures_keyboard(s.state())) << "the visitor's keys still work";
  EXPECT_NE(s.message().find("haptic-kiosk pin set --config " + path_), std::string::npos) << s.message();
  s.tick(1.0 + 10.0, kT0);
  EXPECT_EQ(s.state(), PanelState::closed) << "the notice goes away by itself";
  // Without a settings file at all, the panel cannot open either, and says why.
  OperatorSession none("", config::Settings{}, "", {});
  none.chord(1.0, kT0);
  EXPECT_EQ(none.state(), PanelState::notice);
  EXPECT_NE(none.message().find("--config"), std::string::npos) << none.message();
}

TEST_F(OperatorSessionTest, EditsAreCheckedAsTheLoaderChecksThemApplyAuditsAndSaveKeepsTheBak) {
  config::Settings handed;
  OperatorSession s(path_, in_use_, "", [&](const config::Settings& next) {
    handed = next;
    ApplyReport r;
    r.gains = true;
    return r;
  });
  s.chord(0.0, kT0);
  s.submit_pin("2468", 0.1, kT0);
  finish_check(s, 0.2);
  ASSERT_EQ(s.state(), PanelState::open);

  const config::FieldDescriptor& k = field("haptics", "stiffness_n_per_m");
  EXPECT_EQ(s.edit_text(k), "800");
  // Out of range: refused, saying the range, the working copy unchanged.
  s.edit_text(k) = "9000";
  const std::string why = s.commit_field(k, kT0);
  EXPECT_EQ(why, s.field_error(k));
  EXPECT_EQ(why, "9000 is out of range [10, 5000] N/m");
  EXPECT_EQ(s.working().haptics.stiffness_n_per_m, 800.0);
  EXPECT_FALSE(s.dirty());
  // In range: taken.
  s.edit_text(k) = "1200";
  EXPECT_EQ(s.commit_field(k, kT0), "");
  EXPECT_TRUE(s.field_error(k).empty());
  EXPECT_EQ(s.working().haptics.stiffness_n_per_m, 1200.0);
  EXPECT_TRUE(s.dirty());

  EXPECT_EQ(s.apply(kT0 + 1), "Applied; forces changing now.");
  EXPECT_EQ(handed.haptics.stiffness_n_per_m, 1200.0);
  EXPECT_FALSE(s.dirty());
  EXPECT_TRUE(s.unsaved());
  EXPECT_NE(read(dir_ / "kiosk.toml.audit.log").find("panel haptics.stiffness_n_per_m 800.0 -> 1200.0"),
            std::string::npos);
  EXPECT_EQ(config::load_settings(path_).haptics.stiffness_n_per_m, 800.0) << "applied is not saved";

  s.save(kT0 + 2);
  EXPECT_FALSE(s.unsaved()) << s.status();
  const config::Settings saved = config::load_settings(path_);
  EXPECT_EQ(saved.haptics.stiffness_n_per_m, 1200.0);
  EXPECT_EQ(saved.operator_.pin_hash, in_use_.operator_.pin_hash) << "the PIN survives a save";
  EXPECT_EQ(config::load_settings(path_ + ".bak").haptics.stiffness_n_per_m, 800.0);
  struct stat st {};
  ASSERT_EQ(::stat(path_.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u) << "a file with the PIN's hash";
}

TEST_F(OperatorSessionTest, APinSetWhileThePanelIsOpenIsNotUndoneBySave) {
  OperatorSession s(path_, in_use_, "", [](const config::Settings&) { return ApplyReport{}; });
  s.chord(0.0, kT0);
  s.submit_pin("2468", 0.1, kT0);
  finish_check(s, 0.2);
  ASSERT_EQ(s.state(), PanelState::open);
  config::set_pin(path_, "97531");  // another operator at the console
  const std::string new_hash = config::load_settings(path_).operator_.pin_hash;
  s.edit_text(field("kiosk", "timeout_s")) = "300";
  ASSERT_EQ(s.commit_field(field("kiosk", "timeout_s"), kT0), "");
  s.save(kT0);
  const config::Settings saved = config::load_settings(path_);
  EXPECT_EQ(saved.kiosk.timeout_s, 300.0);
  EXPECT_EQ(saved.operator_.pin_hash, new_hash);
}

TEST_F(OperatorSessionTest, ResetToDefaultsKeepsTheOperatorTableAndIsNotAppliedUntilAsked) {
  config::Settings changed = in_use_;
  changed.haptics.stiffness_n_per_m = 2000;
  changed.keys.next = "N";
  int applied = 0;
  OperatorSession s(path_, changed, "", [&](const config::Settings&) {
    ++applied;
    return ApplyReport{};
  });
  s.chord(0.0, kT0);
  s.submit_pin("2468", 0.1, kT0);
  finish_check(s, 0.2);
  ASSERT_EQ(s.state(), PanelState::open);
  s.reset_to_defaults(kT0);
  EXPECT_EQ(s.working().haptics.stiffness_n_per_m, 800.0);
  EXPECT_EQ(s.working().keys.next, "RIGHT");
  EXPECT_EQ(s.working().operator_.pin_hash, changed.operator_.pin_hash);
  EXPECT_EQ(applied, 0);
  EXPECT_EQ(s.edit_text(field("haptics", "stiffness_n_per_m")), "800");
  EXPECT_NE(read(dir_ / "kiosk.toml.audit.log").find("reset to defaults"), std::string::npos);
}

TEST_F(OperatorSessionTest, ThePanelClosesItselfAfterTheIdleTimeAndInputKeepsItOpen) {
  OperatorSession s(path_, in_use_, "", [](const config::Settings&) { return ApplyReport{}; });
  s.chord(0.0, kT0);
  s.submit_pin("2468", 0.1, kT0);
  finish_check(s, 0.2);
  ASSERT_EQ(s.state(), PanelState::open);
  const double idle = in_use_.operator_.idle_close_s;  // 60 s
  s.tick(0.2 + idle - 1.0, kT0);
  EXPECT_EQ(s.state(), PanelState::open);
  s.touch(0.2 + idle - 1.0);  // the operator types
  s.tick(0.2 + idle + 10.0, kT0);
  EXPECT_EQ(s.state(), PanelState::open) << "input restarts the idle time";
  s.tick(0.2 + 2 * idle, kT0);
  EXPECT_EQ(s.state(), PanelState::closed);
  // The prompt closes itself too.
  s.chord(500.0, kT0);
  ASSERT_EQ(s.state(), PanelState::pin_entry);
  s.tick(500.0 + idle + 0.5, kT0);
  EXPECT_EQ(s.state(), PanelState::closed);
}

TEST_F(OperatorSessionTest, TheLockoutHoldsThePromptAndTheWaitIsShown) {
  OperatorSession s(path_, in_use_, "", {});
  s.chord(0.0, kT0);
  for (int i = 0; i < 3; ++i) {
    s.submit_pin("0000", 0.1 * i, kT0);
    finish_check(s, 0.1 * i + 0.05);
  }
  EXPECT_EQ(s.state(), PanelState::pin_entry);
  EXPECT_GT(s.wait_s(), 29.0);
  EXPECT_NE(s.message().find("Try again in 30 seconds."), std::string::npos) << s.message();
  // Inside the wait, even the right PIN is not heard.
  s.submit_pin("2468", 1.0, kT0 + 1);
  EXPECT_EQ(s.state(), PanelState::pin_entry);
  s.tick(11.0, kT0 + 11);
  EXPECT_NE(s.message().find("Try again in 20 seconds."), std::string::npos) << s.message();
}

TEST_F(OperatorSessionTest, EveryLineOfThePanelIsInTheStaffsLanguage) {
  OperatorSession s(path_, in_use_, "", [](const config::Settings&) {
    ApplyReport r;
    r.scene_rebuilt = true;
    r.restart = {"audio.voice", "audio.device"};
    return r;
  });
  s.set_language("fr", audio::default_locale_dir());
  ASSERT_EQ(s.words().language(), "fr");
  s.chord(0.0, kT0);
  EXPECT_EQ(s.message(), "Saisissez le code PIN de l'opérateur, puis Entrée.");
  s.submit_pin("1357", 0.1, kT0);
  EXPECT_EQ(s.message(), "Vérification…");
  finish_check(s, 0.2);
  EXPECT_EQ(s.message(), "Code PIN erroné (1 essai manqué).") << "French plural: one attempt";
  s.submit_pin("2468", 0.3, kT0);
  finish_check(s, 0.4);
  ASSERT_EQ(s.state(), PanelState::open) << s.message();

  // A refused value says why in French, whatever kind of mistake it is; the loader's rule across fields aside.
  const config::FieldDescriptor& k = field("haptics", "stiffness_n_per_m");
  s.edit_text(k) = "9000";
  EXPECT_EQ(s.commit_field(k, kT0), "9000 est hors de l'intervalle [10, 5000] N/m");
  s.edit_text(k) = "beaucoup";
  EXPECT_EQ(s.commit_field(k, kT0), "« beaucoup » n'est pas un nombre ; valeurs permises : [10, 5000] N/m");
  const config::FieldDescriptor& levels = field("haptics", "max_levels");
  s.edit_text(levels) = "2.5";
  EXPECT_EQ(s.commit_field(levels, kT0).rfind("2.5 n'est pas un nombre entier", 0), 0u) << s.field_error(levels);
  const config::FieldDescriptor& policy = field("haptics", "level_mode");
  s.edit_text(policy) = "sometimes";
  EXPECT_EQ(s.commit_field(policy, kT0).rfind("« sometimes » ne fait pas partie des choix : \"", 0), 0u)
      << s.field_error(policy);

  s.edit_text(k) = "1200";
  ASSERT_EQ(s.commit_field(k, kT0), "");
  EXPECT_EQ(s.apply(kT0 + 1), "Appliqué; scène reconstruite; 2 réglages après un redémarrage.");
  EXPECT_EQ(s.save(kT0 + 2), "Enregistré dans " + path_ + " (le fichier précédent est gardé en .bak).");
  EXPECT_EQ(s.apply(kT0 + 3), "Rien à appliquer.");
  // The audit log stays English, whoever reads the panel.
  EXPECT_NE(read(dir_ / "kiosk.toml.audit.log").find("panel opened"), std::string::npos);

  // Back to English: the words change with [operator] language.
  s.set_language("en", audio::default_locale_dir());
  EXPECT_EQ(s.apply(kT0 + 4), "Nothing to apply.");
}

TEST_F(OperatorSessionTest, TheLockoutIsToldInTheStaffsLanguageToo) {
  OperatorSession s(path_, in_use_, "", {});
  s.set_language("fr", audio::default_locale_dir());
  s.chord(0.0, kT0);
  for (int i = 0; i < 3; ++i) {
    s.submit_pin("0000", 0.1 * i, kT0);
    finish_check(s, 0.1 * i + 0.05);
  }
  EXPECT_EQ(s.message(), "Code PIN erroné (3 essais manqués). Réessayez dans 30 secondes.");
  s.tick(29.5, kT0 + 29);
  EXPECT_EQ(s.message(), "Réessayez dans 1 seconde.");
}

}  // namespace
}  // namespace hk::app

namespace hk::app {
namespace {

TEST_F(OperatorSessionTest, TheMuseumsFieldsAreLockedKeptAtResetAndNeverWrittenIntoTheStaffsFile) {
  // The staff's file says English and a 300 s timeout; the museum's fleet file says French.
  config::Settings own = in_use_;
  own.kiosk.timeout_s = 300;
  config::save_settings_atomic(own, path_);
  std::ofstream(dir_ / "fleet.toml") << "[kiosk]\nlanguage = \"fr\"\n\n[metrics]\nlisten = \"127.0.0.1:9471\"\n";
  const std::optional<FleetSettings> fleet = load_fleet(fleet_path_for(path_));
  ASSERT_TRUE(fleet);
  const config::Settings merged = with_fleet(config::load_settings(path_), *fleet);
  ASSERT_EQ(merged.kiosk.language, "fr");
  OperatorSession s(path_, merged, "", [](const config::Settings&) { return ApplyReport{}; });
  s.set_fleet(fleet->path, fleet->keys);
  s.chord(0.0, kT0);
  s.submit_pin("2468", 0.1, kT0);
  finish_check(s, 0.2);
  ASSERT_EQ(s.state(), PanelState::open);
  EXPECT_TRUE(s.managed(field("kiosk", "language")));
  EXPECT_FALSE(s.managed(field("kiosk", "timeout_s")));
  // A locked field cannot be changed: refused, its box back to the museum's value.
  s.edit_text(field("kiosk", "language")) = "de";
  const std::string why = s.commit_field(field("kiosk", "language"), kT0);
  EXPECT_NE(why.find("Set by the museum in " + fleet->path), std::string::npos) << why;
  EXPECT_EQ(s.working().kiosk.language, "fr");
  EXPECT_EQ(s.edit_text(field("kiosk", "language")), "fr");
  // Reset keeps the museum's values; a staff field goes back to its default.
  s.reset_to_defaults(kT0);
  EXPECT_EQ(s.working().kiosk.language, "fr");
  EXPECT_EQ(s.working().metrics.listen, "127.0.0.1:9471");
  EXPECT_EQ(s.working().kiosk.timeout_s, 120.0);
  // Save: the staff's file gets the staff's change and keeps its own values of the museum's fields.
  s.edit_text(field("kiosk", "timeout_s")) = "600";
  ASSERT_EQ(s.commit_field(field("kiosk", "timeout_s"), kT0), "");
  s.save(kT0);
  const config::Settings saved = config::load_settings(path_);
  EXPECT_EQ(saved.kiosk.timeout_s, 600.0);
  EXPECT_EQ(saved.kiosk.language, "en");
  EXPECT_EQ(saved.metrics.listen, "");
  EXPECT_EQ(s.working().kiosk.language, "fr");  // still in force
}

}  // namespace
}  // namespace hk::app
