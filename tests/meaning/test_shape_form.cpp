/// @file test_shape_form.cpp
/// Forms guessed from outlines (meaning/shape_form.hpp): each form of the table from exact geometry, the
/// same rotated, scaled and jittered, and the shapes that must not be mistaken (an L is no star, an octagon
/// with a corner cut is no polygon of eight).

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "meaning/shape_form.hpp"

namespace hk::meaning {
namespace {

constexpr double kPi = std::numbers::pi;

/// A regular polygon of `corners` corners of circumradius r [m], each side sampled at 10 points, turned by
/// `turn_rad`.
std::vector<Vec2> regular(int corners, double r, double turn_rad = 0.0) {
  std::vector<Vec2> p;
  for (int i = 0; i < corners; ++i) {
    const double a0 = turn_rad + 2 * kPi * i / corners, a1 = turn_rad + 2 * kPi * (i + 1) / corners;
    const Vec2 c0{r * std::cos(a0), r * std::sin(a0)}, c1{r * std::cos(a1), r * std::sin(a1)};
    for (int k = 0; k < 10; ++k) p.push_back(c0 + (k / 10.0) * (c1 - c0));
  }
  return p;
}

std::vector<Vec2> ellipse(double rx, double ry, double turn_rad = 0.0, int n = 120) {
  std::vector<Vec2> p;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * kPi * i / n, x = rx * std::cos(a), y = ry * std::sin(a);
    p.push_back({x * std::cos(turn_rad) - y * std::sin(turn_rad), x * std::sin(turn_rad) + y * std::cos(turn_rad)});
  }
  return p;
}

std::vector<Vec2> rectangle(double w, double h, double turn_rad = 0.0) {
  const std::vector<Vec2> c{{-w / 2, -h / 2}, {w / 2, -h / 2}, {w / 2, h / 2}, {-w / 2, h / 2}};
  std::vector<Vec2> p;
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 10; ++k) {
      const Vec2 q = c[i] + (k / 10.0) * (c[(i + 1) % 4] - c[i]);
      p.push_back(
          {q.x * std::cos(turn_rad) - q.y * std::sin(turn_rad), q.x * std::sin(turn_rad) + q.y * std::cos(turn_rad)});
    }
  return p;
}

/// A five-pointed star: tips at radius r, notches at 0.4 r.
std::vector<Vec2> star(double r) {
  std::vector<Vec2> p;
  for (int i = 0; i < 10; ++i) {
    const double a = kPi / 2 + kPi * i / 5, rr = i % 2 == 0 ? r : 0.4 * r;
    const double b = kPi / 2 + kPi * (i + 1) / 5, rb = i % 2 == 0 ? 0.4 * r : r;
    const Vec2 c0{rr * std::cos(a), rr * std::sin(a)}, c1{rb * std::cos(b), rb * std::sin(b)};
    for (int k = 0; k < 8; ++k) p.push_back(c0 + (k / 8.0) * (c1 - c0));
  }
  return p;
}

/// Each point moved by up to `amount` [m] in x and y (uniform, fixed seed): edge pixels' jitter.
std::vector<Vec2> jittered(std::vector<Vec2> p, double amount, unsigned seed = 7u) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  for (Vec2& q : p) q = q + Vec2{u(rng), u(rng)};
  return p;
}

TEST(ShapeForm, EachClosedFormOfTheTable) {
  EXPECT_EQ(form_of(ellipse(0.01, 0.01), true).form, Form::round);
  EXPECT_EQ(form_of(ellipse(0.02, 0.01), true).form, Form::oval);
  EXPECT_EQ(form_of(rectangle(0.02, 0.02), true).form, Form::square);
  EXPECT_EQ(form_of(rectangle(0.03, 0.015), true).form, Form::rectangle);
  const FormGuess tri = form_of(regular(3, 0.01), true);
  EXPECT_EQ(tri.form, Form::triangle);
  EXPECT_EQ(tri.corners, 3);
  const FormGuess pent = form_of(regular(5, 0.01), true);
  EXPECT_EQ(pent.form, Form::polygon);
  EXPECT_EQ(pent.corners, 5);
  const FormGuess hex = form_of(regular(6, 0.01), true);
  EXPECT_EQ(hex.form, Form::polygon);
  EXPECT_EQ(hex.corners, 6);
  const FormGuess st = form_of(star(0.01), true);
  EXPECT_EQ(st.form, Form::star);
  EXPECT_EQ(st.corners, 10);
}

