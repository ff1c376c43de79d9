// Take-home copies (copies/): braille with liblouis each way and as BRF; a scene laid out as a tactile graphic
// keeps the guidelines' distances (shapes 3 mm apart, nothing under 6 mm, labels 3 mm clear of every line); the
// PDF, rasterised by poppler, has ink on every outline kept and nowhere far from what was laid out; the SVG parses
// (librsvg) with one element per shape named by aria-label; the BRF holds the title and every label; the command
// refuses bad options and files in one line and leaves an existing copy whole.
#include <gtest/gtest.h>
#include <liblouis.h>
#include <librsvg/rsvg.h>
#include <unistd.h>

#include <poppler-document.h>
#include <poppler-image.h>
#include <poppler-page-renderer.h>
#include <poppler-page.h>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli/explore.hpp"
#include "cli/tactile_command.hpp"
#include "copies/braille.hpp"
#include "copies/tactile_graphic.hpp"
#include "copies/tactile_output.hpp"
#include "copies/tactile_scene.hpp"
#include "curves.hpp"
#include "pictures/picture_names.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

namespace hk::app {
namespace {

const std::string kButterfly = std::string(HK_SHIPPED_PICTURES_DIR) + "/butterfly.jpg";

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hk_tactile_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// The butterfly as the library names it, laid out on A4 in uncontracted English braille.
TactileGraphic butterfly_copy(BrailleGrade grade = BrailleGrade::one) {
  const config::Settings s;
  ImageScene is = build_input_scene(kButterfly, 0, s);
  apply_names(is, names_file_for(kButterfly, ""), "butterfly.jpg");
  return lay_out_tactile(tactile_input_of(is, s.haptics.level, Paper::a4, "en", "a butterfly on a leaf", grade),
                         Paper::a4);
}

double dist_point_segment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a, ap = p - a;
  const double len2 = ab.x * ab.x + ab.y * ab.y;
  const double t = len2 > 0 ? std::clamp((ap.x * ab.x + ap.y * ab.y) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(p.x - (a.x + t * ab.x), p.y - (a.y + t * ab.y));
}

/// Distance from `p` to the stroke's centre line [mm].
double dist_to_stroke(Vec2 p, const TactileStroke& s) {
  double best = 1e9;
  const auto& q = s.points_mm;
  for (std::size_t i = 0; i + 1 < q.size(); ++i) best = std::min(best, dist_point_segment(p, q[i], q[i + 1]));
  if (s.closed && q.size() > 2) best = std::min(best, dist_point_segment(p, q.back(), q.front()));
  return best;
}

/// A label's box on the page: its braille line, and its print line under it.
std::array<Vec2, 2> label_box(const TactileLabel& l) {
  const double w =
      std::max(braille_cell_count(l.cells) * kBrailleCellPitchMm, l.print.empty() ? 0.0 : print_width_mm(l.print));
  const double h = kBrailleLinePitchMm + (l.print_below && !l.print.empty() ? kPrintTextMm + 1.0 : 0.0);
  return {l.at_mm, l.at_mm + Vec2{w, h}};
}

TEST(Braille, EachLanguagesNamesComeBackFromTheirUncontractedBraille) {
  const std::pair<const char*, const char*> names[] = {
      {"en", "right wing"}, {"fr", "l'aile droite"}, {"de", "rechter Flügel"}, {"es", "el ala derecha"}};
  for (const auto& [lang, name] : names) {
    const std::string cells = to_braille(name, lang, BrailleGrade::one);
    ASSERT_FALSE(cells.empty()) << lang;
    for (std::size_t i = 0; i < cells.size(); i += 3)  // every cell a Unicode braille pattern (3 bytes of UTF-8)
      EXPECT_EQ(static_cast<unsigned char>(cells[i]), 0xE2u) << lang;
    // German braille marks no capitals (the Brailleschriftkomitee's rules): a German name comes back lower case.
    std::string expected = name;
    if (std::string(lang) == "de") expected[std::string(name).find('F')] = 'f';
    EXPECT_EQ(from_braille(cells, lang, BrailleGrade::one), expected) << lang << ": " << cells;
  }
  // Contracted English is shorter than uncontracted, and reads back the same.
  const std::string g2 = to_braille("the right wing of the butterfly", "en", BrailleGrade::two);
  EXPECT_LT(braille_cell_count(g2),
            braille_cell_count(to_braille("the right wing of the butterfly", "en", BrailleGrade::one)));
  EXPECT_EQ(from_braille(g2, "en", BrailleGrade::two), "the right wing of the butterfly");
}

TEST(Braille, BrfIsTheNorthAmericanBrailleAsciiLiblouisWritesItself) {
  // liblouis's own BRF display table (en-us-brf.dis) against our mapping of the same cells.
  const std::string text = "Hello, world 42: (a-b) \"quoted\" & more!";
  std::vector<widechar> in;
  for (const char c : text) in.push_back(static_cast<unsigned char>(c));
  std::vector<widechar> out(512);
  int in_len = static_cast<int>(in.size()), out_len = static_cast<int>(out.size());
  ASSERT_NE(
      lou_translateString("en-us-brf.dis,en-ueb-g1.ctb", in.data(), &in_len, out.data(), &out_len, nullptr, nullptr, 0),
      0);
  std::string louis_brf;
  for (int i = 0; i < out_len; ++i) louis_brf += static_cast<char>(std::toupper(static_cast<int>(out[i])));
  EXPECT_EQ(brf_of(to_braille(text, "en", BrailleGrade::one)), louis_brf);
  EXPECT_EQ(brf_of("\u2801\u2802\u283f\u2800"), "A1= ");
}

TEST(TactileLayout, ShapesTooSmallOrTooCloseAreLeftOutAndTheRestStayApart) {
  // A workspace of 0.14 m x 0.09 m on A4: about 1.3 mm a millimetre of workspace.
  const auto circle = [](Vec2 c, double r_m) { return hk::test::circle_points(c, r_m); };
  TactileInput in;
  in.title = "circles";
  in.grade = BrailleGrade::one;
  in.picture_lo_m = {-0.07, -0.045};
  in.picture_hi_m = {0.07, 0.045};
  in.curves = {{circle({-0.03, 0.0}, 0.02), true, "sun", 1, 0.126},
               {circle({0.0, 0.0}, 0.0095), true, "moon", 2, 0.06},  // 0.5 mm of workspace from the sun
               {circle({0.045, 0.0}, 0.012), true, "star", 3, 0.075},
               {circle({0.05, 0.035}, 0.0015), true, "speck", 4, 0.009}};  // 4 mm across on the page
  const TactileGraphic g = lay_out_tactile(in, Paper::a4);
  ASSERT_FALSE(g.pages.empty());
  const TactilePage& p = g.pages[0];
  ASSERT_EQ(p.shapes.size(), 2u);
  EXPECT_EQ(p.shapes[0].name, "sun");
  EXPECT_EQ(p.shapes[1].name, "star");
  EXPECT_EQ(g.left_out, 2);
  // Distinct shapes' outlines at least a line's width plus the gap apart, centre to centre.
  std::vector<const TactileStroke*> outlines;
  for (const TactileStroke& s : p.strokes)
    if (s.shape >= 0 && s.closed) outlines.push_back(&s);
  ASSERT_EQ(outlines.size(), 2u);
  EXPECT_GE(polyline_distance(outlines[0]->points_mm, true, outlines[1]->points_mm, true),
            kTactileGapMm + kTactileLineWidthMm);
  // Different names, different line styles; the key page names them.
  EXPECT_NE(p.shapes[0].style, p.shapes[1].style);
  ASSERT_EQ(g.pages.size(), 2u);
}

TEST(TactileLayout, ARealPictureKeepsTheGuidelinesDistancesEverywhere) {
  const TactileGraphic g = butterfly_copy();
  ASSERT_FALSE(g.pages.empty());
  const TactilePage& p = g.pages[0];
  ASSERT_GE(p.shapes.size(), 5u);
  const auto& frame = *p.frame_mm;
  for (std::size_t i = 0; i < p.strokes.size(); ++i) {
    const TactileStroke& s = p.strokes[i];
    for (const Vec2& q : s.points_mm) {  // inside the frame, clear of it
      EXPECT_GE(q.x, frame[0].x + kTactileGapMm);
      EXPECT_LE(q.x, frame[1].x - kTactileGapMm);
      EXPECT_GE(q.y, frame[0].y + kTactileGapMm);
      EXPECT_LE(q.y, frame[1].y - kTactileGapMm);
    }
    const double w = [&] {
      double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
      for (const Vec2& q : s.points_mm)
        x0 = std::min(x0, q.x), x1 = std::max(x1, q.x), y0 = std::min(y0, q.y), y1 = std::max(y1, q.y);
      return std::max(x1 - x0, y1 - y0);
    }();
    if (s.points_mm.size() > 2) {
      EXPECT_GE(w, kTactileSmallestMm) << "shape " << s.shape;
    }
    for (std::size_t j = i + 1; j < p.strokes.size(); ++j) {
      if (s.shape == p.strokes[j].shape || s.points_mm.size() <= 2 || p.strokes[j].points_mm.size() <= 2) continue;
      EXPECT_GE(polyline_distance(s.points_mm, s.closed, p.strokes[j].points_mm, p.strokes[j].closed),
                kTactileGapMm + kTactileLineWidthMm)
          << "shapes " << s.shape << " and " << p.strokes[j].shape;
    }
  }
  // Every label 3 mm clear of every line (its edge from a line's edge), and labels clear of each other.
  int labels = 0;
  for (const TactileLabel& l : p.labels) {
    if (l.shape < 0) continue;
    ++labels;
    const auto box = label_box(l);
    for (const TactileStroke& s : p.strokes) {
      const bool lead = s.shape == l.shape && s.points_mm.size() == 2;
      if (lead) continue;  // its own lead line starts at its shape and ends at it
      for (double y = box[0].y; y <= box[1].y + 1e-9; y += 0.5)
        for (double x = box[0].x; x <= box[1].x + 1e-9; x += 0.5)
          ASSERT_GE(dist_to_stroke({x, y}, s), kTactileGapMm + kTactileLineWidthMm / 2)
              << "label '" << l.print << "' at (" << x << ", " << y << ") near shape " << s.shape;
    }
  }
  EXPECT_GE(labels, 5);
  // Braille labels read back as the shapes' names or key letters.
  for (const TactileLabel& l : p.labels)
    if (l.shape >= 0) {
      EXPECT_EQ(from_braille(l.cells, "en", BrailleGrade::one), l.print);
    }
}

TEST(TactilePdf, EveryOutlineKeptIsInkAndNothingIsDrawnFarFromWhatWasLaidOut) {
  const fs::path dir = temp_dir("pdf");
  const TactileGraphic g = butterfly_copy();
  const fs::path pdf = dir / "copy.pdf";
  write_tactile(g, pdf.string(), BrailleGrade::one);
  std::unique_ptr<poppler::document> doc(poppler::document::load_from_file(pdf.string()));
  ASSERT_TRUE(doc);
  ASSERT_EQ(doc->pages(), static_cast<int>(g.pages.size()));
  EXPECT_EQ(doc->get_title().to_latin1(), "a butterfly on a leaf");
  constexpr double kPxPerMm = 10.0;
  poppler::page_renderer r;
  std::unique_ptr<poppler::page> page(doc->create_page(0));
  const poppler::image img = r.render_page(page.get(), 25.4 * kPxPerMm, 25.4 * kPxPerMm);
  ASSERT_TRUE(img.is_valid());
  const auto dark = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= img.width() || y >= img.height()) return false;
    const auto* row =
        reinterpret_cast<const unsigned char*>(img.const_data()) + static_cast<std::ptrdiff_t>(y) * img.bytes_per_row();
    const unsigned char* px = row + 4 * x;  // ARGB32: B, G, R, A
    return px[0] < 128 && px[1] < 128 && px[2] < 128;
  };
  const auto ink_near = [&](Vec2 mm, double r_mm) {
    const int cx = static_cast<int>(mm.x * kPxPerMm), cy = static_cast<int>(mm.y * kPxPerMm),
              r = static_cast<int>(r_mm * kPxPerMm);
    for (int y = cy - r; y <= cy + r; ++y)
      for (int x = cx - r; x <= cx + r; ++x)
        if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r && dark(x, y)) return true;
    return false;
  };
  // Ink within 1 mm of every point of every outline (dashes aside: their gaps are 3 mm at most).
  const TactilePage& p = g.pages[0];
  for (const TactileStroke& s : p.strokes) {
    const double reach = s.style == LineStyle::solid || s.style == LineStyle::textured ? 1.0 : 2.5;
    for (std::size_t i = 0; i + 1 < s.points_mm.size(); ++i)
      for (double t = 0; t < 1.0; t += 0.25) {
        const Vec2 q = s.points_mm[i] + t * (s.points_mm[i + 1] - s.points_mm[i]);
        ASSERT_TRUE(ink_near(q, reach)) << "no ink near (" << q.x << ", " << q.y << ") of shape " << s.shape;
      }
  }
  // No ink more than 2 mm from every stroke, label, fill dot and the frame (sampled every 2 mm).
  int checked = 0;
  for (double y = 1.0; y < g.paper.height_mm - 1.0; y += 2.0)
    for (double x = 1.0; x < g.paper.width_mm - 1.0; x += 2.0) {
      const Vec2 q{x, y};
      bool near = false;
      for (const TactileStroke& s : p.strokes) near = near || dist_to_stroke(q, s) < 2.5;
      for (const TactileLabel& l : p.labels) {
        const auto b = label_box(l);
        near = near || (q.x > b[0].x - 2.5 && q.x < b[1].x + 2.5 && q.y > b[0].y - 2.5 && q.y < b[1].y + 2.5);
      }
      for (const Vec2& d : p.fill_dots_mm) near = near || std::hypot(q.x - d.x, q.y - d.y) < 2.5;
      const auto& f = *p.frame_mm;
      const TactileStroke frame{{f[0], {f[1].x, f[0].y}, f[1], {f[0].x, f[1].y}}, true};
      near = near || dist_to_stroke(q, frame) < 2.5;
      if (near) continue;
      ++checked;
      EXPECT_FALSE(dark(static_cast<int>(x * kPxPerMm), static_cast<int>(y * kPxPerMm)))
          << "ink at (" << x << ", " << y << ")";
    }
  EXPECT_GT(checked, 1000);
  fs::remove_all(dir);
}

