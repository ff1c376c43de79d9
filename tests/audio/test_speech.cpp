// Speech with espeak-ng into our own stream: non-silent, longer text → longer audio, refused voices and
// parameters, thread-safety, streaming through a small ring, cancel within 10 ms of audio, a new text
// replaces the old one, repeat, the message log, destruction while speaking. No wall-clock speed asserts:
// every timeout below is a generous bound against a hang. espeak-ng is not sample-deterministic (the same
// text comes out 0.3 % longer or shorter from call to call, ~3 % on the first call of a process), so texts
// are compared by length with a 5 % tolerance; the texts compared differ ~12-fold.
#include <gtest/gtest.h>

#include <atomic>
#include <cctype>
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
bool pull(SpeechStream& s, std::vector<float>& all, Until until, std::vector<float>* speech = nullptr,
          double timeout_s = 30) {
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
  EXPECT_LT(static_cast<double>(synthesize_speech(t, fast).size()),
            0.75 * static_cast<double>(synthesize_speech(t, {}).size()));
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
  // espeak-ng carries a little state from the text it said last: "Hello there." comes out 7 % longer right
  // after "... because a key is pressed." (the first of kLong's two pieces, which the worker says between
  // these calls) than fresh. A call run inside another synthesis would give a mix of both, far longer.
  for (std::size_t n : sizes)
    EXPECT_NEAR(static_cast<double>(n), static_cast<double>(ref), 0.10 * static_cast<double>(ref));
}

TEST(Speech, StreamsBeforeTheSentenceIsDone) {
  // 16 blocks (85 ms) cannot hold the ~7 s sentence: the worker must stream it through while we read.
  SpeechStream stream(16);
  Speaker speaker(stream, {});
  speaker.say(kLong);
  std::vector<float> all, speech;
  ASSERT_TRUE(pull(
      stream, all, [&] { return !speech.empty(); }, &speech))
      << "speech never started";
  EXPECT_FALSE(speaker.wait_idle(0)) << "the first samples arrived only after the whole sentence was synthesised";
  EXPECT_TRUE(speaker.busy());
  ASSERT_TRUE(pull(
      stream, all, [&] { return !speaker.busy(); }, &speech));
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
  speaker.say(kShort);        // between two reads, as a key press would
  std::vector<float> speech;  // what is heard after the cut, without the test's read-ahead gaps
  ASSERT_TRUE(pull(
      stream, all, [&] { return !speaker.busy(); }, &speech));
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
  ASSERT_TRUE(pull(
      stream, all, [&] { return !speaker.busy() && !speech.empty(); }, &speech));
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
  ASSERT_TRUE(pull(
      stream, all, [&] { return !speaker.busy() && !first.empty(); }, &first));
  speaker.repeat();
  ASSERT_TRUE(pull(
      stream, all, [&] { return !speaker.busy() && !second.empty(); }, &second));
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
  ASSERT_TRUE(pull(
      stream, all, [&] { return !speaker.busy() && !speech.empty(); }, &speech));
  const double expected = static_cast<double>(synthesize_speech(kShort, {}).size());
  EXPECT_NEAR(static_cast<double>(speech.size()), expected, 0.05 * expected);
}

}  // namespace
}  // namespace hk::audio

