// Pages made flat: find the page in a camera frame, its aspect ratio, the warp flat.
// See vision/page.hpp for the contract; the steps are described at each function below.

#include "vision/page.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"

namespace hk::vision {
namespace {

using Quad = std::array<cv::Point2d, 4>;

/// A line through `p` with unit direction `d`.
struct Line {
  cv::Point2d p;
  cv::Point2d d;
};

double cross(cv::Point2d a, cv::Point2d b) { return a.x * b.y - a.y * b.x; }

/// Shoelace area; positive when the corners run clockwise on screen (x right, y down).
double signed_area(const Quad& q) {
  double s = 0.0;
  for (std::size_t i = 0; i < 4; ++i) s += cross(q[i], q[(i + 1) % 4]);
  return 0.5 * s;
}

bool finite(cv::Point2d p) { return std::isfinite(p.x) && std::isfinite(p.y); }

std::optional<cv::Point2d> intersect(const Line& a, const Line& b) {
  const double den = cross(a.d, b.d);
  if (std::abs(den) < 1e-9) return std::nullopt;
  const double t = cross(b.p - a.p, b.d) / den;
  return a.p + t * a.d;
}

/// The order of PageDetection: clockwise on screen, starting at the corner where the side that faces the frame's
/// top most directly (outward normal closest to straight up) begins.
Quad order_corners(Quad q) {
  if (signed_area(q) < 0) std::swap(q[1], q[3]);
  std::size_t best = 0;
  double best_dx = -2.0;
  for (std::size_t i = 0; i < 4; ++i) {
    const cv::Point2d d = q[(i + 1) % 4] - q[i];
    const double n = std::hypot(d.x, d.y);
    // Clockwise on screen, the outward normal of side d is (d.y, -d.x) / |d|: up is d pointing right.
    if (n > 0 && d.x / n > best_dx) {
      best_dx = d.x / n;
      best = i;
    }
  }
  std::rotate(q.begin(), q.begin() + static_cast<std::ptrdiff_t>(best), q.end());
  return q;
}

/// The part of the segment a → b within the rectangle of pixel centres [m, W − 1 − m] x [m, H − 1 − m]
/// (Liang–Barsky), as parameters 0 <= t0 < t1 <= 1; empty when the segment misses it.
std::optional<std::pair<double, double>> clip_segment(cv::Point2d a, cv::Point2d b, cv::Size size, double m) {
  double t0 = 0.0, t1 = 1.0;
  const cv::Point2d d = b - a;
  const std::array<std::pair<double, double>, 4> pq{
      {{-d.x, a.x - m}, {d.x, size.width - 1 - m - a.x}, {-d.y, a.y - m}, {d.y, size.height - 1 - m - a.y}}};
  for (const auto& [p, q] : pq) {
    if (p == 0.0) {
      if (q < 0.0) return std::nullopt;
      continue;
    }
    const double r = q / p;
    if (p < 0.0)
      t0 = std::max(t0, r);
    else
      t1 = std::min(t1, r);
  }
  if (t1 - t0 <= 0.0) return std::nullopt;
  return std::make_pair(t0, t1);
}

/// Area of the part of `q` (convex) inside the frame [px²].
double visible_area(const Quad& q, cv::Size size) {
  std::vector<cv::Point2f> quad, rect{{-0.5f, -0.5f},
                                      {size.width - 0.5f, -0.5f},
                                      {size.width - 0.5f, size.height - 0.5f},
                                      {-0.5f, size.height - 0.5f}};
  for (const cv::Point2d& p : q) quad.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
  if (signed_area(q) < 0) std::reverse(quad.begin(), quad.end());
  std::vector<cv::Point2f> both;
  return static_cast<double>(cv::intersectConvexConvex(quad, rect, both, true));
}

/// Samples `image` (CV_8UC1 or CV_8UC3) at the points base_i + o_k·normal + s_j·tangent for every sample position
/// i, tangential offset j and normal offset k: n_pos rows of (n_tan · n_off) pixels, j-major, same type as `image`
/// (bilinear, border replicated). The result is a view of a buffer kept per thread and reused by the next call
/// (this runs a few hundred times per frame; reusing the buffers keeps it from allocating each time).
cv::Mat sample_across(const cv::Mat& image, const std::vector<cv::Point2d>& base, cv::Point2d tangent,
                      cv::Point2d normal, const std::vector<double>& tan_offsets,
                      const std::vector<double>& normal_offsets) {
  const int n_pos = static_cast<int>(base.size());
  const int n_tan = static_cast<int>(tan_offsets.size()), n_off = static_cast<int>(normal_offsets.size());
  thread_local cv::Mat map_buffer, out_buffers[2];  // out: grey, colour
  const auto view = [](cv::Mat& buffer, int rows, int cols, int type) {
    if (buffer.type() != type || buffer.rows < rows || buffer.cols < cols)
      buffer.create(std::max(rows, buffer.type() == type ? buffer.rows : 0),
                    std::max(cols, buffer.type() == type ? buffer.cols : 0), type);
    return buffer(cv::Rect(0, 0, cols, rows));
  };
  cv::Mat map = view(map_buffer, n_pos, n_tan * n_off, CV_32FC2);
  for (int i = 0; i < n_pos; ++i) {
    cv::Vec2f* m = map.ptr<cv::Vec2f>(i);
    for (int j = 0; j < n_tan; ++j) {
      const cv::Point2d b = base[static_cast<std::size_t>(i)] + tan_offsets[static_cast<std::size_t>(j)] * tangent;
      for (int k = 0; k < n_off; ++k) {
        const cv::Point2d p = b + normal_offsets[static_cast<std::size_t>(k)] * normal;
        m[j * n_off + k] = {static_cast<float>(p.x), static_cast<float>(p.y)};
      }
    }
  }
  cv::Mat out = view(out_buffers[image.channels() == 1 ? 0 : 1], n_pos, n_tan * n_off, image.type());
  cv::remap(image, out, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

/// Positions spread along a → b over [t0, t1], those at least `margin` inside the frame.
std::vector<cv::Point2d> positions_along(cv::Point2d a, cv::Point2d b, int n, double t0, double t1, cv::Size frame,
                                         double margin) {
  std::vector<cv::Point2d> out;
  out.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double t = t0 + (t1 - t0) * (n == 1 ? 0.5 : static_cast<double>(i) / (n - 1));
    const cv::Point2d p = a + t * (b - a);
    if (p.x >= margin && p.y >= margin && p.x <= frame.width - 1 - margin && p.y <= frame.height - 1 - margin)
      out.push_back(p);
  }
  return out;
}

/// Edge points found across a side, and where along it they were looked for.
struct EdgePoints {
  std::vector<cv::Point2f> pts;  ///< the edge points found
  std::vector<double> t;         ///< each point's position along a → b, [0, 1]
  std::vector<double> tried;     ///< the positions looked at, [0, 1]
  std::vector<float> strength;   ///< each point's derivative across the side [grey levels / px]
};

/// Edge points near the side a → b of `image` (grey or BGR), at up to 64 positions spread over [t0, t1] of it: at
/// each, the largest change across the side within ±window px (colour: the length of the vector of per-channel
/// derivatives) or, with `nearest`, the one nearest the side among those at least 0.4 x the largest; located to
/// sub-pixel precision (parabola through the peak). The profiles across the side are sampled every 0.5 px
/// (cv::remap, bilinear), averaged over 5 samples along the side (less noise, no blur across it), smoothed across
/// it (Gaussian, σ = smooth_px x unit) and differentiated ([-1 0 1]). `unit`: frame px per downscaled px.
EdgePoints edge_points(const cv::Mat& image, cv::Point2d a, cv::Point2d b, double window, double unit, double t0 = 0.05,
                       double t1 = 0.95, bool nearest = false, double smooth_px = 0.75) {
  const cv::Point2d d = b - a;
  const double len = std::hypot(d.x, d.y);
  const cv::Point2d t = d / len, n(t.y, -t.x);
  const int n_pos = std::clamp(static_cast<int>((t1 - t0) * len / (2.7 * unit)), 12, 64);
  const std::vector<cv::Point2d> base = positions_along(a, b, n_pos, t0, t1, image.size(), 2.0);
  EdgePoints out;
  for (const cv::Point2d& p : base) out.tried.push_back((p - a).dot(d) / (len * len));
  if (base.size() < 8) return out;
  constexpr double kStep = 0.5;  // px between samples across the side
  const int half = static_cast<int>(std::ceil(window / kStep)) + 4;
  std::vector<double> offs;
  for (int k = -half; k <= half; ++k) offs.push_back(k * kStep);
  const std::vector<double> tans{-2 * unit, -unit, 0.0, unit, 2 * unit};
  const cv::Mat s = sample_across(image, base, t, n, tans, offs);
  const int n_off = static_cast<int>(offs.size()), n_tan = static_cast<int>(tans.size()), cn = image.channels();
  const int rows = static_cast<int>(base.size());
  const double sigma = smooth_px * std::max(1.0, unit) / kStep;  // in samples
  const int ks = 2 * static_cast<int>(std::ceil(3 * sigma)) + 1;
  // Profiles across the side, averaged along it, per channel; smoothed and differentiated across.
  cv::Mat prof(rows, n_off, CV_MAKETYPE(CV_32F, cn), cv::Scalar::all(0));
  for (int i = 0; i < rows; ++i) {
    const uchar* src = s.ptr<uchar>(i);
    float* dst = prof.ptr<float>(i);
    for (int j = 0; j < n_tan; ++j)
      for (int k = 0; k < n_off * cn; ++k) dst[k] += src[j * n_off * cn + k] / static_cast<float>(n_tan);
  }
  cv::GaussianBlur(prof, prof, cv::Size(ks, 1), sigma, 0, cv::BORDER_REPLICATE);
  cv::Mat d3;
  cv::Sobel(prof, d3, CV_32F, 1, 0, 1, 1.0 / (2 * kStep), 0, cv::BORDER_REPLICATE);  // grey levels per px
  const cv::Mat sq = d3.mul(d3);
  cv::Mat mag2;
  cv::reduce(sq.reshape(1, rows * n_off), mag2, 1, cv::REDUCE_SUM);  // sum over the channels
  mag2 = mag2.reshape(1, rows);
  cv::Mat der;
  cv::sqrt(mag2, der);
  const int lo = half - static_cast<int>(std::floor(window / kStep)),
            hi = half + static_cast<int>(std::floor(window / kStep));
  for (int i = 0; i < der.rows; ++i) {
    const float* g = der.ptr<float>(i);
    int best = -1;
    float best_v = 0.0f;
    for (int k = std::max(lo, 1); k <= std::min(hi, n_off - 2); ++k) {
      if (g[k] > best_v) {
        best_v = g[k];
        best = k;
      }
    }
    if (nearest && best >= 0) {  // the peak nearest the side among those at least 0.4 x the strongest
      for (int k = std::max(lo, 1) + 1; k < std::min(hi, n_off - 2); ++k) {
        if (g[k] >= 0.4f * best_v && g[k] >= g[k - 1] && g[k] > g[k + 1] && std::abs(k - half) < std::abs(best - half))
          best = k;
      }
      best_v = g[best];
    }
    if (best <= std::max(lo, 1) || best >= std::min(hi, n_off - 2) || best_v < 2.0f)
      continue;  // no peak inside the window
    const double y0 = g[best - 1], y1 = g[best], y2 = g[best + 1];
    const double den = y0 - 2 * y1 + y2;
    const double delta = den < 0 ? std::clamp(0.5 * (y0 - y2) / den, -0.5, 0.5) : 0.0;
    const double o = offs[static_cast<std::size_t>(best)] + delta * kStep;
    const cv::Point2d p = base[static_cast<std::size_t>(i)] + o * n;
    out.pts.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
    out.t.push_back(out.tried[static_cast<std::size_t>(i)]);
    out.strength.push_back(best_v);
  }
  return out;
}

Line fit(const std::vector<cv::Point2f>& pts, int dist) {
  cv::Vec4f l;
  cv::fitLine(pts, l, dist, 0, 0.01, 0.01);
  return {{l[2], l[3]}, {l[0], l[1]}};
}

double distance(const Line& l, cv::Point2d p) { return std::abs(cross(l.d, p - l.p)); }

/// The side a → b refined at full resolution: edge points within ±window of it (at each position the change nearest
/// the side among those at least 0.4 x the strongest, so a stronger edge in the picture just inside its border
/// does not pull the side in), a robust (Huber) line fit, edge
/// points again within a narrow window of that line, and a least-squares fit to those within `inlier_px` of a
/// second Huber fit. Empty when too few edge points were found.
std::optional<Line> refine_side(const cv::Mat& image, cv::Point2d a, cv::Point2d b, double window, double unit) {
  EdgePoints e = edge_points(image, a, b, window, unit, 0.05, 0.95, true);
  if (e.pts.size() < 8) return std::nullopt;
  Line l = fit(e.pts, cv::DIST_HUBER);
  // Narrow pass along the fitted line, between the projections of a and b.
  const cv::Point2d a2 = l.p + (a - l.p).dot(l.d) * l.d, b2 = l.p + (b - l.p).dot(l.d) * l.d;
  e = edge_points(image, a2, b2, 1.5 + 1.5 * unit, unit);
  if (e.pts.size() < 8) return std::nullopt;
  l = fit(e.pts, cv::DIST_HUBER);
  const double inlier_px = std::max(0.75, 0.75 * unit);
  std::vector<cv::Point2f> in;
  for (const cv::Point2f& p : e.pts)
    if (distance(l, p) <= inlier_px) in.push_back(p);
  if (in.size() < 8) return std::nullopt;
  l = fit(in, cv::DIST_L2);
  if (l.d.dot(b - a) < 0) l.d = -l.d;
  return l;
}

/// How well the stretch [t0, t1] of the side a → b of a found quadrilateral is backed by an edge: the share of
/// positions along it where the change across it nearest the side (edge_points with `nearest`, within ±4 px)
/// lies within 1.25 px of it and is at least 0.3 x `typical`. `typical`: when zero, set to the median strength of
/// the changes found (so a weak page edge counts where it is as strong as elsewhere along the side).
double side_support(const cv::Mat& image, cv::Point2d a, cv::Point2d b, double unit, double t0, double t1,
                    float* typical) {
  const EdgePoints e = edge_points(image, a, b, 4.0 * std::max(1.0, unit), unit, t0, t1, true, 1.0);
  if (e.tried.size() < 4 || e.pts.empty()) return 0.0;
  float least = 0.0f;
  if (*typical > 0.0f) {
    least = 0.3f * *typical;
  } else {
    std::vector<float> v = e.strength;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    *typical = v[v.size() / 2];
    least = 0.3f * *typical;
  }
  const Line l{a, (b - a) / cv::norm(b - a)};
  const double inlier_px = std::max(1.25, 0.75 * unit);
  int hits = 0;
  for (std::size_t i = 0; i < e.pts.size(); ++i) hits += distance(l, e.pts[i]) <= inlier_px && e.strength[i] >= least;
  return static_cast<double>(hits) / e.tried.size();
}

/// Contrast across the sides of a quadrilateral (corners clockwise on screen; each side a → b, or the part of it
/// inside the frame) in `image` (grey, or BGR: the distance between mean colours): per side not on the frame's
/// edge, in stretches of an eighth of the side, the difference between the mean of a band just inside
/// the quad and the mean of a band just outside it; bands `depth` px deep starting `gap` px from the side. Where
/// the side lies nearer the frame's edge than that, the outer band is cut short at the frame's edge (a page whole
/// in the frame but close to its edge shows only a strip of the background beyond its side); a position whose
/// outer band would start outside the frame is not measured.
struct SideContrast {
  std::array<std::vector<double>, 4> stretches;  ///< per side, the contrast of each stretch measured
  /// Mean over all stretches measured; negative when none.
  double mean() const {
    double sum = 0.0;
    std::size_t n = 0;
    for (const auto& v : stretches) {
      for (double x : v) sum += x;
      n += v.size();
    }
    return n > 0 ? sum / static_cast<double>(n) : -1.0;
  }
};

using Segments = std::array<std::pair<cv::Point2d, cv::Point2d>, 4>;

SideContrast border_contrast(const cv::Mat& image, const Segments& sides, const std::array<bool, 4>& on_frame,
                             double gap, double depth) {
  constexpr int kStretches = 8, kPerStretch = 5, kDepths = 4;
  std::vector<double> offs;
  for (int k = 0; k < kDepths; ++k) offs.push_back(gap + depth * k / (kDepths - 1));     // outward (positive) ...
  for (int k = 0; k < kDepths; ++k) offs.push_back(-(gap + depth * k / (kDepths - 1)));  // ... and inward
  const double reach = gap + depth;
  const int cn = image.channels();
  SideContrast out;
  for (std::size_t s = 0; s < 4; ++s) {
    if (on_frame[s]) continue;
    const auto [a, b] = sides[s];
    const cv::Point2d d = b - a;
    const double len = std::hypot(d.x, d.y);
    if (len < 1.0) continue;
    const cv::Point2d t = d / len, n(t.y, -t.x);  // n: outward for corners clockwise on screen
    const auto in_frame = [&](cv::Point2d x) {
      return x.x >= 0 && x.y >= 0 && x.x <= image.cols - 1 && x.y <= image.rows - 1;
    };
    for (int st = 0; st < kStretches; ++st) {
      std::vector<cv::Point2d> base;
      for (int i = 0; i < kPerStretch; ++i) {
        const double u = 0.08 + 0.84 * (st * kPerStretch + i + 0.5) / (kStretches * kPerStretch);
        const cv::Point2d p = a + u * d;
        if (in_frame(p + gap * n) && in_frame(p - reach * n)) base.push_back(p);
      }
      if (base.size() < 2) continue;
      const cv::Mat v = sample_across(image, base, t, n, {0.0}, offs);
      double dist2 = 0.0;
      for (int c = 0; c < cn; ++c) {
        double out_sum = 0.0, in_sum = 0.0;
        int out_count = 0;
        for (int i = 0; i < v.rows; ++i) {
          const uchar* r = v.ptr<uchar>(i);
          for (int k = 0; k < kDepths; ++k) {
            in_sum += r[(kDepths + k) * cn + c];
            if (!in_frame(base[static_cast<std::size_t>(i)] + offs[static_cast<std::size_t>(k)] * n))
              continue;  // beyond the frame's edge
            out_sum += r[k * cn + c];
            ++out_count;
          }
        }
        const double diff = out_sum / out_count - in_sum / (v.rows * kDepths);
        dist2 += diff * diff;
      }
      out.stretches[s].push_back(std::sqrt(dist2));
    }
  }
  return out;
}

/// A candidate quadrilateral from the downscaled frame, corners in order, and which of its sides lie on the
/// frame's edge (top, right, bottom or left).
struct Candidate {
  Quad q;
  std::array<int, 4> frame_edge{-1, -1, -1, -1};  ///< per side: the frame edge (0 top, 1 right, 2 bottom, 3 left) or -1
  double area = 0.0;
};

/// The frame edge (0 top, 1 right, 2 bottom, 3 left) both ends of a → b lie within `tol` of, or -1.
int frame_edge_of(cv::Point2d a, cv::Point2d b, cv::Size size, double tol) {
  const double r = size.width - 1.0, btm = size.height - 1.0;
  if (a.y <= tol && b.y <= tol) return 0;
  if (a.x >= r - tol && b.x >= r - tol) return 1;
  if (a.y >= btm - tol && b.y >= btm - tol) return 2;
  if (a.x <= tol && b.x <= tol) return 3;
  return -1;
}

void add_quad(const Quad& quad, double min_area, cv::Size size, std::vector<Candidate>& out) {
  std::vector<cv::Point2f> poly;
  for (const cv::Point2d& p : quad) {
    const double beyond = 0.25 * std::max(size.width, size.height);
    if (!finite(p) || p.x < -beyond || p.y < -beyond || p.x > size.width + beyond || p.y > size.height + beyond) return;
    poly.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
  }
  if (!cv::isContourConvex(poly)) return;
  const double area = visible_area(quad, size);
  if (area < min_area) return;
  Candidate c;
  c.q = order_corners(quad);
  c.area = area;
  for (std::size_t i = 0; i < 4; ++i) c.frame_edge[i] = frame_edge_of(c.q[i], c.q[(i + 1) % 4], size, 3.0);
  out.push_back(c);
}

/// Quadrilaterals from a convex polygon of 4 to 6 corners: itself when it has 4; else its sides' lines with the
/// shortest dropped until 4 remain, intersected in turn (a corner the outline missed, cut off by a shadow or a
/// dark stretch of the page's edge, is restored by extending its neighbouring sides).
void quads_from_polygon(const std::vector<cv::Point>& poly, double min_area, cv::Size size,
                        std::vector<Candidate>& out) {
  const std::size_t n = poly.size();
  if (n < 4 || n > 6) return;
  if (n == 4) {
    add_quad({cv::Point2d(poly[0]), cv::Point2d(poly[1]), cv::Point2d(poly[2]), cv::Point2d(poly[3])}, min_area, size,
             out);
    return;
  }
  std::vector<std::size_t> keep(n);
  for (std::size_t i = 0; i < n; ++i) keep[i] = i;
  const auto side_len = [&](std::size_t i) { return cv::norm(cv::Point2d(poly[(i + 1) % n]) - cv::Point2d(poly[i])); };
  while (keep.size() > 4) {
    const auto shortest = std::min_element(keep.begin(), keep.end(),
                                           [&](std::size_t a, std::size_t b) { return side_len(a) < side_len(b); });
    keep.erase(shortest);
  }
  std::array<Line, 4> lines;
  for (std::size_t k = 0; k < 4; ++k) {
    const cv::Point2d a(poly[keep[k]]), b(poly[(keep[k] + 1) % n]);
    const double len = cv::norm(b - a);
    if (len < 1.0) return;
    lines[k] = {a, (b - a) / len};
  }
  Quad q;
  for (std::size_t k = 0; k < 4; ++k) {
    const auto p = intersect(lines[(k + 3) % 4], lines[k]);
    if (!p) return;
    q[k] = *p;
  }
  add_quad(q, min_area, size, out);
}

/// Quadrilaterals from the outlines in a binary map: each outline's convex hull (which closes a page cut off by
/// the frame's edge and ignores what the page shows inside) and the outline itself, each simplified with
/// Douglas–Peucker (cv::approxPolyDP) at a few tolerances until four corners remain.
void quads_from_map(const cv::Mat& map, double min_area, std::vector<Candidate>& out) {
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(map, contours, cv::RETR_LIST, cv::CHAIN_APPROX_SIMPLE);
  for (const auto& c : contours) {
    if (cv::boundingRect(c).area() < min_area) continue;
    std::vector<cv::Point> hull;
    cv::convexHull(c, hull);
    if (cv::contourArea(hull) < min_area) continue;
    for (const std::vector<cv::Point>* shape : {static_cast<const std::vector<cv::Point>*>(&hull), &c}) {
      const double perimeter = cv::arcLength(*shape, true);
      for (double f : {0.015, 0.025, 0.04, 0.06}) {
        std::vector<cv::Point> poly;
        cv::approxPolyDP(*shape, poly, f * perimeter, true);
        if (poly.size() < 4) break;
        if (shape == &hull || poly.size() == 4) quads_from_polygon(poly, min_area, map.size(), out);
        if (poly.size() == 4) break;
      }
    }
  }
}

/// A straight line gathered from collinear edge segments: unit normal n (angle in [0, π)), offset rho = n·p,
/// and the stretches along it (parameter along (−n.y, n.x)) that the segments cover.
struct SegmentLine {
  cv::Point2d n;
  double rho = 0.0;
  std::vector<std::pair<double, double>> spans;
  double covered = 0.0;  ///< total length of the union of spans
  int frame_edge = -1;   ///< 0..3 for the frame's own edges (top, right, bottom, left), else -1
};

/// Length of the union of `spans` within [t0, t1].
double covered_length(std::vector<std::pair<double, double>> spans, double t0, double t1) {
  std::sort(spans.begin(), spans.end());
  double total = 0.0, reach = t0;
  for (const auto& [a, b] : spans) {
    const double lo = std::max(a, reach), hi = std::min(b, t1);
    if (hi > lo) total += hi - lo;
    reach = std::max(reach, std::min(b, t1));
  }
  return total;
}

/// Groups segments (longest first) into lines: a segment joins a line when it is within 5° of it and both its ends
/// are within `tol` px of it; the line is then fitted again (least squares) to points along all its segments.
std::vector<SegmentLine> group_segments(std::vector<std::pair<cv::Point2d, cv::Point2d>> segs, double tol) {
  std::sort(segs.begin(), segs.end(),
            [](const auto& x, const auto& y) { return cv::norm(x.second - x.first) > cv::norm(y.second - y.first); });
  const double cos_tol = std::cos(5.0 * CV_PI / 180.0);
  std::vector<SegmentLine> lines;
  std::vector<std::vector<cv::Point2f>> members;  // per line, points along its segments
  for (const auto& [a, b] : segs) {
    const double len = cv::norm(b - a);
    if (len < 1.0) continue;
    const cv::Point2d d = (b - a) / len;
    const auto joined = std::find_if(lines.begin(), lines.end(), [&](const SegmentLine& l) {
      return std::abs(l.n.dot(cv::Point2d(-d.y, d.x))) >= cos_tol && std::abs(l.n.dot(a) - l.rho) <= tol &&
             std::abs(l.n.dot(b) - l.rho) <= tol;
    });
    const auto k = static_cast<std::size_t>(joined - lines.begin());
    if (joined == lines.end()) {
      lines.emplace_back();
      members.emplace_back();
    }
    SegmentLine& l = lines[k];
    const int steps = std::max(1, static_cast<int>(len / 2.0));
    for (int i = 0; i <= steps; ++i) {
      const cv::Point2d p = a + (static_cast<double>(i) / steps) * (b - a);
      members[k].emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
    }
    const Line fitted = fit(members[k], cv::DIST_L2);
    l.n = {-fitted.d.y, fitted.d.x};
    if (l.n.y < 0 || (l.n.y == 0 && l.n.x < 0)) l.n = -l.n;
    l.rho = l.n.dot(fitted.p);
  }
  // Spans along each line's final direction.
  for (std::size_t k = 0; k < lines.size(); ++k) {
    SegmentLine& l = lines[k];
    const cv::Point2d t(-l.n.y, l.n.x);
    l.spans.clear();
    std::vector<double> proj;
    for (const cv::Point2f& p : members[k]) proj.push_back(t.dot(cv::Point2d(p)));
    // Consecutive points of one segment are 2 px or less apart; a larger jump starts another segment.
    std::size_t start = 0;
    for (std::size_t i = 1; i <= proj.size(); ++i) {
      if (i == proj.size() || cv::norm(cv::Point2d(members[k][i]) - cv::Point2d(members[k][i - 1])) > 2.5) {
        const auto [lo, hi] = std::minmax_element(proj.begin() + static_cast<std::ptrdiff_t>(start),
                                                  proj.begin() + static_cast<std::ptrdiff_t>(i));
        l.spans.emplace_back(*lo, *hi);
        start = i;
      }
    }
    l.covered = covered_length(l.spans, -1e18, 1e18);
  }
  return lines;
}

/// Quadrilaterals bounded by four of the 24 longest straight lines (or by up to two of the frame's own edges, for a
/// page cut off by them): two roughly parallel pairs (within 35°) crossing at more than 45°, every side not on the
/// frame's edge covered at least 20 % by edge segments, corners at most a quarter of the frame's size outside it (a
/// page cut off at a corner). This finds a page whose outline no single edge map closes: broken by weak stretches,
/// or tied to a textured background.
void quads_from_lines(const std::vector<std::pair<cv::Point2d, cv::Point2d>>& segs, cv::Size size, double min_area,
                      std::vector<Candidate>& out) {
  const double shorter = std::min(size.width, size.height);
  std::vector<SegmentLine> lines = group_segments(segs, std::max(2.5, 0.006 * shorter));
  std::sort(lines.begin(), lines.end(),
            [](const SegmentLine& a, const SegmentLine& b) { return a.covered > b.covered; });
  lines.erase(
      std::remove_if(lines.begin(), lines.end(), [&](const SegmentLine& l) { return l.covered < 0.1 * shorter; }),
      lines.end());
  if (lines.size() > 24) lines.resize(24);
  const double w = size.width - 1.0, h = size.height - 1.0;
  const std::array<std::pair<cv::Point2d, double>, 4> frame{{{{0, 1}, 0.0}, {{1, 0}, w}, {{0, 1}, h}, {{1, 0}, 0.0}}};
  for (int e = 0; e < 4; ++e) {
    SegmentLine l;
    l.n = frame[static_cast<std::size_t>(e)].first;
    l.rho = frame[static_cast<std::size_t>(e)].second;
    l.frame_edge = e;
    lines.push_back(l);
  }
  const std::size_t n = lines.size();
  const double beyond = 0.25 * std::max(w, h);  // a page cut off at a corner has that corner outside the frame
  const auto as_line = [](const SegmentLine& l) { return Line{l.rho * l.n, {-l.n.y, l.n.x}}; };
  const double cos_parallel = std::cos(35.0 * CV_PI / 180.0), cos_cross = std::cos(45.0 * CV_PI / 180.0);
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if (std::abs(lines[i].n.dot(lines[j].n)) >= cos_parallel) pairs.emplace_back(i, j);
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    for (std::size_t r = p + 1; r < pairs.size(); ++r) {
      const auto [i, j] = pairs[p];
      const auto [k, l] = pairs[r];
      if (i == k || i == l || j == k || j == l) continue;
      if (std::abs(lines[i].n.dot(lines[k].n)) > cos_cross) continue;
      const int on_frame = (lines[i].frame_edge >= 0) + (lines[j].frame_edge >= 0) + (lines[k].frame_edge >= 0) +
                           (lines[l].frame_edge >= 0);
      if (on_frame > 2) continue;
      const std::array<std::size_t, 4> side{i, k, j, l};  // around the quad: i, k, j, l; corner s joins side s-1 and s
      Quad q;
      bool ok = true;
      for (std::size_t s = 0; s < 4 && ok; ++s) {
        const auto c = intersect(as_line(lines[side[(s + 3) % 4]]), as_line(lines[side[s]]));
        ok = c && c->x >= -beyond && c->y >= -beyond && c->x <= w + beyond && c->y <= h + beyond;
        if (ok) q[s] = *c;
      }
      if (!ok || visible_area(q, size) < min_area) continue;
      for (std::size_t s = 0; s < 4 && ok; ++s) {
        const SegmentLine& sl = lines[side[s]];
        if (sl.frame_edge >= 0) continue;
        const cv::Point2d t(-sl.n.y, sl.n.x);
        const double t0 = std::min(t.dot(q[s]), t.dot(q[(s + 1) % 4])),
                     t1 = std::max(t.dot(q[s]), t.dot(q[(s + 1) % 4]));
        ok = t1 - t0 > 1.0 && covered_length(sl.spans, t0, t1) >= 0.2 * (t1 - t0);
      }
      if (ok) add_quad(q, min_area, size, out);
    }
  }
}

/// Candidates (in downscaled px) from six edge maps of the half-size copy (after OpenCV's squares.cpp sample):
/// Canny edges (of the colour image where there is one: the largest gradient of its channels) at three thresholds
/// after two blurs (σ 1.5 and 2.5 px of the half-size copy, 3 and 5 of the downscaled frame: they wash out the fine
/// texture of a table or cloth, which would otherwise tie the page's outline to the background). Each map gives
/// quadrilaterals two ways: quads_from_map on the dilated map, and quads_from_lines on the long straight stretches of
/// all the maps together (cv::HoughLinesP). Sorted by area, largest first, near-duplicates dropped.
std::vector<Candidate> candidates(const cv::Mat& small, const cv::Mat& half, double min_area) {
  std::vector<Candidate> out;
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  const double to_small_x = static_cast<double>(small.cols) / half.cols,
               to_small_y = static_cast<double>(small.rows) / half.rows;
  const double half_area = min_area / (to_small_x * to_small_y);
  std::vector<std::pair<cv::Point2d, cv::Point2d>> segments;  // in downscaled-frame px
  for (double sigma : {1.5, 2.5}) {
    cv::Mat blurred;
    cv::GaussianBlur(half, blurred, cv::Size(0, 0), sigma);
    for (double hi : {30.0, 60.0, 120.0}) {
      cv::Mat edges;
      cv::Canny(blurred, edges, hi / 2, hi);
      std::vector<cv::Vec4i> segs;
      const double shorter = std::min(edges.cols, edges.rows);
      cv::HoughLinesP(edges, segs, 1, CV_PI / 180, static_cast<int>(0.05 * shorter), 0.06 * shorter, 0.015 * shorter);
      for (const cv::Vec4i& sg : segs)
        segments.emplace_back(cv::Point2d((sg[0] + 0.5) * to_small_x - 0.5, (sg[1] + 0.5) * to_small_y - 0.5),
                              cv::Point2d((sg[2] + 0.5) * to_small_x - 0.5, (sg[3] + 0.5) * to_small_y - 0.5));
      cv::dilate(edges, edges, kernel);
      std::vector<Candidate> found;
      quads_from_map(edges, half_area, found);
      for (Candidate& c : found) {
        for (cv::Point2d& p : c.q) p = {(p.x + 0.5) * to_small_x - 0.5, (p.y + 0.5) * to_small_y - 0.5};
        c.area *= to_small_x * to_small_y;
        for (std::size_t i = 0; i < 4; ++i)
          c.frame_edge[i] = frame_edge_of(c.q[i], c.q[(i + 1) % 4], small.size(), 4.0);
        out.push_back(c);
      }
    }
  }
  quads_from_lines(segments, small.size(), min_area, out);
  std::sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) { return a.area > b.area; });
  // Near-duplicates (every corner within 2 px) add nothing.
  std::vector<Candidate> unique;
  for (const Candidate& c : out) {
    const bool dup = std::any_of(unique.begin(), unique.end(), [&](const Candidate& u) {
      for (std::size_t i = 0; i < 4; ++i)
        if (cv::norm(u.q[i] - c.q[i]) > 2.0) return false;
      return true;
    });
    if (!dup) unique.push_back(c);
  }
  return unique;
}