TEST(TactileSvg, ParsesWithOneElementPerShapeNamedByItsAriaLabel) {
  const TactileGraphic g = butterfly_copy();
  const std::string svg = tactile_svg(g);
  GError* err = nullptr;
  RsvgHandle* h = rsvg_handle_new_from_data(reinterpret_cast<const guint8*>(svg.data()), svg.size(), &err);
  ASSERT_NE(h, nullptr) << (err ? err->message : "");
  for (const TactileShape& s : g.pages[0].shapes) {
    const std::string id = "#shape-" + std::to_string(s.number);
    EXPECT_TRUE(rsvg_handle_has_sub(h, id.c_str())) << id;
    const std::string element =
        "<g id=\"shape-" + std::to_string(s.number) + "\" role=\"img\" aria-label=\"" + s.name + "\">";
    EXPECT_NE(svg.find(element), std::string::npos) << element;
  }
  g_object_unref(h);
  // Braille as Unicode braille text.
  EXPECT_NE(svg.find("<text class=\"braille\""), std::string::npos);
  EXPECT_NE(svg.find(to_braille("left wing", "en", BrailleGrade::one)), std::string::npos);
}

TEST(TactileBrf, HoldsTheTitleAndEveryLabelInBraille) {
  const TactileGraphic g = butterfly_copy();
  const std::string brf = tactile_brf(g, BrailleGrade::one);
  // Back to cells (the inverse of North American Braille ASCII), then to text with liblouis.
  const std::string ascii = " A1B'K2L@CIF/MSP\"E3H9O6R^DJG>NTQ,*5<-U8V.%[$+X!&;:4\\0Z7(_?W]#Y)=";
  std::string text;
  std::istringstream lines(brf);
  for (std::string line; std::getline(lines, line);) {
    ASSERT_LE(line.size(), static_cast<std::size_t>(kBrfCellsPerLine) + 2);  // with its CR (and a form feed)
    std::string cells;
    for (const char c : line) {
      const std::size_t k = ascii.find(c);
      if (k == std::string::npos) continue;  // CR, form feed
      cells += "\xE2";
      cells += static_cast<char>(0xA0 + (k >> 6));
      cells += static_cast<char>(0x80 + (k & 0x3F));
    }
    text += from_braille(cells, "en", BrailleGrade::one) + "\n";
  }
  EXPECT_NE(text.find("a butterfly on a leaf"), std::string::npos) << text;
  for (const TactileShape& s : g.pages[0].shapes)
    EXPECT_NE(text.find(s.name), std::string::npos) << s.name << "\n" << text;
}

