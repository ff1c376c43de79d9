// LevelChoice: every level id names one choice and back, and Finer / Coarser step within a kind and stop at
// its ends: a level never becomes a tolerance step, nor a tolerance step a cut step.
#include <gtest/gtest.h>

#include "hk/level_choice.hpp"

namespace hk {
namespace {

TEST(LevelChoice, EveryLevelIdIsOneChoiceAndBack) {
  for (int id = 0; id < kLevelIds; ++id) {
    const LevelChoice c = LevelChoice::of_id(id);
    EXPECT_EQ(c.id(), id);
    const LevelChoice::Kind want = id < kToleranceLevelBase ? LevelChoice::Kind::Level
                                   : id < kCutLevelBase     ? LevelChoice::Kind::Tolerance
                                                            : LevelChoice::Kind::Cut;
    EXPECT_EQ(c.kind, want) << id;
  }
  EXPECT_EQ(LevelChoice::of_id(kToleranceLevelBase + 3), (LevelChoice{LevelChoice::Kind::Tolerance, 3}));
  EXPECT_EQ(LevelChoice::of_id(kCutLevelBase), (LevelChoice{LevelChoice::Kind::Cut, 0}));
}

TEST(LevelChoice, StepsStayWithinTheirKindAndStopAtItsEnds) {
  const LevelChoice level{LevelChoice::Kind::Level, 4};
  EXPECT_EQ(level.stepped(+1, 5), (LevelChoice{LevelChoice::Kind::Level, 5}));
  EXPECT_FALSE(level.stepped(+2, 5)) << "past max_levels";
  EXPECT_FALSE((LevelChoice{LevelChoice::Kind::Level, 0}).stepped(-1, 5)) << "below the finest level";
  const LevelChoice last_tolerance{LevelChoice::Kind::Tolerance, kToleranceSteps - 1};
  EXPECT_FALSE(last_tolerance.stepped(+1, 5)) << "a tolerance step never becomes a cut step";
  EXPECT_EQ(last_tolerance.stepped(-1, 5), (LevelChoice{LevelChoice::Kind::Tolerance, kToleranceSteps - 2}));
  EXPECT_FALSE((LevelChoice{LevelChoice::Kind::Cut, 0}).stepped(-1, 5)) << "a cut step never becomes a tolerance step";
  EXPECT_EQ((LevelChoice{LevelChoice::Kind::Cut, 2}).stepped(+1, 5)->id(), kCutLevelBase + 3);
}

}  // namespace
}  // namespace hk