/// The frame edge `e` (0 top, 1 right, 2 bottom, 3 left) as a line in frame pixels: the outer boundary of the
/// outermost pixels (half a pixel beyond their centres), directed clockwise on screen.
Line frame_line(int e, cv::Size size) {
  const double r = size.width - 0.5, b = size.height - 0.5;
  switch (e) {
    case 0:
      return {{-0.5, -0.5}, {1, 0}};
    case 1:
      return {{r, -0.5}, {0, 1}};
    case 2:
      return {{r, b}, {-1, 0}};
    default:
      return {{-0.5, b}, {0, -1}};
  }
}

/// The gradient of the half-size copy of the downscaled frame (blurred, σ 1 px): Sobel 3 x 3 d/dx and d/dy (about
/// 8 x grey levels per px), CV_16S with one channel per colour channel.
struct Gradient {
  cv::Mat gx, gy;
  double to_half_x = 0.5, to_half_y = 0.5;  ///< half-size px per downscaled px
  /// At pixel (x, y) of the half-size copy, the gradient of the channel where it is largest.
  cv::Point2d at(int x, int y) const {
    const short* px = gx.ptr<short>(y) + static_cast<std::ptrdiff_t>(x) * gx.channels();
    const short* py = gy.ptr<short>(y) + static_cast<std::ptrdiff_t>(x) * gy.channels();
    int best = 0, best_m = -1;
    for (int c = 0; c < gx.channels(); ++c) {
      const int m = px[c] * px[c] + py[c] * py[c];
      if (m > best_m) best_m = m, best = c;
    }
    return {static_cast<double>(px[best]), static_cast<double>(py[best])};
  }
};

