// Folder settings resolved (kiosk_folders.hpp).
#include "pictures/kiosk_folders.hpp"

#include <cstdlib>

namespace hk::app {

std::string kiosk_folder(const std::string& setting, const char* service_env, const char* xdg_env,
                         const char* home_base, const char* leaf) {
  if (setting == "off") return "";
  if (setting != "auto") return setting;
  auto absolute = [](const char* name) -> std::string {
    const char* e = std::getenv(name);
    if (e == nullptr || e[0] != '/') return "";
    return e;
  };
  const std::string service = absolute(service_env);
  if (!service.empty()) return service.substr(0, service.find(':')) + "/" + leaf;
  const std::string xdg = absolute(xdg_env);
  if (!xdg.empty()) return xdg + "/haptic-kiosk/" + leaf;
  const std::string home = absolute("HOME");
  if (!home.empty()) return home + "/" + home_base + "/haptic-kiosk/" + leaf;
  return "";
}

}  // namespace hk::app
