#include "visit/describe.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

#include "hk/text.hpp"

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

const char* size_key(double diag_m, Vec2 half) {
  const double ws = 2.0 * length(half);
  return diag_m > 0.4 * ws ? "large" : (diag_m > 0.15 * ws ? "medium" : "small");
}

/// The look_* / gender_* ending of a form ("round", "square", "polygon", "straight", "shape", …).
std::string form_ending(const meaning::ShapeDescriptor& d) {
  using meaning::Form;
  switch (d.form.form) {
    case Form::round:
      return "round";
    case Form::oval:
      return "oval";
    case Form::square:
      return "square";
    case Form::rectangle:
      return "rectangle";
    case Form::triangle:
      return "triangle";
    case Form::star:
      return "star";
    case Form::polygon:
      return d.form.corners >= 4 && d.form.corners <= 8 ? "polygon" : "shape";
    case Form::straight_line:
      return "straight";
    case Form::curve:
      return d.form.corners > 0 ? "bent" : "curved";
    case Form::irregular:
      break;
  }
  return "shape";
}

/// What makes shapes alike: the same size word, colour term and form.
struct LookKey {
  std::string size, form;
  int corners = 0;
  bool has_colour = false;
  meaning::BasicColour colour = meaning::BasicColour::grey;
  bool operator==(const LookKey&) const = default;
};

LookKey look_key(const Shape& s, const meaning::ShapeDescriptor& d, Vec2 half) {
  return {size_key(s.diag_m, half), form_ending(d), d.form.form == meaning::Form::polygon ? d.form.corners : 0,
          d.has_colour, d.colour.colour};
}

/// A shape's look as the catalogue says it: "a small white round shape" (`count` > 1: "26 small white round
/// shapes"); `shade` false leaves out light and dark ("small blue square" for a light blue one). The size and
/// colour words take the gender of the form's noun (gender_*) and the number of `count`.
std::string look_words(const audio::MessageCatalog& m, const LookKey& k, meaning::Shade shade, int count = 1) {
  const std::string gender = m.word("gender_" + k.form);
  const std::string g = gender == "m" || gender == "f" ? gender : "n";
  std::string colour;
  if (k.has_colour) {
    colour = m.word("colour_" + std::string(meaning::colour_key(k.colour)) + "_" + g, count);
    if (shade != meaning::Shade::plain)
      colour = m.word(shade == meaning::Shade::light ? "shade_light" : "shade_dark", count, {{"colour", colour}});
  }
  return m.word("look_" + k.form, count,
                {{"size", m.word("size_" + k.size + "_" + g, count)},
                 {"colour", colour},
                 {"corners", std::to_string(k.corners)}});
}

/// Shapes said together: alike in size word, colour term and form (their shade said only when they share it).
struct Group {
  LookKey key;
  meaning::Shade shade = meaning::Shade::plain;  // the members' shade, plain when they differ
  std::vector<std::size_t> members;              // indices into the shapes
  double max_diag_m = 0;
  std::string place;  // the members' place key (place_key), or "across" when they differ
};

/// The place_* key of point `c` in the 3 x 3 grid of the workspace ("far_left", …, "near_right").
std::string place_key(Vec2 c, Vec2 half) {
  // Thirds of the workspace; +y is away from the visitor: far. (Up on the screen, but a visitor who
  // cannot see it knows only near and far.)
  const int col = c.x < -half.x / 3 ? 0 : (c.x > half.x / 3 ? 2 : 1);
  const int row = c.y > half.y / 3 ? 0 : (c.y < -half.y / 3 ? 2 : 1);
  static const char* const keys[3][3] = {
      {"far_left", "far_middle", "far_right"}, {"left", "middle", "right"}, {"near_left", "near_middle", "near_right"}};
  return keys[row][col];
}

/// The shapes `members` (indices into `all`) in groups of alike ones, in the order of their first member.
std::vector<Group> group_alike(const std::vector<Shape>& all, const std::vector<std::size_t>& members,
                               const std::vector<meaning::ShapeDescriptor>& ds, Vec2 half) {
  std::vector<Group> groups;
  for (const std::size_t i : members) {
    const Shape& s = all[i];
    const meaning::ShapeDescriptor& d = ds[s.curve];
    const LookKey key = look_key(s, d, half);
    const std::string place = place_key(s.centre_m, half);
    auto g = std::find_if(groups.begin(), groups.end(), [&](const Group& x) { return x.key == key; });
    if (g == groups.end()) {
      groups.push_back({key, d.has_colour ? d.colour.shade : meaning::Shade::plain, {}, 0.0, place});
      g = groups.end() - 1;
    } else {
      if (g->shade != d.colour.shade) g->shade = meaning::Shade::plain;  // shades differ: the colour term alone
      if (g->place != place) g->place = "across";
    }
    g->members.push_back(i);
    g->max_diag_m = std::max(g->max_diag_m, s.diag_m);
  }
  return groups;
}