Gradient gradient_of(const cv::Mat& half, cv::Size small) {
  cv::Mat blurred;
  cv::GaussianBlur(half, blurred, cv::Size(0, 0), 1.0);
  Gradient g;
  cv::Sobel(blurred, g.gx, CV_16S, 1, 0, 3);
  cv::Sobel(blurred, g.gy, CV_16S, 0, 1, 3);
  g.to_half_x = static_cast<double>(half.cols) / small.width;
  g.to_half_y = static_cast<double>(half.rows) / small.height;
  return g;
}

/// A quick check of a candidate (in downscaled px) on the half-size copy: the least, over its sides not on the
/// frame's edge, share of points along the side with a gradient across it (within 1.5 px + 1 % of the side's length
/// of it, at least `min_grad`, pointing within ~37° of the side's normal).
double quick_support(const Gradient& grad, const Candidate& c, double min_grad) {
  double least = 1.0;
  for (std::size_t s = 0; s < 4; ++s) {
    if (c.frame_edge[s] >= 0) continue;
    const cv::Point2d a = c.q[s], b = c.q[(s + 1) % 4];
    const double len = cv::norm(b - a);
    if (len < 4.0) return 0.0;
    const cv::Point2d t = (b - a) / len, n(t.y, -t.x);
    const int count = std::clamp(static_cast<int>(len / 3.0), 8, 80);
    int hits = 0, tried = 0;
    for (int i = 0; i < count; ++i) {
      const cv::Point2d p = a + (0.05 + 0.9 * (i + 0.5) / count) * (b - a);
      bool hit = false, inside = false;
      const double reach = 1.5 + 0.01 * len;
      for (double o = -reach; o <= reach; o += 1.0) {
        const cv::Point2d q = p + o * n;
        const int x = static_cast<int>(std::lround((q.x + 0.5) * grad.to_half_x - 0.5));
        const int y = static_cast<int>(std::lround((q.y + 0.5) * grad.to_half_y - 0.5));
        if (x < 0 || y < 0 || x >= grad.gx.cols || y >= grad.gx.rows) continue;
        inside = true;
        const cv::Point2d g = grad.at(x, y);
        const double across = std::abs(g.dot(n)), along = std::abs(g.dot(t));
        if (across >= min_grad && across >= 1.33 * along) hit = true;
      }
      tried += inside ? 1 : 0;
      hits += hit ? 1 : 0;
    }
    if (tried < 4) return 0.0;
    least = std::min(least, static_cast<double>(hits) / tried);
  }
  return least;
}

