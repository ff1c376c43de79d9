#include "visit/describe.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

namespace hk::app {
namespace {

struct Shape {
  double diag_m;
  Vec2 centre_m;
  bool closed;
  std::size_t curve;  // index in the curves described
  int inside = 0;     // shapes nested in it, at any depth
  bool top = true;    // inside no other shape
  int parent = -1;    // the smallest shape it lies inside (index into the shapes), −1 for none
};

/// Distance from `p` to the polyline of `c` (with its closing segment when closed) [m].
double distance_to(const Polyline& c, Vec2 p) {
  const std::vector<Vec2>& q = c.points_m;
  if (q.empty()) return std::numeric_limits<double>::infinity();
  double best = length(p - q[0]);
  const std::size_t n = q.size(), segments = c.closed && n > 2 ? n : n - 1;
  for (std::size_t i = 0; i < segments; ++i) {
    const Vec2 a = q[i], b = q[(i + 1) % n], ab = b - a;
    const double len2 = dot(ab, ab);
    const double t = len2 > 0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    best = std::min(best, length(p - (a + t * ab)));
  }
  return best;
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

/// Whether p lies inside the closed polygon `poly` (even-odd rule, crossing count of a ray towards +x).
bool inside_polygon(Vec2 p, const std::vector<Vec2>& poly) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2 a = poly[i], b = poly[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y)) in = !in;
  }
  return in;
}

/// Whether curve `inner` lies inside the closed curve `outer`: its bounding box within outer's, and up to
/// kNestSamples of its points, spread along it, all inside outer's polygon.
bool nested_in(const Polyline& inner, const Polyline& outer, const std::pair<Vec2, Vec2>& inner_box,
               const std::pair<Vec2, Vec2>& outer_box) {
  constexpr std::size_t kNestSamples = 16;
  if (!outer.closed || outer.points_m.size() < 3) return false;
  if (inner_box.first.x < outer_box.first.x || inner_box.first.y < outer_box.first.y ||
      inner_box.second.x > outer_box.second.x || inner_box.second.y > outer_box.second.y)
    return false;
  const std::size_t n = inner.points_m.size();
  const std::size_t step = std::max<std::size_t>(1, n / kNestSamples);
  for (std::size_t i = 0; i < n; i += step)
    if (!inside_polygon(inner.points_m[i], outer.points_m)) return false;
  return true;
}

/// The shapes of `curves` with their nesting: `inside` counts the shapes within each closed shape (at any
/// depth), `top` marks those within none.
std::vector<Shape> shapes_of(const std::vector<Polyline>& curves) {
  std::vector<Shape> shapes;
  std::vector<std::pair<Vec2, Vec2>> boxes;
  for (std::size_t k = 0; k < curves.size(); ++k) {
    const Polyline& p = curves[k];
    if (p.points_m.empty()) continue;
    boxes.push_back(bounds_of(p));
    shapes.push_back({length(boxes.back().second - boxes.back().first),
                      0.5 * (boxes.back().first + boxes.back().second), p.closed, k});
  }
  for (std::size_t i = 0; i < shapes.size(); ++i)
    for (std::size_t j = 0; j < shapes.size(); ++j) {
      if (i == j || shapes[j].diag_m <= shapes[i].diag_m) continue;
      if (nested_in(curves[shapes[i].curve], curves[shapes[j].curve], boxes[i], boxes[j])) {
        ++shapes[j].inside;
        shapes[i].top = false;
        if (shapes[i].parent < 0 || shapes[j].diag_m < shapes[static_cast<std::size_t>(shapes[i].parent)].diag_m)
          shapes[i].parent = static_cast<int>(j);
      }
    }
  return shapes;
}

const char* size_word(const Shape& s, Vec2 half) {
  const double ws = 2.0 * length(half);
  return s.diag_m > 0.4 * ws ? "large" : (s.diag_m > 0.15 * ws ? "medium" : "small");
}

}  // namespace

std::string place_words(Vec2 c, Vec2 half) {
  // Thirds of the workspace; +y is away from the visitor: far. (Up on the screen, but a visitor who
  // cannot see it knows only near and far.)
  const int col = c.x < -half.x / 3 ? 0 : (c.x > half.x / 3 ? 2 : 1);
  const int row = c.y > half.y / 3 ? 0 : (c.y < -half.y / 3 ? 2 : 1);
  static const char* const names[3][3] = {{"at the far left", "in the far middle", "at the far right"},
                                          {"on the left", "in the middle", "on the right"},
                                          {"at the near left", "in the near middle", "at the near right"}};
  return names[row][col];
}

