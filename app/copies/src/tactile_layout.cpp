// A scene laid out as a tactile graphic (tactile_graphic.hpp): page, scale, shapes kept apart, styles, labels, key.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include "copies/tactile_graphic.hpp"
#include "hk/text.hpp"

namespace hk::app {
namespace {

constexpr double kMmPerInch = 25.4;
constexpr int kTitleBrailleLines = 2;  // the title band's braille
constexpr double kTitleBandMm = kTitleBrailleLines * kBrailleLinePitchMm + kPrintTextMm + 2 * kTactileGapMm;
constexpr double kClearMm = kTactileGapMm + kTactileLineWidthMm / 2;  // a label's edge from a line's centre
constexpr double kCellReachMm = 0.71;  // a 1 mm cell's half diagonal: a free cell's every point keeps the clearance
constexpr double kPictureInsetMm = kTactileGapMm + kTactileLineWidthMm;  // the picture inside the frame
constexpr double kLeadLineFromMm = 6.0;  // a label standing farther off its shape gets a lead line
constexpr double kFillPitchMm = 5.0;     // a textured fill's dots

double dist_point_segment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a, ap = p - a;
  const double len2 = ab.x * ab.x + ab.y * ab.y;
  const double t = len2 > 0 ? std::clamp((ap.x * ab.x + ap.y * ab.y) / len2, 0.0, 1.0) : 0.0;
  const Vec2 q = a + t * ab;
  return std::hypot(p.x - q.x, p.y - q.y);
}

bool segments_cross(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a), d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
}

double dist_segment_segment(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  if (segments_cross(a, b, c, d)) return 0.0;
  return std::min({dist_point_segment(a, c, d), dist_point_segment(b, c, d), dist_point_segment(c, a, b),
                   dist_point_segment(d, a, b)});
}

/// Calls f(a, b) for each segment of the polyline (with the closing one when closed).
template <typename F>
void for_segments(const std::vector<Vec2>& p, bool closed, F&& f) {
  if (p.size() == 1) f(p[0], p[0]);
  for (std::size_t i = 0; i + 1 < p.size(); ++i) f(p[i], p[i + 1]);
  if (closed && p.size() > 2) f(p.back(), p.front());
}

struct Box {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

Box box_of(const std::vector<Vec2>& p) {
  Box b{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(),
        std::numeric_limits<double>::lowest()};
  for (const Vec2& q : p) {
    b.x0 = std::min(b.x0, q.x);
    b.y0 = std::min(b.y0, q.y);
    b.x1 = std::max(b.x1, q.x);
    b.y1 = std::max(b.y1, q.y);
  }
  return b;
}

double box_gap(const Box& a, const Box& b) {
  const double dx = std::max({0.0, b.x0 - a.x1, a.x0 - b.x1}), dy = std::max({0.0, b.y0 - a.y1, a.y0 - b.y1});
  return std::hypot(dx, dy);
}

bool inside_polygon(Vec2 p, const std::vector<Vec2>& poly) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2 a = poly[i], b = poly[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x) in = !in;
  }
  return in;
}

std::string with_arg(std::string text, std::string_view key, const std::string& value) {
  const std::size_t at = text.find(key);
  if (at != std::string::npos) text.replace(at, key.size(), value);
  return text;
}

/// Key letters: a … z, then aa, bb, … zz, then aaa …
std::string key_letters(int i) {
  const int round = i / 26 + 1;
  return std::string(static_cast<std::size_t>(round), static_cast<char>('a' + i % 26));
}

// ---- the page's geometry -------------------------------------------------------------------------------

/// The frame's rectangle on `paper`: below the title band, inside the margins.
Box frame_box(PaperSize paper) {
  return {kTactileMarginMm, kTactileMarginMm + kTitleBandMm, paper.width_mm - kTactileMarginMm,
          paper.height_mm - kTactileMarginMm};
}

/// Where the picture goes: the frame less its clearance.
Box picture_box(PaperSize paper) {
  const Box f = frame_box(paper);
  return {f.x0 + kPictureInsetMm, f.y0 + kPictureInsetMm, f.x1 - kPictureInsetMm, f.y1 - kPictureInsetMm};
}

/// Which cells of the page (1 mm) are taken, and by what: −1 free, a shape's index, kLabel, kFrame.
class Occupancy {
 public:
  static constexpr int kFree = -1, kLabel = -2, kFrame = -3;

