// Field table and validate(): defaults, every documented range, cross-field rules.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <variant>

#include "config/keys.hpp"
#include "config/load.hpp"
#include "config_test_util.hpp"

namespace hk::config {
namespace {

using test::capture_error;
using test::is_one_line;
using test::numeric_specs;

/// Sets the field `table.key` of `s` to `v` (numeric fields only).
void set_numeric(Settings& s, const test::NumericSpec& spec, double v) {
  const FieldDescriptor* d = find_field(spec.table, spec.key);
  ASSERT_NE(d, nullptr) << spec.name();
  std::visit(
      [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_same_v<T, std::string>) {
          FAIL() << spec.name() << " is not numeric";
        } else {
          *p = static_cast<T>(v);
        }
      },
      d->ref(s));
}

TEST(ConfigValidate, DefaultsAreValid) { EXPECT_NO_THROW(validate(Settings{})); }

TEST(ConfigValidate, DescriptorTableMatchesDocumentedRanges) {
  // Every documented numeric field is in the table with its documented range and kind...
  std::set<std::string> seen;
  for (const auto& spec : numeric_specs()) {
    const FieldDescriptor* d = find_field(spec.table, spec.key);
    ASSERT_NE(d, nullptr) << spec.name() << " missing from field_descriptors()";
    EXPECT_EQ(d->min, spec.min) << spec.name();
    EXPECT_EQ(d->max, spec.max) << spec.name();
    EXPECT_EQ(d->kind, spec.integer ? FieldKind::integer : FieldKind::real) << spec.name();
    seen.insert(spec.name());
  }
  // ...and the table holds nothing else but device.type and the [keys] (text fields with choices).
  std::size_t texts = 0;
  for (const auto& d : field_descriptors()) {
    const std::string name = std::string(d.table) + "." + std::string(d.key);
    if (name == "device.type") {
      EXPECT_EQ(d.kind, FieldKind::text);
      ASSERT_EQ(d.choices.size(), 4u);
      EXPECT_EQ(d.choices[0], "auto");
      EXPECT_EQ(d.choices[1], "simulated");
      EXPECT_EQ(d.choices[2], "haply");
      EXPECT_EQ(d.choices[3], "haply-gen2");
      ++texts;
      continue;
    }
    if (name == "haptics.level_mode") {
      EXPECT_EQ(d.kind, FieldKind::text);
      ASSERT_EQ(d.choices.size(), 4u);
      EXPECT_EQ(d.choices[0], "auto");
      EXPECT_EQ(d.choices[1], "tolerance");
      EXPECT_EQ(d.choices[2], "cut");
      EXPECT_EQ(d.choices[3], "fixed");
      ++texts;
      continue;
    }
    if (name == "vision.detector") {
      EXPECT_EQ(d.kind, FieldKind::text);
      ASSERT_EQ(d.choices.size(), 6u);
      EXPECT_EQ(d.choices[0], "auto");
      EXPECT_EQ(d.choices[1], "canny");
      EXPECT_EQ(d.choices[2], "surround");
      EXPECT_EQ(d.choices[3], "bilateral");
      EXPECT_EQ(d.choices[4], "edpf");
      EXPECT_EQ(d.choices[5], "outline");
      ++texts;
      continue;
    }
    if (name == "vision.ocr") {
      EXPECT_EQ(d.kind, FieldKind::text);
      ASSERT_EQ(d.choices.size(), 3u);
      EXPECT_EQ(d.choices[0], "auto");
      EXPECT_EQ(d.choices[1], "always");
      EXPECT_EQ(d.choices[2], "off");
      ++texts;
      continue;
    }
    if (name == "haptics.render") {
      EXPECT_EQ(d.kind, FieldKind::text);
      ASSERT_EQ(d.choices.size(), 2u);
      EXPECT_EQ(d.choices[0], "walls");
      EXPECT_EQ(d.choices[1], "grooves");
      ++texts;
      continue;
    }
    if (d.table == "keys") {
      EXPECT_EQ(d.kind, FieldKind::text) << name;
      EXPECT_GT(d.choices.size(), 50u) << name;
      ++texts;
      continue;
    }
    if (name == "device.transport" || name == "device.actuator1_dir" || name == "device.actuator2_dir" ||
        name == "device.encoder1_dir" || name == "device.encoder2_dir" || name == "kiosk.say_names_on_touch" ||
        name == "audio.voice" || name == "copy.to" || name == "copy.paper") {
      EXPECT_EQ(d.kind, FieldKind::text) << name;
      EXPECT_GE(d.choices.size(), 2u) << name;
      ++texts;
      continue;
    }
    if (name == "operator.open_chord" || name == "device.serial_path" || name == "device.usb_ids" ||
        name == "camera.source" || name == "operator.pin_hash" || name == "operator.state_file" ||
        name == "operator.audit_log" || name == "kiosk.quiet_hours" || name == "kiosk.scene_cache" ||
        name == "kiosk.names_dir" || name == "vision.ocr_languages" || name == "kiosk.languages" ||
        name == "kiosk.language" || name == "operator.language" || name == "copy.printer" ||
        name == "copy.printed_line" || name == "kiosk.library" || name == "metrics.listen") {
      EXPECT_EQ(d.kind, FieldKind::text) << name;
      EXPECT_TRUE(d.choices.empty()) << name;
      EXPECT_NE(d.check, nullptr) << name;  // free text, checked
      ++texts;
      continue;
    }
    EXPECT_TRUE(seen.count(name)) << name << " is in the table but not documented in the test";
    EXPECT_FALSE(d.help.empty()) << name;
  }
  EXPECT_EQ(texts, 53u);
  EXPECT_EQ(field_descriptors().size(), numeric_specs().size() + texts);
}

TEST(ConfigValidate, EveryDefaultIsInsideItsRange) {
  const Settings s{};
  for (const auto& spec : numeric_specs()) {
    const FieldDescriptor* d = find_field(spec.table, spec.key);
    ASSERT_NE(d, nullptr);
    double v = std::visit(
        [](auto* p) -> double {
          if constexpr (std::is_same_v<std::remove_cvref_t<decltype(*p)>, std::string>) {
            return std::numeric_limits<double>::quiet_NaN();
          } else {
            return static_cast<double>(*p);
          }
        },
        d->cref(s));
    EXPECT_GE(v, spec.min) << spec.name();
    EXPECT_LE(v, spec.max) << spec.name();
  }
}

TEST(ConfigValidate, EveryFieldBelowMinOrAboveMaxIsRefusedNamingIt) {
  for (const auto& spec : numeric_specs()) {
    const double below = spec.integer ? spec.min - 1 : std::nextafter(spec.min, -INFINITY);
    const double above = spec.integer ? spec.max + 1 : std::nextafter(spec.max, INFINITY);
    for (double bad : {below, above}) {
      Settings s;
      set_numeric(s, spec, bad);
      auto e = capture_error([&] { validate(s); });
      ASSERT_TRUE(e) << spec.name() << " = " << bad;
      const std::string msg = e->what();
      EXPECT_NE(msg.find(spec.name() + " = "), std::string::npos) << msg;
      EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
      EXPECT_EQ(e->key(), spec.name());
      EXPECT_EQ(msg.rfind("settings: ", 0), 0u) << msg;
      EXPECT_TRUE(is_one_line(msg)) << msg;
    }
  }
}

TEST(ConfigValidate, BoundsThemselvesAreAccepted) {
  for (const auto& spec : numeric_specs()) {
    for (double ok : {spec.min, spec.max}) {
      Settings s;
      s.haptics.max_levels = 12;        // so that haptics.level = 12 passes the cross-field rule
      s.haptics.static_friction = 2.0;  // and any dynamic friction passes dynamic <= static...
      if (spec.name() == "haptics.static_friction") s.haptics.dynamic_friction = 0.0;  // ...and any static
      s.device.link_distal_m = 0.5;      // so that any motor spacing lets the links meet
      s.haptics.pop_force_n = 20.0;      // so that any tour force stays below the push-through force...
      s.haptics.tour_max_force_n = 0.1;  // ...and any push-through force above the tour's
      // Within the simulated pantograph's profile (device_profile.hpp): motors strong enough for the largest
      // forces and a servo rate fast enough for the largest stiffness; the weakest motors and the slowest
      // rate with forces and a stiffness they can hold.
      s.haptics.max_force_n = 20.0;
      s.device.max_torque_n_m = 10.0;
      s.haptics.servo_rate_hz = 2000.0;
      const bool weak =
          (spec.name() == "haptics.max_force_n" || spec.name() == "device.max_torque_n_m") && ok == spec.min;
      if (weak) {
        s.haptics.max_force_n = 0.1;
        s.haptics.pop_force_n = 0.0;
        s.haptics.groove_depth_n = 0.05;
      }
      if (spec.name() == "haptics.servo_rate_hz" && ok == spec.min) s.haptics.stiffness_n_per_m = 100.0;
      set_numeric(s, spec, ok);
      // The other actuator/encoder moves off a port this bound takes (each needs its own board port).
      if (spec.name() == "device.actuator1_port" && ok == s.device.actuator2_port) s.device.actuator2_port = 3;
      if (spec.name() == "device.actuator2_port" && ok == s.device.actuator1_port) s.device.actuator1_port = 3;
      if (spec.name() == "device.encoder1_port" && ok == s.device.encoder2_port) s.device.encoder2_port = 3;
      if (spec.name() == "device.encoder2_port" && ok == s.device.encoder1_port) s.device.encoder1_port = 3;
      EXPECT_NO_THROW(validate(s)) << spec.name() << " = " << ok;
    }
  }
}

TEST(ConfigValidate, NonFiniteRealsAreRefused) {
  for (const auto& spec : numeric_specs()) {
    if (spec.integer) continue;
    for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                       -std::numeric_limits<double>::infinity()}) {
      Settings s;
      set_numeric(s, spec, bad);
      auto e = capture_error([&] { validate(s); });
      ASSERT_TRUE(e) << spec.name();
      EXPECT_EQ(e->key(), spec.name());
      EXPECT_NE(std::string(e->what()).find("not a finite number"), std::string::npos) << e->what();
    }
  }
}

