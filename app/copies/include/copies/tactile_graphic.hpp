#pragma once
/// @file tactile_graphic.hpp
/// A take-home copy of the scene a visitor felt, laid out as a tactile graphic: the curves scaled to a page,
/// simplified to what a fingertip tells apart, shapes kept 3 mm apart, closed shapes of different names told
/// apart by line style, a frame, braille labels beside the shapes (a key letter when the name does not fit) and
/// a key page. The layout follows the BANA / CAST "Guidelines and Standards for Tactile Graphics" (2010):
/// lines at least 1 mm wide, 3 mm between distinct lines, nothing smaller than 6 mm, at most five line styles or
/// area fills, braille at the standard cell (6.2 mm from cell to cell, 10 mm from line to line, dots 2.5 mm
/// apart). The renderers (tactile_output.hpp) draw a TactileGraphic as PDF, SVG or BRF.
///
/// Page coordinates: millimetres from the page's top-left corner, x right, y down.

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "copies/braille.hpp"
#include "hk/vec2.hpp"

namespace hk::app {

// ---- the guidelines' numbers [mm] ----
inline constexpr double kTactileLineWidthMm = 1.0;    ///< every line's width
inline constexpr double kTactileGapMm = 3.0;          ///< least gap between distinct lines, labels and the frame
inline constexpr double kTactileSmallestMm = 6.0;     ///< a shape whose box's longer side is shorter is left out
inline constexpr double kTactileToleranceMm = 1.0;    ///< detail finer than this on the page is smoothed away
inline constexpr double kBrailleCellPitchMm = 6.2;    ///< cell to cell along a line
inline constexpr double kBrailleLinePitchMm = 10.0;   ///< line to line
inline constexpr double kBrailleDotPitchMm = 2.5;     ///< dot to dot within a cell
inline constexpr double kBrailleDotDiameterMm = 1.5;  ///< a dot's base
inline constexpr double kPrintTextMm = 6.35;          ///< large print's font size (18 pt, large print's least)
inline constexpr double kTactileMarginMm = 12.7;      ///< the page's margin (half an inch)
inline constexpr int kTactileStyles = 5;              ///< line styles and fills told apart

/// Paper the copy is laid out for.
enum class Paper {
  a4,              ///< 210 × 297 mm
  letter,          ///< 8.5 × 11 in
  tactile_11x11_5  ///< 11 × 11.5 in, the common swell-paper and embosser size
};

/// Width and height of `paper` [mm].
struct PaperSize {
  double width_mm = 0, height_mm = 0;
};
PaperSize paper_size(Paper paper);
/// "a4", "letter" or "11x11.5in"; none for anything else.
std::optional<Paper> parse_paper(std::string_view name);

/// How a closed shape's outline is drawn, so that shapes of different names feel different; open curves and
/// unnamed shapes are solid.
enum class LineStyle {
  solid,
  dashed,    ///< 6 mm dashes, 3 mm gaps
  dotted,    ///< dots 1.5 mm long every 3.5 mm
  dash_dot,  ///< a 6 mm dash, a dot, gaps of 3 mm
  textured,  ///< solid outline, its inside filled with dots 5 mm apart, 3 mm clear of the outline
};

/// One curve of the scene the visitor felt, ready to lay out.
struct TactileCurve {
  std::vector<Vec2> points_m;  ///< the curve at the level chosen, workspace [m] (x right, y up)
  bool closed = false;         ///< the last point joins the first
  std::string name;            ///< the shape's name in the copy's language; "" when it has none
  int number = 0;              ///< the number the visitor hears for it ("shape 3"), from 1
  double salience = 0;         ///< kept first when shapes crowd: its length [m]
};

/// What a copy shows, in the copy's language.
struct TactileInput {
  std::string title;            ///< the picture's title
  std::string language = "en";  ///< BCP 47: the braille table's and the words' language
  BrailleGrade grade = BrailleGrade::two;
  Vec2 picture_lo_m, picture_hi_m;  ///< the picture's rectangle in the workspace [m]
  std::vector<TactileCurve> curves;
};

/// The words of a copy's key in its language: the catalogue's copy_key_title, copy_shape ({number}: the shape's
/// number), copy_left_out ({count}) and copy_not_labelled ({name}) templates.
struct TactileWords {
  std::string key = "Key";
  std::string shape = "shape {number}";
  std::string left_out = "Shapes left out, too small or too close to another: {count}";
  std::string not_labelled = "Not labelled on the picture: {name}";
};

/// A line on the page: an outline, a lead line or the frame.
struct TactileStroke {
  std::vector<Vec2> points_mm;
  bool closed = false;
  LineStyle style = LineStyle::solid;
  int shape = -1;  ///< index in TactilePage::shapes, −1 for the frame and key samples
};

/// A braille text: its cells and the same words in print.
struct TactileLabel {
  std::string cells;        ///< UTF-8 Unicode braille
  std::string print;        ///< the text in print
  Vec2 at_mm;               ///< top-left corner of the first cell
  bool print_below = true;  ///< the print line under the braille (false: print only in the key)
  int shape = -1;           ///< index in TactilePage::shapes, −1 for titles and key lines
};

/// A shape on the page: what its stroke and label stand for.
struct TactileShape {
  int number = 0;    ///< TactileCurve::number
  std::string name;  ///< its name, or the key's "shape {n}" when it has none
  std::string key;   ///< the key letters its label shows ("" when the label is the name itself)
  bool labelled = false;
  LineStyle style = LineStyle::solid;
};

/// One page of the copy.
struct TactilePage {
  std::vector<TactileStroke> strokes;
  std::vector<TactileLabel> labels;
  std::vector<TactileShape> shapes;             ///< the picture page's shapes; empty on a key page
  std::optional<std::array<Vec2, 2>> frame_mm;  ///< the graphic's frame (top-left, bottom-right), picture page only
  std::vector<Vec2> fill_dots_mm;               ///< the centres of the textured fills' dots
};

/// A laid-out copy: the picture page, then the key page when one is needed.
struct TactileGraphic {
  PaperSize paper;
  std::string title;
  std::string language;
  std::vector<TactilePage> pages;
  double mm_per_m = 0;                 ///< the picture's scale on the page
  Vec2 origin_mm;                      ///< where the workspace point (picture_lo.x, picture_hi.y) lands
  int left_out = 0;                    ///< shapes left out, too small or too close to one kept
  std::vector<std::string> key_lines;  ///< the key in print, one line an entry (the BRF's key)
};

/// The scale [mm per m] at which the picture rectangle fits `paper`'s graphic area (the page less margins, the
/// title band and the frame's clearance).
double tactile_scale_mm_per_m(PaperSize paper, Vec2 picture_lo_m, Vec2 picture_hi_m);

/// Lays out `in` on `paper`: the title in braille and print, the frame, the curves scaled, the shapes smaller than
/// kTactileSmallestMm left out, then, most salient first, each shape kept only when its outline is at least
/// kTactileGapMm + kTactileLineWidthMm (centre to centre) from every shape kept before; line styles by name; each
/// kept shape labelled with its name in braille (else a key letter) where it fits 3 mm clear of every line, with a
/// lead line when it stands more than 6 mm off; a key page when a key letter, a style or a left-out shape needs
/// one. Never throws but std::bad_alloc and BrailleError (a table liblouis cannot compile).
TactileGraphic lay_out_tactile(const TactileInput& in, Paper paper, const TactileWords& words = {});

/// The width of `text` in large print as the PDF draws it (DejaVu Sans at kPrintTextMm, measured with cairo) [mm].
double print_width_mm(const std::string& text);

/// Least distance between two polylines [same unit as their points] (a closed one with its closing segment).
double polyline_distance(const std::vector<Vec2>& a, bool a_closed, const std::vector<Vec2>& b, bool b_closed);

}  // namespace hk::app
