// Earcons rendered on a servo timeline and analysed as a listener's ear would have to: onsets, spectra,
// envelopes, pitch.
#include <gtest/gtest.h>

#include <vector>

#include "audio/earcons.hpp"
#include "audio/mixer.hpp"
#include "audio_analysis.hpp"
#include "hk/error.hpp"

namespace hk::audio {
namespace {

constexpr double kPeriod = 0.001;  // 1 kHz servo
constexpr int kRate = kSampleRateHz;

CueEvent cue(std::int64_t tick, CueKind kind, int curve = 0, float speed = 0.0f, int level = 0) {
  CueEvent e;
  e.tick = tick;
  e.kind = kind;
  e.curve = curve;
  e.speed_m_per_s = speed;
  e.level = static_cast<std::int16_t>(level);
  return e;
}

std::size_t at(std::int64_t tick) { return static_cast<std::size_t>(tick * kPeriod * kRate); }

TEST(Earcons, CurvePitchesArePentatonicAndNeighboursDiffer) {
  // Golden values: C4 = 261.63 Hz, D4 = 293.66 Hz, E4 = 329.63 Hz, G4 = 392.00 Hz (equal temperament, A4 = 440).
  EXPECT_NEAR(curve_pitch_hz(0), 261.63, 0.01);
  EXPECT_NEAR(curve_pitch_hz(1), 293.66, 0.01);
  EXPECT_NEAR(curve_pitch_hz(2), 329.63, 0.01);
  EXPECT_NEAR(curve_pitch_hz(3), 392.00, 0.01);
  for (int c = 0; c < 10; ++c) {
    for (int d = c + 1; d < 10; ++d)
      EXPECT_GT(std::fabs(curve_pitch_hz(c) / curve_pitch_hz(d) - 1.0), 0.1) << c << " " << d;
  }
}

// A known sequence of events: every one is heard within 10 ms after its tick, nothing is heard where no
// event is, and all is silent before the first and after the last has died away.
TEST(Earcons, KnownSequenceOnsetsLandWithin10msOfTheirEvents) {
  const std::vector<CueEvent> events{cue(100, CueKind::ContactBegin, 0, 0.1f),
                                     cue(300, CueKind::ConvexCorner),
                                     cue(500, CueKind::ContactEnd),
                                     cue(800, CueKind::ContactBegin, 1, 0.05f),
                                     cue(1000, CueKind::VertexContact, 1),
                                     cue(1300, CueKind::LevelFiner, -1, 0, 1),
                                     cue(1600, CueKind::LevelCoarser, -1, 0, 2),
                                     cue(1900, CueKind::WorkspaceEdge, -1)};
  const std::vector<float> x = render_cue_timeline(events, kPeriod, 2.4);
  ASSERT_EQ(x.size(), static_cast<std::size_t>(2.4 * kRate));
  const std::vector<std::size_t> on = test::onsets(x);
  // Every event has an onset in [t, t + 10 ms].
  for (const CueEvent& e : events) {
    const std::size_t t = at(e.tick);
    const bool found = std::any_of(on.begin(), on.end(), [&](std::size_t o) { return o >= t && o <= t + kRate / 100; });
    EXPECT_TRUE(found) << cue_kind_name(e.kind) << " at tick " << e.tick;
  }
  // Every onset belongs to an event: within 10 ms after one (the vertex earcon is a double tick: +30 ms).
  for (std::size_t o : on) {
    bool explained = false;
    for (const CueEvent& e : events) {
      const std::size_t t = at(e.tick) + (e.kind == CueKind::VertexContact ? 0 : 0);
      const std::size_t extra = e.kind == CueKind::VertexContact ? static_cast<std::size_t>(0.031 * kRate) : 0;
      explained = explained || (o >= t && o <= t + extra + kRate / 100);
    }
    EXPECT_TRUE(explained) << "onset at " << static_cast<double>(o) / kRate << " s has no event";
  }
  // Silence where there are no events: exactly zero before the first, and after the last has decayed.
  EXPECT_EQ(test::peak(x, 0, at(100)), 0.0);
  EXPECT_LT(test::peak(x, at(2200), x.size()), 1e-4);
  // Between events, after each earcon's tail (all are under 200 ms), the signal is silent.
  EXPECT_LT(test::peak(x, at(1850), at(1900)), 1e-4);
  EXPECT_LT(test::peak(x, at(700), at(800)), 1e-4);
}

// Corner and contact earcons differ measurably: a corner tick is brighter (spectral centroid) and shorter.
TEST(Earcons, CornerAndContactDifferInSpectrumAndEnvelope) {
  const std::vector<float> contact =
      render_cue_timeline(std::vector{cue(10, CueKind::ContactBegin, 0, 0.1f)}, kPeriod, 0.3);
  const std::vector<float> corner = render_cue_timeline(std::vector{cue(10, CueKind::ConvexCorner, 0)}, kPeriod, 0.3);
  const std::size_t t = at(10);
  const double c_contact = test::spectral_centroid(contact, t, 2048);
  const double c_corner = test::spectral_centroid(corner, t, 2048);
  EXPECT_GT(c_corner, 3.0 * c_contact) << "corner centroid " << c_corner << " Hz, contact " << c_contact << " Hz";
  const std::size_t d_contact = test::decay_length(contact, t, t + at(250));
  const std::size_t d_corner = test::decay_length(corner, t, t + at(250));
  EXPECT_GT(d_contact, 4 * d_corner) << "contact decays in " << d_contact << " samples, corner in " << d_corner;
}

// Two curves differ in pitch: the body of a contact click sits at the curve's pitch.
TEST(Earcons, TwoCurvesDifferInPitch) {
  const std::vector<float> a = render_cue_timeline(std::vector{cue(10, CueKind::ContactBegin, 0, 0.1f)}, kPeriod, 0.3);
  const std::vector<float> b = render_cue_timeline(std::vector{cue(10, CueKind::ContactBegin, 1, 0.1f)}, kPeriod, 0.3);
  const std::size_t from = at(10) + 480;  // after the 6 ms strike
  const double fa = test::dominant_frequency(a, from, 4800);
  const double fb = test::dominant_frequency(b, from, 4800);
  EXPECT_NEAR(fa, 261.63, 261.63 * 0.02);
  EXPECT_NEAR(fb, 293.66, 293.66 * 0.02);
}

// The text-block chime: two soft notes, G5 (784 Hz) then D6 (1175 Hz) 80 ms later, and no strike:
// unlike a contact click it has no noise burst at its start (low spectral centroid over its first 5 ms).
TEST(Earcons, TextBlockIsTwoRisingNotesWithoutAStrike) {
  const std::vector<float> x = render_cue_timeline(std::vector{cue(10, CueKind::TextBlock, 0)}, kPeriod, 0.4);
  const std::size_t t = at(10);
  EXPECT_NEAR(test::dominant_frequency(x, t + 960, 2400), 784.0, 784.0 * 0.03) << "first note";
  EXPECT_NEAR(test::dominant_frequency(x, t + 4800, 2400), 1175.0, 1175.0 * 0.03) << "second note, 80 ms on";
  const std::vector<float> click =
      render_cue_timeline(std::vector{cue(10, CueKind::ContactBegin, 0, 0.1f)}, kPeriod, 0.4);
  EXPECT_LT(test::spectral_centroid(x, t, 240), test::spectral_centroid(click, t, 240))
      << "no bright strike at the start";
  EXPECT_GT(test::rms(x, t, t + at(200)), 0.0);
  EXPECT_LT(test::peak(x, t + at(350), x.size()), 1e-4) << "over within 350 ms";
}

// The push-through earcon: a bright noisy burst at once, then a low plop falling from 220 Hz,
// all over within 150 ms; unlike the coarser chirp, which starts as a pure tone near 1 kHz.
TEST(Earcons, PopThroughIsABurstOverALowFallingPlop) {
  const std::vector<float> x = render_cue_timeline(std::vector{cue(10, CueKind::PopThrough, 0)}, kPeriod, 0.4);
  const std::size_t t = at(10);
  const double plop = test::dominant_frequency(x, t + at(55), 1440);  // 55–85 ms: the burst is over
  EXPECT_GT(plop, 100.0);
  EXPECT_LT(plop, 200.0) << "the plop has fallen below its 220 Hz start";
  const std::vector<float> coarser =
      render_cue_timeline(std::vector{cue(10, CueKind::LevelCoarser, -1, 0, 2)}, kPeriod, 0.4);
  EXPECT_GT(test::spectral_centroid(x, t, 480), 1.5 * test::spectral_centroid(coarser, t, 480)) << "a noisy start";
  EXPECT_GT(test::rms(x, t, t + at(50)), 0.0);
  EXPECT_LT(test::peak(x, t + at(150), x.size()), 1e-4) << "over within 150 ms";
}

// The guided tour's start: three rising notes, C5, E5, G5, 70 ms apart.
TEST(Earcons, TourStartIsARisingArpeggio) {
  const std::vector<float> x = render_cue_timeline(std::vector{cue(10, CueKind::TourStart, 0)}, kPeriod, 0.5);
  const std::size_t t = at(10);
  EXPECT_NEAR(test::dominant_frequency(x, t + at(10), 2400), 523.25, 523.25 * 0.03);
  EXPECT_NEAR(test::dominant_frequency(x, t + at(150), 4800), 783.99, 783.99 * 0.03);
  EXPECT_LT(test::peak(x, t + at(400), x.size()), 1e-4);
}

// The camera's shutter: two bright clicks 60 ms apart, the second softer, silence between them and
// after, over within 120 ms.
TEST(Earcons, ShutterIsTwoBrightClicksSixtyMillisecondsApart) {
  const std::vector<float> x = render_cue_timeline(std::vector{cue(10, CueKind::Shutter, -1)}, kPeriod, 0.3);
  const std::size_t t = at(10);
  const double first = test::peak(x, t, t + at(20)), second = test::peak(x, t + at(60), t + at(80));
  EXPECT_GT(first, 0.05);
  EXPECT_GT(second, 0.05);
  EXPECT_LT(second, first) << "the second click is softer";
  EXPECT_LT(test::peak(x, t + at(35), t + at(58)), 0.1 * second) << "silence between the clicks";
  EXPECT_LT(test::peak(x, t + at(120), x.size()), 1e-4) << "over within 120 ms";
  const std::vector<float> contact =
      render_cue_timeline(std::vector{cue(10, CueKind::ContactBegin, 0, 0.1f)}, kPeriod, 0.3);
  EXPECT_GT(test::spectral_centroid(x, t, 240), test::spectral_centroid(contact, t, 240))
      << "brighter than a wall's click";
}

TEST(Earcons, ContactLoudnessGrowsWithApproachSpeed) {
  const std::vector<float> soft =
      render_cue_timeline(std::vector{cue(10, CueKind::ContactBegin, 0, 0.01f)}, kPeriod, 0.2);
  const std::vector<float> hard =
      render_cue_timeline(std::vector{cue(10, CueKind::ContactBegin, 0, 0.15f)}, kPeriod, 0.2);
  const double ps = test::rms(soft, at(10), at(60)), ph = test::rms(hard, at(10), at(60));
  EXPECT_GT(ps, 0.0) << "a gentle touch must still be heard";
  EXPECT_GT(ph, 2.0 * ps);
}

TEST(Earcons, LevelChirpsRiseAndFall) {
  const std::vector<float> up = render_cue_timeline(std::vector{cue(10, CueKind::LevelFiner, -1, 0, 1)}, kPeriod, 0.3);
  const std::vector<float> down =
      render_cue_timeline(std::vector{cue(10, CueKind::LevelCoarser, -1, 0, 2)}, kPeriod, 0.3);
  const std::size_t t = at(10);
  const std::size_t n = 2400;  // 50 ms
  EXPECT_GT(test::dominant_frequency(up, t + at(105), n), 1.3 * test::dominant_frequency(up, t + at(5), n));
  EXPECT_LT(test::dominant_frequency(down, t + at(105), n), 0.77 * test::dominant_frequency(down, t + at(5), n));
}

// The slide texture's grain rate follows the sliding speed: one grain per 2 mm of sliding.
TEST(Earcons, SlideTextureRateFollowsSpeed) {
  for (float speed : {0.02f, 0.06f}) {
    std::vector<CueEvent> ev;
    for (std::int64_t k = 0; k < 1000; k += 5) ev.push_back(cue(k, CueKind::Slide, 0, speed));
    const std::vector<float> x = render_cue_timeline(ev, kPeriod, 1.0);
    const std::size_t grains = test::onsets(x, 1e-6).size();
    const double expected = speed / 0.002;  // grains per second
    EXPECT_NEAR(static_cast<double>(grains), expected, 0.15 * expected + 1) << "speed " << speed << " m/s";
  }
  // The texture stops by itself when the slide updates stop (no stuck sound).
  std::vector<CueEvent> ev;
  for (std::int64_t k = 0; k < 200; k += 5) ev.push_back(cue(k, CueKind::Slide, 0, 0.05f));
  const std::vector<float> x = render_cue_timeline(ev, kPeriod, 0.5);
  EXPECT_EQ(test::peak(x, at(260), x.size()), 0.0);
}

TEST(Earcons, VoicePoolSurvivesAFlood) {
  // 10 000 cues in one second, 10 per tick: the pool steals voices, the output stays finite and bounded.
  std::vector<CueEvent> ev;
  for (std::int64_t k = 0; k < 1000; ++k) {
    for (int j = 0; j < 10; ++j) ev.push_back(cue(k, static_cast<CueKind>(j % kCueKindCount), j, 0.2f));
  }
  const std::vector<float> x = render_cue_timeline(ev, kPeriod, 1.2);
  for (float v : x) {
    ASSERT_TRUE(std::isfinite(v));
    ASSERT_LE(std::fabs(v), 1.0f);
  }
}

TEST(Earcons, TimelineRejectsBadArguments) {
  EXPECT_THROW(render_cue_timeline({}, 0.0, 1.0), hk::ArgumentError);
  EXPECT_THROW(render_cue_timeline({}, 0.001, -1.0), hk::ArgumentError);
  EXPECT_THROW(render_cue_timeline({}, 0.001, 1e6), hk::ArgumentError);
  // Cues past the end or before the start are ignored, not a crash.
  const std::vector<float> x =
      render_cue_timeline(std::vector{cue(-5, CueKind::ContactBegin), cue(999999, CueKind::ContactBegin)}, 0.001, 0.1);
  EXPECT_EQ(test::peak(x, 0, x.size()), 0.0);
}

}  // namespace
}  // namespace hk::audio
