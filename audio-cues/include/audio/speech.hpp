#pragma once
/// @file speech.hpp
/// Speech with espeak-ng (every language) or CMU Flite (its English voices), synthesised into our own mixer:
/// the synthesisers only make
/// samples (AUDIO_OUTPUT_SYNCHRONOUS + espeak_SetSynthCallback, never its own playback); they are
/// resampled from espeak-ng's rate (22050 Hz) to kSampleRateHz with libsamplerate and handed to the audio
/// callback through a SpeechStream, so speech can be cut at once, repeated, and mixed with the earcons
/// (which the mixer ducks under it).
///
/// espeak-ng is one process-wide library that is not thread-safe: every call into it made here is
/// serialised by one process-wide mutex, and it is initialised once per process (on first use). Nothing
/// else in the process should call espeak-ng directly.

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
#include "hk/error.hpp"

#include "audio/source.hpp"
#include "audio/speech_stream.hpp"

namespace hk::audio {

/// Voice settings. Units in names.
struct SpeechParams {
  /// espeak-ng voice name as espeak_SetVoiceByName takes it ("en", "en-us", "de", "en+f3" for a variant;
  /// espeak-ng accepts an unknown variant after '+' silently), or a CMU Flite English voice: "flite:slt",
  /// "flite:kal", "flite:awb", "flite:rms" (pitch is the voice's own there).
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

/// Most bytes of UTF-8 handed to espeak-ng in one call. A longer text is spoken as several pieces
/// (speech_pieces), one after the other, so no length a visitor can reach is refused.
inline constexpr std::size_t kMaxSpeechPieceBytes = 4000;
/// Longest text spoken [bytes of UTF-8] (1 MiB, about 40 hours of speech): Speaker::say cuts a longer one
/// at a piece boundary (logged); synthesize_speech refuses it.
inline constexpr std::size_t kMaxSpeechTextBytes = std::size_t{1} << 20;
/// The size a piece aims at [bytes]: one sentence, or a run of words of about this size where a sentence
/// is longer (a paragraph of a scanned page with no full stop).
inline constexpr std::size_t kSpeechPieceBytes = 400;

/// Cuts `text` into the pieces it is spoken in, in order: one sentence each (ending at '.', '!', '?', ';' or
/// ':' followed by white space, or at a line break); a sentence over `piece_bytes` is cut at the last space
/// before that size (or, with no space, at the last UTF-8 sequence boundary). White space at a cut is
/// dropped; pieces of white space only are left out. Concatenated with single spaces the pieces give the
/// text's words in order. `piece_bytes` is clamped to [16, kMaxSpeechPieceBytes]. Allocates.
std::vector<std::string> speech_pieces(std::string_view text, std::size_t piece_bytes = kSpeechPieceBytes);

/// Blocking: `text` (UTF-8, plain text, not SSML) → mono samples in [−1, 1] at kSampleRateHz, piece by
/// piece (speech_pieces), including espeak-ng's short trailing pause after each. Empty text → empty result
/// (the parameters are still checked). Thread-safe: serialised with every other espeak-ng call of the
/// process, so it also waits while a Speaker synthesises a piece. Allocates; not for the audio callback.
/// About 600× faster than real time on a desktop core (6 s of speech in ~10 ms).
/// @throws SpeechError on an unknown voice, rate / pitch out of range, text over kMaxSpeechTextBytes, or
///         when espeak-ng cannot be initialised (its data missing) or fails.
std::vector<float> synthesize_speech(std::string_view text, const SpeechParams& params);

/// The kiosk's speaker: one worker thread synthesises each text into a SpeechStream as it goes, piece by
/// piece (speech_pieces; each piece, one sentence, is synthesised whole, tens of milliseconds, then handed to the
/// mixer, so a long text starts as fast as a short one).
/// The Speaker is the stream's only producer: one Speaker per stream.
///
/// Threads: every member but the destructor may be called from any thread except the audio callback; each
/// takes a short lock and returns in microseconds (wait_idle waits).
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
  /// SpeechStream::kFadeSamples), ends a pause, and speaks `text` instead, piece by piece. Returns at once:
  /// the text is handed to the worker. `keep`: the text becomes last_text(), what repeat() says again (false
  /// for an acknowledgement such as "Louder." that a visitor asking to hear it again does not mean). Empty
  /// text only cancels (it is logged, and last_text() keeps the previous text). Never throws for a text's
  /// length: over kMaxSpeechTextBytes it is cut at the last piece that fits (logged as a warning).
  void say(std::string text, bool keep = true);
  /// As say(), but its pieces from `from_piece` up to (not including) `until_piece` (speech_pieces, from 0;
  /// SIZE_MAX: to the end) in `voice`: a document's text in its own language after words in the visitor's, or a
  /// description staff wrote in another language between them. @throws SpeechError when the synthesisers have no
  /// such voice (nothing is said then).
  void say_switching(std::string text, bool keep, std::size_t from_piece, const std::string& voice,
                     std::size_t until_piece = SIZE_MAX);
  /// Says last_text() again, from its start, in the voice it was said in (nothing if there was none). Logged
  /// like say().
  void repeat();
  /// The voice of the texts said from now on (espeak-ng voice name); what is being said goes on in its own.
  /// @throws SpeechError when espeak-ng has no such voice (the voice stays as it was).
  void set_voice(const std::string& voice);
  /// The voice of the texts said from now on.
  std::string voice() const;
  /// Silence now: cancels what is playing and drops what waits, and ends a pause. Not logged.
  void cancel();
  /// cancel(), and last_text() forgotten: a new visitor must not hear the last one's texts again.
  void forget();
  /// Holds what is being said where it is (SpeechStream::set_paused: a 2 ms fade, then silence; synthesis
  /// goes on into the stream's buffer). Returns false, doing nothing, when nothing is being said.
  bool pause();
  /// Goes on from where pause() held it. Returns false, doing nothing, when not paused.
  bool resume();
  /// Speech is held by pause().
  bool paused() const;
  /// True while a text waits or is being synthesised, while the stream is speaking() the current
  /// utterance, or for up to kHandOverGrace after the worker finished an utterance (speaking() is only
  /// updated when the mixer reads, so a short utterance could otherwise sit unheard in the ring while
  /// busy() said false); false while paused. speaking() is updated only by the consumer: with no audio
  /// callback running it keeps its last value.
  bool busy() const;
  /// Waits until no text waits or is being synthesised (the stream may still play it) or `timeout_s` [s]
  /// passes. Returns false on time-out. For tests and shutdown.
  bool wait_idle(double timeout_s);
  /// Which piece (speech_pieces, counted from 0) of the newest text asked for is being heard: 0 while it waits
  /// for its first sample to reach the mixer, the piece whose samples the mixer reads now (or held by a pause),
  /// and −1 once it has been played to its end, when it was cut off (cancel(), a newer text) or was empty, and
  /// before the first text. Follows the mixer within one audio buffer: with nothing pulling the stream it stays
  /// at 0. The kiosk's sentence keys move from here (a sentence is a piece).
  int piece_heard() const;
  /// The last non-empty text asked for with `keep` ("" before the first).
  std::string last_text() const;
  /// Every text passed to say() / repeat(), oldest first, with the std::chrono::steady_clock time it was
  /// asked at [ns since the clock's epoch]; the newest kLogEntries are kept. The "message log" that flow
  /// tests read.
  std::vector<std::pair<std::int64_t, std::string>> log() const;
  /// Pieces handed whole to the stream since the start, in order, with the text they belong to (its
  /// position in log(), counted from the start), the newest kLogEntries kept: tests check that a long text
  /// was spoken whole and in order. Each piece is also logged at spdlog's debug level.
  std::vector<std::string> pieces_spoken() const;

