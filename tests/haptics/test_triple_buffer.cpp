// The latest-value slot between the servo thread and the display: never torn, never older than what was
// read before, the newest value once the writer stops.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "haptics/triple_buffer.hpp"

namespace hk {
namespace {

struct Pair {
  long a = 0;
  long b = 0;  // always == a when written; a torn read would show a != b
  long pad[14] = {};
};

TEST(TripleBuffer, SingleThreadSeesTheNewestValue) {
  TripleBuffer<Pair> t;
  EXPECT_EQ(t.read().a, 0);
  t.back().a = 1;
  t.publish();
  t.back().a = 2;
  t.publish();
  EXPECT_EQ(t.read().a, 2);
  EXPECT_EQ(t.read().a, 2) << "reading again without a new value keeps the last one";
  t.back().a = 3;
  t.publish();
  EXPECT_EQ(t.read().a, 3);
}

TEST(TripleBuffer, ConcurrentReadsAreNeverTornAndNeverGoBack) {
  TripleBuffer<Pair> t;
  constexpr long kN = 2'000'000;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (long i = 1; i <= kN; ++i) {
      Pair& p = t.back();
      p.a = i;
      for (long& x : p.pad) x = i;
      p.b = i;
      t.publish();
    }
    done = true;
  });
  long last = 0, reads = 0;
  while (!done || last < kN) {
    const Pair& p = t.read();
    ASSERT_EQ(p.a, p.b) << "torn read";
    ASSERT_EQ(p.pad[7], p.a) << "torn read";
    ASSERT_GE(p.a, last) << "went back in time";
    last = p.a;
    ++reads;
  }
  writer.join();
  EXPECT_EQ(t.read().a, kN);
  EXPECT_GT(reads, 0);
}

}  // namespace
}  // namespace hk
