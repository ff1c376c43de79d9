#pragma once
/// @file picture_notes.hpp
/// What a person wrote about a picture: a title and a description in a sidecar file
/// beside it, `horse.toml` for `horse.png`:
///
///     title = "a horse, seen from the side"
///     description = "A horse standing, its head to the left."
///     guesses = false   # optional: no faces or text guessed on it
///
///     [fr]              # optional, one table per language (a BCP 47 tag): said to a visitor in that language
///     title = "un cheval, vu de côté"
///     description = "Un cheval debout, la tête à gauche."
///
/// The kiosk speaks the title when the picture is shown ("Picture 2 of 5: a horse, seen from the side.") and
/// both first when the visitor asks for a description. Written by people, so read with care: a sidecar that
/// cannot be used is refused with one line, and the picture is shown without it.

#include <cstddef>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include "hk/error.hpp"

namespace hk::app {

/// A picture's title and description; both empty when it has none.
struct PictureNotes {
  std::string title;        ///< one line, 1 to kMaxTitleBytes bytes of UTF-8; empty when none
  std::string description;  ///< 1 to kMaxDescriptionBytes bytes of UTF-8, spoken as it is; empty when none
  /// Whether the kiosk's own guesses name parts of the picture (faces, text blocks: picture_names.hpp); a
  /// sidecar's `guesses = false` turns them off (a false face on an artwork).
  bool guesses = true;
  /// The title and description in other languages, by BCP 47 tag ("fr"): the sidecar's [fr] table; either may
  /// be empty (the top-level one is said then).
  struct Translation {
    std::string title, description;
  };
  std::map<std::string, Translation> translations;
  /// The language the title and description are in (BCP 47): notes_in's translation's tag; "" when not known
  /// (the sidecar's top-level keys, in the kiosk's default language; a file's own metadata).
  std::string language;
  /// The title and description are a sidecar's (a person wrote them for the kiosk, in its default language),
  /// not the picture file's own metadata.
  bool from_sidecar = false;
};

/// `notes` as said to a visitor in `language` (a BCP 47 tag): its translation's title and description where
/// the sidecar has them (the tag, else its language subtag: "fr-CA" takes [fr]), else the top-level ones.
PictureNotes notes_in(const PictureNotes& notes, std::string_view language);

inline constexpr std::size_t kMaxNotesFileBytes = 16 * 1024;
inline constexpr std::size_t kMaxTitleBytes = 200;
inline constexpr std::size_t kMaxDescriptionBytes = 1000;

/// A sidecar that cannot be used: what() is one line naming the file and what is wrong with it, e.g.
/// "picture notes 'horse.toml': title is 312 bytes, at most 200".
class PictureNotesError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// What the picture file itself says of it (exiv2, and libpng for a PNG's text chunks, png_text.hpp): the
/// title from XMP dc:title, else a PNG's `Title` text, else EXIF ImageDescription; the description from XMP
/// dc:description, else a PNG's `Description` text, else the image comment (a JPEG's COM). Values are checked as a
/// sidecar's are (trimmed, valid UTF-8, not blank, within the byte limits, one line for the title); a value that fails,
/// and the placeholders cameras write ("OLYMPUS DIGITAL CAMERA", "SONY DSC", ...), are skipped rather than refused: the
/// file's author did not write them for the kiosk. Never throws; a file exiv2 cannot read gives empty notes. Safe to
/// call from any thread: calls take turns (exiv2's XMP toolkit is not thread-safe).
PictureNotes embedded_notes(const std::string& image_path);

/// A title or description found in a file (a picture's metadata, a PDF's Info /Title): trimmed, when it is
/// valid UTF-8, not blank, at most max_bytes, one line when `lines` is false (no control characters but line
/// breaks when true), and no camera's placeholder ("OLYMPUS DIGITAL CAMERA", "Untitled", ...); else "".
/// Never throws.
std::string usable_note(const std::string& raw, std::size_t max_bytes, bool lines);

/// The sidecar of `image_path`: the file of the same name with the extension `.toml` in the same folder.
std::string notes_path(const std::string& image_path);

/// Reads the sidecar of `image_path` (notes_path). No sidecar: what the file itself says, `*file_notes` when
/// given (embedded_notes read earlier, e.g. kept with a cached scene), else embedded_notes (a sidecar wins
/// over the file: it is the operator's). The sidecar must be at most
/// kMaxNotesFileBytes, valid TOML, with only the string keys `title` (one line, no control characters, at
/// most kMaxTitleBytes) and `description` (no control characters but line breaks, at most
/// kMaxDescriptionBytes), both valid UTF-8 and not blank, and the boolean `guesses`; surrounding white space is
/// trimmed.
/// @throws PictureNotesError (one line) for a sidecar that breaks any of these, or cannot be read.
PictureNotes read_picture_notes(const std::string& image_path, const PictureNotes* file_notes = nullptr);

/// Reads the sidecar file `sidecar_path` itself (read_picture_notes' rules; a missing file is refused too).
/// @throws PictureNotesError (one line) for a file that breaks them or cannot be read.
PictureNotes read_sidecar(const std::string& sidecar_path);

}  // namespace hk::app
