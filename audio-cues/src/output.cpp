// PortAudio output (see output.hpp). Set-up and tear-down run on the owning thread; only
// OutputCallback::call runs on PortAudio's audio thread.
#include "audio/output.hpp"

#include <dlfcn.h>
#include <portaudio.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <ctime>

namespace hk::audio {

void render_interleaved(AudioSource& source, std::span<float> scratch, float* out, std::size_t frames,
                        int channels) noexcept {
  const std::size_t ch = static_cast<std::size_t>(std::max(channels, 1));
  std::size_t done = 0;
  while (done < frames && !scratch.empty()) {
    const std::size_t n = std::min(frames - done, scratch.size());
    source.render(scratch.data(), n);
    float* dst = out + done * ch;
    if (ch == 1) {
      std::memcpy(dst, scratch.data(), n * sizeof(float));
    } else {
      for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t c = 0; c < ch; ++c) dst[i * ch + c] = scratch[i];
      }
    }
    done += n;
  }
}

/// PortAudio's C callback (a friend of AudioOutput). Real-time: no allocation, lock, log or throw.
struct OutputCallback {
  static int call(const void* /*in*/, void* out, unsigned long frames, const PaStreamCallbackTimeInfo* /*time*/,
                  PaStreamCallbackFlags flags, void* self) {
    static_cast<AudioOutput*>(self)->on_callback(static_cast<float*>(out), static_cast<std::size_t>(frames),
                                                 (flags & paOutputUnderflow) != 0);
    return paContinue;
  }
};

namespace {

// --- ALSA and JACK chatter while PortAudio probes devices --------------------------------------------
// With no sound card, Pa_Initialize makes libasound and libjack print ~40 lines to stderr. Both libraries
// are already loaded (libportaudio links them), so their message hooks are looked up at run time with
// dlsym: no build dependency on ALSA or JACK headers. The messages go to spdlog's debug level while the
// probe runs, and the libraries' default printers are restored afterwards (NULL restores them in both).

using AlsaHandler = void (*)(const char* file, int line, const char* function, int err, const char* fmt, ...);
using AlsaSetHandler = int (*)(AlsaHandler);
using JackSetFunction = void (*)(void (*)(const char*));

[[gnu::format(printf, 5, 6)]] void alsa_to_debug(const char* file, int line, const char* function, int err,
                                                 const char* fmt, ...) {
  char msg[512];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(msg, sizeof msg, fmt ? fmt : "", ap);
  va_end(ap);
  spdlog::debug("audio: ALSA {}:{} ({}): {} [err {}]", file ? file : "?", line, function ? function : "?", msg, err);
}

void jack_to_debug(const char* msg) { spdlog::debug("audio: JACK: {}", msg ? msg : ""); }

template <class F>
F lookup(const char* name) {
  void* p = dlsym(RTLD_DEFAULT, name);
  F f = nullptr;
  static_assert(sizeof f == sizeof p);
  std::memcpy(&f, &p, sizeof f);  // object pointer -> function pointer, as POSIX guarantees works
  return f;
}

class ProbeMessagesToDebug {
 public:
  ProbeMessagesToDebug()
      : alsa_(lookup<AlsaSetHandler>("snd_lib_error_set_handler")),
        jack_error_(lookup<JackSetFunction>("jack_set_error_function")),
        jack_info_(lookup<JackSetFunction>("jack_set_info_function")) {
    if (alsa_) alsa_(&alsa_to_debug);
    if (jack_error_) jack_error_(&jack_to_debug);
    if (jack_info_) jack_info_(&jack_to_debug);
  }
  ~ProbeMessagesToDebug() {
    if (alsa_) alsa_(nullptr);
    if (jack_error_) jack_error_(nullptr);
    if (jack_info_) jack_info_(nullptr);
  }
  ProbeMessagesToDebug(const ProbeMessagesToDebug&) = delete;
  ProbeMessagesToDebug& operator=(const ProbeMessagesToDebug&) = delete;

 private:
  AlsaSetHandler alsa_;
  JackSetFunction jack_error_, jack_info_;
};

std::string host_api_names() {
  std::string s;
  for (PaHostApiIndex i = 0; i < Pa_GetHostApiCount(); ++i) {
    const PaHostApiInfo* h = Pa_GetHostApiInfo(i);
    if (!h) continue;
    if (!s.empty()) s += ", ";
    s += h->name ? h->name : "?";
  }
  return s.empty() ? "none" : s;
}

std::string output_device_names() {
  std::string s;
  for (PaDeviceIndex i = 0; i < Pa_GetDeviceCount(); ++i) {
    const PaDeviceInfo* d = Pa_GetDeviceInfo(i);
    if (!d || d->maxOutputChannels <= 0) continue;
    if (!s.empty()) s += ", ";
    s += std::string("'") + (d->name ? d->name : "?") + "'";
    if (s.size() > 300) return s + ", ...";
  }
  return s.empty() ? "none" : s;
}

}  // namespace

std::chrono::nanoseconds OutputPacer::after(std::size_t frames, std::chrono::steady_clock::time_point now) noexcept {
  using std::chrono::duration;
  if (!started_ || now - window_start_ > duration<double>(kWindow_s)) {
    started_ = true;
    window_start_ = now;
    window_frames_ = 0;
  }
  window_frames_ += frames;
  const double lead_s = static_cast<double>(window_frames_) / rate_hz_ - duration<double>(now - window_start_).count();
  if (lead_s <= kMaxLead_s) return std::chrono::nanoseconds(0);
  return std::chrono::duration_cast<std::chrono::nanoseconds>(duration<double>(lead_s - kMaxLead_s));
}

