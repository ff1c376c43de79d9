#pragma once
/// @file earcons.hpp
/// Earcon synthesis from haptic cues. Each cue kind has its own short sound, designed
/// so that a listener can tell them apart without seeing anything:
///   ContactBegin  a pitched "tock" at the curve's pitch, loudness from approach speed;
///   ContactEnd    a soft, lower tock;
///   Slide         a texture of band-passed noise grains, one grain per `slide_grain_spacing_m` of
///                 sliding, so the grain rate follows the sliding speed (like running a nail along a
///                 ridged surface; cf. Gaver 1993, "What in the world do we hear?");
///   ConvexCorner  a short bright tick (high spectral centroid, 1 ms decay);
///   VertexContact a double tick (the proxy is held in a concave corner);
///   LevelFiner / LevelCoarser  a rising / falling chirp (an octave in 160 ms);
///   WorkspaceEdge a low thud;
///   TextBlock     two soft rising sine notes, G5 then D6 (text here: Describe reads it).
///   PopThrough    a membrane giving way: a 50 ms burst of band-passed noise around 1 kHz with a tone
///                 sweeping down two octaves (1600 → 400 Hz), over a low plop (220 → 110 Hz in 90 ms);
///   TourStart     "follow me": three soft rising sine notes, C5, E5, G5, 70 ms apart.
/// Each curve has its own pitch (curve_pitch_hz) so two touching shapes sound different. Clicks and ticks
/// start at least 3 ms apart (a later one waits, at most 6 ms), so each stays audible on its own.
/// Earcons as a design idea: Blattner, Sumikawa & Greenberg 1989; Brewster 1994.
///
/// Real-time: trigger() and render_add() allocate nothing, take no lock and never throw; the voice pool
/// is fixed (kMaxVoices) and the quietest voice is stolen when all are busy.

#include <array>
#include <cstddef>
#include <cstdint>

#include "audio/cue_event.hpp"
#include "audio/source.hpp"

namespace hk::audio {

/// Earcon tuning. Units in names.
struct EarconParams {
  double gain = 0.5;                       ///< overall earcon gain, linear [0, 1]
  double click_full_speed_m_per_s = 0.15;  ///< approach speed at which a contact click is loudest [m/s]
  double slide_grain_spacing_m = 0.002;    ///< sliding distance per texture grain [m]
  double slide_max_grain_rate_hz = 80.0;   ///< texture grain rate limit [Hz]
  double slide_timeout_s = 0.03;           ///< texture stops when no Slide cue came for this long [s]
};

/// The pitch of curve `curve` [Hz]: a major-pentatonic scale over two octaves from C4 (261.6 Hz), so
/// curves c and c+1 always differ (by 2 to 3 semitones) and any two of ten consecutive ids differ.
/// Curve −1 (none) gets C4.
double curve_pitch_hz(int curve);

/// Additive synthesiser of earcons (mono, float).
class EarconSynth {
 public:
  static constexpr int kMaxVoices = 32;

  explicit EarconSynth(const EarconParams& params = {}, int sample_rate_hz = kSampleRateHz);

  /// Starts the earcon of `cue` at the next rendered sample. Real-time safe.
  void trigger(const CueEvent& cue) noexcept;
  /// Adds the next `frames` samples of every sounding earcon into `out`. Real-time safe.
  void render_add(float* out, std::size_t frames) noexcept;
  /// Silences everything (a new session).
  void reset() noexcept;
  /// Voices sounding now (for tests and the operator overlay).
  int active_voices() const noexcept;
  /// True while the slide texture runs.
  bool sliding() const noexcept { return slide_active_; }
  const EarconParams& params() const noexcept { return params_; }

 private:
  struct Voice {  // 96 bytes; the pool is flat and fixed
    bool active = false;
    int delay = 0;                 ///< samples to wait before starting [samples]
    int left = 0;                  ///< samples still to play [samples]
    int attack = 1;                ///< attack length [samples]
    int age = 0;                   ///< samples played
    int release = 1;               ///< linear fade over the last `release` samples
    float amp = 0;                 ///< peak amplitude
    float env = 1;                 ///< exponential decay envelope
    float decay = 1;               ///< per-sample decay factor
    float noise_mix = 0;           ///< 0 = pure tone, 1 = pure band-passed noise
    double phase = 0;              ///< [rad]
    double omega = 0;              ///< tone phase step [rad/sample]
    double glide = 1;              ///< per-sample multiplier of omega (chirps)
    float b0 = 0, a1 = 0, a2 = 0;  ///< band-pass biquad (RBJ, constant 0 dB peak; b1 = 0, b2 = −b0)
    float x1 = 0, x2 = 0, y1 = 0, y2 = 0;
  };
  static_assert(sizeof(Voice) <= 96, "voices are walked every sample: keep them small");
  struct Shape {  // what a voice plays, in physical units
    double freq_hz, glide_to_hz, duration_s, attack_s, tau_s, release_s, amp, noise_mix, noise_hz, noise_q, delay_s;
  };
  void start(const Shape& s) noexcept;
  double transient_delay_s(bool claim) noexcept;
  /// The contact cues (ContactBegin, ContactEnd, Slide): pitched by the curve, the slide's state updated.
  void contact_cue(const CueEvent& e) noexcept;
  /// The knocks (ConvexCorner, VertexContact, WorkspaceEdge, PopThrough): strikes and thuds in transient slots.
  void knock_cue(CueKind kind) noexcept;
  /// The signals (LevelFiner, LevelCoarser, TextBlock, TourStart, Shutter): chirps, notes and the shutter.
  void signal_cue(CueKind kind) noexcept;
  static constexpr double kMinTransientGapS = 0.003;    ///< clicks start at least this far apart [s]
  static constexpr double kMaxTransientDelayS = 0.006;  ///< and are never pushed back further [s]
  float next_noise() noexcept;

  EarconParams params_;
  int rate_;
  std::array<Voice, kMaxVoices> voices_{};
  std::uint32_t noise_state_ = 0x9E3779B9u;
  // slide texture
  bool slide_active_ = false;
  double slide_speed_ = 0;  ///< [m/s]
  int slide_curve_ = -1;
  long slide_since_update_ = 0;  ///< samples since the last Slide cue
  double grain_phase_ = 0;       ///< fractional grains accumulated
  long now_ = 0;                 ///< samples rendered so far
  long next_transient_at_ = 0;   ///< earliest sample the next click may start at
};

}  // namespace hk::audio
