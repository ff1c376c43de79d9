#pragma once
/// @file tactile_output.hpp
/// A laid-out tactile graphic (tactile_graphic.hpp) written as the files a museum hands over:
///   PDF  for swell paper and graphics embossers, drawn with cairo: lines 1 mm wide in their styles, braille as
///        dots of 1.5 mm at the standard cell, large print under it; one PDF page a TactilePage.
///   SVG  for pin displays and screens, written directly (cairo cannot give an element per shape or text as text):
///        each shape a `<g>` with its name as `aria-label`, braille as Unicode braille text, pages one under the
///        other.
///   BRF  braille-ready text for text embossers: the title, the key and each label, 40 cells a line, 25 lines a
///        page (CR LF line ends, a form feed between pages).

#include <string>

#include "copies/tactile_graphic.hpp"

namespace hk::app {

/// A copy that could not be written. what() is one line naming the file.
class CopyError : public AppError {
 public:
  using AppError::AppError;
};

/// Cells a BRF line holds and lines a BRF page holds (the common 11 × 11.5 in embosser page).
inline constexpr int kBrfCellsPerLine = 40;
inline constexpr int kBrfLinesPerPage = 25;

/// Writes `g` as a PDF file at `path`. @throws CopyError (one line naming the file) when cairo cannot write it.
void write_tactile_pdf(const TactileGraphic& g, const std::string& path);
/// `g` as a PDF file's bytes (as write_tactile_pdf writes them). @throws CopyError when cairo cannot draw it.
std::string tactile_pdf(const TactileGraphic& g);

/// `g` as an SVG document (UTF-8).
std::string tactile_svg(const TactileGraphic& g);
/// `g` as BRF text (North American Braille ASCII), in `language`'s braille at `grade`.
/// @throws BrailleError as to_braille.
std::string tactile_brf(const TactileGraphic& g, BrailleGrade grade);

/// The format a file name asks for: "pdf", "svg" or "brf" (its extension, any case); "" for any other.
std::string tactile_format_of(const std::string& path);
/// Writes `g` to `path` in the format its extension names (tactile_format_of), through a temporary file renamed
/// into place so that a file already there is never left half-written.
/// @throws CopyError (one line naming the file and why: an unknown extension, a folder that cannot be written).
void write_tactile(const TactileGraphic& g, const std::string& path, BrailleGrade grade);

}  // namespace hk::app