  static constexpr std::size_t kLogEntries = 256;  ///< entries kept in log() and pieces_spoken()
  static constexpr double kHandOverGrace = 0.25;   ///< see busy() [s]
  static constexpr double kFullRingRetry = 0.005;  ///< worker's wait when the stream is full [s]

 private:
  void run();
  void submit(std::string text, bool keep, bool again, std::size_t switch_from = SIZE_MAX,
              const SpeechParams* switch_to = nullptr,
              std::size_t switch_until = SIZE_MAX);  // cancels and queues; caller holds m_
  bool speak_piece(const std::string& piece, const SpeechParams& params, std::uint32_t gen,
                   std::uint64_t* pushed);  // false: cancelled; *pushed += samples handed over

  SpeechStream& stream_;
  mutable std::mutex m_;
  SpeechParams params_;                                                     // the voice of the next say()
  SpeechParams job_params_;                                                 // the waiting text's
  SpeechParams last_params_;                                                // last_'s
  std::size_t job_switch_from_ = SIZE_MAX, last_switch_from_ = SIZE_MAX;    // pieces from here in *_switch_params_
  std::size_t job_switch_until_ = SIZE_MAX, last_switch_until_ = SIZE_MAX;  // ... up to (not including) here
  SpeechParams job_switch_params_, last_switch_params_;
  std::condition_variable cv_;
  bool has_job_ = false;  // a text waits for the worker
  std::uint32_t job_generation_ = 0;
  std::string job_text_;
  std::deque<std::pair<std::int64_t, std::string>> log_;
  std::deque<std::string> pieces_;
  std::string last_;
  bool working_ = false;                 // the worker is synthesising
  std::uint32_t handed_generation_ = 0;  // the last utterance the worker finished, and when [steady ns]
  std::int64_t handed_at_ns_ = 0;
  bool handed_ = false;
  std::uint32_t starts_generation_ = 0;      // the utterance piece_starts_ belongs to
  std::vector<std::uint64_t> piece_starts_;  // its pieces' first samples in the stream [samples], as synthesised
  std::uint64_t utterance_samples_ = 0;      // all its samples, once the last piece is handed over [samples]
  bool stop_ = false;
  std::thread worker_;
};

}  // namespace hk::audio
