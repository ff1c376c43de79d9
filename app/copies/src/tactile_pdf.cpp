// A tactile graphic drawn as PDF with cairo (tactile_output.hpp).
#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "copies/tactile_output.hpp"
#include "hk/text.hpp"

namespace hk::app {
namespace {

constexpr double kPtPerMm = 72.0 / 25.4;

void set_style(cairo_t* cr, LineStyle style) {
  static constexpr double kDashed[] = {6.0, 3.0};
  static constexpr double kDotted[] = {1.5, 2.0};
  static constexpr double kDashDot[] = {6.0, 3.0, 1.5, 3.0};
  switch (style) {
    case LineStyle::dashed:
      cairo_set_dash(cr, kDashed, 2, 0);
      break;
    case LineStyle::dotted:
      cairo_set_dash(cr, kDotted, 2, 0);
      break;
    case LineStyle::dash_dot:
      cairo_set_dash(cr, kDashDot, 4, 0);
      break;
    case LineStyle::solid:
    case LineStyle::textured:
      cairo_set_dash(cr, nullptr, 0, 0);
      break;
  }
}

void draw_stroke(cairo_t* cr, const TactileStroke& s) {
  if (s.points_mm.empty()) return;
  set_style(cr, s.style);
  cairo_move_to(cr, s.points_mm[0].x, s.points_mm[0].y);
  for (std::size_t i = 1; i < s.points_mm.size(); ++i) cairo_line_to(cr, s.points_mm[i].x, s.points_mm[i].y);
  if (s.closed) cairo_close_path(cr);
  cairo_stroke(cr);
}

void draw_dot(cairo_t* cr, Vec2 c) {
  cairo_new_sub_path(cr);
  cairo_arc(cr, c.x, c.y, kBrailleDotDiameterMm / 2, 0, 2 * M_PI);
}

/// Braille cells from `at` (the first cell's top-left corner): each raised dot a filled circle.
void draw_cells(cairo_t* cr, const std::string& cells, Vec2 at) {
  const double r = kBrailleDotDiameterMm / 2;
  int k = 0;
  for (std::size_t i = 0; i < cells.size(); ++k) {
    const Utf8Step st = decode_utf8(cells, i);
    i += st.length;
    if (!st.well_formed || st.code_point < 0x2800 || st.code_point > 0x28FF) continue;
    const unsigned dots = st.code_point - 0x2800;
    const double x = at.x + k * kBrailleCellPitchMm + r, y = at.y + r;
    static constexpr int kCol[8] = {0, 0, 0, 1, 1, 1, 0, 1}, kRow[8] = {0, 1, 2, 0, 1, 2, 3, 3};
    for (int d = 0; d < 6; ++d)
      if (dots & (1u << d)) draw_dot(cr, {x + kCol[d] * kBrailleDotPitchMm, y + kRow[d] * kBrailleDotPitchMm});
  }
  cairo_fill(cr);
}

constexpr char kPrintFont[] = "DejaVu Sans";

void set_print_font(cairo_t* cr) {
  cairo_select_font_face(cr, kPrintFont, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, kPrintTextMm);
}

void draw_print(cairo_t* cr, const std::string& text, Vec2 top_left) {
  set_print_font(cr);
  cairo_move_to(cr, top_left.x, top_left.y + 0.8 * kPrintTextMm);  // the baseline under the ascent
  cairo_show_text(cr, text.c_str());
  cairo_new_path(cr);
}

void draw_page(cairo_t* cr, const TactilePage& page) {
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, kTactileLineWidthMm);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  if (page.frame_mm) {
    const auto& f = *page.frame_mm;
    cairo_set_dash(cr, nullptr, 0, 0);
    cairo_rectangle(cr, f[0].x, f[0].y, f[1].x - f[0].x, f[1].y - f[0].y);
    cairo_stroke(cr);
  }
  for (const TactileStroke& s : page.strokes) draw_stroke(cr, s);
  for (const Vec2& d : page.fill_dots_mm) draw_dot(cr, d);
  cairo_fill(cr);
  for (const TactileLabel& l : page.labels) {
    if (!l.cells.empty()) draw_cells(cr, l.cells, l.at_mm);
    if (l.print_below && !l.print.empty())
      draw_print(cr, l.print, {l.at_mm.x, l.at_mm.y + (l.cells.empty() ? 0.0 : kBrailleLinePitchMm)});
  }
}

}  // namespace

double print_width_mm(const std::string& text) {
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create(CAIRO_FORMAT_A8, 1, 1), cairo_surface_destroy);
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface.get()), cairo_destroy);
  set_print_font(cr.get());
  cairo_text_extents_t e{};
  cairo_text_extents(cr.get(), text.c_str(), &e);
  return std::max(e.x_advance, e.x_bearing + e.width);
}

namespace {

/// Draws `g` on the PDF surface `surface` and finishes it; cairo's status afterwards.
cairo_status_t draw_pdf(cairo_surface_t* surface, const TactileGraphic& g) {
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface), cairo_destroy);
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_TITLE, g.title.c_str());
  cairo_scale(cr.get(), kPtPerMm, kPtPerMm);
  for (const TactilePage& page : g.pages) {
    draw_page(cr.get(), page);
    cairo_show_page(cr.get());
  }
  cr.reset();
  cairo_surface_finish(surface);
  return cairo_surface_status(surface);
}

using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;

}  // namespace

void write_tactile_pdf(const TactileGraphic& g, const std::string& path) {
  SurfacePtr surface(cairo_pdf_surface_create(path.c_str(), g.paper.width_mm * kPtPerMm, g.paper.height_mm * kPtPerMm),
                     cairo_surface_destroy);
  const cairo_status_t st = draw_pdf(surface.get(), g);
  if (st != CAIRO_STATUS_SUCCESS)
    throw CopyError("copy " + hk::quoted(path) + ": cannot write the PDF (" + cairo_status_to_string(st) + ")");
}

std::string tactile_pdf(const TactileGraphic& g) {
  std::string bytes;
  const cairo_write_func_t append = [](void* closure, const unsigned char* data, unsigned int length) {
    static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
    return CAIRO_STATUS_SUCCESS;
  };
  SurfacePtr surface(
      cairo_pdf_surface_create_for_stream(append, &bytes, g.paper.width_mm * kPtPerMm, g.paper.height_mm * kPtPerMm),
      cairo_surface_destroy);
  const cairo_status_t st = draw_pdf(surface.get(), g);
  if (st != CAIRO_STATUS_SUCCESS)
    throw CopyError("copy '" + g.title + "': cannot draw the PDF (" + cairo_status_to_string(st) + ")");
  return bytes;
}

}  // namespace hk::app
