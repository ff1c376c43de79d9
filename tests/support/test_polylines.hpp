#pragma once
/// @file test_polylines.hpp
/// Polylines the describe tests draw by hand: an axis-aligned rectangle of four corners.

#include "haptics/multires.hpp"
#include "hk/vec2.hpp"

namespace hk::test {

/// The rectangle of centre `c` and half extents `half` [m], its four corners counter-clockwise from the lower
/// left; `closed` false leaves the left side out (a bracket: three sides, two corners).
inline Polyline rect(Vec2 c, Vec2 half, bool closed = true) {
  Polyline p;
  p.closed = closed;
  p.points_m = {{c.x - half.x, c.y - half.y},
                {c.x + half.x, c.y - half.y},
                {c.x + half.x, c.y + half.y},
                {c.x - half.x, c.y + half.y}};
  return p;
}

}  // namespace hk::test
