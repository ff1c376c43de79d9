#include "audio/earcons.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hk::audio {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
// Major pentatonic steps over two octaves [semitones above C4].
constexpr std::array<int, 10> kPentatonic{0, 2, 4, 7, 9, 12, 14, 16, 19, 21};
constexpr double kC4Hz = 261.6256;

}  // namespace

const char* cue_kind_name(CueKind kind) {
  switch (kind) {
    case CueKind::ContactBegin:
      return "contact_begin";
    case CueKind::ContactEnd:
      return "contact_end";
    case CueKind::Slide:
      return "slide";
    case CueKind::VertexContact:
      return "vertex_contact";
    case CueKind::ConvexCorner:
      return "convex_corner";
    case CueKind::LevelFiner:
      return "level_finer";
    case CueKind::LevelCoarser:
      return "level_coarser";
    case CueKind::WorkspaceEdge:
      return "workspace_edge";
    case CueKind::TextBlock:
      return "text_block";
    case CueKind::PopThrough:
      return "pop_through";
    case CueKind::TourStart:
      return "tour_start";
    case CueKind::Shutter:
      return "shutter";
  }
  return "unknown";
}

double curve_pitch_hz(int curve) {
  const int i = curve < 0 ? 0 : curve % static_cast<int>(kPentatonic.size());
  return kC4Hz * std::exp2(kPentatonic[static_cast<std::size_t>(i)] / 12.0);
}

EarconSynth::EarconSynth(const EarconParams& params, int sample_rate_hz) : params_(params), rate_(sample_rate_hz) {}

void EarconSynth::reset() noexcept {
  for (Voice& v : voices_) v.active = false;
  slide_active_ = false;
  grain_phase_ = 0;
  next_transient_at_ = now_;
}

int EarconSynth::active_voices() const noexcept {
  int n = 0;
  for (const Voice& v : voices_) n += v.active;
  return n;
}

float EarconSynth::next_noise() noexcept {
  // xorshift32: cheap, allocation-free white noise; quality is ample for band-passed grains.
  std::uint32_t x = noise_state_;
  x ^= x << 13;
  x ^= x >> 17;
  x ^= x << 5;
  noise_state_ = x;
  return static_cast<float>(static_cast<double>(x) * (2.0 / 4294967295.0) - 1.0);
}

void EarconSynth::start(const Shape& s) noexcept {
  // A free voice, or steal the one with the least remaining loudness.
  Voice* v = nullptr;
  float quietest = 1e30f;
  for (Voice& c : voices_) {
    if (!c.active) {
      v = &c;
      break;
    }
    const float loud = c.amp * c.env;
    if (loud < quietest) {
      quietest = loud;
      v = &c;
    }
  }
  const double fs = rate_;
  *v = Voice{};
  v->active = true;
  v->delay = static_cast<int>(std::lround(s.delay_s * fs));
  v->left = std::max(1, static_cast<int>(std::lround(s.duration_s * fs)));
  v->attack = std::max(1, static_cast<int>(std::lround(s.attack_s * fs)));
  v->release = std::max(1, static_cast<int>(std::lround(s.release_s * fs)));
  v->amp = static_cast<float>(s.amp);
  v->decay = s.tau_s > 0 ? static_cast<float>(std::exp(-1.0 / (s.tau_s * fs))) : 1.0f;
  v->noise_mix = static_cast<float>(s.noise_mix);
  v->omega = kTwoPi * s.freq_hz / fs;
  v->glide = std::pow(s.glide_to_hz / s.freq_hz, 1.0 / static_cast<double>(v->left));
  if (s.noise_mix > 0) {
    // RBJ audio-EQ cookbook band-pass, constant 0 dB peak gain, normalised by a0.
    const double w0 = kTwoPi * std::min(s.noise_hz, 0.45 * fs) / fs;
    const double alpha = std::sin(w0) / (2.0 * s.noise_q);
    const double a0 = 1.0 + alpha;
    v->b0 = static_cast<float>(alpha / a0);
    v->a1 = static_cast<float>(-2.0 * std::cos(w0) / a0);
    v->a2 = static_cast<float>((1.0 - alpha) / a0);
  }
}

double EarconSynth::transient_delay_s(bool claim) noexcept {
  // Transients (strikes and ticks) start at least kMinTransientGap apart: two clicks closer than
  // ~2–3 ms fuse into one for the ear, so a click that follows a corner tick within a tick or two is
  // pushed back to the end of the gap (never by more than kMaxTransientDelay, well inside the 10 ms in
  // which a cue must be heard).
  const long gap = static_cast<long>(kMinTransientGapS * rate_);
  const long max_delay = static_cast<long>(kMaxTransientDelayS * rate_);
  const long delay = std::clamp(next_transient_at_ - now_, 0L, max_delay);
  if (claim) next_transient_at_ = now_ + delay + gap;
  return static_cast<double>(delay) / rate_;
}

