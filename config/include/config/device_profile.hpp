#pragma once
/// @file device_profile.hpp
/// Device profiles: what each kind of handle can give, and the settings it brings ([device] type picks
/// one; DESIGN.md "Devices").
///
/// | [device] type | device | everywhere | max_force_n | pop_force_n | tour_max_force_n | groove_depth_n | stiffness |
/// |---|---|---|---|---|---|---|---|
/// | "simulated", "auto" | simulated pantograph | 3.78 N | 3.5 N | 3.0 N | 1.2 N | 1.0 N | 800 (3000; 3784) N/m |
/// | "haply" | Haply 2DIY gen3 | 1.65 N | 1.5 N | 1.2 N | 0.5 N | 0.45 N | 500 (850; 1103) N/m |
/// | "haply-gen2" | the original Haply 2DIY | 1.60 N | 1.45 N | 1.15 N | 0.5 N | 0.45 N | 500 (850; 1129) N/m |
///
/// Stiffness: stiffness_n_per_m's default (its limit; stable to). Force everywhere: the least force the handle gives in
/// every direction at every point of its usable rectangle with its torque limit (pantograph.hpp
/// `min_force_everywhere_n`; computed from the settings by `force_everywhere_n`, the table shows the shipped values).
/// max_force_n is about 0.9 of it, the push-through force 0.8 of max_force_n, the tour's pull and the groove's depth
/// about a third; the force step of a level change or a live change scales with max_force_n. The stiffness limit is the
/// largest wall stiffness the servo loop renders stably on the device's model (mass, damping, encoder quantisation, and
/// for a USB board one tick of delay; `bench_stability --profiles`, docs/PERFORMANCE.md "Device profiles") with a
/// margin, at 1000 Hz; at other servo rates it scales with the rate (the sampled-data bound 2b/T is proportional to
/// it).
///
/// Sources of the Haply boards: HaplyHaptics' hAPI examples (`add_actuator`, `add_encoder` for
/// hardwareVersion 2 and 3: ports, directions, home offsets, encoder resolutions) and Pantograph.java
/// (link lengths l = 0.07 m, L = 0.09 m; motor spacing d = 0 for version 2, 0.038 m for version 3);
/// the torque limit is the M0 firmware's MAX_TORQUE (Haply_M0_Firmware_V0_3), 0.123 N·m.
///
/// "auto" loads with the simulated profile; when the kiosk takes a USB board, `fit_to_profile` moves
/// the settings into the board's profile.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/settings.hpp"

namespace hk::config {

/// One device profile. Values are the shipped ones; see the table in the file comment.
struct DeviceProfile {
  std::string_view type;            ///< the [device] type that picks it: "simulated", "haply", "haply-gen2"
  std::string_view name;            ///< for people: "Haply 2DIY gen3"
  double stable_stiffness_n_per_m;  ///< largest stiffness allowed at a 1000 Hz servo rate [N/m]
  double max_force_n;               ///< the force budget it brings: [haptics] max_force_n [N]
  double pop_force_n;               ///< [haptics] pop_force_n [N]
  double tour_max_force_n;          ///< [haptics] tour_max_force_n [N]
  double groove_depth_n;            ///< [haptics] groove_depth_n [N]
  double level_max_force_step_n;    ///< [haptics] level_max_force_step_n [N per tick]
  double stiffness_n_per_m;         ///< [haptics] stiffness_n_per_m [N/m]
};

/// Every profile, simulated first.
const std::vector<DeviceProfile>& device_profiles();

/// The profile a [device] type picks: "auto" and "simulated" → the simulated pantograph; "haply" → Haply
/// 2DIY gen3; "haply-gen2" → the original 2DIY. Anything else → the simulated pantograph.
const DeviceProfile& device_profile(std::string_view type) noexcept;

/// True when `type` drives a USB board ("haply", "haply-gen2").
bool is_usb_type(std::string_view type) noexcept;

/// The shipped settings with `type`'s profile in: its force budget ([haptics] stiffness_n_per_m,
/// max_force_n, pop_force_n, tour_max_force_n, groove_depth_n, level_max_force_step_n) and, for a Haply,
/// its board ([device] link lengths, motor spacing, ports, directions, encoder offsets and resolutions,
/// torque limit, rectangle) with the park place at the board's home pose (the pose its encoder offsets
/// name, by forward kinematics). [device] type = `type`. An unknown type gives the shipped settings.
Settings profile_defaults(std::string_view type);

/// The force the device of `s`, taken as `type`, gives in every direction everywhere in its usable
/// rectangle [N]: the simulated pantograph's geometry over [workspace] with [device] max_torque_n_m, or a
/// Haply's links over [device] rect_* with torque_limit_n_m. 0 when the rectangle is out of reach.
double force_everywhere_n(const Settings& s, std::string_view type);

/// The stiffness limit of `type`'s profile at `servo_rate_hz` [N/m]: the profile's limit × rate / 1000 Hz
/// (the sampled-data bound 2b/T is proportional to the rate).
double stiffness_limit_n_per_m(std::string_view type, double servo_rate_hz) noexcept;

/// The park place [m, workspace frame] of the home pose the encoder offsets of `s` name (forward
/// kinematics of the Haply links, then the device rectangle mapped onto [workspace]); false when the links
/// cannot meet there.
bool home_park_place(const Settings& s, double* x_m, double* y_m);

/// Why `s` asks more of `type`'s device than its profile allows, as "<table.key> = <value> <why>" naming
/// the limit; empty when it does not. Checked: max_force_n ≤ the force everywhere (not when the rectangle
/// is out of the links' reach: the device refuses that when opened); stiffness_n_per_m ≤ the
/// stiffness limit; pop_force_n, tour_max_force_n and groove_depth_n ≤ max_force_n. The key is written to
/// `*key` when not null.
std::string profile_problem(const Settings& s, std::string_view type, std::string* key = nullptr);

/// What the profile in force allows for one field, as the operator's panel shows it beside the field (in the
/// staff's words: "at most 1.65 N (what the Haply 2DIY gen3 gives everywhere)").
struct ProfileLimit {
  enum class Kind {
    force_everywhere,  ///< haptics.max_force_n: at most `value` [N], what `device` gives everywhere in its rectangle
    stable_stiffness,  ///< haptics.stiffness_n_per_m: at most `value` [N/m], stable on `device` at `servo_rate_hz`
    within_max_force,  ///< pop_force_n, tour_max_force_n, groove_depth_n: at most haptics.max_force_n = `value` [N]
  };
  Kind kind = Kind::force_everywhere;
  double value = 0;          ///< the limit [N] or [N/m]
  std::string device;        ///< the profile's device name ("Haply 2DIY gen3")
  double servo_rate_hz = 0;  ///< the servo rate the stiffness limit holds at [Hz]
};

/// The limit the profile of `type`'s device sets on field `table.key` with settings `s`; none for fields the
/// profile does not bound.
std::optional<ProfileLimit> profile_limit(const Settings& s, std::string_view type, std::string_view table,
                                          std::string_view key);

/// The settings a kiosk in "auto" runs with once it has taken a board of `type`: every force-budget field
/// still at the simulated profile's value takes `type`'s (the operator never chose it), and a field the
/// profile refuses takes `type`'s value too; one line per refused field is appended to `notes`, naming the
/// limit. [device] type stays as it was.
Settings fit_to_profile(const Settings& s, std::string_view type, std::vector<std::string>* notes);

}  // namespace hk::config
