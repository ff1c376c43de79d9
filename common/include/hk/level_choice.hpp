#pragma once
/// @file level_choice.hpp
/// What the visitor and the operator choose the walls' detail by: a level of the curves' multiresolution
/// model, a tolerance step or a tolerance cut step (hk/constants.hpp). The servo path keeps the choice as its
/// level id, the index of its flat per-id tables (kLevelIds entries); everything that reasons about the
/// choice (Finer and Coarser, what is shown and said) takes a LevelChoice and converts at the boundary.

#include <optional>

#include "hk/constants.hpp"

namespace hk {

/// A level, a tolerance step or a cut step. A value type: compare, step, convert to and from a level id.
struct LevelChoice {
  enum class Kind : unsigned char {
    Level,      ///< level `index` of every curve (0 = the finest), clamped to each curve's coarsest
    Tolerance,  ///< each curve at the coarsest of its levels within kToleranceLadder_m[index]
    Cut,        ///< the tolerance cut at kToleranceLadder_m[index]: each stretch of a curve as coarse as it allows
  };
  Kind kind = Kind::Level;
  int index = 0;  ///< the level (0 .. kMaxLevels − 1) or the tolerance step (0 .. kToleranceSteps − 1)

  /// The choice a level id names (a level, kToleranceLevelBase + t or kCutLevelBase + t).
  static constexpr LevelChoice of_id(int id) {
    if (is_tolerance_level(id)) return {Kind::Tolerance, id - kToleranceLevelBase};
    if (is_cut_level(id)) return {Kind::Cut, id - kCutLevelBase};
    return {Kind::Level, id};
  }
  /// Its level id, the index the servo path's tables are read by.
  constexpr int id() const {
    return kind == Kind::Tolerance ? kToleranceLevelBase + index : kind == Kind::Cut ? kCutLevelBase + index : index;
  }
  /// `delta` steps coarser (> 0) or finer (< 0) of the same kind: levels within 0 .. `max_level`, steps within
  /// the ladder; nullopt past either end (the kind never changes, so Finer and Coarser keep their order).
  constexpr std::optional<LevelChoice> stepped(int delta, int max_level) const {
    const int next = index + delta;
    const int last = kind == Kind::Level ? max_level : kToleranceSteps - 1;
    if (next < 0 || next > last) return std::nullopt;
    return LevelChoice{kind, next};
  }
  friend constexpr bool operator==(const LevelChoice&, const LevelChoice&) = default;
};

}  // namespace hk
