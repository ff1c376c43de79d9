#include "audio/mixer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "hk/error.hpp"

namespace hk::audio {
namespace {

// Soft limiter: linear below 0.5, then a tanh knee that never exceeds 1, so loud overlaps (a click on
// top of speech at full volume) do not wrap or hard-clip.
inline float soft_limit(float x) {
  const float a = std::fabs(x);
  if (a <= 0.5f) return x;
  const float y = 0.5f + 0.5f * std::tanh((a - 0.5f) * 2.0f);
  return x < 0 ? -y : y;
}

}  // namespace

Mixer::Mixer(const MixerParams& params, SpscRing<CueEvent>* cues, SpeechStream* speech, const Volume* volume,
             SpscRing<CueEvent>* ui_cues)
    : params_(params),
      synth_(params.earcons, kSampleRateHz),
      cues_(cues),
      ui_cues_(ui_cues),
      speech_(speech),
      volume_(volume) {
  const double fs = kSampleRateHz;
  duck_down_ = static_cast<float>(1.0 - std::exp(-1.0 / (std::max(1e-4, params.duck_attack_s) * fs)));
  duck_up_ = static_cast<float>(1.0 - std::exp(-1.0 / (std::max(1e-4, params.duck_release_s) * fs)));
  duck_floor_ = static_cast<float>(std::pow(10.0, std::min(0.0, params.duck_db) / 20.0));
}

void Mixer::render(float* out, std::size_t frames) noexcept {
  for (SpscRing<CueEvent>* queue : {cues_, ui_cues_}) {
    if (queue == nullptr) continue;
    CueEvent e;
    while (queue->try_pop(e)) {
      synth_.trigger(e);
      ++cues_played_;
    }
  }
  const float master = volume_ ? volume_->gain() : 1.0f;
  const float speech_gain = static_cast<float>(params_.speech_gain);
  std::size_t done = 0;
  while (done < frames) {
    const std::size_t n = std::min(kChunk, frames - done);
    std::fill_n(earcon_buf_, n, 0.0f);
    synth_.render_add(earcon_buf_, n);
    std::size_t spoken = 0;
    if (speech_) {
      spoken = speech_->read(speech_buf_, n);
    } else {
      std::fill_n(speech_buf_, n, 0.0f);
    }
    const bool ducking = spoken > 0;
    const float target = ducking ? duck_floor_ : 1.0f;
    const float k = ducking ? duck_down_ : duck_up_;
    for (std::size_t i = 0; i < n; ++i) {
      duck_ += k * (target - duck_);
      out[done + i] = soft_limit(master * (duck_ * earcon_buf_[i] + speech_gain * speech_buf_[i]));
    }
    done += n;
  }
}

std::vector<float> render_cue_timeline(std::span<const CueEvent> cues, double period_s, double duration_s,
                                       const MixerParams& params) {
  if (!(period_s > 0) || !std::isfinite(period_s)) {
    throw hk::ArgumentError("servo period " + std::to_string(period_s) + " s must be > 0");
  }
  if (!(duration_s >= 0 && duration_s <= 3600)) {
    throw hk::ArgumentError("audio duration " + std::to_string(duration_s) + " s is outside [0, 3600] s");
  }
  std::vector<CueEvent> sorted(cues.begin(), cues.end());
  std::stable_sort(sorted.begin(), sorted.end(), [](const CueEvent& a, const CueEvent& b) { return a.tick < b.tick; });
  const auto total = static_cast<std::size_t>(std::llround(duration_s * kSampleRateHz));
  std::vector<float> out(total, 0.0f);
  Mixer mixer(params, nullptr, nullptr, nullptr);
  std::size_t pos = 0;
  for (const CueEvent& e : sorted) {
    const double at = static_cast<double>(e.tick) * period_s * kSampleRateHz;
    if (at < 0) continue;
    const auto sample = static_cast<std::size_t>(std::llround(at));
    if (sample >= total) break;
    if (sample > pos) {
      mixer.render(out.data() + pos, sample - pos);
      pos = sample;
    }
    mixer.trigger(e);
  }
  if (pos < total) mixer.render(out.data() + pos, total - pos);
  return out;
}

}  // namespace hk::audio
