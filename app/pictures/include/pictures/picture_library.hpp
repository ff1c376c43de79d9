#pragma once
/// @file picture_library.hpp
/// The pictures a visitor can feel: the tutorial shapes, made here, and the image files
/// of a library folder (PNG, JPEG, BMP, TIFF, WebP; sorted by name; shipped: data/pictures).

#include <string>
#include <vector>

#include "config/settings.hpp"
#include "haptics/multires.hpp"
#include "hk/vec2.hpp"

namespace hk::app {

/// Tutorial shapes, in order.
enum class TutorialShape { Square = 0, Circle = 1, Triangle = 2 };

/// The tutorial shape as one closed polyline in workspace metres, centred, about half the workspace high.
Polyline tutorial_polyline(TutorialShape shape, Vec2 half_extent_m);

/// How long a picture's files must be unchanged before the library watched takes it [s] (library_watch.hpp).
inline constexpr double kLibrarySettle_s = 2.0;

/// The library folder of [kiosk] library: "auto" → $STATE_DIRECTORY/library under the service (systemd's
/// StateDirectory=; its first entry when colon-separated), else "" (the shipped pictures); an absolute folder →
/// itself. Reads the environment at each call; never throws but std::bad_alloc.
std::string library_dir(const config::Settings& s);

/// Whether a file named `name` (no directory) is a picture of a library: a PNG, JPEG, BMP, TIFF or WebP by its
/// extension (any case), not hidden (a name starting with '.', such as a sync tool's temporary file).
bool is_picture_name(const std::string& name);

/// Image files of `folder` (is_picture_name), sorted by name. @throws AppError (one line) if the folder cannot be
/// read or holds no image.
std::vector<std::string> list_pictures(const std::string& folder);

}  // namespace hk::app
