// The SPSC byte ring between the caller and the libusb event thread: order, wrap-around, full and empty
// behaviour, and a two-thread stream that checks every byte arrives once and in order.
#include <gtest/gtest.h>

#include <numeric>
#include <thread>
#include <vector>

#include "haptics/io/spsc_byte_ring.hpp"

namespace hk::io {
namespace {

TEST(SpscByteRing, CapacityMustBeAPowerOfTwo) {
  EXPECT_THROW(SpscByteRing(0), DeviceError);
  EXPECT_THROW(SpscByteRing(1), DeviceError);
  try {
    SpscByteRing r(1000);
    FAIL();
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("1000"), std::string::npos);
  }
  EXPECT_EQ(SpscByteRing(1024).capacity(), 1024u);
}

TEST(SpscByteRing, FillsToCapacityThenRefuses) {
  SpscByteRing r(8);
  std::uint8_t in[12];
  std::iota(in, in + 12, 1);
  EXPECT_EQ(r.push(in, 5), 5u);
  EXPECT_EQ(r.push(in + 5, 7), 3u) << "only 3 bytes of room left";
  EXPECT_EQ(r.room(), 0u);
  EXPECT_EQ(r.push(in, 1), 0u);
  std::uint8_t out[12] = {};
  EXPECT_EQ(r.pop(out, 12), 8u);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(out[i], i + 1);
  EXPECT_EQ(r.pop(out, 12), 0u);
}

TEST(SpscByteRing, WrapsAroundKeepingOrder) {
  SpscByteRing r(8);
  std::uint8_t next_in = 0, next_out = 0;
  for (int round = 0; round < 100; ++round) {  // sizes 1..7 so the indices cross the end at every offset
    const std::size_t n = 1 + static_cast<std::size_t>(round % 7);
    std::uint8_t buf[8];
    for (std::size_t i = 0; i < n; ++i) buf[i] = next_in++;
    ASSERT_EQ(r.push(buf, n), n);
    std::uint8_t out[8];
    ASSERT_EQ(r.pop(out, 8), n);
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(out[i], next_out++);
  }
}

TEST(SpscByteRing, ClearDropsWhatWasPushed) {
  SpscByteRing r(16);
  const std::uint8_t a[3] = {1, 2, 3};
  r.push(a, 3);
  r.clear();
  EXPECT_EQ(r.size(), 0u);
  std::uint8_t out[4];
  EXPECT_EQ(r.pop(out, 4), 0u);
  const std::uint8_t b[1] = {9};
  r.push(b, 1);
  ASSERT_EQ(r.pop(out, 4), 1u);
  EXPECT_EQ(out[0], 9);
}

TEST(SpscByteRing, TwoThreadsStreamEveryByteOnceInOrder) {
  SpscByteRing r(256);
  constexpr std::size_t kTotal = 4 << 20;
  std::thread producer([&] {
    std::size_t sent = 0;
    std::uint8_t buf[97];
    while (sent < kTotal) {
      const std::size_t n = std::min<std::size_t>(sizeof buf, kTotal - sent);
      for (std::size_t i = 0; i < n; ++i) buf[i] = static_cast<std::uint8_t>((sent + i) * 31 + 7);
      std::size_t done = 0;
      while (done < n) done += r.push(buf + done, n - done);
      sent += n;
    }
  });
  std::size_t got = 0, mismatches = 0;
  std::uint8_t buf[61];
  while (got < kTotal) {
    const std::size_t n = r.pop(buf, sizeof buf);
    for (std::size_t i = 0; i < n; ++i) mismatches += buf[i] != static_cast<std::uint8_t>((got + i) * 31 + 7);
    got += n;
  }
  producer.join();
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(r.size(), 0u);
}

}  // namespace
}  // namespace hk::io