// ── Long text: spoken piece by piece, whatever its length ─────────────────────────────────────────────
namespace hk::audio {
namespace {

/// The bytes of `text` but its white space: what the pieces must add up to (a 700-byte run with no space
/// is cut inside the run, so word boundaries alone would not do).
std::string letters_of(const std::string& text) {
  std::string out;
  for (char c : text)
    if (!std::isspace(static_cast<unsigned char>(c))) out += c;
  return out;
}

std::string joined(const std::vector<std::string>& pieces) {
  std::string out;
  for (const std::string& p : pieces) out += p;
  return out;
}

bool valid_utf8(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    const std::size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    if (n == 0 || i + n > s.size()) return false;
    for (std::size_t k = 1; k < n; ++k)
      if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return false;
    i += n;
  }
  return true;
}

/// A paragraph as a scanned page gives it: ~9 KB, sentences of every length, one run of 1 200 bytes with
/// no full stop, a line break, and a 700-byte "word" of two-byte letters with no space at all.
std::string long_paragraph() {
  std::string t;
  for (int i = 0; t.size() < 7000; ++i)
    t += "Sentence " + std::to_string(i) + " of the manual tells how the part number " + std::to_string(1000 + 7 * i) +
         (i % 5 == 0 ? " fits, and why; then" : " fits.") + " ";
  t += "\n";
  for (int i = 0; i < 200; ++i) t += "word" + std::to_string(i) + " ";
  for (int i = 0; i < 350; ++i) t += "\xC3\xA9";  // é, 700 bytes
  t += ". The end.";
  return t;
}

TEST(SpeechPieces, SentenceSizedPiecesThatAddUpToTheWholeText) {
  const std::string text = long_paragraph();
  ASSERT_GT(text.size(), 8000u);
  const std::vector<std::string> pieces = speech_pieces(text);
  ASSERT_GT(pieces.size(), 100u);
  for (const std::string& p : pieces) {
    EXPECT_FALSE(p.empty());
    EXPECT_LE(p.size(), kSpeechPieceBytes) << p.substr(0, 60);
    EXPECT_TRUE(valid_utf8(p)) << "a piece cut inside a UTF-8 sequence: " << p.substr(0, 60);
    EXPECT_FALSE(std::isspace(static_cast<unsigned char>(p.front())) ||
                 std::isspace(static_cast<unsigned char>(p.back())));
  }
  EXPECT_EQ(letters_of(joined(pieces)), letters_of(text)) << "every word, in order, none doubled";
  EXPECT_EQ(pieces[0], "Sentence 0 of the manual tells how the part number 1000 fits, and why;")
      << "a sentence ends at ';' too";
  EXPECT_EQ(pieces[1], "then Sentence 1 of the manual tells how the part number 1007 fits.");
  EXPECT_EQ(pieces.back(), "The end.");
  // A short text is one piece, as it was.
  EXPECT_EQ(speech_pieces("Louder."), std::vector<std::string>{"Louder."});
  EXPECT_TRUE(speech_pieces(" \n\t ").empty());
}

TEST(SpeechPieces, ALongTextIsSpokenWholeAndInOrder) {
  const std::string text = long_paragraph();
  SpeechStream stream;
  SpeechParams fast;
  fast.rate_wpm = 450;  // fewer samples to read through; the pieces are the same
  Speaker speaker(stream, fast);
  speaker.say(text);  // over the 4 000 bytes espeak-ng is handed at once: never refused
  EXPECT_EQ(speaker.last_text(), text);
  // Read as the audio callback would, without keeping the minutes of samples.
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(600);
  float buf[4096];
  std::size_t heard = 0;
  while (speaker.busy() && std::chrono::steady_clock::now() < end) {
    const std::size_t n = stream.read(buf, 4096);
    heard += n;
    if (n == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_FALSE(speaker.busy()) << "not done after 600 s";
  EXPECT_GT(heard, static_cast<std::size_t>(60 * kSampleRateHz)) << "minutes of speech, not a refusal";
  EXPECT_EQ(letters_of(joined(speaker.pieces_spoken())), letters_of(text)) << "every word was handed on, in order";
}

TEST(SpeechPieces, ThePieceHeardFollowsTheMixer) {
  // Three sentences; the piece heard moves from one to the next where the mixer reaches the samples of the
  // next, i.e. after as many samples as the first sentence takes when synthesised on its own.
  const std::string text = "The first sentence is here. A second one follows it. And the third ends the text.";
  const std::vector<std::string> pieces = speech_pieces(text);
  ASSERT_EQ(pieces.size(), 3u);
  SpeechStream stream;
  Speaker speaker(stream, {});
  EXPECT_EQ(speaker.piece_heard(), -1) << "nothing said yet";
  speaker.say(text);
  EXPECT_EQ(speaker.piece_heard(), 0) << "asked for, not heard yet: its first piece is next";
  std::vector<float> all, speech;
  std::vector<std::pair<std::size_t, int>> changes;  // (samples of speech read, piece heard after them)
  ASSERT_TRUE(pull(
      stream, all,
      [&] {
        const int p = speaker.piece_heard();
        if (changes.empty() || changes.back().second != p) changes.emplace_back(speech.size(), p);
        return p < 0;
      },
      &speech));
  ASSERT_EQ(changes.size(), 4u) << "0, 1, 2, then over";
  EXPECT_EQ(changes[0].second, 0);
  EXPECT_EQ(changes[1].second, 1);
  EXPECT_EQ(changes[2].second, 2);
  EXPECT_EQ(changes[3].second, -1);
  const double first = static_cast<double>(synthesize_speech(pieces[0], {}).size());
  const double second = static_cast<double>(synthesize_speech(pieces[1], {}).size());
  EXPECT_NEAR(static_cast<double>(changes[1].first), first, 0.05 * first + kChunk);
  EXPECT_NEAR(static_cast<double>(changes[2].first), first + second, 0.05 * (first + second) + kChunk);
  // Held by a pause it stays; cut off it is over.
  speaker.say(text);
  ASSERT_TRUE(pull(stream, all, [&] { return speaker.piece_heard() == 1; }));
  ASSERT_TRUE(speaker.pause());
  for (int i = 0; i < 100; ++i) {
    float buf[kChunk];
    stream.read(buf, kChunk);
  }
  EXPECT_EQ(speaker.piece_heard(), 1);
  speaker.cancel();
  EXPECT_EQ(speaker.piece_heard(), -1);
}

TEST(SpeechPieces, TextOverTheLimitIsCutNotRefused) {
  SpeechStream stream(4);
  Speaker speaker(stream, {});
  std::string huge;
  while (huge.size() <= kMaxSpeechTextBytes) huge += "many words ";
  EXPECT_NO_THROW(speaker.say(huge));
  const std::string kept = speaker.last_text();
  EXPECT_LE(kept.size(), kMaxSpeechTextBytes);
  EXPECT_GT(kept.size(), kMaxSpeechTextBytes - 16);
  EXPECT_EQ(huge.rfind(kept, 0), 0u) << "the start of the text, cut between words";
  EXPECT_NE(kept.back(), ' ');
  speaker.cancel();
}

TEST(SpeechPieces, AnAcknowledgementIsNotKeptForRepeat) {
  SpeechStream stream;
  Speaker speaker(stream, {});
  speaker.say(kLong);
  speaker.say(kShort, false);
  EXPECT_EQ(speaker.last_text(), kLong);
  speaker.forget();
  EXPECT_EQ(speaker.last_text(), "");
}

TEST(SpeechPause, PauseHoldsTheSpeechWhereItIsAndResumeGoesOn) {
  SpeechStream stream;
  Speaker speaker(stream, {});
  EXPECT_FALSE(speaker.pause()) << "nothing is being said";
  speaker.say(kLong);
  std::vector<float> all, speech;
  ASSERT_TRUE(pull(
      stream, all, [&] { return speech.size() > static_cast<std::size_t>(1.0 * kSampleRateHz); }, &speech));
  ASSERT_TRUE(speaker.pause());
  EXPECT_TRUE(speaker.paused());
  EXPECT_FALSE(speaker.busy()) << "paused speech is not being heard";
  const std::size_t cut = all.size();
  for (int i = 0; i < 200; ++i) {  // 1 s of audio while paused
    float buf[kChunk];
    speech.insert(speech.end(), buf, buf + stream.read(buf, kChunk));
    all.insert(all.end(), buf, buf + kChunk);
  }
  EXPECT_EQ(test::peak(all, cut + SpeechStream::kFadeSamples, all.size()), 0.0) << "silent after the fade";
  EXPECT_FALSE(speaker.pause()) << "already paused";
  ASSERT_TRUE(speaker.resume());
  EXPECT_FALSE(speaker.resume());
  ASSERT_TRUE(pull(
      stream, all, [&] { return !speaker.busy(); }, &speech));
  // Nothing was dropped: the whole text was heard, in two parts.
  const double expected = static_cast<double>(synthesize_speech(kLong, {}).size());
  EXPECT_NEAR(static_cast<double>(speech.size()), expected, 0.05 * expected);
}

TEST(SpeechPause, ANewTextEndsThePause) {
  SpeechStream stream;
  Speaker speaker(stream, {});
  speaker.say(kLong);
  std::vector<float> all, speech;
  ASSERT_TRUE(pull(
      stream, all, [&] { return !speech.empty(); }, &speech));
  ASSERT_TRUE(speaker.pause());
  speaker.say(kShort);
  EXPECT_FALSE(speaker.paused());
  speech.clear();
  ASSERT_TRUE(pull(
      stream, all, [&] { return !speaker.busy() && !speech.empty(); }, &speech));
  const double expected = static_cast<double>(synthesize_speech(kShort, {}).size());
  EXPECT_NEAR(static_cast<double>(speech.size()), expected, 0.05 * expected + SpeechStream::kFadeSamples);
}

}  // namespace
}  // namespace hk::audio
