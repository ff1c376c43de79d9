// Seeded random visits (tests/support/random_visit.hpp): every key, bursts of keys, stray keys and chords,
// learning mode, sticks of damaged files put in and taken out, the operator's settings applied, a wandering
// hand; every key answered, nothing failed, and after Finish the kiosk as a new visitor finds it. Short runs
// here (20 000 frames: 5.5 minutes of kiosk time, a few seconds of the machine's); bench/random_visits.cpp runs
// long ones.
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <string>

#include "random_visit.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

namespace hk::test {
namespace {

const fs::path kData = HK_TEST_DATA_DIR;

/// A random visit of 20 000 frames with seed `seed`. The faults found
/// fail the test; the report is returned for what the run must have held.
RandomVisitReport visit(std::uint32_t seed) {
  const fs::path work =
      fs::temp_directory_path() / ("hk_random_visit_" + std::to_string(::getpid()) + "_" + std::to_string(seed));
  fs::remove_all(work);
  fs::create_directories(work / "library");
  for (const char* name : {"horse.png", "coins.png", "silhouette_2.png"})
    fs::copy_file(kData / "images" / name, work / "library" / name);
  RandomVisitParams p;
  p.seed = seed;
  p.frames = 20000;
  p.library = work / "library";
  p.data = kData;
  p.work = work;
  const RandomVisitReport r = run_random_visit(p);
  for (const std::string& u : r.unanswered) ADD_FAILURE() << u;
  for (const std::string& l : r.left_behind) ADD_FAILURE() << "after Finish: " << l;
  EXPECT_EQ(r.failures, 0) << "actions answered with the sorry line (the log says which)";
  fs::remove_all(work);
  return r;
}

class RandomVisits : public ::testing::TestWithParam<std::uint32_t> {};

TEST_P(RandomVisits, EveryKeyIsAnsweredAndTheKioskEndsAsANewVisitorFindsIt) {
  const RandomVisitReport r = visit(GetParam());
  // The run was what it claims: hundreds of keys, bursts, sticks, the panel.
  EXPECT_GT(r.keys, 400);
  EXPECT_GT(r.bursts, 10);
  EXPECT_GE(r.sticks_in, 2);
  EXPECT_GT(r.panel_applies, 1);
}

INSTANTIATE_TEST_SUITE_P(Seeds, RandomVisits, ::testing::Values(1u, 2u, 3u));

}  // namespace
}  // namespace hk::test
