#pragma once
/// @file messages.hpp
/// Everything the kiosk says, in one catalogue. The English text lives in
/// audio-cues/messages/en.toml and is compiled in; a translation is a copy of that file with the
/// right-hand sides translated, loaded with MessageCatalog::load().
///
/// Keys: a message names the visitor's keys with placeholders ({help_key}, {next_key},
/// …: kKeyPlaceholders), filled with the spoken form of the key the operator configured; the [key_names]
/// table of the catalogue gives that spoken form for every key name ("UP" → "the Up arrow"). The
/// catalogue knows nothing of the settings: the caller passes the key names (KeyArg).

#include <array>
#include <functional>
#include <initializer_list>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include "hk/error.hpp"

namespace hk::audio {

/// The messages. Their keys in the TOML file are kMessageKeys[id].
enum class MessageId : int {
  welcome,
  attract,
  help,
  picture_loaded,
  picture_loaded_one,
  picture_empty,
  picture_titled,
  picture_titled_one,
  picture_titled_empty,
  describe,
  level_finer,
  level_coarser,
  level_finest,
  level_coarsest,
  volume_up,
  volume_down,
  volume_limit,
  tutorial_start,
  tutorial_circle,
  tutorial_triangle,
  tutorial_done,
  timeout_warning,
  goodbye,
  no_audio_device,
  stick_inserted,
  stick_empty,
  stick_removed,
  stick_unreadable,
  document_page,
  document_picture,
  document_unreadable,
  loading,
  text_block,
  device_ready,
  device_simulated,
  device_lost,
  device_back,
  tour_remaining,
  tour_one_remaining,
  tour_all_touched,
  tour_stopped,
  tour_nothing,
  help_camera,
  camera_ready,
  camera_none,
  capture_start,
  capture_no_camera,
  capture_place,
  capture_too_dark,
  capture_cut_off_top,
  capture_cut_off_bottom,
  capture_cut_off_left,
  capture_cut_off_right,
  capture_move_left,
  capture_move_right,
  capture_move_up,
  capture_move_down,
  capture_hold_still,
  captured,
  captured_one,
  captured_empty,
  capture_cancelled,
  capture_failed,
  capture_timeout,
  help_brief,
  place_tutorial,
  place_picture,
  place_document,
  place_capture,
  key_help,
  key_next,
  key_previous,
  key_describe,
  key_finer,
  key_coarser,
  key_volume_up,
  key_volume_down,
  key_tutorial,
  key_guide,
  key_capture,
  key_repeat,
  key_pause,
  key_where,
  key_finish,
  key_other,
  this_key,
  nothing_to_pause,
  nothing_to_repeat,
  where_on,
  where_on_part,
  where_near,
  where_inside,
  where_region,
  where_none,
  where_text,
  sorry,
  tour_ask,
  tour_traced,
  tour_ask_part,
  touch_name,
  high_contrast_on,
  high_contrast_off,
  overlay_on,
  overlay_off,
  text_reading,
  text_ready,
  text_none,
  text_unavailable,
  device_not_home,
  tour_stuck,
  finish_ask,
  timeout_warning_stick,
  level_manual,
  files_unreadable,
  file_unreadable,
  document_unreadable_alone,
  read_aloud_warning,
  long_text_minutes,
  long_text_minute,
  tutorial_push,
  tutorial_no_levels,
  far_near,
  shape_square,
  shape_circle,
  shape_triangle,
  help_next,
  help_last,
  key_place,
  key_next_sentence,
  key_previous_sentence,
  key_next_paragraph,
  key_previous_paragraph,
  reading_none,
  reading_start,
  reading_end,
  reading_paragraph,
  unclear_word,
  unclear_words,
};
inline constexpr int kMessageCount = 138;

/// TOML key of every MessageId, in enum order.
inline constexpr std::array<std::string_view, kMessageCount> kMessageKeys{"welcome",
                                                                          "attract",
                                                                          "help",
                                                                          "picture_loaded",
                                                                          "picture_loaded_one",
                                                                          "picture_empty",
                                                                          "picture_titled",
                                                                          "picture_titled_one",
                                                                          "picture_titled_empty",
                                                                          "describe",
                                                                          "level_finer",
                                                                          "level_coarser",
                                                                          "level_finest",
                                                                          "level_coarsest",
                                                                          "volume_up",
                                                                          "volume_down",
                                                                          "volume_limit",
                                                                          "tutorial_start",
                                                                          "tutorial_circle",
                                                                          "tutorial_triangle",
                                                                          "tutorial_done",
                                                                          "timeout_warning",
                                                                          "goodbye",
                                                                          "no_audio_device",
                                                                          "stick_inserted",
                                                                          "stick_empty",
                                                                          "stick_removed",
                                                                          "stick_unreadable",
                                                                          "document_page",
                                                                          "document_picture",
                                                                          "document_unreadable",
                                                                          "loading",
                                                                          "text_block",
                                                                          "device_ready",
                                                                          "device_simulated",
                                                                          "device_lost",
                                                                          "device_back",
                                                                          "tour_remaining",
                                                                          "tour_one_remaining",
                                                                          "tour_all_touched",
                                                                          "tour_stopped",
                                                                          "tour_nothing",
                                                                          "help_camera",
                                                                          "camera_ready",
                                                                          "camera_none",
                                                                          "capture_start",
                                                                          "capture_no_camera",
                                                                          "capture_place",
                                                                          "capture_too_dark",
                                                                          "capture_cut_off_top",
                                                                          "capture_cut_off_bottom",
                                                                          "capture_cut_off_left",
                                                                          "capture_cut_off_right",
                                                                          "capture_move_left",
                                                                          "capture_move_right",
                                                                          "capture_move_up",
                                                                          "capture_move_down",
                                                                          "capture_hold_still",
                                                                          "captured",
                                                                          "captured_one",
                                                                          "captured_empty",
                                                                          "capture_cancelled",
                                                                          "capture_failed",
                                                                          "capture_timeout",
                                                                          "help_brief",
                                                                          "place_tutorial",
                                                                          "place_picture",
                                                                          "place_document",
                                                                          "place_capture",
                                                                          "key_help",
                                                                          "key_next",
                                                                          "key_previous",
                                                                          "key_describe",
                                                                          "key_finer",
                                                                          "key_coarser",
                                                                          "key_volume_up",
                                                                          "key_volume_down",
                                                                          "key_tutorial",
                                                                          "key_guide",
                                                                          "key_capture",
                                                                          "key_repeat",
                                                                          "key_pause",
                                                                          "key_where",
                                                                          "key_finish",
                                                                          "key_other",
                                                                          "this_key",
                                                                          "nothing_to_pause",
                                                                          "nothing_to_repeat",
                                                                          "where_on",
                                                                          "where_on_part",
                                                                          "where_near",
                                                                          "where_inside",
                                                                          "where_region",
                                                                          "where_none",
                                                                          "where_text",
                                                                          "sorry",
                                                                          "tour_ask",
                                                                          "tour_traced",
                                                                          "tour_ask_part",
                                                                          "touch_name",
                                                                          "high_contrast_on",
                                                                          "high_contrast_off",
                                                                          "overlay_on",
                                                                          "overlay_off",
                                                                          "text_reading",
                                                                          "text_ready",
                                                                          "text_none",
                                                                          "text_unavailable",
                                                                          "device_not_home",
                                                                          "tour_stuck",
                                                                          "finish_ask",
                                                                          "timeout_warning_stick",
                                                                          "level_manual",
                                                                          "files_unreadable",
                                                                          "file_unreadable",
                                                                          "document_unreadable_alone",
                                                                          "read_aloud_warning",
                                                                          "long_text_minutes",
                                                                          "long_text_minute",
                                                                          "tutorial_push",
                                                                          "tutorial_no_levels",
                                                                          "far_near",
                                                                          "shape_square",
                                                                          "shape_circle",
                                                                          "shape_triangle",
                                                                          "help_next",
                                                                          "help_last",
                                                                          "key_place",
                                                                          "key_next_sentence",
                                                                          "key_previous_sentence",
                                                                          "key_next_paragraph",
                                                                          "key_previous_paragraph",
                                                                          "reading_none",
                                                                          "reading_start",
                                                                          "reading_end",
                                                                          "reading_paragraph",
                                                                          "unclear_word",
                                                                          "unclear_words"};

/// A catalogue file that cannot be used. what() is one line naming the file and, when one entry is at
/// fault, its key, e.g. "messages 'de.toml': messages.help uses {colour}, which the English text does not have".
class MessageError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// A named value for a {placeholder}.
using MessageArg = std::pair<std::string_view, std::string>;

/// The placeholders that name one of the visitor's keys, one per action of the [keys] settings (help, next,
/// previous, describe, finer, coarser, volume_up, volume_down, tutorial, guide, capture, repeat, pause, where,
/// finish, next_sentence, previous_sentence, next_paragraph, previous_paragraph), in that order.
inline constexpr std::array<std::string_view, 19> kKeyPlaceholders{"help_key",
                                                                   "next_key",
                                                                   "previous_key",
                                                                   "describe_key",
                                                                   "finer_key",
                                                                   "coarser_key",
                                                                   "volume_up_key",
                                                                   "volume_down_key",
                                                                   "tutorial_key",
                                                                   "guide_key",
                                                                   "capture_key",
                                                                   "repeat_key",
                                                                   "pause_key",
                                                                   "where_key",
                                                                   "finish_key",
                                                                   "next_sentence_key",
                                                                   "previous_sentence_key",
                                                                   "next_paragraph_key",
                                                                   "previous_paragraph_key"};

/// A key placeholder and the key it stands for, by its settings name: {"help_key", "F1"}. MessageCatalog::text()
/// puts the spoken form of the key (MessageCatalog::key_name()) in its place.
using KeyArg = std::pair<std::string_view, std::string_view>;

/// The texts of one language.
class MessageCatalog {
 public:
  /// The compiled-in English catalogue (never throws: it is checked by the tests).
  static const MessageCatalog& english();
  /// Loads a translation. Every key of the English file must be there, no other key may be, every value is
  /// a non-empty string of at most 1000 bytes, and it may use only the placeholders its English text uses.
  /// The same holds for [key_names]: exactly the English key names, each a spoken form of 1 to 100 bytes.
  /// @throws MessageError (one line: the file and the key at fault, e.g. "key_names.UP is missing").
  static MessageCatalog load(const std::string& path);
  /// Parses catalogue text (`source` names it in errors). @throws MessageError.
  static MessageCatalog parse(std::string_view toml_text, const std::string& source);

