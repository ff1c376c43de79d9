#pragma once
/// @file describe.hpp
/// The Describe key (issue 5, item 4): a spoken summary of a picture's shapes and where they are, e.g.
/// "3 shapes. A large closed shape with a smaller shape inside it, in the middle, a small line at the top
/// left, and a small closed shape at the bottom right." English only for now (the catalogue's `describe` message carries it whole).

#include <string>
#include <vector>

#include "haptics/multires.hpp"
#include "haptics/vec2.hpp"

namespace hk::app {

/// Describes `curves` (workspace metres) in a workspace of half extents `half_extent_m` [m] (issue 5, item 4;
/// structure, issue 15, item 4): how many shapes, then the largest `max_named` of those inside no other shape,
/// each with its size (large / medium / small by bounding-box diagonal against the workspace diagonal:
/// > 40 %, > 15 %, else small), kind (closed shape or line), how many shapes lie inside it (a shape is inside
/// a larger closed one when its bounding box is within the other's and 16 of its points, spread along it,
/// are inside the other's polygon) and place (the cell of a 3 x 3 grid holding its bounding-box centre);
/// the rest are counted. E.g. "4 shapes. A large closed shape with 3 smaller shapes inside it, at the top
/// left." Cost: O(shapes² · 16 · points of the larger), for the few dozen shapes of a scene.
std::string describe_scene(const std::vector<Polyline>& curves, Vec2 half_extent_m, int max_named = 3);

/// Figures on a document page: groups of curves whose bounding boxes, grown by margin_m on every side,
/// overlap (transitively: union-find over the pairs). A drawing of many strokes counts once; two drawings
/// apart count twice. Returns 0 for no curves.
int count_figures(const std::vector<Polyline>& curves, double margin_m = 0.002);

/// How many shapes a picture has, for speech: "It has 4 shapes.", "It has one shape.", "I found no shapes in it."
std::string describe_shapes(int shapes);

/// What a document page holds, for speech (issue 11, item 4): "It has 2 blocks of text and one figure.",
/// "It has one block of text and no figures.", "It has no text and no figures."
std::string describe_page(int text_blocks, int figures);

}  // namespace hk::app
