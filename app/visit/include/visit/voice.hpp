#pragma once
/// @file voice.hpp
/// What the kiosk says, as the visitor hears it: every line logged ("say: ..."; a reading's line breaks as
/// spaces), kept as the caption and spoken through the audio system. A line given to say() is kept for
/// Repeat; an acknowledgement (say_brief: "Louder.", "More detail.") is said the same way but not kept, so
/// Repeat passes over it. Window thread.

#include <cstdint>
#include <string>

#include "audio/system.hpp"

namespace hk::app {

/// The kiosk's spoken lines. Not thread-safe: the window thread.
class Voice {
 public:
  /// `audio` outlives the voice.
  explicit Voice(audio::AudioSystem& audio) : audio_(audio) {}

  /// Logs, shows and speaks `text` (cutting off what is being said); Repeat says it again.
  void say(const std::string& text);
  /// As say(), but Repeat passes it over.
  void say_brief(const std::string& text);
  /// Says the last text given to say() again; false when there is none (since forget()).
  bool repeat();
  /// Forgets the text Repeat would say (a new visitor).
  void forget() { repeatable_.clear(); }

  /// The last text said (the caption).
  const std::string& last_said() const { return last_said_; }
  /// Texts given to say() since the start.
  std::uint64_t kept_texts() const { return kept_texts_; }
  /// Texts given to say() or say_brief() since the start: a key press that leaves it unchanged said nothing.
  std::uint64_t texts_said() const { return texts_said_; }
  /// The piece of the last text given to say() being heard (audio::AudioSystem::piece_heard); −1 once an
  /// acknowledgement has cut it off.
  int heard_piece() const { return brief_last_ ? -1 : audio_.piece_heard(); }

 private:
  audio::AudioSystem& audio_;
  std::string last_said_;
  std::string repeatable_;        // the last text given to say(), for Repeat
  std::uint64_t kept_texts_ = 0;  // texts given to say()
  std::uint64_t texts_said_ = 0;  // texts given to say() or say_brief()
  bool brief_last_ = false;       // the last text said was given to say_brief()
};

}  // namespace hk::app
