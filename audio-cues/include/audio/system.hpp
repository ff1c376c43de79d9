#pragma once
/// @file system.hpp
/// The kiosk's whole audio side in one object: the cue ring the servo thread fills, the mixer
/// (earcons + speech, ducking, volume), the espeak-ng speaker, the message catalogue and the PortAudio
/// output. Any part that cannot start (no sound card, no espeak-ng data) is logged once and the rest goes
/// on: a kiosk without a speaker still renders forces, and tests run it headless and pull render().

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "audio/cue_event.hpp"
#include "audio/messages.hpp"
#include "audio/mixer.hpp"
#include "audio/output.hpp"
#include "audio/speech.hpp"
#include "audio/speech_stream.hpp"
#include "audio/spsc_ring.hpp"
#include "audio/volume.hpp"

namespace hk::audio {

/// Everything the audio side is configured with. Units in names.
struct AudioSystemParams {
  MixerParams mixer;
  SpeechParams speech;  ///< voice: empty = the catalogue's voice
  OutputParams output;
  int volume_default_step = 7;      ///< [1, 10]
  double volume_step_db = 3.0;      ///< [dB]
  std::size_t cue_capacity = 4096;  ///< cue ring entries (4 s of cues at 1 kHz)
  bool open_output = true;          ///< false: no PortAudio; the caller pulls render() (headless runs, tests)
  /// The languages offered to visitors (BCP 47 tags, in the order the Language key steps through them).
  std::vector<std::string> languages{"en"};
  /// The language each visit starts in; one of `languages` (else the first of them that loads).
  std::string language = "en";
  /// The voice English is spoken with (SpeechParams::voice: "flite:slt"); empty: espeak-ng's "en". Every other
  /// language speaks with its espeak-ng voice.
  std::string english_voice;
  /// Where the compiled catalogues are (audio::default_locale_dir(): this build's or the package's).
  std::filesystem::path locale_dir = default_locale_dir();
};

/// The audio side. Construct and destroy on the kiosk's main thread.
class AudioSystem {
 public:
  /// Loads the catalogue of every offered language; one that cannot be loaded (no catalogue file, a broken
  /// one, not a BCP 47 tag) is logged in one line naming it and left out, and English stands in when none
  /// is left. Never throws for a missing sound card, speech engine or voice (logged; running without, or
  /// with the espeak-ng voice "en").
  explicit AudioSystem(const AudioSystemParams& params);
  ~AudioSystem();
  AudioSystem(const AudioSystem&) = delete;
  AudioSystem& operator=(const AudioSystem&) = delete;

  /// The ring the servo thread pushes cues into (its only producer). Real-time safe to push.
  SpscRing<CueEvent>& cues() noexcept { return cues_; }

  /// Plays the earcon of `kind` now, from the window thread (its queue's only producer; the servo thread has
  /// cues()): the camera's Shutter. Returns at once; false when the queue is full (dropped).
  bool play(CueKind kind) noexcept;