  explicit Occupancy(PaperSize paper)
      : w_(static_cast<int>(std::ceil(paper.width_mm))),
        h_(static_cast<int>(std::ceil(paper.height_mm))),
        owner_(static_cast<std::size_t>(w_ * h_), kFree) {}

  /// Marks every cell whose centre lies within `r` [mm] of segment a–b as `owner` (a free cell, or any for kLabel
  /// and kFrame).
  void mark_segment(Vec2 a, Vec2 b, double r, int owner) {
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min(a.x, b.x) - r)));
    const int x1 = std::min(w_ - 1, static_cast<int>(std::ceil(std::max(a.x, b.x) + r)));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min(a.y, b.y) - r)));
    const int y1 = std::min(h_ - 1, static_cast<int>(std::ceil(std::max(a.y, b.y) + r)));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x)
        if (dist_point_segment({x + 0.5, y + 0.5}, a, b) <= r) take(x, y, owner);
  }
  void mark_box(const Box& b, double grow, int owner) {
    for (int y = std::max(0, static_cast<int>(std::floor(b.y0 - grow)));
         y <= std::min(h_ - 1, static_cast<int>(std::ceil(b.y1 + grow))); ++y)
      for (int x = std::max(0, static_cast<int>(std::floor(b.x0 - grow)));
           x <= std::min(w_ - 1, static_cast<int>(std::ceil(b.x1 + grow))); ++x)
        take(x, y, owner);
  }
  /// Everything outside `b` taken.
  void mark_outside(const Box& b) {
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x)
        if (x < b.x0 || x + 1 > b.x1 || y < b.y0 || y + 1 > b.y1) take(x, y, kFrame);
  }
  /// True when every cell `b` touches is free.
  bool free(const Box& b) const {
    const int x0 = static_cast<int>(std::floor(b.x0)), x1 = static_cast<int>(std::ceil(b.x1)) - 1;
    const int y0 = static_cast<int>(std::floor(b.y0)), y1 = static_cast<int>(std::ceil(b.y1)) - 1;
    if (x0 < 0 || y0 < 0 || x1 >= w_ || y1 >= h_) return false;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x)
        if (owner_[static_cast<std::size_t>(y * w_ + x)] != kFree) return false;
    return true;
  }
  /// True when segment a–b crosses only free cells and cells of `own`.
  bool clear_path(Vec2 a, Vec2 b, int own) const {
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int steps = std::max(1, static_cast<int>(std::ceil(len / 0.5)));
    for (int i = 0; i <= steps; ++i) {
      const Vec2 p = a + (static_cast<double>(i) / steps) * (b - a);
      const int x = static_cast<int>(p.x), y = static_cast<int>(p.y);
      if (x < 0 || y < 0 || x >= w_ || y >= h_) return false;
      const int o = owner_[static_cast<std::size_t>(y * w_ + x)];
      if (o != kFree && o != own) return false;
    }
    return true;
  }

 private:
  void take(int x, int y, int owner) {
    int& o = owner_[static_cast<std::size_t>(y * w_ + x)];
    if (o == kFree || owner < 0) o = owner;
  }
  int w_, h_;
  std::vector<int> owner_;
};

// ---- the phases ------------------------------------------------------------------------------------------

struct Placed {
  std::vector<Vec2> points_mm;
  bool closed = false;
  std::string name;
  int number = 0;
  double salience = 0;
  Box box;
};

/// The curves on the page, in millimetres.
std::vector<Placed> to_page(const TactileInput& in, double s, Vec2 origin_mm) {
  std::vector<Placed> out;
  for (const TactileCurve& c : in.curves) {
    if (c.points_m.empty()) continue;
    Placed p;
    p.closed = c.closed && c.points_m.size() > 2;
    p.name = c.name;
    p.number = c.number;
    p.salience = c.salience;
    for (const Vec2& q : c.points_m)
      p.points_mm.push_back({origin_mm.x + s * (q.x - in.picture_lo_m.x), origin_mm.y + s * (in.picture_hi_m.y - q.y)});
    p.box = box_of(p.points_mm);
    out.push_back(std::move(p));
  }
  return out;
}

