#pragma once
/// @file describe.hpp
/// The Describe and Where keys: a spoken summary of a picture's shapes and where they are, e.g.
/// "3 shapes. A large black shape with a small white round shape inside it, in the middle, a straight line at
/// the far left, and a small red square at the near right.", and one shape under, around or near the hand. Places are
/// in the visitor's terms: far is away from them (+y), near towards them. Every phrase is built from the words of
/// the catalogue `m` (audio/messages.hpp kWordSources: look_*, size_*, colour_*, place_*, list_*, …), so it
/// comes out in the visitor's language with its genders and word order; the examples are English.

#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "audio/messages.hpp"
#include "haptics/multires.hpp"
#include "hk/vec2.hpp"
#include "meaning/shape_descriptors.hpp"

namespace hk::app {

/// Where point `p_m` lies in a workspace of half extents `half_extent_m` [m], in the visitor's terms: the cell
/// of a 3 x 3 grid, "at the far left", "in the far middle", "at the far right", "on the left", "in the
/// middle", "on the right", "at the near left", "in the near middle", "at the near right".
std::string place_words(Vec2 p_m, Vec2 half_extent_m,
                        const audio::MessageCatalog& m = audio::MessageCatalog::english());

/// The shape under or nearest a hand.
struct ShapeAtHand {
  int curve = -1;       ///< index into the curves, −1 when there are none
  bool on = false;      ///< in contact with it, or within on_within_m of it
  bool inside = false;  ///< not on it, and within it: the smallest closed shape holding the hand
  double distance_m = std::numeric_limits<double>::infinity();  ///< from the hand to its polyline [m]
  Vec2 nearest_m;                                               ///< its point nearest the hand [m]
};

/// The shape the hand at `hand_m` [m] is on, in, or nearest, among the curves whose descriptor is not a speck
/// (`descriptors` parallel to `curves`; empty: every curve counts): `contact_curve` (the curve the proxy rests
/// on, −1 for none) when it counts; else the nearest curve (polyline, closing segment included) within
/// `on_within_m` [m]; else the smallest closed curve holding the hand (`inside`); else the nearest. Cost:
/// O(points).
ShapeAtHand shape_at_hand(const std::vector<Polyline>& curves, const std::vector<meaning::ShapeDescriptor>& descriptors,
                          Vec2 hand_m, int contact_curve, double on_within_m = 0.003);

/// Whether the closed curve `c` holds the point `p_m` [m] (even-odd rule); false for an open curve.
bool shape_holds(const Polyline& c, Vec2 p_m);

/// Which way and how far `to_m` lies from `from_m`, in the visitor's terms: "3 cm to your right", "less than a
/// centimetre farther away", "5 cm nearer to you, to your left" (8 directions; far is +y).
std::string direction_words(Vec2 from_m, Vec2 to_m, const audio::MessageCatalog& m = audio::MessageCatalog::english());

/// The number a visitor hears for curve `curve` of `curves` curves (from 1), counting only the shapes that are not
/// specks, and how many there are: {number, count}. A speck's number is 0. `descriptors` not one per curve (none
/// known): every curve counts, as shape_at_hand counts them.
std::pair<int, int> shape_number(const std::vector<meaning::ShapeDescriptor>& descriptors, std::size_t curves,
                                 std::size_t curve);

/// One shape, `curves[index]`, for speech, from its descriptor (size against the workspace, colour, form):
/// "a small white round shape", "a large black shape with 26 small white round shapes inside it"; `with_place`
/// adds its place (place_words of its bounding-box centre).
/// `descriptors`: parallel to `curves`; empty: forms from the curves' own points, no colours.
std::string describe_one_shape(const std::vector<Polyline>& curves,
                               const std::vector<meaning::ShapeDescriptor>& descriptors, std::size_t index,
                               Vec2 half_extent_m, bool with_place = true,
                               const audio::MessageCatalog& m = audio::MessageCatalog::english());

/// Names staff gave the picture (meaning/names.hpp), in the terms Describe and Where use.
struct PictureNames {
  /// One per curve: its name as said ("the left wing"), "" for none; empty: no names.
  std::vector<std::string> shape_name;
  /// One per curve: the name of the part it belongs to, as said when it is touched ("the left wing"; "one of the
  /// white spots" for a plural name several shapes share), "" for none; empty: no names.
  std::vector<std::string> part_name;
  /// One per curve: the region it takes its name from, −1 for none; empty: no names.
  std::vector<int> shape_region;
  /// A named part of the picture: each name once, with the centre of its region [m] and its area [m²].
  struct Part {
    std::string name;  ///< as said ("the left wing")
    Vec2 centre_m;
    double area_m2 = 0;
    int curve = -1;      ///< the longest curve taking this name (what a tour to it traces), −1 for none or not known
    bool guess = false;  ///< named by the kiosk's own guess (a face, a text block), not by staff
  };
  std::vector<Part> parts;  ///< largest first
};

/// A staff name as said: "the " before a name that starts with a small letter and no article ("left wing" →
/// "the left wing"); a proper name ("Gänseliesel fountain") and one with its own article as written.
std::string said_name(const std::string& name, const audio::MessageCatalog& m = audio::MessageCatalog::english());

/// One shape's look only (size, colour, form): "a small white round shape"; "a speck" for a speck.
std::string describe_one_look(const std::vector<Polyline>& curves,
                              const std::vector<meaning::ShapeDescriptor>& descriptors, std::size_t index,
                              Vec2 half_extent_m, const audio::MessageCatalog& m = audio::MessageCatalog::english());

/// Describes `curves` (workspace metres) in a workspace of half extents `half_extent_m` [m]: how many shapes
/// (specks not counted), then up to `max_named` groups of those inside no other shape, the largest first or,
/// given `hand_m`, the nearest to the hand first (a shape holding the hand at distance 0, introduced "Nearest
/// your hand, ..."). Shapes alike (the same size word, colour and form, inside the same shape) are said
/// together: "4 small grey round shapes, at the far right"; each with its size (large / medium / small by
/// bounding-box diagonal against the workspace diagonal: > 40 %, > 15 %, else small), colour, form, what lies
/// inside it (as groups: "with 26 small white round shapes inside it"; a shape is inside a larger closed one when
/// its bounding box is within the other's and 16 of its points, spread along it, are inside the other's
/// polygon) and place (the members' place_words when they share it, else "across the picture"). The rest are
/// counted, "smaller ones" only when every one of them is smaller than the last named. With `names`, the named
/// parts come first, largest first, each with its place ("The left wing on the left, the body in the middle,
/// ..."), and the groups that follow are of the shapes without a name ("Also 5 small round shapes across the
/// picture."). `descriptors` as describe_one_shape. Cost: O(shapes² · 16 · points of the larger), for the few
/// dozen shapes of a scene.
std::string describe_scene(const std::vector<Polyline>& curves,
                           const std::vector<meaning::ShapeDescriptor>& descriptors, Vec2 half_extent_m,
                           int max_named = 3, std::optional<Vec2> hand_m = std::nullopt,
                           const PictureNames* names = nullptr,
                           const audio::MessageCatalog& m = audio::MessageCatalog::english());

/// Figures on a document page: groups of curves whose bounding boxes, grown by margin_m on every side,
/// overlap (transitively: union-find over the pairs). A drawing of many strokes counts once; two drawings
/// apart count twice. Returns 0 for no curves.
int count_figures(const std::vector<Polyline>& curves, double margin_m = 0.002);

/// `text` with its first letter upper case (hk::capitalised): a phrase that begins a sentence ("the left wing" →
/// "The left wing").
std::string sentence_case(std::string text);

/// How many shapes a picture has, for speech: "It has 4 shapes.", "It has one shape.", "I found no shapes in it."
std::string describe_shapes(int shapes, const audio::MessageCatalog& m = audio::MessageCatalog::english());

/// What a document page holds, for speech: "It has 2 blocks of text and one figure.",
/// "It has one block of text and no figures.", "It has no text and no figures."
std::string describe_page(int text_blocks, int figures,
                          const audio::MessageCatalog& m = audio::MessageCatalog::english());

}  // namespace hk::app
