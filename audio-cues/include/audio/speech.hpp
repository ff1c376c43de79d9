#pragma once
/// @file speech.hpp
/// Speech with espeak-ng, synthesised into our own mixer (issue 4, item 2): espeak-ng only makes
/// samples (AUDIO_OUTPUT_SYNCHRONOUS + espeak_SetSynthCallback, never its own playback); they are
/// resampled from espeak-ng's rate (22050 Hz) to kSampleRateHz with libsamplerate and handed to the audio
/// callback through a SpeechStream, so speech can be cut at once, repeated, and mixed with the earcons
/// (which the mixer ducks under it).
///
/// espeak-ng is one process-wide library that is not thread-safe: every call into it made here is
/// serialised by one process-wide mutex, and it is initialised once per process (on first use). Nothing
/// else in the process should call espeak-ng directly.

#include "hk/error.hpp"
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "audio/source.hpp"
#include "audio/speech_stream.hpp"

namespace hk::audio {

/// Voice settings. Units in names.
struct SpeechParams {
  /// espeak-ng voice name as espeak_SetVoiceByName takes it ("en", "en-us", "de", "en+f3" for a variant).
  /// espeak-ng accepts an unknown variant after '+' silently (the base voice is used).
  std::string voice = "en";
  int rate_wpm = 165;  ///< speaking rate [words/min], [80, 450] (espeakRATE_MINIMUM .. espeakRATE_MAXIMUM)
  int pitch = 50;      ///< base pitch, [0, 100] (espeakPITCH); 50 is the voice's normal pitch

  bool operator==(const SpeechParams&) const = default;
};

/// espeak-ng could not start, a voice or parameter was refused, or a text is too long. what() is one
/// line naming the voice / parameter and the limit, e.g. "speech: espeak-ng has no voice 'xx'".
class SpeechError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// Longest text spoken at once [bytes of UTF-8]; longer text is refused (a catalogue message is ≤ 1000).
inline constexpr std::size_t kMaxSpeechTextBytes = 4000;

/// Blocking: `text` (UTF-8, plain text, not SSML) → mono samples in [−1, 1] at kSampleRateHz, including
/// espeak-ng's short trailing pause. Empty text → empty result (the parameters are still checked).
/// Thread-safe: serialised with every other espeak-ng call of the process, so it also waits while a
/// Speaker synthesises an utterance. Allocates; not for the audio callback. About 600× faster than real
/// time on a desktop core (6 s of speech in ~10 ms).
/// @throws SpeechError on an unknown voice, rate / pitch out of range, text over kMaxSpeechTextBytes, or
///         when espeak-ng cannot be initialised (its data missing) or fails.
std::vector<float> synthesize_speech(std::string_view text, const SpeechParams& params);

/// The kiosk's speaker: one worker thread synthesises each text into a SpeechStream as it goes (every
/// ~100 ms of espeak-ng output is resampled and pushed at once, so the first block reaches the mixer long
/// before the sentence is done). The Speaker is the stream's only producer: one Speaker per stream.
///
/// Threads: say / repeat / cancel / busy / last_text / log / wait_idle may be called from any thread
/// except the audio callback; each takes a short lock and returns in microseconds (wait_idle waits).
class Speaker {
 public:
  /// Checks the voice and parameters and starts the worker. `stream` must outlive the speaker.
  /// @throws SpeechError if espeak-ng cannot be initialised or the voice / parameters are refused.
  Speaker(SpeechStream& stream, const SpeechParams& params);
  /// Cancels speech (stream.cancel()), stops synthesis (within one espeak-ng buffer, ~0.2 ms of work) and
  /// joins the worker. Does not wait for the mixer.
  ~Speaker();
  Speaker(const Speaker&) = delete;
  Speaker& operator=(const Speaker&) = delete;

  /// Cuts off what is playing or queued (stream.cancel(): the mixer drops it within one audio buffer plus
  /// SpeechStream::kFadeSamples) and speaks `text` instead. Returns at once: the text is handed to the
  /// worker. Empty text only cancels (it is logged, but last_text() keeps the previous text).
  /// @throws SpeechError if text is over kMaxSpeechTextBytes (nothing is cancelled then).
  void say(std::string text);
  /// Says last_text() again, from its start (nothing if there was none). Logged like say().
  void repeat();
  /// Silence now: cancels what is playing and drops what waits. Not logged.
  void cancel();
  /// True while a text waits or is being synthesised, while the stream is speaking() the current
  /// utterance, or for up to kHandOverGrace after the worker finished an utterance (speaking() is only
  /// updated when the mixer reads, so a short utterance could otherwise sit unheard in the ring while
  /// busy() said false). speaking() is updated only by the consumer: with no audio callback running it
  /// keeps its last value.
  bool busy() const;
  /// Waits until no text waits or is being synthesised (the stream may still play it) or `timeout_s` [s]
  /// passes. Returns false on time-out. For tests and shutdown.
  bool wait_idle(double timeout_s);
  /// The last non-empty text asked for ("" before the first).
  std::string last_text() const;
  /// Every text passed to say() / repeat(), oldest first, with the std::chrono::steady_clock time it was
  /// asked at [ns since the clock's epoch]; the newest kLogEntries are kept. The "message log" that flow
  /// tests read.
  std::vector<std::pair<std::int64_t, std::string>> log() const;

  static constexpr std::size_t kLogEntries = 256;       ///< entries kept in log()
  static constexpr double kHandOverGrace = 0.25;        ///< see busy() [s]
  static constexpr double kFullRingRetry = 0.005;       ///< worker's wait when the stream is full [s]

 private:
  void run();
  void submit(std::string text);  // cancels and queues; caller holds m_

  SpeechStream& stream_;
  SpeechParams params_;
  mutable std::mutex m_;
  std::condition_variable cv_;
  bool has_job_ = false;         // a text waits for the worker
  std::uint32_t job_generation_ = 0;
  std::string job_text_;
  std::deque<std::pair<std::int64_t, std::string>> log_;
  std::string last_;
  bool working_ = false;         // the worker is synthesising
  std::uint32_t handed_generation_ = 0;  // the last utterance the worker finished, and when [steady ns]
  std::int64_t handed_at_ns_ = 0;
  bool handed_ = false;
  bool stop_ = false;
  std::thread worker_;
};

}  // namespace hk::audio
