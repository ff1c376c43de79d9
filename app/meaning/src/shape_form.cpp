// The form of an outline from its corners, circularity, solidity and principal axes (shape_form.hpp).
#include "meaning/shape_form.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "haptics/multires.hpp"

namespace hk::meaning {
namespace {

/// The measures the table of shape_form.hpp reads, of an outline resampled to kFormSamples points.
struct Outline {
  std::vector<Vec2> p;              // the samples [m]
  std::vector<double> turn;         // |turn| at each sample over the window [deg]; 0 where an open curve has no window
  std::vector<double> signed_turn;  // the same with its sign: + to the left (counter-clockwise) [deg]
  std::vector<std::size_t> corners;
  double length_m = 0.0;
};

double signed_turn_deg(Vec2 before, Vec2 after) {
  const double c = before.x * after.y - before.y * after.x, d = dot(before, after);
  return std::atan2(c, d) * 180.0 / std::numbers::pi;
}

/// Samples whose turn is at least kCornerTurnDeg, sharp (at least kCornerSharpness of the turn over twice the
/// window: a smooth bend turns about twice as much over twice the arc, a corner hardly more) and the largest
/// within the window (the first of equals).
std::vector<std::size_t> corners_of(const std::vector<double>& turn, const std::vector<double>& wide_turn,
                                    bool closed) {
  const std::size_t n = turn.size(), k = kCornerWindow;
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < n; ++i) {
    if (turn[i] < kCornerTurnDeg || turn[i] < kCornerSharpness * wide_turn[i]) continue;
    bool peak = true;
    for (std::size_t d = 1; d <= k && peak; ++d) {
      const bool has_before = closed || i >= d, has_after = closed || i + d < n;
      if (has_before && turn[(i + n - d) % n] >= turn[i]) peak = false;
      if (has_after && turn[(i + d) % n] > turn[i]) peak = false;
    }
    if (peak) out.push_back(i);
  }
  return out;
}

Outline outline_of(const std::vector<Vec2>& points_m, bool closed) {
  Outline o;
  o.p = resample_arc_length(Polyline{points_m, closed}, kFormSamples);
  const std::size_t n = o.p.size(), k = kCornerWindow;
  for (std::size_t i = 0; i + 1 < n; ++i) o.length_m += length(o.p[i + 1] - o.p[i]);
  if (closed) o.length_m += length(o.p.front() - o.p.back());
  o.turn.assign(n, 0.0);
  o.signed_turn.assign(n, 0.0);
  std::vector<double> wide_turn(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!closed && (i < k || i + k >= n)) continue;
    o.signed_turn[i] = signed_turn_deg(o.p[i] - o.p[(i + n - k) % n], o.p[(i + k) % n] - o.p[i]);
    o.turn[i] = std::abs(o.signed_turn[i]);
    const std::size_t w = closed || (i >= 2 * k && i + 2 * k < n) ? 2 * k : k;  // near an open end: what there is
    wide_turn[i] = std::abs(signed_turn_deg(o.p[i] - o.p[(i + n - w) % n], o.p[(i + w) % n] - o.p[i]));
  }
  o.corners = corners_of(o.turn, wide_turn, closed);
  return o;
}

double area_of(const std::vector<Vec2>& p) {
  double a = 0.0;
  for (std::size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) a += p[j].x * p[i].y - p[i].x * p[j].y;
  return 0.5 * std::abs(a);
}

/// Area of the convex hull of `p` [m²] (OpenCV's convexHull, in micrometres for float precision).
double hull_area(const std::vector<Vec2>& p) {
  std::vector<cv::Point2f> pts;
  for (const Vec2& q : p) pts.emplace_back(static_cast<float>(q.x * 1e6), static_cast<float>(q.y * 1e6));
  std::vector<cv::Point2f> hull;
  cv::convexHull(pts, hull);
  return cv::contourArea(hull) * 1e-12;
}

