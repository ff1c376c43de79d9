#include "cli/stick_command.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>

#include "config/load.hpp"
#include "formats/app_error.hpp"
#include "pictures/documents.hpp"
#include "sticks/usb_stick.hpp"

namespace hk::app {
namespace {

void write_atomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << text;
    f.close();
    if (!f) {
      std::filesystem::remove(tmp);
      throw AppError("--json '" + path + "': cannot write the file");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp);
    throw AppError("--json '" + path + "': cannot write the file (" + ec.message() + ")");
  }
}

}  // namespace

int run_stick(const StickOptions& o) {
  if (o.folder.empty() == o.device.empty()) throw AppError("stick: give exactly one of a folder or --device DEV");
  const config::Settings s = o.config_path.empty() ? config::Settings{} : config::load_settings(o.config_path);
  if (!o.json_path.empty()) {  // refuse a bad output before mounting anything
    const std::filesystem::path p(o.json_path);
    const auto parent = p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
    if (!std::filesystem::is_directory(parent))
      throw AppError("--json '" + o.json_path + "': folder '" + parent.string() + "' does not exist");
  }
  std::optional<sticks::MountedStick> mounted;
  std::string root = o.folder;
  if (!o.device.empty()) {
    mounted.emplace(o.device, o.mount_root.empty() ? std::string(sticks::kDefaultStickMountRoot) : o.mount_root, 0);
    root = mounted->mount_point();
  }
  const StickListing listing = list_stick(root, s);
  nlohmann::json j = stick_listing_json(listing);
  if (mounted) {
    j["device"] = {{"devnode", o.device}, {"filesystem", mounted->filesystem()}};
    mounted->unmount();
  }
  const std::string text = j.dump(2) + "\n";
  if (o.json_path.empty()) {
    std::fputs(text.c_str(), stdout);
  } else {
    write_atomically(o.json_path, text);
    std::printf("stick: %zu documents (%d pictures, %d PDFs), %zu refused%s -> %s\n", listing.documents.size(),
                listing.pictures(), listing.pdfs(), listing.refused.size(),
                listing.scan.complete ? "" : " (stopped by a limit)", o.json_path.c_str());
  }
  return 0;
}

}  // namespace hk::app
