// The museum's settings over the staff's (fleet_settings.hpp).
#include "visit/fleet_settings.hpp"

#include <toml++/toml.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <variant>

#include "config/load.hpp"

namespace hk::app {
namespace {

/// Sets field `d` of `to` to its value in `from`.
void copy_field(const config::FieldDescriptor& d, const config::Settings& from, config::Settings& to) {
  std::visit(
      [&](auto* dst) {
        using T = std::remove_pointer_t<decltype(dst)>;
        *dst = *std::get<const T*>(d.cref(from));
      },
      d.ref(to));
}

const config::FieldDescriptor* field_of(const std::string& key) {
  const std::size_t dot = key.find('.');
  if (dot == std::string::npos) return nullptr;
  return config::find_field(std::string_view(key).substr(0, dot), std::string_view(key).substr(dot + 1));
}

}  // namespace

std::string fleet_path_for(const std::string& settings_path) {
  if (settings_path.empty()) return {};
  return (std::filesystem::path(settings_path).parent_path() / kFleetFileName).string();
}

std::optional<FleetSettings> load_fleet(const std::string& path) {
  std::error_code ec;
  if (path.empty() || !std::filesystem::exists(path, ec)) return std::nullopt;
  FleetSettings f;
  f.path = path;
  f.values = config::load_settings(path);  // every check a settings file gets, the file's own errors named
  // Which keys it names: the loader took them all, so the text parses.
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  const toml::table root = toml::parse(text.str(), path);
  for (const config::FieldDescriptor& d : config::field_descriptors()) {
    const toml::table* t = root[d.table].as_table();
    if (!t || !t->contains(d.key)) continue;
    const std::string key = std::string(d.table) + "." + std::string(d.key);
    if (key == "operator.pin_hash")
      throw config::ConfigError(path, key,
                                path +
                                    ": operator.pin_hash is not the museum's to set here; the PIN's hash goes into "
                                    "settings.toml ('haptic-kiosk pin set-hash')");
    f.keys.push_back(key);
  }
  return f;
}

config::Settings with_fleet(const config::Settings& own, const FleetSettings& fleet) {
  config::Settings s = own;
  for (const std::string& key : fleet.keys)
    if (const config::FieldDescriptor* d = field_of(key)) copy_field(*d, fleet.values, s);
  try {
    config::validate(s);
  } catch (const config::ConfigError& e) {
    throw config::ConfigError(fleet.path, e.key(),
                              fleet.path + ": with settings.toml it does not hold: " + std::string(e.what()));
  }
  return s;
}

config::Settings keep_own(const config::Settings& s, const config::Settings& own,
                          const std::vector<std::string>& keys) {
  config::Settings out = s;
  for (const std::string& key : keys)
    if (const config::FieldDescriptor* d = field_of(key)) copy_field(*d, own, out);
  return out;
}

}  // namespace hk::app
