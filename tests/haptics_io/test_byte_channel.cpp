// ByteChannel: the bounded waits the USB transport's read/write are made of. Two-thread tests are
// written so the outcome is the same whichever thread runs first; timing is only checked as bounds.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

#include "haptics/io/byte_channel.hpp"

namespace hk::io {
namespace {

using Clock = std::chrono::steady_clock;

long elapsed_us(Clock::time_point t0) {
  return static_cast<long>(std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - t0).count());
}

TEST(ByteChannel, PopWaitTimesOutWithZero) {
  ByteChannel c(64);
  std::uint8_t buf[8];
  EXPECT_EQ(c.pop_wait(buf, 8, 0), 0);
  const auto t0 = Clock::now();
  EXPECT_EQ(c.pop_wait(buf, 8, 15000), 0);
  const long us = elapsed_us(t0);
  EXPECT_GE(us, 14000) << "returned before its timeout";
  EXPECT_LT(us, 1000000) << "blocked far past its 15 ms timeout";
}

TEST(ByteChannel, PushWaitTimesOutWhenFull) {
  ByteChannel c(16);
  std::uint8_t data[20] = {};
  EXPECT_EQ(c.push_wait(data, 20, 0), 16) << "what fits goes in";
  const auto t0 = Clock::now();
  EXPECT_EQ(c.push_wait(data, 4, 15000), 0);
  const long us = elapsed_us(t0);
  EXPECT_GE(us, 14000);
  EXPECT_LT(us, 1000000);
}

TEST(ByteChannel, WaitingReaderGetsBytesPushedByAnotherThread) {
  ByteChannel c(64);
  const std::uint8_t msg[3] = {7, 8, 9};
  std::thread producer([&] { c.push(msg, 3); });  // before or after the wait starts: same outcome
  std::uint8_t buf[8] = {};
  const auto t0 = Clock::now();
  const int n = c.pop_wait(buf, 8, 5000000);
  const long us = elapsed_us(t0);
  producer.join();
  ASSERT_GT(n, 0);
  EXPECT_EQ(buf[0], 7);
  EXPECT_LT(us, 4000000) << "woke by the timeout, not by the push";
}

TEST(ByteChannel, CloseWakesAWaitingReaderAfterItsBytes) {
  ByteChannel c(64);
  const std::uint8_t msg[2] = {1, 2};
  c.push(msg, 2);
  std::thread closer([&] { c.close(); });
  std::uint8_t buf[8];
  EXPECT_EQ(c.pop_wait(buf, 8, 5000000), 2) << "bytes received before the close come first";
  const auto t0 = Clock::now();
  EXPECT_EQ(c.pop_wait(buf, 8, 5000000), -1);
  EXPECT_LT(elapsed_us(t0), 4000000) << "close() did not wake the reader";
  closer.join();
  EXPECT_EQ(c.push_wait(msg, 2, 0), -1) << "a closed channel refuses writes";
}

TEST(ByteChannel, CloseWakesAWriterWaitingForRoom) {
  ByteChannel c(8);
  std::uint8_t data[8] = {};
  ASSERT_EQ(c.push_wait(data, 8, 0), 8);
  std::thread closer([&] { c.close(); });
  const auto t0 = Clock::now();
  EXPECT_EQ(c.push_wait(data, 1, 5000000), -1);
  EXPECT_LT(elapsed_us(t0), 4000000);
  closer.join();
}

TEST(ByteChannel, StreamThroughASmallChannelWithoutLostWakeups) {
  // 1 MiB through 64 bytes: both sides wait constantly. A lost wake-up would leave a call waiting its
  // whole 2 s timeout and return 0, which the asserts below catch.
  ByteChannel c(64);
  constexpr int kTotal = 1 << 20;
  std::atomic<int> zero_pushes{0};
  std::thread producer([&] {
    std::vector<std::uint8_t> chunk(1000);
    for (int sent = 0; sent < kTotal;) {
      const int n = std::min<int>(static_cast<int>(chunk.size()), kTotal - sent);
      for (int i = 0; i < n; ++i) chunk[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>((sent + i) % 251);
      int done = 0;
      while (done < n) {
        const int k = c.push_wait(chunk.data() + done, n - done, 2000000);
        if (k <= 0) {
          zero_pushes.fetch_add(1);
          return;
        }
        done += k;
      }
      sent += n;
    }
  });
  int got = 0, bad = 0, zero_pops = 0;
  std::uint8_t buf[37];
  while (got < kTotal && zero_pops == 0) {
    const int n = c.pop_wait(buf, sizeof buf, 2000000);
    if (n <= 0) {
      ++zero_pops;
      break;
    }
    for (int i = 0; i < n; ++i) bad += buf[i] != static_cast<std::uint8_t>((got + i) % 251);
    got += n;
  }
  c.close();  // frees the producer if the reader gave up
  producer.join();
  EXPECT_EQ(got, kTotal);
  EXPECT_EQ(bad, 0);
  EXPECT_EQ(zero_pops, 0);
  EXPECT_EQ(zero_pushes.load(), 0);
}

TEST(ByteChannel, ClearDropsPendingBytes) {
  ByteChannel c(16);
  const std::uint8_t msg[4] = {1, 2, 3, 4};
  c.push(msg, 4);
  c.clear();
  std::uint8_t buf[8];
  EXPECT_EQ(c.pop_wait(buf, 8, 0), 0);
  EXPECT_EQ(c.size(), 0u);
}

}  // namespace
}  // namespace hk::io
