#pragma once
/// @file byte_channel.hpp
/// An SpscByteRing plus two eventfds so either side can wait, bounded by a timeout, for the other: the
/// producer for room, the consumer for data. The USB transport uses one per direction between the caller
/// and the libusb event thread (usb_transport.hpp); the event thread polls data_fd() of the out channel.
///
/// What blocks: only push_wait/pop_wait, in ppoll(2) on one eventfd, never past their timeout. Signalling
/// is eventfd(2) write of 1 on a non-blocking eventfd: one syscall, no user-space lock, no allocation
/// (Linux eventfd(2); the kernel takes a spinlock for the counter).
/// Lost wake-ups cannot happen: a waiter drains its eventfd, re-checks the ring, then waits; a signal sent
/// after the drain leaves the eventfd readable.

#include <atomic>
#include <cstddef>
#include <cstdint>

#include "haptics/io/spsc_byte_ring.hpp"

namespace hk::io {

/// One producer thread, one consumer thread; close() from any thread.
class ByteChannel {
 public:
  /// `capacity_bytes`: a power of two (SpscByteRing). Throws hk::DeviceError when the capacity is bad or
  /// the eventfds cannot be created (naming errno). Setup-time: allocates.
  explicit ByteChannel(std::size_t capacity_bytes);
  ~ByteChannel();
  ByteChannel(const ByteChannel&) = delete;
  ByteChannel& operator=(const ByteChannel&) = delete;

  /// Producer: copies in what fits now (0..n) and signals data_fd() when anything went in. Real-time.
  std::size_t push(const std::uint8_t* src, std::size_t n) noexcept;
  /// Producer: pushes up to n bytes, waiting at most timeout_us [µs] in total for room. Returns the bytes
  /// pushed, or -1 when the channel is closed and nothing was pushed. Real-time (bounded wait).
  int push_wait(const std::uint8_t* src, int n, int timeout_us) noexcept;
  /// Consumer: copies out what is there (0..n) and signals space when anything came out. Real-time.
  std::size_t pop(std::uint8_t* dst, std::size_t n) noexcept;
  /// Consumer: pops up to n bytes, waiting at most timeout_us [µs] for the first one (0 = no wait).
  /// Returns the bytes popped; when the channel is closed, bytes still in it first, then -1. Real-time.
  int pop_wait(std::uint8_t* dst, int n, int timeout_us) noexcept;
  /// Consumer: drops what is in the ring. Real-time.
  void clear() noexcept;
  /// Marks the channel closed (the device is gone) and wakes both sides. Any thread, idempotent.
  void close() noexcept;
  bool closed() const noexcept { return closed_.load(std::memory_order_acquire); }
  /// Bytes in the ring now.
  std::size_t size() const noexcept { return ring_.size(); }
  /// Readable when data was pushed since the consumer last drained it; for the consumer's own poll().
  int data_fd() const noexcept { return data_fd_; }
  /// Consumer: resets data_fd() (call before re-checking the ring, then poll).
  void drain_data_signal() noexcept;

 private:
  SpscByteRing ring_;
  int data_fd_ = -1, space_fd_ = -1;
  std::atomic<bool> closed_{false};
};

}  // namespace hk::io