void AudioOutput::on_callback(float* out, std::size_t frames, bool underflow) noexcept {
  render_interleaved(source_, mono_, out, frames, channels_);
  callbacks_.fetch_add(1, std::memory_order_relaxed);
  if (underflow) underflows_.fetch_add(1, std::memory_order_relaxed);
  const std::chrono::nanoseconds wait = pacer_.after(frames, std::chrono::steady_clock::now());
  if (wait.count() > 0) {  // a device that discards (ALSA null): held to the wall clock
    const timespec ts{static_cast<time_t>(wait.count() / 1'000'000'000),
                      static_cast<long>(wait.count() % 1'000'000'000)};
    ::nanosleep(&ts, nullptr);
  }
}

void AudioOutput::give_up(const std::string& why) {
  if (stream_) {
    Pa_CloseStream(static_cast<PaStream*>(stream_));
    stream_ = nullptr;
  }
  if (initialised_) {
    Pa_Terminate();
    initialised_ = false;
  }
  info_ = OutputInfo{};
  info_.why_not = why;
  spdlog::warn("audio: no output device ({}); the kiosk continues without sound", why);
}

AudioOutput::AudioOutput(AudioSource& source, const OutputParams& params) : source_(source) {
  if (params.frames_per_buffer < 32 || params.frames_per_buffer > static_cast<int>(kMaxFrames)) {
    give_up("frames_per_buffer " + std::to_string(params.frames_per_buffer) + " is outside [32, 4096]");
    return;
  }
  if (!std::isfinite(params.suggested_latency_s) || params.suggested_latency_s < 0 || params.suggested_latency_s > 1) {
    give_up("suggested_latency_s " + std::to_string(params.suggested_latency_s) + " is outside [0, 1] s");
    return;
  }
  ProbeMessagesToDebug quiet;
  PaError e = Pa_Initialize();
  if (e != paNoError) {
    give_up(std::string("PortAudio did not start: ") + Pa_GetErrorText(e));
    return;
  }
  initialised_ = true;
  PaDeviceIndex dev = paNoDevice;
  if (params.device.empty()) {
    dev = Pa_GetDefaultOutputDevice();
    if (dev == paNoDevice) {
      give_up("PortAudio finds no output device; host APIs: " + host_api_names());
      return;
    }
  } else {
    for (PaDeviceIndex i = 0; i < Pa_GetDeviceCount(); ++i) {
      const PaDeviceInfo* d = Pa_GetDeviceInfo(i);
      if (d && d->maxOutputChannels > 0 && d->name && params.device == d->name) {
        dev = i;
        break;
      }
    }
    if (dev == paNoDevice) {
      give_up("no output device named '" + params.device + "'; PortAudio's output devices: " + output_device_names());
      return;
    }
  }
  const PaDeviceInfo* di = Pa_GetDeviceInfo(dev);
  if (!di) {
    give_up("PortAudio lost device " + std::to_string(dev));
    return;
  }
  const std::string name = di->name ? di->name : "?";
  PaStreamParameters out{};
  out.device = dev;
  out.channelCount = std::clamp(di->maxOutputChannels, 1, 2);
  out.sampleFormat = paFloat32;
  out.suggestedLatency = params.suggested_latency_s > 0 ? params.suggested_latency_s : di->defaultLowOutputLatency;
  channels_ = out.channelCount;
  PaStream* stream = nullptr;
  // paNoFlag: PortAudio clips (and dithers) when the device takes integers, so an overshoot is not a wrap.
  e = Pa_OpenStream(&stream, nullptr, &out, kSampleRateHz, static_cast<unsigned long>(params.frames_per_buffer),
                    paNoFlag, &OutputCallback::call, this);
  if (e != paNoError) {
    give_up("cannot open '" + name + "' at " + std::to_string(kSampleRateHz) + " Hz: " + Pa_GetErrorText(e));
    return;
  }
  stream_ = stream;
  e = Pa_StartStream(stream);
  if (e != paNoError) {
    give_up("cannot start '" + name + "': " + Pa_GetErrorText(e));
    return;
  }
  const PaHostApiInfo* hi = Pa_GetHostApiInfo(di->hostApi);
  const PaStreamInfo* si = Pa_GetStreamInfo(stream);
  info_.running = true;
  info_.device_name = name;
  info_.host_api = hi && hi->name ? hi->name : "?";
  info_.sample_rate_hz = si ? static_cast<int>(std::lround(si->sampleRate)) : kSampleRateHz;
  info_.channels = channels_;
  info_.frames_per_buffer = params.frames_per_buffer;
  info_.reported_latency_s = si ? si->outputLatency : 0.0;
  spdlog::info(
      "audio: output '{}' via {}, {} Hz, {} channel(s), {} frames per buffer ({:.1f} ms), reported output latency "
      "{:.1f} ms",
      info_.device_name, info_.host_api, info_.sample_rate_hz, info_.channels, info_.frames_per_buffer,
      1e3 * info_.frames_per_buffer / std::max(info_.sample_rate_hz, 1), info_.reported_latency_s * 1e3);
}

bool AudioOutput::running() const { return stream_ && Pa_IsStreamActive(static_cast<PaStream*>(stream_)) == 1; }

void AudioOutput::stop() {
  if (stream_) {
    auto* s = static_cast<PaStream*>(stream_);
    if (Pa_IsStreamStopped(s) == 0) Pa_StopStream(s);
    Pa_CloseStream(s);
    stream_ = nullptr;
  }
  info_.running = false;
}

AudioOutput::~AudioOutput() {
  stop();
  if (initialised_) Pa_Terminate();
}

}  // namespace hk::audio
