#pragma once
/// @file messages.hpp
/// Everything the kiosk says, in GNU gettext catalogues: the English text is the source (messages_en.cpp, each
/// message a key and its English text, the key being its msgctxt), audio-cues/po/LANG.po translates it, and the
/// build checks each catalogue and compiles it to LOCALE_DIR/LANG/LC_MESSAGES/haptic-kiosk.mo (audio-cues/po/
/// catalogues.sh), which MessageCatalog::load reads with Boost.Locale's gettext backend: no system locale is
/// needed, and a kiosk holds one catalogue per offered language and switches between them per visitor.
///
/// | part | keys (msgctxt) | what |
/// |---|---|---|
/// | messages | kMessageSources, MessageId | whole sentences, some counted (plural forms from the catalogue) |
/// | words | kWordSources | the pieces Describe and Where build phrases from: look_*, size_*, colour_*, place_*, … |
/// | key names | key_name.NAME | how a key is said after "Press" |
/// | key places | key_place.NAME | where a key lies on a standard keyboard |
///
/// Keys: a message names the visitor's keys with placeholders ({help_key}, {next_key}, …: kKeyPlaceholders),
/// filled with the spoken form of the key the operator configured. The catalogue knows nothing of the
/// settings: the caller passes the key names (KeyArg).

#include <array>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <locale>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "audio/mo_catalogue.hpp"
#include "hk/error.hpp"

namespace hk::audio {

/// The messages, in the order of kMessageSources.
enum class MessageId : int {
  welcome,
  attract,
  help,
  picture_loaded,
  picture_empty,
  picture_titled,
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
  document_unreadable_alone,
  read_aloud_warning,
  long_text_minutes,
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
  reading_soon,
  reading_start,
  reading_end,
  reading_paragraph,
  unclear_words,
  language_name,
  language_offer,
  key_language,
  other_language,
  key_copy,
  copy_confirm,
  copy_making,
  copy_printed,
  copy_not_set_up,
  copy_nothing,
  copy_visit_limit,
  copy_day_limit,
  copy_failed,
  copy_key_title,
  copy_shape,
  copy_left_out,
  copy_not_labelled,
  help_copy,
  copy_saved,
  copy_no_stick,
  copy_stick_full,
  copy_stick_locked,
  copy_stick_format,
  copy_stick_failed,
  copy_folder,
};
inline constexpr int kMessageCount = 157;

/// One entry of the English source: its key (the msgctxt), its English text (the msgid) and, for a counted
/// entry, its English text for more than one (the msgid_plural; empty for an entry that is not counted).
struct MessageSource {
  std::string_view key;
  std::string_view one;
  std::string_view many;
};

inline constexpr int kWordCount = 127;     ///< entries of kWordSources
inline constexpr int kKeyNameCount = 75;   ///< entries of kKeyNameSources
inline constexpr int kKeyPlaceCount = 21;  ///< entries of kKeyPlaceSources

/// The messages' English source, in MessageId order.
extern const std::array<MessageSource, kMessageCount> kMessageSources;
/// The words of Describe and Where, by key (MessageCatalog::word).
extern const std::array<MessageSource, kWordCount> kWordSources;
/// How each key of the settings' [keys] table is said: key "key_name.UP", English "the Up arrow".
extern const std::array<MessageSource, kKeyNameCount> kKeyNameSources;
/// Where keys lie on a standard PC keyboard: key "key_place.F1".
extern const std::array<MessageSource, kKeyPlaceCount> kKeyPlaceSources;

/// The key of `id` ("welcome").
inline std::string_view message_key(MessageId id) { return kMessageSources[static_cast<std::size_t>(id)].key; }

/// The gettext domain: the catalogues' file name, haptic-kiosk.mo.
inline constexpr std::string_view kMessageDomain = "haptic-kiosk";

/// The folder of the compiled catalogues this build or package ships (LANG/LC_MESSAGES/haptic-kiosk.mo below it).
std::filesystem::path default_locale_dir();

/// A named value for a {placeholder}.
using MessageArg = std::pair<std::string_view, std::string>;

/// The placeholders that name one of the visitor's keys, one per action of the [keys] settings (help, next,
/// previous, describe, finer, coarser, volume_up, volume_down, tutorial, guide, capture, repeat, pause, where,
/// finish, next_sentence, previous_sentence, next_paragraph, previous_paragraph, language, copy), in that order.
inline constexpr std::array<std::string_view, 21> kKeyPlaceholders{"help_key",
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
                                                                   "previous_paragraph_key",
                                                                   "language_key",
                                                                   "copy_key"};

/// A key placeholder and the key it stands for, by its settings name: {"help_key", "F1"}. MessageCatalog::text()
/// puts the spoken form of the key (MessageCatalog::key_name()) in its place.
using KeyArg = std::pair<std::string_view, std::string_view>;

/// The texts of one language. Copyable (a few hundred strings); copies share the compiled catalogue.
class MessageCatalog {
 public:
  /// English, the source texts (never throws: the tests check them).
  static const MessageCatalog& english();
  /// The catalogue of `language` (a BCP 47 tag: "fr", "de-CH") from `locale_dir`/LANG/LC_MESSAGES/haptic-kiosk.mo,
  /// LANG being the tag, then its language subtag ("de-CH" falls back to "de"); "en" is english().
  /// @throws MessageError (one line naming the language or file, and the limit or key at fault) when the tag
  ///         is not BCP 47, no catalogue file is there, the file is over kMaxCatalogueBytes or not a gettext
  ///         MO file, or a message, word or key name is missing, over 2000 bytes or uses a {placeholder}
  ///         its English text does not have.
  static MessageCatalog load(std::string_view language, const std::filesystem::path& locale_dir);
  /// The catalogue of `language` from the bytes of an MO file (`source` names it in errors). @throws MessageError.
  static MessageCatalog from_mo(std::string_view language, std::vector<char> mo_bytes, const std::string& source);

