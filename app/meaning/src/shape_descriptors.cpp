// Forms, colours and sizes of a scene's shapes (shape_descriptors.hpp).
#include "meaning/shape_descriptors.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include "haptics/tour_guide.hpp"

namespace hk::meaning {
namespace {

/// Largest deviation of the form's level from the curve, as a share of the curve's bounding-box diagonal.
constexpr double kFormLevelError = 0.03;
/// Fewest points of the form's level: fewer, and its polygon's own vertices turn as much as corners.
constexpr std::uint32_t kFormLevelPoints = 32;

struct Box {
  Vec2 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  Vec2 hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  void add(Vec2 p) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
  }
};

double length_of(const std::vector<Vec2>& p, bool closed) {
  double len = 0.0;
  for (std::size_t i = 0; i + 1 < p.size(); ++i) len += length(p[i + 1] - p[i]);
  if (closed && p.size() > 1) len += length(p.back() - p.front());
  return len;
}

/// The points of scene curve c at the coarsest level within kFormLevelError of the curve's size.
std::vector<Vec2> form_level_points(const Scene& scene, std::size_t c, double diagonal_m) {
  const CurveInfo& ci = scene.curve(c);
  int level = 0;
  for (int l = ci.levels - 1; l > 0; --l)
    if (ci.max_error_m[l] <= kFormLevelError * diagonal_m && ci.point_count[l] >= kFormLevelPoints) {
      level = l;
      break;
    }
  const Vec2* p = scene.points(c, level);
  return std::vector<Vec2>(p, p + ci.point_count[level]);
}

/// A polyline's points on the picture's pixels [px].
std::vector<cv::Point> pixels_of(const Polyline& line, const PictureColours& pc) {
  std::vector<cv::Point> px;
  px.reserve(line.points_m.size());
  for (const Vec2& p : line.points_m)
    px.emplace_back(static_cast<int>(std::lround(pc.px_to_m.u_px(p.x))),
                    static_cast<int>(std::lround(pc.px_to_m.v_px(p.y))));
  return px;
}

/// For each closed polyline, the closed polylines directly or deeper inside it (bounding box within its own and
/// first point inside its polygon); empty for an open one. What its colour leaves out: a thick stroke drawn as a
/// square is the ring between its two outlines, a wing is black around its white spots.
std::vector<std::vector<std::size_t>> shapes_inside(const std::vector<Polyline>& polylines) {
  std::vector<Box> boxes(polylines.size());
  for (std::size_t i = 0; i < polylines.size(); ++i)
    for (const Vec2& p : polylines[i].points_m) boxes[i].add(p);
  std::vector<std::vector<std::size_t>> inside(polylines.size());
  for (std::size_t i = 0; i < polylines.size(); ++i) {
    if (!polylines[i].closed || polylines[i].points_m.size() < 3) continue;
    std::vector<cv::Point2f> poly;
    for (const Vec2& p : polylines[i].points_m) poly.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
    for (std::size_t j = 0; j < polylines.size(); ++j) {
      const Box& a = boxes[i];
      const Box& b = boxes[j];
      if (j == i || !polylines[j].closed || polylines[j].points_m.empty()) continue;
      if (b.lo.x < a.lo.x || b.lo.y < a.lo.y || b.hi.x > a.hi.x || b.hi.y > a.hi.y) continue;
      const Vec2 q = polylines[j].points_m.front();
      if (cv::pointPolygonTest(poly, cv::Point2f(static_cast<float>(q.x), static_cast<float>(q.y)), false) > 0)
        inside[i].push_back(j);
    }
  }
  return inside;
}

/// The colour inside the closed outline (2 px in from it, and from the closed shapes `holes` inside it) or
/// along the line, in the picture's pixels.
bool colour_of(const Polyline& line, bool inside, const std::vector<const Polyline*>& holes, const PictureColours& pc,
               ColourName* out) {
  if (pc.picture.empty() || line.points_m.empty()) return false;
  std::vector<cv::Point> px = pixels_of(line, pc);
  const cv::Rect box = cv::boundingRect(px) & cv::Rect(0, 0, pc.picture.cols, pc.picture.rows);
  if (box.area() == 0) return false;
  for (cv::Point& q : px) q -= box.tl();
  cv::Mat mask = cv::Mat::zeros(box.size(), CV_8U);
  if (inside) {
    cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{px}, 255);
    cv::Mat own = mask.clone();
    for (const Polyline* h : holes) {
      std::vector<cv::Point> hp = pixels_of(*h, pc);
      for (cv::Point& q : hp) q -= box.tl();
      cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{hp}, 0);
    }
    cv::Mat eroded;
    cv::erode(mask, eroded, cv::Mat(), cv::Point(-1, -1), 2);
    if (cv::countNonZero(eroded) < 16) cv::erode(own, eroded, cv::Mat(), cv::Point(-1, -1), 2);  // holes fill it
    if (cv::countNonZero(eroded) >= 16) mask = eroded;  // else the outline's own pixels: a speck of a shape
  } else {
    cv::polylines(mask, std::vector<std::vector<cv::Point>>{px}, line.closed, 255);
  }
  Lab lab;
  if (!median_lab(pc.picture(box), mask, &lab)) return false;
  *out = name_of(lab);
  return true;
}

