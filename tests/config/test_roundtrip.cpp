// to_toml -> parse_settings gives back exactly the same Settings, and the text is operator-readable.

#include <algorithm>
#include <gtest/gtest.h>

#include <random>
#include <sstream>
#include <string>

#include "config/load.hpp"
#include "config_test_util.hpp"

namespace hk::config {
namespace {

using test::numeric_specs;

TEST(ConfigRoundTrip, Defaults) {
  const Settings s{};
  EXPECT_EQ(parse_settings(to_toml(s), "defaults"), s) << to_toml(s);
}

/// Every field set by hand (not through the implementation's table) to a non-default valid value,
/// so a field missing from the table would come back as its default and fail the comparison.
Settings every_field_changed() {
  Settings s;
  s.haptics.stiffness_n_per_m = 1234.5;
  s.haptics.damping_n_s_per_m = 1.25;
  s.haptics.max_force_n = 7.5;
  s.haptics.servo_rate_hz = 2000;
  s.haptics.level = 3;
  s.haptics.max_levels = 9;
  s.haptics.query_box_budget = 1500;
  s.haptics.force_ramp_s = 1.5;
  s.device.type = "haply";
  s.device.handle_mass_kg = 0.1;
  s.device.handle_damping_n_s_per_m = 3;
  s.device.encoder_counts_per_rev = 4096;
  s.device.max_torque_n_m = 0.25;
  s.device.transport = "tty";
  s.device.usb_vid = 0x239A;
  s.device.usb_pid = 0x8013;
  s.device.serial_path = "/dev/serial/by-id/usb-Haply_board-if00";
  s.device.device_id = 7;
  s.device.lost_after_ticks = 5;
  s.device.actuator1_port = 1;
  s.device.actuator1_dir = "ccw";
  s.device.actuator2_port = 2;
  s.device.actuator2_dir = "ccw";
  s.device.encoder1_port = 1;
  s.device.encoder1_dir = "cw";
  s.device.encoder1_offset_deg = 181.5;
  s.device.encoder1_resolution = 2048;
  s.device.encoder2_port = 2;
  s.device.encoder2_dir = "cw";
  s.device.encoder2_offset_deg = -1.25;
  s.device.encoder2_resolution = 8192;
  s.device.link_proximal_m = 0.05;
  s.device.link_distal_m = 0.07;
  s.device.motor_spacing_m = 0.02;
  s.device.torque_limit_n_m = 0.2;
  s.device.rect_width_m = 0.08;
  s.device.rect_height_m = 0.05;
  s.device.rect_center_y_m = -0.08;
  s.device.park_x_m = 0.01;
  s.device.park_y_m = -0.02;
  s.hand.stiffness_n_per_m = 300;
  s.hand.damping_n_s_per_m = 6;
  s.hand.max_force_n = 2.5;
  s.hand.raster_speed_m_per_s = 0.05;
  s.hand.raster_spacing_m = 0.004;
  s.vision.max_file_bytes = 12345678;
  s.vision.max_width_px = 4000;
  s.vision.max_height_px = 3000;
  s.vision.max_pixels = 12000000;
  s.vision.blur_sigma_px = 2.25;
  s.vision.canny_low = 50;
  s.vision.canny_high = 150;
  s.vision.min_chain_length_m = 0.002;
  s.vision.max_image_side_px = 640;
  s.workspace.width_m = 0.16;
  s.workspace.height_m = 0.1;
  return s;
}

TEST(ConfigRoundTrip, EveryFieldChanged) {
  const Settings s = every_field_changed();
  ASSERT_NO_THROW(validate(s));
  // Guard the guard: every numeric field differs from its default.
  const Settings d{};
  EXPECT_NE(s.haptics, d.haptics);
  EXPECT_NE(s.device.encoder_counts_per_rev, d.device.encoder_counts_per_rev);
  EXPECT_EQ(parse_settings(to_toml(s), "changed"), s) << to_toml(s);
}

/// A random valid Settings: uniform in each documented range, bounds themselves now and then,
/// awkward doubles (full 17-digit precision), then the cross-field rules repaired.
Settings random_settings(std::mt19937_64& rng) {
  Settings s;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const auto& spec : numeric_specs()) {
    const double r = unit(rng);
    double v;
    if (r < 0.05) {
      v = spec.min;
    } else if (r < 0.10) {
      v = spec.max;
    } else if (spec.integer) {
      v = static_cast<double>(std::uniform_int_distribution<long long>(
          static_cast<long long>(spec.min), static_cast<long long>(spec.max))(rng));
    } else {
      v = std::uniform_real_distribution<double>(spec.min, spec.max)(rng);
    }
    const FieldDescriptor* d = find_field(spec.table, spec.key);
    if (!d) throw std::runtime_error("no field " + spec.name());
    std::visit(
        [&](auto* p) {
          using T = std::remove_pointer_t<decltype(p)>;
          if constexpr (!std::is_same_v<T, std::string>) *p = static_cast<T>(v);
        },
        d->ref(s));
  }
  if (s.haptics.level > s.haptics.max_levels) std::swap(s.haptics.level, s.haptics.max_levels);
  if (s.haptics.max_levels < 1) s.haptics.max_levels = 1;
  if (s.haptics.level > s.haptics.max_levels) s.haptics.level = s.haptics.max_levels;
  if (s.vision.canny_low > s.vision.canny_high) std::swap(s.vision.canny_low, s.vision.canny_high);
  if (s.haptics.dynamic_friction > s.haptics.static_friction) std::swap(s.haptics.dynamic_friction, s.haptics.static_friction);
  if (s.haptics.pop_force_n > 0.0 && s.haptics.tour_max_force_n >= s.haptics.pop_force_n) {
    if (s.haptics.pop_force_n > 0.2) s.haptics.tour_max_force_n = s.haptics.pop_force_n / 2; else s.haptics.pop_force_n = 0.0;
  }
  if (s.device.actuator1_port == s.device.actuator2_port) s.device.actuator2_port = s.device.actuator1_port % 4 + 1;
  if (s.device.encoder1_port == s.device.encoder2_port) s.device.encoder2_port = s.device.encoder1_port % 4 + 1;
  s.device.motor_spacing_m = std::min(s.device.motor_spacing_m, 1.9 * (s.device.link_proximal_m + s.device.link_distal_m));
  return s;
}

TEST(ConfigRoundTrip, SeededRandomValidSettings) {
  std::mt19937_64 rng(20240611);
  const Settings defaults{};
  int differing = 0;
  for (int i = 0; i < 500; ++i) {
    const Settings s = random_settings(rng);
    ASSERT_NO_THROW(validate(s)) << "iteration " << i;
    const std::string text = to_toml(s);
    Settings back;
    ASSERT_NO_THROW(back = parse_settings(text, "random")) << text;
    ASSERT_EQ(back, s) << "iteration " << i << "\n" << text << "\nreads back as\n" << to_toml(back);
    differing += (s != defaults);
  }
  EXPECT_EQ(differing, 500);  // the generator really generates something
}

TEST(ConfigRoundTrip, TextIsCommentedForOperators) {
  const std::string text = to_toml(Settings{});
  // Every key appears once, under its table, right after a comment giving its range (and unit).
  for (const auto& d : field_descriptors()) {
    const std::string header = "[" + std::string(d.table) + "]\n";
    const auto table_at = text.find(header);
    ASSERT_NE(table_at, std::string::npos) << header;
    const std::string line_start = "\n" + std::string(d.key) + " = ";
    const auto key_at = text.find(line_start, table_at);
    ASSERT_NE(key_at, std::string::npos) << d.key;
    const auto next_table = text.find("\n[", table_at + 1);
    EXPECT_LT(key_at, next_table) << d.key << " is not under [" << d.table << "]";
    const auto comment_at = text.rfind("\n# ", key_at - 1);
    ASSERT_NE(comment_at, std::string::npos);
    const std::string comment = text.substr(comment_at + 1, key_at - comment_at - 1);
    EXPECT_EQ(comment.find('\n'), std::string::npos) << "no single comment line above " << d.key;
    if (d.kind == FieldKind::text && d.check) {
      EXPECT_EQ(comment.find("Allowed:"), std::string::npos) << comment;  // free text: the help says what it holds
    } else if (d.kind == FieldKind::text) {
      EXPECT_NE(comment.find("Allowed: one of \"" + std::string(d.choices[0]) + "\""), std::string::npos) << comment;
    } else {
      EXPECT_NE(comment.find("Range ["), std::string::npos) << comment;
      EXPECT_NE(comment.find(std::string(d.unit)), std::string::npos) << comment;
    }
    EXPECT_NE(comment.find("Default "), std::string::npos) << comment;
  }
  EXPECT_NE(text.find("# Wall stiffness. Range [10, 5000] N/m. Default 800.0.\nstiffness_n_per_m = 800.0\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("max_file_bytes = 67108864\n"), std::string::npos) << text;
  EXPECT_NE(text.find("Range [1024, 2147483648] bytes, an integer."), std::string::npos) << text;
}

TEST(ConfigRoundTrip, EveryLineIsCommentHeaderBlankOrKeyValue) {
  std::istringstream in(to_toml(every_field_changed()));
  std::string line;
  int keys = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line.starts_with("# ") || (line.starts_with("[") && line.ends_with("]"))) continue;
    EXPECT_NE(line.find(" = "), std::string::npos) << line;
    ++keys;
  }
  EXPECT_EQ(keys, static_cast<int>(field_descriptors().size()));
}

TEST(ConfigRoundTrip, StringsAreEscapedSoTheTextStaysValidToml) {
  // An invalid type with quotes and a newline: to_toml must still write valid TOML, and loading it
  // must then refuse the value (not fail with a syntax error).
  Settings s;
  s.device.type = "a\"b\\c\nd";
  auto e = test::capture_error([&] { (void)parse_settings(to_toml(s), "esc.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "device.type") << e->what();
  EXPECT_TRUE(test::is_one_line(e->what())) << e->what();
}

TEST(ConfigRoundTrip, TinyAndHugeRealsKeepEveryBit) {
  Settings s;
  s.vision.min_chain_length_m = 5e-324;             // smallest subnormal
  s.hand.raster_spacing_m = 0.0005000000000000001;  // not the shortest-looking neighbour
  s.workspace.width_m = 0.1 + 0.2;                  // 0.30000000000000004
  ASSERT_NO_THROW(validate(s));
  EXPECT_EQ(parse_settings(to_toml(s), "bits"), s) << to_toml(s);
}

}  // namespace
}  // namespace hk::config
