// The cue queue between the 1 kHz servo thread and the audio callback (issue 4: "no blocking, overflow
// counted, not crashed").
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "audio/cue_event.hpp"
#include "audio/spsc_ring.hpp"

namespace hk::audio {
namespace {

using Clock = std::chrono::steady_clock;

TEST(CueQueue, CapacityIsRoundedToAPowerOfTwoAndBadSizesAreRefused) {
  EXPECT_EQ(SpscRing<int>(1).capacity(), 1u);
  EXPECT_EQ(SpscRing<int>(100).capacity(), 128u);
  EXPECT_THROW(SpscRing<int>(0), std::invalid_argument);
  EXPECT_THROW(SpscRing<int>(std::size_t{1} << 25), std::invalid_argument);
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

// A producer at 1 kHz for 0.5 s into a small ring, a consumer that wakes every 40 ms and takes only 10:
// the producer is never held up by the consumer, every drop is counted, and what arrives is in order.
TEST(CueQueue, ServoRateProducerAndSlowConsumer) {
  SpscRing<CueEvent> ring(64);
  constexpr int kTicks = 500;
  std::atomic<bool> done{false};
  std::atomic<long> accepted{0};
  std::thread producer([&] {
    auto next = Clock::now();
    for (int k = 0; k < kTicks; ++k) {
      CueEvent e;
      e.tick = k;
      e.kind = CueKind::Slide;
      accepted += ring.try_push(e) ? 1 : 0;
      next += std::chrono::milliseconds(1);
      std::this_thread::sleep_until(next);
    }
    done = true;
  });
  std::vector<std::int64_t> got;
  while (!done || ring.size() > 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
    CueEvent e;
    for (int i = 0; i < 10 && ring.try_pop(e); ++i) got.push_back(e.tick);
    if (done) {
      while (ring.try_pop(e)) got.push_back(e.tick);
    }
  }
  producer.join();
  EXPECT_EQ(static_cast<long>(got.size()), accepted.load());
  EXPECT_EQ(static_cast<std::uint64_t>(kTicks - accepted), ring.overflows());
  EXPECT_GT(ring.overflows(), 0u) << "the consumer was slow on purpose: some cues must have been dropped";
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
