#include "runtime/guided_tour.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

namespace hk::app {

void VisitTouches::reset(int scene_id, int curve_count) {
  scene_id_ = scene_id;
  count_ = 0;
  touched_.assign(static_cast<std::size_t>(std::max(0, curve_count)), 0);
}

void VisitTouches::touch(int scene_id, int curve) {
  if (scene_id != scene_id_ || curve < 0 || curve >= static_cast<int>(touched_.size())) return;
  unsigned char& t = touched_[static_cast<std::size_t>(curve)];
  if (!t) ++count_;
  t = 1;
}

bool VisitTouches::touched(int curve) const {
  return curve >= 0 && curve < static_cast<int>(touched_.size()) && touched_[static_cast<std::size_t>(curve)] != 0;
}

double curve_length_m(const Scene& scene, std::size_t c) {
  const CurveInfo& ci = scene.curve(c);
  const Vec2* p = scene.points(c, 0);
  const std::size_t n = ci.point_count[0];
  double len = 0.0;
  for (std::size_t i = 0; i + 1 < n; ++i) len += distance(p[i], p[i + 1]);
  if (ci.closed && n > 1) len += distance(p[n - 1], p[0]);
  return len;
}

bool is_tour_shape(const Scene& scene, std::size_t c, const TourParams& p) {
  return curve_length_m(scene, c) >= p.min_shape_length_m;
}

int shapes_remaining(const Scene& scene, const VisitTouches& touched, const TourParams& p) {
  int n = 0;
  for (std::size_t c = 0; c < scene.curve_count(); ++c)
    n += is_tour_shape(scene, c, p) && !touched.touched(static_cast<int>(c));
  return n;
}

int tour_plan_level(const Scene& scene, std::size_t c, const TourParams& p) {
  const CurveInfo& ci = scene.curve(c);
  int best = 0;
  for (int l = 1; l < ci.levels; ++l)
    if (ci.max_error_m[l] < p.plan_error_m) best = l;
  return best;
}

namespace {

/// The polyline of curve c at level l, as a vector (closed: not repeating the first point).
std::vector<Vec2> curve_points(const Scene& scene, std::size_t c, int level) {
  const int l = scene.clamp_level(c, level);
  const Vec2* p = scene.points(c, l);
  return {p, p + scene.curve(c).point_count[l]};
}

/// The point of a polyline nearest a given point: its distance [m], the segment, the parameter along it.
struct Closest {
  double dist_m = std::numeric_limits<double>::infinity();
  std::size_t segment = 0;  // segment i: points i → i+1 (mod n when closed)
  double t = 0.0;
  Vec2 q;
};

Closest closest_on(const std::vector<Vec2>& pts, bool closed, Vec2 p) {
  Closest best;
  const std::size_t n = pts.size();
  if (n == 1) {
    best.dist_m = distance(p, pts[0]);
    best.q = pts[0];
    return best;
  }
  const std::size_t segs = closed ? n : n - 1;
  for (std::size_t i = 0; i < segs; ++i) {
    double t = 0.0;
    const Vec2 q = closest_point_on_segment(p, pts[i], pts[(i + 1) % n], &t);
    const double d = distance(p, q);
    if (d < best.dist_m) best = {d, i, t, q};
  }
  return best;
}

/// Left unit normal of the segment a → b (the left normal of `fallback_dir` for a zero-length segment).
Vec2 seg_normal(Vec2 a, Vec2 b, Vec2 fallback_dir) { return left_perp(normalized_or(b - a, fallback_dir)); }

/// Offset direction at a vertex between the segments with unit normals n0 and n1: their bisector, scaled
/// by the miter factor 1 / cos(half the turn) (at most 2), so an offset along it lies the offset's distance
/// from both segments' lines (n0 for a cusp).
Vec2 vertex_normal(Vec2 n0, Vec2 n1) {
  const Vec2 b = normalized_or(n0 + n1, n0);
  return (1.0 / std::max(0.5, dot(b, n0))) * b;
}

/// Appends the polyline `pts` (with its press force at each point) to `out` at `speed` [m/s]: its vertices
/// and points in between no more than `step` [m] apart, each timed by its arc length from the last point
/// of `out`, the press interpolated along each piece.
void append_polyline(std::vector<TourPoint>& out, const std::vector<Vec2>& pts, const std::vector<Vec2>& press,
                     double speed, double step) {
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const TourPoint last = out.back();
    const Vec2 b = pts[k];
    const double len = distance(last.target_m, b);
    if (len <= 1e-9) {
      out.back().press_n = press[k];
      continue;
    }
    const int pieces = std::max(1, static_cast<int>(std::ceil(len / step)));
    for (int i = 1; i <= pieces; ++i) {
      const double f = static_cast<double>(i) / pieces;
      out.push_back({last.t_s + f * len / speed, lerp(last.target_m, b, f), lerp(last.press_n, press[k], f)});
    }
  }
}

/// The shape a tour goes round: its curve index and the level its outline is planned at (tour_plan_level).
struct ChosenShape {
  std::size_t curve = 0;
  int level = 0;
};

/// The outline a tour follows: its points on the curve from start to end, the unit (vertex: miter-scaled)
/// normal at each, and the direction along the curve's own points (+1 increasing, -1 reversed).
struct Outline {
  std::vector<Vec2> base, normal;
  int direction = 1;
};

/// A closed curve's outline from its point nearest the handle, once round and back to that point.
Outline closed_outline(const std::vector<Vec2>& pts, Vec2 handle_m) {
  Outline o;
  const std::size_t n = pts.size();
  const Closest cl = closest_on(pts, true, handle_m);
  const std::size_t k = cl.segment;
  std::vector<Vec2> seg_n(n);
  for (std::size_t i = 0; i < n; ++i) seg_n[i] = seg_normal(pts[i], pts[(i + 1) % n], {1.0, 0.0});
  const auto vn = [&](std::size_t v) { return vertex_normal(seg_n[(v + n - 1) % n], seg_n[v % n]); };
  Vec2 nq = seg_n[k];
  if (cl.t <= 1e-9) nq = vn(k);
  if (cl.t >= 1.0 - 1e-9) nq = vn(k + 1);
  o.base.push_back(cl.q);
  o.normal.push_back(nq);
  for (std::size_t i = 1; i <= n; ++i) {  // vertices k+1 … k+n (= k), then back to q
    o.base.push_back(pts[(k + i) % n]);
    o.normal.push_back(vn((k + i) % n));
  }
  o.base.push_back(cl.q);
  o.normal.push_back(nq);
  return o;
}

/// An open curve's outline from its end nearer the handle to the other end.
Outline open_outline(std::vector<Vec2> pts, Vec2 handle_m) {
  Outline o;
  const std::size_t n = pts.size();
  if (distance(handle_m, pts.back()) < distance(handle_m, pts.front())) {
    std::reverse(pts.begin(), pts.end());
    o.direction = -1;
  }
  std::vector<Vec2> seg_n(n - 1);
  for (std::size_t i = 0; i + 1 < n; ++i) seg_n[i] = seg_normal(pts[i], pts[i + 1], {1.0, 0.0});
  for (std::size_t i = 0; i < n; ++i) {
    o.base.push_back(pts[i]);
    o.normal.push_back(i == 0 ? seg_n[0] : (i == n - 1 ? seg_n[n - 2] : vertex_normal(seg_n[i - 1], seg_n[i])));
  }
  return o;
}

/// Appends the transit to `path`: minimum-jerk from the handle to `start` (m), at mean speed
/// p.speed_m_per_s but taking at least p.min_transit_s, sampled every p.transit_sample_s. Returns its
/// duration [s]. `base_points` sizes the reservation for the rest of the path.
double append_transit(TourPath& path, Vec2 handle_m, Vec2 start, std::size_t base_points, const TourParams& p) {
  const double transit_len = distance(handle_m, start);
  const double T = std::max(transit_len / p.speed_m_per_s, p.min_transit_s);
  const int steps = std::max(1, static_cast<int>(std::ceil(T / p.transit_sample_s)));
  path.points.reserve(static_cast<std::size_t>(steps) + 4 * base_points + 64);
  for (int i = 0; i <= steps; ++i) {
    const double tau = static_cast<double>(i) / steps;
    const double s = tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
    path.points.push_back({tau * T, lerp(handle_m, start, s), {}});
  }
  return T;
}

/// The track round the outline: points and the press force [N] at each.
struct Track {
  std::vector<Vec2> rest, press;
};

/// The track on the handle's `side` (±1 along the normals): the outline offset by p.track_offset_m and
/// densified to p.sample_m, the press towards the wall (inside a segment along its normal, at a vertex
/// along the bisector) ramped in and out over p.press_ramp_m, then the release to the start's offset
/// p.offset_m with no press.
Track outline_track(const Outline& o, double side, const TourParams& p) {
  const std::vector<Vec2>& base = o.base;
  const std::vector<Vec2>& normal = o.normal;
  Track t;
  std::vector<Vec2>& rest = t.rest;
  std::vector<Vec2>& press = t.press;
  std::vector<Vec2> press_dir;
  std::vector<double> arc;
  const double k_off = side * p.track_offset_m;
  for (std::size_t i = 0; i < base.size(); ++i) {
    if (i == 0) {
      rest.push_back(base[0] + k_off * normal[0]);
      press_dir.push_back(normalized_or(normal[0], {0.0, 1.0}));
      arc.push_back(0.0);
      continue;
    }
    const Vec2 a = rest.back(), b = base[i] + k_off * normal[i];
    const double len = distance(a, b);
    const int pieces = std::max(1, static_cast<int>(std::ceil(len / p.sample_m)));
    const Vec2 seg_dir = left_perp(normalized_or(base[i] - base[i - 1], {1.0, 0.0}));
    const Vec2 seg_n = dot(seg_dir, normal[i]) < 0.0 ? -seg_dir : seg_dir;  // the normals' orientation
    for (int j = 1; j <= pieces; ++j) {
      const double f = static_cast<double>(j) / pieces;
      rest.push_back(lerp(a, b, f));
      press_dir.push_back(j == pieces ? normalized_or(normal[i], seg_n) : seg_n);
      arc.push_back(arc.back() + len / pieces);
    }
  }
  const double total = arc.back();
  press.reserve(rest.size() + 1);
  for (std::size_t i = 0; i < rest.size(); ++i) {
    const double ramp =
        p.press_ramp_m > 0.0 ? std::clamp(std::min(arc[i], total - arc[i]) / p.press_ramp_m, 0.0, 1.0) : 1.0;
    press.push_back((-side * p.press_force_n * ramp) * press_dir[i]);
  }
  rest.push_back(base.back() + (side * p.offset_m) * normalized_or(normal.back(), {0.0, 1.0}));
  press.push_back({});
  return t;
}

}  // namespace

