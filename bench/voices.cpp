// Per voice and per language: how soon speech starts and how fast it is made, how big each catalogue is and how
// long a change of language takes. Writes Markdown (docs/bench/voices.md).
//
// - first audio [ms]: the synthesis of a message's first piece (speech_pieces: a sentence), which the Speaker
//   finishes before it hands the mixer a sample; the message is each language's welcome, best of `--repeats`
//   (the machine's other work only adds);
// - real-time factor: synthesis time / length of the speech made, over each language's whole help text;
// - switch [ms]: AudioSystem::set_language to the next language, then its language_name message's first piece
//   synthesised in its voice: what a visitor waits for between the Language key and the next words;
// - catalogue: the MO file's bytes and entries (messages, words, key names and places).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "audio/messages.hpp"
#include "audio/speech.hpp"
#include "audio/system.hpp"
#include "config/settings.hpp"
#include "visit/kiosk_flow.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

/// Best time [ms] of `repeats` syntheses of `text` in `params`, and the samples of the last.
double best_ms(const std::string& text, const hk::audio::SpeechParams& params, int repeats, std::size_t* samples) {
  double best = 1e9;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = Clock::now();
    const std::vector<float> x = hk::audio::synthesize_speech(text, params);
    best = std::min(best, ms_since(t0));
    *samples = x.size();
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  using hk::audio::MessageCatalog;
  using hk::audio::MessageId;
  int repeats = 5;
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--repeats") repeats = std::max(1, std::atoi(argv[i + 1]));
  const hk::config::KeysSettings shipped;
  const auto keys = hk::app::key_args(shipped);
  struct Voice {
    std::string language, voice;
  };
  const std::vector<Voice> voices{{"en", "flite:slt"}, {"en", "flite:kal"}, {"en", "flite:awb"}, {"en", "flite:rms"},
                                  {"en", "en"},        {"fr", "fr"},        {"de", "de"},        {"es", "es"}};
  std::printf("# Voices and languages\n\n");
  std::printf("Each voice at the default rate (165 words a minute); best of %d runs.\n\n", repeats);
  std::printf("| language | voice | first audio [ms] | real-time factor | help: speech [s] / made in [ms] |\n");
  std::printf("|---|---|---|---|---|\n");
  for (const Voice& v : voices) {
    const MessageCatalog m = MessageCatalog::load(v.language, hk::audio::default_locale_dir());
    hk::audio::SpeechParams p;
    p.voice = v.voice;
    const std::string first = hk::audio::speech_pieces(m.text(MessageId::welcome, {}, keys)).front();
    std::size_t n = 0;
    const double first_ms = best_ms(first, p, repeats, &n);
    const double help_ms = best_ms(m.text(MessageId::help, {}, keys), p, std::max(1, repeats / 2), &n);
    const double help_s = static_cast<double>(n) / hk::audio::kSampleRateHz;
    std::printf("| %s | %s | %.1f | %.3f | %.1f / %.0f |\n", v.language.c_str(), v.voice.c_str(), first_ms,
                help_ms / 1000.0 / help_s, help_s, help_ms);
  }

  std::printf(
      "\n## Switching language\n\nThe Language key's wait: set_language, then the language's own name "
      "synthesised in its voice (English in flite:slt).\n\n| from → to | switch [ms] |\n|---|---|\n");
  hk::audio::AudioSystemParams ap;
  ap.open_output = false;
  ap.languages = {"en", "fr", "de", "es"};
  ap.english_voice = "flite:slt";
  hk::audio::AudioSystem audio(ap);
  for (int i = 0; i < 4; ++i) {
    const int next = (i + 1) % 4;
    audio.set_language(i);
    double best = 1e9;
    for (int r = 0; r < repeats; ++r) {
      audio.set_language(i);
      const auto t0 = Clock::now();
      audio.set_language(next);
      hk::audio::SpeechParams p;
      p.voice = next == 0 ? "flite:slt" : audio.messages().voice();
      (void)hk::audio::synthesize_speech(audio.messages().text(MessageId::language_name), p);
      best = std::min(best, ms_since(t0));
    }
    std::printf("| %s → %s | %.1f |\n", ap.languages[static_cast<std::size_t>(i)].c_str(),
                ap.languages[static_cast<std::size_t>(next)].c_str(), best);
  }

  std::printf("\n## Catalogues\n\n| language | MO file [bytes] | entries |\n|---|---|---|\n");
  const int entries =
      hk::audio::kMessageCount + hk::audio::kWordCount + hk::audio::kKeyNameCount + hk::audio::kKeyPlaceCount;
  std::printf("| en | (built in) | %d |\n", entries);
  for (const char* lang : {"fr", "de", "es"}) {
    const auto f = hk::audio::default_locale_dir() / lang / "LC_MESSAGES" / "haptic-kiosk.mo";
    std::printf("| %s | %ju | %d |\n", lang, static_cast<std::uintmax_t>(std::filesystem::file_size(f)), entries);
  }
  return 0;
}