/// The shapes kept: none smaller than kTactileSmallestMm, and most salient first, none nearer one kept before than
/// a line's width plus the gap. Returns how many were left out.
int keep_apart(std::vector<Placed>& shapes) {
  std::stable_sort(shapes.begin(), shapes.end(),
                   [](const Placed& a, const Placed& b) { return a.salience > b.salience; });
  const double apart = kTactileGapMm + kTactileLineWidthMm;
  std::vector<Placed> kept;
  int left_out = 0;
  for (Placed& p : shapes) {
    bool ok = std::max(p.box.x1 - p.box.x0, p.box.y1 - p.box.y0) >= kTactileSmallestMm;
    for (const Placed& k : kept) {
      if (!ok) break;
      if (box_gap(p.box, k.box) >= apart) continue;
      ok = polyline_distance(p.points_mm, p.closed, k.points_mm, k.closed) >= apart;
    }
    if (ok)
      kept.push_back(std::move(p));
    else
      ++left_out;
  }
  shapes = std::move(kept);
  return left_out;
}

/// A line style for each kept shape: closed shapes of different names told apart (the most salient names first),
/// unnamed and open ones solid.
std::vector<LineStyle> choose_styles(const std::vector<Placed>& shapes) {
  static constexpr LineStyle kOrder[] = {LineStyle::solid, LineStyle::dashed, LineStyle::dotted, LineStyle::dash_dot,
                                         LineStyle::textured};
  const bool any_unnamed = std::any_of(shapes.begin(), shapes.end(), [](const Placed& p) { return p.name.empty(); });
  std::map<std::string, LineStyle> by_name;
  int next = any_unnamed ? 1 : 0;  // solid stays for the unnamed when there are some
  std::vector<LineStyle> out;
  for (const Placed& p : shapes) {
    if (!p.closed || p.name.empty()) {
      out.push_back(LineStyle::solid);
      continue;
    }
    auto it = by_name.find(p.name);
    if (it == by_name.end())
      it = by_name.emplace(p.name, next < kTactileStyles ? kOrder[next++] : LineStyle::solid).first;
    out.push_back(it->second);
  }
  return out;
}

/// The dots of a textured shape's fill: a 5 mm grid inside it, each dot 3 mm clear of every outline kept.
std::vector<Vec2> fill_dots(const Placed& shape, const std::vector<Placed>& all) {
  std::vector<Vec2> dots;
  const double clear = kTactileGapMm + kTactileLineWidthMm / 2 + kBrailleDotDiameterMm / 2;
  for (double y = std::ceil(shape.box.y0 / kFillPitchMm) * kFillPitchMm; y <= shape.box.y1; y += kFillPitchMm)
    for (double x = std::ceil(shape.box.x0 / kFillPitchMm) * kFillPitchMm; x <= shape.box.x1; x += kFillPitchMm) {
      const Vec2 p{x, y};
      if (!inside_polygon(p, shape.points_mm)) continue;
      bool ok = true;
      for (const Placed& o : all) {
        if (!ok) break;
        for_segments(o.points_mm, o.closed, [&](Vec2 a, Vec2 b) { ok = ok && dist_point_segment(p, a, b) >= clear; });
      }
      if (ok) dots.push_back(p);
    }
  return dots;
}

/// A label's size on the page [mm]: its braille line, and its print line under it when given.
Vec2 label_size(const std::string& cells, const std::string& print) {
  const double braille_w = braille_cell_count(cells) * kBrailleCellPitchMm;
  const double print_w = print.empty() ? 0.0 : print_width_mm(print);
  return {std::max(braille_w, print_w), kBrailleLinePitchMm + (print.empty() ? 0.0 : kPrintTextMm + 1.0)};
}

/// Samples of a shape's outline about every `step` [mm] (at most 80).
std::vector<Vec2> outline_samples(const Placed& p, double step) {
  std::vector<Vec2> out;
  for_segments(p.points_mm, p.closed, [&](Vec2 a, Vec2 b) {
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int n = std::max(1, static_cast<int>(len / step));
    for (int i = 0; i < n; ++i) out.push_back(a + (static_cast<double>(i) / n) * (b - a));
  });
  if (out.size() > 80) {
    std::vector<Vec2> thin;
    for (std::size_t i = 0; i < 80; ++i) thin.push_back(out[i * out.size() / 80]);
    out = std::move(thin);
  }
  return out;
}

