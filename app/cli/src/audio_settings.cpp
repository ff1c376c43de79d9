#include "cli/audio_settings.hpp"

#include "visit/kiosk_flow.hpp"

#include "audio/wav.hpp"
#include "config/load.hpp"
#include "runtime/runtime_params.hpp"

namespace hk::app {

std::string run_speak(const SpeakOptions& o) {
  const config::Settings s = o.config_path.empty() ? config::Settings{} : config::load_settings(o.config_path);
  const audio::MessageCatalog catalog = audio::MessageCatalog::load(o.language, audio::default_locale_dir());
  std::string text = o.what;
  const auto keys = key_args(s.keys);  // the keys of the settings, named as the kiosk names them
  for (int i = 0; i < audio::kMessageCount; ++i) {
    if (audio::message_key(static_cast<audio::MessageId>(i)) == o.what) {
      // Sample values for the placeholders, so a translator hears a whole sentence.
      text = catalog.text(static_cast<audio::MessageId>(i), 7,
                          {{"picture", "2"},
                           {"pictures", "5"},
                           {"shapes", "7"},
                           {"level", "3"},
                           {"seconds", "20"},
                           {"description", "A large closed shape in the middle."}},
                          keys);
    }
  }
  audio::SpeechParams sp = audio_params_from(s).speech;
  sp.voice = catalog.voice();
  const std::vector<float> samples = audio::synthesize_speech(text, sp);
  audio::write_wav(o.wav_path, samples, audio::kSampleRateHz);
  return text;
}

}  // namespace hk::app
