#pragma once
/// @file picture_library.hpp
/// The pictures a visitor can feel: the tutorial shapes, made here, and the image files
/// of a library folder (PNG, JPEG, BMP, TIFF, WebP; sorted by name; shipped: data/pictures).

#include <string>
#include <vector>

#include "haptics/multires.hpp"
#include "hk/vec2.hpp"

namespace hk::app {

/// Tutorial shapes, in order.
enum class TutorialShape { Square = 0, Circle = 1, Triangle = 2 };

/// The tutorial shape as one closed polyline in workspace metres, centred, about half the workspace high.
Polyline tutorial_polyline(TutorialShape shape, Vec2 half_extent_m);

/// Image files of `folder`, sorted by name. @throws AppError (one line) if the folder cannot be
/// read or holds no image.
std::vector<std::string> list_pictures(const std::string& folder);

}  // namespace hk::app
