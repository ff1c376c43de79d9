// to_toml -> parse_settings gives back exactly the same Settings, and the text is operator-readable.

#include <gtest/gtest.h>
#include <algorithm>

#include <random>
#include <sstream>
#include <string>

#include "config/device_profile.hpp"
#include "config/load.hpp"
#include "config_test_util.hpp"

namespace hk::config {
namespace {

using test::numeric_specs;

TEST(ConfigRoundTrip, Defaults) {
  const Settings s{};
  EXPECT_EQ(parse_settings(to_toml(s), "defaults"), s) << to_toml(s);
}

/// Every field set by hand (not through the implementation's table) to a valid value that is not its
/// default, so a field missing from the table (or written or read under the wrong key) comes back as
/// its default and fails the comparison. kFieldsSetByHand counts the assignments below; the test checks
/// it against the table, so a field added to Settings and the table but not here fails too.
constexpr std::size_t kFieldsSetByHand = 147;

Settings every_field_changed() {
  Settings s;
  auto& h = s.haptics;
  h.stiffness_n_per_m = 1234.5;
  h.damping_n_s_per_m = 1.25;
  h.max_force_n = 3.25;  // within what the Haply below gives everywhere with its torque limit
  h.servo_rate_hz = 2000;
  h.level = 3;
  h.level_mode = "fixed";
  h.level_error_at_rest_m = 2.5e-4;
  h.level_blur_time_s = 0.02;
  h.level_hysteresis = 0.45;
  h.level_min_dwell_s = 0.3;
  h.level_max_force_step_n = 0.125;
  h.static_friction = 0.7;
  h.dynamic_friction = 0.55;
  h.max_levels = 9;
  h.query_box_budget = 1500;
  h.force_ramp_s = 1.5;
  h.pop_force_n = 2.5;
  h.pop_hold_s = 0.6;
  h.pop_release_s = 0.05;
  h.render = "grooves";
  h.groove_capture_radius_m = 0.004;
  h.groove_depth_n = 1.5;
  h.tour_max_force_n = 0.9;
  h.tour_speed_m_per_s = 0.045;
  auto& d = s.device;
  d.type = "haply";
  d.handle_mass_kg = 0.1;
  d.handle_damping_n_s_per_m = 3;
  d.encoder_counts_per_rev = 4096;
  d.max_torque_n_m = 0.25;
  d.transport = "tty";
  d.usb_ids = "239a:8013";
  d.serial_path = "/dev/serial/by-id/usb-Haply_board-if00";
  d.device_id = 7;
  d.lost_after_ticks = 5;
  d.actuator1_port = 1;
  d.actuator1_dir = "ccw";
  d.actuator2_port = 2;
  d.actuator2_dir = "ccw";
  d.encoder1_port = 1;
  d.encoder1_dir = "cw";
  d.encoder1_offset_deg = 181.5;
  d.encoder1_resolution = 2048;
  d.encoder2_port = 2;
  d.encoder2_dir = "cw";
  d.encoder2_offset_deg = -1.25;
  d.encoder2_resolution = 8192;
  d.link_proximal_m = 0.05;
  d.link_distal_m = 0.07;
  d.motor_spacing_m = 0.02;
  d.torque_limit_n_m = 0.2;
  d.rect_width_m = 0.08;
  d.rect_height_m = 0.05;
  d.rect_center_y_m = -0.08;
  d.park_x_m = 0.01;
  d.park_y_m = -0.02;
  auto& hand = s.hand;
  hand.stiffness_n_per_m = 300;
  hand.damping_n_s_per_m = 6;
  hand.max_force_n = 2.5;
  hand.raster_speed_m_per_s = 0.05;
  hand.raster_spacing_m = 0.004;
  auto& v = s.vision;
  v.max_file_bytes = 12345678;
  v.max_width_px = 4000;
  v.max_height_px = 3000;
  v.max_pixels = 12000000;
  v.blur_sigma_px = 2.25;
  v.canny_low = 50;
  v.canny_high = 150;
  v.min_chain_length_m = 0.002;
  v.max_image_side_px = 640;
  v.max_segments = 12000;
  v.max_shapes = 12;
  v.thin_line_max_width_m = 0.0015;
  v.gap_close_m = 0.002;
  v.surround_inhibition = 2.25;
  v.detector = "surround";
  s.workspace.width_m = 0.16;
  s.workspace.height_m = 0.1;
  auto& a = s.audio;
  a.volume_default_step = 4;
  a.volume_step_db = 2.5;
  a.earcon_gain = 0.75;
  a.duck_db = -20;
  a.speech_rate_wpm = 200;
  a.buffer_frames = 512;
  s.kiosk.timeout_s = 300;
  s.kiosk.warning_s = 30;
  s.kiosk.attract_every_s = 45;
  s.vision.ocr = "always";
  s.vision.ocr_languages = "eng+deu";
  s.vision.ocr_min_confidence = 0.7;
  s.kiosk.quiet_hours = "22:00-07:00";
  s.kiosk.prefetch_mb = 64;
  s.kiosk.scene_cache = "/var/cache/x";
  s.kiosk.names_dir = "/var/lib/names";
  s.kiosk.say_names_on_touch = "off";
  s.kiosk.library = "/srv/kiosk library";
  s.metrics.listen = "[::1]:9471";
  s.kiosk.languages = "de, en";
  s.audio.voice = "espeak";
  s.kiosk.language = "de";
  auto& st = s.stick;
  st.max_depth = 4;
  st.max_entries = 2000;
  st.max_documents = 50;
  st.max_file_bytes = 50LL << 20;
  st.scan_timeout_s = 3.5;
  st.max_pdf_pages = 200;
  st.page_max_pixels = 2e6;
  st.page_max_dpi = 150;
  st.page_timeout_s = 8;
  auto& c = s.camera;
  c.source = "v4l2:/dev/video2";
  c.width_px = 1920;
  c.height_px = 1080;
  c.still_s = 1.5;
  c.timeout_s = 90;
  auto& k = s.keys;
  k.help = "H";
  k.next = "N";
  k.previous = "P";
  k.describe = "W";
  k.finer = "F";
  k.coarser = "X";
  k.volume_up = "EQUAL";
  k.volume_down = "MINUS";
  k.tutorial = "U";
  k.guide = "R";
  k.capture = "ENTER";
  k.repeat = "A";
  k.pause = "B";
  k.where = "E";
  k.finish = "HOME";
  k.next_sentence = "KP_6";
  k.previous_sentence = "KP_4";
  k.next_paragraph = "KP_2";
  k.previous_paragraph = "KP_8";
  k.language = "KP_5";
  k.copy = "KP_0";
  auto& cp = s.copy;
  cp.to = "printer";
  cp.printer = "front-desk";
  cp.printed_line = "Your copy will be at the front desk.";
  cp.per_visit = 2;
  cp.per_day = 20;
  cp.paper = "11x11.5in";
  cp.braille_grade = 1;
  auto& o = s.operator_;
  o.open_chord = "CTRL+SHIFT+P";
  o.idle_close_s = 120;
  o.pin_hash = "$argon2id$v=19$m=65536,t=2,p=1$c29tZXNhbHQ$aGFzaA";
  o.state_file = "/var/lib/haptic-kiosk/pin.state";
  o.audit_log = "/var/log/haptic-kiosk/audit.log";
  o.language = "fr";
  return s;
}

/// Whether field `d` has the same value in `a` and `b`.
bool same_field(const FieldDescriptor& d, const Settings& a, const Settings& b) {
  return std::visit([&](const auto* pa) { return *pa == *std::get<std::decay_t<decltype(pa)>>(d.cref(b)); }, d.cref(a));
}

TEST(ConfigRoundTrip, EveryFieldChanged) {
  const Settings s = every_field_changed();
  ASSERT_NO_THROW(validate(s));
  // Guard the guard: every field of the table differs from its default, and the table has exactly as
  // many fields as every_field_changed() sets.
  const Settings d{};
  for (const FieldDescriptor& f : field_descriptors())
    EXPECT_FALSE(same_field(f, s, d)) << f.table << "." << f.key << " is left at its default";
  EXPECT_EQ(field_descriptors().size(), kFieldsSetByHand);
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
      v = static_cast<double>(std::uniform_int_distribution<long long>(static_cast<long long>(spec.min),
                                                                       static_cast<long long>(spec.max))(rng));
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
  if (s.haptics.dynamic_friction > s.haptics.static_friction)
    std::swap(s.haptics.dynamic_friction, s.haptics.static_friction);
  // Within the simulated pantograph's profile (device_profile.hpp): forces it gives, stiffness it holds.
  s.haptics.stiffness_n_per_m =
      std::min(s.haptics.stiffness_n_per_m, stiffness_limit_n_per_m(s.device.type, s.haptics.servo_rate_hz));
  if (const double f = force_everywhere_n(s, s.device.type); f > 0.0)
    s.haptics.max_force_n = std::max(0.1, std::min(s.haptics.max_force_n, f));
  s.haptics.pop_force_n = std::min(s.haptics.pop_force_n, s.haptics.max_force_n);
  s.haptics.tour_max_force_n = std::min(s.haptics.tour_max_force_n, s.haptics.max_force_n);
  s.haptics.groove_depth_n = std::min(s.haptics.groove_depth_n, s.haptics.max_force_n);
  if (s.haptics.pop_force_n > 0.0 && s.haptics.tour_max_force_n >= s.haptics.pop_force_n) {
    if (s.haptics.pop_force_n > 0.2)
      s.haptics.tour_max_force_n = s.haptics.pop_force_n / 2;
    else
      s.haptics.pop_force_n = 0.0;
  }
  if (s.device.actuator1_port == s.device.actuator2_port) s.device.actuator2_port = s.device.actuator1_port % 4 + 1;
  if (s.device.encoder1_port == s.device.encoder2_port) s.device.encoder2_port = s.device.encoder1_port % 4 + 1;
  s.device.motor_spacing_m =
      std::min(s.device.motor_spacing_m, 1.9 * (s.device.link_proximal_m + s.device.link_distal_m));
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
  s.haptics.max_force_n = 3.0;                      // what the simulated pantograph gives over that width
  ASSERT_NO_THROW(validate(s));
  EXPECT_EQ(parse_settings(to_toml(s), "bits"), s) << to_toml(s);
}

}  // namespace
}  // namespace hk::config
