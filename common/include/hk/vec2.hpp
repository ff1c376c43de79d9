#pragma once
/// @file vec2.hpp
/// The 2-D vector every module that works in the workspace shares, and free functions on it.
/// All coordinates are workspace metres unless a name says otherwise (DESIGN.md "Frames and units").

#include <cmath>

namespace hk {

/// A 2-D vector or point. 16 bytes. Workspace frame: x to the user's right, y away from the user [m].
struct Vec2 {
  double x = 0.0;
  double y = 0.0;
};

constexpr Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
constexpr Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
constexpr Vec2 operator-(Vec2 a) { return {-a.x, -a.y}; }
constexpr Vec2 operator*(double s, Vec2 a) { return {s * a.x, s * a.y}; }
constexpr Vec2 operator*(Vec2 a, double s) { return {s * a.x, s * a.y}; }
constexpr Vec2& operator+=(Vec2& a, Vec2 b) {
  a.x += b.x;
  a.y += b.y;
  return a;
}
constexpr Vec2& operator-=(Vec2& a, Vec2 b) {
  a.x -= b.x;
  a.y -= b.y;
  return a;
}
constexpr bool operator==(Vec2 a, Vec2 b) { return a.x == b.x && a.y == b.y; }

/// Dot product.
constexpr double dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
/// z-component of the 3-D cross product: > 0 when b turns left (counter-clockwise) from a.
constexpr double cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
/// The left normal (a rotated by +90°); same length as a.
constexpr Vec2 left_perp(Vec2 a) { return {-a.y, a.x}; }
/// Euclidean length. sqrt of the squared length, not std::hypot: workspace coordinates are ~0.1 m, far
/// from overflow, and hypot's care costs several times as much on the servo path.
inline double length(Vec2 a) { return std::sqrt(a.x * a.x + a.y * a.y); }
/// Squared length (no square root).
constexpr double length_sq(Vec2 a) { return a.x * a.x + a.y * a.y; }
/// Distance between two points.
inline double distance(Vec2 a, Vec2 b) { return length(b - a); }
/// Linear interpolation a + t (b − a).
constexpr Vec2 lerp(Vec2 a, Vec2 b, double t) { return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)}; }
/// True when both components are finite.
inline bool is_finite(Vec2 a) { return std::isfinite(a.x) && std::isfinite(a.y); }
/// Unit vector along a, or `fallback` when |a| is below 1e-300 (a degenerate segment has no direction).
inline Vec2 normalized_or(Vec2 a, Vec2 fallback) {
  const double len = length(a);
  return len > 1e-300 ? Vec2{a.x / len, a.y / len} : fallback;
}

/// Closest point to p on segment [a, b]; `t_out` receives its parameter in [0, 1].
inline Vec2 closest_point_on_segment(Vec2 p, Vec2 a, Vec2 b, double* t_out = nullptr) {
  const Vec2 ab = b - a;
  const double len_sq = length_sq(ab);
  double t = len_sq > 0.0 ? dot(p - a, ab) / len_sq : 0.0;
  t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  if (t_out) *t_out = t;
  return lerp(a, b, t);
}

/// Distance from p to segment [a, b] [m].
inline double distance_to_segment(Vec2 p, Vec2 a, Vec2 b) { return distance(p, closest_point_on_segment(p, a, b)); }
/// Squared distance from p to segment [a, b] [m²] (no square root: for comparisons).
inline double distance_sq_to_segment(Vec2 p, Vec2 a, Vec2 b) {
  return length_sq(p - closest_point_on_segment(p, a, b));
}

}  // namespace hk