double distance_to_curve_m(const Scene& scene, std::size_t c, int level, Vec2 p) {
  return closest_on(curve_points(scene, c, level), scene.curve(c).closed, p).dist_m;
}

namespace {

/// The tour shape (is_tour_shape) not yet touched that is nearest the handle (m), if any is left.
std::optional<ChosenShape> nearest_untouched_shape(const Scene& scene, Vec2 handle_m, const VisitTouches& touched,
                                                   const TourParams& p) {
  std::optional<ChosenShape> chosen;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < scene.curve_count(); ++c) {
    if (touched.touched(static_cast<int>(c)) || !is_tour_shape(scene, c, p)) continue;
    const int l = tour_plan_level(scene, c, p);
    const double d = distance_to_curve_m(scene, c, l, handle_m);
    if (d < best) {
      best = d;
      chosen = ChosenShape{c, l};
    }
  }
  return chosen;
}

}  // namespace

std::optional<TourPath> plan_tour(const Scene& scene, int scene_id, Vec2 handle_m, const VisitTouches& touched,
                                  const TourParams& p) {
  const std::optional<ChosenShape> chosen = nearest_untouched_shape(scene, handle_m, touched, p);
  if (!chosen) return std::nullopt;
  return plan_tour_to(scene, scene_id, handle_m, chosen->curve, p);
}

