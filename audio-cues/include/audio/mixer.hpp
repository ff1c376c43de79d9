#pragma once
/// @file mixer.hpp
/// The kiosk's one audio mix: earcons from haptic cues plus speech, earcons
/// ducked under speech, master volume, and a soft limiter. Live, the audio callback drains the cue
/// queue the servo thread fills; headless, render_cue_timeline() places every cue sample-exactly at its
/// tick's time so the WAV lines up with trace.csv.

#include <cstddef>
#include <span>
#include <vector>

#include "audio/cue_event.hpp"
#include "audio/earcons.hpp"
#include "audio/source.hpp"
#include "audio/speech_stream.hpp"
#include "audio/spsc_ring.hpp"
#include "audio/volume.hpp"

namespace hk::audio {

/// Mixer tuning. Units in names.
struct MixerParams {
  EarconParams earcons;
  double duck_db = -14.0;         ///< earcon level change while speech plays [dB] (≤ 0)
  double duck_attack_s = 0.010;   ///< time constant of ducking down [s]
  double duck_release_s = 0.150;  ///< time constant of coming back up [s]
  double speech_gain = 0.9;       ///< speech level, linear
};

/// The mix. One consumer thread (the audio callback) calls render(); other threads only push cues into
/// the queue, cancel speech through the SpeechStream and change the Volume.
class Mixer final : public AudioSource {
 public:
  /// `cues` (may be null: no live cues), `speech` (may be null) and `volume` must outlive the mixer.
  /// `ui_cues` (may be null): a second queue, for cues of the window thread (the camera's shutter), drained
  /// the same way; each queue has its own single producer.
  Mixer(const MixerParams& params, SpscRing<CueEvent>* cues, SpeechStream* speech, const Volume* volume,
        SpscRing<CueEvent>* ui_cues = nullptr);

  /// Real-time: drains the cue queues (each cue starts at the beginning of this buffer), renders earcons
  /// and speech, ducks, applies the volume and limits. No allocation, lock or throw.
  void render(float* out, std::size_t frames) noexcept override;

  /// Starts a cue now (headless rendering and tests; the consumer thread only).
  void trigger(const CueEvent& cue) noexcept { synth_.trigger(cue); }
  /// Silences earcons (a new session). Consumer thread only.
  void reset() noexcept { synth_.reset(); }
  /// Cues taken from the queue so far.
  std::uint64_t cues_played() const noexcept { return cues_played_; }
  const EarconSynth& synth() const noexcept { return synth_; }

 private:
  static constexpr std::size_t kChunk = 512;  ///< internal block [samples]
  MixerParams params_;
  EarconSynth synth_;
  SpscRing<CueEvent>* cues_;
  SpscRing<CueEvent>* ui_cues_;
  SpeechStream* speech_;
  const Volume* volume_;
  float duck_ = 1.0f;          ///< current earcon gain from ducking
  float duck_down_, duck_up_;  ///< one-pole coefficients per sample
  float duck_floor_;
  std::uint64_t cues_played_ = 0;
  float earcon_buf_[kChunk];
  float speech_buf_[kChunk];
};

/// Renders the earcons of `cues` (sorted by tick, or not: they are sorted here) on the timeline of a servo
/// run: tick k sounds at sample round(k · period_s · sample_rate_hz). Returns duration_s of mono audio at
/// kSampleRateHz (volume: unity). Allocates (not real-time). Cues past the end are ignored.
/// @throws hk::ArgumentError if period_s ≤ 0 or duration_s is not in [0, 3600] s.
std::vector<float> render_cue_timeline(std::span<const CueEvent> cues, double period_s, double duration_s,
                                       const MixerParams& params = {});

}  // namespace hk::audio
