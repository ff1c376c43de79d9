#pragma once
/// @file output.hpp
/// Audio out through PortAudio: a float32 stream at kSampleRateHz with small buffers,
/// pulling one AudioSource (the mixer) in PortAudio's callback. The output latency PortAudio reports is
/// logged at start. With no audio device, or any PortAudio error, the kiosk keeps running silent: the
/// constructor does not throw, running() is false, info().why_not says why and one warning is logged.
///
/// Threads: construct, stop and destroy AudioOutput objects from one non-real-time thread at a time
/// (PortAudio's set-up calls are not thread-safe). The callback runs on PortAudio's audio thread and
/// follows DESIGN.md "Real-time rules": it only calls AudioSource::render() and copies samples.

#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "audio/source.hpp"

namespace hk::audio {

/// What to open. Units in names.
struct OutputParams {
  /// Callback size [frames], in [32, 4096] (256 = 5.3 ms at 48 kHz). PortAudio then always calls back
  /// with exactly this many frames.
  int frames_per_buffer = 256;
  /// Output latency asked of the host API [s], in [0, 1]; 0 = the device's default low latency. The
  /// host API may grant more: info().reported_latency_s is what it granted.
  double suggested_latency_s = 0.010;
  /// Output device name, exactly as PortAudio lists it (e.g. "default", "pulse"); empty: the host's
  /// default output device.
  std::string device;
};

/// What was opened, for the log and the operator overlay. A snapshot taken when the stream started.
struct OutputInfo {
  bool running = false;             ///< the stream started and stop() was not called since
  std::string device_name;          ///< PortAudio's device name
  std::string host_api;             ///< e.g. "ALSA", "JACK Audio Connection Kit"
  int sample_rate_hz = 0;           ///< the stream's actual rate [Hz] (kSampleRateHz when running)
  int channels = 0;                 ///< 1 (mono) or 2 (the mono mix on both channels)
  int frames_per_buffer = 0;        ///< frames per callback
  double reported_latency_s = 0.0;  ///< Pa_GetStreamInfo()->outputLatency [s]
  std::string why_not;              ///< one line, when not running; empty otherwise
};

/// Real-time helper used by AudioOutput's callback, public so it can be tested without a device.
/// Pulls `frames` mono frames from `source` in chunks of at most `scratch.size()` frames and writes
/// each frame to all `channels` (>= 1) of the interleaved buffer `out` (frames · channels floats).
/// No allocation, lock, log or throw.
void render_interleaved(AudioSource& source, std::span<float> scratch, float* out, std::size_t frames,
                        int channels) noexcept;

/// Holds an output stream that takes samples faster than it could play them to the wall clock. ALSA's null
/// device (the kiosk's tests and any machine without a sound card configured that way) discards each buffer
/// at once, so PortAudio would call back flat out and the mixer would take a whole core. Over a window of
/// kWindow_s [s] of wall time the audio taken since the window began may run at most kMaxLead_s [s] ahead of
/// the wall clock; past that the callback waits. A real device never comes near it: within a window it takes
/// what it plays plus at most its buffer (tens of ms), and restarting the window every kWindow_s keeps a
/// sound card's clock drift (≤ 0.1 %: ≤ 10 ms a window) from adding up. Real-time: no allocation, lock or
/// throw.
class OutputPacer {
 public:
  static constexpr double kMaxLead_s = 0.25;  ///< audio taken ahead of the wall clock before waiting [s]
  static constexpr double kWindow_s = 10.0;   ///< the wall time over which the lead is counted [s]
  /// A pacer for a stream of `rate_hz` (> 0) frames a second.
  explicit OutputPacer(int rate_hz) noexcept : rate_hz_(rate_hz) {}
  /// `frames` frames were just taken at `now`: how long to wait so that the lead is at most kMaxLead_s
  /// (zero when it is within).
  std::chrono::nanoseconds after(std::size_t frames, std::chrono::steady_clock::time_point now) noexcept;

 private:
  int rate_hz_;
  bool started_ = false;
  std::chrono::steady_clock::time_point window_start_{};
  std::uint64_t window_frames_ = 0;  // frames taken since window_start_
};

/// One PortAudio output stream pulling one AudioSource. Not copyable or movable (PortAudio holds a
/// pointer to it). Several may exist; PortAudio is initialised by each and terminated when the last
/// one is destroyed (Pa_Initialize / Pa_Terminate are reference counted).
class AudioOutput {
 public:
  /// Opens and starts a float32 stream at kSampleRateHz on the chosen device, mono or (when the device
  /// has two or more channels) stereo with the mono mix on both; `source.render()` is called in the
  /// callback. `source` must outlive this object. Never throws for a missing device, an unknown device
  /// name, bad parameters or any PortAudio error: then running() is false, info().why_not says why and
  /// one spdlog warning is logged. On success one spdlog info line gives device, host API, rate, buffer
  /// size and the reported latency. ALSA/JACK chatter while PortAudio probes devices goes to spdlog's
  /// debug level instead of stderr.
  /// @throws std::bad_alloc only (building the message strings).
  AudioOutput(AudioSource& source, const OutputParams& params);
  /// Stops (as stop()) and closes the stream; Pa_Terminate when this is the last PortAudio user.
  ~AudioOutput();
  AudioOutput(const AudioOutput&) = delete;
  AudioOutput& operator=(const AudioOutput&) = delete;

  /// True while the stream is active: started, not stopped, and PortAudio has not ended it (e.g. the
  /// device went away). Owning thread.
  bool running() const;
  /// What was opened, or why not. Owning thread.
  const OutputInfo& info() const { return info_; }
  /// Callbacks served so far. Any thread.
  std::uint64_t callbacks() const { return callbacks_.load(std::memory_order_relaxed); }
  /// Callbacks whose statusFlags had paOutputUnderflow (a gap the visitor may hear). Any thread.
  std::uint64_t underflows() const { return underflows_.load(std::memory_order_relaxed); }
  /// Stops and closes the stream, letting queued buffers play out; no callback runs after it returns
  /// and the stream cannot be restarted (make a new AudioOutput). Sets info().running to false; the
  /// other info() fields stay. Idempotent. Owning thread.
  void stop();

 private:
  friend struct OutputCallback;  // output.cpp: PortAudio's C callback, which calls on_callback()
  void on_callback(float* out, std::size_t frames, bool underflow) noexcept;
  void give_up(const std::string& why);

  static constexpr std::size_t kMaxFrames = 4096;  // largest frames_per_buffer [frames]
  AudioSource& source_;
  OutputInfo info_;
  void* stream_ = nullptr;    // PaStream*
  bool initialised_ = false;  // this object holds one Pa_Initialize
  int channels_ = 1;          // fixed before the stream starts; read by the callback
  std::atomic<std::uint64_t> callbacks_{0}, underflows_{0};
  std::array<float, kMaxFrames> mono_{};  // the callback's scratch buffer
  OutputPacer pacer_{kSampleRateHz};      // the callback's; a device faster than real time waits here
};

}  // namespace hk::audio
