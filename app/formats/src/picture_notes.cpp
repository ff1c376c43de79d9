// A picture's title and description from its sidecar file: read_picture_notes.
#include "formats/picture_notes.hpp"

#include "hk/language.hpp"
#include "hk/text.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <string_view>

#include <exiv2/exiv2.hpp>

#include <toml++/toml.h>
#include "formats/png_text.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& file, const std::string& what) {
  throw PictureNotesError("picture notes '" + fs::path(file).filename().string() + "': " + what);
}

/// Whether `s` is valid UTF-8 (no overlong forms, no surrogates, at most U+10FFFF).
bool valid_utf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    int extra = c < 0x80 ? 0 : (c >> 5) == 0x6 ? 1 : (c >> 4) == 0xE ? 2 : (c >> 3) == 0x1E ? 3 : -1;
    if (extra < 0 || i + static_cast<std::size_t>(extra) >= s.size())
      return false;  // a lead byte, and all its bytes there
    unsigned cp = extra == 0 ? c : extra == 1 ? (c & 0x1Fu) : extra == 2 ? (c & 0x0Fu) : (c & 0x07u);
    for (int k = 1; k <= extra; ++k) {
      const auto d = static_cast<unsigned char>(s[i + static_cast<std::size_t>(k)]);
      if ((d >> 6) != 0x2) return false;
      cp = (cp << 6) | (d & 0x3Fu);
    }
    if ((extra == 1 && cp < 0x80) || (extra == 2 && cp < 0x800) || (extra == 3 && cp < 0x10000) || cp > 0x10FFFF ||
        (cp >= 0xD800 && cp <= 0xDFFF))
      return false;
    i += 1 + static_cast<std::size_t>(extra);
  }
  return true;
}

std::string trimmed(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return std::string(s.substr(b, e - b + 1));
}

/// What is wrong with `raw` as a title (lines = false) or description (true), or "" when nothing is: valid
/// UTF-8, not blank, at most `max_bytes` once trimmed, no control characters (but line breaks where `lines`).
std::string text_problem(const std::string& key, const std::string& raw, std::size_t max_bytes, bool lines) {
  if (!valid_utf8(raw)) return key + " is not valid UTF-8";
  const std::string text = trimmed(raw);
  if (text.empty()) return key + " is blank";
  if (text.size() > max_bytes)
    return key + " is " + std::to_string(text.size()) + " bytes, at most " + std::to_string(max_bytes);
  for (const char ch : text) {
    const auto u = static_cast<unsigned char>(ch);
    if ((u < 0x20 && !(lines && (ch == '\n' || ch == '\r'))) || u == 0x7F)
      return key + " holds a control character" + (lines ? "" : " (one line, please)");
  }
  return "";
}

/// The text of a sidecar's key `key`, checked (text_problem); refused with fail().
std::string checked_text(const std::string& file, const std::string& key, const toml::node& node, std::size_t max_bytes,
                         bool lines) {
  const auto* str = node.as_string();
  if (!str) fail(file, key + " must be a string");
  if (const std::string why = text_problem(key, str->get(), max_bytes, lines); !why.empty()) fail(file, why);
  return trimmed(str->get());
}

}  // namespace

std::string usable_note(const std::string& raw, std::size_t max_bytes, bool lines) {
  static const char* const kPlaceholders[] = {
      "OLYMPUS DIGITAL CAMERA",     "SONY DSC", "DCIM",     "Digital Camera", "DIGITAL CAMERA",
      "KODAK Digital Still Camera", "Default",  "Untitled", "default"};
  if (!text_problem("", raw, max_bytes, lines).empty()) return "";
  std::string text = trimmed(raw);
  for (const char* p : kPlaceholders)
    if (text == p) return "";
  return text;
}

namespace {

/// An XMP language alternative's default text ("x-default", else the first), "" when absent.
std::string xmp_text(const Exiv2::XmpData& xmp, const char* key) {
  const auto it = xmp.findKey(Exiv2::XmpKey(key));
  if (it == xmp.end()) return "";
  if (const auto* alt = dynamic_cast<const Exiv2::LangAltValue*>(&it->value())) {
    const auto d = alt->value_.find("x-default");
    if (d != alt->value_.end()) return d->second;
    return alt->value_.empty() ? "" : alt->value_.begin()->second;
  }
  return it->toString();
}

}  // namespace

