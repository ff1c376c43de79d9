// The scene's queries of its boxes and levels (scene.hpp); its build is in scene_build.cpp (seed paper §3;
// DESIGN.md "Collision tree").
#include "haptics/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace hk {

bool box_contains(const ErrorBox& box, Vec2 p, double margin_m) {
  const Vec2 r = p - box.origin_m;
  const double u = dot(r, box.axis);
  const double n = cross(box.axis, r);
  return u >= box.u_min - margin_m && u <= box.u_max + margin_m && n >= box.n_min - margin_m &&
         n <= box.n_max + margin_m;
}

void box_corners(const ErrorBox& box, Vec2 out[4]) {
  const Vec2 nrm = left_perp(box.axis);
  out[0] = box.origin_m + box.u_min * box.axis + box.n_min * nrm;
  out[1] = box.origin_m + box.u_max * box.axis + box.n_min * nrm;
  out[2] = box.origin_m + box.u_max * box.axis + box.n_max * nrm;
  out[3] = box.origin_m + box.u_min * box.axis + box.n_max * nrm;
}

double box_error_bound(const ErrorBox& box, double segment_length_m) {
  const double overhang = std::max(std::max(0.0, -box.u_min), box.u_max - segment_length_m);
  const double half_width = box_half_width(box);
  return std::sqrt(overhang * overhang + half_width * half_width);
}

std::size_t Scene::hot_bytes() const {
  return points_m_.size() * sizeof(Vec2) + extent_.size() * sizeof(BoxExtent) + tag_.size() * sizeof(std::uint32_t) +
         curve_nodes_.size() * sizeof(CurveNodes) + group_box_.size() * sizeof(Aabb) +
         group_info_.size() * sizeof(NodeInfo) +
         (group_parent_.size() + group_child_first_.size() + group_child_count_.size() + chunk_of_curve_.size()) *
             sizeof(std::uint32_t) +
         wide_.bytes();
}

Aabb Scene::aabb(std::uint32_t node) const noexcept {
  if (node >= segment_nodes_) return group_box_[node - segment_nodes_];
  // From the box's centre and half-extents rather than its four corners: half-width along x is
  // |axis.x| hu + |axis.y| hn (the normal is (−axis.y, axis.x)), along y |axis.y| hu + |axis.x| hn. Grown by
  // a few ulps of the largest coordinate, so it holds the corners as rounded by box_corners too.
  const ErrorBox b = segment_box(node);
  const double cu = 0.5 * (b.u_min + b.u_max), hu = 0.5 * (b.u_max - b.u_min);
  const double cn = 0.5 * (b.n_min + b.n_max), hn = 0.5 * (b.n_max - b.n_min);
  const Vec2 c{b.origin_m.x + cu * b.axis.x - cn * b.axis.y, b.origin_m.y + cu * b.axis.y + cn * b.axis.x};
  const double ax = std::abs(b.axis.x), ay = std::abs(b.axis.y);
  const double slack = 0x1p-48 * (std::abs(c.x) + std::abs(c.y) + hu + hn);
  const double hx = ax * hu + ay * hn + slack, hy = ay * hu + ax * hn + slack;
  return Aabb{{c.x - hx, c.y - hy}, {c.x + hx, c.y + hy}};
}

std::size_t Scene::total_segments(int level) const {
  std::size_t total = 0;
  for (std::size_t c = 0; c < curves_.size(); ++c) total += curves_[c].segment_count[clamp_level(c, level)];
  return total;
}

double Scene::max_box_half_width_m(int level) const {
  double widest = 0.0;
  for (std::size_t c = 0; c < curves_.size(); ++c)
    widest = std::max(widest, curves_[c].max_box_half_width_m[clamp_level(c, level)]);
  return widest;
}

double Scene::max_error_bound_m(int level) const {
  double bound = 0.0;
  for (std::size_t c = 0; c < curves_.size(); ++c)
    bound = std::max(bound, curves_[c].max_error_bound_m[clamp_level(c, level)]);
  return bound;
}

int Scene::coarsest_level_within(std::size_t c, double tol_m) const {
  // A curve's bounds need not grow with the level, so every level is looked at, not just the first that fails.
  const CurveInfo& ci = curves_[c];
  int level = 0;
  for (int l = 0; l < ci.levels; ++l) {
    if (ci.max_error_bound_m[l] <= tol_m) level = l;
  }
  return level;
}

int Scene::max_curve_levels() const {
  int levels = 1;
  for (const CurveInfo& ci : curves_) levels = std::max(levels, ci.levels);
  return levels;
}

}  // namespace hk
