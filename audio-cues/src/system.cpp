#include "audio/system.hpp"
#include "hk/language.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace hk::audio {

void AudioSystem::load_languages(const AudioSystemParams& p) {
  for (const std::string& code : p.languages) {
    if (std::find(language_codes_.begin(), language_codes_.end(), code) != language_codes_.end()) continue;
    try {
      catalogues_.push_back(MessageCatalog::load(code, p.locale_dir));
      language_codes_.push_back(code);
    } catch (const MessageError& e) {
      spdlog::error("audio: {}; the language is not offered", e.what());
    }
  }
  if (catalogues_.empty()) {
    spdlog::error("audio: no offered language could be loaded; the kiosk speaks English");
    catalogues_.push_back(MessageCatalog::english());
    language_codes_.emplace_back("en");
  }
  const auto it = std::find(language_codes_.begin(), language_codes_.end(), p.language);
  if (it == language_codes_.end())
    spdlog::error("audio: the default language '{}' is not among those loaded; visits start in '{}'", p.language,
                  language_codes_[0]);
  default_language_ = language_ = it == language_codes_.end() ? 0 : static_cast<int>(it - language_codes_.begin());
  catalog_ = catalogues_[static_cast<std::size_t>(language_)];
}

AudioSystem::AudioSystem(const AudioSystemParams& p)
    : cues_(p.cue_capacity),
      ui_cues_(64),
      volume_(p.volume_default_step, 10, p.volume_step_db),
      mixer_(p.mixer, &cues_, &speech_stream_, &volume_, &ui_cues_) {
  load_languages(p);
  english_voice_ = p.english_voice;
  SpeechParams sp = p.speech;
  if (sp.voice.empty()) sp.voice = voice_for(language_codes_[static_cast<std::size_t>(language_)]);
  speech_params_ = sp;
  try {
    speaker_ = std::make_unique<Speaker>(speech_stream_, sp);
  } catch (const SpeechError& e) {
    if (sp.voice != "en") {  // the language's voice is missing: espeak-ng's English, never silence
      spdlog::error("audio: {}; speaking with the voice 'en'", e.what());
      sp.voice = "en";
      try {
        speaker_ = std::make_unique<Speaker>(speech_stream_, sp);
      } catch (const SpeechError&) {
      }
    }
    if (!speaker_) spdlog::warn("audio: no speech ({}); the kiosk continues with earcons only", e.what());
  }
  pulled_ = !p.open_output;
  if (p.open_output) output_ = std::make_unique<AudioOutput>(mixer_, p.output);  // logs its own state
}

bool AudioSystem::set_language(int index) {
  if (index < 0 || index >= static_cast<int>(catalogues_.size())) return false;
  if (index == language_) return true;
  language_ = index;
  catalog_ = catalogues_[static_cast<std::size_t>(index)];
  const std::string voice = voice_for(language_codes_[static_cast<std::size_t>(index)]);
  if (speaker_) {
    try {
      speaker_->set_voice(voice);
    } catch (const SpeechError& e) {
      if (missing_voices_.insert(voice).second)  // once per voice
        spdlog::error("audio: {}; speaking {} with the voice 'en'", e.what(),
                      language_codes_[static_cast<std::size_t>(index)]);
      try {
        speaker_->set_voice("en");
      } catch (const SpeechError&) {  // "en" started the speaker: not refused now
      }
    }
  }
  speech_params_.voice = speaker_ ? speaker_->voice() : catalog_.voice();
  return true;
}

std::string AudioSystem::voice_for(std::string_view language) const {
  const std::string_view subtag = hk::language_subtag(language);
  return subtag == "en" && !english_voice_.empty() ? english_voice_ : std::string(subtag);
}

const MessageCatalog& AudioSystem::catalogue(int index) const {
  return index >= 0 && index < static_cast<int>(catalogues_.size()) ? catalogues_[static_cast<std::size_t>(index)]
                                                                    : catalog_;
}

bool AudioSystem::play(CueKind kind) noexcept {
  CueEvent e;
  e.kind = kind;
  return ui_cues_.try_push(e);
}

AudioSystem::~AudioSystem() {
  output_.reset();  // stop the callback before the mixer and the stream go
  speaker_.reset();
}

void AudioSystem::say_text(std::string text, bool keep) {
  if (speaker_) speaker_->say(std::move(text), keep);
}

void AudioSystem::say_text_in(std::string text, bool keep, std::size_t from_piece, const std::string& language,
                              std::size_t until_piece) {
  if (!speaker_) return;
  const std::string voice = voice_for(language);
  try {
    speaker_->say_switching(text, keep, from_piece, voice, until_piece);
  } catch (const SpeechError& e) {
    if (missing_voices_.insert(voice).second)
      spdlog::error("audio: {}; its text is said in the voice in use", e.what());
    speaker_->say(std::move(text), keep);
  }
}

bool AudioSystem::pause_speech() { return speaker_ && speaker_->pause(); }

bool AudioSystem::resume_speech() { return speaker_ && speaker_->resume(); }

double AudioSystem::speech_duration_s(const std::string& text) const {
  if (!speaker_ || text.empty()) return 0.0;
  try {
    return static_cast<double>(synthesize_speech(text, speech_params_).size()) / kSampleRateHz;
  } catch (const SpeechError& e) {
    spdlog::warn("audio: {}", e.what());
    return 0.0;
  }
}

bool AudioSystem::speaking() const { return speaker_ && (pulled_ || sound_output()) && speaker_->busy(); }

void AudioSystem::new_session() {
  volume_.reset();
  if (speaker_) speaker_->forget();
}

std::vector<std::pair<std::int64_t, std::string>> AudioSystem::speech_log() const {
  return speaker_ ? speaker_->log() : std::vector<std::pair<std::int64_t, std::string>>{};
}

}  // namespace hk::audio
