#pragma once
/// @file annotations.hpp
/// Names staff give regions of a picture, read from `NAME.annotations.json`: the W3C Web Annotation Data Model
/// (https://www.w3.org/TR/annotation-model/) as IIIF publishes it.
///
/// | the file holds | read as |
/// |---|---|
/// | an `AnnotationPage` (`items`) | its annotations |
/// | a JSON array, or one `Annotation` | those annotations |
/// | a IIIF Presentation 3 `Manifest` | the `annotations` pages of the picture's canvas (below) |
/// | a IIIF Presentation 2 `sc:AnnotationList` (`resources`) | its `oa:Annotation`s (below) |
///
/// A Manifest's canvas is the one whose painted image's file name is the picture's (else the first), its width
/// and height kept. An `oa:Annotation` has a `resource` (`chars`; an `oa:Tag` is a name) and an `on` (a `#xywh=`
/// string, or an `oa:SpecificResource` with a selector, or an `oa:Choice` of two). An annotation page referenced
/// only by URL is not fetched (the kiosk is offline): noted in `problems`. A target whose `source` is a `Canvas`
/// with `width` and `height` (as write_annotation_page writes one) gives the canvas when no Manifest does.
///
/// | part | read |
/// |---|---|
/// | `body` | a `TextualBody` or an array of them (`value`, `language`, `purpose`) |
/// | `target` | a `source#xywh=…` string, or a `SpecificResource` with a `selector` (the first understood) |
/// | `FragmentSelector` | `xywh=x,y,w,h` (pixels, also `xywh=pixel:…`) or `xywh=percent:x,y,w,h` |
/// | `SvgSelector` | its `value`, an SVG document (drawn later by librsvg: meaning/names.hpp) |
///
/// A body is a name when its purpose, else the annotation's motivation, is `identifying` or `tagging`, a
/// description when `describing` or `commenting` (neither said: a name). The first name's `language` is the
/// annotation's; bodies in other languages are its translations (a name and a description a language).
///
/// Rules (an annotation that breaks one is left out, with one line in `problems` naming the file and the rule;
/// the rest are kept): a name of at most kMaxNameBytes and a description of at most kMaxRegionDescriptionBytes, both
/// valid UTF-8 without control characters (a description may break lines); a region of positive size; an SVG of
/// at most kMaxSvgBytes; at most kMaxAnnotations annotations (the rest left out). A file that is not JSON, or
/// JSON that is none of the forms above, or larger than kMaxAnnotationFileBytes, is refused whole
/// (AnnotationError).

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "formats/app_error.hpp"

namespace hk::app {

inline constexpr std::size_t kMaxNameBytes = 200;                ///< a name's length at most [bytes]
inline constexpr std::size_t kMaxRegionDescriptionBytes = 4096;  ///< a description's at most [bytes]
inline constexpr std::size_t kMaxSvgBytes = 64 * 1024;           ///< an SvgSelector's document at most [bytes]
inline constexpr std::size_t kMaxAnnotations = 1000;             ///< annotations read from one file at most
inline constexpr std::size_t kMaxAnnotationFileBytes = 8 << 20;  ///< a file's size at most [bytes]

/// A file of annotations refused whole: its message names the file and the rule, on one line.
class AnnotationError : public AppError {
 public:
  using AppError::AppError;
};

/// Where an annotation points, in canvas coordinates (AnnotationSet::canvas_width_px; without a canvas, the
/// picture's pixels after its EXIF orientation).
struct AnnotationSelector {
  enum class Kind { rect, svg };
  Kind kind = Kind::rect;
  double x = 0, y = 0, w = 0, h = 0;  ///< rect: its box [px, or % of the canvas when percent]
  bool percent = false;               ///< rect: x, y, w, h are percentages of the canvas's width and height
  std::string svg;                    ///< svg: the SVG document
};

/// One region staff described.
struct Annotation {
  std::string name;         ///< what it is ("the left wing"); may be empty when only described
  std::string description;  ///< a longer text; may be empty
  std::string language;     ///< the name's BCP 47 language tag, "" when not said
  AnnotationSelector selector;
  /// The name and description in other languages, by BCP 47 tag: the bodies whose `language` differs from the
  /// first name's (one TextualBody a language, as the W3C model gives translations). Either may be empty.
  struct Translation {
    std::string name, description;
  };
  std::map<std::string, Translation> translations;
};

/// The name and description of `a` said to a visitor in `language` (a BCP 47 tag): its translation's where it
/// has one (the tag, else its language subtag: "fr-CA" takes "fr"), else the annotation's own (first) ones.
/// `*language_out`, when given, is the language of the name chosen ("" when not said).
Annotation::Translation annotation_text_in(const Annotation& a, std::string_view language,
                                           std::string* language_out = nullptr);

/// What one file says.
struct AnnotationSet {
  std::vector<Annotation> annotations;
  /// The canvas the coordinates are in [px] (a Manifest's canvas); 0: the picture's own pixels.
  double canvas_width_px = 0, canvas_height_px = 0;
  /// One line per annotation or page left out: "FILE: annotation 3: the name is longer than 200 bytes".
  std::vector<std::string> problems;
};

/// Why `text` cannot be an annotation's name (`description` false) or its description (true), as the reader leaves
/// such an annotation out: "the name is longer than 200 bytes", "the name is not valid UTF-8", "the name has a
/// control character" (a description may break lines); "" when it can.
std::string annotation_text_problem(const std::string& text, bool description);

/// The file of names for `picture_path` ("…/horse.png" → "…/horse.annotations.json").
std::string annotations_path(const std::string& picture_path);

/// The same in the folder `names_dir` (the writable names folder): "DIR/horse.annotations.json".
std::string annotations_path_in(const std::string& names_dir, const std::string& picture_path);

/// Reads the annotations of `text` (the bytes of a file named `source` in messages) for the picture whose file
/// name is `picture_file_name` (which canvas of a Manifest). Throws AnnotationError for a text that is not JSON
/// or none of the forms of the table, or larger than kMaxAnnotationFileBytes.
AnnotationSet parse_annotations(std::string_view text, const std::string& source, const std::string& picture_file_name);

/// Reads the file `path` (parse_annotations). Throws AnnotationError when it cannot be read or is refused.
AnnotationSet read_annotations(const std::string& path, const std::string& picture_file_name);

/// The annotations as an AnnotationPage (W3C model: TextualBody with purpose "identifying" for the name and
/// "describing" for the description; a SpecificResource target with its selector; canvas coordinates as
/// given), for a file written by the kiosk. `source` is the target's source (the picture's file name); with a
/// canvas in `set` (AnnotationSet::canvas_width_px > 0) the source is a Canvas of that width and height, which
/// parse_annotations reads back as the canvas, so the coordinates keep their meaning.
std::string write_annotation_page(const AnnotationSet& set, const std::string& source);

}  // namespace hk::app
