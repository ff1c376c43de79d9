// WAV files through libsndfile (see wav.hpp).
#include "audio/wav.hpp"
#include "hk/text.hpp"

#include <sndfile.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <system_error>

namespace hk::audio {
namespace {

struct SndCloser {
  void operator()(SNDFILE* f) const { sf_close(f); }
};
using SndPtr = std::unique_ptr<SNDFILE, SndCloser>;

constexpr std::size_t kChunkFrames = 4096;                              // conversion buffer [frames]
constexpr std::int64_t kMaxWriteFrames = (std::int64_t{1} << 31) - 64;  // 16-bit mono RIFF size limit

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw WavError("wav '" + hk::one_line(path) + "': " + hk::one_line(problem));
}

std::int16_t to_pcm16(float x) {
  if (std::isnan(x)) return 0;
  const float s = std::nearbyint(std::clamp(x, -1.0f, 1.0f) * 32768.0f);
  return static_cast<std::int16_t>(std::clamp(s, -32768.0f, 32767.0f));
}

}  // namespace

void write_wav(const std::string& path, std::span<const float> mono, int sample_rate_hz) {
  if (sample_rate_hz < 8000 || sample_rate_hz > 192000) {
    fail(path, "sample rate " + std::to_string(sample_rate_hz) + " Hz is outside [8000, 192000] Hz");
  }
  if (static_cast<std::int64_t>(mono.size()) > kMaxWriteFrames) {
    fail(path, std::to_string(mono.size()) + " samples do not fit in a WAV file (limit " +
                   std::to_string(kMaxWriteFrames) + ")");
  }
  const std::string tmp = path + ".tmp";
  SF_INFO info{};
  info.samplerate = sample_rate_hz;
  info.channels = 1;
  info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
  SndPtr f(sf_open(tmp.c_str(), SFM_WRITE, &info));
  if (!f) fail(path, "cannot open '" + tmp + "' for writing (" + sf_strerror(nullptr) + ")");
  // From here on the temporary file is ours: remove it on any failure.
  auto abandon = [&](const std::string& problem) {
    f.reset();
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    fail(path, problem);
  };
  std::array<short, kChunkFrames> pcm;
  for (std::size_t done = 0; done < mono.size();) {
    const std::size_t n = std::min(kChunkFrames, mono.size() - done);
    for (std::size_t i = 0; i < n; ++i) pcm[i] = to_pcm16(mono[done + i]);
    if (sf_writef_short(f.get(), pcm.data(), static_cast<sf_count_t>(n)) != static_cast<sf_count_t>(n)) {
      abandon(std::string("write failed (") + sf_strerror(f.get()) + ")");
    }
    done += n;
  }
  sf_write_sync(f.get());
  const int closed = sf_close(f.release());
  if (closed != 0) abandon(std::string("write failed on close (") + sf_error_number(closed) + ")");
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) abandon("cannot rename '" + tmp + "' onto it (" + ec.message() + ")");
}

std::vector<float> read_wav(const std::string& path, int* sample_rate_hz) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(st)) fail(path, "no such file");
  if (!std::filesystem::is_regular_file(st)) fail(path, "not a regular file");
  if (std::filesystem::file_size(path, ec) == 0 && !ec) fail(path, "is empty (0 bytes)");
  SF_INFO info{};
  SndPtr f(sf_open(path.c_str(), SFM_READ, &info));
  if (!f) fail(path, std::string("not a sound file libsndfile can read (") + sf_strerror(nullptr) + ")");
  if (info.channels <= 0) fail(path, "has " + std::to_string(info.channels) + " channels");
  if (info.samplerate <= 0) fail(path, "has a sample rate of " + std::to_string(info.samplerate) + " Hz");
  if (info.frames <= 0) fail(path, "holds no samples");
  if (info.frames > kMaxWavFrames) {
    char len[64];
    std::snprintf(len, sizeof len, "%.1f min at %d Hz", static_cast<double>(info.frames) / info.samplerate / 60.0,
                  info.samplerate);
    fail(path, std::to_string(info.frames) + " frames (" + len + ") is over the limit of " +
                   std::to_string(kMaxWavFrames) + " frames (1 h at 48 kHz)");
  }
  const auto ch = static_cast<std::size_t>(info.channels);
  std::vector<float> mono;
  mono.reserve(static_cast<std::size_t>(info.frames));
  std::vector<float> chunk(kChunkFrames * ch);  // interleaved; at most 4096 · 1024 floats
  for (;;) {
    const sf_count_t got = sf_readf_float(f.get(), chunk.data(), static_cast<sf_count_t>(kChunkFrames));
    if (got <= 0) break;
    for (std::size_t i = 0; i < static_cast<std::size_t>(got); ++i) {
      float s = 0.0f;
      for (std::size_t c = 0; c < ch; ++c) s += chunk[i * ch + c];
      mono.push_back(s / static_cast<float>(ch));
    }
    if (static_cast<std::int64_t>(mono.size()) >= info.frames) break;
  }
  if (mono.empty()) fail(path, "holds no samples (the header promises " + std::to_string(info.frames) + " frames)");
  if (sample_rate_hz) *sample_rate_hz = info.samplerate;
  return mono;
}

}  // namespace hk::audio
