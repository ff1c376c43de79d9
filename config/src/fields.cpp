/// @file fields.cpp
/// The one table of settings fields (table, key, range, unit, help, accessors) and the checks
/// built on it: range checks, cross-field checks, message formatting.

#include <arpa/inet.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>

#include "config/device_profile.hpp"
#include "config/keys.hpp"
#include "config/load.hpp"
#include "detail.hpp"
#include "hk/language.hpp"

namespace hk::config {

ConfigError::ConfigError(std::string source, std::string key, const std::string& message)
    : hk::Error(message), source_(std::move(source)), key_(std::move(key)) {}

namespace {

template <auto Sub, auto Member>
FieldRef ref_of(Settings& s) {
  return &(s.*Sub.*Member);
}

template <auto Sub, auto Member>
ConstFieldRef cref_of(const Settings& s) {
  return &(s.*Sub.*Member);
}

/// Builds a descriptor; evaluated at compile time, so a bad row (min > max, fractional integer
/// bound, int bound beyond int, a text field with neither choices nor a check) is a compile error.
template <auto Sub, auto Member>
constexpr FieldDescriptor make_field(std::string_view table, std::string_view key, FieldGroup group, ApplyWhen apply,
                                     double min, double max, std::string_view unit, std::string_view help,
                                     std::span<const std::string_view> choices = {},
                                     std::string (*check)(std::string_view) = nullptr) {
  using T = std::remove_cvref_t<decltype(std::declval<Settings&>().*Sub.*Member)>;
  static_assert(std::is_same_v<T, double> || std::is_same_v<T, int> || std::is_same_v<T, std::int64_t> ||
                    std::is_same_v<T, std::string>,
                "unsupported settings field type");
  FieldKind kind = FieldKind::real;
  if constexpr (std::is_same_v<T, std::string>) {
    kind = FieldKind::text;
    if (choices.empty() == (check == nullptr)) throw "a text field needs either its list of choices or a check";
  } else if constexpr (!std::is_same_v<T, double>) {
    kind = FieldKind::integer;
    if (min != static_cast<double>(static_cast<long long>(min)) ||
        max != static_cast<double>(static_cast<long long>(max)))
      throw "integer bounds must be whole numbers";
    if (std::is_same_v<T, int> && (min < INT_MIN || max > INT_MAX)) throw "bounds of an int field must fit in int";
  }
  if (kind != FieldKind::text && check != nullptr) throw "only a text field has a check";
  if (kind != FieldKind::text && !(min <= max)) throw "min must be <= max";
  return FieldDescriptor{table,
                         key,
                         kind,
                         min,
                         max,
                         unit,
                         help,
                         choices,
                         check,
                         group,
                         apply,
                         &ref_of<Sub, Member>,
                         &cref_of<Sub, Member>};
}

// HK_FIELD(table, field, group, apply, min, max, unit, help[, choices]): the key is the field name,
// spelled once. HK_FIELD_IN(member, "toml table", ...) for a table whose name is a C++ keyword.
#define HK_FIELD(table, field, ...) \
  make_field<&Settings::table, &decltype(Settings::table)::field>(#table, #field, __VA_ARGS__)
#define HK_FIELD_IN(member, table_name, field, ...) \
  make_field<&Settings::member, &decltype(Settings::member)::field>(table_name, #field, __VA_ARGS__)

/// The check of a path field: at most 4096 bytes, no control characters.
std::string path_problem(std::string_view v) {
  if (v.size() > 4096) return "is longer than 4096 bytes";
  for (char c : v)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return "holds a control character";
  return {};
}

/// The check of [copy] printer: a CUPS queue name (at most 127 printable characters, none of space, '/', '#'),
/// or empty.
std::string printer_problem(std::string_view v) {
  if (v.size() > 127) return "is longer than a CUPS queue name (127 bytes)";
  for (char c : v)
    if (static_cast<unsigned char>(c) <= 0x20 || c == 0x7f || c == '/' || c == '#')
      return "is not a CUPS queue name (no spaces, '/', '#' or control characters)";
  return {};
}

/// The check of a line staff write for visitors to hear: at most 200 bytes, no control characters.
std::string spoken_line_problem(std::string_view v) {
  if (v.size() > 200) return "is longer than 200 bytes";
  for (char c : v)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return "holds a control character";
  return {};
}

/// The check of [device] usb_ids (parse_usb_ids).
std::string usb_ids_problem(std::string_view v) {
  std::string why;
  return parse_usb_ids(v, &why).empty() ? why : std::string{};
}

/// The check of [camera] source: "auto", "none", or "file:PATH" (a path field's rules), "libcamera:N" or
/// "v4l2:DEV" (vision::parse_source_spec reads it when the camera is opened, and refuses a bad index there).
std::string camera_source_problem(std::string_view v) {
  if (v == "auto" || v == "none") return {};
  for (std::string_view kind : {"file:", "libcamera:", "v4l2:"})
    if (v.substr(0, kind.size()) == kind) {
      if (v.size() == kind.size())
        return "names no " + std::string(kind == "libcamera:" ? "camera number" : "path") + " after '" +
               std::string(kind) + "'";
      return path_problem(v);
    }
  return "is not \"auto\", \"none\", \"file:PATH\", \"libcamera:N\" or \"v4l2:DEV\"";
}

/// The check of [operator] pin_hash: empty, or what libsodium's crypto_pwhash_str writes for argon2id
/// (printable ASCII starting "$argon2id$", at most 127 bytes: crypto_pwhash_STRBYTES − 1).
std::string pin_hash_problem(std::string_view v) {
  if (v.empty()) return {};
  if (v.size() > 127) return "is longer than an argon2id hash (127 bytes); set the PIN with 'haptic-kiosk pin set'";
  if (v.rfind("$argon2id$", 0) != 0) return "is not an argon2id hash; set the PIN with 'haptic-kiosk pin set'";
  for (char c : v)
    if (c <= 0x20 || c >= 0x7f)
      return "holds a character no argon2id hash has; set the PIN with 'haptic-kiosk pin set'";
  return {};
}

/// The check of [kiosk] scene_cache and names_dir: "auto", "off" or an absolute folder.
std::string scene_cache_problem(std::string_view v) {
  if (v == "auto" || v == "off" || (!v.empty() && v.front() == '/')) return {};
  return "must be \"auto\", \"off\" or an absolute folder";
}

/// The check of [kiosk] library: "auto" or an absolute folder.
std::string library_problem(std::string_view v) {
  if (v == "auto" || (!v.empty() && v.front() == '/')) return path_problem(v);
  return "must be \"auto\" or an absolute folder";
}

/// The check of [metrics] listen: empty, or ADDRESS:PORT with a numeric IPv4 address or a bracketed IPv6 one and a
/// port in [1, 65535].
std::string listen_problem(std::string_view v) {
  if (v.empty()) return {};
  const std::string_view::size_type colon = v.rfind(':');
  if (colon == std::string_view::npos || colon == 0) return "must be ADDRESS:PORT (\"127.0.0.1:9471\") or empty";
  const std::string_view host = v.substr(0, colon), port = v.substr(colon + 1);
  int p = 0;
  if (port.empty() || port.size() > 5) return "has no port in [1, 65535] after the last ':'";
  for (char c : port) {
    if (c < '0' || c > '9') return "has no port in [1, 65535] after the last ':'";
    p = p * 10 + (c - '0');
  }
  if (p < 1 || p > 65535) return "has no port in [1, 65535] after the last ':'";
  std::array<unsigned char, 16> addr{};
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') {
    const std::string h(host.substr(1, host.size() - 2));
    if (inet_pton(AF_INET6, h.c_str(), addr.data()) == 1) return {};
    return "has an IPv6 address in brackets that does not parse";
  }
  if (inet_pton(AF_INET, std::string(host).c_str(), addr.data()) == 1) return {};
  return "must name a numeric IPv4 address or a bracketed IPv6 one before the port";
}

/// The check of [kiosk] quiet_hours (parse_quiet_hours).
std::string quiet_hours_problem(std::string_view v) {
  std::string why;
  return v.empty() || parse_quiet_hours(v, &why) ? std::string{} : why;
}

/// The check of [kiosk] languages: BCP 47 tags separated by commas.
std::string languages_problem(std::string_view v) {
  std::string why;
  return language_list(v, &why).empty() ? why : std::string{};
}

/// The check of [kiosk] language: one BCP 47 tag.
std::string language_problem(std::string_view v) {
  return is_language_tag(v) ? std::string{} : "is not a language tag such as \"fr\" or \"pt-BR\"";
}

/// The check of [vision] ocr_languages: empty, or Tesseract language codes joined by '+'.
std::string ocr_languages_problem(std::string_view v) {
  if (v.empty()) return {};
  if (v.size() > 200) return "is longer than 200 characters";
  std::size_t from = 0;
  while (from <= v.size()) {
    const std::size_t plus = std::min(v.find('+', from), v.size());
    const std::string_view lang = v.substr(from, plus - from);
    if (lang.empty() || lang.size() > 32) return "must be Tesseract languages joined by '+', e.g. \"eng+deu\"";
    for (char c : lang)
      if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_'))
        return "must be Tesseract languages joined by '+', e.g. \"eng+deu\"";
    from = plus + 1;
  }
  return {};
}

/// The check of [operator] open_chord (parse_chord).
std::string chord_problem(std::string_view v) {
  std::string why;
  return parse_chord(v, &why) ? std::string{} : why;
}

constexpr std::array<std::string_view, 4> kDeviceTypes{"auto", "simulated", "haply", "haply-gen2"};
constexpr std::array<std::string_view, 3> kTransports{"auto", "usb", "tty"};
constexpr std::array<std::string_view, 2> kRotations{"cw", "ccw"};
constexpr std::array<std::string_view, 4> kLevelModes{"auto", "tolerance", "cut", "fixed"};
constexpr std::array<std::string_view, 2> kRenderModes{"walls", "grooves"};
constexpr std::array<std::string_view, 6> kDetectors{"auto", "canny", "surround", "bilateral", "edpf", "outline"};
constexpr std::array<std::string_view, 3> kOcrModes{"auto", "always", "off"};
constexpr std::array<std::string_view, 2> kOnOff{"on", "off"};
constexpr std::array<std::string_view, 5> kVoices{"flite-slt", "flite-kal", "flite-awb", "flite-rms", "espeak"};
constexpr double kTwoPow31 = 2147483648.0;
// Where [copy] sends copies, and the papers a copy is laid out for (copies/tactile_graphic.hpp parse_paper).
constexpr auto kCopyTo = std::to_array<std::string_view>({"off", "printer", "stick", "both"});
constexpr auto kPapers = std::to_array<std::string_view>({"a4", "letter", "11x11.5in"});
// Key names of [keys] (GLFW's names without the GLFW_KEY_ prefix; app/kiosk maps them).
constexpr auto kKeyNames = std::to_array<std::string_view>(
    {"F1",    "F2",    "F3",     "F4",          "F5",      "F6",        "F7",    "F8",    "F9",     "F10",
     "F11",   "F12",   "A",      "B",           "D",       "E",         "F",     "G",     "H",      "I",
     "J",     "K",     "L",      "M",           "N",       "P",         "Q",     "R",     "S",      "T",
     "U",     "V",     "W",      "X",           "Y",       "Z",         "0",     "1",     "2",      "3",
     "4",     "5",     "6",      "7",           "8",       "9",         "SPACE", "ENTER", "TAB",    "BACKSPACE",
     "LEFT",  "RIGHT", "UP",     "DOWN",        "PAGE_UP", "PAGE_DOWN", "HOME",  "END",   "INSERT", "DELETE",
     "MINUS", "EQUAL", "KP_0",   "KP_1",        "KP_2",    "KP_3",      "KP_4",  "KP_5",  "KP_6",   "KP_7",
     "KP_8",  "KP_9",  "KP_ADD", "KP_SUBTRACT", "KP_ENTER"});

constexpr std::array<detail::TableInfo, 13> kTables{{
    {"haptics", "Force rendering and the servo loop."},
    {"device",
     "Which device drives the handle: the simulated pantograph's physics, and the USB pantograph's board, links and "
     "calibration."},
    {"hand", "The model hand that drives the simulated pantograph in headless runs."},
    {"vision", "Image intake limits, edge detection and linking."},
    {"workspace", "The device's usable rectangle, centred on the workspace origin."},
    {"audio", "Earcons, speech and volume."},
    {"kiosk", "The visitor's session."},
    {"stick", "Documents from USB sticks: how far a scan goes and how PDF pages are drawn."},
    {"camera", "The camera a visitor puts a picture under: the source, the frame size and when a capture happens."},
    {"keys", "The key for each of the visitor's actions (O, C and ESCAPE are never a visitor's)."},
    {"copy",
     "Take-home copies: a tactile graphic of the picture with braille, made when a visitor presses the Copy "
     "key twice."},
    {"metrics", "The Prometheus metrics endpoint a museum's monitoring scrapes: counts only, no visitor data."},
    {"operator", "The operator's panel: how it opens, its PIN (set with 'haptic-kiosk pin set') and its records."},
}};

constexpr auto kFields = std::to_array<FieldDescriptor>({
    // [haptics]
    HK_FIELD(haptics, stiffness_n_per_m, FieldGroup::haptics, ApplyWhen::live, 10, 5000, "N/m", "Wall stiffness."),
    HK_FIELD(haptics, damping_n_s_per_m, FieldGroup::haptics, ApplyWhen::live, 0, 20, "N·s/m",
             "Damping rendered while in contact."),
    HK_FIELD(haptics, max_force_n, FieldGroup::haptics, ApplyWhen::live, 0.1, 20, "N",
             "Force clamp: no force above this leaves the device."),
    HK_FIELD(haptics, servo_rate_hz, FieldGroup::haptics, ApplyWhen::restart, 100, 10000, "Hz", "Servo loop rate."),
    HK_FIELD(
        haptics, level, FieldGroup::levels, ApplyWhen::scene, 0, 12, "",
        "Resolution level at the start, and always when level_mode = \"fixed\"; 0 = finest; must be <= max_levels."),
    HK_FIELD(haptics, level_mode, FieldGroup::levels, ApplyWhen::scene, 0, 0, "",
             "\"auto\": the level follows the hand's speed; \"tolerance\": so does the tolerance, each shape at the "
             "coarsest of its own levels within it; \"cut\": so does the tolerance, each stretch of a shape as coarse "
             "as it allows (the tolerance cut); \"fixed\": always `level`.",
             kLevelModes),
    HK_FIELD(haptics, level_error_at_rest_m, FieldGroup::levels, ApplyWhen::scene, 0, 0.01, "m",
             "Deviation from the true curve a slowly moving fingertip cannot feel."),
    HK_FIELD(haptics, level_blur_time_s, FieldGroup::levels, ApplyWhen::scene, 0, 0.1, "s",
             "The tolerable deviation grows by the hand's speed times this."),
    HK_FIELD(haptics, level_hysteresis, FieldGroup::levels, ApplyWhen::scene, 0, 0.9, "",
             "Go coarser only when that level's error is this fraction below the tolerance."),
    HK_FIELD(haptics, level_min_dwell_s, FieldGroup::levels, ApplyWhen::scene, 0, 5, "s",
             "Least time between two level changes."),
    HK_FIELD(haptics, level_max_force_step_n, FieldGroup::haptics, ApplyWhen::live, 0.001, 5, "N",
             "Largest force change per tick that a level change or a live change of stiffness, damping, force or "
             "friction may cause."),
    HK_FIELD(haptics, static_friction, FieldGroup::haptics, ApplyWhen::live, 0, 2, "",
             "Coulomb static friction of the walls; >= dynamic_friction."),
    HK_FIELD(haptics, dynamic_friction, FieldGroup::haptics, ApplyWhen::live, 0, 2, "",
             "Coulomb dynamic friction of the walls; both 0 = frictionless."),
    HK_FIELD(haptics, max_levels, FieldGroup::levels, ApplyWhen::scene, 1, 12, "",
             "Number of levels built above level 0."),
    HK_FIELD(haptics, query_box_budget, FieldGroup::haptics, ApplyWhen::live, 0, 10000000, "box tests",
             "Box tests the collision queries and level-change checks of one servo tick may do; past it the proxy "
             "waits where the sweep is proven clear (anytime). 0 = no limit."),
    HK_FIELD(haptics, force_ramp_s, FieldGroup::haptics, ApplyWhen::scene, 0, 10, "s", "Start-up force ramp duration."),
    HK_FIELD(haptics, pop_force_n, FieldGroup::haptics, ApplyWhen::live, 0, 20, "N",
             "Pressing a wall harder than this for pop_hold_s lets the hand through it; 0 = walls never give way."),
    HK_FIELD(haptics, pop_hold_s, FieldGroup::haptics, ApplyWhen::live, 0.01, 5, "s",
             "How long a press must last to push through a wall."),
    HK_FIELD(haptics, pop_release_s, FieldGroup::haptics, ApplyWhen::live, 0.001, 1, "s",
             "After a push-through the force falls to zero over this."),
    HK_FIELD(haptics, render, FieldGroup::haptics, ApplyWhen::scene, 0, 0, "",
             "\"walls\": curves are walls the hand slides along; \"grooves\": curves are engraved lines that pull the "
             "hand in.",
             kRenderModes),
    HK_FIELD(haptics, groove_capture_radius_m, FieldGroup::haptics, ApplyWhen::scene, 0.0005, 0.02, "m",
             "A groove pulls the hand within this distance of its curve."),
    HK_FIELD(haptics, groove_depth_n, FieldGroup::haptics, ApplyWhen::scene, 0.05, 10, "N",
             "Depth of a groove as felt: its strongest pull (never more than stiffness x capture radius / 2)."),
    HK_FIELD(haptics, tour_max_force_n, FieldGroup::haptics, ApplyWhen::live, 0.1, 5, "N",
             "The guided tour never pulls the handle harder than this; below pop_force_n."),
    HK_FIELD(haptics, tour_speed_m_per_s, FieldGroup::haptics, ApplyWhen::live, 0.005, 0.2, "m/s",
             "Speed of the guided tour along an outline."),
    // [device]
    HK_FIELD(device, type, FieldGroup::devices, ApplyWhen::restart, 0, 0, "",
             "Device driving the handle, and the profile whose forces, stiffness and board it brings: \"auto\" (a USB "
             "Haply when one answers, else simulated), \"simulated\", \"haply\" (2DIY gen3) or \"haply-gen2\" (the "
             "original 2DIY).",
             kDeviceTypes),
    HK_FIELD(device, handle_mass_kg, FieldGroup::devices, ApplyWhen::restart, 0.001, 5, "kg",
             "Effective handle mass (simulated pantograph)."),
    HK_FIELD(device, handle_damping_n_s_per_m, FieldGroup::devices, ApplyWhen::restart, 0, 100, "N·s/m",
             "Device viscous damping."),
    HK_FIELD(device, encoder_counts_per_rev, FieldGroup::devices, ApplyWhen::restart, 64, 1048576, "counts/rev",
             "Encoder resolution."),
    HK_FIELD(device, max_torque_n_m, FieldGroup::devices, ApplyWhen::restart, 0.02, 10, "N·m",
             "Per-motor torque limit (simulated pantograph)."),
    HK_FIELD(device, transport, FieldGroup::devices, ApplyWhen::restart, 0, 0, "",
             "How to reach the USB pantograph: \"auto\" (libusb, then the kernel's tty), \"usb\" or \"tty\".",
             kTransports),
    HK_FIELD(device, usb_ids, FieldGroup::devices, ApplyWhen::restart, 0, 0, "",
             "USB ids (VVVV:PPPP, comma-separated) the pantograph's board is looked for at, in order; one found is "
             "taken once it answers hAPI ('haptic-kiosk devices' says which answered).",
             {}, &usb_ids_problem),
    HK_FIELD(device, serial_path, FieldGroup::devices, ApplyWhen::restart, 0, 0, "",
             "The board's tty for the tty transport; empty: the first /dev/serial/by-id entry.", {}, &path_problem),
    HK_FIELD(device, device_id, FieldGroup::devices, ApplyWhen::restart, 1, 255, "",
             "hAPI device id the board is set up with."),
    HK_FIELD(device, lost_after_ticks, FieldGroup::devices, ApplyWhen::restart, 1, 1000, "ticks",
             "Servo ticks without a valid reply before the device counts as lost (force off, spoken)."),
    HK_FIELD(device, actuator1_port, FieldGroup::devices, ApplyWhen::restart, 1, 4, "",
             "Board port of actuator 1 (Haply joint 1)."),
    HK_FIELD(device, actuator1_dir, FieldGroup::devices, ApplyWhen::restart, 0, 0, "",
             "Positive direction of actuator 1.", kRotations),
    HK_FIELD(device, actuator2_port, FieldGroup::devices, ApplyWhen::restart, 1, 4, "",
             "Board port of actuator 2 (Haply joint 2)."),
    HK_FIELD(device, actuator2_dir, FieldGroup::devices, ApplyWhen::restart, 0, 0, "",
             "Positive direction of actuator 2.", kRotations),
    HK_FIELD(device, encoder1_port, FieldGroup::devices, ApplyWhen::restart, 1, 4, "", "Board port of encoder 1."),
    HK_FIELD(device, encoder1_dir, FieldGroup::devices, ApplyWhen::restart, 0, 0, "",
             "Positive direction of encoder 1.", kRotations),
    HK_FIELD(device, encoder1_offset_deg, FieldGroup::devices, ApplyWhen::restart, -360, 360, "deg",
             "Angle encoder 1 reports at the pose the board starts in ('haptic-kiosk calibrate' sets it)."),
    HK_FIELD(device, encoder1_resolution, FieldGroup::devices, ApplyWhen::restart, 1, 1000000, "counts/rev",
             "Encoder 1 resolution as the board's firmware takes it."),
    HK_FIELD(device, encoder2_port, FieldGroup::devices, ApplyWhen::restart, 1, 4, "", "Board port of encoder 2."),
    HK_FIELD(device, encoder2_dir, FieldGroup::devices, ApplyWhen::restart, 0, 0, "",
             "Positive direction of encoder 2.", kRotations),
    HK_FIELD(device, encoder2_offset_deg, FieldGroup::devices, ApplyWhen::restart, -360, 360, "deg",
             "Angle encoder 2 reports at the pose the board starts in ('haptic-kiosk calibrate' sets it)."),
    HK_FIELD(device, encoder2_resolution, FieldGroup::devices, ApplyWhen::restart, 1, 1000000, "counts/rev",
             "Encoder 2 resolution as the board's firmware takes it."),
    HK_FIELD(device, link_proximal_m, FieldGroup::devices, ApplyWhen::restart, 0.01, 0.5, "m",
             "USB pantograph: motor-to-elbow link length."),
    HK_FIELD(device, link_distal_m, FieldGroup::devices, ApplyWhen::restart, 0.01, 0.5, "m",
             "USB pantograph: elbow-to-handle link length."),
    HK_FIELD(device, motor_spacing_m, FieldGroup::devices, ApplyWhen::restart, 0, 0.5, "m",
             "USB pantograph: distance between the two motor axes."),
    HK_FIELD(device, torque_limit_n_m, FieldGroup::devices, ApplyWhen::restart, 0.001, 10, "N·m",
             "USB pantograph: torque limit per motor (the board's own limit)."),
    HK_FIELD(device, rect_width_m, FieldGroup::devices, ApplyWhen::restart, 0.01, 1, "m",
             "USB pantograph: width of its usable rectangle, mapped onto [workspace]."),
    HK_FIELD(device, rect_height_m, FieldGroup::devices, ApplyWhen::restart, 0.01, 1, "m",
             "USB pantograph: height of its usable rectangle."),
    HK_FIELD(device, rect_center_y_m, FieldGroup::devices, ApplyWhen::restart, -1, 1, "m",
             "USB pantograph: the rectangle's centre relative to the motor axes (negative: towards the visitor)."),
    HK_FIELD(device, park_x_m, FieldGroup::devices, ApplyWhen::restart, -0.5, 0.5, "m",
             "Where the handle rests for 'haptic-kiosk calibrate' (workspace x)."),
    HK_FIELD(device, park_y_m, FieldGroup::devices, ApplyWhen::restart, -0.5, 0.5, "m",
             "Where the handle rests for calibration (workspace y)."),
    // [hand]
    HK_FIELD(hand, stiffness_n_per_m, FieldGroup::devices, ApplyWhen::restart, 1, 5000, "N/m",
             "Spring pulling the hand to its target."),
    HK_FIELD(hand, damping_n_s_per_m, FieldGroup::devices, ApplyWhen::restart, 0, 200, "N·s/m",
             "Damping of the hand spring."),
    HK_FIELD(hand, max_force_n, FieldGroup::devices, ApplyWhen::restart, 0.01, 50, "N",
             "The most a visitor pushes with."),
    HK_FIELD(hand, raster_speed_m_per_s, FieldGroup::devices, ApplyWhen::restart, 0.001, 5, "m/s",
             "Target speed along the raster."),
    HK_FIELD(hand, raster_spacing_m, FieldGroup::devices, ApplyWhen::restart, 0.0005, 0.05, "m",
             "Line spacing of the raster."),
    // [vision]
    HK_FIELD(vision, max_file_bytes, FieldGroup::scene, ApplyWhen::scene, 1024, kTwoPow31, "bytes",
             "Largest image file accepted."),
    HK_FIELD(vision, max_width_px, FieldGroup::scene, ApplyWhen::scene, 16, 100000, "px", "Widest image accepted."),
    HK_FIELD(vision, max_height_px, FieldGroup::scene, ApplyWhen::scene, 16, 100000, "px", "Tallest image accepted."),
    HK_FIELD(vision, max_pixels, FieldGroup::scene, ApplyWhen::scene, 256, kTwoPow31, "px",
             "Largest width x height accepted."),
    HK_FIELD(vision, blur_sigma_px, FieldGroup::scene, ApplyWhen::scene, 0, 20, "px", "Gaussian pre-blur sigma."),
    HK_FIELD(vision, canny_low, FieldGroup::scene, ApplyWhen::scene, 0, 2000, "",
             "Canny hysteresis low threshold; 0 = from the image; <= canny_high when both nonzero."),
    HK_FIELD(vision, canny_high, FieldGroup::scene, ApplyWhen::scene, 0, 2000, "",
             "Canny hysteresis high threshold; 0 = from the image."),
    HK_FIELD(vision, min_chain_length_m, FieldGroup::scene, ApplyWhen::scene, 0, 0.1, "m",
             "Edge chains shorter than this are dropped."),
    HK_FIELD(vision, max_image_side_px, FieldGroup::scene, ApplyWhen::scene, 64, 10000, "px",
             "Images are downscaled to this longest side."),
    HK_FIELD(vision, max_segments, FieldGroup::scene, ApplyWhen::scene, 100, 1000000, "",
             "Scene budget: level-0 segments kept, the most salient curves first."),
    HK_FIELD(vision, max_shapes, FieldGroup::scene, ApplyWhen::scene, 1, 1000, "",
             "Shape budget: curves kept, the most salient first (long, sure, closed, enclosing much); the rest are not "
             "felt."),
    HK_FIELD(vision, thin_line_max_width_m, FieldGroup::scene, ApplyWhen::scene, 0, 0.01, "m",
             "The two edges of a line thinner than this become one curve; 0 = off."),
    HK_FIELD(vision, gap_close_m, FieldGroup::scene, ApplyWhen::scene, 0, 0.005, "m",
             "Chain ends facing each other across a gap up to this are joined into one curve (closing outlines Canny "
             "broke); 0 = off."),
    HK_FIELD(vision, surround_inhibition, FieldGroup::scene, ApplyWhen::scene, 0, 4, "",
             "Texture test of the \"surround\" detector: how much of the surrounding edge strength is taken off each "
             "edge before asking whether it still stands out; 0 = none."),
    HK_FIELD(vision, detector, FieldGroup::scene, ApplyWhen::scene, 0, 0, "",
             "\"auto\": two-tone pictures (silhouettes, logos) traced from a threshold, two-tone line drawings by "
             "\"canny\", others by \"surround\"; \"canny\": Canny alone; \"surround\": Canny, edges that do not stand "
             "out from the texture around them dropped; \"bilateral\": Canny after a bilateral filter; \"edpf\": Edge "
             "Drawing (parameter-free); \"outline\": always traced from a threshold.",
             kDetectors),
    HK_FIELD(vision, ocr, FieldGroup::scene, ApplyWhen::scene, 0, 0, "",
             "\"auto\": text is read aloud (Tesseract) from pictures that look like a page of text and PDF pages "
             "without a text layer; \"always\": from every picture; \"off\": never. The picture is felt at once; its "
             "text (about 10 s a page) comes when it is read.",
             kOcrModes),
    HK_FIELD(vision, ocr_languages, FieldGroup::scene, ApplyWhen::scene, 0, 0, "",
             "Tesseract languages joined by '+' (\"eng\", \"eng+deu\"); empty: the kiosk's language and English "
             "(\"fra+eng\" for [kiosk] language = \"fr\"). A "
             "missing one turns OCR off at start, said in the log.",
             {}, &ocr_languages_problem),
    HK_FIELD(vision, ocr_min_confidence, FieldGroup::scene, ApplyWhen::scene, 0, 1, "",
             "Marks with no letter or digit that Tesseract is less sure of than this are said as \"unclear word\"; "
             "words are said as read, however unsure, and a paragraph with no word this sure is left out."),
    // [workspace]
    HK_FIELD(workspace, width_m, FieldGroup::scene, ApplyWhen::restart, 0.01, 1, "m", "Width of the usable rectangle."),
    HK_FIELD(workspace, height_m, FieldGroup::scene, ApplyWhen::restart, 0.01, 1, "m",
             "Height of the usable rectangle."),
    // [audio]
    HK_FIELD(audio, volume_default_step, FieldGroup::audio, ApplyWhen::session, 1, 10, "",
             "Volume step at the start of every session (10 = loudest)."),
    HK_FIELD(audio, volume_step_db, FieldGroup::audio, ApplyWhen::restart, 1, 6, "dB",
             "Loudness change per volume step."),
    HK_FIELD(audio, earcon_gain, FieldGroup::audio, ApplyWhen::restart, 0, 1, "",
             "Level of the earcons before the volume."),
    HK_FIELD(audio, duck_db, FieldGroup::audio, ApplyWhen::restart, -40, 0, "dB",
             "Earcons are this much quieter while speech plays."),
    HK_FIELD(audio, speech_rate_wpm, FieldGroup::audio, ApplyWhen::restart, 80, 450, "words/min", "Speaking rate."),
    HK_FIELD(audio, voice, FieldGroup::audio, ApplyWhen::restart, 0, 0, "",
             "The voice English is spoken with: a CMU Flite voice (\"flite-slt\", a woman's, the most natural; "
             "\"flite-kal\", \"flite-awb\", \"flite-rms\", men's) or \"espeak\" (espeak-ng, clipped but fastest). "
             "Other languages speak with espeak-ng.",
             kVoices),
    HK_FIELD(audio, buffer_frames, FieldGroup::audio, ApplyWhen::restart, 32, 4096, "frames",
             "Audio output buffer at 48 kHz (256 = 5.3 ms)."),
    // [kiosk]
    HK_FIELD(kiosk, timeout_s, FieldGroup::kiosk, ApplyWhen::live, 20, 3600, "s",
             "No key, no handle motion, no contact and no speech for this long ends the session."),
    HK_FIELD(kiosk, warning_s, FieldGroup::kiosk, ApplyWhen::live, 10, 600, "s",
             "The spoken warning comes this long before the end (at most half the timeout)."),
    HK_FIELD(kiosk, attract_every_s, FieldGroup::kiosk, ApplyWhen::live, 0, 3600, "s",
             "While nobody is there, a short spoken invitation comes this often (0: never)."),
    HK_FIELD(kiosk, quiet_hours, FieldGroup::kiosk, ApplyWhen::live, 0, 0, "",
             "Local times with no spoken invitation, \"HH:MM-HH:MM\" (e.g. \"22:00-07:00\"); empty: none.", {},
             &quiet_hours_problem),
    HK_FIELD(kiosk, prefetch_mb, FieldGroup::kiosk, ApplyWhen::live, 0, 4096, "MiB",
             "Memory for the next and previous pictures (of the library, and the pages of a USB stick), built while "
             "the visitor explores this one, so Next is at once (0: none built ahead)."),
    HK_FIELD(
        kiosk, scene_cache, FieldGroup::kiosk, ApplyWhen::restart, 0, 0, "",
        "Where built scenes of the library's pictures are kept, so the first picture after a restart is felt at once: "
        "\"auto\" (the service's cache folder, else ~/.cache/haptic-kiosk/scenes), \"off\", or an absolute folder.",
        {}, &scene_cache_problem),
    HK_FIELD(kiosk, names_dir, FieldGroup::kiosk, ApplyWhen::restart, 0, 0, "",
             "Where names staff give shapes at the kiosk are kept (they win over the file beside the picture): "
             "\"auto\" (the service's state folder, else ~/.local/share/haptic-kiosk/names), \"off\" (only the "
             "files beside the pictures), or an absolute folder.",
             {}, &scene_cache_problem),
    HK_FIELD(kiosk, library, FieldGroup::kiosk, ApplyWhen::restart, 0, 0, "",
             "The picture library folder, watched: pictures added, changed or removed there are taken without a "
             "restart once unchanged for 2 s. \"auto\" (the service's state folder's library, else the shipped "
             "pictures) or an absolute folder; the shipped pictures while it holds none.",
             {}, &library_problem),
    HK_FIELD(kiosk, say_names_on_touch, FieldGroup::kiosk, ApplyWhen::live, 0, 0, "",
             "\"on\": the first time a visitor touches a named shape of a picture, its name is said, once; \"off\": "
             "names only when asked (Where, Describe).",
             kOnOff),
    HK_FIELD(kiosk, languages, FieldGroup::kiosk, ApplyWhen::restart, 0, 0, "",
             "The languages offered to visitors, as BCP 47 tags separated by commas (\"en, fr, de, es\"); the "
             "Language key steps through them in this order. Each needs its catalogue; one without is left out "
             "(logged).",
             {}, &languages_problem),
    HK_FIELD(kiosk, language, FieldGroup::kiosk, ApplyWhen::restart, 0, 0, "",
             "The language each visit starts in, and comes back to at Finish or time-out: one of the languages.", {},
             &language_problem),
    // [stick]
    HK_FIELD(stick, max_depth, FieldGroup::devices, ApplyWhen::restart, 1, 64, "",
             "Deepest folder of a stick that is entered (its root is 0)."),
    HK_FIELD(stick, max_entries, FieldGroup::devices, ApplyWhen::restart, 10, 1000000, "",
             "Directory entries looked at per scan of a stick."),
    HK_FIELD(stick, max_documents, FieldGroup::devices, ApplyWhen::restart, 1, 100000, "",
             "Documents offered per stick."),
    HK_FIELD(stick, max_file_bytes, FieldGroup::devices, ApplyWhen::restart, 1024, kTwoPow31, "bytes",
             "Largest document read from a stick."),
    HK_FIELD(stick, scan_timeout_s, FieldGroup::devices, ApplyWhen::restart, 0.1, 60, "s",
             "Wall-clock limit of one scan of a stick."),
    HK_FIELD(stick, max_pdf_pages, FieldGroup::devices, ApplyWhen::restart, 1, 100000, "",
             "Pages offered per PDF (the first ones)."),
    HK_FIELD(stick, page_max_pixels, FieldGroup::devices, ApplyWhen::restart, 1e5, 4e7, "px",
             "A PDF page is drawn at the DPI that keeps it within this many pixels."),
    HK_FIELD(stick, page_max_dpi, FieldGroup::devices, ApplyWhen::restart, 10, 1200, "dpi",
             "A PDF page is never drawn finer than this."),
    HK_FIELD(stick, page_timeout_s, FieldGroup::devices, ApplyWhen::restart, 0.5, 120, "s",
             "The worker drawing a PDF page is stopped after this (wall clock and CPU)."),
    // [camera]
    HK_FIELD(camera, source, FieldGroup::devices, ApplyWhen::restart, 0, 0, "",
             "\"auto\": the first camera found (libcamera, then V4L2); \"none\": no capture; or \"file:PATH\", "
             "\"libcamera:N\", \"v4l2:DEV\".",
             {}, &camera_source_problem),
    HK_FIELD(camera, width_px, FieldGroup::devices, ApplyWhen::restart, 64, 8192, "px",
             "Frame width asked of the camera."),
    HK_FIELD(camera, height_px, FieldGroup::devices, ApplyWhen::restart, 64, 8192, "px",
             "Frame height asked of the camera."),
    HK_FIELD(camera, still_s, FieldGroup::devices, ApplyWhen::live, 0.2, 10, "s",
             "A picture is captured once it has been whole, centred and still this long."),
    HK_FIELD(camera, timeout_s, FieldGroup::devices, ApplyWhen::live, 5, 600, "s",
             "A capture that has not happened after this long is given up."),
    // [keys]
    HK_FIELD(keys, help, FieldGroup::keys, ApplyWhen::live, 0, 0, "", "Help.", kKeyNames),
    HK_FIELD(keys, next, FieldGroup::keys, ApplyWhen::live, 0, 0, "", "Next picture (next tutorial shape).", kKeyNames),
    HK_FIELD(keys, previous, FieldGroup::keys, ApplyWhen::live, 0, 0, "", "Previous picture.", kKeyNames),
    HK_FIELD(keys, describe, FieldGroup::keys, ApplyWhen::live, 0, 0, "", "Describe the picture.", kKeyNames),
    HK_FIELD(keys, finer, FieldGroup::keys, ApplyWhen::live, 0, 0, "", "More detail (finer level).", kKeyNames),
    HK_FIELD(keys, coarser, FieldGroup::keys, ApplyWhen::live, 0, 0, "", "Less detail (coarser level).", kKeyNames),
    HK_FIELD(keys, volume_up, FieldGroup::keys, ApplyWhen::live, 0, 0, "", "Louder.", kKeyNames),
    HK_FIELD(keys, volume_down, FieldGroup::keys, ApplyWhen::live, 0, 0, "", "Quieter.", kKeyNames),
    HK_FIELD(keys, tutorial, FieldGroup::keys, ApplyWhen::live, 0, 0, "", "Start the tutorial again.", kKeyNames),
    HK_FIELD(keys, guide, FieldGroup::keys, ApplyWhen::live, 0, 0, "",
             "Guided tour: lead the handle to the next shape not yet touched and round it.", kKeyNames),
    HK_FIELD(keys, capture, FieldGroup::keys, ApplyWhen::live, 0, 0, "",
             "Capture a picture with the camera, guided by voice (any key cancels).", kKeyNames),
    HK_FIELD(keys, repeat, FieldGroup::keys, ApplyWhen::live, 0, 0, "", "Say the last message again, from its start.",
             kKeyNames),
    HK_FIELD(keys, pause, FieldGroup::keys, ApplyWhen::live, 0, 0, "", "Pause the speech; pressed again, it goes on.",
             kKeyNames),
    HK_FIELD(keys, where, FieldGroup::keys, ApplyWhen::live, 0, 0, "",
             "What is here: the shape under or nearest the hand, and where the hand is.", kKeyNames),
    HK_FIELD(keys, finish, FieldGroup::keys, ApplyWhen::live, 0, 0, "",
             "Finish: end the visit, for the next visitor (pressed twice).", kKeyNames),
    HK_FIELD(keys, next_sentence, FieldGroup::keys, ApplyWhen::live, 0, 0, "",
             "Reading a text: on from the next sentence.", kKeyNames),
    HK_FIELD(keys, previous_sentence, FieldGroup::keys, ApplyWhen::live, 0, 0, "",
             "Reading a text: back to the sentence before.", kKeyNames),
    HK_FIELD(keys, next_paragraph, FieldGroup::keys, ApplyWhen::live, 0, 0, "",
             "Reading a text: on from the next paragraph (block of text).", kKeyNames),
    HK_FIELD(keys, previous_paragraph, FieldGroup::keys, ApplyWhen::live, 0, 0, "",
             "Reading a text: back to the paragraph before.", kKeyNames),
    HK_FIELD(keys, language, FieldGroup::keys, ApplyWhen::live, 0, 0, "",
             "The next of the offered languages, said in itself; while the kiosk waits, the language of the "
             "invitation just heard.",
             kKeyNames),
    HK_FIELD(keys, copy, FieldGroup::keys, ApplyWhen::live, 0, 0, "",
             "Copy to take home: pressed twice within 10 s, a copy of the picture as a tactile graphic ([copy]).",
             kKeyNames),
    // [copy]
    HK_FIELD(copy, to, FieldGroup::kiosk, ApplyWhen::live, 0, 0, "",
             "Where take-home copies go: \"off\" (none offered), \"printer\" (the CUPS queue [copy] printer), "
             "\"stick\" (a new folder on the visitor's USB stick, FAT or exFAT) or \"both\".",
             kCopyTo),
    HK_FIELD(copy, printer, FieldGroup::kiosk, ApplyWhen::live, 0, 0, "",
             "Printer for copies: the CUPS queue's name (swell paper or an embosser behind it).", {}, &printer_problem),
    HK_FIELD(copy, printed_line, FieldGroup::kiosk, ApplyWhen::live, 0, 0, "",
             "Said when a copy has gone to the printer, e.g. where to collect it; empty = the kiosk's own line.", {},
             &spoken_line_problem),
    HK_FIELD(copy, per_visit, FieldGroup::kiosk, ApplyWhen::live, 0, 20, "", "Copies a visitor may have."),
    HK_FIELD(copy, per_day, FieldGroup::kiosk, ApplyWhen::live, 0, 10000, "",
             "Copies a day: the kiosk makes no more until midnight."),
    HK_FIELD(copy, paper, FieldGroup::kiosk, ApplyWhen::live, 0, 0, "", "Paper of the copies.", kPapers),
    HK_FIELD(copy, braille_grade, FieldGroup::kiosk, ApplyWhen::live, 1, 2, "",
             "Braille of the copies' labels: 1 uncontracted, 2 contracted."),
    // [metrics]
    HK_FIELD(metrics, listen, FieldGroup::kiosk, ApplyWhen::restart, 0, 0, "",
             "Where the Prometheus metrics endpoint listens, \"ADDRESS:PORT\" (\"127.0.0.1:9471\"; a LAN address "
             "for a central Prometheus); empty: off.",
             {}, &listen_problem),
    // [operator]
    HK_FIELD_IN(operator_, "operator", open_chord, FieldGroup::kiosk, ApplyWhen::live, 0, 0, "",
                "Key chord that opens the operator's panel (then the PIN), e.g. \"CTRL+ALT+O\".", {}, &chord_problem),
    HK_FIELD_IN(operator_, "operator", idle_close_s, FieldGroup::kiosk, ApplyWhen::live, 10, 3600, "s",
                "The operator's panel closes itself after this long without input."),
    HK_FIELD_IN(operator_, "operator", pin_hash, FieldGroup::hidden, ApplyWhen::live, 0, 0, "",
                "Hash of the operator's PIN (argon2id); written by 'haptic-kiosk pin set', never by hand.", {},
                &pin_hash_problem),
    HK_FIELD_IN(
        operator_, "operator", state_file, FieldGroup::kiosk, ApplyWhen::restart, 0, 0, "",
        "Failed PIN attempts and the time of the last (the lockout); empty = beside the settings file (.state).", {},
        &path_problem),
    HK_FIELD_IN(operator_, "operator", audit_log, FieldGroup::kiosk, ApplyWhen::restart, 0, 0, "",
                "One line per change made in the panel; empty = beside the settings file (.audit.log).", {},
                &path_problem),
    HK_FIELD_IN(operator_, "operator", language, FieldGroup::kiosk, ApplyWhen::live, 0, 0, "",
                "Language of the operator's panel (a tag: \"en\", \"fr\"); English where it has no translation.", {},
                &language_problem),
});

#undef HK_FIELD
#undef HK_FIELD_IN

std::string with_unit(std::string text, std::string_view unit) {
  if (!unit.empty()) {
    text += ' ';
    text += unit;
  }
  return text;
}

std::string format_bound(const FieldDescriptor& d, double b) {
  if (d.kind == FieldKind::integer) return std::to_string(static_cast<long long>(b));
  return detail::format_real(b);
}

}  // namespace

std::span<const FieldDescriptor> field_descriptors() noexcept { return kFields; }

std::string field_allowed_text(const FieldDescriptor& d) { return detail::allowed_text(d); }

std::string field_choices_text(const FieldDescriptor& d) {
  std::string s;
  for (std::size_t i = 0; i < d.choices.size(); ++i) {
    if (i) s += ", ";
    s += detail::toml_string(d.choices[i]);
  }
  return s;
}

// N_ marks a word of the operator's panel for the translators' template (the panel catalogue, xgettext --keyword=N_);
// the panel looks it up in the staff's language.
#define N_(text) text

std::string_view group_name(FieldGroup g) noexcept {
  switch (g) {
    case FieldGroup::haptics:
      return N_("Haptics");
    case FieldGroup::levels:
      return N_("Levels");
    case FieldGroup::scene:
      return N_("Scene");
    case FieldGroup::audio:
      return N_("Audio");
    case FieldGroup::kiosk:
      return N_("Kiosk");
    case FieldGroup::keys:
      return N_("Keys");
    case FieldGroup::devices:
      return N_("Devices");
    case FieldGroup::hidden:
      return "";
  }
  return "";
}

std::string field_label(const FieldDescriptor& d) {
  return field_label(d.help, std::string(d.table) + "." + std::string(d.key));
}

std::string field_label(std::string_view help, std::string_view key) {
  std::string_view h = help;
  const std::size_t end = std::min({h.find(". "), h.find(':'), h.find(';'), h.find(", "), h.find(" ("), h.size()});
  std::string label(h.substr(0, end));
  // Another setting's key is no staff word: the label stops before it ("... for pop_hold_s" → "... for ...").
  bool cut = false;
  if (const std::size_t u = label.find('_'); u != std::string::npos) {
    const std::size_t word = label.rfind(' ', u);
    label = label.substr(0, word == std::string::npos ? 0 : word);
    cut = true;
  }
  while (!label.empty() && (label.back() == '.' || label.back() == ' ')) label.pop_back();
  if (cut && !label.empty()) label += " ...";
  if (label.size() > kMaxFieldLabelBytes) {
    const std::size_t cut = label.rfind(' ', kMaxFieldLabelBytes);
    label = label.substr(0, cut == std::string::npos ? kMaxFieldLabelBytes : cut) + " ...";
  }
  return label.empty() ? std::string(key) : label;
}

std::span<const std::string_view> visitor_key_names() noexcept { return kKeyNames; }

std::optional<KeyChord> parse_chord(std::string_view text, std::string* why) {
  const auto refuse = [&](std::string reason) -> std::optional<KeyChord> {
    if (why) *why = std::move(reason);
    return std::nullopt;
  };
  if (text.empty()) return refuse("is empty; write e.g. \"CTRL+ALT+O\"");
  KeyChord c;
  std::size_t start = 0;
  for (;;) {
    const std::size_t plus = text.find('+', start);
    const std::string_view part =
        text.substr(start, plus == std::string_view::npos ? std::string_view::npos : plus - start);
    if (part.empty()) return refuse("has an empty part between '+' signs");
    if (plus == std::string_view::npos) {  // the key
      bool known = part == "O" || part == "C" || part == "ESCAPE";
      for (auto k : kKeyNames) known = known || k == part;
      if (!known)
        return refuse("ends in '" + detail::one_line(part, 40) + "', which is not a key name (e.g. O, F12, HOME)");
      c.key = std::string(part);
      break;
    }
    bool* flag = part == "CTRL"    ? &c.ctrl
                 : part == "ALT"   ? &c.alt
                 : part == "SHIFT" ? &c.shift
                 : part == "SUPER" ? &c.super
                                   : nullptr;
    if (!flag)
      return refuse("has '" + detail::one_line(part, 40) + "' where a modifier (CTRL, ALT, SHIFT, SUPER) belongs");
    if (*flag) return refuse("names " + std::string(part) + " twice");
    *flag = true;
    start = plus + 1;
  }
  if (!c.ctrl && !c.alt && !c.super)
    return refuse("needs CTRL, ALT or SUPER, so no visitor opens the PIN prompt with one key");
  return c;
}

std::string chord_text(const KeyChord& c) {
  std::string s;
  if (c.ctrl) s += "CTRL+";
  if (c.alt) s += "ALT+";
  if (c.shift) s += "SHIFT+";
  if (c.super) s += "SUPER+";
  return s + c.key;
}

const FieldDescriptor* find_field(std::string_view table, std::string_view key) noexcept {
  for (const auto& d : kFields)
    if (d.table == table && d.key == key) return &d;
  return nullptr;
}

namespace detail {

std::span<const TableInfo> tables() noexcept { return kTables; }

std::string format_real(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  // Plain decimals read best ("100000", "0.0005"); very large or small magnitudes would make them
  // long, so those fall back to the shortest form, which may use an exponent ("5e-324").
  std::array<char, 32> fixed{};
  if (auto [end, ec] = std::to_chars(fixed.data(), fixed.data() + fixed.size(), v, std::chars_format::fixed);
      ec == std::errc{})
    return std::string(fixed.data(), end);
  std::array<char, 64> buf{};
  auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  if (ec != std::errc{}) return "?";  // cannot happen with 64 chars
  return std::string(buf.data(), end);
}

std::string format_toml_real(double v) {
  std::string s = format_real(v);
  if (std::isfinite(v) && s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

std::string toml_string(std::string_view s) {
  std::string out = "\"";
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (u < 0x20 || u == 0x7f) {
          static constexpr char kHex[] = "0123456789ABCDEF";
          out += "\\u00";
          out += kHex[u >> 4];
          out += kHex[u & 15];
        } else {
          out += c;
        }
    }
  }
  out += '"';
  return out;
}

std::string toml_value(const FieldDescriptor& d, const Settings& s) {
  return std::visit(
      [](auto* p) -> std::string {
        using T = std::remove_cvref_t<decltype(*p)>;
        if constexpr (std::is_same_v<T, double>) {
          return format_toml_real(*p);
        } else if constexpr (std::is_same_v<T, std::string>) {
          return toml_string(*p);
        } else {
          return std::to_string(*p);
        }
      },
      d.cref(s));
}

std::string temp_prefix(const std::string& dir, const std::string& target_name) {
  // Appended piece by piece: "literal" + a temporary trips GCC 12's -Wrestrict (bug 105329) in the package build.
  std::string out = dir;
  if (!out.empty() && out.back() != '/') out += '/';
  out += '.';
  out += target_name;
  out += ".tmp.";
  return out;
}

int write_all(int fd, std::string_view text) {
  const char* p = text.data();
  std::size_t left = text.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  return 0;
}

std::string qualified(const FieldDescriptor& d) {
  std::string s(d.table);
  s += '.';
  s += d.key;
  return s;
}

std::string allowed_text(const FieldDescriptor& d) {
  if (d.kind == FieldKind::text && d.check) return "text";
  if (d.kind == FieldKind::text) return "one of " + field_choices_text(d);
  std::string range = "[";  // appended piece by piece: "literal" + a temporary trips GCC 12's -Wrestrict (bug 105329)
  range += format_bound(d, d.min);
  range += ", ";
  range += format_bound(d, d.max);
  range += ']';
  return with_unit(std::move(range), d.unit);
}

std::optional<std::string> real_problem(const FieldDescriptor& d, double v) {
  if (!std::isfinite(v)) return "is not a finite number; allowed range " + allowed_text(d);
  if (v < d.min || v > d.max) return "is out of range " + allowed_text(d);
  return std::nullopt;
}

std::optional<std::string> integer_problem(const FieldDescriptor& d, long long v) {
  // Bounds are whole and |bound| <= 2^31, so comparing in long long is exact.
  if (v < static_cast<long long>(d.min) || v > static_cast<long long>(d.max))
    return "is out of range " + allowed_text(d);
  return std::nullopt;
}

std::optional<std::string> text_problem(const FieldDescriptor& d, std::string_view v) {
  if (d.check) {
    std::string why = d.check(v);
    if (why.empty()) return std::nullopt;
    return why;
  }
  for (auto c : d.choices)
    if (c == v) return std::nullopt;
  return "is not a known value; allowed: " + allowed_text(d);
}

void fail(const Source& src, const std::string& key, const std::string& body, std::size_t line) {
  std::string msg = src.is_file ? "config '" + one_line(src.name) + "': " : one_line(src.name) + ": ";
  msg += body;
  if (line > 0) msg += " (line " + std::to_string(line) + ")";
  // Belt and braces: callers escape what they insert, but the message must stay one line.
  for (char& c : msg)
    if (c == '\n' || c == '\r') c = ' ';
  throw ConfigError(src.name, key, msg);
}

void validate_as(const Settings& s, const Source& src) {
  for (const auto& d : kFields) {
    const std::string key = qualified(d);
    std::visit(
        [&](auto* p) {
          using T = std::remove_cvref_t<decltype(*p)>;
          if constexpr (std::is_same_v<T, double>) {
            if (auto why = real_problem(d, *p)) fail(src, key, key + " = " + format_real(*p) + " " + *why);
          } else if constexpr (std::is_same_v<T, std::string>) {
            if (auto why = text_problem(d, *p)) fail(src, key, key + " = \"" + one_line(*p, 80) + "\" " + *why);
          } else {
            if (auto why = integer_problem(d, static_cast<long long>(*p)))
              fail(src, key, key + " = " + std::to_string(*p) + " " + *why);
          }
        },
        d.cref(s));
  }
  // Cross-field rules.
  if (s.haptics.level > s.haptics.max_levels)
    fail(src, "haptics.level",
         "haptics.level = " + std::to_string(s.haptics.level) + " must be <= haptics.max_levels = " +
             std::to_string(s.haptics.max_levels) + " (only levels 0..max_levels are built)");
  if (s.vision.canny_low != 0.0 && s.vision.canny_high != 0.0 && s.vision.canny_low > s.vision.canny_high)
    fail(src, "vision.canny_low",
         "vision.canny_low = " + format_real(s.vision.canny_low) +
             " must be <= vision.canny_high = " + format_real(s.vision.canny_high) + " when both are nonzero");
  if (s.haptics.dynamic_friction > s.haptics.static_friction)
    fail(src, "haptics.dynamic_friction",
         "haptics.dynamic_friction = " + format_real(s.haptics.dynamic_friction) +
             " must be <= haptics.static_friction = " + format_real(s.haptics.static_friction) +
             " (a wall that holds less at rest than while sliding would chatter)");
  // What the device of [device] type can give and render stably (device_profile.hpp).
  {
    std::string key;
    const std::string why = profile_problem(s, s.device.type, &key);
    if (!why.empty()) fail(src, key, why);
  }
  if (s.haptics.pop_force_n > 0.0 && s.haptics.tour_max_force_n >= s.haptics.pop_force_n)
    fail(src, "haptics.tour_max_force_n",
         "haptics.tour_max_force_n = " + format_real(s.haptics.tour_max_force_n) + " must be < haptics.pop_force_n = " +
             format_real(s.haptics.pop_force_n) + " (the guided tour must not push the hand through a wall)");
  // The USB pantograph's board: two actuators on two ports, two encoders on two ports (hAPI masks one bit
  // per port), and links that can close the five-bar (2·L must span the motor spacing).
  if (s.device.actuator1_port == s.device.actuator2_port)
    fail(src, "device.actuator1_port",
         "device.actuator1_port = " + std::to_string(s.device.actuator1_port) +
             " is also device.actuator2_port; each actuator needs its own board port");
  if (s.device.encoder1_port == s.device.encoder2_port)
    fail(src, "device.encoder1_port",
         "device.encoder1_port = " + std::to_string(s.device.encoder1_port) +
             " is also device.encoder2_port; each encoder needs its own board port");
  if (s.device.motor_spacing_m >= 2.0 * (s.device.link_proximal_m + s.device.link_distal_m))
    fail(src, "device.motor_spacing_m",
         "device.motor_spacing_m = " + format_real(s.device.motor_spacing_m) +
             " must be < 2 * (device.link_proximal_m + device.link_distal_m) or the links cannot meet");
  {
    const std::vector<std::string> offered = language_list(s.kiosk.languages);
    if (!offered.empty() && std::find(offered.begin(), offered.end(), s.kiosk.language) == offered.end())
      fail(src, "kiosk.language",
           "kiosk.language = \"" + one_line(s.kiosk.language, 40) + "\" must be one of kiosk.languages = \"" +
               one_line(s.kiosk.languages, 80) + "\"");
  }
  // Each visitor action on its own key: one key cannot do two things, and the help names each action's key.
  // The first pair in table order is reported, attributed to the earlier key and naming the later.
  {
    const auto keys = key_actions(s.keys);
    for (std::size_t i = 0; i < keys.size(); ++i)
      for (std::size_t j = i + 1; j < keys.size(); ++j)
        if (keys[i].second == keys[j].second) {
          const std::string earlier = "keys." + std::string(keys[i].first);
          fail(src, earlier,
               earlier + " = \"" + one_line(keys[i].second, 80) + "\" is also keys." + std::string(keys[j].first) +
                   "; each action needs its own key");
        }
  }
}

}  // namespace detail

std::vector<UsbId> parse_usb_ids(std::string_view text, std::string* why) {
  auto fail = [&](const char* what) {
    if (why) *why = what;
    return std::vector<UsbId>{};
  };
  auto hex4 = [](std::string_view h, std::uint16_t* out) {
    if (h.size() != 4) return false;
    unsigned v = 0;
    for (char c : h) {
      const int d = c >= '0' && c <= '9'   ? c - '0'
                    : c >= 'a' && c <= 'f' ? c - 'a' + 10
                    : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                           : -1;
      if (d < 0) return false;
      v = v * 16 + static_cast<unsigned>(d);
    }
    *out = static_cast<std::uint16_t>(v);
    return true;
  };
  constexpr std::size_t kMaxIds = 16;
  std::vector<UsbId> ids;
  std::size_t at = 0;
  while (at <= text.size()) {
    std::size_t comma = text.find(',', at);
    if (comma == std::string_view::npos) comma = text.size();
    std::string_view item = text.substr(at, comma - at);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    UsbId id;
    if (item.size() != 9 || item[4] != ':' || !hex4(item.substr(0, 4), &id.vid) || !hex4(item.substr(5, 4), &id.pid))
      return fail(
          "must be USB ids \"VVVV:PPPP\" (four hex digits each), comma-separated, e.g. \"2341:804d,2341:003e\"");
    ids.push_back(id);
    if (ids.size() > kMaxIds) return fail("holds more than 16 USB ids");
    at = comma + 1;
  }
  return ids;
}

std::optional<QuietHours> parse_quiet_hours(std::string_view t, std::string* why) {
  auto fail = [&](const char* what) -> std::optional<QuietHours> {
    if (why) *why = what;
    return std::nullopt;
  };
  if (t.empty()) return std::nullopt;
  auto digit = [](char c) { return c >= '0' && c <= '9'; };
  auto minute = [&](std::string_view hm) -> int {  // "HH:MM" → minutes, −1 when malformed
    if (hm.size() != 5 || hm[2] != ':' || !digit(hm[0]) || !digit(hm[1]) || !digit(hm[3]) || !digit(hm[4])) return -1;
    const int h = (hm[0] - '0') * 10 + (hm[1] - '0'), m = (hm[3] - '0') * 10 + (hm[4] - '0');
    return h < 24 && m < 60 ? h * 60 + m : -1;
  };
  if (t.size() != 11 || t[5] != '-') return fail("must be two times \"HH:MM-HH:MM\", e.g. \"22:00-07:00\"");
  const int from = minute(t.substr(0, 5)), to = minute(t.substr(6, 5));
  if (from < 0 || to < 0) return fail("holds a time outside 00:00 to 23:59");
  if (from == to) return fail("starts and ends at the same time");
  return QuietHours{from, to};
}

void validate(const Settings& settings) { detail::validate_as(settings, {"settings", false}); }

}  // namespace hk::config