PictureNotes embedded_notes(const std::string& image_path) {
  // exiv2's XMP toolkit is not safe to use from two threads at once, and pictures are read on the scene
  // builder's worker, the stick service's and beside a build: one file at a time.
  static std::mutex exiv2_mutex;
  const std::lock_guard<std::mutex> lock(exiv2_mutex);
  PictureNotes notes;
  try {
    Exiv2::LogMsg::setLevel(Exiv2::LogMsg::mute);  // exiv2 would print to stderr about odd files
    const Exiv2::Image::AutoPtr image = Exiv2::ImageFactory::open(image_path);
    if (image.get() == nullptr) return notes;
    image->readMetadata();
    const PngText png = read_png_text(image_path);  // empty for any other format
    notes.title = usable_note(xmp_text(image->xmpData(), "Xmp.dc.title"), kMaxTitleBytes, false);
    if (notes.title.empty()) notes.title = usable_note(png.title, kMaxTitleBytes, false);
    if (notes.title.empty()) {
      const auto it = image->exifData().findKey(Exiv2::ExifKey("Exif.Image.ImageDescription"));
      if (it != image->exifData().end()) notes.title = usable_note(it->toString(), kMaxTitleBytes, false);
    }
    notes.description = usable_note(xmp_text(image->xmpData(), "Xmp.dc.description"), kMaxDescriptionBytes, true);
    if (notes.description.empty()) notes.description = usable_note(png.description, kMaxDescriptionBytes, true);
    if (notes.description.empty()) notes.description = usable_note(image->comment(), kMaxDescriptionBytes, true);
  } catch (const std::exception&) {
    return {};  // not an image exiv2 reads, or damaged metadata: nothing said of it
  }
  return notes;
}

std::string notes_path(const std::string& image_path) {
  return fs::path(image_path).replace_extension(".toml").string();
}

PictureNotes read_picture_notes(const std::string& image_path, const PictureNotes* file_notes) {
  const std::string file = notes_path(image_path);
  std::error_code ec;
  if (!fs::exists(file, ec)) return file_notes != nullptr ? *file_notes : embedded_notes(image_path);
  return read_sidecar(file);
}

PictureNotes read_sidecar(const std::string& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) fail(file, "is not a regular file");
  const auto size = fs::file_size(file, ec);
  if (ec) fail(file, "cannot be read: " + ec.message());
  if (size > kMaxNotesFileBytes)
    fail(file, "is " + std::to_string(size) + " bytes, at most " + std::to_string(kMaxNotesFileBytes));
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file, "cannot be opened");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  toml::table root;
  try {
    root = toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    fail(file, "TOML syntax error at line " + std::to_string(b.line) + ", column " + std::to_string(b.column));
  }
  PictureNotes notes;
  notes.from_sidecar = true;
  for (auto&& [key, node] : root) {
    const std::string name(key.str());
    if (name == "title") {
      notes.title = checked_text(file, name, node, kMaxTitleBytes, false);
    } else if (name == "description") {
      notes.description = checked_text(file, name, node, kMaxDescriptionBytes, true);
    } else if (name == "guesses") {
      const toml::value<bool>* flag = node.as_boolean();
      if (!flag) fail(file, "guesses must be true or false");
      notes.guesses = flag->get();
    } else if (node.is_table() && hk::is_language_tag(name)) {
      PictureNotes::Translation& t = notes.translations[name];
      for (auto&& [inner_key, inner] : *node.as_table()) {
        const std::string inner_name(inner_key.str());
        if (inner_name == "title")
          t.title = checked_text(file, name + ".title", inner, kMaxTitleBytes, false);
        else if (inner_name == "description")
          t.description = checked_text(file, name + ".description", inner, kMaxDescriptionBytes, true);
        else
          fail(file,
               "unknown key '" + name + "." + hk::one_line(inner_name, 60) + "' (title and description are known)");
      }
    } else {
      fail(file, "unknown key '" + hk::one_line(name, 60) +
                     "' (title, description, guesses and a table per language such as [fr] are known)");
    }
  }
  return notes;
}

PictureNotes notes_in(const PictureNotes& notes, std::string_view language) {
  PictureNotes out = notes;
  auto it = notes.translations.find(std::string(language));
  if (it == notes.translations.end()) it = notes.translations.find(std::string(hk::language_subtag(language)));
  if (it == notes.translations.end()) return out;
  if (!it->second.title.empty()) out.title = it->second.title;
  if (!it->second.description.empty()) out.description = it->second.description;
  // The language of what is said at length: the translated description, or the translated title of notes that
  // have no description; a translated title over the top-level description leaves it the top level's.
  const bool translated_description = !it->second.description.empty();
  const bool only_a_title = notes.description.empty() && !it->second.title.empty();
  if (translated_description || only_a_title) out.language = it->first;
  return out;
}

}  // namespace hk::app
