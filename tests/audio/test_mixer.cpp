// The mix: earcons ducked under speech, stepped volume, the limiter, live cues from the queue.
#include <gtest/gtest.h>

#include <vector>

#include "audio/mixer.hpp"
#include "audio/volume.hpp"
#include "audio_analysis.hpp"

namespace hk::audio {
namespace {

TEST(Volume, StepsLimitsAndReset) {
  Volume v(7, 10, 3.0);
  EXPECT_EQ(v.step(), 7);
  EXPECT_NEAR(20 * std::log10(v.gain()), -9.0, 1e-4);  // three steps below the top
  EXPECT_TRUE(v.up());
  EXPECT_TRUE(v.up());
  EXPECT_TRUE(v.up());
  EXPECT_FLOAT_EQ(v.gain(), 1.0f);
  EXPECT_FALSE(v.up()) << "past the top step";
  EXPECT_EQ(v.step(), 10);
  for (int i = 0; i < 9; ++i) EXPECT_TRUE(v.down());
  EXPECT_FALSE(v.down()) << "the bottom step is never silent";
  EXPECT_EQ(v.step(), 1);
  EXPECT_GT(v.gain(), 0.0f);
  v.reset();  // a new session
  EXPECT_EQ(v.step(), 7);
  v.set_default(99);  // clamped
  EXPECT_EQ(v.step(), 10);
}

// Fills a speech stream with a steady 0.2 tone for `seconds`.
void speak_tone(SpeechStream& s, double seconds) {
  const std::uint32_t gen = s.generation();
  std::vector<float> x(static_cast<std::size_t>(seconds * kSampleRateHz));
  for (std::size_t i = 0; i < x.size(); ++i)
    x[i] = 0.2f * static_cast<float>(std::sin(2 * 3.14159265 * 200.0 * i / kSampleRateHz));
  ASSERT_TRUE(s.push(gen, x.data(), x.size()));
  ASSERT_TRUE(s.finish(gen));
}

// Earcons under speech are ducked by duck_db, and come back when speech ends.
TEST(Mixer, EarconsAreDuckedUnderSpeech) {
  MixerParams p;
  p.duck_db = -14;
  p.speech_gain = 0.0;  // measure the earcons alone
  SpeechStream speech;
  Mixer m(p, nullptr, &speech, nullptr);
  CueEvent e;
  e.kind = CueKind::LevelFiner;  // a steady chirp, no decay: a clean level to compare
  std::vector<float> alone(4800), ducked(4800);
  m.trigger(e);
  m.render(alone.data(), alone.size());
  Mixer m2(p, nullptr, &speech, nullptr);
  speak_tone(speech, 0.5);
  std::vector<float> warm(960);
  m2.render(warm.data(), warm.size());  // 20 ms: ducking settles (10 ms time constant)
  m2.trigger(e);
  m2.render(ducked.data(), ducked.size());
  const double ratio_db = 20 * std::log10(test::rms(ducked, 480, 4800) / test::rms(alone, 480, 4800));
  EXPECT_NEAR(ratio_db, -14.0, 2.0);
}

// Volume scales the whole mix, and the limiter keeps a pile-up within [−1, 1].
TEST(Mixer, VolumeScalesAndLimiterBounds) {
  Volume v(10, 10, 3.0);
  MixerParams p;
  Mixer loud(p, nullptr, nullptr, &v);
  CueEvent e;
  e.kind = CueKind::LevelFiner;
  std::vector<float> a(4800), b(4800);
  loud.trigger(e);
  loud.render(a.data(), a.size());
  v.down();
  v.down();  // −6 dB
  Mixer quiet(p, nullptr, nullptr, &v);
  quiet.trigger(e);
  quiet.render(b.data(), b.size());
  EXPECT_NEAR(20 * std::log10(test::rms(b, 0, 4800) / test::rms(a, 0, 4800)), -6.0, 0.5);

  v.reset();
  Mixer pile(p, nullptr, nullptr, &v);
  for (int i = 0; i < 30; ++i) {
    CueEvent c;
    c.kind = CueKind::ContactBegin;
    c.speed_m_per_s = 1.0f;
    pile.trigger(c);
  }
  std::vector<float> x(4800);
  pile.render(x.data(), x.size());
  for (float s : x) ASSERT_LE(std::fabs(s), 1.0f);
  EXPECT_GT(test::peak(x, 0, x.size()), 0.5);
}

// Live: the callback drains the queue the servo thread fills; each cue starts in the buffer it arrives in.
TEST(Mixer, DrainsTheCueQueue) {
  SpscRing<CueEvent> q(16);
  Mixer m({}, &q, nullptr, nullptr);
  std::vector<float> x(256);
  m.render(x.data(), x.size());
  EXPECT_EQ(test::peak(x, 0, x.size()), 0.0);
  CueEvent e;
  e.kind = CueKind::ContactBegin;
  e.speed_m_per_s = 0.1f;
  ASSERT_TRUE(q.try_push(e));
  m.render(x.data(), x.size());
  EXPECT_EQ(m.cues_played(), 1u);
  EXPECT_GT(test::peak(x, 0, 48), 0.01) << "the click must start within 1 ms of the buffer that took it";
}

// Cancelling speech silences it within 10 ms of audio (plus nothing of the old utterance comes back).
TEST(Mixer, SpeechCancelSilencesWithin10ms) {
  SpeechStream speech;
  MixerParams p;
  Mixer m(p, nullptr, &speech, nullptr);
  speak_tone(speech, 1.0);
  std::vector<float> x(48000, 0.0f);
  m.render(x.data(), 4800);  // 100 ms of speech
  EXPECT_GT(test::rms(x, 0, 4800), 0.05);
  EXPECT_TRUE(speech.speaking());
  speech.cancel();
  for (std::size_t i = 4800; i < x.size(); i += 256) m.render(x.data() + i, std::min<std::size_t>(256, x.size() - i));
  EXPECT_EQ(test::peak(x, 4800 + 480, x.size()), 0.0);
  EXPECT_FALSE(speech.speaking());
}

}  // namespace
}  // namespace hk::audio