/// A free place for a label of `size` beside shape `index`: the nearest to its outline in gaps of 4, 7, 11 and 16
/// mm in eight directions; none when nothing is free. `lead` is set to the lead line's ends when it is needed.
std::optional<Box> find_label_place(const Placed& shape, int index, Vec2 size, const Occupancy& occ,
                                    std::optional<std::array<Vec2, 2>>* lead) {
  static constexpr double kGaps[] = {kClearMm + kCellReachMm + 0.3, 7.0, 11.0, 16.0};
  static constexpr int kDirs[8][2] = {{1, 0}, {-1, 0}, {0, -1}, {0, 1}, {1, -1}, {-1, -1}, {1, 1}, {-1, 1}};
  const std::vector<Vec2> samples = outline_samples(shape, 3.0);
  for (const double g : kGaps)
    for (const auto& d : kDirs)
      for (const Vec2& p : samples) {
        const double gx = d[0] != 0 && d[1] != 0 ? g / std::sqrt(2.0) : g;
        Box b;
        b.x0 = d[0] > 0 ? p.x + gx : d[0] < 0 ? p.x - gx - size.x : p.x - size.x / 2;
        b.y0 = d[1] > 0 ? p.y + gx : d[1] < 0 ? p.y - gx - size.y : p.y - size.y / 2;
        b.x1 = b.x0 + size.x;
        b.y1 = b.y0 + size.y;
        if (!occ.free(b)) continue;
        lead->reset();
        if (g > kLeadLineFromMm) {
          const Vec2 end{std::clamp(p.x, b.x0, b.x1), std::clamp(p.y, b.y0, b.y1)};
          if (!occ.clear_path(p, end, index)) continue;
          *lead = std::array<Vec2, 2>{p, end};
        }
        return b;
      }
  return std::nullopt;
}

/// Braille lines of `text` no wider than `max_cells`, broken at blank cells where it can.
std::vector<std::string> wrap_cells(const std::string& cells, int max_cells) {
  std::vector<std::string> lines;
  std::vector<std::string> cps;
  for (std::size_t i = 0; i < cells.size();) {
    const std::size_t n = decode_utf8(cells, i).length;
    cps.push_back(cells.substr(i, n));
    i += n;
  }
  std::size_t start = 0;
  while (start < cps.size()) {
    std::size_t end = std::min(cps.size(), start + static_cast<std::size_t>(max_cells));
    if (end < cps.size())
      for (std::size_t k = end; k > start + 1; --k)
        if (cps[k - 1] == "\u2800" || cps[k - 1] == " ") {
          end = k;
          break;
        }
    std::string line;
    for (std::size_t k = start; k < end; ++k) line += cps[k];
    lines.push_back(line);
    start = end;
  }
  return lines;
}

/// The title band: the title in braille (at most kTitleBrailleLines lines), its print under it.
void add_title(TactilePage& page, const TactileInput& in, PaperSize paper) {
  if (in.title.empty()) return;
  const int max_cells = static_cast<int>((paper.width_mm - 2 * kTactileMarginMm) / kBrailleCellPitchMm);
  std::vector<std::string> lines = wrap_cells(to_braille(in.title, in.language, in.grade), max_cells);
  if (lines.size() > kTitleBrailleLines) lines.resize(kTitleBrailleLines);
  double y = kTactileMarginMm;
  for (std::size_t i = 0; i < lines.size(); ++i, y += kBrailleLinePitchMm)
    page.labels.push_back({lines[i], i == 0 ? in.title : std::string(), {kTactileMarginMm, y}, false, -1});
  page.labels.push_back({{}, in.title, {kTactileMarginMm, y}, true, -1});  // the print line under the braille
}

}  // namespace

PaperSize paper_size(Paper paper) {
  switch (paper) {
    case Paper::a4:
      return {210.0, 297.0};
    case Paper::letter:
      return {8.5 * kMmPerInch, 11.0 * kMmPerInch};
    case Paper::tactile_11x11_5:
      return {11.0 * kMmPerInch, 11.5 * kMmPerInch};
  }
  return {210.0, 297.0};
}

std::optional<Paper> parse_paper(std::string_view name) {
  if (name == "a4") return Paper::a4;
  if (name == "letter") return Paper::letter;
  if (name == "11x11.5in") return Paper::tactile_11x11_5;
  return std::nullopt;
}

