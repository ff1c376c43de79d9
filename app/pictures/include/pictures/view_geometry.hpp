#pragma once
/// @file view_geometry.hpp
/// Where the workspace lands on the kiosk's screen, without OpenGL (the window draws with it, view.hpp; the
/// runtime and the benchmarks size pictures with it).
///
/// View mapping (tests rely on it; kiosk_app.hpp documents it): workspace metres → window pixels with one
/// uniform scale s = 0.9 · min(W / width_m, 0.8 · H / height_m) [px/m], y up, the bottom 14 % left to
/// the captions:  px = W/2 + s·x,  py = 0.43·H − s·y  (py counted from the top row).

#include <algorithm>
#include <cmath>

#include "hk/vec2.hpp"
#include "pictures/image_scene.hpp"

namespace hk::app {

/// Workspace metres ↔ window pixels.
struct View {
  int w = 0, h = 0;  ///< window (or framebuffer) size [px]
  double s = 1;      ///< scale [px/m]
  double px(double x) const { return w / 2.0 + s * x; }
  double py(double y) const { return 0.43 * h - s * y; }
  Vec2 to_m(double x_px, double y_px) const { return {(x_px - w / 2.0) / s, (0.43 * h - y_px) / s}; }
};

/// The view of a `w` x `h` pixel window onto a workspace of half extent `half` [m].
inline View make_view(int w, int h, Vec2 half) {
  return {w, h, 0.9 * std::min(w / (2 * half.x), 0.8 * h / (2 * half.y))};
}

/// The longest side a picture needs on this view [px]: the workspace rectangle's longer side on the screen
/// (a picture spans at most the workspace), within [256, kScreenPictureMaxSidePx]. Pictures are shrunk to
/// it on the workers that build them (KioskRuntime::set_screen_picture_side_px): a larger texture would only
/// be minified when drawn (and alias), and would cost its upload on the window thread.
inline int picture_side_px(const View& v, Vec2 half) {
  const double side = std::ceil(2.0 * std::max(half.x, half.y) * v.s);
  return static_cast<int>(std::clamp(side, 256.0, static_cast<double>(kScreenPictureMaxSidePx)));
}

}  // namespace hk::app
