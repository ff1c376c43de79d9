#pragma once
/// @file fleet_settings.hpp
/// Who owns which setting when a museum rolls its settings out to many kiosks:
///
/// | file (beside each other in /etc/haptic-kiosk) | written by | holds |
/// |---|---|---|
/// | `fleet.toml` | the roll-out (deploy/ansible), never the kiosk | the settings the museum manages, in the settings'
/// own tables and keys | | `settings.toml` | the operator's panel (and `haptic-kiosk pin`) | everything else: the
/// staff's; the PIN's hash |
///
/// The kiosk runs with settings.toml, then fleet.toml's keys over it. The panel shows the museum's fields locked
/// ("set by the museum") and never writes their values into settings.toml, so a roll-out never reverts what staff
/// changed, and staff never undo the museum's choice by accident. A fleet file that does not load, or that together
/// with settings.toml does not validate, is refused whole (logged, said in the panel): the kiosk runs on its own.
/// The PIN is not a fleet key: its hash goes into settings.toml (`haptic-kiosk pin set-hash`), where the lockout
/// reads it.

#include <optional>
#include <string>
#include <vector>

#include "config/settings.hpp"

namespace hk::app {

/// The fleet file's name beside the settings file.
inline constexpr const char* kFleetFileName = "fleet.toml";

/// A fleet file as loaded.
struct FleetSettings {
  std::string path;               ///< the file
  std::vector<std::string> keys;  ///< "table.key" of each setting it names, in field order
  config::Settings values;        ///< its values over the defaults (only `keys` are the museum's)
};

/// The fleet file beside `settings_path` (same folder, kFleetFileName); "" when `settings_path` is empty.
std::string fleet_path_for(const std::string& settings_path);

/// Loads the fleet file at `path`; nullopt when there is no such file.
/// @throws config::ConfigError (one line naming the file) when it does not load as a settings file would (syntax,
/// unknown key, wrong type, out of range), or names [operator] pin_hash.
std::optional<FleetSettings> load_fleet(const std::string& path);

/// `own` with the fleet's keys set to the fleet's values.
/// @throws config::ConfigError (one line naming the fleet file) when the result does not validate (a rule across
/// two fields, one from each file).
config::Settings with_fleet(const config::Settings& own, const FleetSettings& fleet);

/// `s` with each of `keys` ("table.key") set to its value in `own` (what settings.toml keeps for a field the
/// museum manages). Unknown keys are passed over.
config::Settings keep_own(const config::Settings& s, const config::Settings& own, const std::vector<std::string>& keys);

}  // namespace hk::app