void check_params(const PageParams& p) {
  if (!(p.min_area_fraction > 0.0 && p.min_area_fraction < 1.0))
    throw hk::ArgumentError("find_page: min_area_fraction must be in (0, 1)");
  if (!(p.min_contrast >= 0.0 && p.min_contrast <= 255.0))
    throw hk::ArgumentError("find_page: min_contrast must be in [0, 255]");
  if (p.max_side_px < 64) throw hk::ArgumentError("find_page: max_side_px must be at least 64");
}

/// The frame being searched, and how the downscaled copy maps onto it.
struct Frame {
  const cv::Mat& image;  ///< CV_8UC3 or CV_8UC1
  cv::Mat grey;
  double sx, sy;         ///< frame px per downscaled px, along x and y
  double unit;           ///< the larger of sx, sy
  double same_side_tol;  ///< 1 % of the frame's diagonal [px]: sides of two quadrilaterals this close are one side
  double band_start;     ///< the contrast bands start this far off a side: 1.5 + 1.5 x unit [px]
  double area;           ///< [px²]
};

/// A candidate that passed: the page it would be, and the colour contrast across each of its sides (in the order of
/// det.corners_px: side s runs from corner s to corner s + 1; negative on the frame's edge).
struct Found {
  PageDetection det;
  std::array<std::vector<double>, 4> side_contrast;  ///< per side, per stretch (empty on the frame's edge)
};

