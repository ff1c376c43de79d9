#include "audio/speech_stream.hpp"

#include <algorithm>
#include <cstring>

namespace hk::audio {

bool SpeechStream::push(std::uint32_t generation, const float* samples, std::size_t count,
                        std::size_t* written) noexcept {
  std::size_t done = 0;
  bool ok = true;
  if (pending_.generation != generation) {  // a new utterance: forget a partial block of an old one
    pending_.generation = generation;
    pending_.count = 0;
    pending_.last = false;
  }
  while (done < count) {
    if (generation_.load(std::memory_order_acquire) != generation) {
      ok = false;
      break;
    }
    const std::size_t take = std::min(count - done, kBlockSamples - pending_.count);
    std::memcpy(pending_.samples + pending_.count, samples + done, take * sizeof(float));
    pending_.count += static_cast<std::uint32_t>(take);
    if (pending_.count == kBlockSamples) {
      if (!ring_.try_push(pending_)) {
        pending_.count -= static_cast<std::uint32_t>(take);  // not taken: the caller retries these
        ok = false;
        break;
      }
      pending_.count = 0;
    }
    done += take;
  }
  if (written) *written = done;
  return ok;
}

bool SpeechStream::finish(std::uint32_t generation) noexcept {
  if (generation_.load(std::memory_order_acquire) != generation) return false;
  if (pending_.generation != generation) {
    pending_.generation = generation;
    pending_.count = 0;
  }
  pending_.last = true;
  if (!ring_.try_push(pending_)) {
    pending_.last = false;
    return false;
  }
  pending_.count = 0;
  pending_.last = false;
  return true;
}

std::size_t SpeechStream::read_paused(float* out, std::size_t frames) noexcept {
  const std::uint32_t gen = generation_.load(std::memory_order_acquire);
  std::size_t n = 0;
  while (n < frames && pause_fade_left_ > 0 && have_current_ && current_.generation == gen &&
         offset_ < current_.count) {
    out[n++] = current_.samples[offset_++] * static_cast<float>(pause_fade_left_) / static_cast<float>(kFadeSamples);
    --pause_fade_left_;
  }
  heard_samples_ += n;
  publish_heard();
  pause_fade_left_ = 0;  // the fade is over (or there was nothing to fade)
  if (n < frames) std::memset(out + n, 0, (frames - n) * sizeof(float));
  speaking_.store(false, std::memory_order_relaxed);
  return n;
}

void SpeechStream::publish_heard() noexcept {
  constexpr unsigned shift = 64 - kHeardGenerationBits;
  const std::uint64_t samples = std::min<std::uint64_t>(heard_samples_, (std::uint64_t{1} << shift) - 1);
  heard_.store((std::uint64_t{playing_generation_ & kHeardGenerationMask} << shift) | samples,
               std::memory_order_release);
}

std::size_t SpeechStream::read(float* out, std::size_t frames) noexcept {
  if (paused_.load(std::memory_order_acquire)) return read_paused(out, frames);
  pause_fade_left_ = kFadeSamples;
  const std::uint32_t gen = generation_.load(std::memory_order_acquire);
  std::size_t n = 0;
  std::size_t spoken = 0;
  while (n < frames) {
    if (!have_current_ || offset_ >= current_.count) {
      if (have_current_ && current_.last) speaking_.store(false, std::memory_order_relaxed);
      have_current_ = ring_.try_pop(current_);
      offset_ = 0;
      if (!have_current_) break;
      if (current_.generation != gen) {  // cancelled before it played: drop silently
        have_current_ = false;
        continue;
      }
      if (playing_generation_ != gen) {
        fade_left_ = 0;
        heard_samples_ = 0;
      }
      playing_generation_ = gen;
      continue;
    }
    if (current_.generation != gen) {
      // Cancelled mid-block: play at most kFadeSamples more, ramped to zero, then drop the block.
      if (fade_left_ == 0) fade_left_ = kFadeSamples;
      while (n < frames && offset_ < current_.count && fade_left_ > 0) {
        out[n++] = current_.samples[offset_++] * static_cast<float>(fade_left_) / static_cast<float>(kFadeSamples);
        --fade_left_;
        ++spoken;
      }
      if (fade_left_ == 0 || offset_ >= current_.count) {
        have_current_ = false;
        fade_left_ = 0;
      }
      continue;
    }
    const std::size_t take = std::min(frames - n, current_.count - offset_);
    std::memcpy(out + n, current_.samples + offset_, take * sizeof(float));
    n += take;
    offset_ += take;
    spoken += take;
    heard_samples_ += take;
    speaking_.store(true, std::memory_order_relaxed);
  }
  publish_heard();
  if (n < frames) std::memset(out + n, 0, (frames - n) * sizeof(float));
  // Still speaking while a block of the current utterance plays or waits in the ring (the producer may be
  // behind the consumer for a moment without the utterance being over).
  const bool more = (have_current_ && current_.generation == gen && offset_ < current_.count) || ring_.size() > 0;
  speaking_.store(more || (spoken > 0 && !(have_current_ && current_.last)), std::memory_order_relaxed);
  return spoken;
}

}  // namespace hk::audio