/// A group as said: "a small white round shape" or "26 small white round shapes".
std::string group_words(const audio::MessageCatalog& m, const Group& g) {
  return look_words(m, g.key, g.shade, static_cast<int>(g.members.size()));
}

/// What lies inside shape `index` (at any depth), as groups: "26 small white round shapes", "a small red
/// square and 2 small blue triangles", "9 smaller shapes" when they are of more than two kinds; "" when
/// nothing is.
std::string inside_words(const audio::MessageCatalog& m, const std::vector<Shape>& all, std::size_t index,
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
  if (groups.size() == 1) return group_words(m, groups[0]);
  if (groups.size() == 2)
    return m.word("list_two", 1, {{"first", group_words(m, groups[0])}, {"second", group_words(m, groups[1])}});
  return m.word("inside_many", static_cast<long>(within.size()));
}

}  // namespace

std::string place_words(Vec2 c, Vec2 half, const audio::MessageCatalog& m) {
  return m.word("place_" + place_key(c, half));
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

std::string direction_words(Vec2 from, Vec2 to, const audio::MessageCatalog& m) {
  const Vec2 v = to - from;
  const double d = length(v);
  const std::string how_far =
      d < 0.01 ? m.word("distance_under_cm") : m.word("distance_cm", static_cast<long>(std::lround(d * 100.0)));
  // Eight sectors of 45°, +x (right) at 0°, +y (far) at 90°.
  const double deg = std::atan2(v.y, v.x) * 180.0 / std::numbers::pi;
  const int sector = static_cast<int>(std::lround(deg / 45.0)) & 7;
  static const char* const ways[8] = {"way_right", "way_far_right", "way_far",  "way_far_left",
                                      "way_left",  "way_near_left", "way_near", "way_near_right"};
  return m.word("direction", 1, {{"distance", how_far}, {"way", m.word(ways[sector])}});
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
                               bool with_place, const audio::MessageCatalog& m) {
  const std::vector<meaning::ShapeDescriptor> ds = descriptors_for(curves, descriptors);
  const std::vector<Shape> all = shapes_of(curves, ds);
  const auto it = std::find_if(all.begin(), all.end(), [&](const Shape& s) { return s.curve == index; });
  if (it == all.end()) return m.word("look_speck");
  const Shape& s = *it;
  const meaning::ShapeDescriptor& d = ds[s.curve];
  const std::string look = look_words(m, look_key(s, d, half), d.has_colour ? d.colour.shade : meaning::Shade::plain);
  const std::string inside = inside_words(m, all, static_cast<std::size_t>(it - all.begin()), ds, half);
  const std::string place = place_words(s.centre_m, half, m);
  if (inside.empty()) return with_place ? m.word("shape_place", 1, {{"shape", look}, {"place", place}}) : look;
  return with_place ? m.word("shape_inside_place", 1, {{"shape", look}, {"inside", inside}, {"place", place}})
                    : m.word("shape_inside", 1, {{"shape", look}, {"inside", inside}});
}

std::string describe_one_look(const std::vector<Polyline>& curves,
                              const std::vector<meaning::ShapeDescriptor>& descriptors, std::size_t index, Vec2 half,
                              const audio::MessageCatalog& m) {
  const std::vector<meaning::ShapeDescriptor> ds = descriptors_for(curves, descriptors);
  if (index >= curves.size() || curves[index].points_m.empty() || ds[index].speck) return m.word("look_speck");
  const auto [lo, hi] = bounds_of(curves[index]);
  const Shape s{length(hi - lo), 0.5 * (lo + hi), lo, hi, curves[index].closed, index};
  const meaning::ShapeDescriptor& d = ds[index];
  return look_words(m, look_key(s, d, half), d.has_colour ? d.colour.shade : meaning::Shade::plain);
}

std::string said_name(const std::string& name, const audio::MessageCatalog& m) {
  if (name.empty()) return name;
  const unsigned char c = static_cast<unsigned char>(name[0]);
  for (const char* article : {"the ", "a ", "an "})
    if (name.rfind(article, 0) == 0) return name;
  return c < 0x80 && std::islower(c) ? m.word("name_the", 1, {{"name", name}}) : name;
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

/// Items joined as the catalogue joins a list: "A", "A, and B", "A, B, and C" (list_next, list_last).
std::string join_list(const audio::MessageCatalog& m, const std::vector<std::string>& items, bool last_is_end) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i == 0)
      out = items[0];
    else
      out = m.word(i + 1 == items.size() && last_is_end ? "list_last" : "list_next", 1,
                   {{"list", out}, {"item", items[i]}});
  }
  return out;
}

