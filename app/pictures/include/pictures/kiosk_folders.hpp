#pragma once
/// @file kiosk_folders.hpp
/// Folders the kiosk keeps its own files in ([kiosk] scene_cache, names_dir), resolved from their settings the one
/// way: under the service the folder systemd gives it, else the XDG base directory, else one under $HOME.

#include <string>

namespace hk::app {

/// A folder setting resolved to an absolute path (no trailing slash added):
///   "off" → "" (none);
///   "auto" → $`service_env` + "/" + `leaf` (systemd's CacheDirectory= or StateDirectory=; its first entry when
///            colon-separated), else $`xdg_env` + "/haptic-kiosk/" + `leaf`, else $HOME + "/" + `home_base` +
///            "/haptic-kiosk/" + `leaf`, else "" (environment values that are empty or not absolute are skipped, as
///            XDG asks);
///   an absolute folder → itself (validate() allows nothing else).
/// Never throws but std::bad_alloc; reads the environment at each call.
std::string kiosk_folder(const std::string& setting, const char* service_env, const char* xdg_env,
                         const char* home_base, const char* leaf);

}  // namespace hk::app
