// load_settings / parse_settings: overriding defaults, and refusing bad input with one clear line.

#include <gtest/gtest.h>

#include <cmath>
#include <ostream>
#include <string>

#include "config/load.hpp"
#include "config_test_util.hpp"

namespace hk::config {
namespace {

using test::capture_error;
using test::data_dir;
using test::is_one_line;
using test::numeric_specs;

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// ---------------------------------------------------------------------------------------------
// Good input

TEST(ConfigLoad, EmptyTextGivesDefaults) { EXPECT_EQ(parse_settings("", "empty"), Settings{}); }

TEST(ConfigLoad, PresentKeysOverrideAndOthersKeepDefaults) {
  const Settings s =
      parse_settings("[haptics]\nstiffness_n_per_m = 1200.5\nlevel = 3\n[vision]\nmax_file_bytes = 2048\n", "t");
  Settings expected;
  expected.haptics.stiffness_n_per_m = 1200.5;
  expected.haptics.level = 3;
  expected.vision.max_file_bytes = 2048;
  EXPECT_EQ(s, expected);
}

TEST(ConfigLoad, IntegerIsAcceptedForAReal) {
  const Settings s = parse_settings("[haptics]\nstiffness_n_per_m = 900\n", "t");
  EXPECT_EQ(s.haptics.stiffness_n_per_m, 900.0);
}

TEST(ConfigLoad, InlineTablesAndDottedKeysWork) {
  const Settings s = parse_settings("workspace = { width_m = 0.2 }\nhand.max_force_n = 3\n", "t");
  EXPECT_EQ(s.workspace.width_m, 0.2);
  EXPECT_EQ(s.hand.max_force_n, 3.0);
}

TEST(ConfigLoad, ShippedDefaultFileLoadsEqualToDefaults) {
  EXPECT_EQ(load_settings((data_dir() / "config" / "default.toml").string()), Settings{});
}

TEST(ConfigLoad, ShippedDefaultFileIsUpToDate) {
  // The shipped file is to_toml(Settings{}) byte for byte, so its comments (ranges, units,
  // defaults) can't drift from the code. To regenerate after a deliberate change, run
  //   HK_UPDATE_DEFAULT_TOML=1 test_config --gtest_filter=ConfigLoad.ShippedDefaultFileIsUpToDate
  const auto path = data_dir() / "config" / "default.toml";
  const std::string expected = to_toml(Settings{});
  if (std::getenv("HK_UPDATE_DEFAULT_TOML")) test::write_file(path, expected);
  EXPECT_EQ(test::read_file(path), expected)
      << path << " is stale; regenerate it with HK_UPDATE_DEFAULT_TOML=1 (see this test)";
}

// ---------------------------------------------------------------------------------------------
// The committed bad files: one line, naming the file and the key.

struct BadFile {
  const char* file;
  const char* key;           // expected ConfigError::key(); "" when not about one key
  const char* must_contain;  // another part the message must contain
};

void PrintTo(const BadFile& b, std::ostream* os) { *os << b.file; }

class ConfigBadFile : public ::testing::TestWithParam<BadFile> {};

TEST_P(ConfigBadFile, IsRefusedWithOneLineNamingFileAndKey) {
  const BadFile& bad = GetParam();
  const std::string path = (data_dir() / "bad" / bad.file).string();
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  auto e = capture_error([&] { (void)load_settings(path); });
  ASSERT_TRUE(e);
  const std::string msg = e->what();
  EXPECT_TRUE(is_one_line(msg)) << msg;
  EXPECT_EQ(msg.rfind("config '" + path + "': ", 0), 0u) << msg;
  EXPECT_TRUE(contains(msg, bad.file)) << msg;
  EXPECT_EQ(e->source(), path);
  EXPECT_EQ(e->key(), bad.key) << msg;
  if (*bad.key) {
    EXPECT_TRUE(contains(msg, bad.key)) << msg;
  }
  EXPECT_TRUE(contains(msg, bad.must_contain)) << msg;
}

INSTANTIATE_TEST_SUITE_P(
    Committed, ConfigBadFile,
    ::testing::Values(BadFile{"config_syntax.toml", "", "TOML syntax error at line 5"},
                      BadFile{
                          "config_unknown_key.toml", "haptics.stifness_n_per_m",
                          "unknown key haptics.stifness_n_per_m (did you mean haptics.stiffness_n_per_m?) (line 3)"},
                      BadFile{"config_wrong_type.toml", "haptics.stiffness_n_per_m",
                              "haptics.stiffness_n_per_m = \"stiff\" has the wrong type (string); expected a number in "
                              "[10, 5000] N/m (line 3)"},
                      BadFile{"config_out_of_range.toml", "haptics.stiffness_n_per_m",
                              "haptics.stiffness_n_per_m = -5 is out of range [10, 5000] N/m (line 3)"},
                      BadFile{"config_nan.toml", "haptics.max_force_n",
                              "haptics.max_force_n = nan is not a finite number; allowed range [0.1, 20] N"}),
    [](const auto& info) {
      std::string n = info.param.file;
      return n.substr(0, n.find('.'));
    });

TEST(ConfigLoad, OutOfRangeMessageIsExactlyAsDocumented) {
  const std::string path = (data_dir() / "bad" / "config_out_of_range.toml").string();
  auto e = capture_error([&] { (void)load_settings(path); });
  ASSERT_TRUE(e);
  EXPECT_EQ(std::string(e->what()),
            "config '" + path + "': haptics.stiffness_n_per_m = -5 is out of range [10, 5000] N/m (line 3)");
}

// ---------------------------------------------------------------------------------------------
// Files that can't be read

TEST(ConfigLoad, MissingFileIsRefusedNamingIt) {
  const std::string path = (data_dir() / "config" / "no_such_settings.toml").string();
  auto e = capture_error([&] { (void)load_settings(path); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(is_one_line(e->what()));
  EXPECT_TRUE(contains(e->what(), path)) << e->what();
  EXPECT_TRUE(contains(e->what(), "No such file")) << e->what();
  EXPECT_EQ(e->key(), "");
}

TEST(ConfigLoad, DirectoryIsRefused) {
  auto e = capture_error([&] { (void)load_settings(data_dir().string()); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(contains(e->what(), "is a directory")) << e->what();
}

TEST(ConfigLoad, OversizedFileIsRefusedNamingTheLimit) {
  test::TempDir dir;
  const auto path = dir.path() / "huge.toml";
  test::write_file(path, std::string(kMaxConfigFileBytes + 1, '#'));
  auto e = capture_error([&] { (void)load_settings(path.string()); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(contains(e->what(), std::to_string(kMaxConfigFileBytes) + " bytes")) << e->what();
  EXPECT_TRUE(is_one_line(e->what()));
}

TEST(ConfigLoad, InvalidUtf8IsASyntaxError) {
  auto e = capture_error([&] { (void)parse_settings("[haptics]\n# \xff\xfe\n", "bin"); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(contains(e->what(), "TOML syntax error at line 2")) << e->what();
  EXPECT_TRUE(is_one_line(e->what()));
}

TEST(ConfigLoad, DuplicateKeyIsASyntaxError) {
  auto e = capture_error([&] { (void)parse_settings("[haptics]\nlevel = 1\nlevel = 2\n", "dup.toml"); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(contains(e->what(), "config 'dup.toml': TOML syntax error at line 3")) << e->what();
}

// ---------------------------------------------------------------------------------------------
// Unknown names

TEST(ConfigLoad, UnknownTableIsNamedWithSuggestion) {
  auto e = capture_error([&] { (void)parse_settings("[haptic]\nlevel = 1\n", "t.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(std::string(e->what()), "config 't.toml': unknown table [haptic] (did you mean [haptics]?) (line 1)");
  EXPECT_EQ(e->key(), "[haptic]");
}

TEST(ConfigLoad, UnknownTableWithoutCloseMatch) {
  auto e = capture_error([&] { (void)parse_settings("[printer]\nx = 1\n", "t.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(std::string(e->what()), "config 't.toml': unknown table [printer] (line 1)");
}

TEST(ConfigLoad, KeyInTheWrongTableSaysWhereItBelongs) {
  auto e = capture_error([&] { (void)parse_settings("[haptics]\ncanny_low = 10\n", "t.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "haptics.canny_low");
  EXPECT_TRUE(contains(e->what(), "did you mean vision.canny_low?")) << e->what();
}

TEST(ConfigLoad, KeyOutsideAnyTableIsRefused) {
  auto e = capture_error([&] { (void)parse_settings("max_pixels = 10\n", "t.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "max_pixels");
  EXPECT_TRUE(contains(e->what(), "outside any table")) << e->what();
  EXPECT_TRUE(contains(e->what(), "vision.max_pixels")) << e->what();
}

TEST(ConfigLoad, NestedTableInsideAKnownTableIsAnUnknownKey) {
  auto e = capture_error([&] { (void)parse_settings("[haptics.extra]\nx = 1\n", "t.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "haptics.extra");
}

TEST(ConfigLoad, TableGivenAsAValueIsAWrongType) {
  auto e = capture_error([&] { (void)parse_settings("haptics = 5\n", "t.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "[haptics]");
  EXPECT_TRUE(contains(e->what(), "wrong type (integer); expected a table")) << e->what();
}

TEST(ConfigLoad, WeirdQuotedKeyStaysOneLine) {
  auto e = capture_error([&] { (void)parse_settings("[haptics]\n\"a\\nb\" = 1\n", "t.toml"); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(is_one_line(e->what())) << e->what();
  EXPECT_TRUE(contains(e->what(), "haptics.a\\x0Ab")) << e->what();
}

// ---------------------------------------------------------------------------------------------
// Every key, through TOML text: out of range, wrong type, non-finite.

std::string doc(const test::NumericSpec& spec, const std::string& value) {
  return std::string("[") + spec.table + "]\n" + spec.key + " = " + value + "\n";
}

std::string number_text(const test::NumericSpec& spec, double v) {
  return spec.integer ? std::to_string(static_cast<long long>(v)) : test::toml_float(v);
}

/// How a value is shown in a message: shortest round-trip text, no ".0".
std::string shown(const test::NumericSpec& spec, double v) {
  std::string t = number_text(spec, v);
  if (t.size() > 2 && t.ends_with(".0")) t.resize(t.size() - 2);
  return t;
}

TEST(ConfigLoad, EveryKeyBelowMinOrAboveMaxIsRefusedNamingIt) {
  for (const auto& spec : numeric_specs()) {
    const double below = spec.integer ? spec.min - 1 : std::nextafter(spec.min, -INFINITY);
    const double above = spec.integer ? spec.max + 1 : std::nextafter(spec.max, INFINITY);
    for (double bad : {below, above}) {
      const std::string text = doc(spec, number_text(spec, bad));
      auto e = capture_error([&] { (void)parse_settings(text, "range.toml"); });
      ASSERT_TRUE(e) << text;
      const std::string msg = e->what();
      EXPECT_EQ(e->key(), spec.name()) << msg;
      EXPECT_TRUE(
          contains(msg, "config 'range.toml': " + spec.name() + " = " + shown(spec, bad) + " is out of range ["))
          << msg;
      EXPECT_TRUE(contains(msg, "(line 2)")) << msg;
      EXPECT_TRUE(is_one_line(msg)) << msg;
    }
  }
}

TEST(ConfigLoad, EveryKeyAtItsBoundsIsAccepted) {
  for (const auto& spec : numeric_specs()) {
    for (double ok : {spec.min, spec.max}) {
      std::string text = doc(spec, number_text(spec, ok));
      if (spec.name() == "haptics.level") text += "max_levels = 12\n";
      if (spec.name() == "haptics.dynamic_friction") text += "static_friction = 2.0\n";
      if (spec.name() == "haptics.static_friction") text += "dynamic_friction = 0.0\n";
      // The device profile bounds these (device_profile.hpp): the simulated pantograph's motors made strong
      // enough for the largest forces, its servo rate fast enough for the largest stiffness.
      const std::string strong = "max_force_n = 20.0\n[device]\nmax_torque_n_m = 10.0\n";
      const std::string weak = "pop_force_n = 0.0\ntour_max_force_n = 0.1\ngroove_depth_n = 0.05\nmax_force_n = 0.1\n";
      if (spec.name() == "haptics.tour_max_force_n")
        text += "pop_force_n = 20.0\n";  // the tour stays below the push-through force
      if (spec.name() == "haptics.pop_force_n") text += "tour_max_force_n = 0.1\n";
      if (spec.name() == "haptics.tour_max_force_n" ||
          (ok == spec.max && (spec.name() == "haptics.pop_force_n" || spec.name() == "haptics.groove_depth_n")))
        text += strong;
      if (ok == spec.max && spec.name() == "haptics.max_force_n") text += "[device]\nmax_torque_n_m = 10.0\n";
      if (ok == spec.min && spec.name() == "haptics.max_force_n")
        text += "pop_force_n = 0.0\ntour_max_force_n = 0.1\ngroove_depth_n = 0.05\n";
      if (ok == spec.min && spec.name() == "device.max_torque_n_m") text += "[haptics]\n" + weak;
      if (ok == spec.max && spec.name() == "haptics.stiffness_n_per_m") text += "servo_rate_hz = 2000\n";
      if (ok == spec.min && spec.name() == "haptics.servo_rate_hz") text += "stiffness_n_per_m = 100.0\n";
      // The other actuator/encoder moves off a port this bound takes (each needs its own board port).
      if (spec.name() == "device.actuator1_port") text += ok == 1 ? "actuator2_port = 2\n" : "actuator2_port = 1\n";
      if (spec.name() == "device.actuator2_port") text += ok == 2 ? "actuator1_port = 1\n" : "actuator1_port = 2\n";
      if (spec.name() == "device.encoder1_port") text += ok == 1 ? "encoder2_port = 2\n" : "encoder2_port = 1\n";
      if (spec.name() == "device.encoder2_port") text += ok == 2 ? "encoder1_port = 1\n" : "encoder1_port = 2\n";
      if (spec.name() == "device.motor_spacing_m") text += "link_distal_m = 0.5\n";
      EXPECT_NO_THROW((void)parse_settings(text, "bounds.toml")) << text;
    }
  }
}

TEST(ConfigLoad, EveryNumericKeyRefusesAStringABoolAnArrayAndATable) {
  for (const auto& spec : numeric_specs()) {
    for (const char* bad : {"\"12\"", "true", "[1, 2]", "{ a = 1 }"}) {
      const std::string text = doc(spec, bad);
      auto e = capture_error([&] { (void)parse_settings(text, "type.toml"); });
      ASSERT_TRUE(e) << text;
      EXPECT_EQ(e->key(), spec.name()) << e->what();
      EXPECT_TRUE(contains(e->what(), "has the wrong type")) << e->what();
      EXPECT_TRUE(contains(e->what(), spec.integer ? "expected an integer in [" : "expected a number in ["))
          << e->what();
    }
  }
}

TEST(ConfigLoad, IntegerKeysRefuseFloatsEvenWhole) {
  for (const auto& spec : numeric_specs()) {
    if (!spec.integer) continue;
    const std::string text = doc(spec, test::toml_float(spec.min));
    auto e = capture_error([&] { (void)parse_settings(text, "t.toml"); });
    ASSERT_TRUE(e) << text;
    EXPECT_EQ(e->key(), spec.name());
    EXPECT_TRUE(contains(e->what(), "wrong type (float)")) << e->what();
  }
}

TEST(ConfigLoad, HugeIntegersAreOutOfRangeNotWrapped) {
  // 2^32 + 5 would wrap to 5 in an int; it must be refused, not read as 5.
  auto e = capture_error([&] { (void)parse_settings("[haptics]\nlevel = 4294967301\n", "t.toml"); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(contains(e->what(), "haptics.level = 4294967301 is out of range [0, 12]")) << e->what();
}

TEST(ConfigLoad, EveryRealKeyRefusesNanAndInfinities) {
  for (const auto& spec : numeric_specs()) {
    if (spec.integer) continue;
    for (const char* bad : {"nan", "+nan", "-nan", "inf", "+inf", "-inf"}) {
      const std::string text = doc(spec, bad);
      auto e = capture_error([&] { (void)parse_settings(text, "nf.toml"); });
      ASSERT_TRUE(e) << text;
      EXPECT_EQ(e->key(), spec.name());
      EXPECT_TRUE(contains(e->what(), "is not a finite number")) << e->what();
    }
  }
}

TEST(ConfigLoad, DeviceTypeMustBeAKnownStringValue) {
  EXPECT_EQ(parse_settings("[device]\ntype = \"simulated\"\n", "t").device.type, "simulated");
  auto e = capture_error([&] { (void)parse_settings("[device]\ntype = \"usb\"\n", "t.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(std::string(e->what()),
            "config 't.toml': device.type = \"usb\" is not a known value; allowed: one of \"auto\", \"simulated\", "
            "\"haply\", \"haply-gen2\" (line 2)");
  e = capture_error([&] { (void)parse_settings("[device]\ntype = 3\n", "t.toml"); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(contains(e->what(), "device.type = 3 has the wrong type (integer)")) << e->what();
}

TEST(ConfigLoad, CrossFieldRulesApplyToFiles) {
  auto e = capture_error([&] { (void)parse_settings("[vision]\ncanny_low = 100\ncanny_high = 50\n", "x.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "vision.canny_low");
  EXPECT_EQ(std::string(e->what()).rfind("config 'x.toml': ", 0), 0u) << e->what();
  e = capture_error([&] { (void)parse_settings("[haptics]\nlevel = 7\n", "x.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "haptics.level");
}

}  // namespace
}  // namespace hk::config