/// Sides already refined (candidates share sides: the same page outline is found in several edge maps).
struct RefinedSide {
  cv::Point2d a, b;          ///< the candidate's side
  std::optional<Line> line;  ///< the refined line, empty when it failed
};

/// Quadrilaterals already checked, after refinement.
struct Memo {
  std::vector<RefinedSide> sides;
  std::vector<Quad> quads;
};

/// The lines of a candidate's sides at full resolution: a side on the frame's edge is that edge; every other side
/// is refined (refine_side, shared through `memo` with candidates that have the same side) and must be an edge over
/// most of the candidate's side. Empty when a side fails.
std::optional<std::array<Line, 4>> refined_lines(const Frame& f, const Candidate& c, Memo& memo) {
  const double unit = f.unit;
  Quad full;
  for (std::size_t i = 0; i < 4; ++i) full[i] = {(c.q[i].x + 0.5) * f.sx - 0.5, (c.q[i].y + 0.5) * f.sy - 0.5};
  std::array<Line, 4> lines;
  for (std::size_t s = 0; s < 4; ++s) {
    if (c.frame_edge[s] >= 0) {
      lines[s] = frame_line(c.frame_edge[s], f.image.size());
      continue;
    }
    const cv::Point2d a = full[s], b = full[(s + 1) % 4];
    const double same = 2.0 * unit;
    auto known = std::find_if(memo.sides.begin(), memo.sides.end(), [&](const RefinedSide& r) {
      return (cv::norm(r.a - a) <= same && cv::norm(r.b - b) <= same) ||
             (cv::norm(r.a - b) <= same && cv::norm(r.b - a) <= same);
    });
    if (known == memo.sides.end()) {
      const double window = std::max(4.0 * unit + 2.0, 0.04 * cv::norm(b - a));
      std::optional<Line> l = refine_side(f.image, a, b, window, unit);
      // Early out: the refined line, over the candidate's side, must be mostly an edge.
      if (l) {
        const cv::Point2d pa = l->p + (a - l->p).dot(l->d) * l->d, pb = l->p + (b - l->p).dot(l->d) * l->d;
        float typical = 0.0f;
        if (side_support(f.image, pa, pb, unit, 0.1, 0.9, &typical) < 0.5) l.reset();
      }
      memo.sides.push_back({a, b, l});
      known = memo.sides.end() - 1;
    }
    if (!known->line) return std::nullopt;
    std::optional<Line> l = known->line;
    if (l->d.dot(b - a) < 0) l->d = -l->d;
    lines[s] = *l;
  }
  return lines;
}

/// The corners where adjacent lines meet (corner i between lines i − 1 and i); empty when two are parallel.
std::optional<Quad> corners_of(const std::array<Line, 4>& lines) {
  Quad q;
  for (std::size_t i = 0; i < 4; ++i) {
    const auto p = intersect(lines[(i + 3) % 4], lines[i]);
    if (!p || !finite(*p)) return std::nullopt;
    q[i] = *p;
  }
  return q;
}

/// A side found nearer the frame's edge than the contrast test's outer band starts (both ends) shows too little of
/// the background beyond it to be told from that edge: it is taken as on the edge (the page may go on beyond it).
/// Returns whether a side was moved.
bool snap_to_frame(const Frame& f, const Quad& corners, std::array<Line, 4>& lines, std::array<bool, 4>& on_frame) {
  bool snapped = false;
  for (std::size_t s = 0; s < 4; ++s) {
    if (on_frame[s]) continue;
    const cv::Point2d half(0.5, 0.5);
    const int e =
        frame_edge_of(corners[s] + half, corners[(s + 1) % 4] + half, f.image.size() + cv::Size(1, 1), f.band_start);
    if (e < 0) continue;
    lines[s] = frame_line(e, f.image.size());
    on_frame[s] = snapped = true;
  }
  return snapped;
}

/// Whether `q` was checked already (every corner within `unit` of one of a checked quadrilateral's); if not, it is
/// remembered.
bool checked_before(Memo& memo, const Quad& q, double unit) {
  const bool seen = std::any_of(memo.quads.begin(), memo.quads.end(), [&](const Quad& old) {
    return std::all_of(q.begin(), q.end(), [&](cv::Point2d p) {
      return std::any_of(old.begin(), old.end(), [&](cv::Point2d r) { return cv::norm(p - r) <= unit; });
    });
  });
  if (!seen) memo.quads.push_back(q);
  return seen;
}

