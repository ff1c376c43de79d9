#include "describe.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace hk::app {
namespace {

struct Shape {
  double diag_m;
  Vec2 centre_m;
  bool closed;
};

const char* place(Vec2 c, Vec2 half) {
  // Thirds of the workspace; y is away from the visitor = up on the screen = "top".
  const int col = c.x < -half.x / 3 ? 0 : (c.x > half.x / 3 ? 2 : 1);
  const int row = c.y > half.y / 3 ? 0 : (c.y < -half.y / 3 ? 2 : 1);
  static const char* const names[3][3] = {{"at the top left", "at the top", "at the top right"},
                                          {"on the left", "in the middle", "on the right"},
                                          {"at the bottom left", "at the bottom", "at the bottom right"}};
  return names[row][col];
}

/// Bounding box (lower left, upper right) of a non-empty polyline [m].
std::pair<Vec2, Vec2> bounds_of(const Polyline& p) {
  Vec2 lo = p.points_m[0], hi = p.points_m[0];
  for (const Vec2& q : p.points_m) {
    lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
    hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
  }
  return {lo, hi};
}

}  // namespace

std::string describe_scene(const std::vector<Polyline>& curves, Vec2 half, int max_named) {
  std::vector<Shape> shapes;
  for (const Polyline& p : curves) {
    if (p.points_m.empty()) continue;
    const auto [lo, hi] = bounds_of(p);
    shapes.push_back({length(hi - lo), 0.5 * (lo + hi), p.closed});
  }
  if (shapes.empty()) return "There are no shapes in this picture.";
  std::sort(shapes.begin(), shapes.end(), [](const Shape& a, const Shape& b) { return a.diag_m > b.diag_m; });
  const double ws = 2.0 * length(half);
  auto size = [&](const Shape& s) { return s.diag_m > 0.4 * ws ? "large" : (s.diag_m > 0.15 * ws ? "medium" : "small"); };
  std::string out = shapes.size() == 1 ? "One shape. " : std::to_string(shapes.size()) + " shapes. ";
  const std::size_t named = std::min<std::size_t>(shapes.size(), static_cast<std::size_t>(std::max(1, max_named)));
  for (std::size_t i = 0; i < named; ++i) {
    const Shape& s = shapes[i];
    std::string part = std::string(i == 0 ? "A " : "a ") + size(s) + (s.closed ? " closed shape " : " line ") + place(s.centre_m, half);
    if (i > 0) out += (i + 1 == named && shapes.size() == named) ? ", and " : ", ";
    out += part;
  }
  if (shapes.size() > named) {
    const std::size_t rest = shapes.size() - named;
    out += ", and " + std::to_string(rest) + (rest == 1 ? " more, smaller." : " more, smaller ones.");
  } else {
    out += ".";
  }
  return out;
}

int count_figures(const std::vector<Polyline>& curves, double margin_m) {
  std::vector<std::pair<Vec2, Vec2>> boxes;
  for (const Polyline& p : curves) {
    if (!p.points_m.empty()) boxes.push_back(bounds_of(p));
  }
  std::vector<std::size_t> parent(boxes.size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto find = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  int groups = static_cast<int>(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    for (std::size_t j = i + 1; j < boxes.size(); ++j) {
      const auto& [a0, a1] = boxes[i];
      const auto& [b0, b1] = boxes[j];
      const bool touch = a0.x - margin_m <= b1.x && b0.x <= a1.x + margin_m && a0.y - margin_m <= b1.y && b0.y <= a1.y + margin_m;
      if (!touch) continue;
      const std::size_t ri = find(i), rj = find(j);
      if (ri != rj) {
        parent[ri] = rj;
        --groups;
      }
    }
  }
  return groups;
}

std::string describe_shapes(int shapes) {
  if (shapes == 0) return "I found no shapes in it.";
  return shapes == 1 ? "It has one shape." : "It has " + std::to_string(shapes) + " shapes.";
}

std::string describe_page(int text_blocks, int figures) {
  auto count = [](int n, const char* one, const char* many, const char* none) {
    return n == 0 ? std::string(none) : n == 1 ? std::string(one) : std::to_string(n) + " " + many;
  };
  return "It has " + count(text_blocks, "one block of text", "blocks of text", "no text") + " and " +
         count(figures, "one figure", "figures", "no figures") + ".";
}

}  // namespace hk::app
