// The audio side as the kiosk uses it: messages spoken through the mixer, cues from the ring, a new
// session resetting the volume, no sound card tolerated, a bad translation refused.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

#include "audio/system.hpp"
#include "audio_analysis.hpp"
#include "test_paths.hpp"

namespace hk::audio {
namespace {

AudioSystemParams headless() {
  AudioSystemParams p;
  p.open_output = false;
  return p;
}

// Pulls the mix like an audio callback for `seconds` of audio (sleeping 1 ms between 5 ms buffers so the
// speech worker keeps ahead).
std::vector<float> pull(AudioSystem& a, double seconds) {
  std::vector<float> x(static_cast<std::size_t>(seconds * kSampleRateHz));
  for (std::size_t i = 0; i < x.size(); i += 240) {
    a.render(x.data() + i, std::min<std::size_t>(240, x.size() - i));
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  return x;
}

// Pulls 5 ms buffers until one is not silent: the speech worker has begun to deliver. The give-up bound
// (60 s) only keeps a broken build from hanging; the outcome is the sound, not the time.
bool until_heard(AudioSystem& a) {
  std::vector<float> x(240);
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < give_up) {
    a.render(x.data(), x.size());
    if (test::peak(x, 0, x.size()) > 0.0) return true;
    std::this_thread::yield();
  }
  return false;
}

TEST(AudioSystem, SpeaksCatalogueMessagesThroughTheMix) {
  AudioSystem a(headless());
  ASSERT_TRUE(a.speech_available());
  a.say_text(a.messages().text(MessageId::picture_loaded, 3, {{"picture", "1"}, {"pictures", "4"}}));
  ASSERT_TRUE(until_heard(a));
  const std::vector<float> x = pull(a, 1.0);
  EXPECT_GT(test::rms(x, 0, x.size()), 0.01) << "the message is heard";
  const auto log = a.speech_log();
  ASSERT_EQ(log.size(), 1u);
  EXPECT_EQ(log[0].second, "Picture 1 of 4. It has 3 shapes.");
}

TEST(AudioSystem, CuesFromTheRingAreHeard) {
  AudioSystem a(headless());
  CueEvent e;
  e.kind = CueKind::ContactBegin;
  e.speed_m_per_s = 0.1f;
  ASSERT_TRUE(a.cues().try_push(e));
  std::vector<float> x(2400);
  a.render(x.data(), x.size());
  EXPECT_GT(test::peak(x, 0, 96), 0.05) << "the click starts in the first buffer after the push";
  EXPECT_EQ(a.cues_dropped(), 0u);
}

TEST(AudioSystem, NewSessionResetsTheVolumeAndStopsSpeech) {
  AudioSystemParams p = headless();
  p.volume_default_step = 5;
  AudioSystem a(p);
  EXPECT_TRUE(a.volume_up());
  EXPECT_TRUE(a.volume_up());
  EXPECT_EQ(a.volume().step(), 7);
  a.say_text(a.messages().text(MessageId::help));
  ASSERT_TRUE(until_heard(a));
  const std::vector<float> before = pull(a, 0.5);
  ASSERT_GT(test::rms(before, 0, before.size()), 0.01) << "help was being spoken";
  a.new_session();
  EXPECT_EQ(a.volume().step(), 5);
  const std::vector<float> x = pull(a, 0.2);
  EXPECT_EQ(test::peak(x, 480, x.size()), 0.0) << "speech was cut at the new session";
}

TEST(AudioSystem, RunsWithoutASoundCard) {
  AudioSystemParams p;  // open_output = true: on this machine there is no device, on a kiosk there is
  AudioSystem a(p);
  ASSERT_NE(a.output_info(), nullptr);
  if (!a.sound_output()) {
    EXPECT_FALSE(a.output_info()->why_not.empty());
  }
  a.say_text(a.messages().text(MessageId::welcome));
  EXPECT_EQ(a.speech_log().size(), 1u);
}

TEST(AudioSystem, OffersItsLanguagesEachWithItsVoice) {
  AudioSystemParams p = headless();
  p.languages = {"en", "fr", "de", "es"};
  p.language = "de";
  AudioSystem a(p);
  ASSERT_EQ(a.languages(), (std::vector<std::string>{"en", "fr", "de", "es"}));
  EXPECT_EQ(a.language(), 2);
  EXPECT_EQ(a.messages().language_name(), "Deutsch");
  const MessageCatalog& current = a.messages();  // the reference the visitor flow keeps
  ASSERT_TRUE(a.set_language(1));
  EXPECT_EQ(current.language_name(), "Français");
  EXPECT_EQ(current.voice(), "fr");
  a.say_text(current.text(MessageId::volume_up));
  EXPECT_EQ(a.speech_log().back().second, "Plus fort.");
  EXPECT_FALSE(a.set_language(4));
  EXPECT_EQ(a.language(), 1);
}

TEST(AudioSystem, ALanguageThatCannotLoadIsLeftOutAndTheDefaultFallsBack) {
  AudioSystemParams p = headless();
  p.languages = {"it", "fr", "EN_us"};  // no Italian catalogue; not a BCP 47 tag
  p.language = "it";
  AudioSystem a(p);
  EXPECT_EQ(a.languages(), std::vector<std::string>{"fr"});
  EXPECT_EQ(a.messages().language(), "fr");
  p.languages = {"it"};
  AudioSystem none(p);
  EXPECT_EQ(none.languages(), std::vector<std::string>{"en"});
  EXPECT_EQ(none.messages().text(MessageId::volume_up), "Louder.");
}

TEST(AudioSystem, EnglishSpeaksWithFliteAndADocumentsTextWithItsOwnVoice) {
  AudioSystemParams p = headless();
  p.languages = {"en", "de"};
  p.english_voice = "flite:slt";
  AudioSystem a(p);
  ASSERT_TRUE(a.speech_available());
  // Flite's slt and espeak-ng's en are different voices: the same words make different sound.
  SpeechParams slt, en;
  slt.voice = "flite:slt";
  const std::vector<float> by_flite = synthesize_speech("The handle is ready.", slt);
  const std::vector<float> by_espeak = synthesize_speech("The handle is ready.", en);
  ASSERT_GT(by_flite.size(), static_cast<std::size_t>(kSampleRateHz / 2));
  EXPECT_GT(test::rms(by_flite, 0, by_flite.size()), 0.01);
  EXPECT_NE(by_flite.size(), by_espeak.size());
  a.say_text(a.messages().text(MessageId::device_ready));
  ASSERT_TRUE(until_heard(a));
  const std::vector<float> x = pull(a, 1.0);
  EXPECT_GT(test::rms(x, 0, x.size()), 0.01) << "English is heard in Flite's voice";
  // A German text after English words: said, the German from its piece on; a language without a voice
  // falls back to the voice in use (and is still said).
  a.say_text_in("Text: Der Brunnen steht auf dem Markt.", true, 1, "de");
  EXPECT_EQ(a.speech_log().back().second, "Text: Der Brunnen steht auf dem Markt.");
  a.say_text_in("Text: something.", true, 1, "xx");
  EXPECT_EQ(a.speech_log().back().second, "Text: something.");
  SpeechParams none;
  none.voice = "flite:nobody";
  EXPECT_THROW(synthesize_speech("x", none), SpeechError);
}

}  // namespace
}  // namespace hk::audio