/// The part of `q` inside the frame [px²] when it can be a page: corners inside the frame or, for a page cut off at
/// a corner, not far beyond it; that part at least min_area_fraction of the frame; convex. Empty otherwise.
std::optional<double> page_shaped(const Frame& f, const Quad& q, const PageParams& params) {
  const cv::Mat& frame = f.image;
  const double beyond = 0.25 * std::max(frame.cols, frame.rows);
  if (!std::all_of(q.begin(), q.end(), [&](cv::Point2d p) {
        return p.x >= -beyond && p.y >= -beyond && p.x <= frame.cols - 1 + beyond && p.y <= frame.rows - 1 + beyond;
      }))
    return std::nullopt;
  const double area = visible_area(q, frame.size());
  if (signed_area(q) <= 0.0 || area / f.area < params.min_area_fraction) return std::nullopt;
  std::vector<cv::Point2f> poly;
  for (const cv::Point2d& p : q) poly.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
  if (!cv::isContourConvex(poly)) return std::nullopt;
  return area;
}

/// The visible part of each side of `q`, and whether it ends at the frame's edge (at a side on the frame's edge, or
/// where the side leaves the frame) rather than at a corner of the page, per end.
struct VisibleSides {
  Segments segments;
  std::array<std::pair<bool, bool>, 4> ends_at_frame{};
};

/// The sides of `q` as far as they are in the frame; empty when a side off the frame's edge shows less than 3 % of
/// the frame's diagonal.
std::optional<VisibleSides> visible_sides(const cv::Size& frame, const Quad& q, const std::array<bool, 4>& on_frame) {
  VisibleSides v;
  for (std::size_t s = 0; s < 4; ++s) {
    const cv::Point2d a = q[s], b = q[(s + 1) % 4];
    v.segments[s] = {a, b};
    if (on_frame[s]) continue;
    const auto t = clip_segment(a, b, frame, 0.0);
    if (!t || (t->second - t->first) * cv::norm(b - a) < 0.03 * std::hypot(frame.width, frame.height))
      return std::nullopt;
    v.segments[s] = {a + t->first * (b - a), a + t->second * (b - a)};
    v.ends_at_frame[s] = {on_frame[(s + 3) % 4] || t->first > 0.0, on_frame[(s + 1) % 4] || t->second < 1.0};
  }
  return v;
}

/// Every side off the frame's edge backed by an edge along most of its length (60 %), and, where it meets the frame's
/// edge, over 50 % of its last 10 % (or 15 px) from 2 px inside the frame. A page cut off by the frame shows its sides
/// right up to the frame's edge: two sides of a page and two edges of the frame make a larger, false quadrilateral
/// whose sides run on past the page's corners, over the background, to the frame.
bool backed_by_edges(const Frame& f, const VisibleSides& v, const std::array<bool, 4>& on_frame) {
  const cv::Mat& frame = f.image;
  const double unit = f.unit;
  for (std::size_t s = 0; s < 4; ++s) {
    const auto [a, b] = v.segments[s];
    if (on_frame[s]) continue;
    float typical = 0.0f;
    if (side_support(frame, a, b, unit, 0.05, 0.95, &typical) < 0.6) return false;
    // The ends at the frame's edge from where the edge is looked for (2 px inside the frame), so that a side that
    // meets the frame's edge at a slant is looked at along its whole last stretch.
    const auto inner = clip_segment(a, b, frame.size(), 2.0);
    if (!inner) return false;
    const cv::Point2d ia = a + inner->first * (b - a), ib = a + inner->second * (b - a);
    const double len = cv::norm(ib - ia), stretch = std::max(0.1, 15.0 * unit / len), tip = std::min(0.02, 3.0 / len);
    if (v.ends_at_frame[s].first && side_support(frame, ia, ib, unit, tip, stretch, &typical) < 0.5) return false;
    if (v.ends_at_frame[s].second && side_support(frame, ia, ib, unit, 1.0 - stretch, 1.0 - tip, &typical) < 0.5)
      return false;
  }
  return true;
}

/// Every side off the frame's edge set off from its surroundings along most of its length (its median stretch of
/// colour contrast at least 1.5 x min_contrast: a grain line of a table or a fold of a cloth has the same stuff on
/// both sides), and at its end on the frame's edge as elsewhere (at least 0.35 x its median there: where a side
/// runs on past the page's corner along a grain of the background, the stretch at the frame has no step across it).
bool set_off(const SideContrast& colour, const VisibleSides& v, const std::array<bool, 4>& on_frame,
             const PageParams& params) {
  for (std::size_t s = 0; s < 4; ++s) {
    const std::vector<double>& c = colour.stretches[s];
    if (on_frame[s]) continue;
    if (c.size() < 2) return false;
    std::vector<double> sorted = c;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double median = sorted[sorted.size() / 2];
    if (median < 1.5 * params.min_contrast) return false;
    if (c.size() < 4) continue;
    if (v.ends_at_frame[s].first && c.front() < 0.35 * median) return false;
    if (v.ends_at_frame[s].second && c.back() < 0.35 * median) return false;
  }
  return true;
}

/// The page that `q` is, its corners in PageDetection's order with their sides' contrast, and the frame's edges it
/// is cut off at: where a corner lies on the edge or beyond, or nearer it than band_start (too near for the page's
/// outline to be told from the frame's edge, as snap_to_frame judges a side). A side on the frame's edge has its
/// corners there; a page lying whole in the frame, its outline seen between it and the edge, none.
Found page_found(const Frame& f, const Quad& q, const SideContrast& colour, double area, double contrast) {
  Found out;
  PageDetection& det = out.det;
  det.found = true;
  det.corners_px = order_corners(q);
  for (std::size_t s = 0; s < 4; ++s) {
    const auto k = static_cast<std::size_t>(std::find(q.begin(), q.end(), det.corners_px[s]) - q.begin());
    out.side_contrast[s] = colour.stretches[k];
  }
  det.area_fraction = area / f.area;
  det.contrast = contrast;
  const cv::Mat& frame = f.image;
  for (const cv::Point2d& p : q) {
    det.touches_frame[0] = det.touches_frame[0] || p.y < -0.5 + f.band_start;
    det.touches_frame[1] = det.touches_frame[1] || p.x > frame.cols - 0.5 - f.band_start;
    det.touches_frame[2] = det.touches_frame[2] || p.y > frame.rows - 0.5 - f.band_start;
    det.touches_frame[3] = det.touches_frame[3] || p.x < -0.5 + f.band_start;
  }
  return out;
}

/// Refines a candidate at full resolution and checks it; the page when it passes. Its sides' lines
/// (refined_lines), the corners where they meet (corners_of), sides too near the frame's edge taken as on it
/// (snap_to_frame; at most two sides may be on the frame's edge), a quadrilateral not checked before
/// (checked_before) that can be a page (page_shaped), whose visible sides (visible_sides) are backed by edges
/// (backed_by_edges), with a mean grey contrast across them of at least min_contrast (bands 3 px deep) and each set
/// off from its surroundings (set_off, colour bands 3 to 11 px deep, deeper than the grain of a table).
std::optional<Found> verify(const Frame& f, const Candidate& c, const PageParams& params, Memo& memo) {
  std::optional<std::array<Line, 4>> lines = refined_lines(f, c, memo);
  if (!lines) return std::nullopt;
  std::optional<Quad> corners = corners_of(*lines);
  if (!corners) return std::nullopt;
  std::array<bool, 4> on_frame{};
  for (std::size_t s = 0; s < 4; ++s) on_frame[s] = c.frame_edge[s] >= 0;
  const bool snapped = snap_to_frame(f, *corners, *lines, on_frame);
  if (std::count(on_frame.begin(), on_frame.end(), true) > 2) return std::nullopt;  // at least two sides the page's own
  if (snapped) corners = corners_of(*lines);
  if (!corners || checked_before(memo, *corners, f.unit)) return std::nullopt;
  const Quad& q = *corners;
  const std::optional<double> area = page_shaped(f, q, params);
  if (!area) return std::nullopt;
  const std::optional<VisibleSides> visible = visible_sides(f.image.size(), q, on_frame);
  if (!visible || !backed_by_edges(f, *visible, on_frame)) return std::nullopt;
  const double contrast = border_contrast(f.grey, visible->segments, on_frame, f.band_start, 3.0 * f.unit).mean();
  if (contrast < params.min_contrast) return std::nullopt;
  const SideContrast colour = border_contrast(f.image, visible->segments, on_frame, f.band_start, 8.0 * f.unit);
  if (!set_off(colour, *visible, on_frame, params)) return std::nullopt;
  return page_found(f, q, colour, *area, contrast);
}

/// Whether side `s` of quadrilateral `b` lies on a side of `a` (both its ends within `tol` px of that side's line,
/// directions within 3°).
bool shares_side(const Quad& a, const Quad& b, std::size_t s, double tol) {
  const cv::Point2d b0 = b[s], b1 = b[(s + 1) % 4];
  const cv::Point2d bd = (b1 - b0) / cv::norm(b1 - b0);
  for (std::size_t i = 0; i < 4; ++i) {
    const Line l{a[i], (a[(i + 1) % 4] - a[i]) / cv::norm(a[(i + 1) % 4] - a[i])};
    if (std::abs(l.d.dot(bd)) >= std::cos(3.0 * CV_PI / 180.0) && distance(l, b0) <= tol && distance(l, b1) <= tol)
      return true;
  }
  return false;
}

