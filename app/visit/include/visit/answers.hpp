#pragma once
/// @file answers.hpp
/// The Where and Describe answers, from what is shown and where the hand is: free functions the stage (the
/// kiosk) and the explore command (`explore INPUT --where X_M,Y_M`, `--describe`) share, so what a script
/// prints is what a visitor hears.

#include <string>
#include <vector>

#include "audio/messages.hpp"
#include "formats/picture_notes.hpp"
#include "haptics/multires.hpp"
#include "hk/vec2.hpp"
#include "meaning/shape_descriptors.hpp"
#include "pictures/image_scene.hpp"
#include "visit/describe.hpp"

namespace hk::app {

/// What an answer reads of what is shown. The references outlive the view.
struct ShownView {
  const std::vector<Polyline>& polylines;                    ///< level-0 curves [m]
  const std::vector<meaning::ShapeDescriptor>& descriptors;  ///< one per polyline (or empty: forms only)
  const std::vector<TextBlockM>& text_blocks;                ///< a page's text
  const PictureNotes& notes;                                 ///< title and description written by a person
  Vec2 half_m;                                               ///< half the workspace's extent [m]
  bool tutorial = false;                                     ///< a practice shape: notes.title names it ("a square")
  bool page = false;                                         ///< a document page (its text blocks and figures are said)
  const PictureNames* names = nullptr;                       ///< staff names in spoken form; null: none
  const std::vector<meaning::NamedRegion>* regions = nullptr;  ///< their regions on the picture; null: none
  vision::PxToM px_to_m{1, 0, 0};                              ///< the picture's pixels → metres (for `regions`)
};

/// What a person wrote of a picture, as Describe opens with it: "A horse. A horse standing, ... " (the title
/// left out when the description opens with it; a space after); "" when nothing was written.
std::string notes_words(const PictureNotes& notes);

/// A region's name as said in `m`'s language: staff's in that language where they gave one (region_name_in), with
/// its article (said_name: "the left wing"), a guess's from the catalogue ("something that could be a face",
/// "text: Emergency exit").
std::string region_said_name(const meaning::NamedRegion& region,
                             const audio::MessageCatalog& m = audio::MessageCatalog::english());

/// The names of a picture in the terms Describe and Where use: each curve's name (said_name of the region it
/// takes it from, `shape_region[i]`, −1 none; when several shapes take one region's: "one of the white spots" for a
/// plural name, "part of the left wing" for another) and each named region once (the largest region of a name), largest
/// first, with its centre and area in metres (`px_to_m`). `curves`: how many curves there are. Given `polylines`
/// (the `curves` curves [m]), each part's curve is the longest curve taking its name.
PictureNames picture_names(const std::vector<meaning::NamedRegion>& regions, const std::vector<int>& shape_region,
                           std::size_t curves, const vision::PxToM& px_to_m,
                           const std::vector<Polyline>* polylines = nullptr,
                           const audio::MessageCatalog& m = audio::MessageCatalog::english());

/// Words of a block of text that Where reads (Describe reads it whole).
inline constexpr int kWhereTextWords = 8;

/// What shape `curve` is, for speech: a practice shape's title, else its staff name ("the left wing"), else
/// describe_one_shape without its place.
std::string shape_words(const ShownView& shown, std::size_t curve,
                        const audio::MessageCatalog& m = audio::MessageCatalog::english());

/// What shape `curve` looks like, short: a practice shape's title, its staff name, else describe_one_look ("a small
/// white round shape"): what Where says of a shape the hand is inside or near.
std::string shape_look(const ShownView& shown, std::size_t curve,
                       const audio::MessageCatalog& m = audio::MessageCatalog::english());

/// The Where answer for the hand at `hand_m` [m] with the proxy on curve `contact_curve` (−1 for none): the text
/// block under it (where_text), else the shape it is on (where_on; where_on_part with the smallest named region
/// under the hand when that is not the shape's own name: "the horse, at the head"), else the smallest named
/// region under it (where_region: a named area with no shape in it too), else the shape it is inside (where_inside: the
/// way to its edge) or nearest (where_near: the way and distance to it), else where_none. Specks are not shapes.
std::string where_answer(const ShownView& shown, const audio::MessageCatalog& messages, Vec2 hand_m, int contact_curve);

/// The Describe answer with the hand at `hand_m` and the proxy at `proxy_m` [m]: on a page, the block of text
/// under the proxy read whole, else what the page holds and its shapes; a practice shape by its title; a
/// picture by what a person wrote of it (its title unless its description opens with it, then the
/// description) and then its shapes (describe_scene, nearest the hand first).
std::string describe_answer(const ShownView& shown, const audio::MessageCatalog& messages, Vec2 hand_m, Vec2 proxy_m);

}  // namespace hk::app
