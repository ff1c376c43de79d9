#pragma once
/// @file names.hpp
/// Staff names on a picture's shapes: the regions of an annotation file (formats/annotations.hpp) drawn onto
/// the picture's pixels, and each shape named by the smallest region holding at least half of its outline.
///
/// A FragmentSelector's box is filled; an SvgSelector is drawn by librsvg as its SVG says (fill and stroke),
/// so any path SVG allows (relative commands, arcs, transforms, groups) takes the shape it shows. An SVG that
/// draws only thin strokes (less than a fifth of its box covered: an open path, a polyline) is widened by
/// kLineReachPx on each side, so the shapes along it fall inside. Coordinates are the canvas's, scaled to the
/// picture's pixels when the canvas's size differs (a museum's master image is larger than the kiosk's copy).

#include <opencv2/core.hpp>

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "formats/annotations.hpp"
#include "haptics/multires.hpp"
#include "vision/mapping.hpp"

namespace hk::meaning {

/// How far an SVG line's region reaches on each side of its stroke [px of the picture].
inline constexpr int kLineReachPx = 6;

/// Who named a region: staff (an annotation file, the authority), or a guess of the kiosk's own.
enum class RegionSource {
  staff,  ///< an annotation: said with its article ("the left wing")
  face,   ///< a face guessed (faces.hpp): said as a guess, kFaceName
  text,   ///< a block of text read from the page or picture: "text: " and its first words
};

/// The name of a face guessed, as said: a guess, never a certainty.
inline constexpr const char* kFaceName = "something that could be a face";
/// Words of a text block a text region's name keeps ("text: Emergency exit").
inline constexpr int kTextNameWords = 4;

/// The key scene.json gives each source: "staff", "face", "text".
const char* region_source_key(RegionSource s);

/// One named region on the picture's pixels.
struct NamedRegion {
  RegionSource source = RegionSource::staff;
  std::string name;         ///< what staff called it (may be empty when they only described it), or the guess's name
  std::string description;  ///< their longer text; may be empty
  cv::Rect box_px;          ///< its bounding box on the picture [px], within the picture
  cv::Mat mask;             ///< CV_8U over box_px, non-zero inside
  double area_px = 0;       ///< pixels inside
  int annotation = -1;      ///< the index in AnnotationSet::annotations it was drawn from; −1 when not from a set
  std::string language;     ///< the name's BCP 47 tag, "" when not said
  /// The name in other languages, by BCP 47 tag (Annotation::translations' names).
  std::map<std::string, std::string> names_in;
};

/// The name of `region` said to a visitor in `language` (a BCP 47 tag): its name in that language (the tag, else
/// its language subtag) where it has one, else its own name. `*language_out`, when given, is the language of the
/// name returned ("" when not said).
std::string region_name_in(const NamedRegion& region, std::string_view language, std::string* language_out = nullptr);

/// The regions of `set` on a picture of `width_px` x `height_px` [px] whose full-detail size (the file's, upright)
/// is `full_width_px` x `full_height_px`: without a canvas in `set`, coordinates are those full-detail pixels. A
/// region outside the picture, an SVG that cannot be read or draws nothing, is left out with one line in
/// `problems` (naming `source` and the rule). Cost: one picture-sized 8-bit surface per SVG region.
std::vector<NamedRegion> draw_regions(const app::AnnotationSet& set, int width_px, int height_px, int full_width_px,
                                      int full_height_px, const std::string& source,
                                      std::vector<std::string>* problems);

/// A guessed region (`source` face or text) named `name` filling the box `box_px` [px] of a `width_px` x
/// `height_px` picture (clipped to it): an ellipse for a face, the whole box for text. nullopt when nothing of
/// the box lies on the picture.
std::optional<NamedRegion> guessed_region(RegionSource source, std::string name, cv::Rect box_px, int width_px,
                                          int height_px);

/// Whether at least half of `guess`'s pixels lie in one of `staff` (staff named that part already: their name is
/// the one said, the guess is dropped).
bool covered_by_staff(const NamedRegion& guess, const std::vector<NamedRegion>& staff);

/// The region each polyline takes its name from: the smallest (fewest pixels) region with a name that holds at
/// least half of the polyline's points (`px_to_m` maps picture pixels to metres); −1 for none. One per polyline.
std::vector<int> name_shapes(const std::vector<NamedRegion>& regions, const std::vector<Polyline>& polylines,
                             const vision::PxToM& px_to_m);

/// The regions with a name holding the picture pixel (u, v) [px], the smallest first.
std::vector<int> regions_at(const std::vector<NamedRegion>& regions, double u_px, double v_px);

}  // namespace hk::meaning