/// Ratio of the principal axes' spreads (√ of the covariance's eigenvalues, larger over smaller), ≥ 1.
double axis_ratio(const std::vector<Vec2>& p) {
  Vec2 mean;
  for (const Vec2& q : p) mean += q;
  mean = (1.0 / static_cast<double>(p.size())) * mean;
  double sxx = 0, syy = 0, sxy = 0;
  for (const Vec2& q : p) {
    const Vec2 d = q - mean;
    sxx += d.x * d.x;
    syy += d.y * d.y;
    sxy += d.x * d.y;
  }
  const double tr = sxx + syy, det = sxx * syy - sxy * sxy;
  const double disc = std::sqrt(std::max(0.0, tr * tr / 4 - det));
  const double l1 = tr / 2 + disc, l2 = tr / 2 - disc;
  return l2 > 0 ? std::sqrt(l1 / l2) : std::numeric_limits<double>::infinity();
}

/// Whether the outline runs straight between consecutive corners: no sample farther from the chord joining the
/// two corners than kSideBow of its length (a blob with three bumps is no triangle).
bool straight_sides(const Outline& o) {
  constexpr double kSideBow = 0.08;
  const std::size_t n = o.p.size(), k = o.corners.size();
  for (std::size_t c = 0; c < k; ++c) {
    const std::size_t i0 = o.corners[c], i1 = o.corners[(c + 1) % k];
    const Vec2 a = o.p[i0], ab = o.p[i1] - a;
    const double len = length(ab);
    if (!(len > 0)) return false;
    for (std::size_t i = (i0 + 1) % n; i != i1; i = (i + 1) % n) {
      const Vec2 d = o.p[i] - a;
      if (std::abs(ab.x * d.y - ab.y * d.x) / len > kSideBow * len) return false;
    }
  }
  return true;
}

FormGuess closed_form(const Outline& o) {
  const int n = static_cast<int>(o.corners.size());
  const double area = area_of(o.p);
  const double hull = hull_area(o.p);
  const double solidity = hull > 0 ? area / hull : 0.0;
  const double circularity = 4.0 * std::numbers::pi * area / (o.length_m * o.length_m);
  const double axes = axis_ratio(o.p);
  const bool convex = solidity >= 0.9;
  if (n == 0 && circularity >= 0.7 && solidity >= 0.95) return {axes <= 1.25 ? Form::round : Form::oval, 0};
  const bool polygon = convex && straight_sides(o);
  if (n == 3 && polygon) return {Form::triangle, 3};
  if (n == 4 && polygon) {
    const bool right_angles = std::all_of(o.corners.begin(), o.corners.end(),
                                          [&](std::size_t i) { return o.turn[i] >= 60.0 && o.turn[i] <= 120.0; });
    if (right_angles) return {axes <= 1.15 ? Form::square : Form::rectangle, 4};
  }
  // A star's tips and notches alternate: as many corners turn against the outline's way round as with it.
  double way = 0.0;
  for (const double t : o.signed_turn) way += t;
  const auto notches = std::count_if(o.corners.begin(), o.corners.end(),
                                     [&](std::size_t i) { return (o.signed_turn[i] > 0) != (way > 0); });
  if (n >= 8 && solidity < 0.75 && 5 * notches >= 2 * n) return {Form::star, n};
  if (n >= 4 && n <= 8 && polygon) return {Form::polygon, n};
  return {Form::irregular, n};
}

}  // namespace

FormGuess form_of(const std::vector<Vec2>& points_m, bool closed) {
  std::size_t distinct = points_m.empty() ? 0 : 1;
  for (std::size_t i = 1; i < points_m.size(); ++i)
    if (length(points_m[i] - points_m[i - 1]) > 0) ++distinct;
  if (distinct < 3) return {closed ? Form::irregular : Form::straight_line, 0};
  const Outline o = outline_of(points_m, closed);
  if (!(o.length_m > 0)) return {closed ? Form::irregular : Form::straight_line, 0};
  if (closed) return closed_form(o);
  const double chord = length(o.p.back() - o.p.front());
  return {chord >= 0.95 * o.length_m ? Form::straight_line : Form::curve, static_cast<int>(o.corners.size())};
}

namespace {
constexpr std::array<std::string_view, 10> kFormKeys = {"irregular", "round",   "oval", "square",        "rectangle",
                                                        "triangle",  "polygon", "star", "straight line", "curve"};
}  // namespace

std::string_view form_key(Form form) { return kFormKeys[static_cast<std::size_t>(form)]; }

bool form_from_key(std::string_view key, Form* form) {
  for (std::size_t i = 0; i < kFormKeys.size(); ++i)
    if (kFormKeys[i] == key) {
      *form = static_cast<Form>(i);
      return true;
    }
  return false;
}

}  // namespace hk::meaning