double polyline_distance(const std::vector<Vec2>& a, bool a_closed, const std::vector<Vec2>& b, bool b_closed) {
  double best = std::numeric_limits<double>::infinity();
  for_segments(a, a_closed, [&](Vec2 p, Vec2 q) {
    for_segments(b, b_closed, [&](Vec2 r, Vec2 s) { best = std::min(best, dist_segment_segment(p, q, r, s)); });
  });
  return best;
}

double tactile_scale_mm_per_m(PaperSize paper, Vec2 lo, Vec2 hi) {
  const Box b = picture_box(paper);
  const double w = std::max(hi.x - lo.x, 1e-9), h = std::max(hi.y - lo.y, 1e-9);
  return std::min((b.x1 - b.x0) / w, (b.y1 - b.y0) / h);
}

namespace {

/// The picture page's shapes: their outlines in their styles, the textured fills, each taken in `occ`.
void draw_shapes(TactilePage& page, const std::vector<Placed>& shapes, const TactileWords& words, Occupancy& occ) {
  const std::vector<LineStyle> styles = choose_styles(shapes);
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const Placed& p = shapes[i];
    page.strokes.push_back({p.points_mm, p.closed, styles[i], static_cast<int>(i)});
    TactileShape ts;
    ts.number = p.number;
    ts.name = p.name.empty() ? with_arg(words.shape, "{number}", std::to_string(p.number)) : p.name;
    ts.style = styles[i];
    page.shapes.push_back(ts);
    for_segments(p.points_mm, p.closed,
                 [&](Vec2 a, Vec2 b) { occ.mark_segment(a, b, kClearMm + kCellReachMm, static_cast<int>(i)); });
    if (styles[i] != LineStyle::textured) continue;
    for (const Vec2& d : fill_dots(p, shapes)) {
      page.fill_dots_mm.push_back(d);
      occ.mark_segment(d, d, kTactileGapMm + kBrailleDotDiameterMm / 2 + kCellReachMm, static_cast<int>(i));
    }
  }
}

/// Labels, most salient shape first: its name where it fits, else the next key letter; each taken in `occ`.
void place_labels(TactilePage& page, const std::vector<Placed>& shapes, const TactileInput& in, Occupancy& occ) {
  int keys = 0;
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    TactileShape& ts = page.shapes[i];
    const std::string name_cells = to_braille(ts.name, in.language, in.grade);
    const std::string key = key_letters(keys);
    const std::string key_cells = to_braille(key, in.language, in.grade);
    struct Try {
      const std::string* cells;
      std::string print;
      bool is_key;
    };
    const Try tries[] = {{&name_cells, ts.name, false}, {&key_cells, key, true}};
    for (const Try& t : tries) {
      std::optional<std::array<Vec2, 2>> lead;
      const Vec2 size = label_size(*t.cells, t.print);
      const std::optional<Box> at = find_label_place(shapes[i], static_cast<int>(i), size, occ, &lead);
      if (!at) continue;
      page.labels.push_back({*t.cells, t.print, {at->x0, at->y0}, true, static_cast<int>(i)});
      occ.mark_box(*at, kTactileGapMm, Occupancy::kLabel);
      if (lead) {
        page.strokes.push_back({{(*lead)[0], (*lead)[1]}, false, LineStyle::solid, static_cast<int>(i)});
        occ.mark_segment((*lead)[0], (*lead)[1], kClearMm + kCellReachMm, Occupancy::kLabel);
      }
      ts.labelled = true;
      if (t.is_key) {
        ts.key = key;
        ++keys;
      }
      break;
    }
  }
}

