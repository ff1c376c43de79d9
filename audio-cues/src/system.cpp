#include "audio/system.hpp"

#include <spdlog/spdlog.h>

namespace hk::audio {

namespace {

MessageCatalog load_catalog(const std::string& file) {
  return file.empty() ? MessageCatalog::english() : MessageCatalog::load(file);
}

}  // namespace

AudioSystem::AudioSystem(const AudioSystemParams& p)
    : catalog_(load_catalog(p.messages_file)),
      cues_(p.cue_capacity),
      ui_cues_(64),
      volume_(p.volume_default_step, 10, p.volume_step_db),
      mixer_(p.mixer, &cues_, &speech_stream_, &volume_, &ui_cues_) {
  SpeechParams sp = p.speech;
  if (sp.voice.empty()) sp.voice = catalog_.voice();
  speech_params_ = sp;
  try {
    speaker_ = std::make_unique<Speaker>(speech_stream_, sp);
  } catch (const SpeechError& e) {
    spdlog::warn("audio: no speech ({}); the kiosk continues with earcons only", e.what());
  }
  pulled_ = !p.open_output;
  if (p.open_output) output_ = std::make_unique<AudioOutput>(mixer_, p.output);  // logs its own state
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
