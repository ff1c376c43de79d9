#pragma once
/// @file triple_buffer.hpp
/// A latest-value slot between one writer and one reader (DESIGN.md "Real-time rules": threads meet
/// through SPSC rings and a latest-value slot). The servo thread writes its state every tick; the display
/// reads the newest one at 60 Hz. Neither waits: three slots, the writer fills its back slot and swaps it
/// with the middle one; the reader swaps the middle one with its front slot when the writer marked it new.
/// Slot indices and the "new" bit live in one atomic byte, so every swap is one atomic exchange.

#include <atomic>
#include <cstdint>
#include <type_traits>

namespace hk {

/// Triple buffer of trivially copyable T. One writer thread, one reader thread.
template <class T>
class TripleBuffer {
  static_assert(std::is_trivially_copyable_v<T>, "TripleBuffer holds plain values");

 public:
  /// Writer: the slot to fill (only the writer touches it until publish()).
  T& back() noexcept { return slots_[back_]; }
  /// Writer: makes back() the newest value. Wait-free.
  void publish() noexcept {
    const std::uint8_t old = middle_.exchange(static_cast<std::uint8_t>(back_ | kNew), std::memory_order_acq_rel);
    back_ = old & kIndex;
  }
  /// Reader: the newest published value (or the last one read if nothing new came). Wait-free.
  const T& read() noexcept {
    if (middle_.load(std::memory_order_relaxed) & kNew) {
      const std::uint8_t old = middle_.exchange(front_, std::memory_order_acq_rel);
      front_ = old & kIndex;
    }
    return slots_[front_];
  }

 private:
  static constexpr std::uint8_t kIndex = 0x3, kNew = 0x4;
  T slots_[3]{};
  std::uint8_t back_ = 0;                // writer's
  std::atomic<std::uint8_t> middle_{1};  // shared: index | kNew
  std::uint8_t front_ = 2;               // reader's
};

}  // namespace hk
