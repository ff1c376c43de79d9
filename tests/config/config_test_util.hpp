#pragma once
/// @file config_test_util.hpp
/// Helpers shared by the config tests: the expected field list (written from the comments in
/// settings.hpp, independently of the implementation's descriptor table), temp directories and
/// error capture.

#include <gtest/gtest.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/load.hpp"
#include "test_paths.hpp"

namespace hk::config::test {

/// One numeric field as documented in settings.hpp.
struct NumericSpec {
  const char* table;
  const char* key;
  double min;
  double max;
  bool integer;
  std::string name() const { return std::string(table) + "." + key; }
};

inline constexpr double kTwo31 = 2147483648.0;

/// Every numeric field with its documented range (settings.hpp). device.type is the one text field.
inline const std::vector<NumericSpec>& numeric_specs() {
  static const std::vector<NumericSpec> specs{
      {"haptics", "stiffness_n_per_m", 10, 5000, false},
      {"haptics", "damping_n_s_per_m", 0, 20, false},
      {"haptics", "max_force_n", 0.1, 20, false},
      {"haptics", "servo_rate_hz", 100, 10000, false},
      {"haptics", "level", 0, 12, true},
      {"haptics", "max_levels", 1, 12, true},
      {"haptics", "query_box_budget", 0, 10000000, true},
      {"haptics", "force_ramp_s", 0, 10, false},
      {"haptics", "pop_force_n", 0, 20, false},
      {"haptics", "pop_hold_s", 0.01, 5, false},
      {"haptics", "pop_release_s", 0.001, 1, false},
      {"haptics", "groove_capture_radius_m", 0.0005, 0.02, false},
      {"haptics", "groove_depth_n", 0.05, 10, false},
      {"haptics", "tour_max_force_n", 0.1, 5, false},
      {"haptics", "tour_speed_m_per_s", 0.005, 0.2, false},
      {"haptics", "level_error_at_rest_m", 0, 0.01, false},
      {"haptics", "level_blur_time_s", 0, 0.1, false},
      {"haptics", "level_hysteresis", 0, 0.9, false},
      {"haptics", "level_min_dwell_s", 0, 5, false},
      {"haptics", "level_max_force_step_n", 0.001, 5, false},
      {"haptics", "static_friction", 0, 2, false},
      {"haptics", "dynamic_friction", 0, 2, false},
      {"device", "handle_mass_kg", 0.001, 5, false},
      {"device", "handle_damping_n_s_per_m", 0, 100, false},
      {"device", "encoder_counts_per_rev", 64, 1048576, true},
      {"device", "max_torque_n_m", 0.02, 10, false},
      {"device", "device_id", 1, 255, true},
      {"device", "lost_after_ticks", 1, 1000, true},
      {"device", "actuator1_port", 1, 4, true},
      {"device", "actuator2_port", 1, 4, true},
      {"device", "encoder1_port", 1, 4, true},
      {"device", "encoder1_offset_deg", -360, 360, false},
      {"device", "encoder1_resolution", 1, 1000000, false},
      {"device", "encoder2_port", 1, 4, true},
      {"device", "encoder2_offset_deg", -360, 360, false},
      {"device", "encoder2_resolution", 1, 1000000, false},
      {"device", "link_proximal_m", 0.01, 0.5, false},
      {"device", "link_distal_m", 0.01, 0.5, false},
      {"device", "motor_spacing_m", 0, 0.5, false},
      {"device", "torque_limit_n_m", 0.001, 10, false},
      {"device", "rect_width_m", 0.01, 1, false},
      {"device", "rect_height_m", 0.01, 1, false},
      {"device", "rect_center_y_m", -1, 1, false},
      {"device", "park_x_m", -0.5, 0.5, false},
      {"device", "park_y_m", -0.5, 0.5, false},
      {"hand", "stiffness_n_per_m", 1, 5000, false},
      {"hand", "damping_n_s_per_m", 0, 200, false},
      {"hand", "max_force_n", 0.01, 50, false},
      {"hand", "raster_speed_m_per_s", 0.001, 5, false},
      {"hand", "raster_spacing_m", 0.0005, 0.05, false},
      {"vision", "max_file_bytes", 1024, kTwo31, true},
      {"vision", "max_width_px", 16, 100000, true},
      {"vision", "max_height_px", 16, 100000, true},
      {"vision", "max_pixels", 256, kTwo31, true},
      {"vision", "blur_sigma_px", 0, 20, false},
      {"vision", "canny_low", 0, 2000, false},
      {"vision", "canny_high", 0, 2000, false},
      {"vision", "min_chain_length_m", 0, 0.1, false},
      {"vision", "max_image_side_px", 64, 10000, true},
      {"vision", "max_segments", 100, 1000000, true},
      {"vision", "max_shapes", 1, 1000, true},
      {"vision", "thin_line_max_width_m", 0, 0.01, false},
      {"vision", "gap_close_m", 0, 0.005, false},
      {"vision", "surround_inhibition", 0, 4, false},
      {"workspace", "width_m", 0.01, 1, false},
      {"workspace", "height_m", 0.01, 1, false},
      {"audio", "volume_default_step", 1, 10, true},
      {"audio", "volume_step_db", 1, 6, false},
      {"audio", "earcon_gain", 0, 1, false},
      {"audio", "duck_db", -40, 0, false},
      {"audio", "speech_rate_wpm", 80, 450, true},
      {"audio", "buffer_frames", 32, 4096, true},
      {"vision", "ocr_min_confidence", 0, 1, false},
      {"kiosk", "timeout_s", 20, 3600, false},
      {"kiosk", "warning_s", 10, 600, false},
      {"kiosk", "attract_every_s", 0, 3600, false},
      {"kiosk", "prefetch_mb", 0, 4096, true},
      {"stick", "max_depth", 1, 64, true},
      {"stick", "max_entries", 10, 1000000, true},
      {"stick", "max_documents", 1, 100000, true},
      {"stick", "max_file_bytes", 1024, 2147483648.0, true},
      {"stick", "scan_timeout_s", 0.1, 60, false},
      {"stick", "max_pdf_pages", 1, 100000, true},
      {"stick", "page_max_pixels", 1e5, 4e7, false},
      {"stick", "page_max_dpi", 10, 1200, false},
      {"stick", "page_timeout_s", 0.5, 120, false},
      {"camera", "width_px", 64, 8192, true},
      {"camera", "height_px", 64, 8192, true},
      {"camera", "still_s", 0.2, 10, false},
      {"camera", "timeout_s", 5, 600, false},
      {"copy", "per_visit", 0, 20, true},
      {"copy", "per_day", 0, 10000, true},
      {"copy", "braille_grade", 1, 2, true},
      {"operator", "idle_close_s", 10, 3600, false},
  };
  return specs;
}

/// Directory of the test data (tests/data).
inline std::filesystem::path data_dir() { return HK_TEST_DATA_DIR; }

/// Shortest round-trip text of a double as a TOML float ("1.0", "0.006", "1e-05").
inline std::string toml_float(double v) {
  char buf[64];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, end);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

/// Runs `f`; returns the ConfigError it threw, or nullopt (and records a failure) if it threw
/// nothing or something else.
inline std::optional<ConfigError> capture_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "threw a non-ConfigError: " << e.what();
    return std::nullopt;
  }
  ADD_FAILURE() << "did not throw";
  return std::nullopt;
}

/// True when `s` is a single line.
inline bool is_one_line(const std::string& s) { return s.find_first_of("\r\n") == std::string::npos; }

/// A fresh directory under the system temp dir, removed (with its contents) at scope exit.
class TempDir {
 public:
  TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "hk_config_test_XXXXXX").string();
    if (!::mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
    path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all, std::filesystem::perm_options::add, ec);
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline void write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + p.string());
}

/// Names of the entries of a directory, sorted.
inline std::vector<std::string> list_dir(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace hk::config::test
