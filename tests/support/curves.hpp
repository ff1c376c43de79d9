#include <algorithm>
#pragma once
// Seeded random curves and independent geometry checks shared by the test suites.
// The checks here are written separately from the library (orientation predicates, brute force), so a
// bug in the library's own geometry cannot hide itself.
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "haptics/multires.hpp"
#include "haptics/scene.hpp"

namespace hk::test {

/// A closed axis-aligned square of half side `half` [m] centred at the origin, counter-clockwise.
inline Polyline square(double half) {
  Polyline p;
  p.closed = true;
  p.points_m = {{-half, -half}, {half, -half}, {half, half}, {-half, half}};
  return p;
}

/// The same square sampled every `step` [m] along its sides (4·round(2·half/step) points, counter-clockwise from
/// (−half, −half)), for tests that need a curve with many points.
inline Polyline sampled_square(double half, double step) {
  Polyline p;
  p.closed = true;
  const int n = static_cast<int>(std::lround(2 * half / step));
  for (int i = 0; i < n; ++i) p.points_m.push_back({-half + i * step, -half});
  for (int i = 0; i < n; ++i) p.points_m.push_back({half, -half + i * step});
  for (int i = 0; i < n; ++i) p.points_m.push_back({half - i * step, half});
  for (int i = 0; i < n; ++i) p.points_m.push_back({-half, half - i * step});
  return p;
}

/// A smooth random closed blob: r(θ) = r0 (1 + Σ a_i cos(iθ + φ_i)), n points, centred at c.
inline Polyline random_blob(std::mt19937& rng, Vec2 c, double r0, int n) {
  std::uniform_real_distribution<double> amp(-0.12, 0.12), ph(0.0, 2 * M_PI);
  double a[6], phi[6];
  for (int i = 0; i < 6; ++i) {
    a[i] = amp(rng) / (1 + i);
    phi[i] = ph(rng);
  }
  Polyline p;
  p.closed = true;
  for (int k = 0; k < n; ++k) {
    const double th = 2 * M_PI * k / n;
    double r = 1.0;
    for (int i = 0; i < 6; ++i) r += a[i] * std::cos((i + 2) * th + phi[i]);
    p.points_m.push_back({c.x + r0 * r * std::cos(th), c.y + r0 * r * std::sin(th)});
  }
  return p;
}

/// A random open wiggly stroke of n points starting at s, step length step_m, smoothly turning.
inline Polyline random_stroke(std::mt19937& rng, Vec2 s, double step_m, int n) {
  std::normal_distribution<double> turn(0.0, 0.15);
  Polyline p;
  double heading = std::uniform_real_distribution<double>(0, 2 * M_PI)(rng), rate = 0.0;
  Vec2 q = s;
  for (int k = 0; k < n; ++k) {
    p.points_m.push_back(q);
    rate = 0.8 * rate + turn(rng);
    heading += rate;
    q = q + step_m * Vec2{std::cos(heading), std::sin(heading)};
  }
  return p;
}

/// `n` points on the circle of centre `c` and radius `r_m` [m], counter-clockwise from angle 0.
inline std::vector<Vec2> circle_points(Vec2 c, double r_m, int n = 48) {
  std::vector<Vec2> p;
  for (int i = 0; i < n; ++i)
    p.push_back({c.x + r_m * std::cos(2 * M_PI * i / n), c.y + r_m * std::sin(2 * M_PI * i / n)});
  return p;
}

/// A pixel-like staircase curve: a circle rounded to a grid of `cell_m` (as edge chains are).
inline Polyline staircase_circle(Vec2 c, double r, double cell_m) {
  Polyline p;
  p.closed = true;
  const int n = static_cast<int>(2 * M_PI * r / cell_m);
  for (int k = 0; k < n; ++k) {
    const double th = 2 * M_PI * k / n;
    Vec2 q{std::round((c.x + r * std::cos(th)) / cell_m) * cell_m,
           std::round((c.y + r * std::sin(th)) / cell_m) * cell_m};
    if (p.points_m.empty() || !(p.points_m.back() == q)) p.points_m.push_back(q);
  }
  if (p.points_m.size() > 1 && p.points_m.back() == p.points_m.front()) p.points_m.pop_back();
  return p;
}

/// Orientation of (a, b, c): > 0 counter-clockwise.
inline double orient(Vec2 a, Vec2 b, Vec2 c) { return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x); }

