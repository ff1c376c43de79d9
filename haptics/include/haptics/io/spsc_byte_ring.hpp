#pragma once
/// @file spsc_byte_ring.hpp
/// A fixed-capacity lock-free byte ring between one producer thread and one consumer thread: the USB
/// transport's path between the caller and the libusb event thread (usb_transport.hpp).

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>

#include "haptics/device.hpp"

namespace hk::io {

/// Single-producer single-consumer byte ring. The storage is allocated once in the constructor; push,
/// pop, size and clear are wait-free (no allocation, no lock, no throw). Indices are free-running
/// std::size_t counters (release on publish, acquire on observe), so a full ring holds capacity() bytes.
class SpscByteRing {
 public:
  /// `capacity_bytes` must be a power of two in [2, 2^30]; else throws hk::DeviceError naming it.
  explicit SpscByteRing(std::size_t capacity_bytes) : capacity_(capacity_bytes), mask_(capacity_bytes - 1) {
    if (capacity_bytes < 2 || capacity_bytes > (std::size_t{1} << 30) || (capacity_bytes & mask_) != 0) {
      throw DeviceError("byte ring capacity " + std::to_string(capacity_bytes) +
                        " must be a power of two in [2, 2^30]");
    }
    data_ = std::make_unique<std::uint8_t[]>(capacity_bytes);
  }

  /// Producer: copies up to n bytes in; returns how many fit (0..n).
  std::size_t push(const std::uint8_t* src, std::size_t n) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    const std::size_t tail = tail_.load(std::memory_order_acquire);
    const std::size_t count = std::min(n, capacity_ - (head - tail));
    copy_in(head, src, count);
    head_.store(head + count, std::memory_order_release);
    return count;
  }
  /// Consumer: copies up to n bytes out; returns how many there were (0..n).
  std::size_t pop(std::uint8_t* dst, std::size_t n) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    const std::size_t head = head_.load(std::memory_order_acquire);
    const std::size_t count = std::min(n, head - tail);
    copy_out(tail, dst, count);
    tail_.store(tail + count, std::memory_order_release);
    return count;
  }
  /// Consumer: drops everything pushed so far.
  void clear() noexcept { tail_.store(head_.load(std::memory_order_acquire), std::memory_order_release); }
  /// Bytes held now (exact from either side's own view, a snapshot otherwise).
  std::size_t size() const noexcept {
    return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire);
  }
  /// Free room now [bytes].
  std::size_t room() const noexcept { return capacity_ - size(); }
  std::size_t capacity() const noexcept { return capacity_; }

 private:
  void copy_in(std::size_t at, const std::uint8_t* src, std::size_t n) noexcept {
    const std::size_t i = at & mask_, first = std::min(n, capacity_ - i);
    if (first) std::memcpy(data_.get() + i, src, first);
    if (n > first) std::memcpy(data_.get(), src + first, n - first);
  }
  void copy_out(std::size_t at, std::uint8_t* dst, std::size_t n) const noexcept {
    const std::size_t i = at & mask_, first = std::min(n, capacity_ - i);
    if (first) std::memcpy(dst, data_.get() + i, first);
    if (n > first) std::memcpy(dst + first, data_.get(), n - first);
  }

  std::size_t capacity_, mask_;
  std::unique_ptr<std::uint8_t[]> data_;
  alignas(64) std::atomic<std::size_t> head_{0};  // written by the producer
  alignas(64) std::atomic<std::size_t> tail_{0};  // written by the consumer
};

}  // namespace hk::io