TEST(ConfigValidate, LevelMustNotExceedMaxLevels) {
  Settings s;
  s.haptics.max_levels = 4;
  s.haptics.level = 4;
  EXPECT_NO_THROW(validate(s));
  s.haptics.level = 5;
  auto e = capture_error([&] { validate(s); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "haptics.level");
  EXPECT_NE(std::string(e->what()).find("haptics.max_levels = 4"), std::string::npos) << e->what();
}

TEST(ConfigValidate, CannyLowMustNotExceedHighWhenBothSet) {
  Settings s;
  s.vision.canny_low = 300;
  s.vision.canny_high = 0;  // high from the image: any low is fine
  EXPECT_NO_THROW(validate(s));
  s.vision.canny_high = 300;
  EXPECT_NO_THROW(validate(s));
  s.vision.canny_high = 200;
  auto e = capture_error([&] { validate(s); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "vision.canny_low");
  EXPECT_EQ(std::string(e->what()),
            "settings: vision.canny_low = 300 must be <= vision.canny_high = 200 when both are nonzero");
}

TEST(ConfigValidate, DynamicFrictionMustNotExceedStatic) {
  Settings s;
  s.haptics.static_friction = 0.0;
  s.haptics.dynamic_friction = 0.0;  // frictionless walls
  EXPECT_NO_THROW(validate(s));
  s.haptics.static_friction = 0.5;
  s.haptics.dynamic_friction = 0.5;
  EXPECT_NO_THROW(validate(s));
  s.haptics.dynamic_friction = 0.6;
  auto e = capture_error([&] { validate(s); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "haptics.dynamic_friction");
  EXPECT_NE(std::string(e->what()).find("must be <= haptics.static_friction = 0.5"), std::string::npos) << e->what();
}

TEST(ConfigValidate, TheTourMustPullLessThanAPushThrough) {
  Settings s;
  s.haptics.pop_force_n = 2.0;
  s.haptics.tour_max_force_n = 1.9;
  EXPECT_NO_THROW(validate(s));
  s.haptics.tour_max_force_n = 2.0;  // the tour could push the hand through a wall
  auto e = capture_error([&] { validate(s); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "haptics.tour_max_force_n");
  EXPECT_EQ(std::string(e->what()),
            "settings: haptics.tour_max_force_n = 2 must be < haptics.pop_force_n = 2 (the guided tour must not push "
            "the hand through a wall)");
  s.haptics.pop_force_n = 0.0;  // walls never give way: any tour force is fine
  EXPECT_NO_THROW(validate(s));
}

TEST(ConfigValidate, UnknownRenderModeIsRefused) {
  Settings s;
  s.haptics.render = "ridges";
  auto e = capture_error([&] { validate(s); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "haptics.render");
  EXPECT_NE(std::string(e->what()).find("grooves"), std::string::npos) << e->what();
}

TEST(ConfigValidate, UnknownDetectorIsRefused) {
  Settings s;
  s.vision.detector = "sobel";
  auto e = capture_error([&] { validate(s); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "vision.detector");
  EXPECT_NE(std::string(e->what()).find("outline"), std::string::npos) << e->what();
}

TEST(ConfigValidate, CameraSourceIsAutoNoneOrASourceSpec) {
  Settings s;
  for (const char* good : {"auto", "none", "file:/srv/frames", "libcamera:0", "v4l2:/dev/video0"}) {
    s.camera.source = good;
    EXPECT_NO_THROW(validate(s)) << good;
  }
  for (const char* bad : {"usb:1", "", "file:", "libcamera:", "webcam"}) {
    s.camera.source = bad;
    auto e = capture_error([&] { validate(s); });
    ASSERT_TRUE(e) << bad;
    EXPECT_EQ(e->key(), "camera.source");
    EXPECT_TRUE(is_one_line(e->what())) << e->what();
  }
  s.camera.source = std::string("file:/tmp/a\nb");
  auto e = capture_error([&] { validate(s); });
  ASSERT_TRUE(e);
  EXPECT_NE(std::string(e->what()).find("control character"), std::string::npos) << e->what();
}

TEST(ConfigValidate, MetricsListenIsEmptyOrANumericAddressAndAPort) {
  Settings s;
  for (const char* good : {"", "127.0.0.1:9471", "0.0.0.0:1", "192.168.4.20:65535", "[::1]:9471", "[::]:80"}) {
    s.metrics.listen = good;
    EXPECT_NO_THROW(validate(s)) << good;
  }
  for (const char* bad : {"9471", ":9471", "127.0.0.1", "127.0.0.1:0", "127.0.0.1:65536", "127.0.0.1:94x1",
                          "localhost:9471", "::1:9471", "[::1]", "[fe80::zz]:9471", "300.1.1.1:9471"}) {
    s.metrics.listen = bad;
    auto e = capture_error([&] { validate(s); });
    ASSERT_TRUE(e) << bad;
    EXPECT_EQ(e->key(), "metrics.listen") << bad;
    EXPECT_TRUE(is_one_line(e->what())) << e->what();
  }
}

TEST(ConfigValidate, LibraryIsAutoOrAnAbsoluteFolder) {
  Settings s;
  for (const char* good : {"auto", "/var/lib/haptic-kiosk/library", "/srv/gallery 2"}) {
    s.kiosk.library = good;
    EXPECT_NO_THROW(validate(s)) << good;
  }
  for (const char* bad : {"", "off", "pictures", "./library"}) {
    s.kiosk.library = bad;
    auto e = capture_error([&] { validate(s); });
    ASSERT_TRUE(e) << bad;
    EXPECT_EQ(e->key(), "kiosk.library") << bad;
  }
}

TEST(ConfigValidate, UnknownLevelModeIsRefused) {
  Settings s;
  s.haptics.level_mode = "adaptive";
  auto e = capture_error([&] { validate(s); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "haptics.level_mode");
}

TEST(ConfigValidate, UnknownDeviceTypeIsRefused) {
  Settings s;
  s.device.type = "mouse";
  auto e = capture_error([&] { validate(s); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "device.type");
  EXPECT_EQ(std::string(e->what()),
            "settings: device.type = \"mouse\" is not a known value; allowed: one of \"auto\", \"simulated\", "
            "\"haply\", \"haply-gen2\"");
}

TEST(ConfigValidate, ControlCharactersInValuesDoNotBreakTheLine) {
  Settings s;
  s.device.type = "sim\nulated\r\x01";
  auto e = capture_error([&] { validate(s); });
  ASSERT_TRUE(e);
  EXPECT_TRUE(is_one_line(e->what())) << e->what();
  EXPECT_NE(std::string(e->what()).find("sim\\x0Aulated\\x0D\\x01"), std::string::npos) << e->what();
}

// [operator] open_chord: what parse_chord reads, and what it refuses with a phrase saying why.
TEST(OperatorChord, ParsesModifiersInAnyOrderAndRefusesWhatAVisitorCouldPressAlone) {
  std::string why;
  const auto c = parse_chord("ALT+CTRL+O", &why);
  ASSERT_TRUE(c) << why;
  EXPECT_TRUE(c->ctrl && c->alt && !c->shift && !c->super);
  EXPECT_EQ(c->key, "O");
  EXPECT_EQ(chord_text(*c), "CTRL+ALT+O");
  EXPECT_EQ(parse_chord(chord_text(*c)), c);
  EXPECT_TRUE(parse_chord("SUPER+F12"));
  for (const char* bad :
       {"", "O", "SHIFT+O", "CTRL+", "+O", "CTRL+CTRL+O", "CTRL+ALT+Ö", "ctrl+alt+o", "CTRL+META+O"}) {
    why.clear();
    EXPECT_FALSE(parse_chord(bad, &why)) << bad;
    EXPECT_FALSE(why.empty()) << bad;
  }
  EXPECT_FALSE(parse_chord("SHIFT+O", &why));
  EXPECT_NE(why.find("CTRL, ALT or SUPER"), std::string::npos) << why;
  // The loader gives the same phrase, naming the key.
  try {
    (void)parse_settings("[operator]\nopen_chord = \"O\"\n", "k.toml");
    FAIL() << "a chord of one key was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "operator.open_chord");
    EXPECT_NE(std::string(e.what()).find("needs CTRL, ALT or SUPER"), std::string::npos) << e.what();
  }
}

// [operator] pin_hash is empty or an argon2id hash: anything else typed by hand is refused at load.
TEST(OperatorPinHash, OnlyAnArgon2idHashOrNothingIsAccepted) {
  EXPECT_NO_THROW((void)parse_settings("[operator]\npin_hash = \"\"\n", "k.toml"));
  EXPECT_NO_THROW((void)parse_settings(
      "[operator]\npin_hash = \"$argon2id$v=19$m=65536,t=2,p=1$c29tZXNhbHQ$aGFzaGhhc2hoYXNoaGFzaA\"\n", "k.toml"));
  for (const char* bad : {"1234", "$argon2i$v=19$m=4096,t=3,p=1$abc$def", "$argon2id$ with space"}) {
    try {
      (void)parse_settings(std::string("[operator]\npin_hash = \"") + bad + "\"\n", "k.toml");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), "operator.pin_hash");
      EXPECT_NE(std::string(e.what()).find("pin set"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace hk::config

namespace hk::config {
namespace {

// [kiosk] quiet_hours: two times "HH:MM-HH:MM", possibly across midnight; anything else is refused in one
// line naming the key.
TEST(QuietHours, ReadsTwoTimesAndKnowsWhetherAMinuteIsInThem) {
  const auto night = parse_quiet_hours("22:00-07:00");
  ASSERT_TRUE(night);
  EXPECT_EQ(night->first, 22 * 60);
  EXPECT_EQ(night->second, 7 * 60);
  EXPECT_TRUE(in_quiet_hours(*night, 23 * 60 + 59));
  EXPECT_TRUE(in_quiet_hours(*night, 0));
  EXPECT_TRUE(in_quiet_hours(*night, 6 * 60 + 59));
  EXPECT_FALSE(in_quiet_hours(*night, 7 * 60));
  EXPECT_FALSE(in_quiet_hours(*night, 12 * 60));
  const auto lunch = parse_quiet_hours("12:00-13:30");
  ASSERT_TRUE(lunch);
  EXPECT_TRUE(in_quiet_hours(*lunch, 13 * 60 + 29));
  EXPECT_FALSE(in_quiet_hours(*lunch, 13 * 60 + 30));
  EXPECT_FALSE(in_quiet_hours(*lunch, 11 * 60 + 59));
  EXPECT_FALSE(parse_quiet_hours(""));  // none
  std::string why;
  for (const char* bad :
       {"24:00-07:00", "7:00-8:00", "22:00-22:00", "22:00 07:00", "22:60-07:00", "22:00-07:00x", "ab:cd-ef:gh"}) {
    why.clear();
    EXPECT_FALSE(parse_quiet_hours(bad, &why)) << bad;
    EXPECT_FALSE(why.empty()) << bad;
  }
  EXPECT_NO_THROW((void)parse_settings("[kiosk]\nquiet_hours = \"\"\n", "k.toml"));
  EXPECT_NO_THROW((void)parse_settings("[kiosk]\nquiet_hours = \"21:30-06:45\"\n", "k.toml"));
  try {
    (void)parse_settings("[kiosk]\nquiet_hours = \"25:00-07:00\"\n", "k.toml");
    FAIL() << "a time past 23:59 was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "kiosk.quiet_hours");
    EXPECT_NE(std::string(e.what()).find("00:00 to 23:59"), std::string::npos) << e.what();
  }
}

// [kiosk] scene_cache: "auto", "off" or an absolute folder; a relative one (which would land wherever the
// service happens to start) is refused naming the key.
TEST(SceneCacheSetting, TakesAutoOffOrAnAbsoluteFolderOnly) {
  for (const std::string key : {"scene_cache", "names_dir"}) {
    for (const char* good : {"auto", "off", "/var/cache/haptic-kiosk/scenes"})
      EXPECT_NO_THROW((void)parse_settings("[kiosk]\n" + key + " = \"" + good + "\"\n", "k.toml")) << good;
    for (const char* bad : {"", "scenes", "./cache", "Off"}) {
      try {
        (void)parse_settings("[kiosk]\n" + key + " = \"" + bad + "\"\n", "k.toml");
        ADD_FAILURE() << key << " '" << bad << "' was accepted";
      } catch (const ConfigError& e) {
        EXPECT_EQ(e.key(), "kiosk." + key) << bad;
        EXPECT_NE(std::string(e.what()).find("absolute folder"), std::string::npos) << e.what();
      }
    }
  }
}

}  // namespace
}  // namespace hk::config

namespace hk::config {
namespace {

TEST(ConfigFields, EachFieldHasAShortNameInStaffWords) {
  EXPECT_EQ(field_label(*find_field("haptics", "stiffness_n_per_m")), "Wall stiffness");
  EXPECT_EQ(field_label(*find_field("audio", "speech_rate_wpm")), "Speaking rate");
  EXPECT_EQ(field_label(*find_field("kiosk", "languages")), "The languages offered to visitors");
  for (const FieldDescriptor& d : field_descriptors()) {
    const std::string label = field_label(d);
    EXPECT_FALSE(label.empty()) << d.table << "." << d.key;
    EXPECT_LE(label.size(), kMaxFieldLabelBytes + 4) << label;
    EXPECT_EQ(label.find('_'), std::string::npos) << d.table << "." << d.key << ": a key, not words: " << label;
  }
}

}  // namespace
}  // namespace hk::config
