#include "audio/wav.hpp"

#include <sndfile.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>

namespace hk::audio {
namespace {

struct SndCloser {
  void operator()(SNDFILE* f) const { sf_close(f); }
};
using SndPtr = std::unique_ptr<SNDFILE, SndCloser>;

}  // namespace

void write_wav(const std::string& path, std::span<const float> mono, int sample_rate_hz) {
  if (sample_rate_hz < 8000 || sample_rate_hz > 192000) {
    throw WavError("wav '" + path + "': sample rate " + std::to_string(sample_rate_hz) + " Hz is outside [8000, 192000] Hz");
  }
  const std::string tmp = path + ".tmp";
  SF_INFO info{};
  info.samplerate = sample_rate_hz;
  info.channels = 1;
  info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
  {
    SndPtr f(sf_open(tmp.c_str(), SFM_WRITE, &info));
    if (!f) throw WavError("wav '" + path + "': cannot write (" + sf_strerror(nullptr) + ")");
    // libsndfile scales floats by 32767 and, with clipping on, saturates instead of wrapping.
    sf_command(f.get(), SFC_SET_CLIPPING, nullptr, SF_TRUE);
    const sf_count_t n = static_cast<sf_count_t>(mono.size());
    if (sf_writef_float(f.get(), mono.data(), n) != n) {
      const std::string why = sf_strerror(f.get());
      f.reset();
      std::remove(tmp.c_str());
      throw WavError("wav '" + path + "': write failed (" + why + ")");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw WavError("wav '" + path + "': cannot replace the file (" + ec.message() + ")");
  }
}

std::vector<float> read_wav(const std::string& path, int* sample_rate_hz) {
  SF_INFO info{};
  SndPtr f(sf_open(path.c_str(), SFM_READ, &info));
  if (!f) throw WavError("wav '" + path + "': not a readable sound file (" + sf_strerror(nullptr) + ")");
  if (info.frames <= 0 || info.channels <= 0) throw WavError("wav '" + path + "': holds no audio");
  if (static_cast<double>(info.frames) > kMaxWavSeconds * info.samplerate) {
    throw WavError("wav '" + path + "': " + std::to_string(info.frames / info.samplerate) + " s is over the limit of 3600 s");
  }
  std::vector<float> inter(static_cast<std::size_t>(info.frames) * static_cast<std::size_t>(info.channels));
  const sf_count_t got = sf_readf_float(f.get(), inter.data(), info.frames);
  if (got <= 0) throw WavError("wav '" + path + "': holds no audio");
  std::vector<float> mono(static_cast<std::size_t>(got));
  for (std::size_t i = 0; i < mono.size(); ++i) {
    float s = 0;
    for (int c = 0; c < info.channels; ++c) s += inter[i * static_cast<std::size_t>(info.channels) + static_cast<std::size_t>(c)];
    mono[i] = s / static_cast<float>(info.channels);
  }
  if (sample_rate_hz) *sample_rate_hz = info.samplerate;
  return mono;
}

}  // namespace hk::audio
