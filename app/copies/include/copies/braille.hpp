#pragma once
/// @file braille.hpp
/// Text to braille cells and back with liblouis, the table chosen by language and grade, and braille cells to
/// BRF (the North American Braille ASCII that text embossers read). Cells are Unicode braille patterns
/// (U+2800 + the dots' bits: dot 1 = bit 0 … dot 6 = bit 5), UTF-8 encoded.
///
/// liblouis compiles a table on first use and keeps it; its translation is not thread-safe, so every call here
/// holds one process-wide lock (setup and copies, never the servo path).

#include <stdexcept>
#include <string>
#include <string_view>

#include "formats/app_error.hpp"

namespace hk::app {

/// Contracted (grade 2) or uncontracted (grade 1) braille.
enum class BrailleGrade { one = 1, two = 2 };

/// A table that is missing or a text liblouis cannot translate. what() is one line naming the table.
class BrailleError : public AppError {
 public:
  using AppError::AppError;
};

/// The liblouis table list for `language` (a BCP 47 tag; its language subtag decides) at `grade`: English UEB
/// (en-ueb-g1.ctb / en-ueb-g2.ctb), French (fr-bfu-comp6.utb, the uncontracted "intégral" / fr-bfu-g2.ctb),
/// German (de-g1.ctb / de-g2.ctb), Spanish (es-g1.ctb / es-g2.ctb); English UEB for any other language.
std::string braille_table(std::string_view language, BrailleGrade grade);

/// `text` (UTF-8) as braille cells (UTF-8 Unicode braille) with the table of `language` and `grade`.
/// @throws BrailleError when the table cannot be compiled or the translation fails.
std::string to_braille(std::string_view text, std::string_view language, BrailleGrade grade);

/// Braille cells (UTF-8 Unicode braille; a space is U+2800 or ' ') back to text with the table of `language` and
/// `grade`: how a reader of that code reads them. @throws BrailleError as to_braille.
std::string from_braille(std::string_view cells, std::string_view language, BrailleGrade grade);

/// The cells (UTF-8 Unicode braille, ' ' read as the blank cell) as BRF characters, one a cell (North American
/// Braille ASCII: ⠁ → 'A', ⠂ → '1', ⠿ → '='); anything else in `cells` becomes a blank.
std::string brf_of(std::string_view cells);

/// The number of cells in `cells` (code points; UTF-8 Unicode braille).
int braille_cell_count(std::string_view cells);

}  // namespace hk::app
