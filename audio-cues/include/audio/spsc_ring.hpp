#pragma once
/// @file spsc_ring.hpp
/// A bounded lock-free single-producer single-consumer ring (DESIGN.md "Real-time rules": threads meet
/// through SPSC rings). The producer (e.g. the servo thread) never blocks and never allocates: when the
/// ring is full, try_push() drops the item and counts it in overflows(). Storage is sized once at
/// construction (the only allocation).
///
/// Memory order: the producer publishes an item with a release store of its head index; the consumer
/// reads the head with acquire, so the item's bytes are visible before the index is (Lamport's ring,
/// as in Boost.Lockfree's spsc_queue). Head and tail live on separate cache lines so the two threads do
/// not false-share.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "hk/error.hpp"

namespace hk::audio {

/// Bounded SPSC ring of trivially copyable T. Capacity is rounded up to a power of two.
/// Thread use: exactly one thread calls try_push, exactly one (maybe another) calls try_pop / pop_all.
template <class T>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "SpscRing holds trivially copyable values");

 public:
  /// @param capacity  entries [1, 2^24]; rounded up to a power of two.
  /// @throws hk::ArgumentError outside that range (setup only).
  explicit SpscRing(std::size_t capacity) {
    if (capacity < 1 || capacity > (std::size_t{1} << 24)) {
      throw hk::ArgumentError("SpscRing capacity " + std::to_string(capacity) + " is outside [1, 16777216]");
    }
    std::size_t n = 1;
    while (n < capacity) n <<= 1;
    mask_ = n - 1;
    items_ = std::make_unique<T[]>(n);
  }

  /// Producer: appends `item`. Wait-free. Returns false (and counts an overflow) when full.
  bool try_push(const T& item) noexcept {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_cache_ > mask_) {
      tail_cache_ = tail_.load(std::memory_order_acquire);
      if (head - tail_cache_ > mask_) {
        overflows_.fetch_add(1, std::memory_order_relaxed);
        return false;
      }
    }
    items_[head & mask_] = item;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  /// Consumer: takes the oldest item into `out`. Wait-free. Returns false when empty.
  bool try_pop(T& out) noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_cache_) {
      head_cache_ = head_.load(std::memory_order_acquire);
      if (tail == head_cache_) return false;
    }
    out = items_[tail & mask_];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  /// Consumer: number of items it could pop now (a snapshot).
  std::size_t size() const noexcept {
    return static_cast<std::size_t>(head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire));
  }
  /// Entries the ring holds (a power of two).
  std::size_t capacity() const noexcept { return mask_ + 1; }
  /// Items dropped by try_push because the ring was full (any thread may read it).
  std::uint64_t overflows() const noexcept { return overflows_.load(std::memory_order_relaxed); }

 private:
  static constexpr std::size_t kLine = 64;  // cache line [bytes]
  std::unique_ptr<T[]> items_;
  std::size_t mask_ = 0;
  alignas(kLine) std::atomic<std::uint64_t> head_{0};  // written by the producer
  std::uint64_t tail_cache_ = 0;                       // producer's last view of tail_
  std::atomic<std::uint64_t> overflows_{0};
  alignas(kLine) std::atomic<std::uint64_t> tail_{0};  // written by the consumer
  std::uint64_t head_cache_ = 0;                       // consumer's last view of head_
};

}  // namespace hk::audio
