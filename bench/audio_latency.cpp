// PortAudio output on this machine: opens an output with the
// kiosk's settings, plays a quiet 440 Hz tone for a while and prints one JSON object per line: the
// device, host API, buffer size, the output latency PortAudio reports, callbacks, underflows, and the
// spread of the period between callbacks (p50 / p99 / max, and the mean rate the device pulled at;
// "paced": false when the device is not clocked, e.g. ALSA's null PCM, see below).
// With no device it prints why (the kiosk then runs silent) and exits 0.
//
// Usage: bench_audio_latency [--device NAME] [--frames N] [--latency S] [--seconds S] [--verbose]
// --verbose shows spdlog's debug lines (ALSA/JACK messages from PortAudio's device probe).
// Log lines go to stderr, results to stdout.
//
// Without a sound card (a container), ALSA's null PCM gives PortAudio a device that accepts any buffer
// set-up, so the reported latency of PortAudio's buffer sizing can still be read; it is not clocked, so
// the callback periods then mean nothing ("paced": false):
//   printf 'pcm.!default { type null }\n' > /tmp/null.conf
//   ALSA_CONFIG_PATH=/usr/share/alsa/alsa.conf:/tmp/null.conf bench_audio_latency
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "audio/output.hpp"

namespace {

// A 440 Hz tone at −26 dBFS that stamps the time of every render call (one per callback).
struct Tone final : hk::audio::AudioSource {
  double phase = 0;
  std::vector<std::int64_t> stamps;  // steady_clock [ns], sized before the stream starts
  std::size_t n = 0;                 // stamps written (audio thread; read after stop())
  std::uint64_t frames = 0;
  void render(float* out, std::size_t count) noexcept override {
    if (n < stamps.size()) {
      stamps[n++] =
          std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
              .count();
    }
    const double step = 2 * std::numbers::pi * 440.0 / hk::audio::kSampleRateHz;
    for (std::size_t i = 0; i < count; ++i) {
      out[i] = 0.05f * static_cast<float>(std::sin(phase));
      phase = std::fmod(phase + step, 2 * std::numbers::pi);
    }
    frames += count;
  }
};

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace

int main(int argc, char** argv) {
  spdlog::set_default_logger(spdlog::stderr_color_mt("bench"));
  hk::audio::OutputParams p;
  double seconds = 2.0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--frames" && has_value) {
      p.frames_per_buffer = std::atoi(argv[++i]);
    } else if (a == "--device" && has_value) {
      p.device = argv[++i];
    } else if (a == "--latency" && has_value) {
      p.suggested_latency_s = std::atof(argv[++i]);
    } else if (a == "--seconds" && has_value) {
      seconds = std::clamp(std::atof(argv[++i]), 0.1, 60.0);
    } else if (a == "--verbose") {
      spdlog::set_level(spdlog::level::debug);
    } else {
      std::fprintf(stderr, "usage: %s [--device NAME] [--frames N] [--latency S] [--seconds S] [--verbose]\n", argv[0]);
      return 2;
    }
  }
  Tone tone;
  tone.stamps.resize(1 << 20);  // plenty even if a null device pulls faster than real time
  hk::audio::AudioOutput out(tone, p);
  const hk::audio::OutputInfo& in = out.info();
  if (!out.running()) {
    std::printf("{\"running\": false, \"why_not\": %s}\n", json_string(in.why_not).c_str());
    return 0;
  }
  std::printf(
      "{\"running\": true, \"device\": %s, \"host_api\": %s, \"sample_rate_hz\": %d, \"channels\": %d, "
      "\"frames_per_buffer\": %d, \"buffer_ms\": %.3f, \"suggested_latency_ms\": %.3f, \"reported_latency_ms\": "
      "%.3f}\n",
      json_string(in.device_name).c_str(), json_string(in.host_api).c_str(), in.sample_rate_hz, in.channels,
      in.frames_per_buffer, 1e3 * in.frames_per_buffer / in.sample_rate_hz, p.suggested_latency_s * 1e3,
      in.reported_latency_s * 1e3);
  std::fflush(stdout);
  const auto t0 = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  out.stop();  // joins PortAudio's thread: tone.stamps / n / frames are ours to read from here
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  std::vector<double> dt_ms;
  for (std::size_t i = 1; i < tone.n; ++i)
    dt_ms.push_back(static_cast<double>(tone.stamps[i] - tone.stamps[i - 1]) / 1e6);
  std::sort(dt_ms.begin(), dt_ms.end());
  auto pct = [&](double q) {
    return dt_ms.empty() ? 0.0
                         : dt_ms[static_cast<std::size_t>(std::lround(q * static_cast<double>(dt_ms.size() - 1)))];
  };
  const double span_s = tone.n >= 2 ? static_cast<double>(tone.stamps[tone.n - 1] - tone.stamps[0]) / 1e9 : 0.0;
  const double pulled_hz = span_s > 0 ? static_cast<double>(tone.n - 1) * in.frames_per_buffer / span_s : 0.0;
  // A device that is not paced by a clock (ALSA's null PCM) pulls as fast as the CPU allows: then the
  // period figures describe the CPU, not a sound card, and "paced" says so.
  const bool paced = pulled_hz > 0 && pulled_hz < 1.5 * in.sample_rate_hz;
  std::printf(
      "{\"seconds\": %.3f, \"callbacks\": %llu, \"underflows\": %llu, \"frames\": %llu, \"pulled_rate_hz\": %.1f, "
      "\"paced\": %s, "
      "\"period_ms\": {\"expected\": %.3f, \"p50\": %.3f, \"p99\": %.3f, \"min\": %.3f, \"max\": %.3f}, "
      "\"jitter_ms\": {\"p99_minus_p50\": %.3f}}\n",
      elapsed_s, static_cast<unsigned long long>(out.callbacks()), static_cast<unsigned long long>(out.underflows()),
      static_cast<unsigned long long>(tone.frames), pulled_hz, paced ? "true" : "false",
      1e3 * in.frames_per_buffer / in.sample_rate_hz, pct(0.5), pct(0.99), dt_ms.empty() ? 0.0 : dt_ms.front(),
      dt_ms.empty() ? 0.0 : dt_ms.back(), pct(0.99) - pct(0.5));
  return 0;
}
