// Staff names drawn onto the picture and given to its shapes (names.hpp).
#include "meaning/names.hpp"

#include "hk/language.hpp"

#include <cairo.h>
#include <librsvg/rsvg.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <memory>

#include "hk/language.hpp"
#include "hk/text.hpp"

namespace hk::meaning {
namespace {

/// Share of its box an SVG's drawing must cover to be a region rather than a line.
constexpr double kRegionShareOfBox = 0.2;

struct CanvasScale {
  double sx = 1, sy = 1;  // picture pixels per canvas unit
  double canvas_w = 0, canvas_h = 0;
};

/// `mask` (CV_8U, the whole picture) with every area its drawing encloses filled in: an outline drawn as a stroke
/// (a transparent fill) stands for what it encloses.
cv::Mat filled(const cv::Mat& mask) {
  cv::Mat padded;
  cv::copyMakeBorder(mask, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  cv::floodFill(padded, cv::Point(0, 0), 128);  // everything outside the drawing
  cv::Mat inside = padded != 128;
  return inside(cv::Rect(1, 1, mask.cols, mask.rows)).clone();
}

/// The SVG document drawn by librsvg onto a picture-sized 8-bit alpha mask, or an empty Mat with `why` set.
cv::Mat draw_svg(const std::string& svg, int w, int h, const CanvasScale& cs, std::string* why) {
  GError* err = nullptr;
  std::unique_ptr<RsvgHandle, decltype(&g_object_unref)> handle(
      rsvg_handle_new_from_data(reinterpret_cast<const guint8*>(svg.data()), svg.size(), &err), &g_object_unref);
  if (!handle) {
    *why = std::string("its SVG selector cannot be read (") + (err ? one_line(err->message, 120) : "librsvg") + ")";
    if (err) g_error_free(err);
    return {};
  }
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create(CAIRO_FORMAT_A8, w, h), &cairo_surface_destroy);
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface.get()), &cairo_destroy);
  cairo_scale(cr.get(), cs.sx, cs.sy);
  const RsvgRectangle viewport{0, 0, cs.canvas_w, cs.canvas_h};
  if (!rsvg_handle_render_document(handle.get(), cr.get(), &viewport, &err)) {
    *why = std::string("its SVG selector cannot be drawn (") + (err ? one_line(err->message, 120) : "librsvg") + ")";
    if (err) g_error_free(err);
    return {};
  }
  cairo_surface_flush(surface.get());
  const cv::Mat alpha(h, w, CV_8U, cairo_image_surface_get_data(surface.get()),
                      static_cast<std::size_t>(cairo_image_surface_get_stride(surface.get())));
  return alpha > 0;
}

/// A FragmentSelector's box on the picture, filled.
cv::Mat draw_rect(const app::AnnotationSelector& s, int w, int h, const CanvasScale& cs) {
  const double k = s.percent ? 0.01 : 1.0;
  const double cw = s.percent ? cs.canvas_w : 1.0, ch = s.percent ? cs.canvas_h : 1.0;
  const double x0 = k * s.x * cw * cs.sx, y0 = k * s.y * ch * cs.sy;
  const double x1 = x0 + k * s.w * cw * cs.sx, y1 = y0 + k * s.h * ch * cs.sy;
  cv::Mat mask = cv::Mat::zeros(h, w, CV_8U);
  const cv::Rect r = cv::Rect(cv::Point(static_cast<int>(std::floor(x0)), static_cast<int>(std::floor(y0))),
                              cv::Point(static_cast<int>(std::ceil(x1)), static_cast<int>(std::ceil(y1)))) &
                     cv::Rect(0, 0, w, h);
  if (r.area() > 0) mask(r).setTo(255);
  return mask;
}

}  // namespace

std::vector<NamedRegion> draw_regions(const app::AnnotationSet& set, int width_px, int height_px, int full_width_px,
                                      int full_height_px, const std::string& source,
                                      std::vector<std::string>* problems) {
  std::vector<NamedRegion> out;
  if (width_px <= 0 || height_px <= 0) return out;
  CanvasScale cs;
  cs.canvas_w = set.canvas_width_px > 0 ? set.canvas_width_px : std::max(full_width_px, 1);
  cs.canvas_h = set.canvas_height_px > 0 ? set.canvas_height_px : std::max(full_height_px, 1);
  cs.sx = width_px / cs.canvas_w;
  cs.sy = height_px / cs.canvas_h;
  for (std::size_t i = 0; i < set.annotations.size(); ++i) {
    const app::Annotation& a = set.annotations[i];
    const std::string which = hk::quoted(source) + ": annotation " + std::to_string(i + 1) + ": ";
    std::string why;
    cv::Mat mask = a.selector.kind == app::AnnotationSelector::Kind::svg
                       ? draw_svg(a.selector.svg, width_px, height_px, cs, &why)
                       : draw_rect(a.selector, width_px, height_px, cs);
    if (mask.empty()) {
      if (problems) problems->push_back(which + why);
      continue;
    }
    if (a.selector.kind == app::AnnotationSelector::Kind::svg) {
      mask = filled(mask);
      const cv::Rect box = cv::boundingRect(mask);
      if (box.area() > 0 && cv::countNonZero(mask(box)) < kRegionShareOfBox * box.area()) {  // a line
        const int d = 2 * kLineReachPx + 1;
        cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(d, d)));
      }
    }
    const cv::Rect box = cv::boundingRect(mask);
    if (box.area() == 0) {
      if (problems)
        problems->push_back(which + (a.selector.kind == app::AnnotationSelector::Kind::svg
                                         ? "its SVG selector draws nothing on the picture"
                                         : "its region lies outside the picture"));
      continue;
    }
    NamedRegion r;
    r.name = a.name;
    r.description = a.description;
    r.language = a.language;
    for (const auto& [tag, tr] : a.translations)
      if (!tr.name.empty()) r.names_in[tag] = tr.name;
    r.box_px = box;
    r.mask = mask(box).clone();
    r.area_px = cv::countNonZero(r.mask);
    r.annotation = static_cast<int>(i);
    out.push_back(std::move(r));
  }
  return out;
}