  /// Speaks free text (e.g. a picture description), cutting off whatever is being said. `keep` as
  /// Speaker::say: false for an acknowledgement, which Speaker::repeat passes over. Any length (Speaker::say).
  void say_text(std::string text, bool keep = true);
  /// As say_text(), but its pieces from `from_piece` up to (not including) `until_piece` (SIZE_MAX: to the end)
  /// in the voice of `language` (a BCP 47 tag: English's voice for "en", else espeak-ng's voice of its language
  /// subtag). A language without a voice is said in the voice in use (logged once per language).
  void say_text_in(std::string text, bool keep, std::size_t from_piece, const std::string& language,
                   std::size_t until_piece = SIZE_MAX);
  /// Holds speech where it is (Speaker::pause); false when nothing is being said.
  bool pause_speech();
  /// Goes on from the pause (Speaker::resume); false when not paused.
  bool resume_speech();
  /// Speech is being said to someone: the speaker is busy, not paused, and its sound reaches a device (or
  /// the caller pulls render(), open_output false). Without a sound device nobody hears it: false.
  bool speaking() const;
  /// Which piece (speech_pieces) of the newest text said is being heard (Speaker::piece_heard); −1 when it is
  /// over or cut off, and without speech or without anyone hearing it (no sound device, nothing pulled).
  int piece_heard() const { return speaker_ && (pulled_ || sound_output()) ? speaker_->piece_heard() : -1; }
  /// How long `text` takes to say [s] at the speaker's voice and rate (synthesised, not played: ~1/600 of
  /// that in CPU time); 0 without speech. Allocates; not for the audio callback.
  double speech_duration_s(const std::string& text) const;
  /// Volume one step up / down; false at the limit (the kiosk then says volume_limit).
  bool volume_up() noexcept { return volume_.up(); }
  bool volume_down() noexcept { return volume_.down(); }
  /// A new visitor: volume back to the operator's default, speech stopped and the last text forgotten (the
  /// language is the visitor flow's to set back).
  void new_session();

  /// Headless: pulls `frames` samples of the mix (only when open_output was false; otherwise PortAudio pulls).
  void render(float* out, std::size_t frames) noexcept { mixer_.render(out, frames); }

  const Volume& volume() const noexcept { return volume_; }
  /// The catalogue of the language in use. The reference stays valid for the system's life; its texts
  /// change with set_language().
  const MessageCatalog& messages() const noexcept { return catalog_; }
  /// The offered languages that loaded, in order (BCP 47 tags); never empty.
  const std::vector<std::string>& languages() const noexcept { return language_codes_; }
  /// Index into languages() of the language in use, and of the default.
  int language() const noexcept { return language_; }
  int default_language() const noexcept { return default_language_; }
  /// Speaks and answers in languages()[index] from now on: messages() becomes its catalogue, the speaker
  /// its voice (what is being said goes on in its own). Out of range: nothing changes (false).
  bool set_language(int index);
  /// The catalogue of languages()[index] (the one in use when out of range).
  const MessageCatalog& catalogue(int index) const;
  /// True if sound reaches a device.
  bool sound_output() const { return output_ && output_->running(); }
  /// The output's state (why_not when there is none); null if open_output was false.
  const OutputInfo* output_info() const { return output_ ? &output_->info() : nullptr; }
  /// True if espeak-ng started.
  bool speech_available() const noexcept { return speaker_ != nullptr; }
  /// Every text spoken, with its steady-clock time [ns] (empty without speech).
  std::vector<std::pair<std::int64_t, std::string>> speech_log() const;
  /// Cues dropped because the ring was full.
  std::uint64_t cues_dropped() const noexcept { return cues_.overflows(); }

 private:
  void load_languages(const AudioSystemParams& p);
  /// The voice of `language` (a BCP 47 tag): english_voice_ for English when set, else the espeak-ng voice of
  /// its language subtag.
  std::string voice_for(std::string_view language) const;

  std::vector<MessageCatalog> catalogues_;   // one per offered language that loaded
  std::vector<std::string> language_codes_;  // their tags
  int language_ = 0, default_language_ = 0;
  std::set<std::string> missing_voices_;  // voices the synthesisers refused, each logged once
  std::string english_voice_;
  MessageCatalog catalog_;  // a copy of catalogues_[language_]: what messages() hands out
  SpscRing<CueEvent> cues_;
  SpscRing<CueEvent> ui_cues_;  // the window thread's earcons (play)
  SpeechStream speech_stream_;
  Volume volume_;
  Mixer mixer_;
  std::unique_ptr<Speaker> speaker_;
  std::unique_ptr<AudioOutput> output_;
  SpeechParams speech_params_;  // the speaker's
  bool pulled_ = false;         // open_output was false: the caller pulls render()
};

}  // namespace hk::audio
