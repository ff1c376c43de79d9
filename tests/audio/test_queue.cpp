// The cue queue between the 1 kHz servo thread and the audio callback: no blocking, overflow
// counted, not crashed.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "audio/cue_event.hpp"
#include "audio/spsc_ring.hpp"
#include "hk/error.hpp"

namespace hk::audio {
namespace {

using Clock = std::chrono::steady_clock;

TEST(CueQueue, CapacityIsRoundedToAPowerOfTwoAndBadSizesAreRefused) {
  EXPECT_EQ(SpscRing<int>(1).capacity(), 1u);
  EXPECT_EQ(SpscRing<int>(100).capacity(), 128u);
  EXPECT_THROW(SpscRing<int>(0), hk::ArgumentError);
  EXPECT_THROW(SpscRing<int>(std::size_t{1} << 25), hk::ArgumentError);
}

TEST(CueQueue, FullRingDropsAndCountsInsteadOfBlocking) {
  SpscRing<int> r(4);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(r.try_push(i));
  EXPECT_FALSE(r.try_push(99));
  EXPECT_FALSE(r.try_push(100));
  EXPECT_EQ(r.overflows(), 2u);
  int v = -1;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(r.try_pop(v));
    EXPECT_EQ(v, i);  // FIFO, the dropped ones are the newest
  }
  EXPECT_FALSE(r.try_pop(v));
}

// A producer on its own thread that never waits, into a small ring, and a consumer that starts only after
// the producer has pushed more than the ring holds and then takes at most 10 at a time: the producer is
// never held up by the consumer, every drop is counted (some drops are certain: 100 pushes met a ring of
// 64 before anything was taken), and what arrives is in order.
TEST(CueQueue, ProducerNeverWaitsAndEveryDropIsCounted) {
  SpscRing<CueEvent> ring(64);
  constexpr int kTicks = 500;
  constexpr int kHeadStart = 100;  // pushes before the consumer starts: > capacity
  std::atomic<int> pushed{0};
  std::atomic<long> accepted{0};
  std::thread producer([&] {
    for (int k = 0; k < kTicks; ++k) {
      CueEvent e;
      e.tick = k;
      e.kind = CueKind::Slide;
      accepted += ring.try_push(e) ? 1 : 0;
      pushed.store(k + 1, std::memory_order_release);
      if (k % 16 == 15) std::this_thread::yield();
    }
  });
  while (pushed.load(std::memory_order_acquire) < kHeadStart) std::this_thread::yield();
  std::vector<std::int64_t> got;
  CueEvent e;
  while (pushed.load(std::memory_order_acquire) < kTicks || ring.size() > 0) {
    for (int i = 0; i < 10 && ring.try_pop(e); ++i) got.push_back(e.tick);
    std::this_thread::yield();
  }
  producer.join();
  while (ring.try_pop(e)) got.push_back(e.tick);
  EXPECT_EQ(static_cast<long>(got.size()), accepted.load());
  EXPECT_EQ(static_cast<std::uint64_t>(kTicks - accepted), ring.overflows());
  EXPECT_GE(ring.overflows(), static_cast<std::uint64_t>(kHeadStart - 64))
      << "the ring was full before the consumer started";
  for (std::size_t i = 1; i < got.size(); ++i) ASSERT_LT(got[i - 1], got[i]);
}

// A consumer that never reads (a hung audio device): the producer still finishes every tick; pushes past
// the capacity are dropped and counted. If try_push blocked, this test would never end.
TEST(CueQueue, StalledConsumerNeverHoldsUpTheProducer) {
  SpscRing<CueEvent> ring(64);
  std::thread producer([&] {
    for (int k = 0; k < 1000; ++k) {
      CueEvent e;
      e.tick = k;
      ring.try_push(e);
    }
  });
  producer.join();
  EXPECT_EQ(ring.size(), 64u);
  EXPECT_EQ(ring.overflows(), 1000u - 64u);
  CueEvent e;
  ASSERT_TRUE(ring.try_pop(e));
  EXPECT_EQ(e.tick, 0);  // the oldest are kept: the cues already queued still play
}

// Two threads hammering the ring: every value arrives once, in order (run under ASan in CI).
TEST(CueQueue, StressKeepsOrderAndCount) {
  SpscRing<std::int64_t> ring(256);
  constexpr std::int64_t kN = 2'000'000;
  std::thread producer([&] {
    for (std::int64_t i = 0; i < kN;) {
      if (ring.try_push(i)) ++i;
    }
  });
  std::int64_t expect = 0;
  while (expect < kN) {
    std::int64_t v;
    if (ring.try_pop(v)) {
      ASSERT_EQ(v, expect);
      ++expect;
    }
  }
  producer.join();
  EXPECT_EQ(expect, kN);
}

}  // namespace
}  // namespace hk::audio
