/// @file device_profile.cpp
/// The device profiles and the settings they bring. See device_profile.hpp.

#include "config/device_profile.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "detail.hpp"
#include "kinematics/haply_mechanism.hpp"
#include "kinematics/pantograph.hpp"

namespace hk::config {
namespace {

constexpr double kProfileRateHz = 1000.0;  // the rate the stiffness limits were measured at [Hz]

// N_ marks a device's name for the operator panel's catalogue (xgettext --keyword=N_), where it is looked up.
#define N_(text) text

const std::vector<DeviceProfile> kProfiles = {
    //  type          name                          stable K  max F  pop   tour  groove step  K
    {"simulated", N_("simulated pantograph"), 3000.0, 3.5, 3.0, 1.2, 1.0, 0.05, 800.0},
    {"haply", "Haply 2DIY gen3", 850.0, 1.5, 1.2, 0.5, 0.45, 0.02, 500.0},
    {"haply-gen2", N_("original Haply 2DIY"), 850.0, 1.45, 1.15, 0.5, 0.45, 0.02, 500.0},
};

/// The original 2DIY's board in [device] (hAPI examples, hardwareVersion 2; Pantograph.java: coaxial
/// motors). The shipped [device] defaults are the gen3's, so it needs nothing.
void set_gen2_board(DeviceSettings& d) {
  d.motor_spacing_m = 0.0;
  d.actuator1_port = 2;
  d.actuator1_dir = "ccw";
  d.actuator2_port = 1;
  d.actuator2_dir = "cw";
  d.encoder1_port = 2;
  d.encoder1_dir = "ccw";
  d.encoder1_offset_deg = 241.0;
  d.encoder1_resolution = 10752.0;
  d.encoder2_port = 1;
  d.encoder2_dir = "cw";
  d.encoder2_offset_deg = -61.0;
  d.encoder2_resolution = 10752.0;
}

std::string newtons(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f N", v);
  return b;
}

}  // namespace

const std::vector<DeviceProfile>& device_profiles() { return kProfiles; }

const DeviceProfile& device_profile(std::string_view type) noexcept {
  for (const DeviceProfile& p : kProfiles)
    if (p.type == type) return p;
  return kProfiles.front();
}

bool is_usb_type(std::string_view type) noexcept { return type == "haply" || type == "haply-gen2"; }

Settings profile_defaults(std::string_view type) {
  Settings s;
  bool known = type == "auto";
  for (const DeviceProfile& p : kProfiles) known = known || p.type == type;
  if (!known) return s;
  s.device.type = std::string(type);
  const DeviceProfile& p = device_profile(type);
  s.haptics.stiffness_n_per_m = p.stiffness_n_per_m;
  s.haptics.max_force_n = p.max_force_n;
  s.haptics.pop_force_n = p.pop_force_n;
  s.haptics.tour_max_force_n = p.tour_max_force_n;
  s.haptics.groove_depth_n = p.groove_depth_n;
  s.haptics.level_max_force_step_n = p.level_max_force_step_n;
  if (type == "haply-gen2") {
    set_gen2_board(s.device);
    home_park_place(s, &s.device.park_x_m, &s.device.park_y_m);
  }
  return s;
}

double force_everywhere_n(const Settings& s, std::string_view type) {
  if (!is_usb_type(type)) {
    const PantographGeometry g;  // the simulated pantograph's (sim_pantograph.hpp takes the default geometry)
    return min_force_everywhere_n(g, {0.0, 0.0}, {s.workspace.width_m, s.workspace.height_m}, s.device.max_torque_n_m);
  }
  hapi::HaplyMechanism m;
  m.proximal_m = s.device.link_proximal_m;
  m.distal_m = s.device.link_distal_m;
  m.motor_spacing_m = s.device.motor_spacing_m;
  return min_force_everywhere_n(hapi::geometry_of(m), {0.0, s.device.rect_center_y_m},
                                {s.device.rect_width_m, s.device.rect_height_m}, s.device.torque_limit_n_m);
}

double stiffness_limit_n_per_m(std::string_view type, double servo_rate_hz) noexcept {
  return device_profile(type).stable_stiffness_n_per_m * std::max(0.0, servo_rate_hz) / kProfileRateHz;
}

bool home_park_place(const Settings& s, double* x_m, double* y_m) {
  hapi::HaplyMechanism m;
  m.proximal_m = s.device.link_proximal_m;
  m.distal_m = s.device.link_distal_m;
  m.motor_spacing_m = s.device.motor_spacing_m;
  Vec2 home;
  if (!forward_kinematics(hapi::geometry_of(m),
                          hapi::joints_from_haply_deg(s.device.encoder1_offset_deg, s.device.encoder2_offset_deg),
                          &home))
    return false;
  const double scale =
      std::min(s.workspace.width_m / s.device.rect_width_m, s.workspace.height_m / s.device.rect_height_m);
  *x_m = scale * home.x;
  *y_m = scale * (home.y - s.device.rect_center_y_m);
  return true;
}

std::string profile_problem(const Settings& s, std::string_view type, std::string* key) {
  const DeviceProfile& p = device_profile(type);
  const auto problem = [&](const char* k, double v, const std::string& why) {
    if (key) *key = k;
    return std::string(k) + " = " + detail::format_real(v) + " " + why;
  };
  const HapticsSettings& h = s.haptics;
  const double everywhere = force_everywhere_n(s, type);
  // A rectangle the links cannot reach gives 0: the device refuses it when it is opened, with its own message.
  if (everywhere > 0.0 && h.max_force_n > everywhere + 1e-9)
    return problem(
        "haptics.max_force_n", h.max_force_n,
        "is more than the " + std::string(p.name) + " gives everywhere in its rectangle (" + newtons(everywhere) + ")");
  const double k_max = stiffness_limit_n_per_m(type, h.servo_rate_hz);
  if (h.stiffness_n_per_m > k_max + 1e-9) {
    char b[64];
    std::snprintf(b, sizeof b, "%.0f N/m at %.0f Hz", k_max, h.servo_rate_hz);
    return problem("haptics.stiffness_n_per_m", h.stiffness_n_per_m,
                   "is above the stable limit of the " + std::string(p.name) + " (" + b + ")");
  }
  const std::string within = "must be <= haptics.max_force_n = " + detail::format_real(h.max_force_n);
  if (h.pop_force_n > h.max_force_n)
    return problem("haptics.pop_force_n", h.pop_force_n, within + " (no visitor could push through a wall)");
  if (h.tour_max_force_n > h.max_force_n) return problem("haptics.tour_max_force_n", h.tour_max_force_n, within);
  if (h.groove_depth_n > h.max_force_n) return problem("haptics.groove_depth_n", h.groove_depth_n, within);
  return {};
}

std::optional<ProfileLimit> profile_limit(const Settings& s, std::string_view type, std::string_view table,
                                          std::string_view key) {
  if (table != "haptics") return std::nullopt;
  const std::string device(device_profile(type).name);
  const double rate_hz = s.haptics.servo_rate_hz;
  if (key == "max_force_n")
    return ProfileLimit{ProfileLimit::Kind::force_everywhere, force_everywhere_n(s, type), device, rate_hz};
  if (key == "stiffness_n_per_m")
    return ProfileLimit{ProfileLimit::Kind::stable_stiffness, stiffness_limit_n_per_m(type, rate_hz), device, rate_hz};
  if (key == "pop_force_n" || key == "tour_max_force_n" || key == "groove_depth_n")
    return ProfileLimit{ProfileLimit::Kind::within_max_force, s.haptics.max_force_n, device, rate_hz};
  return std::nullopt;
}

Settings fit_to_profile(const Settings& s, std::string_view type, std::vector<std::string>* notes) {
  const DeviceProfile& from = device_profile("simulated");
  const DeviceProfile& to = device_profile(type);
  Settings out = s;
  HapticsSettings& h = out.haptics;
  const struct {
    double* field;
    double sim, dev;
  } budget[] = {{&h.stiffness_n_per_m, from.stiffness_n_per_m, to.stiffness_n_per_m},
                {&h.max_force_n, from.max_force_n, to.max_force_n},
                {&h.pop_force_n, from.pop_force_n, to.pop_force_n},
                {&h.tour_max_force_n, from.tour_max_force_n, to.tour_max_force_n},
                {&h.groove_depth_n, from.groove_depth_n, to.groove_depth_n},
                {&h.level_max_force_step_n, from.level_max_force_step_n, to.level_max_force_step_n}};
  for (const auto& b : budget)
    if (*b.field == b.sim) *b.field = b.dev;
  // What the operator chose and the profile refuses: the profile's value, said once per field.
  for (int guard = 0; guard < 8; ++guard) {
    std::string key;
    const std::string why = profile_problem(out, type, &key);
    if (why.empty()) break;
    if (notes) notes->push_back(why + "; " + std::string(to.name) + " uses its own value");
    const std::string_view k = std::string_view(key).substr(std::string_view("haptics.").size());
    if (k == "max_force_n")
      h.max_force_n = to.max_force_n;
    else if (k == "stiffness_n_per_m")
      h.stiffness_n_per_m = std::min(to.stiffness_n_per_m, stiffness_limit_n_per_m(type, h.servo_rate_hz));
    else if (k == "pop_force_n")
      h.pop_force_n = std::min(to.pop_force_n, h.max_force_n);
    else if (k == "tour_max_force_n")
      h.tour_max_force_n = std::min(to.tour_max_force_n, h.max_force_n);
    else if (k == "groove_depth_n")
      h.groove_depth_n = std::min(to.groove_depth_n, h.max_force_n);
  }
  // The tour stays below the push-through force (validate's cross-field rule).
  if (h.pop_force_n > 0.0 && h.tour_max_force_n >= h.pop_force_n)
    h.tour_max_force_n = std::min(to.tour_max_force_n, 0.5 * h.pop_force_n);
  return out;
}

}  // namespace hk::config
