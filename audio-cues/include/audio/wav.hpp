#pragma once
/// @file wav.hpp
/// WAV files through libsndfile: the headless `explore --audio-out` rendering and the tests that
/// analyse it. Plain functions for set-up and offline threads: they allocate and do
/// file I/O, so never call them from the audio callback or the servo thread. Any thread may call them
/// concurrently on different paths.

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>
#include "hk/error.hpp"

namespace hk::audio {

/// A WAV file that cannot be written or read. what() is one line (control characters in the path are
/// shown as \xNN) naming the file and the problem, e.g. "wav '/tmp/a.wav': not a sound file (...)".
class WavError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// Longest file read_wav() accepts [frames]: one hour at 48 kHz (172 800 000 frames, 691 MB of
/// floats). Longer files are refused before any sample is read.
inline constexpr std::int64_t kMaxWavFrames = std::int64_t{3600} * 48000;

/// Writes `mono` as a 16-bit PCM mono WAV at `sample_rate_hz` [Hz, 8000 .. 192000]. Samples are in
/// [−1, 1]: larger values are clipped to ±1, NaN is written as 0; a sample x is stored as
/// round(x · 32768) clamped to [−32768, 32767], so read_wav() returns it within 1/32768.
/// The file is written to `path` + ".tmp", flushed to disk and renamed onto `path`, so a failed write
/// never leaves a broken file at `path` and never destroys one already there. An empty `mono` gives a
/// valid WAV with no samples (which read_wav() refuses as empty).
/// @throws WavError if the sample rate is outside [8000, 192000] Hz, `mono` is too long for a WAV file
///         (over 2^31 − 64 samples), or the file cannot be opened for writing, written or renamed.
void write_wav(const std::string& path, std::span<const float> mono, int sample_rate_hz);

/// Reads any sound file libsndfile knows (WAV, FLAC, Ogg, AIFF, …), mono or stereo (any channel count:
/// the channels are averaged to mono), as floats in [−1, 1]. `*sample_rate_hz` (if not null) receives
/// its rate [Hz]. A file cut short after its header returns the samples that are there.
/// @throws WavError if the file is missing or not a regular file, is not a sound file libsndfile can
///         read, holds no samples (0 bytes, header only), or has more than kMaxWavFrames frames.
std::vector<float> read_wav(const std::string& path, int* sample_rate_hz);

}  // namespace hk::audio
