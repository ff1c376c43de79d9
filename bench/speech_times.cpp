// How long the kiosk talks before a visitor can act, and how soon a key is answered: every catalogue
// message synthesised at the default voice and rate with long but real placeholder values (the same as
// tests/app/test_message_lengths.cpp), the longest per part of the visit, the speech from walking up to
// the first shape felt, and the time from a key to its first spoken word (the speaker's synthesis and
// hand-over to the mixer, read as the audio callback would, plus the sound device's buffer).
//
// Usage: bench_speech_times [--repeats N]   (a Markdown report on stdout)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "audio/messages.hpp"
#include "audio/speech.hpp"
#include "config/settings.hpp"
#include "message_samples.hpp"
#include "visit/kiosk_flow.hpp"

namespace {

using hk::audio::MessageId;

/// The part of a visit a message belongs to, by its key's prefix (first match wins).
std::string part_of(std::string_view key) {
  static const std::vector<std::pair<std::string_view, std::string>> parts{
      {"welcome", "walking up"}, {"attract", "walking up"}, {"tutorial", "tutorial"}, {"help", "help"},
      {"place", "help"},         {"key_", "help"},          {"this_key", "help"},     {"stick", "USB stick"},
      {"document", "USB stick"}, {"loading", "USB stick"},  {"capture", "camera"},    {"captured", "camera"},
      {"camera", "camera"},      {"tour", "guided tour"},   {"device", "device"},     {"no_audio", "device"},
      {"timeout", "session"},    {"goodbye", "session"},    {"sorry", "session"},     {"high_contrast", "operator"},
      {"overlay", "operator"}};
  for (const auto& [prefix, part] : parts)
    if (key.rfind(prefix, 0) == 0) return part;
  return "picture";
}

double seconds_of(const std::string& text) {
  return static_cast<double>(hk::audio::synthesize_speech(text, {}).size()) / hk::audio::kSampleRateHz;
}

/// From Speaker::say to the first sample above −40 dBFS read from the stream, reading as a 256-frame
/// audio callback would (as fast as it can: the device's own buffer is added by the caller) [ms].
double first_word_ms(hk::audio::Speaker& speaker, hk::audio::SpeechStream& stream, const std::string& text) {
  float buf[256];
  const auto t0 = std::chrono::steady_clock::now();
  speaker.say(text);
  std::size_t samples = 0;  // read since the say, silence included
  for (;;) {
    const std::size_t n = stream.read(buf, 256);
    for (std::size_t i = 0; i < n; ++i) {
      if (std::fabs(buf[i]) > 0.01f) {
        const double wait_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        speaker.cancel();
        return wait_ms + 1000.0 * static_cast<double>(samples + i) / hk::audio::kSampleRateHz;
      }
    }
    samples += n;
    if (n == 0) std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 5;
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--repeats") repeats = std::max(1, std::atoi(argv[i + 1]));
  const hk::audio::MessageCatalog& en = hk::audio::MessageCatalog::english();
  const hk::config::KeysSettings shipped;  // key_args views its strings
  const auto keys = hk::app::key_args(shipped);

  std::map<std::string, std::pair<double, std::string>> longest;  // part → (seconds, message key)
  std::vector<std::pair<std::string, double>> all;
  for (int i = 0; i < hk::audio::kMessageCount; ++i) {
    const auto id = static_cast<MessageId>(i);
    const std::string key(hk::audio::message_key(id));
    const double s = seconds_of(hk::test::sample_message(en, id, keys));
    all.emplace_back(key, s);
    if (hk::test::asked_to_be_long(id)) continue;
    auto& best = longest[part_of(key)];
    if (s > best.first) best = {s, key};
  }

  std::printf(
      "# Speech times\n\nDefault voice (espeak-ng \"en\") and rate (165 words a minute); placeholders filled with long "
      "but real values.\n\n");
  std::printf("| part of the visit | longest message | seconds |\n|---|---|---|\n");
  for (const auto& [part, best] : longest)
    std::printf("| %s | %s | %.1f |\n", part.c_str(), best.second.c_str(), best.first);
  const double welcome = seconds_of(hk::test::sample_message(en, MessageId::welcome, keys));
  std::printf(
      "\nWalking up to the first shape felt: the welcome, %.1f s, is all that is said before the square is under the "
      "hand "
      "(it is on the device as the welcome starts).\n",
      welcome);
  std::printf("Asked for, however long: help's second layer %.1f s.\n",
              seconds_of(hk::test::sample_message(en, MessageId::help, keys)));

  hk::audio::SpeechStream stream;
  hk::audio::Speaker speaker(stream, {});
  std::vector<double> ms;
  for (int r = 0; r < repeats; ++r) {
    for (const MessageId id :
         {MessageId::volume_up, MessageId::level_finer, MessageId::help_brief, MessageId::picture_loaded,
          MessageId::where_on, MessageId::key_next, MessageId::tour_ask}) {
      ms.push_back(first_word_ms(speaker, stream, hk::test::sample_message(en, id, keys)));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  std::sort(ms.begin(), ms.end());
  const double buffer_ms = 1000.0 * 256 / hk::audio::kSampleRateHz;
  std::printf(
      "\nKey to first spoken word over %zu presses: median %.0f ms, worst %.0f ms (synthesis, hand-over and the "
      "voice's "
      "own lead-in), plus the sound device's buffer (%.1f ms at 256 frames).\n",
      ms.size(), ms[ms.size() / 2], ms.back(), buffer_ms);
  std::printf("\n| message | seconds |\n|---|---|\n");
  for (const auto& [key, s] : all) std::printf("| %s | %.1f |\n", key.c_str(), s);
  return 0;
}