/// The key's pages after the picture page: key letters, what was left out or not labelled, a sample of each line
/// style with the name it stands for; g.key_lines the same in print. None when nothing needs a key.
void add_key_pages(TactileGraphic& g, const TactileInput& in, const TactileWords& words) {
  std::vector<std::string> lines;
  for (const TactileShape& ts : g.pages[0].shapes)
    if (!ts.key.empty()) lines.push_back(ts.key + " " + ts.name);
  for (const TactileShape& ts : g.pages[0].shapes)
    if (!ts.labelled) lines.push_back(with_arg(words.not_labelled, "{name}", ts.name));
  if (g.left_out > 0) lines.push_back(with_arg(words.left_out, "{count}", std::to_string(g.left_out)));
  std::vector<std::pair<LineStyle, std::string>> legend;
  for (const TactileShape& ts : g.pages[0].shapes)
    if (ts.style != LineStyle::solid &&
        std::none_of(legend.begin(), legend.end(), [&](const auto& l) { return l.first == ts.style; }))
      legend.emplace_back(ts.style, ts.name);
  g.key_lines = lines;
  for (const auto& [style, name] : legend) g.key_lines.push_back(name);
  if (lines.empty() && legend.empty()) return;

  const int max_cells = static_cast<int>((g.paper.width_mm - 2 * kTactileMarginMm) / kBrailleCellPitchMm);
  const double bottom = g.paper.height_mm - kTactileMarginMm;
  TactilePage key_page;
  double y = kTactileMarginMm;
  const auto new_page_unless = [&](double need) {
    if (y + need <= bottom) return;
    g.pages.push_back(std::move(key_page));
    key_page = TactilePage{};
    y = kTactileMarginMm;
  };
  const auto add_line = [&](const std::string& text, double indent_mm) {
    const int cells_here = max_cells - static_cast<int>(indent_mm / kBrailleCellPitchMm);
    const std::vector<std::string> wrapped = wrap_cells(to_braille(text, in.language, in.grade), cells_here);
    new_page_unless(static_cast<double>(wrapped.size()) * kBrailleLinePitchMm + kPrintTextMm + 2.0);
    for (std::size_t k = 0; k < wrapped.size(); ++k, y += kBrailleLinePitchMm)
      key_page.labels.push_back(
          {wrapped[k], k == 0 ? text : std::string(), {kTactileMarginMm + indent_mm, y}, false, -1});
    key_page.labels.push_back({{}, text, {kTactileMarginMm + indent_mm, y}, true, -1});
    y += kPrintTextMm + 2.0;
  };
  add_line(words.key, 0.0);
  for (const std::string& l : lines) add_line(l, 0.0);
  for (const auto& [style, name] : legend) {
    // A sample of the style, 30 mm long, then the name it stands for beside it.
    new_page_unless(kBrailleLinePitchMm / 2 + kBrailleLinePitchMm);
    const double sy = y + kBrailleLinePitchMm / 2 - 1.0;
    key_page.strokes.push_back({{{kTactileMarginMm, sy}, {kTactileMarginMm + 30.0, sy}},
                                false,
                                style == LineStyle::textured ? LineStyle::solid : style,
                                -1});
    add_line(name, 30.0 + kTactileGapMm + 1.0);
  }
  g.pages.push_back(std::move(key_page));
}

}  // namespace

TactileGraphic lay_out_tactile(const TactileInput& in, Paper paper_kind, const TactileWords& words) {
  TactileGraphic g;
  g.paper = paper_size(paper_kind);
  g.title = in.title;
  g.language = in.language;
  const Box frame = frame_box(g.paper), pic = picture_box(g.paper);
  g.mm_per_m = tactile_scale_mm_per_m(g.paper, in.picture_lo_m, in.picture_hi_m);
  // The picture centred in its box.
  const double w = g.mm_per_m * (in.picture_hi_m.x - in.picture_lo_m.x);
  const double h = g.mm_per_m * (in.picture_hi_m.y - in.picture_lo_m.y);
  g.origin_mm = {pic.x0 + (pic.x1 - pic.x0 - w) / 2, pic.y0 + (pic.y1 - pic.y0 - h) / 2};

  std::vector<Placed> shapes = to_page(in, g.mm_per_m, g.origin_mm);
  g.left_out = keep_apart(shapes);
  TactilePage page;
  page.frame_mm = std::array<Vec2, 2>{Vec2{frame.x0, frame.y0}, Vec2{frame.x1, frame.y1}};
  add_title(page, in, g.paper);
  Occupancy occ(g.paper);
  occ.mark_outside({frame.x0 + kClearMm, frame.y0 + kClearMm, frame.x1 - kClearMm, frame.y1 - kClearMm});
  draw_shapes(page, shapes, words, occ);
  place_labels(page, shapes, in, occ);
  g.pages.push_back(std::move(page));
  add_key_pages(g, in, words);
  return g;
}

}  // namespace hk::app
