#pragma once
/// @file voice.hpp
/// What the kiosk says, as the visitor hears it: every line logged ("say: ..."; a reading's line breaks as
/// spaces), kept as the caption and spoken through the audio system. A line given to say() is kept for
/// Repeat; an acknowledgement (say_brief: "Louder.", "More detail.") is said the same way but not kept, so
/// Repeat passes over it. It answers the visitor's flow's SpeechEffects (kiosk_effects.hpp). Window thread.

#include <cstdint>
#include <string>

#include "audio/system.hpp"
#include "config/settings.hpp"
#include "visit/kiosk_effects.hpp"

namespace hk::app {

/// The kiosk's spoken lines. Not thread-safe: the window thread.
class Voice final : public SpeechEffects {
 public:
  /// `audio` and `settings` (the settings in use: [kiosk] quiet_hours) outlive the voice.
  Voice(audio::AudioSystem& audio, const config::Settings& settings) : audio_(audio), s_(settings) {}

  /// Logs, shows and speaks `text` (cutting off what is being said); Repeat says it again.
  void say(const std::string& text) override;
  /// As say(), but Repeat passes it over.
  void say_brief(const std::string& text) override;
  /// Says the last text given to say() again; false when there is none (since forget()).
  bool repeat() override;
  /// Forgets the text Repeat would say (a new visitor).
  void forget() { repeatable_.clear(); }

  /// The last text said (the caption).
  const std::string& last_said() const { return last_said_; }
  /// Texts given to say() since the start.
  std::uint64_t kept_texts() const override { return kept_texts_; }
  /// Texts given to say() or say_brief() since the start: a key press that leaves it unchanged said nothing.
  std::uint64_t texts_said() const { return texts_said_; }
  /// The piece of the last text given to say() being heard (audio::AudioSystem::piece_heard); −1 once an
  /// acknowledgement has cut it off.
  int heard_piece() const override { return brief_last_ ? -1 : audio_.piece_heard(); }
  bool heard_to_end() const override { return !brief_last_ && audio_.piece_heard() < 0; }
  /// Speech is being heard (audio::AudioSystem::speaking).
  bool speaking() const override { return audio_.speaking(); }
  /// Holds the speech where it is (audio::AudioSystem::pause_speech); false when nothing is being said.
  bool pause_speech() override { return audio_.pause_speech(); }
  /// Goes on from a pause (audio::AudioSystem::resume_speech); false when speech is not paused.
  bool resume_speech() override { return audio_.resume_speech(); }
  /// Whether the local time of day lies in [kiosk] quiet_hours.
  bool quiet_hours() const override;
  /// The audio system's languages (audio::AudioSystem::languages).
  int language_count() const override { return static_cast<int>(audio_.languages().size()); }
  int language() const override { return audio_.language(); }
  int default_language() const override { return audio_.default_language(); }
  /// audio::AudioSystem::set_language; logged when it changes.
  void set_language(int index) override;
  /// As say(), its pieces from `from_piece` on in the voice of `language` (audio::AudioSystem::say_text_in).
  void say_in(const std::string& text, int from_piece, const std::string& language, int until_piece = -1) override;
  /// The offered language `tag` names (by language subtag), in itself; "" when it is not offered.
  std::string language_name_of(const std::string& tag) const override;

 private:
  audio::AudioSystem& audio_;
  const config::Settings& s_;
  std::string last_said_;
  std::string repeatable_;        // the last text given to say(), for Repeat
  std::uint64_t kept_texts_ = 0;  // texts given to say()
  std::uint64_t texts_said_ = 0;  // texts given to say() or say_brief()
  bool brief_last_ = false;       // the last text said was given to say_brief()
};

}  // namespace hk::app
