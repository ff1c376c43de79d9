// Repeat and Pause on the kiosk's own runtime: the flow drives KioskRuntime, whose AudioSystem (espeak-ng
// speech in its mixer, pulled here as a sound device pulls it) keeps what Repeat says again and whether the
// speech is heard or held. What is checked is what a visitor hears: the line said, and sound or silence.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "runtime_ticks.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"
#include "wait_until.hpp"

namespace fs = std::filesystem;

namespace hk::app {
namespace {

using audio::MessageId;

/// A kiosk without its window: the horse in its library, the flow on its runtime, the mix pulled by the test.
struct SpeakingKiosk {
  fs::path lib = fs::temp_directory_path() / ("hk_repeat_pause_" + std::to_string(::getpid()));
  std::unique_ptr<KioskRuntime> rt;
  std::unique_ptr<KioskFlow> flow;
  double now_s = 1.0;

  SpeakingKiosk() {
    fs::remove_all(lib);
    fs::create_directories(lib);
    fs::copy_file(fs::path(HK_TEST_DATA_DIR) / "images" / "horse.png", lib / "horse.png");
    config::Settings s;
    s.vision.ocr = "off";
    rt = std::make_unique<KioskRuntime>(test::headless_runtime_options(lib), s);
    flow = std::make_unique<KioskFlow>(rt->effects(), rt->audio().messages(), KioskFlowParams{});
  }
  ~SpeakingKiosk() {
    flow.reset();
    rt.reset();
    fs::remove_all(lib);
  }
  /// Pulls `seconds` of the mix in 10 ms buffers, as the sound device would; returns its RMS.
  double listen(double seconds) {
    std::vector<float> buffer(audio::kSampleRateHz / 100);
    double sum = 0.0;
    std::size_t n = 0;
    for (int i = 0; i < static_cast<int>(seconds * 100.0 + 0.5); ++i) {
      rt->audio().render(buffer.data(), buffer.size());
      for (const float x : buffer) sum += static_cast<double>(x) * x;
      n += buffer.size();
      now_s += 0.01;
    }
    return n ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
  }
  /// Pulls the mix until speech is heard in it: a 100 ms buffer with an RMS over 1e-3. The speech worker
  /// synthesises ahead of the mixer; on a loaded machine the first buffers may come before it (silence).
  bool hears_speech() {
    double rms = 0.0;
    return test::wait_until([&] { return rms > 1e-3; }, [&] { rms = listen(0.1); });
  }
  /// Pulls the mix until nothing is being said.
  bool listen_to_the_end() {
    return test::wait_until([&] { return !rt->voice().speaking(); }, [&] { listen(0.1); });
  }
  void key(KioskKey k) {
    flow->key(k, now_s);
    now_s += 0.1;
  }
  /// Wakes the kiosk and walks through the practice shapes to the library's picture, each line heard out.
  void walk_to_the_picture() {
    flow->handle_moved(now_s);
    ASSERT_TRUE(listen_to_the_end());
    for (int i = 0; i < 8 && flow->view().state != KioskState::Picture; ++i) {
      key(KioskKey::Next);
      ASSERT_TRUE(rt->library().finish(flow.get(), now_s));
      ASSERT_TRUE(listen_to_the_end());
    }
    ASSERT_EQ(flow->view().state, KioskState::Picture);
  }
};

TEST(RuntimeRepeat, SaysTheDescriptionAgainAndPassesOverTheAcknowledgementAfterIt) {
  SpeakingKiosk k;
  k.walk_to_the_picture();
  k.key(KioskKey::Describe);
  const std::string description = k.rt->voice().last_said();
  ASSERT_FALSE(description.empty());
  EXPECT_TRUE(k.hears_speech()) << "the description is heard";
  ASSERT_TRUE(k.listen_to_the_end());
  const std::uint64_t kept = k.rt->voice().kept_texts();
  k.key(KioskKey::Finer);  // "More detail." (or that it is the finest): an acknowledgement
  EXPECT_NE(k.rt->voice().last_said(), description);
  EXPECT_EQ(k.rt->voice().kept_texts(), kept) << "an acknowledgement is not kept for Repeat";
  ASSERT_TRUE(k.listen_to_the_end());

  k.key(KioskKey::Repeat);
  EXPECT_EQ(k.rt->voice().last_said(), description) << "Repeat says the description again, not the acknowledgement";
  EXPECT_EQ(k.rt->voice().kept_texts(), kept + 1);
  EXPECT_TRUE(k.rt->voice().speaking());
  EXPECT_TRUE(k.hears_speech()) << "and it is heard";
}

TEST(RuntimeRepeat, BeforeAnythingWasSaidInThisVisitSaysSo) {
  SpeakingKiosk k;
  k.flow->handle_moved(k.now_s);          // the welcome...
  k.rt->effects().session.new_session();  // ...forgotten, as at a new visitor: nothing of the last one is repeated
  k.key(KioskKey::Repeat);
  EXPECT_EQ(k.rt->voice().last_said(), k.flow->text(MessageId::nothing_to_repeat));
}

TEST(RuntimePause, HoldsTheSpeechInSilenceAndPauseAgainGoesOn) {
  SpeakingKiosk k;
  k.walk_to_the_picture();
  k.key(KioskKey::Describe);
  const std::string description = k.rt->voice().last_said();
  ASSERT_TRUE(k.hears_speech()) << "the description is heard";
  ASSERT_TRUE(k.rt->voice().speaking());
  const std::uint64_t said = k.rt->voice().texts_said();

  k.key(KioskKey::Pause);
  EXPECT_FALSE(k.rt->voice().speaking()) << "held";
  EXPECT_EQ(k.rt->voice().texts_said(), said) << "silence is the answer to Pause";
  k.listen(0.05);  // the speech fades out into the pause (SpeechStream::kFadeSamples, 2 ms)
  EXPECT_LT(k.listen(1.0), 1e-6) << "nothing is heard while it is held";
  EXPECT_FALSE(k.rt->voice().speaking()) << "still held a second later";

  k.key(KioskKey::Pause);
  EXPECT_TRUE(k.rt->voice().speaking()) << "pressed again, it goes on";
  EXPECT_EQ(k.rt->voice().texts_said(), said) << "going on is not a new line";
  EXPECT_EQ(k.rt->voice().last_said(), description);
  EXPECT_TRUE(k.hears_speech()) << "and is heard again";

  ASSERT_TRUE(k.listen_to_the_end());
  k.key(KioskKey::Pause);
  EXPECT_EQ(k.rt->voice().last_said(), k.flow->text(MessageId::nothing_to_pause));
}

}  // namespace
}  // namespace hk::app