TEST(TactileCommand, BadOptionsAndFilesAreRefusedAndLeaveACopyAlreadyThereWhole) {
  const fs::path dir = temp_dir("command");
  const fs::path kept = dir / "kept.pdf";
  std::ofstream(kept) << "an earlier copy";
  const auto run = [&](TactileOptions o) { return run_tactile(o); };
  TactileOptions o;
  o.picture = kButterfly;
  o.out = {kept.string()};
  o.paper = "a3";
  EXPECT_EQ(run(o), 1);
  o.paper = "a4";
  o.grade = 3;
  EXPECT_EQ(run(o), 1);
  o.grade = 2;
  o.out = {(dir / "copy.png").string()};
  EXPECT_EQ(run(o), 1);
  o.out = {kept.string()};
  o.picture = (dir / "no such picture.png").string();
  EXPECT_EQ(run(o), 1);
  // A picture that is not one: a text file named .png.
  std::ofstream(dir / "not.png") << "not a picture";
  o.picture = (dir / "not.png").string();
  EXPECT_EQ(run(o), 1);
  EXPECT_EQ(read_file(kept), "an earlier copy");
  // A folder that does not exist: refused, nothing half-written.
  o.picture = kButterfly;
  o.out = {(dir / "no" / "copy.svg").string()};
  EXPECT_EQ(run(o), 1);
  // And a good run writes all three.
  o.out = {(dir / "c.pdf").string(), (dir / "c.svg").string(), (dir / "c.brf").string()};
  EXPECT_EQ(run(o), 0);
  for (const auto& f : o.out) EXPECT_GT(fs::file_size(f), 100u) << f;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace hk::app