ShapeDescriptor describe_one(const Polyline& line, const std::vector<Vec2>& form_points, double length_m,
                             const std::vector<const Polyline*>& holes, const PictureColours& pc) {
  ShapeDescriptor d;
  Box box;
  for (const Vec2& p : line.points_m) box.add(p);
  d.form = form_of(form_points, line.closed);
  d.size_cm = line.points_m.empty() ? 0.0 : 100.0 * std::max(box.hi.x - box.lo.x, box.hi.y - box.lo.y);
  d.length_m = length_m;
  d.speck = length_m < TourParams{}.min_shape_length_m;
  // Inside a closed shape; along a line only when it is ink (a line drawing): a photograph's open edge lies
  // between two colours, and its own pixels are a blend of both.
  if (line.closed || pc.line_drawing)
    d.has_colour = colour_of(line, line.closed && !pc.line_drawing, holes, pc, &d.colour);
  return d;
}

/// The closed polylines inside polylines[i] (shapes_inside), as pointers.
std::vector<const Polyline*> holes_of(const std::vector<Polyline>& polylines,
                                      const std::vector<std::vector<std::size_t>>& inside, std::size_t i) {
  std::vector<const Polyline*> out;
  for (const std::size_t j : inside[i]) out.push_back(&polylines[j]);
  return out;
}

}  // namespace

std::vector<ShapeDescriptor> describe_shapes(const std::vector<Polyline>& polylines, const Scene& scene,
                                             const PictureColours& colours) {
  const std::vector<std::vector<std::size_t>> inside = shapes_inside(polylines);
  std::vector<int> curve_of(polylines.size(), -1);
  for (std::size_t c = 0; c < scene.curve_count(); ++c)
    if (scene.source_index(c) < polylines.size()) curve_of[scene.source_index(c)] = static_cast<int>(c);
  std::vector<ShapeDescriptor> out;
  out.reserve(polylines.size());
  for (std::size_t i = 0; i < polylines.size(); ++i) {
    const Polyline& line = polylines[i];
    if (curve_of[i] < 0) {
      out.push_back(describe_one(line, line.points_m, length_of(line.points_m, line.closed),
                                 holes_of(polylines, inside, i), colours));
      continue;
    }
    const auto c = static_cast<std::size_t>(curve_of[i]);
    Box box;
    for (const Vec2& p : line.points_m) box.add(p);
    const CurveInfo& ci = scene.curve(c);
    const Vec2* p0 = scene.points(c, 0);
    const double len0 = length_of(std::vector<Vec2>(p0, p0 + ci.point_count[0]), ci.closed);
    out.push_back(describe_one(line, form_level_points(scene, c, length(box.hi - box.lo)), len0,
                               holes_of(polylines, inside, i), colours));
  }
  return out;
}

std::vector<ShapeDescriptor> describe_shapes(const std::vector<Polyline>& polylines, const PictureColours& colours) {
  const std::vector<std::vector<std::size_t>> inside = shapes_inside(polylines);
  std::vector<ShapeDescriptor> out;
  out.reserve(polylines.size());
  for (std::size_t i = 0; i < polylines.size(); ++i)
    out.push_back(describe_one(polylines[i], polylines[i].points_m,
                               length_of(polylines[i].points_m, polylines[i].closed), holes_of(polylines, inside, i),
                               colours));
  return out;
}

}  // namespace hk::meaning
