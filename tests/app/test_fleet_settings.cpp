// The museum's fleet file over the staff's settings: what it sets, what it may not, and a bad one refused whole.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "config/load.hpp"
#include "temp_dir.hpp"
#include "visit/fleet_settings.hpp"

namespace {

using hk::app::FleetSettings;
using hk::app::load_fleet;
using hk::app::with_fleet;
namespace fs = std::filesystem;

std::string write(const hk::test::TempDir& dir, const std::string& text) {
  const std::string p = dir.path() + "/fleet.toml";
  std::ofstream(p) << text;
  return p;
}

/// The one-line message of the ConfigError `f` throws ("" when it throws none).
template <typename F>
std::string refusal(F f) {
  try {
    f();
  } catch (const hk::config::ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    return e.what();
  }
  return {};
}

TEST(FleetSettings, TheFileBesideTheSettingsSetsItsKeysOverTheStaffsAndNothingElse) {
  hk::test::TempDir dir("hk_fleet");
  EXPECT_EQ(hk::app::fleet_path_for(dir.path() + "/settings.toml"), dir.path() + "/fleet.toml");
  EXPECT_EQ(hk::app::fleet_path_for(""), "");
  EXPECT_FALSE(load_fleet(dir.path() + "/fleet.toml").has_value());  // none: nothing is the museum's
  write(dir, "[kiosk]\nlanguage = \"de\"\n\n[copy]\nto = \"printer\"\nprinter = \"front-desk\"\n");
  const std::optional<FleetSettings> f = load_fleet(dir.path() + "/fleet.toml");
  ASSERT_TRUE(f);
  EXPECT_EQ(f->keys, (std::vector<std::string>{"kiosk.language", "copy.to", "copy.printer"}));
  hk::config::Settings own;
  own.kiosk.timeout_s = 300;
  own.kiosk.language = "fr";
  const hk::config::Settings s = with_fleet(own, *f);
  EXPECT_EQ(s.kiosk.language, "de");
  EXPECT_EQ(s.copy.to, "printer");
  EXPECT_EQ(s.copy.printer, "front-desk");
  EXPECT_EQ(s.kiosk.timeout_s, 300.0);  // the staff's
  // keep_own: what settings.toml keeps for the museum's fields.
  const hk::config::Settings kept = hk::app::keep_own(s, own, f->keys);
  EXPECT_EQ(kept.kiosk.language, "fr");
  EXPECT_EQ(kept.copy.to, "off");
  EXPECT_EQ(kept.kiosk.timeout_s, 300.0);
}

TEST(FleetSettings, ABadFleetFileIsRefusedInOneLineNamingIt) {
  hk::test::TempDir dir("hk_fleet");
  const std::string p = write(dir, "[kiosk]\nlanguag = \"de\"\n");
  std::string why = refusal([&] { (void)load_fleet(p); });
  EXPECT_NE(why.find(p), std::string::npos) << why;
  EXPECT_NE(why.find("language"), std::string::npos) << why;  // the likely key suggested
  write(dir, "[haptics]\nstiffness_n_per_m = 90000\n");
  why = refusal([&] { (void)load_fleet(p); });
  EXPECT_NE(why.find("out of range"), std::string::npos) << why;
  write(dir, "[kiosk\n");
  EXPECT_NE(refusal([&] { (void)load_fleet(p); }).find("TOML syntax error"), std::string::npos);
  // The PIN is not the fleet file's.
  write(dir, "[operator]\npin_hash = \"$argon2id$v=19$m=65536,t=2,p=1$c2FsdHNhbHQ$aGFzaGhhc2hoYXNo\"\n");
  why = refusal([&] { (void)load_fleet(p); });
  EXPECT_NE(why.find("pin set-hash"), std::string::npos) << why;
}

TEST(FleetSettings, AFleetValueThatBreaksARuleWithTheStaffsFileIsRefused) {
  hk::test::TempDir dir("hk_fleet");
  // The museum's dynamic friction holds over the defaults, but not over this kiosk's lower static friction.
  const std::string p = write(dir, "[haptics]\ndynamic_friction = 0.35\n");
  const std::optional<FleetSettings> f = load_fleet(p);
  ASSERT_TRUE(f);
  hk::config::Settings own;
  own.haptics.static_friction = 0.32;
  own.haptics.dynamic_friction = 0.3;
  const std::string why = refusal([&] { (void)with_fleet(own, *f); });
  EXPECT_NE(why.find(p + ": with settings.toml it does not hold"), std::string::npos) << why;
  EXPECT_NE(why.find("dynamic_friction"), std::string::npos) << why;
}

}  // namespace