/// Mean colour of a band along the side a → b (positions 10 % to 90 % along it), from `gap` to `gap` + `depth` px
/// off it, outward (corners clockwise on screen) or inward.
cv::Scalar band_mean(const cv::Mat& image, cv::Point2d a, cv::Point2d b, double gap, double depth, bool outward) {
  const double len = cv::norm(b - a);
  const cv::Point2d t = (b - a) / len, n = (outward ? 1.0 : -1.0) * cv::Point2d(t.y, -t.x);
  std::vector<cv::Point2d> base;
  for (int i = 0; i < 16; ++i) {
    const cv::Point2d p = a + (0.1 + 0.8 * i / 15.0) * (b - a);
    const cv::Point2d far = p + (gap + depth) * n;
    if (p.x >= 0 && p.y >= 0 && p.x <= image.cols - 1 && p.y <= image.rows - 1 && far.x >= 0 && far.y >= 0 &&
        far.x <= image.cols - 1 && far.y <= image.rows - 1)
      base.push_back(p);
  }
  if (base.empty()) return cv::Scalar::all(-1);
  return cv::mean(sample_across(image, base, t, n, {0.0}, {gap, gap + depth / 3, gap + 2 * depth / 3, gap + depth}));
}

double colour_distance(const cv::Scalar& a, const cv::Scalar& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/// Whether the side a → b lies on the line l: both ends within `tol` px of it, directions within 3°.
bool on_line(const Line& l, cv::Point2d a, cv::Point2d b, double tol) {
  const cv::Point2d d = (b - a) / cv::norm(b - a);
  return std::abs(l.d.dot(d)) >= std::cos(3.0 * CV_PI / 180.0) && distance(l, a) <= tol && distance(l, b) <= tol;
}

/// Whether the larger quadrilateral `x` (its sides that are not sides of the smaller `y` all on the frame's edge)
/// runs on past y's corners over the background: along each side of x that y shares, the stretch from y's corner
/// (less a margin of 3 x unit + 2 px, where y's own side still shows) to x's corner on the frame's edge is not backed
/// by an edge (side_support under 0.5, strengths judged against that of the page's edge along y's side). Stretches
/// shorter than 4 x unit px are not looked at (y's corner lies within a few pixels of the frame's edge); when none
/// is left, the answer is yes too. A page whose sides run on to the frame's edge is cut off there (x); one whose
/// sides end at its corners, with the background between them and the frame's edge, lies whole in the frame (y).
bool runs_past_over_background(const Found& x, const Found& y, const cv::Mat& image, double unit, double tol) {
  const Quad& qx = x.det.corners_px;
  const Quad& qy = y.det.corners_px;
  const double margin = 3.0 * unit + 2.0, least = 4.0 * std::max(1.0, unit);
  for (std::size_t s = 0; s < 4; ++s) {
    if (x.side_contrast[s].empty()) continue;  // on the frame's edge
    const cv::Point2d A = qx[s], B = qx[(s + 1) % 4];
    const double len = cv::norm(B - A);
    const Line l{A, (B - A) / len};
    for (std::size_t t = 0; t < 4; ++t) {
      const cv::Point2d a = qy[t], b = qy[(t + 1) % 4];
      if (!on_line(l, a, b, tol)) continue;
      float typical = 0.0f;  // the strength of the page's edge along y's side
      if (side_support(image, a, b, unit, 0.05, 0.95, &typical) <= 0.0) break;
      const double u0 = std::min((a - A).dot(l.d), (b - A).dot(l.d)), u1 = std::max((a - A).dot(l.d), (b - A).dot(l.d));
      // Beyond y's side towards x's corner where x meets the frame's edge: before s (at A), after s (at B).
      const std::array<std::pair<bool, std::pair<double, double>>, 2> beyond{
          {{x.side_contrast[(s + 3) % 4].empty(), {0.0, u0 - margin}},
           {x.side_contrast[(s + 1) % 4].empty(), {u1 + margin, len}}}};
      for (const auto& [to_frame, span] : beyond) {
        if (!to_frame || span.second - span.first < least) continue;
        float strength = typical;
        if (side_support(image, A + span.first * l.d, A + span.second * l.d, unit, 0.0, 1.0, &strength) >= 0.5)
          return false;
      }
      break;
    }
  }
  return true;
}

/// The page among the quadrilaterals that passed: the largest, unless a smaller one shares some of its sides and
/// the larger runs past it over the background: the larger's other sides are weak (their lower quartile of stretch
/// contrasts under half that of the shared sides), the smaller's other sides at least twice as strong, and the
/// strip between them looks like the background outside the smaller's shared sides more than like the inside of
/// the smaller (a grain line of the table beyond the page's edge, not a line in the picture on it). A smaller one
/// sharing no side lies inside the page: a picture on it. And a larger one with sides on the frame's edge, its
/// other sides shared by a smaller one with fewer sides on the frame's edge, loses to it when its shared sides run
/// on from the smaller's corners to the frame's edge over the background (runs_past_over_background): the page's
/// own side, seen near the frame's edge; the page lies whole in the frame. Bands for the colours: `gap` to `gap` +
/// `depth` px off a side; `tol`: sides this close are the same side; `unit`: frame px per downscaled px.
PageDetection choose(std::vector<Found> found, const cv::Mat& image, double gap, double depth, double tol,
                     double unit) {
  std::sort(found.begin(), found.end(),
            [](const Found& a, const Found& b) { return a.det.area_fraction > b.det.area_fraction; });
  // Lower quartile of the stretch contrasts of x's sides that are (shared = true) or are not sides of y.
  const auto lower_quartile = [&](const Found& x, const Found& y, bool shared) {
    std::vector<double> v;
    for (std::size_t s = 0; s < 4; ++s)
      if (shares_side(y.det.corners_px, x.det.corners_px, s, tol) == shared)
        v.insert(v.end(), x.side_contrast[s].begin(), x.side_contrast[s].end());
    if (v.empty()) return -1.0;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 4), v.end());
    return v[v.size() / 4];
  };
  // Whether the strip between the smaller y's own sides and the larger looks like the background round y.
  const auto strip_is_background = [&](const Found& y, const Found& x) {
    cv::Scalar strip, inside, background;
    int n_strip = 0, n_background = 0;
    for (std::size_t s = 0; s < 4; ++s) {
      const cv::Point2d a = y.det.corners_px[s], b = y.det.corners_px[(s + 1) % 4];
      const cv::Scalar out = band_mean(image, a, b, gap, depth, true);
      if (out[0] < 0) continue;
      if (shares_side(x.det.corners_px, y.det.corners_px, s, tol)) {
        background += out;
        ++n_background;
      } else {
        const cv::Scalar in = band_mean(image, a, b, gap, depth, false);
        if (in[0] < 0) continue;
        strip += out;
        inside += in;
        ++n_strip;
      }
    }
    if (n_strip == 0 || n_background == 0) return false;
    return colour_distance(strip / n_strip, background / n_background) <
           colour_distance(strip / n_strip, inside / n_strip);
  };
  for (std::size_t i = 0; i < found.size(); ++i) {
    bool beaten = false;
    for (std::size_t j = i + 1; j < found.size() && !beaten; ++j) {
      // The larger's sides on the frame's edge, the rest sides of the smaller too, which has fewer on the edge: the
      // same page with a side either on the frame's edge or just inside it. The page's own side, seen between the
      // page and the frame's edge, wins when the larger's shared sides run on past the smaller's corners over the
      // background; when they run on along the page's edge, the page goes on beyond the frame (a line in the
      // picture near the frame's edge made the smaller).
      int on_edge_i = 0, on_edge_j = 0;
      bool rest_shared = true;
      for (std::size_t s = 0; s < 4; ++s) {
        on_edge_j += found[j].side_contrast[s].empty();
        if (found[i].side_contrast[s].empty())
          ++on_edge_i;
        else
          rest_shared = rest_shared && shares_side(found[j].det.corners_px, found[i].det.corners_px, s, tol);
      }
      if (on_edge_i > on_edge_j && rest_shared) {
        beaten = runs_past_over_background(found[i], found[j], image, unit, tol);
        continue;
      }
      int shared = 0;
      for (std::size_t s = 0; s < 4; ++s)
        shared += shares_side(found[i].det.corners_px, found[j].det.corners_px, s, tol);
      if (shared == 0 || shared == 4) continue;
      const double own = lower_quartile(found[i], found[j], false), common = lower_quartile(found[i], found[j], true);
      const double other = lower_quartile(found[j], found[i], false);
      beaten = own >= 0 && own < 0.5 * common && other >= 2.0 * own && strip_is_background(found[j], found[i]);
    }
    if (!beaten) return found[i].det;
  }
  return {};
}

}  // namespace