  /// The text of `id` with each {name} replaced by its argument in `args`, or, for a key placeholder listed
  /// in `keys`, by the spoken form of that key (key_name()), its first letter made upper case where it starts
  /// the text or a sentence ("the Up arrow" → "The Up arrow gives more detail."). Unknown names are left as
  /// they are. One pass: the text put in is never searched for placeholders again.
  std::string text(MessageId id, std::initializer_list<MessageArg> args = {}, std::span<const KeyArg> keys = {}) const;
  /// text() of a template of this catalogue's own, e.g. one sentence of raw(id): the same placeholders, keys and
  /// capitals.
  std::string expand(std::string_view text_template, std::initializer_list<MessageArg> args = {},
                     std::span<const KeyArg> keys = {}) const;
  /// The spoken form of the key that the settings call `name` ("UP" → "the Up arrow", "F1" → "F1"), lower
  /// case as it reads after "Press"; for a name the catalogue does not know, `name` itself.
  std::string key_name(std::string_view name) const;
  /// Every entry of [key_names]: settings name → spoken form.
  const std::map<std::string, std::string, std::less<>>& key_names() const { return key_names_; }
  /// Where the key the settings call `name` lies on the kiosk's keypad, as the optional [key_places] table of
  /// the catalogue describes it for a visitor who finds keys by touch ("the right one of the four arrow keys,
  /// at the bottom right"); "" when it does not say. Each entry names a key of [key_names] and is 1 to
  /// kMaxKeyPlaceBytes bytes (else load() refuses the file).
  std::string key_place(std::string_view name) const;
  /// The longest [key_places] entry [bytes].
  static constexpr std::size_t kMaxKeyPlaceBytes = 200;
  /// The raw text (placeholders unexpanded).
  const std::string& raw(MessageId id) const { return texts_[static_cast<std::size_t>(id)]; }
  /// espeak-ng voice for this language (e.g. "en", "de").
  const std::string& voice() const { return voice_; }
  /// Language name as the file gives it.
  const std::string& language() const { return language_; }

 private:
  std::array<std::string, kMessageCount> texts_;
  std::map<std::string, std::string, std::less<>> key_names_;
  std::map<std::string, std::string, std::less<>> key_places_;
  std::string voice_, language_;
};

}  // namespace hk::audio
