#include "pictures/picture_library.hpp"
#include "formats/app_error.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace hk::app {

Polyline tutorial_polyline(TutorialShape shape, Vec2 half) {
  const double r = 0.5 * std::min(half.x, half.y);  // half the height: room to slide round it
  Polyline p;
  p.closed = true;
  switch (shape) {
    case TutorialShape::Square:
      p.points_m = {{-r, -r}, {r, -r}, {r, r}, {-r, r}};
      break;
    case TutorialShape::Circle:
      for (int k = 0; k < 96; ++k) {
        const double a = 2 * M_PI * k / 96;
        p.points_m.push_back({r * std::cos(a), r * std::sin(a)});
      }
      break;
    case TutorialShape::Triangle:
      for (int k = 0; k < 3; ++k) {
        const double a = M_PI / 2 + 2 * M_PI * k / 3;
        p.points_m.push_back({1.2 * r * std::cos(a), 1.2 * r * std::sin(a) - 0.2 * r});
      }
      break;
  }
  return p;
}

std::string library_dir(const config::Settings& s) {
  if (s.kiosk.library != "auto") return s.kiosk.library;
  const char* env = std::getenv("STATE_DIRECTORY");
  if (!env || env[0] != '/') return {};
  const std::string first(env, std::strcspn(env, ":"));
  return first + "/library";
}

bool is_picture_name(const std::string& name) {
  if (name.empty() || name[0] == '.') return false;
  std::string ext = std::filesystem::path(name).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" || ext == ".tiff" ||
         ext == ".webp";
}

std::vector<std::string> list_pictures(const std::string& folder) {
  std::error_code ec;
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(folder, ec))
    if (is_picture_name(e.path().filename().string())) out.push_back(e.path().string());
  if (ec) throw AppError("picture library '" + folder + "': cannot read the folder (" + ec.message() + ")");
  if (out.empty()) throw AppError("picture library '" + folder + "': holds no picture (png, jpg, bmp, tif, webp)");
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace hk::app
