#pragma once
/// @file shape_form.hpp
/// What a shape looks like, guessed from its outline: round, oval, square, rectangle, triangle, a polygon of
/// N corners, star-like, a straight line or a curve. Said as a guess ("a round shape"), never as a fact.
///
/// | form | when (closed outline unless said) |
/// |---|---|
/// | round | no corner, circularity 4πA/P² ≥ 0.7, convex, principal axes within 1.25 : 1 |
/// | oval | as round, the axes further apart |
/// | square | 4 corners of 60–120° turn each, convex, straight sides, axes within 1.15 : 1 |
/// | rectangle | as square, the axes further apart |
/// | triangle | 3 corners, convex, straight sides (no point farther from a side's chord than 8 % of it) |
/// | polygon | 4–8 corners, convex, straight sides (4 only when not a square or rectangle) |
/// | star | 8 corners or more, at least 2 in 5 of them notches (turning against the way round), solidity < 0.75 |
/// | straight line | open, chord at least 0.95 of its length |
/// | curve | open, the rest |
/// | irregular | closed, the rest (no form is said) |
///
/// Solidity is a shape's area over its convex hull's.
///
/// Corners are found on the curve's coarse wavelet level (the coarsest whose largest deviation from the
/// curve is at most 3 % of its size, with at least 32 points: seed §2, the scaling coefficients as a smoothed curve, so
/// the jitter of edge pixels is gone and true corners stay), resampled to kFormSamples points equally spaced in arc
/// length: a point is a corner where the direction turns by at least kCornerTurnDeg over kCornerWindow
/// samples on either side, sharply (kCornerSharpness), the largest turn within that window.

#include <cstddef>
#include <string_view>
#include <vector>

#include "hk/vec2.hpp"

namespace hk::meaning {

/// Points an outline is resampled to before its corners are counted.
inline constexpr std::size_t kFormSamples = 64;
/// Samples on either side of a point over which its turn is measured (about 5 % of the outline each side).
inline constexpr std::size_t kCornerWindow = 3;
/// Least turn of the direction at a corner [deg]: a circle turns 34° over the window, an octagon's corner 45°.
inline constexpr double kCornerTurnDeg = 45.0;
/// Least share of the turn over twice the window that a corner turns over the window: a corner's turn is
/// all at one point (share about 1), a smooth bend's grows with the arc (share about 1/2: the ends of an oval).
inline constexpr double kCornerSharpness = 0.7;

/// The form a shape looks like (table in the file comment).
enum class Form { irregular, round, oval, square, rectangle, triangle, polygon, star, straight_line, curve };

/// A guess at a shape's form.
struct FormGuess {
  Form form = Form::irregular;
  int corners = 0;  ///< corners found (a polygon's N; 0 for round, oval and lines without corners)
};

/// The form of the outline `points_m` [m] (closed: the last point joins the first, not repeated). Fewer
/// than 3 distinct points, or no length: a straight line when open, irregular when closed. Cost:
/// O(points) plus O(kFormSamples · log kFormSamples) for the hull.
FormGuess form_of(const std::vector<Vec2>& points_m, bool closed);

/// The form's key in scene.json: "round", "oval", "square", "rectangle", "triangle", "polygon", "star",
/// "straight line", "curve", "irregular".
std::string_view form_key(Form form);

/// The form parsed from its key (form_key); false for anything else.
bool form_from_key(std::string_view key, Form* form);

}  // namespace hk::meaning
