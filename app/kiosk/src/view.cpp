#include "kiosk/view.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "hk/level_choice.hpp"

namespace hk::app {

PictureTexture::PictureTexture(int side_px) {
  glGenTextures(2, tex_);
  for (int i = 0; i < 2; ++i) allocate(i, std::max(side_px, 1));
}

PictureTexture::~PictureTexture() { glDeleteTextures(2, tex_); }

void PictureTexture::allocate(int i, int side_px) {
  glBindTexture(GL_TEXTURE_2D, tex_[i]);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, side_px, side_px, 0, GL_BGR, GL_UNSIGNED_BYTE, nullptr);  // storage only
  side_[i] = side_px;
}

void PictureTexture::update(const Shown& shown) {
  if (shown.scene != for_) {
    for_ = shown.scene;
    if (valid_) drawn_ = 1 - drawn_;  // the texture drawn until now may still be read by frames in flight
    valid_ = false;
    pending_.release();
    rows_up_ = 0;
    if (shown.picture.empty() || shown.picture.type() != CV_8UC3) return;
    pending_ = shown.picture;  // shares the pixels: they outlive a later change of what is shown
    if (pending_.step[0] % 3 != 0) pending_ = pending_.clone();  // rows given to OpenGL in whole pixels
    w_ = pending_.cols;
    h_ = pending_.rows;
    if (side_[drawn_] < std::max(w_, h_)) allocate(drawn_, std::max(w_, h_));  // kept for later pictures
  }
  if (pending_.empty()) return;
  // OpenCV's BGR rows go up as they are (GL_BGR, OpenGL 1.2): no converted copy on the window thread.
  const std::size_t row_bytes = pending_.step[0];
  const int rows =
      std::clamp(static_cast<int>(kUploadBytesPerFrame / std::max<std::size_t>(row_bytes, 1)), 1, h_ - rows_up_);
  glBindTexture(GL_TEXTURE_2D, tex_[drawn_]);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, static_cast<GLint>(row_bytes / 3));
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, rows_up_, w_, rows, GL_BGR, GL_UNSIGNED_BYTE, pending_.ptr(rows_up_));
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  rows_up_ += rows;
  if (rows_up_ < h_) return;
  valid_ = true;
  pending_.release();
}

CapturePreviewView::CapturePreviewView() { glGenTextures(1, &tex_); }
CapturePreviewView::~CapturePreviewView() { glDeleteTextures(1, &tex_); }

void CapturePreviewView::draw(const CapturePreview& p, const View& v, Vec2 half) {
  if (p.frame.empty()) return;
  cv::Mat rgb;
  cv::cvtColor(p.frame, rgb, cv::COLOR_BGR2RGB);
  glBindTexture(GL_TEXTURE_2D, tex_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, rgb.cols, rgb.rows, 0, GL_RGB, GL_UNSIGNED_BYTE, rgb.data);
  // The frame fitted into the workspace rectangle, keeping its aspect ratio: pixel (u, v) at (x0 + k·u, y0 − k·v).
  const double k = std::min(2 * half.x / rgb.cols, 2 * half.y / rgb.rows);
  const double x0 = -k * rgb.cols / 2, y0 = k * rgb.rows / 2;
  const auto at = [&](double u, double w) { return std::pair<double, double>{v.px(x0 + k * u), v.py(y0 - k * w)}; };
  // The scene behind is covered: the preview is the only picture on the screen while it runs.
  glColor4f(0.05f, 0.05f, 0.08f, 1.0f);
  glBegin(GL_QUADS);
  glVertex2d(v.px(-half.x), v.py(half.y));
  glVertex2d(v.px(half.x), v.py(half.y));
  glVertex2d(v.px(half.x), v.py(-half.y));
  glVertex2d(v.px(-half.x), v.py(-half.y));
  glEnd();
  glEnable(GL_TEXTURE_2D);
  glColor4f(1, 1, 1, 1);
  glBegin(GL_QUADS);
  const double us[4] = {0, 1, 1, 0}, ws[4] = {0, 0, 1, 1};
  for (int i = 0; i < 4; ++i) {
    const auto [x, y] = at(us[i] * rgb.cols, ws[i] * rgb.rows);
    glTexCoord2d(us[i], ws[i]);
    glVertex2d(x, y);
  }
  glEnd();
  glDisable(GL_TEXTURE_2D);
  if (p.corners_px) {
    glColor4f(0.2f, 1.0f, 0.3f, 1.0f);
    glLineWidth(3.0f);
    glBegin(GL_LINE_LOOP);
    for (const cv::Point2d& c : *p.corners_px) {
      const auto [x, y] = at(c.x + 0.5, c.y + 0.5);
      glVertex2d(x, y);
    }
    glEnd();
  }
}

