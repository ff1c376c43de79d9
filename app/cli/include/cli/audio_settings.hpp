#pragma once
/// @file audio_settings.hpp
/// The headless `speak` command: renders a message or a text to a WAV file (to hear a translation or a
/// voice without a sound card), with the [audio] settings' voice.

#include <stdexcept>
#include <string>

#include "audio/system.hpp"
#include "config/settings.hpp"

namespace hk::app {

/// What `haptic-kiosk speak` was asked to do.
struct SpeakOptions {
  std::string what;             ///< a message key of the catalogue (e.g. "welcome") or free text
  std::string wav_path;         ///< output WAV
  std::string config_path;      ///< TOML settings; empty: defaults
  std::string language = "en";  ///< the catalogue and voice (BCP 47 tag, audio::MessageCatalog::load)
};

/// Renders the speech of `options.what` to `options.wav_path` (a message's placeholders get sample values:
/// picture 2 of 5, 7 shapes, 20 seconds, ...). Returns the spoken text.
/// @throws config::ConfigError, audio::MessageError, audio::SpeechError, audio::WavError (one line each).
std::string run_speak(const SpeakOptions& options);

}  // namespace hk::app