/// True when the open segments p1p2 and q1q2 cross strictly (each separates the other's end points).
inline bool crosses_strictly(Vec2 p1, Vec2 p2, Vec2 q1, Vec2 q2) {
  const double o1 = orient(p1, p2, q1), o2 = orient(p1, p2, q2);
  const double o3 = orient(q1, q2, p1), o4 = orient(q1, q2, p2);
  return ((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0));
}

/// Where the sweep a→b meets segment p→q: true with its sweep parameter `t` in [0, 1], by solving the 2x2
/// system with Cramer's rule in a different arrangement from the library's (parallel pairs: false).
inline bool cramer_sweep_hit(Vec2 a, Vec2 b, Vec2 p, Vec2 q, double* t) {
  // a + t (b − a) = p + s (q − p)  →  [b−a, p−q] [t s]^T = p − a
  const double m11 = b.x - a.x, m12 = p.x - q.x, m21 = b.y - a.y, m22 = p.y - q.y;
  const double det = m11 * m22 - m12 * m21;
  if (det == 0.0) return false;
  const double rx = p.x - a.x, ry = p.y - a.y;
  *t = (rx * m22 - m12 * ry) / det;
  const double s = (m11 * ry - rx * m21) / det;
  return *t >= 0 && *t <= 1 && s >= 0 && s <= 1;
}

/// Brute-force first hit of a→b over every segment of level id `level` (each curve at Scene::clamp_level) but
/// the n_excluded segments at `excluded`: the smallest sweep parameter (cramer_sweep_hit; 2.0 when none) in
/// *t_out, in *seg_out the first segment hit at it in (curve, level, segment) order, and in *near_out (when
/// given) every segment hit within 1e-9 of it (a shared vertex is met by two). Any output may be null.
inline bool brute_first_hit(const Scene& sc, Vec2 a, Vec2 b, int level, double* t_out, SegmentRef* seg_out,
                            const SegmentRef* excluded = nullptr, int n_excluded = 0,
                            std::vector<SegmentRef>* near_out = nullptr) {
  std::vector<std::pair<double, SegmentRef>> hits;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const int l = sc.clamp_level(c, level);
    for (std::uint32_t k = 0; k < sc.curve(c).segment_count[l]; ++k) {
      const SegmentRef ref{static_cast<int>(c), l, static_cast<int>(k)};
      if (n_excluded > 0 && std::find(excluded, excluded + n_excluded, ref) != excluded + n_excluded) continue;
      Vec2 p, q;
      sc.segment(ref, &p, &q);
      double t = 0.0;
      if (cramer_sweep_hit(a, b, p, q, &t)) hits.push_back({t, ref});
    }
  }
  double best = 2.0;
  for (const auto& h : hits) {
    if (h.first < best) {
      best = h.first;
      if (seg_out) *seg_out = h.second;
    }
  }
  if (near_out) {
    near_out->clear();
    for (const auto& h : hits) {
      if (h.first <= best + 1e-9) near_out->push_back(h.second);
    }
  }
  if (t_out) *t_out = best;
  return !hits.empty();
}

/// Distance from p to the nearest segment of any curve at level id `level` (each curve at
/// Scene::clamp_level), by brute force over every segment [m]; 1e9 for an empty scene.
inline double brute_closest_distance(const Scene& sc, Vec2 p, int level) {
  double best = 1e9;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const int l = sc.clamp_level(c, level);
    for (std::uint32_t k = 0; k < sc.curve(c).segment_count[l]; ++k) {
      Vec2 a, b;
      sc.segment({static_cast<int>(c), l, static_cast<int>(k)}, &a, &b);
      best = std::min(best, distance_to_segment(p, a, b));
    }
  }
  return best;
}

/// Number of level-`level` segments that the move p→q crosses strictly.
inline int count_crossings(const Scene& sc, Vec2 p, Vec2 q, int level) {
  int n = 0;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const int l = sc.clamp_level(c, level);
    for (std::uint32_t k = 0; k < sc.curve(c).segment_count[l]; ++k) {
      Vec2 a, b;
      sc.segment({static_cast<int>(c), l, static_cast<int>(k)}, &a, &b);
      if (crosses_strictly(p, q, a, b)) ++n;
    }
  }
  return n;
}

}  // namespace hk::test