namespace {

/// A circle of radius r_px pixels around c (m), filled or as a ring, drawn as 24 sides.
void disc(const View& v, Vec2 c, double r_px, bool filled) {
  glBegin(filled ? GL_TRIANGLE_FAN : GL_LINE_LOOP);
  for (int k = 0; k < 24; ++k) {
    const double a = 2 * M_PI * k / 24;
    glVertex2d(v.px(c.x) + r_px * std::cos(a), v.py(c.y) + r_px * std::sin(a));
  }
  glEnd();
}

/// Sets up a frame: the whole window in pixels (y down), cleared to the background, with alpha blending.
void begin_frame(const View& v) {
  glViewport(0, 0, v.w, v.h);
  glClearColor(0.05f, 0.05f, 0.08f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glOrtho(0, v.w, v.h, 0, -1, 1);  // pixels, y down
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
}

/// The picture, in the workspace where its pixels map; dimmed (more in high contrast) so the curves stand out.
void draw_picture(const View& v, const PictureTexture& tex, const Shown& sh, bool hc) {
  if (!tex.valid()) return;
  const vision::PxToM& m = sh.px_to_m;
  const double x0 = m.x_m(-0.5), x1 = m.x_m(tex.width() - 0.5), y0 = m.y_m(-0.5), y1 = m.y_m(tex.height() - 0.5);
  glEnable(GL_TEXTURE_2D);
  glBindTexture(GL_TEXTURE_2D, tex.id());
  const float dim = hc ? 0.25f : 0.8f;
  glColor4f(dim, dim, dim, 1.0f);
  // The picture's corner of the texture, its far edges at the last texels' centres (half a texel in), so
  // linear filtering never blends in the texels past the picture, left there by a larger one.
  const float side = static_cast<float>(tex.side());
  const float u1 = (static_cast<float>(tex.width()) - 0.5f) / side,
              v1 = (static_cast<float>(tex.height()) - 0.5f) / side;
  glBegin(GL_QUADS);
  glTexCoord2f(0, 0);
  glVertex2d(v.px(x0), v.py(y0));
  glTexCoord2f(u1, 0);
  glVertex2d(v.px(x1), v.py(y0));
  glTexCoord2f(u1, v1);
  glVertex2d(v.px(x1), v.py(y1));
  glTexCoord2f(0, v1);
  glVertex2d(v.px(x0), v.py(y1));
  glEnd();
  glDisable(GL_TEXTURE_2D);
}

/// The usable rectangle's frame (half its size `half`, m), so a companion sees where the handle can go.
void draw_workspace_frame(const View& v, Vec2 half) {
  glColor4f(0.4f, 0.4f, 0.45f, 1.0f);
  glLineWidth(1.0f);
  glBegin(GL_LINE_LOOP);
  glVertex2d(v.px(-half.x), v.py(-half.y));
  glVertex2d(v.px(half.x), v.py(-half.y));
  glVertex2d(v.px(half.x), v.py(half.y));
  glVertex2d(v.px(-half.x), v.py(half.y));
  glEnd();
}

/// Text blocks of a document page (spoken, not felt): pale blue frames, for a companion who sees.
void draw_text_blocks(const View& v, const Shown& sh, bool hc) {
  glColor4f(0.45f, 0.7f, 1.0f, hc ? 1.0f : 0.8f);
  glLineWidth(hc ? 3.0f : 1.5f);
  for (const TextBlockM& b : sh.text_blocks) {
    glBegin(GL_LINE_LOOP);
    glVertex2d(v.px(b.lo_m.x), v.py(b.lo_m.y));
    glVertex2d(v.px(b.hi_m.x), v.py(b.lo_m.y));
    glVertex2d(v.px(b.hi_m.x), v.py(b.hi_m.y));
    glVertex2d(v.px(b.lo_m.x), v.py(b.hi_m.y));
    glEnd();
  }
}

/// The curves at the level in use (a tolerance step's cuts when cut_step >= 0): bright yellow (RGB 255, 220,
/// 0), thicker in high contrast.
void draw_curves(KioskRuntime& app, const View& v, const Shown& sh, bool hc, int cut_step) {
  glColor4f(1.0f, 220.0f / 255.0f, 0.0f, 1.0f);
  glLineWidth(hc ? 6.0f : 3.0f);
  for (std::size_t c = 0; c < sh.levels.size(); ++c) {
    const int top = static_cast<int>(sh.levels[c].size()) - 1;
    const int l = sh.scene ? sh.scene->clamp_level(c, app.stage().level())
                           : std::min(app.stage().level(), top);  // a tolerance step: the curve's own level
    const std::vector<Vec2>& pts =
        cut_step >= 0 ? sh.cuts[c][static_cast<std::size_t>(cut_step)] : sh.levels[c][static_cast<std::size_t>(l)];
    glBegin(sh.closed[c] ? GL_LINE_LOOP : GL_LINE_STRIP);
    for (const Vec2& p : pts) glVertex2d(v.px(p.x), v.py(p.y));
    glEnd();
  }
}

/// The shapes staff named (operator overlay): their level-0 curves in pale green over the walls, so the
/// operator sees which shapes have a name (the Names tab).
void draw_named_shapes(const View& v, const Shown& sh) {
  glColor4f(0.55f, 1.0f, 0.6f, 0.85f);
  glLineWidth(5.0f);
  for (std::size_t c = 0; c < sh.polylines.size() && c < sh.shape_region.size(); ++c) {
    if (sh.shape_region[c] < 0) continue;
    glBegin(sh.polylines[c].closed ? GL_LINE_LOOP : GL_LINE_STRIP);
    for (const Vec2& p : sh.polylines[c].points_m) glVertex2d(v.px(p.x), v.py(p.y));
    glEnd();
  }
}

/// One error box (a rotated rectangle: origin, axis, [u_min, u_max] × [n_min, n_max] in m) as a line loop,
/// in the colour and width already set.
void draw_box(const View& v, const ErrorBox& b) {
  const Vec2 n = left_perp(b.axis);
  glBegin(GL_LINE_LOOP);
  for (const auto& [u, w] : {std::pair{b.u_min, b.n_min}, {b.u_max, b.n_min}, {b.u_max, b.n_max}, {b.u_min, b.n_max}}) {
    const Vec2 q = b.origin_m + u * b.axis + w * n;
    glVertex2d(v.px(q.x), v.py(q.y));
  }
  glEnd();
}

/// Error boxes of the walls' segments at the level in use, or of a tolerance step's own segments when
/// cut_step >= 0 (operator overlay): cyan.
void draw_error_boxes(KioskRuntime& app, const View& v, const Shown& sh, int cut_step) {
  const Scene& sc = *sh.scene;
  glColor4f(0.2f, 0.9f, 1.0f, 0.5f);
  glLineWidth(1.0f);
  const auto segment_box = [&](SegmentRef ref) { draw_box(v, sc.box(sc.node_of(ref))); };
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    if (cut_step >= 0) {
      for (const SegmentRef& ref : sh.cut_segments[c][static_cast<std::size_t>(cut_step)]) segment_box(ref);
      continue;
    }
    const int l = sc.clamp_level(c, app.stage().level());
    const std::uint32_t segs = sc.curve(c).point_count[l] - (sc.curve(c).closed ? 0 : 1);
    for (std::uint32_t k = 0; k < segs; ++k)
      segment_box({static_cast<std::int32_t>(c), l, static_cast<std::int32_t>(k)});
  }
}

/// The boundary section the servo thread keeps (operator overlay): magenta, every entry as a box (a segment's
/// rotated one; a chunk's, hierarchy node's or wide node's rectangle, rect_box).
void draw_section(const View& v, const Scene& sc, const ServoDisplayState& d) {
  glColor4f(1.0f, 0.3f, 1.0f, 0.8f);
  glLineWidth(1.5f);
  const int n = std::min(d.section_count, ServoDisplayState::kMaxSection);
  for (int i = 0; i < n; ++i) {
    const std::uint32_t node = d.section[i];
    const std::size_t wide_node = node - sc.node_count();  // the wide frontier's entries (BoundarySection::section)
    if (node >= sc.node_count() && wide_node >= sc.wide_index().nodes.size()) continue;
    if (node >= sc.node_count()) {
      Aabb r;
      sc.wide_index().node_rect(static_cast<std::uint32_t>(wide_node), &r.lo, &r.hi);
      draw_box(v, rect_box(r));
    } else {
      draw_box(v, sc.box(node));
    }
  }
}

/// Handle (red ring), proxy (white disc, on the curve in contact: seed §4), force arrow from the handle
/// (6 mm per newton, drawn above 0.05 N).
void draw_handle(const View& v, const ServoDisplayState& d) {
  glLineWidth(2.0f);
  glColor4f(1.0f, 0.3f, 0.3f, 1.0f);
  disc(v, d.handle_m, 9, false);
  glColor4f(1.0f, 1.0f, 1.0f, 1.0f);
  disc(v, d.proxy_m, 6, true);
  const double f = length(d.force_n);
  if (f > 0.05) {
    const Vec2 tip = d.handle_m + 0.006 * d.force_n;  // 6 mm per newton
    glColor4f(0.3f, 1.0f, 0.4f, 1.0f);
    glBegin(GL_LINES);
    glVertex2d(v.px(d.handle_m.x), v.py(d.handle_m.y));
    glVertex2d(v.px(tip.x), v.py(tip.y));
    glEnd();
    disc(v, tip, 3, true);
  }
}

}  // namespace

void draw_scene(KioskRuntime& app, const View& v, const PictureTexture& tex) {
  begin_frame(v);
  const Shown& sh = app.stage().shown();
  const bool hc = app.switches().high_contrast();
  draw_picture(v, tex, sh, hc);
  draw_workspace_frame(v, app.half());
  draw_text_blocks(v, sh, hc);
  const LevelChoice choice = LevelChoice::of_id(app.stage().level());
  const int cut_step = choice.kind == LevelChoice::Kind::Cut && !sh.cuts.empty() ? choice.index : -1;
  if (app.switches().overlay()) draw_named_shapes(v, sh);
  draw_curves(app, v, sh, hc, cut_step);
  if (app.switches().overlay() && sh.scene) draw_error_boxes(app, v, sh, cut_step);
  const ServoDisplayState& d = app.core().display();
  if (app.switches().overlay() && sh.scene && d.scene_id == app.stage().shown_id()) draw_section(v, *sh.scene, d);
  draw_handle(v, d);
}

}  // namespace hk::app
