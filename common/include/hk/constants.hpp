#pragma once
/// @file constants.hpp
/// The numbers the real-time structures are sized by, in one place (DESIGN.md "Real-time rules": hot data
/// in flat arrays, fixed stacks with a checked push). Each struct on the servo path asserts its own size
/// in bytes next to its definition (haptics/scene.hpp, haptics/collision_query.hpp, audio/cue_event.hpp).
#include <cstddef>
#include <cstdint>

namespace hk {

/// Levels a curve's multiresolution model can have, level 0 (the finest) included. The per-level arrays
/// of a curve (CurveInfo) and of the level policy have this many entries; [haptics] max_levels ≤ 12
/// stays below it.
inline constexpr int kMaxLevels = 16;

/// Tolerance steps: the level policy may pick a tolerance instead of a level. A level id
/// is either a level, 0 .. kMaxLevels − 1, the same for every curve (clamped to each curve's coarsest), or
/// a tolerance step, kToleranceLevelBase + t: each curve at the coarsest of its own levels whose error
/// bound is ≤ kToleranceLadder_m[t] (level 0 when none is), so a straight curve goes coarse while a
/// wiggly one stays fine (Scene::clamp_level resolves both kinds per curve); or a cut step,
/// kCutLevelBase + t: the tolerance cut at the same tolerance, chosen per segment (below).
inline constexpr int kToleranceSteps = 8;
/// The first tolerance-step id: above every level.
inline constexpr int kToleranceLevelBase = kMaxLevels;
/// The first cut-step id, above the tolerance steps. Cut step kCutLevelBase + t renders the tolerance cut at
/// kToleranceLadder_m[t] (haptics/tolerance_cut.hpp): on every curve, segments of mixed levels, each refined
/// while its error box's bound exceeds the tolerance, joined where the level changes; a per-segment choice
/// where a tolerance step is a per-curve one. BoundarySection and ContactSolver walk it; Scene::clamp_level
/// gives a cut step its tolerance step's per-curve level, which the cut refines.
inline constexpr int kCutLevelBase = kToleranceLevelBase + kToleranceSteps;
/// Level ids in all: the levels, the tolerance steps, then the cut steps. Per-id tables (the contact solver's
/// widths) have this many entries.
inline constexpr int kLevelIds = kMaxLevels + 2 * kToleranceSteps;
/// The tolerance of each step [m], increasing by ~1.6x (the R10 series): from the fingertip's 0.1 mm at
/// rest to 2.5 mm, the tolerable error of a hand at ~0.24 m/s (haptics/level_policy.hpp).
inline constexpr double kToleranceLadder_m[kToleranceSteps] = {1.0e-4, 1.6e-4, 2.5e-4, 4.0e-4,
                                                               6.3e-4, 1.0e-3, 1.6e-3, 2.5e-3};
/// True for a tolerance-step id.
constexpr bool is_tolerance_level(int id) { return id >= kToleranceLevelBase && id < kCutLevelBase; }
/// True for a cut-step id.
constexpr bool is_cut_level(int id) { return id >= kCutLevelBase && id < kLevelIds; }
/// The tolerance step of a tolerance-step or cut-step id (0 .. kToleranceSteps − 1); −1 for a level.
constexpr int tolerance_step_of(int id) {
  if (is_tolerance_level(id)) return id - kToleranceLevelBase;
  if (is_cut_level(id)) return id - kCutLevelBase;
  return -1;
}

/// Deepest hierarchy of nodes above the curves' chunks in a scene's collision tree (the tree over
/// chunks halves per level, so 64 covers any scene that fits in memory).
inline constexpr int kMaxHierarchyDepth = 64;

/// Entries of the depth-first stack of a collision-tree walk whose widest node has `widest_fanout`
/// children: a walk pushes at most every child of one node per level it descends, through at most
/// kMaxLevels curve levels and kMaxHierarchyDepth hierarchy levels, plus the entry it starts from.
/// BoundarySection sizes its stack with this at build; its push is checked against it all the same.
constexpr std::size_t tree_stack_entries(std::size_t widest_fanout) {
  return widest_fanout * static_cast<std::size_t>(kMaxLevels + kMaxHierarchyDepth) + 8;
}

/// Largest free-space ball of BoundarySection::first_hit_wide [m]: its clearance walk stops refining past
/// this distance, so the walk opens only the nodes within it. 1 mm is 2.5–50 servo ticks of a hand at
/// 0.02–0.4 m/s. A larger ball answers more ticks but every walk that measures it opens more nodes; of the
/// caps measured (0.5–6 mm, docs/PERFORMANCE.md "The wide index"), 1 mm gave the lowest p99 within a few
/// ns of the lowest mean.
inline constexpr double kWideBallCap_m = 1e-3;

}  // namespace hk
