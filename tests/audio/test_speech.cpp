// Speech with espeak-ng into our own stream: non-silent, longer text → longer audio, refused voices and
// parameters, thread-safety, streaming through a small ring, cancel within 10 ms of audio, a new text
// replaces the old one, repeat, the message log, destruction while speaking. No wall-clock speed asserts:
// every timeout below is a generous bound against a hang. espeak-ng is not sample-deterministic (the same
// text comes out 0.3 % longer or shorter from call to call, ~3 % on the first call of a process), so texts
// are compared by length with a 5 % tolerance; the texts compared differ ~12-fold.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "audio/speech.hpp"
#include "audio_analysis.hpp"

namespace hk::audio {
namespace {

constexpr std::size_t kChunk = 240;  // an audio callback's buffer: 5 ms at 48 kHz

const std::string kLong =
    "This is a long sentence that the visitor will not hear to the end, because a key is pressed. "
    "Picture two of five has seven shapes, a large closed one in the middle.";
const std::string kShort = "Less detail.";

std::size_t nonzero(const std::vector<float>& x) {
  std::size_t n = 0;
  for (float v : x) n += v != 0.0f;
  return n;
}

// Reads the stream as the audio callback would (kChunk samples at a time, appended to `all`, zeros where
// nothing was there) until `until()` or `timeout_s` of wall time; sleeps 1 ms when nothing was there. The
// test reads faster than real time, so it often finds the ring empty between two of the worker's pushes:
// `speech` (if given) gets only the samples read() reported, i.e. the utterance without those gaps.
// Returns false on time-out.
template <class Until>
bool pull(SpeechStream& s, std::vector<float>& all, Until until, std::vector<float>* speech = nullptr, double timeout_s = 30) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  float buf[kChunk];
  while (!until()) {
    if (std::chrono::steady_clock::now() > end) return false;
    const std::size_t n = s.read(buf, kChunk);
    all.insert(all.end(), buf, buf + kChunk);
    if (speech) speech->insert(speech->end(), buf, buf + n);
    if (n == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

TEST(Speech, RendersNonSilentAudioThatGrowsWithTheText) {
  const std::vector<float> word = synthesize_speech("Hello.", {});
  const std::vector<float> text = synthesize_speech(
      "Picture two of five. It has seven shapes. A large closed shape in the middle, a small one at the top left.", {});
  ASSERT_GT(word.size(), static_cast<std::size_t>(0.2 * kSampleRateHz));  // "Hello." is ~0.5 s
  EXPECT_GT(test::rms(word, 0, word.size()), 0.01);
  EXPECT_GT(test::rms(text, 0, text.size()), 0.01);
  EXPECT_GT(text.size(), 2 * word.size());
  for (float s : text) ASSERT_TRUE(std::isfinite(s) && std::fabs(s) <= 1.0f) << s;
  EXPECT_TRUE(synthesize_speech("", {}).empty());
  // A faster voice says the same text in less time.
  SpeechParams fast;
  fast.rate_wpm = 330;
  const std::string t = "Picture two of five. It has seven shapes.";
  EXPECT_LT(static_cast<double>(synthesize_speech(t, fast).size()), 0.75 * static_cast<double>(synthesize_speech(t, {}).size()));
  // Another voice works too (and the default one again afterwards).
  SpeechParams de;
  de.voice = "de";
  de.pitch = 70;
  EXPECT_GT(test::rms(synthesize_speech("Hallo.", de), 0, ~std::size_t{0}), 0.01);
  EXPECT_GT(test::rms(synthesize_speech("Hello.", {}), 0, ~std::size_t{0}), 0.01);
}

TEST(Speech, BadVoiceAndParametersAreRefusedInOneLine) {
  const auto what = [](const SpeechParams& p, std::string_view text = "Hello") -> std::string {
    try {
      synthesize_speech(text, p);
    } catch (const SpeechError& e) {
      return e.what();
    }
    return "(no error)";
  };
  SpeechParams p;
  p.voice = "no-such-voice-xx";
  std::string w = what(p);
  EXPECT_NE(w.find("no-such-voice-xx"), std::string::npos) << w;
  EXPECT_EQ(w.find('\n'), std::string::npos) << w;
  SpeechStream stream(4);
  EXPECT_THROW(Speaker speaker(stream, p), SpeechError);
  p = {};
  p.rate_wpm = 5000;
  w = what(p);
  EXPECT_NE(w.find("rate_wpm 5000"), std::string::npos) << w;
  EXPECT_NE(w.find("450"), std::string::npos) << w;
  p = {};
  p.pitch = -1;
  w = what(p);
  EXPECT_NE(w.find("pitch -1"), std::string::npos) << w;
  EXPECT_NE(w.find("[0, 100]"), std::string::npos) << w;
  p = {};
  p.voice = "";
  EXPECT_NE(what(p).find("voice"), std::string::npos);
  w = what({}, std::string(kMaxSpeechTextBytes + 1, 'a'));
  EXPECT_NE(w.find(std::to_string(kMaxSpeechTextBytes)), std::string::npos) << w;
  // espeak-ng still works after the refusals, with the default voice.
  const std::vector<float> ok = synthesize_speech("Hello.", {});
  EXPECT_GT(test::rms(ok, 0, ok.size()), 0.01);
}

TEST(Speech, ConcurrentCallersAreSerialised) {
  const std::size_t ref = synthesize_speech("Hello there.", {}).size();
  SpeechStream stream;
  Speaker speaker(stream, {});
  std::atomic<bool> done{false};
  std::thread audio([&] {  // an audio callback draining the stream meanwhile
    float buf[kChunk];
    while (!done.load()) {
      if (stream.read(buf, kChunk) == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  std::vector<std::size_t> sizes(4 * 5, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < 5; ++i) {
        if (t == 0) speaker.say(kLong);  // the worker synthesises at the same time
        sizes[static_cast<std::size_t>(t * 5 + i)] = synthesize_speech("Hello there.", {}).size();
      }
    });
  }
  for (auto& th : threads) th.join();
  EXPECT_TRUE(speaker.wait_idle(30));
  done = true;
  audio.join();
  for (std::size_t n : sizes) EXPECT_NEAR(static_cast<double>(n), static_cast<double>(ref), 0.05 * static_cast<double>(ref));
}

TEST(Speech, StreamsBeforeTheSentenceIsDone) {
  // 16 blocks (85 ms) cannot hold the ~7 s sentence: the worker must stream it through while we read.
  SpeechStream stream(16);
  Speaker speaker(stream, {});
  speaker.say(kLong);
  std::vector<float> all, speech;
  ASSERT_TRUE(pull(stream, all, [&] { return !speech.empty(); }, &speech)) << "speech never started";
  EXPECT_FALSE(speaker.wait_idle(0)) << "the first samples arrived only after the whole sentence was synthesised";
  EXPECT_TRUE(speaker.busy());
  ASSERT_TRUE(pull(stream, all, [&] { return !speaker.busy(); }, &speech));
  EXPECT_GT(stream.full_waits(), 0u);
  // Nothing lost or doubled on the way through the full ring (espeak-ng's length of a text varies by ~0.3 %).
  const double expected = static_cast<double>(synthesize_speech(kLong, {}).size());
  EXPECT_NEAR(static_cast<double>(speech.size()), expected, 0.02 * expected);
  EXPECT_FALSE(stream.speaking());
}

TEST(Speech, CancelStopsWithin10msOfAudio) {
  SpeechStream stream;
  Speaker speaker(stream, {});
  speaker.say(kLong);
  std::vector<float> all;
  ASSERT_TRUE(pull(stream, all, [&] { return nonzero(all) > static_cast<std::size_t>(0.3 * kSampleRateHz); }))
      << "speech never started";
  EXPECT_TRUE(stream.speaking());
  const std::size_t cut = all.size();  // N: the cancel comes between two reads, here
  speaker.cancel();
  for (int i = 0; i < 100; ++i) {  // 0.5 s more of audio
    float buf[kChunk];
    stream.read(buf, kChunk);
    all.insert(all.end(), buf, buf + kChunk);
  }
  EXPECT_EQ(test::peak(all, cut + 480, all.size()), 0.0) << "speech went on past 10 ms after cancel at sample " << cut;
  EXPECT_FALSE(stream.speaking());
  EXPECT_TRUE(speaker.wait_idle(10.0));
  EXPECT_FALSE(speaker.busy());
  // Nothing comes later either (the worker stopped synthesising).
  std::vector<float> later;
  pull(stream, later, [&] { return later.size() >= 100 * kChunk; });
  EXPECT_EQ(nonzero(later), 0u);
}

TEST(Speech, SayingANewTextReplacesTheOneBeingHeard) {
  SpeechStream stream;
  Speaker speaker(stream, {});
  speaker.say(kLong);
  std::vector<float> all;
  ASSERT_TRUE(pull(stream, all, [&] { return nonzero(all) > static_cast<std::size_t>(0.3 * kSampleRateHz); }));
  speaker.say(kShort);  // between two reads, as a key press would
  std::vector<float> speech;  // what is heard after the cut, without the test's read-ahead gaps
  ASSERT_TRUE(pull(stream, all, [&] { return !speaker.busy(); }, &speech));
  // After the cut: the old text fades out within SpeechStream::kFadeSamples, then the new one only.
  const double expected = static_cast<double>(synthesize_speech(kShort, {}).size());
  EXPECT_NEAR(static_cast<double>(speech.size()), expected, 0.05 * expected + SpeechStream::kFadeSamples);
}

TEST(Speech, NewTextReplacesTheQueuedOne) {
  SpeechStream stream;
  Speaker speaker(stream, {});
  speaker.say(kLong);
  speaker.say(kShort);
  std::vector<float> all, speech;
  ASSERT_TRUE(pull(stream, all, [&] { return !speaker.busy() && !speech.empty(); }, &speech));
  // Only the second text plays: its length, not the ~12 times longer first one's (nor both).
  const double expected = static_cast<double>(synthesize_speech(kShort, {}).size());
  EXPECT_NEAR(static_cast<double>(speech.size()), expected, 0.05 * expected);
  const auto log = speaker.log();
  ASSERT_EQ(log.size(), 2u);
  EXPECT_EQ(log[0].second, kLong);
  EXPECT_EQ(log[1].second, kShort);
  EXPECT_LE(log[0].first, log[1].first);
  EXPECT_EQ(speaker.last_text(), kShort);
}

TEST(Speech, RepeatSaysTheLastTextAgainAndTheLogHasIt) {
  SpeechStream stream;
  Speaker speaker(stream, {});
  speaker.repeat();  // nothing said yet: nothing to repeat, nothing logged
  EXPECT_TRUE(speaker.log().empty());
  EXPECT_EQ(speaker.last_text(), "");
  speaker.say(kShort);
  std::vector<float> all, first, second;
  ASSERT_TRUE(pull(stream, all, [&] { return !speaker.busy() && !first.empty(); }, &first));
  speaker.repeat();
  ASSERT_TRUE(pull(stream, all, [&] { return !speaker.busy() && !second.empty(); }, &second));
  const double once = static_cast<double>(first.size());
  EXPECT_GT(once, 0.3 * kSampleRateHz);
  EXPECT_NEAR(static_cast<double>(second.size()), once, 0.05 * once);
  speaker.say("");  // only cancels: logged, but the last text stays
  const auto log = speaker.log();
  ASSERT_EQ(log.size(), 3u);
  EXPECT_EQ(log[0].second, kShort);
  EXPECT_EQ(log[1].second, kShort);
  EXPECT_EQ(log[2].second, "");
  EXPECT_LT(log[0].first, log[1].first);
  EXPECT_LE(log[1].first, log[2].first);
  EXPECT_EQ(speaker.last_text(), kShort);
}

TEST(Speech, LogKeepsTheNewestEntries) {
  SpeechStream stream;
  Speaker speaker(stream, {});
  const std::size_t n = Speaker::kLogEntries + 44;
  for (std::size_t i = 0; i < n; ++i) speaker.say("Item " + std::to_string(i) + ".");
  const auto log = speaker.log();
  ASSERT_EQ(log.size(), Speaker::kLogEntries);
  EXPECT_EQ(log.front().second, "Item 44.");
  EXPECT_EQ(log.back().second, "Item " + std::to_string(n - 1) + ".");
  EXPECT_TRUE(speaker.wait_idle(30));
}

TEST(Speech, DestroyedWhileSpeakingDoesNotHang) {
  SpeechStream stream(4);  // a tiny ring nobody reads: the worker waits for room
  for (int i = 0; i < 20; ++i) {
    Speaker speaker(stream, {});
    speaker.say(kLong);
    if (i % 2 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  // The stream and espeak-ng are still usable after all that.
  Speaker speaker(stream, {});
  speaker.say(kShort);
  std::vector<float> all, speech;
  ASSERT_TRUE(pull(stream, all, [&] { return !speaker.busy() && !speech.empty(); }, &speech));
  const double expected = static_cast<double>(synthesize_speech(kShort, {}).size());
  EXPECT_NEAR(static_cast<double>(speech.size()), expected, 0.05 * expected);
}

}  // namespace
}  // namespace hk::audio