std::optional<TourPath> plan_tour_to(const Scene& scene, int scene_id, Vec2 handle_m, std::size_t c,
                                     const TourParams& p) {
  if (c >= scene.curve_count()) return std::nullopt;
  std::vector<Vec2> pts = curve_points(scene, c, tour_plan_level(scene, c, p));
  if (pts.size() < 2) return std::nullopt;
  // The base sequence (on the curve) and its unit normals, from the start of the outline to its end; the
  // direction is along increasing segment indices (a closed curve's outline, an open one from its first point)
  // unless an open curve is taken from its last point.
  const Outline outline =
      scene.curve(c).closed ? closed_outline(pts, handle_m) : open_outline(std::move(pts), handle_m);
  // The handle's side of the curve at the start (+1: along the normal); on the curve, +1.
  const double along = dot(handle_m - outline.base.front(), outline.normal.front());
  const double side = along < 0.0 ? -1.0 : 1.0;

  TourPath path;
  path.scene_id = scene_id;
  path.curve = static_cast<int>(c);
  path.direction = outline.direction;
  path.params = p;
  // Transit to the start point off the curve, then onto the outline's track, round it with the press
  // towards the wall, and the release to the start's offset.
  const Vec2 start = outline.base.front() + (side * p.offset_m) * normalized_or(outline.normal.front(), {0.0, 1.0});
  path.outline_start_s = append_transit(path, handle_m, start, outline.base.size(), p);
  const Track track = outline_track(outline, side, p);
  append_polyline(path.points, track.rest, track.press, p.speed_m_per_s, p.sample_m);
  return path;
}

}  // namespace hk::app
