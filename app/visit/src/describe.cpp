#include "visit/describe.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

namespace hk::app {
namespace {

struct Shape {
  double diag_m;
  Vec2 centre_m;
  Vec2 lo_m, hi_m;  // bounding box
  bool closed;
  std::size_t curve;  // index in the curves described
  int inside = 0;     // shapes nested in it, at any depth (specks not counted)
  bool top = true;    // inside no other shape
  int parent = -1;    // the smallest shape it lies inside (index into the shapes), −1 for none
};

/// Distance from `p` to the polyline of `c` (with its closing segment when closed) [m], and its nearest point.
double distance_to(const Polyline& c, Vec2 p, Vec2* nearest = nullptr) {
  const std::vector<Vec2>& q = c.points_m;
  if (q.empty()) return std::numeric_limits<double>::infinity();
  double best = length(p - q[0]);
  if (nearest) *nearest = q[0];
  const std::size_t n = q.size(), segments = c.closed && n > 2 ? n : n - 1;
  for (std::size_t i = 0; i < segments; ++i) {
    const Vec2 a = q[i], b = q[(i + 1) % n], ab = b - a;
    const double len2 = dot(ab, ab);
    const double t = len2 > 0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    const double d = length(p - (a + t * ab));
    if (d < best) {
      best = d;
      if (nearest) *nearest = a + t * ab;
    }
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

bool holds(const Polyline& c, Vec2 p) { return c.closed && c.points_m.size() > 2 && inside_polygon(p, c.points_m); }

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

/// The descriptors to describe `curves` by: `given` when it has one per curve, else forms from the curves'
/// own points (no colours).
std::vector<meaning::ShapeDescriptor> descriptors_for(const std::vector<Polyline>& curves,
                                                      const std::vector<meaning::ShapeDescriptor>& given) {
  return given.size() == curves.size() ? given : meaning::describe_shapes(curves, meaning::PictureColours{});
}

/// The shapes of `curves` that are not specks, with their nesting: `inside` counts the shapes within each closed
/// shape (at any depth), `top` marks those within none.
std::vector<Shape> shapes_of(const std::vector<Polyline>& curves, const std::vector<meaning::ShapeDescriptor>& ds) {
  std::vector<Shape> shapes;
  std::vector<std::pair<Vec2, Vec2>> boxes;
  for (std::size_t k = 0; k < curves.size(); ++k) {
    const Polyline& p = curves[k];
    if (p.points_m.empty() || ds[k].speck) continue;
    boxes.push_back(bounds_of(p));
    const auto& [lo, hi] = boxes.back();
    shapes.push_back({length(hi - lo), 0.5 * (lo + hi), lo, hi, p.closed, k});
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

const char* size_word(double diag_m, Vec2 half) {
  const double ws = 2.0 * length(half);
  return diag_m > 0.4 * ws ? "large" : (diag_m > 0.15 * ws ? "medium" : "small");
}

const char* kCornerWords[] = {"", "", "", "three", "four", "five", "six", "seven", "eight"};

/// The form as words before a noun, and the noun: {"round", "shape"}, {"", "square"}, {"straight", "line"}.
std::pair<std::string, std::string> form_words(const meaning::ShapeDescriptor& d) {
  using meaning::Form;
  switch (d.form.form) {
    case Form::round:
      return {"round", "shape"};
    case Form::oval:
      return {"oval", "shape"};
    case Form::square:
      return {"", "square"};
    case Form::rectangle:
      return {"", "rectangle"};
    case Form::triangle:
      return {"", "triangle"};
    case Form::star:
      return {"", "star"};
    case Form::polygon:
      return {d.form.corners >= 3 && d.form.corners <= 8 ? std::string(kCornerWords[d.form.corners]) + "-cornered" : "",
              "shape"};
    case Form::straight_line:
      return {"straight", "line"};
    case Form::curve:
      return {d.form.corners > 0 ? "bent" : "curved", "line"};
    case Form::irregular:
      break;
  }
  return {"", "shape"};
}

/// What a shape looks like without an article: "small white round shape" (`count` > 1: "small white round
/// shapes"); `shade` false leaves out light and dark ("small blue square" for a light blue one).
std::string look_words(const Shape& s, const meaning::ShapeDescriptor& d, Vec2 half, int count = 1, bool shade = true) {
  std::string out = size_word(s.diag_m, half);
  if (d.has_colour)
    out += " " + meaning::colour_words(shade ? d.colour : meaning::ColourName{d.colour.colour, meaning::Shade::plain});
  const auto [adjective, noun] = form_words(d);
  if (!adjective.empty()) out += " " + adjective;
  return out + " " + noun + (count > 1 ? "s" : "");
}

/// "a" or "an" before `words`.
std::string with_article(const std::string& words) {
  const bool vowel = !words.empty() && std::string("aeiou").find(words[0]) != std::string::npos;
  return (vowel ? "an " : "a ") + words;
}

/// Shapes said together: alike in size word, colour term and form (their shade said only when they share it).
struct Group {
  std::string key;                   // look_words without the shade: what makes shapes alike
  std::string look, looks;           // as said, singular and plural
  std::vector<std::size_t> members;  // indices into the shapes
  double max_diag_m = 0;
  std::string place;  // the members' place (place_words), or "across the picture" when they differ
};

/// The shapes `members` (indices into `all`) in groups of alike ones, in the order of their first member.
std::vector<Group> group_alike(const std::vector<Shape>& all, const std::vector<std::size_t>& members,
                               const std::vector<meaning::ShapeDescriptor>& ds, Vec2 half) {
  std::vector<Group> groups;
  for (const std::size_t i : members) {
    const Shape& s = all[i];
    const meaning::ShapeDescriptor& d = ds[s.curve];
    const std::string key = look_words(s, d, half, 1, false);
    const std::string place = place_words(s.centre_m, half);
    auto g = std::find_if(groups.begin(), groups.end(), [&](const Group& x) { return x.key == key; });
    if (g == groups.end()) {
      groups.push_back({key, look_words(s, d, half), look_words(s, d, half, 2), {}, 0.0, place});
      g = groups.end() - 1;
    } else {
      if (g->look != look_words(s, d, half)) {  // shades differ: the colour term alone
        g->look = key;
        g->looks = look_words(s, d, half, 2, false);
      }
      if (g->place != place) g->place = "across the picture";
    }
    g->members.push_back(i);
    g->max_diag_m = std::max(g->max_diag_m, s.diag_m);
  }
  return groups;
}

/// A group as said: "a small white round shape" or "26 small white round shapes".
std::string group_words(const Group& g) {
  return g.members.size() == 1 ? with_article(g.look) : std::to_string(g.members.size()) + " " + g.looks;
}

/// What lies inside shape `index` (at any depth), as groups: " with 26 small white round shapes inside it",
/// " with a small red square and 2 small blue triangles inside it", " with 9 smaller shapes inside it" when they
/// are of more than two kinds; "" when nothing is.
std::string inside_words(const std::vector<Shape>& all, std::size_t index,
                         const std::vector<meaning::ShapeDescriptor>& ds, Vec2 half) {
  std::vector<std::size_t> within;
  for (std::size_t i = 0; i < all.size(); ++i)
    for (int p = all[i].parent; p >= 0; p = all[static_cast<std::size_t>(p)].parent)
      if (static_cast<std::size_t>(p) == index) {
        within.push_back(i);
        break;
      }
  if (within.empty()) return "";
  const std::vector<Group> groups = group_alike(all, within, ds, half);
  if (groups.size() == 1) return " with " + group_words(groups[0]) + " inside it";
  if (groups.size() == 2) return " with " + group_words(groups[0]) + " and " + group_words(groups[1]) + " inside it";
  return " with " + std::to_string(within.size()) + " smaller shapes inside it";
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

ShapeAtHand shape_at_hand(const std::vector<Polyline>& curves, const std::vector<meaning::ShapeDescriptor>& descriptors,
                          Vec2 hand_m, int contact_curve, double on_within_m) {
  const auto counts = [&](std::size_t k) { return descriptors.size() != curves.size() || !descriptors[k].speck; };
  ShapeAtHand r;
  for (std::size_t k = 0; k < curves.size(); ++k) {
    if (!counts(k)) continue;
    Vec2 q;
    const double d = distance_to(curves[k], hand_m, &q);
    if (d < r.distance_m) {
      r.distance_m = d;
      r.curve = static_cast<int>(k);
      r.nearest_m = q;
    }
  }
  if (contact_curve >= 0 && static_cast<std::size_t>(contact_curve) < curves.size() &&
      counts(static_cast<std::size_t>(contact_curve))) {
    r.curve = contact_curve;  // the wall the proxy rests on is what the hand feels
    r.distance_m = distance_to(curves[static_cast<std::size_t>(contact_curve)], hand_m, &r.nearest_m);
    r.on = true;
    return r;
  }
  r.on = r.curve >= 0 && r.distance_m <= on_within_m;
  if (r.on) return r;
  int holder = -1;
  double holder_diag = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < curves.size(); ++k) {
    if (!counts(k) || !holds(curves[k], hand_m)) continue;
    const auto [lo, hi] = bounds_of(curves[k]);
    if (length(hi - lo) < holder_diag) {
      holder_diag = length(hi - lo);
      holder = static_cast<int>(k);
    }
  }
  if (holder >= 0) {
    r.curve = holder;
    r.inside = true;
    r.distance_m = distance_to(curves[static_cast<std::size_t>(holder)], hand_m, &r.nearest_m);
  }
  return r;
}

bool shape_holds(const Polyline& c, Vec2 p_m) { return holds(c, p_m); }

std::string direction_words(Vec2 from, Vec2 to) {
  const Vec2 v = to - from;
  const double d = length(v);
  const std::string how_far =
      d < 0.01 ? "less than a centimetre" : std::to_string(static_cast<int>(std::lround(d * 100.0))) + " cm";
  // Eight sectors of 45°, +x (right) at 0°, +y (far) at 90°.
  const double deg = std::atan2(v.y, v.x) * 180.0 / std::numbers::pi;
  const int sector = static_cast<int>(std::lround(deg / 45.0)) & 7;
  static const char* const ways[8] = {
      "to your right", "farther away, to your right", "farther away",  "farther away, to your left",
      "to your left",  "nearer to you, to your left", "nearer to you", "nearer to you, to your right"};
  return how_far + " " + ways[sector];
}

std::pair<int, int> shape_number(const std::vector<meaning::ShapeDescriptor>& descriptors, std::size_t curves,
                                 std::size_t curve) {
  const bool known = descriptors.size() == curves;
  int number = 0, count = 0;
  for (std::size_t k = 0; k < curves; ++k) {
    if (known && descriptors[k].speck) continue;
    ++count;
    if (k == curve) number = count;
  }
  return {number, count};
}

std::string describe_one_shape(const std::vector<Polyline>& curves,
                               const std::vector<meaning::ShapeDescriptor>& descriptors, std::size_t index, Vec2 half,
                               bool with_place) {
  const std::vector<meaning::ShapeDescriptor> ds = descriptors_for(curves, descriptors);
  const std::vector<Shape> all = shapes_of(curves, ds);
  const auto it = std::find_if(all.begin(), all.end(), [&](const Shape& s) { return s.curve == index; });
  if (it == all.end()) return "a speck";
  const Shape& s = *it;
  const std::string out = with_article(look_words(s, ds[s.curve], half)) +
                          inside_words(all, static_cast<std::size_t>(it - all.begin()), ds, half);
  return with_place ? out + ", " + place_words(s.centre_m, half) : out;
}

std::string describe_one_look(const std::vector<Polyline>& curves,
                              const std::vector<meaning::ShapeDescriptor>& descriptors, std::size_t index, Vec2 half) {
  const std::vector<meaning::ShapeDescriptor> ds = descriptors_for(curves, descriptors);
  if (index >= curves.size() || curves[index].points_m.empty() || ds[index].speck) return "a speck";
  const auto [lo, hi] = bounds_of(curves[index]);
  const Shape s{length(hi - lo), 0.5 * (lo + hi), lo, hi, curves[index].closed, index};
  return with_article(look_words(s, ds[index], half));
}

std::string said_name(const std::string& name) {
  if (name.empty()) return name;
  const unsigned char c = static_cast<unsigned char>(name[0]);
  for (const char* article : {"the ", "a ", "an "})
    if (name.rfind(article, 0) == 0) return name;
  return c < 0x80 && std::islower(c) ? "the " + name : name;
}

namespace {

/// The top-level shapes (inside no other), the largest first or, given a hand, the nearest first (a shape
/// holding the hand at distance 0).
std::vector<std::size_t> ordered_top(const std::vector<Shape>& all, const std::vector<Polyline>& curves,
                                     std::optional<Vec2> hand_m) {
  std::vector<std::size_t> top;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (all[i].top) top.push_back(i);
  std::stable_sort(top.begin(), top.end(), [&](std::size_t a, std::size_t b) { return all[a].diag_m > all[b].diag_m; });
  if (!hand_m) return top;
  std::vector<double> reach(all.size(), 0.0);
  for (const std::size_t i : top) {
    const Polyline& c = curves[all[i].curve];
    reach[i] = holds(c, *hand_m) ? 0.0 : distance_to(c, *hand_m);
  }
  std::stable_sort(top.begin(), top.end(), [&](std::size_t a, std::size_t b) { return reach[a] < reach[b]; });
  return top;
}

/// Up to `max_named` of `groups` said, the rest counted ("and 4 more, smaller ones."): the list after "N shapes. ".
/// `told` counts the shapes already spoken of (the nested ones of a single shape said with it); `lead` opens
/// the list ("Nearest your hand, "), its first letter made a capital.
std::string list_groups(const std::vector<Group>& groups, const std::vector<Shape>& all, std::size_t count,
                        std::size_t told, const std::vector<meaning::ShapeDescriptor>& ds, Vec2 half, int max_named,
                        const std::string& lead, bool with_inside) {
  std::string out;
  const std::size_t named = std::min<std::size_t>(groups.size(), static_cast<std::size_t>(std::max(1, max_named)));
  double smallest_named = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < named; ++i) {
    const Group& g = groups[i];
    std::string part = group_words(g);
    if (i == 0) {
      part = sentence_case(lead + part);
    }
    const std::size_t m0 = g.members[0];
    told += g.members.size();
    if (with_inside) {
      for (const std::size_t m : g.members) told += static_cast<std::size_t>(all[m].inside);
      if (g.members.size() == 1) part += inside_words(all, m0, ds, half) + (all[m0].inside ? "," : "");
    }
    part += " " + g.place;
    smallest_named = std::min(smallest_named, g.max_diag_m);
    if (i > 0) out += (i + 1 == named && told >= count) ? ", and " : ", ";
    out += part;
  }
  if (told >= count) return out + ".";
  const std::size_t rest = count - told;
  bool smaller = true;
  for (std::size_t i = named; i < groups.size(); ++i) smaller = smaller && groups[i].max_diag_m < smallest_named;
  return out + ", and " + std::to_string(rest) + " more" +
         (smaller ? (rest == 1 ? ", smaller." : ", smaller ones.") : ".");
}

/// The named parts, largest first, each with its place: "The left wing on the left, and the body in the middle."
std::string named_parts_words(const PictureNames& names, Vec2 half) {
  std::string out;
  for (std::size_t i = 0; i < names.parts.size(); ++i) {
    std::string part = names.parts[i].name + " " + place_words(names.parts[i].centre_m, half);
    if (i == 0) part = sentence_case(part);
    if (i > 0) out += i + 1 == names.parts.size() ? ", and " : ", ";
    out += part;
  }
  return out + ".";
}

}  // namespace

std::string describe_scene(const std::vector<Polyline>& curves,
                           const std::vector<meaning::ShapeDescriptor>& descriptors, Vec2 half, int max_named,
                           std::optional<Vec2> hand_m, const PictureNames* names) {
  const std::vector<meaning::ShapeDescriptor> ds = descriptors_for(curves, descriptors);
  const std::vector<Shape> all = shapes_of(curves, ds);
  const bool named = names && !names->parts.empty();
  if (all.empty() && !named) return "There are no shapes in this picture.";
  std::string out = all.size() == 1 ? "One shape. " : std::to_string(all.size()) + " shapes. ";
  if (all.empty()) out.clear();
  if (!named)  // shapes alike said together
    return out + list_groups(group_alike(all, ordered_top(all, curves, hand_m), ds, half), all, all.size(), 0, ds, half,
                             max_named, hand_m ? "Nearest your hand, " : "", true);
  // Named parts first; then the shapes without a name, in groups, wherever they lie.
  out += named_parts_words(*names, half);
  std::vector<std::size_t> unnamed;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (names->shape_name.size() != curves.size() || names->shape_name[all[i].curve].empty()) unnamed.push_back(i);
  std::stable_sort(unnamed.begin(), unnamed.end(),
                   [&](std::size_t a, std::size_t b) { return all[a].diag_m > all[b].diag_m; });
  if (unnamed.empty()) return out;
  return out + " " +
         list_groups(group_alike(all, unnamed, ds, half), all, unnamed.size(), 0, ds, half, max_named, "Also ", false);
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

std::string sentence_case(std::string text) {
  if (!text.empty() && text[0] >= 'a' && text[0] <= 'z') text[0] = static_cast<char>(text[0] - 'a' + 'A');
  return text;
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