PageDetection find_page(const cv::Mat& frame, const PageParams& params) {
  if (frame.empty()) throw hk::ArgumentError("find_page: empty frame");
  if (frame.type() != CV_8UC3 && frame.type() != CV_8UC1)
    throw hk::ArgumentError("find_page: the frame must be CV_8UC3 (BGR) or CV_8UC1 (grey)");
  check_params(params);
  Frame f{frame, {},
          1.0,   1.0,
          1.0,   0.01 * std::hypot(frame.cols, frame.rows),
          3.0,   static_cast<double>(frame.cols) * frame.rows};
  if (frame.channels() == 3)
    cv::cvtColor(frame, f.grey, cv::COLOR_BGR2GRAY);
  else
    f.grey = frame;

  const double scale = std::min(1.0, static_cast<double>(params.max_side_px) / std::max(frame.cols, frame.rows));
  cv::Mat small = frame;
  if (scale < 1.0) {
    const cv::Size ss(std::max(1, static_cast<int>(std::lround(frame.cols * scale))),
                      std::max(1, static_cast<int>(std::lround(frame.rows * scale))));
    cv::resize(frame, small, ss, 0, 0, cv::INTER_AREA);
  }
  f.sx = static_cast<double>(frame.cols) / small.cols;
  f.sy = static_cast<double>(frame.rows) / small.rows;
  f.unit = std::max(f.sx, f.sy);
  f.band_start = 1.5 + 1.5 * f.unit;
  cv::Mat half;
  cv::pyrDown(small, half);
  const std::vector<Candidate> cands =
      candidates(small, half, 0.8 * params.min_area_fraction * small.cols * small.rows);

  // Score each candidate by how well its sides are backed by edges; merge those that differ by less than 1 % of
  // the frame's diagonal.
  const Gradient grad = gradient_of(half, small.size());
  std::vector<std::pair<double, Candidate>> ranked;
  const double same = 0.01 * std::hypot(small.cols, small.rows);
  for (const Candidate& c : cands) {
    // At least two sides must be the page's own; each side on the frame's edge (which shows no edge to back it)
    // counts against a candidate, so a cut-off page is looked at after the pages seen whole.
    const auto on_frame = std::count_if(c.frame_edge.begin(), c.frame_edge.end(), [](int e) { return e >= 0; });
    if (on_frame > 2) continue;
    const double score = quick_support(grad, c, 24.0) - 0.15 * static_cast<double>(on_frame);
    if (score < 0.3 - 0.15 * static_cast<double>(on_frame)) continue;
    auto twin = std::find_if(ranked.begin(), ranked.end(), [&](const auto& r) {
      for (std::size_t i = 0; i < 4; ++i)
        if (cv::norm(r.second.q[i] - c.q[i]) > same) return false;
      return true;
    });
    if (twin == ranked.end())
      ranked.emplace_back(score, c);
    else if (score > twin->first)
      *twin = {score, c};
  }
  // Verified: the best-backed candidates, then the largest of the well-backed (score >= 0.75) ones not yet looked at
  // (the page is the largest quadrilateral; the lines of a printed grid or a window in a photograph make many
  // smaller, equally well-backed ones inside it).
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  constexpr std::size_t kBestBacked = 10, kLargest = 10;
  std::vector<const Candidate*> order;
  for (std::size_t i = 0; i < std::min(ranked.size(), kBestBacked); ++i) order.push_back(&ranked[i].second);
  std::vector<const Candidate*> rest;
  for (std::size_t i = kBestBacked; i < ranked.size(); ++i)
    if (ranked[i].first >= 0.75) rest.push_back(&ranked[i].second);
  std::stable_sort(rest.begin(), rest.end(), [](const Candidate* a, const Candidate* b) { return a->area > b->area; });
  for (std::size_t i = 0; i < std::min(rest.size(), kLargest); ++i) order.push_back(rest[i]);
  std::vector<Found> found;
  Memo memo;
  for (const Candidate* c : order) {
    if (std::optional<Found> d = verify(f, *c, params, memo)) found.push_back(*d);
  }
  return choose(found, frame, f.band_start, 8.0 * f.unit, f.same_side_tol + 1.0, f.unit);
}

double page_aspect_ratio(const std::array<cv::Point2d, 4>& corners_px, cv::Point2d centre_px) {
  for (const cv::Point2d& p : corners_px)
    if (!finite(p)) throw hk::ArgumentError("page_aspect_ratio: corners must be finite");
  if (!finite(centre_px)) throw hk::ArgumentError("page_aspect_ratio: the centre must be finite");
  const cv::Point2d tl = corners_px[0], tr = corners_px[1], br = corners_px[2], bl = corners_px[3];
  const double across = cv::norm(tr - tl) + cv::norm(br - bl), down = cv::norm(bl - tl) + cv::norm(br - tr);
  if (!(down > 0.0) || !(across > 0.0)) throw hk::ArgumentError("page_aspect_ratio: degenerate quadrilateral");
  const double mean_sides = across / down;
  // Zhang & He's m1..m4 are the rectangle's (0,0), (w,0), (0,h), (w,h): top-left, top-right, bottom-left,
  // bottom-right. Coordinates relative to the principal point, so u0 = v0 = 0 below.
  const auto h = [&](cv::Point2d p) { return cv::Vec3d(p.x - centre_px.x, p.y - centre_px.y, 1.0); };
  const cv::Vec3d m1 = h(tl), m2 = h(tr), m3 = h(bl), m4 = h(br);
  const double k2 = m1.cross(m4).dot(m3) / m2.cross(m4).dot(m3);
  const double k3 = m1.cross(m4).dot(m2) / m3.cross(m4).dot(m2);
  const cv::Vec3d n2 = k2 * m2 - m1, n3 = k3 * m3 - m1;
  // n2[2] = k2 − 1 and n3[2] = k3 − 1 vanish when a pair of opposite sides is parallel: f is then undetermined.
  constexpr double kParallel = 1e-6;
  if (!std::isfinite(k2) || !std::isfinite(k3) || std::abs(n2[2]) < kParallel || std::abs(n3[2]) < kParallel)
    return mean_sides;
  const double f2 = -(n2[0] * n3[0] + n2[1] * n3[1]) / (n2[2] * n3[2]);
  if (!std::isfinite(f2) || !(f2 > 0.0)) return mean_sides;
  // (w/h)² = n2ᵀ A⁻ᵀA⁻¹ n2 / n3ᵀ A⁻ᵀA⁻¹ n3 with A = [f 0 0; 0 f 0; 0 0 1]; both sides times f².
  const double num = n2[0] * n2[0] + n2[1] * n2[1] + f2 * n2[2] * n2[2];
  const double den = n3[0] * n3[0] + n3[1] * n3[1] + f2 * n3[2] * n3[2];
  const double r = std::sqrt(num / den);
  return std::isfinite(r) && r > 0.0 ? r : mean_sides;
}

cv::Mat rectify_page(const cv::Mat& frame, const std::array<cv::Point2d, 4>& corners_px) {
  if (frame.empty()) throw hk::ArgumentError("rectify_page: empty frame");
  for (const cv::Point2d& p : corners_px)
    if (!finite(p)) throw hk::ArgumentError("rectify_page: corners must be finite");
  if (std::abs(signed_area(corners_px)) < 1.0)
    throw hk::ArgumentError("rectify_page: degenerate quadrilateral (area < 1 px²)");
  double longest = 0.0;
  for (std::size_t i = 0; i < 4; ++i) longest = std::max(longest, cv::norm(corners_px[(i + 1) % 4] - corners_px[i]));
  const double diag = std::hypot(frame.cols, frame.rows);
  if (longest > 4.0 * diag) throw hk::ArgumentError("rectify_page: a side is longer than 4 times the frame's diagonal");
  const double ratio = page_aspect_ratio(corners_px, {(frame.cols - 1) / 2.0, (frame.rows - 1) / 2.0});
  const double w = ratio >= 1.0 ? longest : longest * ratio, h = ratio >= 1.0 ? longest / ratio : longest;
  const int W = std::max(1, static_cast<int>(std::lround(w))), H = std::max(1, static_cast<int>(std::lround(h)));
  cv::Point2f src[4], dst[4];
  for (std::size_t i = 0; i < 4; ++i)
    src[i] = cv::Point2f(static_cast<float>(corners_px[i].x), static_cast<float>(corners_px[i].y));
  // The page's corners are the outer corners of the output's corner pixels.
  dst[0] = {-0.5f, -0.5f};
  dst[1] = {static_cast<float>(W) - 0.5f, -0.5f};
  dst[2] = {static_cast<float>(W) - 0.5f, static_cast<float>(H) - 0.5f};
  dst[3] = {-0.5f, static_cast<float>(H) - 0.5f};
  const cv::Mat m = cv::getPerspectiveTransform(src, dst);
  cv::Mat out;
  cv::warpPerspective(frame, out, m, cv::Size(W, H), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

}  // namespace hk::vision
