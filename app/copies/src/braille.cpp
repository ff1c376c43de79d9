// Text to braille and back with liblouis; cells to BRF (braille.hpp).
#include "copies/braille.hpp"

#include <liblouis.h>

#include <mutex>
#include <vector>

#include "hk/language.hpp"
#include "hk/text.hpp"

namespace hk::app {
namespace {

std::mutex& louis_lock() {
  static std::mutex m;
  return m;
}

/// North American Braille ASCII: the character of each of the 64 six-dot cells, by the cell's dot bits.
constexpr std::string_view kBrf = " A1B'K2L@CIF/MSP\"E3H9O6R^DJG>NTQ,*5<-U8V.%[$+X!&;:4\\0Z7(_?W]#Y)=";
static_assert(kBrf.size() == 64);

constexpr char32_t kBrailleBase = 0x2800;

std::vector<widechar> utf32_of(std::string_view text) {
  std::vector<widechar> out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const Utf8Step st = decode_utf8(text, i);
    out.push_back(st.well_formed ? static_cast<widechar>(st.code_point) : static_cast<widechar>(0xFFFD));
    i += st.length;
  }
  return out;
}

void append_utf8(std::string& out, char32_t c) {
  if (c < 0x80) {
    out += static_cast<char>(c);
  } else if (c < 0x800) {
    out += static_cast<char>(0xC0 | (c >> 6));
    out += static_cast<char>(0x80 | (c & 0x3F));
  } else if (c < 0x10000) {
    out += static_cast<char>(0xE0 | (c >> 12));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (c & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (c >> 18));
    out += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (c & 0x3F));
  }
}

/// The table list compiled, or BrailleError naming it.
void check_table(const std::string& table) {
  if (lou_getTable(table.c_str()) == nullptr)
    throw BrailleError("braille table '" + table + "': liblouis cannot compile it (is liblouis-data installed?)");
}

}  // namespace

std::string braille_table(std::string_view language, BrailleGrade grade) {
  const std::string lang(hk::language_subtag(language));
  const bool two = grade == BrailleGrade::two;
  if (lang == "fr") return two ? "fr-bfu-g2.ctb" : "fr-bfu-comp6.utb";
  if (lang == "de") return two ? "de-g2.ctb" : "de-g1.ctb";
  if (lang == "es") return two ? "es-g2.ctb" : "es-g1.ctb";
  return two ? "en-ueb-g2.ctb" : "en-ueb-g1.ctb";
}

std::string to_braille(std::string_view text, std::string_view language, BrailleGrade grade) {
  const std::string table = braille_table(language, grade);
  std::vector<widechar> in = utf32_of(text);
  if (in.empty()) return {};
  std::lock_guard<std::mutex> lock(louis_lock());
  check_table(table);
  // Contractions can only shorten a text, but indicators (capitals, numbers) lengthen it: room for 4 cells a letter.
  std::vector<widechar> out(in.size() * 4 + 16);
  int in_len = static_cast<int>(in.size()), out_len = static_cast<int>(out.size());
  if (lou_translateString(table.c_str(), in.data(), &in_len, out.data(), &out_len, nullptr, nullptr, dotsIO | ucBrl) ==
      0)
    throw BrailleError("braille table '" + table + "': liblouis could not translate '" +
                       one_line(std::string(text), 80) + "'");
  std::string cells;
  for (int i = 0; i < out_len; ++i) {
    // dotsIO | ucBrl gives Unicode braille; a blank comes as U+2800 or, from some tables, as 0x8000 (no dots).
    const widechar c = out[static_cast<std::size_t>(i)];
    const char32_t cell = (c & 0xFF00) == 0x2800 ? c : (c & 0x8000) ? kBrailleBase + (c & 0xFF) : kBrailleBase;
    append_utf8(cells, cell);
  }
  return cells;
}

std::string from_braille(std::string_view cells, std::string_view language, BrailleGrade grade) {
  const std::string table = braille_table(language, grade);
  std::vector<widechar> in;
  for (const widechar c : utf32_of(cells)) {
    const unsigned dots = c == ' ' ? 0u : (c >= 0x2800 && c <= 0x28FF) ? c - 0x2800 : 0u;
    in.push_back(static_cast<widechar>(0x8000 | dots));  // dotsIO: a cell is 0x8000 + its dots' bits
  }
  if (in.empty()) return {};
  std::lock_guard<std::mutex> lock(louis_lock());
  check_table(table);
  std::vector<widechar> out(in.size() * 8 + 16);
  int in_len = static_cast<int>(in.size()), out_len = static_cast<int>(out.size());
  if (lou_backTranslateString(table.c_str(), in.data(), &in_len, out.data(), &out_len, nullptr, nullptr, dotsIO) == 0)
    throw BrailleError("braille table '" + table + "': liblouis could not read the cells back");
  std::string text;
  for (int i = 0; i < out_len; ++i) append_utf8(text, static_cast<char32_t>(out[static_cast<std::size_t>(i)]));
  return text;
}

std::string brf_of(std::string_view cells) {
  std::string out;
  for (std::size_t i = 0; i < cells.size();) {
    const Utf8Step st = decode_utf8(cells, i);
    i += st.length;
    const char32_t c = st.code_point;
    out += st.well_formed && c >= kBrailleBase && c < kBrailleBase + 64 ? kBrf[c - kBrailleBase] : ' ';
  }
  return out;
}

int braille_cell_count(std::string_view cells) {
  int n = 0;
  for (std::size_t i = 0; i < cells.size(); ++n) i += decode_utf8(cells, i).length;
  return n;
}

}  // namespace hk::app