/// Up to `max_named` of `groups` said, the rest counted ("and 4 more, smaller ones."): the list after "N shapes. ".
/// `told` counts the shapes already spoken of (the nested ones of a single shape said with it); `lead` (a
/// scene_* key, or "") opens the list ("Nearest your hand, "), its first letter made a capital.
std::string list_groups(const audio::MessageCatalog& m, const std::vector<Group>& groups, const std::vector<Shape>& all,
                        std::size_t count, std::size_t told, const std::vector<meaning::ShapeDescriptor>& ds, Vec2 half,
                        int max_named, const char* lead, bool with_inside) {
  const std::size_t named = std::min<std::size_t>(groups.size(), static_cast<std::size_t>(std::max(1, max_named)));
  double smallest_named = std::numeric_limits<double>::infinity();
  std::vector<std::string> items;
  for (std::size_t i = 0; i < named; ++i) {
    const Group& g = groups[i];
    const std::string look = group_words(m, g);
    const std::string place = m.word("place_" + g.place);
    const std::size_t m0 = g.members[0];
    told += g.members.size();
    std::string inside;
    if (with_inside) {
      for (const std::size_t k : g.members) told += static_cast<std::size_t>(all[k].inside);
      if (g.members.size() == 1) inside = inside_words(m, all, m0, ds, half);
    }
    items.push_back(inside.empty()
                        ? m.word("shape_place", 1, {{"shape", look}, {"place", place}})
                        : m.word("shape_inside_place", 1, {{"shape", look}, {"inside", inside}, {"place", place}}));
    smallest_named = std::min(smallest_named, g.max_diag_m);
  }
  std::string list = join_list(m, items, told >= count);
  if (*lead) list = m.word(lead, 1, {{"list", list}});
  list = sentence_case(list);
  if (told >= count) return m.word("list_end", 1, {{"list", list}});
  const std::size_t rest = count - told;
  bool smaller = true;
  for (std::size_t i = named; i < groups.size(); ++i) smaller = smaller && groups[i].max_diag_m < smallest_named;
  return m.word(smaller ? "list_rest_smaller" : "list_rest", static_cast<long>(rest), {{"list", list}});
}

/// The named parts, largest first, each with its place: "The left wing on the left, and the body in the middle."
std::string named_parts_words(const audio::MessageCatalog& m, const PictureNames& names, Vec2 half) {
  std::vector<std::string> items;
  for (const PictureNames::Part& part : names.parts)
    items.push_back(m.word("shape_place", 1, {{"shape", part.name}, {"place", place_words(part.centre_m, half, m)}}));
  return m.word("list_end", 1, {{"list", sentence_case(join_list(m, items, true))}});
}

}  // namespace

std::string describe_scene(const std::vector<Polyline>& curves,
                           const std::vector<meaning::ShapeDescriptor>& descriptors, Vec2 half, int max_named,
                           std::optional<Vec2> hand_m, const PictureNames* names, const audio::MessageCatalog& m) {
  const std::vector<meaning::ShapeDescriptor> ds = descriptors_for(curves, descriptors);
  const std::vector<Shape> all = shapes_of(curves, ds);
  const bool named = names && !names->parts.empty();
  if (all.empty() && !named) return m.word("scene_none");
  std::string out = all.empty() ? std::string() : m.word("scene_count", static_cast<long>(all.size())) + " ";
  if (!named)  // shapes alike said together
    return out + list_groups(m, group_alike(all, ordered_top(all, curves, hand_m), ds, half), all, all.size(), 0, ds,
                             half, max_named, hand_m ? "scene_nearest" : "", true);
  // Named parts first; then the shapes without a name, in groups, wherever they lie.
  out += named_parts_words(m, *names, half);
  std::vector<std::size_t> unnamed;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (names->shape_name.size() != curves.size() || names->shape_name[all[i].curve].empty()) unnamed.push_back(i);
  std::stable_sort(unnamed.begin(), unnamed.end(),
                   [&](std::size_t a, std::size_t b) { return all[a].diag_m > all[b].diag_m; });
  if (unnamed.empty()) return out;
  return out + " " +
         list_groups(m, group_alike(all, unnamed, ds, half), all, unnamed.size(), 0, ds, half, max_named, "scene_also",
                     false);
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

std::string sentence_case(std::string text) { return hk::capitalised(std::move(text)); }

std::string describe_shapes(int shapes, const audio::MessageCatalog& m) {
  return shapes == 0 ? m.word("shapes_none") : m.word("shapes", shapes);
}

std::string describe_page(int text_blocks, int figures, const audio::MessageCatalog& m) {
  return m.word("page_holds", 1,
                {{"blocks", text_blocks == 0 ? m.word("page_no_text") : m.word("page_blocks", text_blocks)},
                 {"figures", figures == 0 ? m.word("page_no_figures") : m.word("page_figures", figures)}});
}

}  // namespace hk::app
