#pragma once
/// @file view.hpp
/// What the screen shows of the scene (OpenGL 2, legacy pipeline: one draw per frame of a few thousand
/// vertices): the picture where its pixels map in the workspace, the usable rectangle, a document page's
/// text blocks, the curves at the level in use, the handle, the proxy and the force; with the operator
/// overlay also the error boxes of the level in use and the boundary section the servo thread keeps.
///
/// View mapping (tests rely on it; kiosk_app.hpp documents it): workspace metres → window pixels with one
/// uniform scale s = 0.9 · min(W / width_m, 0.8 · H / height_m) [px/m], y up, the bottom 14 % left to
/// the captions:  px = W/2 + s·x,  py = 0.43·H − s·y  (py counted from the top row).

#include <GL/gl.h>

#include "kiosk_runtime.hpp"

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
View make_view(int w, int h, Vec2 half);

/// The longest side a picture needs on this view [px]: the workspace rectangle's longer side on the screen
/// (a picture spans at most the workspace), within [256, kScreenPictureMaxSidePx]. Pictures are shrunk to
/// it on the workers that build them (KioskRuntime::set_screen_picture_side_px): a larger texture would only
/// be minified when drawn (and alias), and would cost its upload on the window thread.
int picture_side_px(const View& v, Vec2 half);

/// The shown picture as an OpenGL texture, uploaded again when the scene shown changes.
class PictureTexture {
 public:
  PictureTexture();
  ~PictureTexture();
  PictureTexture(const PictureTexture&) = delete;
  PictureTexture& operator=(const PictureTexture&) = delete;
  /// Uploads `shown.picture` when `shown.scene` is not the one uploaded last.
  void update(const Shown& shown);
  bool valid() const { return valid_; }
  GLuint id() const { return tex_; }
  int width() const { return w_; }
  int height() const { return h_; }

 private:
  GLuint tex_ = 0;
  const Scene* for_ = nullptr;
  bool valid_ = false;
  int w_ = 0, h_ = 0;
};

/// The camera's preview while a capture is under way (for sighted companions): the latest frame
/// fitted into the workspace rectangle, over the scene, with the page the guide found outlined in green.
class CapturePreviewView {
 public:
  CapturePreviewView();
  ~CapturePreviewView();
  CapturePreviewView(const CapturePreviewView&) = delete;
  CapturePreviewView& operator=(const CapturePreviewView&) = delete;
  /// Uploads and draws `p` (nothing when it has no frame yet). `half`: the workspace's half extent [m].
  void draw(const CapturePreview& p, const View& v, Vec2 half);

 private:
  GLuint tex_ = 0;
};

/// Clears the frame and draws the scene (see the file comment).
void draw_scene(KioskRuntime& runtime, const View& view, const PictureTexture& texture);

}  // namespace hk::app