ShapeAtHand shape_at_hand(const std::vector<Polyline>& curves, Vec2 hand_m, int contact_curve, double on_within_m) {
  ShapeAtHand r;
  for (std::size_t k = 0; k < curves.size(); ++k) {
    const double d = distance_to(curves[k], hand_m);
    if (d < r.distance_m) {
      r.distance_m = d;
      r.curve = static_cast<int>(k);
    }
  }
  if (contact_curve >= 0 && static_cast<std::size_t>(contact_curve) < curves.size()) {
    r.curve = contact_curve;  // the wall the proxy rests on is what the hand feels
    r.distance_m = distance_to(curves[static_cast<std::size_t>(contact_curve)], hand_m);
    r.on = true;
  } else {
    r.on = r.curve >= 0 && r.distance_m <= on_within_m;
  }
  return r;
}

std::string describe_one_shape(const std::vector<Polyline>& curves, std::size_t index, Vec2 half, bool with_place) {
  const std::vector<Shape> all = shapes_of(curves);
  const auto it = std::find_if(all.begin(), all.end(), [&](const Shape& s) { return s.curve == index; });
  if (it == all.end()) return "an empty shape";
  const Shape& s = *it;
  std::string out = std::string("a ") + size_word(s, half) + (s.closed ? " closed shape" : " line");
  if (s.inside > 0) out += s.inside == 1 ? " with one inside it" : " with " + std::to_string(s.inside) + " inside it";
  if (s.parent >= 0) {
    const Shape& p = all[static_cast<std::size_t>(s.parent)];
    out += std::string(s.inside > 0 ? ", in a " : " in a ") + size_word(p, half) + " closed shape";
  }
  return with_place ? out + ", " + place_words(s.centre_m, half) : out;
}

std::string describe_scene(const std::vector<Polyline>& curves, Vec2 half, int max_named, std::optional<Vec2> hand_m) {
  std::vector<Shape> all = shapes_of(curves);
  if (all.empty()) return "There are no shapes in this picture.";
  std::vector<Shape> top;
  for (const Shape& s : all)
    if (s.top) top.push_back(s);
  std::stable_sort(top.begin(), top.end(), [](const Shape& a, const Shape& b) { return a.diag_m > b.diag_m; });
  if (hand_m) {  // from where the hand is: the nearest first (a shape holding the hand is at distance 0)
    auto reach = [&](const Shape& s) {
      const Polyline& c = curves[s.curve];
      return c.closed && c.points_m.size() > 2 && inside_polygon(*hand_m, c.points_m) ? 0.0 : distance_to(c, *hand_m);
    };
    std::stable_sort(top.begin(), top.end(), [&](const Shape& a, const Shape& b) { return reach(a) < reach(b); });
  }
  auto size = [&](const Shape& s) { return size_word(s, half); };
  std::string out = all.size() == 1 ? "One shape. " : std::to_string(all.size()) + " shapes. ";
  const std::size_t named = std::min<std::size_t>(top.size(), static_cast<std::size_t>(std::max(1, max_named)));
  std::size_t told = 0;  // shapes spoken of so far, the nested ones included
  for (std::size_t i = 0; i < named; ++i) {
    const Shape& s = top[i];
    std::string part = std::string(i == 0 ? (hand_m ? "Nearest your hand, a " : "A ") : "a ") + size(s) +
                       (s.closed ? " closed shape" : " line");
    if (s.inside > 0)
      part += s.inside == 1 ? " with a smaller shape inside it,"
                            : " with " + std::to_string(s.inside) + " smaller shapes inside it,";
    part += std::string(" ") + place_words(s.centre_m, half);
    told += 1 + static_cast<std::size_t>(s.inside);
    if (i > 0) out += (i + 1 == named && told == all.size()) ? ", and " : ", ";
    out += part;
  }
  if (told < all.size()) {
    const std::size_t rest = all.size() - told;
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
      const bool touch =
          a0.x - margin_m <= b1.x && b0.x <= a1.x + margin_m && a0.y - margin_m <= b1.y && b0.y <= a1.y + margin_m;
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

std::string first_words(const std::string& text, int n) {
  std::string out;
  int words = 0;
  std::size_t i = 0;
  while (i < text.size() && words < n) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    const std::size_t start = i;
    while (i < text.size() && !std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    if (i == start) break;
    if (!out.empty()) out += ' ';
    out.append(text, start, i - start);
    ++words;
  }
  return out;
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
