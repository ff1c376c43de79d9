#pragma once
/// @file speech_stream.hpp
/// The hand-over of synthesised speech from the speech worker (producer) to the mixer in the audio
/// callback (consumer), so speech is mixed with earcons in our own mixer and can be cut at once
/// (interrupted at once, repeated, and mixed with earcons).
///
/// Samples travel in fixed blocks through an SpscRing; every block carries the generation of the
/// utterance it belongs to. cancel() bumps the generation from any thread: the consumer then drops every
/// older block at its next read, so speech stops within one audio buffer (plus a short fade-out,
/// kFadeSamples, so the cut does not click). The producer sees the new generation and stops synthesising.

#include <atomic>
#include <cstddef>
#include <cstdint>

#include "audio/spsc_ring.hpp"

namespace hk::audio {

/// SPSC stream of speech samples (mono, float in [−1, 1], at the mixer's sample rate).
class SpeechStream {
 public:
  static constexpr std::size_t kBlockSamples = 256;  ///< samples per block (5.3 ms at 48 kHz)
  static constexpr std::size_t kFadeSamples = 96;    ///< fade-out on cancel (2 ms at 48 kHz)

  /// One block: 1 KiB of samples plus its tag.
  struct Block {
    std::uint32_t generation = 0;
    std::uint32_t count = 0;  ///< valid samples in `samples` [0, kBlockSamples]
    bool last = false;        ///< the utterance ends with this block
    float samples[kBlockSamples] = {};
  };

  /// @param capacity_blocks  blocks buffered ahead of the mixer; the default holds ~45 s at 48 kHz.
  explicit SpeechStream(std::size_t capacity_blocks = 8192) : ring_(capacity_blocks) {}

  // ---- any thread ---------------------------------------------------------------------------------
  /// Stops what is playing and what is queued; returns the new generation (for the next utterance).
  std::uint32_t cancel() noexcept { return generation_.fetch_add(1, std::memory_order_acq_rel) + 1; }
  /// The current generation: blocks with an older one are dropped.
  std::uint32_t generation() const noexcept { return generation_.load(std::memory_order_acquire); }
  /// True while the consumer is playing (or has queued) samples of the current generation; false while paused.
  bool speaking() const noexcept { return speaking_.load(std::memory_order_relaxed); }
  /// Holds the consumer where it is (true: a kFadeSamples fade-out, then silence, nothing dropped) or lets it
  /// go on from there (false). cancel() does not end a pause: the producer's next utterance does (Speaker).
  void set_paused(bool paused) noexcept { paused_.store(paused, std::memory_order_release); }
  /// Held by set_paused(true).
  bool paused() const noexcept { return paused_.load(std::memory_order_acquire); }

  // ---- producer (the speech worker) ---------------------------------------------------------------
  /// Appends samples of utterance `generation`. Returns false if that generation was cancelled (stop
  /// synthesising) or the ring stayed full (the caller may wait and retry the rest: `*written` says how
  /// many samples were taken). Never blocks.
  bool push(std::uint32_t generation, const float* samples, std::size_t count, std::size_t* written = nullptr) noexcept;
  /// Marks the end of utterance `generation` (flushes the partial block). Returns false if cancelled or full.
  bool finish(std::uint32_t generation) noexcept;

  // ---- consumer (the audio callback) --------------------------------------------------------------
  /// Writes up to `frames` samples of the current utterance into `out` (adds nothing past its end: the
  /// rest of `out` is zero). Returns the number of speech samples written. Wait-free, no allocation.
  std::size_t read(float* out, std::size_t frames) noexcept;

  /// How far the consumer has played into the utterance it plays or played last: that utterance's generation
  /// (its low kHeardGenerationBits bits) and the samples of it read so far, paused or not. Updated at the end of
  /// each read(); any thread. Speaker::piece_heard maps it to the piece being heard.
  struct Heard {
    std::uint32_t generation_low = 0;  ///< generation & kHeardGenerationMask
    std::uint64_t samples = 0;         ///< samples of it read [samples at the mixer's rate]
  };
  static constexpr unsigned kHeardGenerationBits = 24;
  static constexpr std::uint32_t kHeardGenerationMask = (1u << kHeardGenerationBits) - 1;
  Heard heard() const noexcept {
    const std::uint64_t v = heard_.load(std::memory_order_acquire);
    return {static_cast<std::uint32_t>(v >> (64 - kHeardGenerationBits)),
            v & ((std::uint64_t{1} << (64 - kHeardGenerationBits)) - 1)};
  }

  /// Blocks dropped because the ring was full (the producer retries; this counts the waits).
  std::uint64_t full_waits() const noexcept { return ring_.overflows(); }

 private:
  std::size_t read_paused(float* out, std::size_t frames) noexcept;  // the fade into a pause, then silence
  void publish_heard() noexcept;  // heard_ from playing_generation_ and heard_samples_

  SpscRing<Block> ring_;
  std::atomic<std::uint32_t> generation_{0};
  std::atomic<bool> speaking_{false};
  std::atomic<bool> paused_{false};
  std::atomic<std::uint64_t> heard_{0};  // Heard packed: generation_low in the top bits, samples below
  // producer state
  Block pending_{};
  // consumer state
  Block current_{};
  std::size_t offset_ = 0;
  bool have_current_ = false;
  float last_sample_ = 0.0f;
  std::size_t fade_left_ = 0;
  std::uint64_t heard_samples_ = 0;             // samples of playing_generation_ read
  std::size_t pause_fade_left_ = kFadeSamples;  // fade-out samples left on entering a pause
  std::uint32_t playing_generation_ = 0;
};

}  // namespace hk::audio
