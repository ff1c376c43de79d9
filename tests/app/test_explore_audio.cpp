// explore --audio-out on real pictures: the WAV is on trace.csv's timeline and every contact onset in the
// trace is heard within 10 ms after it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "audio/source.hpp"
#include "audio/wav.hpp"
#include "audio_analysis.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

namespace {

const fs::path kData = HK_TEST_DATA_DIR;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hk_test_audio_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

int run(const std::string& args, const fs::path& err) {
  const std::string cmd = std::string(HK_KIOSK_EXE) + " " + args + " >/dev/null 2>'" + err.string() + "'";
  const int raw = std::system(cmd.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

// Times [s] at which trace.csv's contact column goes from 0 (free) to 1 or 2.
std::vector<double> contact_onsets(const fs::path& trace, long* rows) {
  std::ifstream tf(trace);
  std::string line;
  std::getline(tf, line);
  std::vector<double> out;
  int prev = 0;
  *rows = 0;
  while (std::getline(tf, line)) {
    double t, v[6];
    int contact = 0;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%d", &t, &v[0], &v[1], &v[2], &v[3], &v[4], &v[5],
                    &contact) != 8)
      continue;
    if (prev == 0 && contact != 0) out.push_back(t);
    prev = contact;
    ++*rows;
  }
  return out;
}

class ExploreAudio : public ::testing::TestWithParam<std::string> {};

TEST_P(ExploreAudio, EveryContactOnsetIsHeardWithin10ms) {
  const std::string image = GetParam();
  const fs::path out = fresh_dir(fs::path(image).stem().string());
  const fs::path wav = out / "run.wav";
  ASSERT_EQ(run("explore '" + (kData / "images" / image).string() + "' --out '" + out.string() +
                    "' --duration 20 --audio-out '" + wav.string() + "'",
                out / "err.txt"),
            0)
      << slurp(out / "err.txt");
  int rate = 0;
  const std::vector<float> x = hk::audio::read_wav(wav.string(), &rate);
  ASSERT_EQ(rate, hk::audio::kSampleRateHz);
  long rows = 0;
  const std::vector<double> touches = contact_onsets(out / "trace.csv", &rows);
  // Same timeline: one tick of trace.csv is 1 ms of audio.
  EXPECT_EQ(static_cast<long>(x.size()), rows * hk::audio::kSampleRateHz / 1000);
  ASSERT_GE(touches.size(), 5u) << "the raster must touch the picture's shapes several times";
  const std::vector<std::size_t> on = hk::test::onsets(x, 1e-3);
  for (double t : touches) {
    const bool heard = std::any_of(on.begin(), on.end(), [&](std::size_t o) {
      return static_cast<double>(o) >= t * rate && static_cast<double>(o) <= (t + 0.010) * rate;
    });
    EXPECT_TRUE(heard) << "contact at t = " << t << " s has no earcon onset within 10 ms after it";
  }
  // And the WAV is not onsets everywhere: every 10 ms window that starts 200 ms or more after the last cue
  // of cues.csv, with no cue inside it, holds no onset at all (silence where there are no events).
  std::vector<double> cue_t;
  {
    std::ifstream cf(out / "cues.csv");
    std::string line;
    std::getline(cf, line);
    while (std::getline(cf, line)) {
      long long tick;
      double t;
      if (std::sscanf(line.c_str(), "%lld,%lf", &tick, &t) == 2) cue_t.push_back(t);
    }
  }
  ASSERT_FALSE(cue_t.empty());
  int quiet_windows = 0;
  for (double t = 0.2; t + 0.01 < static_cast<double>(x.size()) / rate; t += 0.01) {
    const auto it = std::upper_bound(cue_t.begin(), cue_t.end(), t + 0.01);
    if (it != cue_t.begin() && *(it - 1) > t - 0.2) continue;
    ++quiet_windows;
    const bool any = std::any_of(on.begin(), on.end(), [&](std::size_t o) {
      return static_cast<double>(o) >= t * rate && static_cast<double>(o) <= (t + 0.010) * rate;
    });
    EXPECT_FALSE(any) << "an onset at " << t << " s with no cue in the 200 ms before";
  }
  EXPECT_GT(quiet_windows, 50) << "the run must also have stretches without cues";
  // cues.csv lists the cues the WAV was rendered from, ContactBegin among them.
  EXPECT_NE(slurp(out / "cues.csv").find(",contact_begin,"), std::string::npos);
  fs::remove_all(out);
}

INSTANTIATE_TEST_SUITE_P(Pictures, ExploreAudio, ::testing::Values("horse.png", "silhouette_3.png", "coins.png"),
                         [](const auto& info) { return fs::path(info.param).stem().string(); });

TEST(ExploreAudioBadInput, RefusedInOneLineBeforeTheRun) {
  const fs::path out = fresh_dir("bad");
  const std::string img = (kData / "images" / "horse.png").string();
  struct Case {
    std::string audio_out, must_contain;
  };
  for (const Case& c : {Case{(out / "run.mp3").string(), "must name a .wav file"},
                        Case{(out / "no_such_folder" / "run.wav").string(), "does not exist"}}) {
    ASSERT_EQ(run("explore '" + img + "' --out '" + out.string() + "' --duration 1 --audio-out '" + c.audio_out + "'",
                  out / "err.txt"),
              1);
    const std::string err = slurp(out / "err.txt");
    EXPECT_NE(err.find(c.must_contain), std::string::npos) << err;
    EXPECT_NE(err.find("--audio-out"), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
  fs::remove_all(out);
}

TEST(Speak, RendersMessagesAndTextToWav) {
  const fs::path out = fresh_dir("speak");
  ASSERT_EQ(run("speak picture_loaded --wav '" + (out / "a.wav").string() + "'", out / "err.txt"), 0)
      << slurp(out / "err.txt");
  ASSERT_EQ(run("speak welcome --language de --wav '" + (out / "b.wav").string() + "'", out / "err.txt"), 0)
      << slurp(out / "err.txt");
  int rate = 0;
  const std::vector<float> a = hk::audio::read_wav((out / "a.wav").string(), &rate);
  const std::vector<float> b = hk::audio::read_wav((out / "b.wav").string(), &rate);
  EXPECT_GT(hk::test::rms(a, 0, a.size()), 0.01);
  EXPECT_GT(b.size(), 2 * a.size())
      << "the German welcome is a much longer text than 'Picture 2 of 5. It has 7 shapes.'";
  // A language with no catalogue, and a tag that is not BCP 47: one line naming it, and no WAV written.
  for (const std::string& bad : {std::string("it"), std::string("EN_us")}) {
    ASSERT_EQ(run("speak help --language " + bad + " --wav '" + (out / "c.wav").string() + "'", out / "err.txt"), 1);
    const std::string err = slurp(out / "err.txt");
    EXPECT_NE(err.find("catalogue '" + bad + "'"), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_FALSE(fs::exists(out / "c.wav"));
  }
  fs::remove_all(out);
}

}  // namespace
