#pragma once
/// @file view.hpp
/// What the screen shows of the scene (OpenGL 2, legacy pipeline: one draw per frame of a few thousand
/// vertices): the picture where its pixels map in the workspace, the usable rectangle, a document page's
/// text blocks, the curves at the level in use, the handle, the proxy and the force; with the operator
/// overlay also the error boxes of the level in use, the boundary section the servo thread keeps and the shapes
/// staff named (pale green, under the walls).
/// Where the workspace lands on the screen (View, make_view): view_geometry.hpp.

#include <GL/gl.h>

#include "pictures/view_geometry.hpp"
#include "visit/kiosk_runtime.hpp"

namespace hk::app {

/// The shown picture as an OpenGL texture, uploaded again when the scene shown changes, a slice of rows a
/// frame (at most kUploadBytesPerFrame), so a change never costs the window thread more than one slice.
/// Two square textures take turns, allocated at start at the screen's picture side: a picture goes up into
/// the corner of the one not drawn last, and is drawn from that corner. Allocating a texture's storage
/// (glTexImage2D) for every picture took 17-27 ms of the frame that changed it under Mesa's software OpenGL.
class PictureTexture {
 public:
  /// Bytes of picture rows uploaded per frame [bytes]: about 9 ms under Mesa's software OpenGL, far less on a
  /// GPU; a picture the screen draws at 1040 px is up in 3 frames.
  static constexpr std::size_t kUploadBytesPerFrame = 1u << 20;
  /// Allocates both textures at `side_px` x `side_px` (the screen's picture side, picture_side_px), so that
  /// no picture of the kiosk's needs storage allocated while a visitor waits. A larger picture grows them.
  explicit PictureTexture(int side_px);
  ~PictureTexture();
  PictureTexture(const PictureTexture&) = delete;
  PictureTexture& operator=(const PictureTexture&) = delete;
  /// Once a frame: when `shown.scene` is not the one uploaded last, starts uploading `shown.picture` (BGR) and
  /// stops drawing the old one (its pixel map is not the new picture's); then uploads the next slice of rows.
  /// valid() once every row is up.
  void update(const Shown& shown);
  bool valid() const { return valid_; }
  /// The texture to draw (valid() only).
  GLuint id() const { return tex_[drawn_]; }
  /// The picture's size [px]: it fills texture coordinates [0, width / side] x [0, height / side].
  int width() const { return w_; }
  int height() const { return h_; }
  /// The side of the texture drawn [texels] (>= width and height).
  int side() const { return side_[drawn_]; }

 private:
  void allocate(int i, int side_px);  // texture i's storage, side_px square (glTexImage2D, no pixels)
  GLuint tex_[2] = {0, 0};
  int side_[2] = {0, 0};  // each texture's allocated side [texels] (0: not yet allocated)
  int drawn_ = 0;         // the texture drawn when valid_, else the one being filled (never the one drawn last)
  const Scene* for_ = nullptr;
  bool valid_ = false;
  int w_ = 0, h_ = 0;
  cv::Mat pending_;  // the picture being uploaded (shares the shown picture's pixels), empty when up
  int rows_up_ = 0;  // rows of pending_ uploaded so far
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