TEST(ShapeForm, TurnedScaledAndJitteredOutlinesKeepTheirForm) {
  for (const double turn : {0.1, 0.5, 1.0}) {
    for (const double size : {0.004, 0.03}) {
      EXPECT_EQ(form_of(jittered(ellipse(size, size, turn), 0.01 * size), true).form, Form::round) << size;
      EXPECT_EQ(form_of(jittered(ellipse(size, 0.5 * size, turn), 0.01 * size), true).form, Form::oval) << size;
      EXPECT_EQ(form_of(jittered(rectangle(size, size, turn), 0.01 * size), true).form, Form::square) << size;
      EXPECT_EQ(form_of(jittered(rectangle(size, 0.5 * size, turn), 0.01 * size), true).form, Form::rectangle) << size;
      EXPECT_EQ(form_of(jittered(regular(3, size, turn), 0.01 * size), true).form, Form::triangle) << size;
    }
  }
}

TEST(ShapeForm, ShapesThatAreNoneOfTheFormsAreIrregular) {
  // An L: six corners, one a notch; its hull is much larger, but it is no star.
  const std::vector<Vec2> ell{{-0.04, -0.03}, {0.04, -0.03}, {0.04, -0.01},
                              {-0.02, -0.01}, {-0.02, 0.03}, {-0.04, 0.03}};
  EXPECT_EQ(form_of(ell, true).form, Form::irregular);
  // A crescent: no corner that a window sees as one, far from round.
  std::vector<Vec2> moon;
  for (int i = 0; i <= 40; ++i)
    moon.push_back({0.02 * std::cos(kPi * i / 40 - kPi / 2), 0.02 * std::sin(kPi * i / 40 - kPi / 2)});
  for (int i = 39; i > 0; --i)
    moon.push_back({0.01 * std::cos(kPi * i / 40 - kPi / 2), 0.02 * std::sin(kPi * i / 40 - kPi / 2)});
  EXPECT_NE(form_of(moon, true).form, Form::round);
  EXPECT_NE(form_of(moon, true).form, Form::oval);
  // Too few points to be anything.
  EXPECT_EQ(form_of({{0, 0}, {0.01, 0}}, true).form, Form::irregular);
}

TEST(ShapeForm, LinesAreStraightBentOrCurved) {
  std::vector<Vec2> straight, arc, bracket{{0, 0}, {0.02, 0}, {0.02, 0.01}, {0, 0.01}};
  for (int i = 0; i <= 20; ++i) straight.push_back({0.001 * i, 0.0002 * i});
  for (int i = 0; i <= 20; ++i) arc.push_back({0.02 * std::cos(kPi * i / 20), 0.02 * std::sin(kPi * i / 20)});
  EXPECT_EQ(form_of(jittered(straight, 0.0001), false).form, Form::straight_line);
  const FormGuess a = form_of(arc, false);
  EXPECT_EQ(a.form, Form::curve);
  EXPECT_EQ(a.corners, 0);
  const FormGuess b = form_of(bracket, false);
  EXPECT_EQ(b.form, Form::curve);
  EXPECT_EQ(b.corners, 2);
  EXPECT_EQ(form_of({{0, 0}, {0.01, 0}}, false).form, Form::straight_line);
}

TEST(ShapeForm, KeysParseBack) {
  for (int f = 0; f <= static_cast<int>(Form::curve); ++f) {
    Form back;
    ASSERT_TRUE(form_from_key(form_key(static_cast<Form>(f)), &back));
    EXPECT_EQ(back, static_cast<Form>(f));
  }
  Form f;
  EXPECT_FALSE(form_from_key("blob", &f));
}

}  // namespace
}  // namespace hk::meaning