  /// The text of `id` with each {name} replaced by its argument in `args`, or, for a key placeholder listed
  /// in `keys`, by the spoken form of that key (key_name()), its first letter made upper case where it starts
  /// the text or a sentence ("the Up arrow" → "The Up arrow gives more detail."). Unknown names are left as
  /// they are. One pass: the text put in is never searched for placeholders again. For a counted message,
  /// its form for one.
  std::string text(MessageId id, std::initializer_list<MessageArg> args = {}, std::span<const KeyArg> keys = {}) const;
  /// A counted message (picture_loaded, tour_remaining, …) in the plural form for `count` (the catalogue's
  /// Plural-Forms), with {count} = count and `args` as text().
  std::string text(MessageId id, long count, std::initializer_list<MessageArg> args = {},
                   std::span<const KeyArg> keys = {}) const;
  /// A word or phrase of kWordSources by its key ("place_middle"), in the form for `count`, placeholders as
  /// text() ({count} = count). An unknown key gives "" (the tests say every key used is there).
  std::string word(std::string_view key, long count = 1, std::initializer_list<MessageArg> args = {}) const;
  /// text() of a template of this catalogue's own, e.g. one sentence of raw(id): the same placeholders, keys and
  /// capitals.
  std::string expand(std::string_view text_template, std::initializer_list<MessageArg> args = {},
                     std::span<const KeyArg> keys = {}) const;
  /// The spoken form of the key that the settings call `name` ("UP" → "the Up arrow", "F1" → "F1"), lower
  /// case as it reads after "Press"; for a name the catalogue does not know, `name` itself.
  std::string key_name(std::string_view name) const;
  /// Every key name the catalogue says: settings name → spoken form.
  const std::map<std::string, std::string, std::less<>>& key_names() const { return key_names_; }
  /// Where the key the settings call `name` lies on a standard keyboard ("the right one of the four arrow
  /// keys, at the bottom right"); "" when the catalogue does not say.
  std::string key_place(std::string_view name) const;
  /// The raw text (placeholders unexpanded); for a counted message, its form for one.
  const std::string& raw(MessageId id) const { return texts_[static_cast<std::size_t>(id)]; }
  /// The raw text of a counted message in the form for `count`.
  std::string raw(MessageId id, long count) const;
  /// The language's BCP 47 tag ("en", "fr").
  const std::string& language() const { return language_; }
  /// The language's own name ("English", "Français").
  const std::string& language_name() const { return texts_[static_cast<std::size_t>(MessageId::language_name)]; }
  /// The espeak-ng voice of the language: its language subtag ("fr" for "fr-CA").
  std::string voice() const;

 private:
  static MessageCatalog build(std::string_view language, std::optional<MoCatalogue> mo, const std::string& source);
  /// build() from `mo`, a lookup Boost.Locale throws on made a MessageError.
  static MessageCatalog checked(MoCatalogue mo);
  std::string translate(const MessageSource& s, long count) const;
  std::string expand_all(std::string_view text_template, std::span<const MessageArg> args,
                         std::span<const KeyArg> keys) const;

  std::array<std::string, kMessageCount> texts_;
  std::array<std::string, kWordCount> words_;  // forms for one
  std::map<std::string, std::string, std::less<>> key_names_;
  std::map<std::string, std::string, std::less<>> key_places_;
  std::string language_;
  std::optional<MoCatalogue> mo_;  // none for English
};

}  // namespace hk::audio