namespace {

bool holds(const NamedRegion& r, double u, double v) {
  const int x = static_cast<int>(std::lround(u)) - r.box_px.x, y = static_cast<int>(std::lround(v)) - r.box_px.y;
  return x >= 0 && y >= 0 && x < r.mask.cols && y < r.mask.rows && r.mask.at<std::uint8_t>(y, x) != 0;
}

}  // namespace

std::vector<int> name_shapes(const std::vector<NamedRegion>& regions, const std::vector<Polyline>& polylines,
                             const vision::PxToM& px_to_m) {
  std::vector<int> out(polylines.size(), -1);
  for (std::size_t i = 0; i < polylines.size(); ++i) {
    const std::vector<Vec2>& p = polylines[i].points_m;
    if (p.empty()) continue;
    const std::size_t step = std::max<std::size_t>(1, p.size() / 64);  // up to 64 points along the outline
    double best = 0;
    for (std::size_t r = 0; r < regions.size(); ++r) {
      if (regions[r].name.empty() || (out[i] >= 0 && regions[r].area_px >= best)) continue;
      std::size_t in = 0, n = 0;
      for (std::size_t k = 0; k < p.size(); k += step, ++n)
        in += holds(regions[r], px_to_m.u_px(p[k].x), px_to_m.v_px(p[k].y));
      if (2 * in >= n) {
        out[i] = static_cast<int>(r);
        best = regions[r].area_px;
      }
    }
  }
  return out;
}

std::vector<int> regions_at(const std::vector<NamedRegion>& regions, double u_px, double v_px) {
  std::vector<int> out;
  for (std::size_t r = 0; r < regions.size(); ++r)
    if (!regions[r].name.empty() && holds(regions[r], u_px, v_px)) out.push_back(static_cast<int>(r));
  std::stable_sort(out.begin(), out.end(), [&](int a, int b) {
    return regions[static_cast<std::size_t>(a)].area_px < regions[static_cast<std::size_t>(b)].area_px;
  });
  return out;
}

const char* region_source_key(RegionSource s) {
  switch (s) {
    case RegionSource::face:
      return "face";
    case RegionSource::text:
      return "text";
    case RegionSource::staff:
      break;
  }
  return "staff";
}

std::optional<NamedRegion> guessed_region(RegionSource source, std::string name, cv::Rect box_px, int width_px,
                                          int height_px) {
  const cv::Rect box = box_px & cv::Rect(0, 0, width_px, height_px);
  if (box.empty()) return std::nullopt;
  NamedRegion r;
  r.source = source;
  r.name = std::move(name);
  r.box_px = box;
  r.mask = cv::Mat::zeros(box.size(), CV_8U);
  if (source == RegionSource::face) {
    // The face's own box, drawn as the ellipse it holds, then clipped with the box to the picture.
    cv::Mat whole = cv::Mat::zeros(box_px.size(), CV_8U);
    cv::ellipse(whole, {box_px.width / 2, box_px.height / 2}, {box_px.width / 2, box_px.height / 2}, 0, 0, 360,
                cv::Scalar(255), cv::FILLED);
    whole(cv::Rect(box.x - box_px.x, box.y - box_px.y, box.width, box.height)).copyTo(r.mask);
  } else {
    r.mask.setTo(255);
  }
  r.area_px = cv::countNonZero(r.mask);
  if (r.area_px <= 0) return std::nullopt;
  return r;
}

bool covered_by_staff(const NamedRegion& guess, const std::vector<NamedRegion>& staff) {
  for (const NamedRegion& s : staff) {
    if (s.source != RegionSource::staff) continue;
    const cv::Rect both = guess.box_px & s.box_px;
    if (both.empty()) continue;
    cv::Mat in_both;
    cv::bitwise_and(guess.mask(both - guess.box_px.tl()), s.mask(both - s.box_px.tl()), in_both);
    if (cv::countNonZero(in_both) * 2 >= guess.area_px) return true;
  }
  return false;
}

std::string region_name_in(const NamedRegion& region, std::string_view language, std::string* language_out) {
  auto it = region.names_in.find(std::string(language));
  if (it == region.names_in.end()) it = region.names_in.find(std::string(hk::language_subtag(language)));
  const bool found = it != region.names_in.end();
  if (language_out) *language_out = found ? it->first : region.language;
  return found ? it->second : region.name;
}

}  // namespace hk::meaning