void EarconSynth::trigger(const CueEvent& e) noexcept {
  switch (e.kind) {
    case CueKind::ContactBegin:
    case CueKind::ContactEnd:
    case CueKind::Slide:
      contact_cue(e);
      break;
    case CueKind::ConvexCorner:
    case CueKind::VertexContact:
    case CueKind::WorkspaceEdge:
    case CueKind::PopThrough:
      knock_cue(e.kind);
      break;
    case CueKind::LevelFiner:
    case CueKind::LevelCoarser:
    case CueKind::TextBlock:
    case CueKind::TourStart:
    case CueKind::Shutter:
      signal_cue(e.kind);
      break;
  }
}

void EarconSynth::contact_cue(const CueEvent& e) noexcept {
  const double g = params_.gain;
  const double f = curve_pitch_hz(e.curve);
  switch (e.kind) {
    case CueKind::ContactBegin: {
      // Loudness from approach speed, with a floor so a gentle touch is still heard.
      const double v = std::clamp(static_cast<double>(e.speed_m_per_s) / params_.click_full_speed_m_per_s, 0.0, 1.0);
      const double a = g * (0.35 + 0.65 * v);
      const double d = transient_delay_s(false);                         // the strike's slot: the body starts with it
      start({f, f, 0.15, 0.0003, 0.030, 0.010, 0.8 * a, 0.0, 0, 1, d});  // the pitched body
      // The strike: a 2 ms bright noise transient, so a click that lands on the ringing body of the
      // previous one (contact chatter, 2 ms apart) is still heard as a new one.
      start({f, f, 0.002, 0.00005, 0.0004, 0.0003, 0.9 * a, 1.0, 4000, 0.7, transient_delay_s(true)});
      slide_curve_ = e.curve;
      break;
    }
    case CueKind::ContactEnd:
      start({0.75 * f, 0.75 * f, 0.06, 0.001, 0.012, 0.010, g * 0.2, 0.0, 0, 1, 0});
      slide_active_ = false;
      break;
    case CueKind::Slide:
      slide_speed_ = std::max(0.0f, e.speed_m_per_s);
      slide_curve_ = e.curve;
      slide_since_update_ = 0;
      slide_active_ = true;
      break;
    default:
      break;
  }
}

void EarconSynth::knock_cue(CueKind kind) noexcept {
  const double g = params_.gain;
  switch (kind) {
    case CueKind::ConvexCorner:
      start({2500, 2500, 0.008, 0.0001, 0.001, 0.002, g * 0.45, 0.5, 5000, 2.0, transient_delay_s(true)});
      break;
    case CueKind::VertexContact: {
      const double d = transient_delay_s(true);
      start({2000, 2000, 0.012, 0.0001, 0.0015, 0.003, g * 0.6, 0.5, 4000, 2.0, d});
      start({2000, 2000, 0.012, 0.0001, 0.0015, 0.003, g * 0.6, 0.5, 4000, 2.0, d + 0.030});
      break;
    }
    case CueKind::WorkspaceEdge: {
      // A knock on a wooden frame: a low thud with a short woody strike on top.
      const double d = transient_delay_s(true);
      start({180, 150, 0.15, 0.002, 0.06, 0.02, g * 0.6, 0.3, 400, 1.0, d});
      start({180, 180, 0.003, 0.00005, 0.0007, 0.0005, g * 0.5, 1.0, 1500, 0.8, d});
      break;
    }
    case CueKind::PopThrough: {
      // A membrane giving way: a noisy burst sweeping down two octaves over a low plop. Nothing else
      // glides down this fast (the coarser chirp falls one octave in 160 ms, as a pure tone).
      const double d = transient_delay_s(true);
      start({1600, 400, 0.05, 0.0005, 0.0, 0.015, g * 0.7, 0.8, 1000, 1.5, d});
      start({220, 110, 0.09, 0.001, 0.04, 0.02, g * 0.6, 0.0, 0, 1, d});
      slide_active_ = false;
      break;
    }
    default:
      break;
  }
}

