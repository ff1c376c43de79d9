#pragma once
/// @file source.hpp
/// Something that produces audio in the real-time callback: the mixer for the kiosk, a test tone in
/// tests. The output backend (PortAudio) pulls from one AudioSource.

#include <cstddef>

namespace hk::audio {

/// Mixer sample rate used throughout the kiosk [Hz].
inline constexpr int kSampleRateHz = 48000;

/// A pull-model audio source.
class AudioSource {
 public:
  virtual ~AudioSource() = default;
  /// Fills `out[0 .. frames)` with mono samples in [−1, 1] at kSampleRateHz. Called from the audio
  /// callback: must not allocate, lock, block, throw or log.
  virtual void render(float* out, std::size_t frames) noexcept = 0;
};

}  // namespace hk::audio
