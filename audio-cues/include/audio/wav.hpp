#pragma once
/// @file wav.hpp
/// WAV files through libsndfile: the headless `explore --audio-out` rendering and the tests that
/// analyse it (issue 4, item 5).

#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace hk::audio {

/// A WAV file that cannot be written or read. what() is one line naming the file and the problem.
class WavError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Longest file read_wav() accepts [s]: one hour (a day-long file would be gigabytes of floats).
inline constexpr double kMaxWavSeconds = 3600.0;

/// Writes `mono` (samples in [−1, 1]; clipped) as a 16-bit PCM mono WAV at `sample_rate_hz`.
/// Written to `path` + ".tmp" and renamed, so a failed write never leaves a broken file and never
/// destroys one already at `path`.
/// @throws WavError if the sample rate is outside [8000, 192000] Hz or the file cannot be written.
void write_wav(const std::string& path, std::span<const float> mono, int sample_rate_hz);

/// Reads any sound file libsndfile knows (WAV, FLAC, …), mixing channels down to mono floats.
/// `*sample_rate_hz` (if not null) receives its rate [Hz].
/// @throws WavError if the file is missing, not a sound file, empty, or longer than kMaxWavSeconds.
std::vector<float> read_wav(const std::string& path, int* sample_rate_hz);

}  // namespace hk::audio