void EarconSynth::signal_cue(CueKind kind) noexcept {
  const double g = params_.gain;
  switch (kind) {
    case CueKind::LevelFiner:
      start({500, 1000, 0.16, 0.005, 0.0, 0.03, g * 0.35, 0.0, 0, 1, 0});
      break;
    case CueKind::LevelCoarser:
      start({1000, 500, 0.16, 0.005, 0.0, 0.03, g * 0.35, 0.0, 0, 1, 0});
      break;
    case CueKind::TextBlock:
      // Text here (press Describe to hear it): two soft rising sine notes, a fifth apart (G5 then D6),
      // unlike every contact sound (no strike, no noise) and unlike the level chirps (two steps, not a glide).
      start({784, 784, 0.09, 0.004, 0.0, 0.04, g * 0.3, 0.0, 0, 1, 0});
      start({1175, 1175, 0.12, 0.004, 0.0, 0.05, g * 0.3, 0.0, 0, 1, 0.08});
      break;
    case CueKind::TourStart:
      // "Follow me": a rising C-major arpeggio, soft sine notes with no strike.
      start({523.25, 523.25, 0.08, 0.004, 0.0, 0.03, g * 0.3, 0.0, 0, 1, 0.0});
      start({659.25, 659.25, 0.08, 0.004, 0.0, 0.03, g * 0.3, 0.0, 0, 1, 0.07});
      start({783.99, 783.99, 0.12, 0.004, 0.0, 0.05, g * 0.3, 0.0, 0, 1, 0.14});
      break;
    case CueKind::Shutter:
      // A camera's shutter: two bright noise clicks 60 ms apart (the blades opening, then closing), the second
      // softer, over a faint low thump. Nothing else in the kiosk is two clicks.
      start({3000, 3000, 0.012, 0.0003, 0.003, 0.004, g * 0.8, 1.0, 3500, 1.2, 0.0});
      start({2500, 2500, 0.012, 0.0003, 0.003, 0.004, g * 0.55, 1.0, 3000, 1.2, 0.060});
      start({150, 150, 0.02, 0.001, 0.006, 0.008, g * 0.3, 0.0, 0, 1, 0.0});
      slide_active_ = false;
      break;
    default:
      break;
  }
}

void EarconSynth::render_add(float* out, std::size_t frames) noexcept {
  const double fs = rate_;
  const long timeout = static_cast<long>(params_.slide_timeout_s * fs);
  for (std::size_t i = 0; i < frames; ++i) {
    // Slide texture: one grain per slide_grain_spacing_m of sliding, started sample-exactly.
    if (slide_active_) {
      if (++slide_since_update_ > timeout) {
        slide_active_ = false;
      } else {
        const double rate = std::min(slide_speed_ / params_.slide_grain_spacing_m, params_.slide_max_grain_rate_hz);
        grain_phase_ += rate / fs;
        if (grain_phase_ >= 1.0) {
          grain_phase_ -= std::floor(grain_phase_);
          const double f = curve_pitch_hz(slide_curve_);
          const double loud = 0.4 + 0.6 * std::min(1.0, slide_speed_ / 0.1);
          start({f, f, 0.012, 0.0005, 0.003, 0.002, params_.gain * 0.18 * loud, 1.0, 2 * f, 3.0, 0});
        }
      }
    }
    float sum = 0.0f;
    for (Voice& v : voices_) {
      if (!v.active) continue;
      if (v.delay > 0) {
        --v.delay;
        continue;
      }
      float s = 0.0f;
      if (v.noise_mix < 1.0f) s += (1.0f - v.noise_mix) * static_cast<float>(std::sin(v.phase));
      if (v.noise_mix > 0.0f) {
        const float x0 = next_noise();
        const float y0 = v.b0 * (x0 - v.x2) - v.a1 * v.y1 - v.a2 * v.y2;
        v.x2 = v.x1;
        v.x1 = x0;
        v.y2 = v.y1;
        v.y1 = y0;
        s += v.noise_mix * 2.0f * y0;  // band-passed white noise is ~6 dB quieter than a sine: make it up
      }
      const float a = std::min(1.0f, static_cast<float>(v.age + 1) / static_cast<float>(v.attack));
      const float r = std::min(1.0f, static_cast<float>(v.left) / static_cast<float>(v.release));
      sum += v.amp * v.env * a * r * s;
      v.phase += v.omega;
      if (v.phase > kTwoPi) v.phase -= kTwoPi;
      v.omega *= v.glide;
      v.env *= v.decay;
      ++v.age;
      if (--v.left <= 0 || v.env < 1e-4f) v.active = false;
    }
    out[i] += sum;
    ++now_;
  }
}

}  // namespace hk::audio
