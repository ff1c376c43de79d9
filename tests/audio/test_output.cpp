// Audio output: with no device the kiosk runs on silent and says why; with one, callbacks flow. Every
// test here passes both on this container (no sound card) and on a machine with one.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <thread>
#include <vector>

#include "audio/output.hpp"

namespace hk::audio {
namespace {

// Counts render calls and frames; writes a ramp that continues across calls (sample k = k).
struct CountingSource final : AudioSource {
  std::atomic<std::uint64_t> calls{0}, frames{0};
  float next = 0.0f;
  void render(float* out, std::size_t n) noexcept override {
    for (std::size_t i = 0; i < n; ++i) out[i] = next++;
    calls.fetch_add(1, std::memory_order_relaxed);
    frames.fetch_add(n, std::memory_order_relaxed);
  }
};

bool one_line(const std::string& s) { return !s.empty() && s.find('\n') == std::string::npos; }

// Waits up to `timeout` for at least `n` callbacks.
bool wait_for_callbacks(const AudioOutput& out, std::uint64_t n, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (out.callbacks() < n && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  return out.callbacks() >= n;
}

TEST(Output, RunsOrSaysWhyNotWithoutThrowing) {
  CountingSource src;
  OutputParams p;
  std::unique_ptr<AudioOutput> out;
  ASSERT_NO_THROW(out = std::make_unique<AudioOutput>(src, p));
  const OutputInfo& in = out->info();
  if (!out->running()) {
    // This container: no sound card. Silent, with a one-line reason, and nothing pulled.
    EXPECT_FALSE(in.running);
    EXPECT_TRUE(one_line(in.why_not)) << in.why_not;
    EXPECT_EQ(out->callbacks(), 0u);
    EXPECT_EQ(src.calls.load(), 0u);
    return;
  }
  // A machine with a sound card: the stream is what we asked for and the source is pulled.
  EXPECT_TRUE(in.running);
  EXPECT_TRUE(in.why_not.empty()) << in.why_not;
  EXPECT_FALSE(in.device_name.empty());
  EXPECT_FALSE(in.host_api.empty());
  EXPECT_EQ(in.sample_rate_hz, kSampleRateHz);
  EXPECT_EQ(in.frames_per_buffer, p.frames_per_buffer);
  EXPECT_TRUE(in.channels == 1 || in.channels == 2) << in.channels;
  EXPECT_GE(in.reported_latency_s, 0.0);
  EXPECT_LT(in.reported_latency_s, 1.0);
  ASSERT_TRUE(wait_for_callbacks(*out, 20, std::chrono::milliseconds(1000))) << out->callbacks() << " callbacks in 1 s";
  // Fixed-size callbacks: every callback pulled exactly frames_per_buffer frames (one render call each).
  out->stop();
  EXPECT_FALSE(out->running());
  EXPECT_FALSE(out->info().running);
  EXPECT_EQ(src.frames.load(), out->callbacks() * static_cast<std::uint64_t>(p.frames_per_buffer));
}

TEST(Output, BadParametersAndUnknownDeviceDoNotThrow) {
  CountingSource src;
  for (int frames : {0, 31, 4097, 1 << 20}) {
    OutputParams p;
    p.frames_per_buffer = frames;
    AudioOutput a(src, p);
    EXPECT_FALSE(a.running());
    EXPECT_TRUE(one_line(a.info().why_not));
    EXPECT_NE(a.info().why_not.find("frames_per_buffer"), std::string::npos) << a.info().why_not;
  }
  for (double lat : {-0.01, 2.0, std::numeric_limits<double>::quiet_NaN()}) {
    OutputParams p;
    p.suggested_latency_s = lat;
    AudioOutput a(src, p);
    EXPECT_FALSE(a.running());
    EXPECT_NE(a.info().why_not.find("suggested_latency_s"), std::string::npos) << a.info().why_not;
  }
  OutputParams q;
  q.device = "no such device 1234";
  AudioOutput b(src, q);
  EXPECT_FALSE(b.running());
  EXPECT_TRUE(one_line(b.info().why_not));
  EXPECT_NE(b.info().why_not.find("no such device 1234"), std::string::npos) << b.info().why_not;
  EXPECT_EQ(src.calls.load(), 0u);
}

// PortAudio is reference counted: two outputs at once, then a third after both are gone, all behave.
TEST(Output, SeveralOutputsShareOnePortAudio) {
  CountingSource s1, s2, s3;
  bool first_ran = false;
  std::string first_why;
  {
    AudioOutput a(s1, {});
    first_ran = a.running();
    first_why = a.info().why_not;
    AudioOutput b(s2, {});  // may fail on an exclusive device; must not throw or disturb `a`
    EXPECT_EQ(a.running(), first_ran);
    if (!b.running()) {
      EXPECT_TRUE(one_line(b.info().why_not));
    }
  }
  AudioOutput c(s3, {});
  EXPECT_EQ(c.running(), first_ran) << c.info().why_not;
  if (!first_ran) {
    EXPECT_EQ(c.info().why_not, first_why);
  } else {
    EXPECT_TRUE(wait_for_callbacks(c, 5, std::chrono::milliseconds(1000)));
  }
}

TEST(Output, StopIsIdempotentAndEndsTheCallbacks) {
  CountingSource src;
  AudioOutput out(src, {});
  if (out.running()) {
    ASSERT_TRUE(wait_for_callbacks(out, 3, std::chrono::milliseconds(1000)));
  }
  out.stop();
  EXPECT_FALSE(out.running());
  const std::uint64_t n = out.callbacks(), calls = src.calls.load();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(out.callbacks(), n);
  EXPECT_EQ(src.calls.load(), calls);
  out.stop();
  EXPECT_FALSE(out.running());
}

// The callback's copy, checked without a device: mono pulled in scratch-sized chunks, in order, and
// written to every channel of the interleaved buffer.
// A device that discards each buffer at once (ALSA's null device) is held to the wall clock: audio runs at
// most kMaxLead_s ahead, and each wait is exactly what brings the lead back to it.
TEST(OutputPacer, ADeviceFasterThanRealTimeWaitsForTheWallClock) {
  using namespace std::chrono;
  OutputPacer pacer(48000);
  auto t = steady_clock::time_point{} + hours(1);
  std::size_t frames_before_wait = 0;
  nanoseconds first_wait{0};
  for (int i = 0; i < 100 && first_wait.count() == 0; ++i) {  // no time passes between callbacks
    first_wait = pacer.after(512, t);
    if (first_wait.count() == 0) frames_before_wait += 512;
  }
  // 0.25 s is 12000 frames: the 24th buffer (12288 frames) is the first past it, by 288 frames = 6 ms.
  EXPECT_EQ(frames_before_wait, 23u * 512u);
  EXPECT_NEAR(duration<double>(first_wait).count(), 288.0 / 48000.0, 1e-9);
  // Waiting as asked, the stream then runs at the wall clock's pace: one buffer's time a buffer (for the rest
  // of the 10 s window; the next window starts the count again).
  t += first_wait;
  for (int i = 0; i < 900; ++i) {
    const nanoseconds w = pacer.after(512, t);
    EXPECT_NEAR(duration<double>(w).count(), 512.0 / 48000.0, 1e-6);
    t += w;
  }
}

// A real device never waits: its buffer primed at the start, callbacks with jitter, and a clock 0.1 % fast
// for a whole day.
TEST(OutputPacer, ARealDeviceNeverWaitsEvenWithJitterAndDrift) {
  using namespace std::chrono;
  OutputPacer pacer(48000);
  const auto start = steady_clock::time_point{} + hours(1);
  EXPECT_EQ(pacer.after(4096, start).count(), 0) << "the buffer primed at once";
  const double period_s = 512.0 / 48000.0 / 1.001;  // the card plays 0.1 % fast
  int waits = 0;
  for (long i = 1; i < 24L * 3600 * 94; ++i) {             // a day of callbacks
    const double jitter_s = ((i * 7919) % 11 - 5) * 1e-3;  // ±5 ms
    const auto now = start + duration_cast<nanoseconds>(duration<double>(i * period_s + jitter_s));
    waits += pacer.after(512, now).count() > 0;
  }
  EXPECT_EQ(waits, 0);
}

TEST(Output, RenderInterleavedDuplicatesMonoAcrossChannelsInChunks) {
  std::vector<float> scratch(4096);
  for (int channels : {1, 2}) {
    SCOPED_TRACE(channels);
    CountingSource src;
    const std::size_t frames = 5000;  // more than the scratch: two render calls
    std::vector<float> out(frames * static_cast<std::size_t>(channels) + 1, -7.0f);
    render_interleaved(src, scratch, out.data(), frames, channels);
    EXPECT_EQ(src.calls.load(), 2u);
    EXPECT_EQ(src.frames.load(), frames);
    for (std::size_t i = 0; i < frames; ++i) {
      for (int c = 0; c < channels; ++c)
        ASSERT_EQ(out[i * static_cast<std::size_t>(channels) + static_cast<std::size_t>(c)], static_cast<float>(i))
            << i;
    }
    EXPECT_EQ(out.back(), -7.0f) << "wrote past the end";
  }
  CountingSource none;
  std::vector<float> out(8, -7.0f);
  render_interleaved(none, scratch, out.data(), 0, 2);
  EXPECT_EQ(none.calls.load(), 0u);
  EXPECT_EQ(out[0], -7.0f);
}

}  // namespace
}  // namespace hk::audio
