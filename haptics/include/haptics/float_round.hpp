#pragma once
/// @file float_round.hpp
/// Doubles rounded to floats toward −∞ or +∞, for rectangles stored as floats that must still hold what the
/// exact (double) rectangle holds, and bounds that must not shrink in the rounding: the tightest such floats
/// for the wide index's node rectangles (wide_index.hpp, built once), cheaper ones a little wider for the
/// boundary section's entry rectangles and the scan's bounds (collision_query.hpp, every full query).
/// Branch-free: which side of x the nearest float lies on is a coin toss a branch would mispredict half the time.

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace hk {

/// The next float toward −∞ (`down`) or +∞ from f, by its bits (std::nextafter is a library call). f finite,
/// or +∞ going down (the largest float).
inline float next_float(float f, bool down) noexcept {
  if (f == 0.0f) return down ? -std::numeric_limits<float>::denorm_min() : std::numeric_limits<float>::denorm_min();
  const auto bits = std::bit_cast<std::uint32_t>(f);
  return std::bit_cast<float>(bits + 1u - 2u * static_cast<std::uint32_t>((f > 0.0f) == down));  // magnitude down or up
}

/// `if_true` when `pick`, else `otherwise`, by their bits (no branch).
inline float pick_float(bool pick, float if_true, float otherwise) noexcept {
  const auto a = std::bit_cast<std::uint32_t>(if_true), b = std::bit_cast<std::uint32_t>(otherwise);
  return std::bit_cast<float>(b ^ ((a ^ b) & (0u - static_cast<std::uint32_t>(pick))));
}

/// The largest float not above x (x finite; past the float range, −∞ or the largest float).
inline float float_at_most(double x) noexcept {
  const float f = static_cast<float>(x);
  return pick_float(static_cast<double>(f) > x, next_float(f, true), f);
}

/// The smallest float not below x (x finite; past the float range, +∞ or the lowest float).
inline float float_at_least(double x) noexcept {
  const float f = static_cast<float>(x);
  return pick_float(static_cast<double>(f) < x, next_float(f, false), f);
}

/// A float below x, cheaply: x lowered by 2^-20 of its magnitude and 2^-100, then rounded (the rounding moves it
/// by at most 2^-24 of it, so it stays below). For the servo path's rectangles and bounds, where one conversion
/// and no branch matter more than the tightest float. |x| < 1e38 (past it, ±∞ or not below x).
inline float float_below(double x) noexcept { return static_cast<float>(x - std::abs(x) * 0x1p-20 - 0x1p-100); }

/// A float above x, cheaply (as float_below, upward). |x| < 1e38.
inline float float_above(double x) noexcept { return static_cast<float>(x + std::abs(x) * 0x1p-20 + 0x1p-100); }

}  // namespace hk
