#pragma once
/// @file describe.hpp
/// The Describe and Where keys: a spoken summary of a picture's shapes and where they are, e.g.
/// "3 shapes. A large closed shape with a smaller shape inside it, in the middle, a small line at the far
/// left, and a small closed shape at the near right.", and one shape under or near the hand. Places are in
/// the visitor's terms: far is away from them (+y), near towards them. English only for now (the
/// catalogue's messages carry these phrases whole).

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "haptics/multires.hpp"
#include "hk/vec2.hpp"

namespace hk::app {

/// Where point `p_m` lies in a workspace of half extents `half_extent_m` [m], in the visitor's terms: the cell
/// of a 3 x 3 grid, "at the far left", "in the far middle", "at the far right", "on the left", "in the
/// middle", "on the right", "at the near left", "in the near middle", "at the near right".
std::string place_words(Vec2 p_m, Vec2 half_extent_m);

/// The shape under or nearest a hand.
struct ShapeAtHand {
  int curve = -1;                                               ///< index into the curves, −1 when there are none
  bool on = false;                                              ///< in contact with it, or within on_within_m of it
  double distance_m = std::numeric_limits<double>::infinity();  ///< from the hand to its polyline [m]
};

/// The shape the hand at `hand_m` [m] is on or nearest: `contact_curve` (the curve the proxy rests on, −1 for
/// none) when there is one, else the curve whose polyline (closing segment included) is nearest; `on` when in
/// contact or within `on_within_m` [m]. Cost: O(points).
ShapeAtHand shape_at_hand(const std::vector<Polyline>& curves, Vec2 hand_m, int contact_curve,
                          double on_within_m = 0.003);

/// One shape, `curves[index]`, for speech: size (as describe_scene), kind, how many shapes lie inside it and
/// the smallest closed shape it lies in: "a small closed shape with 2 inside it, in a large closed shape"; `with_place`
/// adds its place (place_words of its bounding-box centre): "..., on the left".
std::string describe_one_shape(const std::vector<Polyline>& curves, std::size_t index, Vec2 half_extent_m,
                               bool with_place = true);

/// Describes `curves` (workspace metres) in a workspace of half extents `half_extent_m` [m]: how many shapes,
/// then `max_named` of those inside no other shape (the largest first or, given `hand_m`, the nearest to the
/// hand first, a shape holding the hand at distance 0, introduced "Nearest your hand, ..."),
/// each with its size (large / medium / small by bounding-box diagonal against the workspace diagonal:
/// > 40 %, > 15 %, else small), kind (closed shape or line), how many shapes lie inside it (a shape is inside
/// a larger closed one when its bounding box is within the other's and 16 of its points, spread along it,
/// are inside the other's polygon) and place (place_words of its bounding-box centre); the rest are
/// counted. E.g. "4 shapes. A large closed shape with 3 smaller shapes inside it, at the far left." Cost:
/// O(shapes² · 16 · points of the larger), for the few dozen shapes of a scene.
std::string describe_scene(const std::vector<Polyline>& curves, Vec2 half_extent_m, int max_named = 3,
                           std::optional<Vec2> hand_m = std::nullopt);

/// Figures on a document page: groups of curves whose bounding boxes, grown by margin_m on every side,
/// overlap (transitively: union-find over the pairs). A drawing of many strokes counts once; two drawings
/// apart count twice. Returns 0 for no curves.
int count_figures(const std::vector<Polyline>& curves, double margin_m = 0.002);

/// The first `n` words of `text` (split at white space, joined by one space), for speech: what a block of
/// text begins with. The whole text when it has no more.
std::string first_words(const std::string& text, int n);

/// How many shapes a picture has, for speech: "It has 4 shapes.", "It has one shape.", "I found no shapes in it."
std::string describe_shapes(int shapes);

/// What a document page holds, for speech: "It has 2 blocks of text and one figure.",
/// "It has one block of text and no figures.", "It has no text and no figures."
std::string describe_page(int text_blocks, int figures);

}  // namespace hk::app
