// WAV files: round trip within 16-bit quantisation, stereo mixed down, and bad files refused in one line
// without harm to anything already on disk.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

#include "audio/wav.hpp"

namespace fs = std::filesystem;

namespace hk::audio {
namespace {

fs::path tmp(const std::string& name) {
  return fs::temp_directory_path() / ("hk_wav_" + std::to_string(::getpid()) + "_" + name);
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// A canonical 44-byte PCM16 WAV header, written by hand (independently of libsndfile).
void put_header(std::ofstream& f, int channels, int rate, std::uint32_t data_bytes) {
  auto u32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) f.put(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  auto u16 = [&](std::uint16_t v) {
    for (int i = 0; i < 2; ++i) f.put(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  f.write("RIFF", 4);
  u32(36 + data_bytes);
  f.write("WAVEfmt ", 8);
  u32(16);
  u16(1);  // PCM
  u16(static_cast<std::uint16_t>(channels));
  u32(static_cast<std::uint32_t>(rate));
  u32(static_cast<std::uint32_t>(rate * channels * 2));
  u16(static_cast<std::uint16_t>(channels * 2));
  u16(16);
  f.write("data", 4);
  u32(data_bytes);
}

void write_pcm16(const fs::path& p, int channels, int rate, const std::vector<std::int16_t>& interleaved) {
  std::ofstream f(p, std::ios::binary);
  put_header(f, channels, rate, static_cast<std::uint32_t>(interleaved.size() * 2));
  for (std::int16_t s : interleaved) {
    const auto u = static_cast<std::uint16_t>(s);
    f.put(static_cast<char>(u & 0xFF));
    f.put(static_cast<char>(u >> 8));
  }
}

// Calls read_wav and returns the WavError message ("" and a failure if it did not throw).
std::string read_error(const fs::path& p) {
  try {
    read_wav(p.string(), nullptr);
  } catch (const WavError& e) {
    return e.what();
  }
  ADD_FAILURE() << "read_wav(" << p << ") did not throw";
  return "";
}

constexpr double kQuantum = 1.0 / 32768 + 1e-6;

TEST(Wav, RoundTripSineAndSilenceWithin16BitQuantisation) {
  for (int rate : {48000, 22050}) {
    SCOPED_TRACE(rate);
    // 50 ms of a 440 Hz sine at 0.9, then 50 ms of silence.
    const std::size_t half = static_cast<std::size_t>(rate / 20);
    std::vector<float> x(2 * half, 0.0f);
    for (std::size_t i = 0; i < half; ++i)
      x[i] = 0.9f * static_cast<float>(std::sin(2 * std::numbers::pi * 440.0 * static_cast<double>(i) / rate));
    const fs::path p = tmp("rt.wav");
    write_wav(p.string(), x, rate);
    EXPECT_FALSE(fs::exists(p.string() + ".tmp"));
    int got_rate = 0;
    const std::vector<float> y = read_wav(p.string(), &got_rate);
    EXPECT_EQ(got_rate, rate);
    ASSERT_EQ(y.size(), x.size());
    double worst = 0;
    for (std::size_t i = 0; i < x.size(); ++i) worst = std::max(worst, std::abs(static_cast<double>(y[i]) - x[i]));
    EXPECT_LE(worst, kQuantum);
    EXPECT_GT(worst, 0.0) << "16-bit, so not bit-exact floats";
    for (std::size_t i = half; i < y.size(); ++i) ASSERT_EQ(y[i], 0.0f) << "silence stays exactly silent at " << i;
    fs::remove(p);
  }
}

TEST(Wav, ClipsOutOfRangeAndWritesNaNAsZero) {
  const std::vector<float> x = {1.5f,
                                -3.0f,
                                1.0f,
                                -1.0f,
                                std::numeric_limits<float>::quiet_NaN(),
                                std::numeric_limits<float>::infinity(),
                                -std::numeric_limits<float>::infinity(),
                                0.25f};
  const fs::path p = tmp("clip.wav");
  write_wav(p.string(), x, 48000);
  const std::vector<float> y = read_wav(p.string(), nullptr);
  ASSERT_EQ(y.size(), x.size());
  const std::vector<float> want = {1.0f, -1.0f, 1.0f, -1.0f, 0.0f, 1.0f, -1.0f, 0.25f};
  for (std::size_t i = 0; i < y.size(); ++i) EXPECT_NEAR(y[i], want[i], kQuantum) << i;
  EXPECT_EQ(y[3], -1.0f) << "-1 is exact in 16-bit PCM";
  EXPECT_EQ(y[4], 0.0f);
  fs::remove(p);
}

TEST(Wav, StereoFileIsMixedDownToMono) {
  // Left and right differ; the mono result is their mean. Written by hand, so this also checks that
  // read_wav takes WAV files from elsewhere.
  const fs::path p = tmp("stereo.wav");
  std::vector<std::int16_t> lr;
  for (int i = 0; i < 1000; ++i) {
    lr.push_back(static_cast<std::int16_t>(i * 16));
    lr.push_back(static_cast<std::int16_t>(-i * 8));
  }
  write_pcm16(p, 2, 44100, lr);
  int rate = 0;
  const std::vector<float> y = read_wav(p.string(), &rate);
  EXPECT_EQ(rate, 44100);
  ASSERT_EQ(y.size(), 1000u);
  for (int i = 0; i < 1000; ++i)
    ASSERT_NEAR(y[static_cast<std::size_t>(i)], (i * 16 - i * 8) / 2.0 / 32768.0, 1e-6) << i;
  fs::remove(p);
}

TEST(Wav, WriteIntoMissingFolderNamesThePath) {
  const fs::path p = tmp("no_such_dir") / "a.wav";
  try {
    write_wav(p.string(), std::vector<float>(100, 0.1f), 48000);
    ADD_FAILURE() << "no error";
  } catch (const WavError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(p.string()), std::string::npos) << what;
    EXPECT_NE(what.find("for writing"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_FALSE(fs::exists(p.parent_path()));
}

TEST(Wav, FailedWriteLeavesTheExistingFileUntouched) {
  const fs::path keep = tmp("keep.wav");
  write_wav(keep.string(), std::vector<float>(100, 0.1f), 48000);
  const std::string before = slurp(keep);
  // Make the temporary path impossible: a folder stands there.
  const fs::path blocker = keep.string() + ".tmp";
  fs::create_directory(blocker);
  EXPECT_THROW(write_wav(keep.string(), std::vector<float>(10000, 0.5f), 48000), WavError);
  EXPECT_EQ(slurp(keep), before) << "the old file must survive a failed write";
  EXPECT_TRUE(fs::is_directory(blocker)) << "only our own temporary file may be removed";
  // A bad sample rate is refused before anything is touched.
  EXPECT_THROW(write_wav(keep.string(), std::vector<float>(10, 0.5f), 100), WavError);
  EXPECT_THROW(write_wav(keep.string(), std::vector<float>(10, 0.5f), 400000), WavError);
  EXPECT_EQ(slurp(keep), before);
  fs::remove(blocker);
  fs::remove(keep);
}

TEST(Wav, BadFilesAreRefusedInOneLineNamingTheFile) {
  const fs::path text = tmp("text.wav"), empty = tmp("empty.wav"), header = tmp("header.wav"), dir = tmp("dir.wav");
  std::ofstream(text) << "this is not a sound file\nat all\n";
  std::ofstream(empty).close();
  {
    // A WAV whose 44-byte header promises 2000 bytes of samples that are not there.
    std::ofstream f(header, std::ios::binary);
    put_header(f, 1, 48000, 2000);
  }
  ASSERT_EQ(fs::file_size(header), 44u);
  fs::create_directory(dir);
  for (const fs::path& p : {text, empty, header, dir, tmp("missing.wav")}) {
    SCOPED_TRACE(p);
    const std::string what = read_error(p);
    EXPECT_EQ(what.rfind("wav '" + p.string() + "': ", 0), 0u) << what;
    EXPECT_GT(what.size(), p.string().size() + 10) << "says what is wrong: " << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  // A control character in the name is shown, not printed raw.
  const std::string odd = read_error(tmp("line\nbreak.wav"));
  EXPECT_EQ(odd.find('\n'), std::string::npos) << odd;
  EXPECT_NE(odd.find("line\\x0Abreak.wav"), std::string::npos) << odd;
  fs::remove(text);
  fs::remove(empty);
  fs::remove(header);
  fs::remove(dir);
}

TEST(Wav, FileCutShortReturnsTheSamplesThatAreThere) {
  const fs::path p = tmp("cut.wav");
  std::vector<float> x(1000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = static_cast<float>(i) / 2000.0f;
  write_wav(p.string(), x, 48000);
  fs::resize_file(p, 44 + 2 * 600);  // 600 of the 1000 samples survive
  const std::vector<float> y = read_wav(p.string(), nullptr);
  ASSERT_EQ(y.size(), 600u);
  for (std::size_t i = 0; i < y.size(); ++i) ASSERT_NEAR(y[i], x[i], kQuantum) << i;
  fs::remove(p);
}

TEST(Wav, TooLongFileIsRefusedWithTheLimit) {
  // One frame over the limit, as a sparse file: the header is real, the samples are a hole on disk.
  const fs::path p = tmp("long.wav");
  const std::uint64_t frames = static_cast<std::uint64_t>(kMaxWavFrames) + 1;
  {
    std::ofstream f(p, std::ios::binary);
    put_header(f, 1, 48000, static_cast<std::uint32_t>(frames * 2));
  }
  fs::resize_file(p, 44 + frames * 2);
  const std::string what = read_error(p);
  EXPECT_NE(what.find(p.string()), std::string::npos) << what;
  EXPECT_NE(what.find(std::to_string(kMaxWavFrames)), std::string::npos) << "says the limit: " << what;
  EXPECT_NE(what.find("1 h at 48 kHz"), std::string::npos) << what;
  fs::remove(p);
}

}  // namespace
}  // namespace hk::audio
