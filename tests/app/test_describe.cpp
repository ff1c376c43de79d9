/// @file test_describe.cpp
/// Describe and Where in words (visit/describe.hpp): shapes said by what they look like (size, colour, form),
/// alike shapes said together, specks never counted, "smaller ones" only when they are, and Where telling
/// on, inside and off a shape with the way and distance to the nearest. Expected sentences are written from
/// the drawn geometry by hand (sizes against the 0.14 m x 0.09 m workspace's diagonal of 166 mm: large
/// above 67 mm, medium above 25 mm).

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "test_polylines.hpp"
#include "visit/describe.hpp"

namespace hk::app {
namespace {

const Vec2 kHalf{0.07, 0.045};

using test::rect;

Polyline circle(Vec2 c, double r, int n = 48) {
  Polyline p;
  p.closed = true;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * std::numbers::pi * i / n;
    p.points_m.push_back({c.x + r * std::cos(a), c.y + r * std::sin(a)});
  }
  return p;
}

TEST(Describe, SizesFormsAndPlaces) {
  // A 100 x 60 mm rectangle in the middle (large), an open 12 x 6 mm bracket at the far left (two corners:
  // a bent line), an 8 mm square at the near right.
  const std::vector<Polyline> curves{rect({0.06, -0.035}, {0.004, 0.004}), rect({0, 0}, {0.05, 0.03}),
                                     rect({-0.05, 0.03}, {0.006, 0.003}, false)};
  EXPECT_EQ(describe_scene(curves, {}, kHalf),
            "3 shapes. A large rectangle in the middle, a small bent line at the far left, and a small square at the "
            "near right.");
  EXPECT_EQ(describe_scene({curves[1]}, {}, kHalf), "One shape. A large rectangle in the middle.");
  EXPECT_EQ(describe_scene({}, {}, kHalf), "There are no shapes in this picture.");
}

TEST(Describe, AlikeShapesAreSaidTogetherAndTheRestCountedTruly) {
  // Six 4 mm squares at the far right and a 30 x 20 mm rectangle on the left: one group of six, never
  // "a small square" six times.
  std::vector<Polyline> many;
  for (int i = 0; i < 6; ++i) many.push_back(rect({0.04 + 0.004 * i, 0.03}, {0.0015, 0.0015}));
  many.push_back(rect({-0.04, 0}, {0.015, 0.01}));
  EXPECT_EQ(describe_scene(many, {}, kHalf, 2),
            "7 shapes. A medium rectangle on the left, and 6 small squares at the far right.");
  EXPECT_EQ(describe_scene(many, {}, kHalf, 1), "7 shapes. A medium rectangle on the left, and 6 more, smaller ones.");
  // The rest is not "smaller" when a shape left unnamed is larger than the last one named (nearest the
  // hand first).
  const std::vector<Polyline> two{rect({0.05, 0.03}, {0.003, 0.003}), rect({-0.03, 0}, {0.03, 0.02})};
  EXPECT_EQ(describe_scene(two, {}, kHalf, 1, Vec2{0.05, 0.03}),
            "2 shapes. Nearest your hand, a small square at the far right, and one more.");
}

TEST(Describe, ShapesInsideAClosedShapeAreToldWithItAsGroups) {
  // A plate at the far left with three holes of three kinds, and a bracket at the near right.
  const Polyline plate = rect({-0.035, 0.02}, {0.03, 0.02});
  const std::vector<Polyline> holes{rect({-0.05, 0.025}, {0.004, 0.004}), rect({-0.035, 0.015}, {0.005, 0.003}),
                                    rect({-0.02, 0.03}, {0.003, 0.003}, false)};
  const std::vector<Polyline> scene{holes[0], plate, holes[1], rect({0.05, -0.035}, {0.003, 0.002}, false), holes[2]};
  EXPECT_EQ(
      describe_scene(scene, {}, kHalf),
      "5 shapes. A large rectangle with 3 smaller shapes inside it, at the far left, and a small bent line at the "
      "near right.");
  EXPECT_EQ(describe_scene(scene, {}, kHalf, 1),
            "5 shapes. A large rectangle with 3 smaller shapes inside it, at the far left, and one more, smaller.");
  // A board with 26 round spots of one size: one group inside it.
  std::vector<Polyline> spots{rect({0, 0}, {0.05, 0.03})};
  for (int i = 0; i < 26; ++i) spots.push_back(circle({-0.04 + 0.003 * i, 0.0}, 0.001));
  EXPECT_EQ(describe_scene(spots, {}, kHalf),
            "27 shapes. A large rectangle with 26 small round shapes inside it, in the middle.");
  // Nesting at any depth, two kinds said by name: a face, an eye in it, a pupil in the eye.
  const std::vector<Polyline> face{rect({0, 0}, {0.04, 0.03}), rect({-0.015, 0.01}, {0.008, 0.005}),
                                   rect({-0.015, 0.01}, {0.002, 0.002})};
  EXPECT_EQ(describe_scene(face, {}, kHalf),
            "3 shapes. A large rectangle with a small rectangle and a small square inside it, in the middle.");
  // In an L's bounding box but in its notch, and across its edge: not inside. The L has no form to name.
  Polyline ell;
  ell.closed = true;
  ell.points_m = {{-0.04, -0.03}, {0.04, -0.03}, {0.04, -0.01}, {-0.02, -0.01}, {-0.02, 0.03}, {-0.04, 0.03}};
  EXPECT_EQ(describe_scene({ell, rect({0.03, 0.02}, {0.005, 0.005}), rect({-0.04, 0.0}, {0.006, 0.004})}, {}, kHalf),
            "3 shapes. A large shape in the middle, a small rectangle on the left, and a small square at the far "
            "right.");
}

TEST(Describe, SpecksAreNotShapes) {
  // A 2 mm square (8 mm round: longer than the tour's 6 mm) is a shape; a 1 mm one (4 mm round) is a speck.
  const std::vector<Polyline> curves{rect({0, 0}, {0.02, 0.015}), rect({0.05, 0.03}, {0.0005, 0.0005}),
                                     rect({-0.05, 0.03}, {0.001, 0.001})};
  const std::vector<meaning::ShapeDescriptor> ds = meaning::describe_shapes(curves, meaning::PictureColours{});
  ASSERT_EQ(ds.size(), 3u);
  EXPECT_FALSE(ds[0].speck);
  EXPECT_TRUE(ds[1].speck);
  EXPECT_FALSE(ds[2].speck);
  EXPECT_EQ(describe_scene(curves, ds, kHalf),
            "2 shapes. A medium rectangle in the middle, and a small square at the far left.");
  EXPECT_EQ(shape_number(ds, 3, 2), std::make_pair(2, 2));
  EXPECT_EQ(shape_number(ds, 3, 1).first, 0);
  EXPECT_EQ(shape_number({}, 3, 2), std::make_pair(3, 3)) << "no descriptors: every curve is a shape";
  // The hand on the speck hears the nearest shape instead.
  const ShapeAtHand at = shape_at_hand(curves, ds, {0.05, 0.03}, 1);
  EXPECT_NE(at.curve, 1);
}

TEST(Describe, ColoursAndFormsFromDescriptorsAreSaid) {
  const std::vector<Polyline> curves{circle({-0.03, 0}, 0.008), rect({0.03, 0}, {0.008, 0.008})};
  std::vector<meaning::ShapeDescriptor> ds = meaning::describe_shapes(curves, meaning::PictureColours{});
  ds[0].has_colour = true;
  ds[0].colour = {meaning::BasicColour::red, meaning::Shade::plain};
  ds[1].has_colour = true;
  ds[1].colour = {meaning::BasicColour::blue, meaning::Shade::light};
  EXPECT_EQ(describe_scene(curves, ds, kHalf),
            "2 shapes. A small red round shape on the left, and a small light blue square on the right.");
  EXPECT_EQ(describe_one_shape(curves, ds, 1, kHalf), "a small light blue square on the right");
  ds[1].has_colour = false;
  EXPECT_EQ(describe_one_shape(curves, ds, 1, kHalf, false), "a small square");
}

TEST(Where, OnInsideAndOffAShapeWithTheWayToIt) {
  // A 60 x 40 mm rectangle centred at (-0.02, 0).
  const std::vector<Polyline> curves{rect({-0.02, 0}, {0.03, 0.02})};
  const ShapeAtHand on = shape_at_hand(curves, {}, {0.01, 0.0}, -1);  // on its right edge
  EXPECT_TRUE(on.on);
  const ShapeAtHand in = shape_at_hand(curves, {}, {-0.02, 0.0}, -1);  // its centre
  EXPECT_FALSE(in.on);
  EXPECT_TRUE(in.inside);
  EXPECT_NEAR(in.distance_m, 0.02, 1e-12);                             // the far and near edges, 20 mm away
  const ShapeAtHand off = shape_at_hand(curves, {}, {0.04, 0.0}, -1);  // 30 mm right of its right edge
  EXPECT_FALSE(off.on);
  EXPECT_FALSE(off.inside);
  EXPECT_EQ(off.curve, 0);
  EXPECT_EQ(direction_words({0.04, 0.0}, off.nearest_m), "3 cm to your left");
  EXPECT_EQ(direction_words({0.0, 0.0}, {0.0, 0.025}), "3 cm farther away");  // 2.5 cm rounds to 3
  EXPECT_EQ(direction_words({0.0, 0.0}, {-0.02, -0.02}), "3 cm nearer to you, to your left");
  EXPECT_EQ(direction_words({0.0, 0.0}, {0.004, 0.0}), "less than a centimetre to your right");
}

}  // namespace
}  // namespace hk::app
