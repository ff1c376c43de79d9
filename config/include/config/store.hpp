#pragma once
/// @file store.hpp
/// Settings that are never lost: the start-up load that keeps a corrupt file aside and falls
/// back to `<path>.bak` or the defaults, the audit log of the operator's changes, and the operator
/// panel's one-field edits, checked exactly as the TOML loader checks them.
///
/// The atomic save that keeps `<path>.bak` is save_settings_atomic() in `config/load.hpp`.
/// Times are Unix seconds (UTC) given by the caller, so every function here is deterministic.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "config/load.hpp"
#include "config/settings.hpp"

namespace hk::config {

/// What load_settings_with_fallback() found.
struct LoadedSettings {
  Settings settings;  ///< the settings to run with (valid)
  /// Where `settings` came from: the file, its `.bak`, or the shipped defaults (Settings{}).
  enum class From { file, backup, defaults } from = From::file;
  /// Where the bad file was moved: "<path>.corrupt-<UTC YYYYmmddTHHMMSSZ>" (with "-1", "-2", ... when
  /// that name was taken). Empty when the file loaded, or when it could not be moved (the notice says so).
  std::string corrupt_path;
  /// Empty when the file loaded; else ONE line for the log and the operator's panel: the loader's
  /// message, where the bad file is kept, and what runs instead ("the .bak of <UTC time>" or
  /// "the defaults"), e.g.
  ///   config '/etc/hk.toml': TOML syntax error at line 1, column 1: ...; the file is kept as
  ///   '/etc/hk.toml.corrupt-20261122T030405Z'; running the .bak of 2026-11-21T18:00:00Z instead
  std::string notice;
};

/// Loads the settings at start-up without ever refusing to start over a damaged file.
/// - A file that loads: returned as load_settings() returns it, `from` = file.
/// - A file that does not parse or validate (syntax error, garbage, unknown key, out-of-range value,
///   larger than kMaxConfigFileBytes): renamed to "<path>.corrupt-<time of now_unix_s>" (never deleted,
///   never overwritten: "-1", "-2", ... is appended while that name exists), then `<path>.bak` is loaded if
///   it loads (it is NOT copied over `path`: the next save writes `path`), else the defaults are used.
///   A corrupt `.bak` is left where it is. When the bad file can't be moved (e.g. read-only directory) it
///   stays at `path`, `corrupt_path` is empty and the notice says so.
/// @param path        the settings file, as given to load_settings()
/// @param now_unix_s  the current time (UTC, Unix seconds); it names the corrupt file
/// @throws ConfigError as load_settings() when `path` is missing, not a regular file or can't be opened
///   (a typo in --config must not silently run the defaults).
[[nodiscard]] LoadedSettings load_settings_with_fallback(const std::string& path, std::int64_t now_unix_s);

/// The audit log's path: [operator] audit_log, or "<settings_path>.audit.log" when that is empty.
[[nodiscard]] std::string audit_log_path(const Settings& s, const std::string& settings_path);

/// One changed field.
struct SettingChange {
  std::string key;        ///< "table.key", e.g. "haptics.stiffness_n_per_m"
  std::string old_value;  ///< as TOML text, e.g. 800.0, "UP", 6; see diff_settings() for hidden fields
  std::string new_value;  ///< as TOML text

  /// Field-by-field equality.
  bool operator==(const SettingChange&) const = default;
};

/// Every field whose value differs between `before` and `after`, in the order of field_descriptors()
/// (table order). Values are TOML text as to_toml() writes them (800.0, 6, "RIGHT"). A hidden field
/// (FieldGroup::hidden: the PIN's hash) is never written: it reads "" -> (set), (set) -> (changed) or
/// (set) -> (removed).
[[nodiscard]] std::vector<SettingChange> diff_settings(const Settings& before, const Settings& after);

/// Appends one line per change to the audit log at `log_path`:
///   "<UTC ISO-8601 time> <who> <table.key> <old> -> <new>\n"
/// e.g. "2026-11-22T03:04:05Z panel haptics.stiffness_n_per_m 800.0 -> 1200.0". Control characters in
/// `who`, keys and values are escaped (\n, \t, \xNN), so each change is one line. The file is opened
/// O_APPEND|O_CREAT|O_CLOEXEC (created with mode 0600, an existing file keeps its mode), all lines are
/// written with one write where possible, then fsync'ed. Nothing is written (nor created) when
/// `changes` is empty.
/// @param unix_s  time of the change (UTC, Unix seconds)
/// @throws ConfigError (one line naming the log, source() = log_path) on any I/O failure.
void append_audit(const std::string& log_path, std::int64_t unix_s, std::string_view who,
                  const std::vector<SettingChange>& changes);

/// Appends one event line "<UTC ISO-8601 time> <who> <event>\n" to the audit log, e.g.
/// "2026-11-22T03:04:05Z panel PIN refused, 2 failed attempts". Events used by the panel: "panel
/// opened", "PIN refused, N failed attempts", "reset to defaults (not saved yet)", "saved".
/// Same guarantees and errors as append_audit().
void append_audit_event(const std::string& log_path, std::int64_t unix_s, std::string_view who, std::string_view event);

/// The operator panel's edit of one field of `s`.
/// @param text  as typed: for a text field the value itself (no quotes, nothing trimmed); for a real or
///   integer field a number, surrounding spaces and tabs ignored (decimal, optional sign, exponent,
///   "inf"/"nan" are read and then refused as the loader refuses them); an integer is accepted for a
///   real, a fraction or exponent is not accepted for an integer.
/// @return an empty string when the value was accepted and set in `s`; otherwise ONE line, the message
///   the TOML loader gives for that value in that key, from source "operator panel" (range, kind,
///   choices, check, and the cross-field rules of validate() with the new value in place), e.g.
///   "operator panel: haptics.stiffness_n_per_m = 9000 is out of range [10, 5000] N/m", or for a
///   non-number "operator panel: haptics.stiffness_n_per_m = \"abc\" is not a number; expected a number
///   in [10, 5000] N/m"; `s` is then unchanged.
[[nodiscard]] std::string set_field_from_text(Settings& s, const FieldDescriptor& d, std::string_view text);

/// Why a text typed for one field is refused on its own, before the rules across fields: what the panel says
/// in the staff's words (the loader's message stays English).
enum class FieldRefusal {
  none,            ///< the text is a value `d` allows (a rule across fields may still refuse it)
  not_a_number,    ///< a real or integer field given no number
  not_an_integer,  ///< an integer field given a fraction or exponent
  out_of_range,    ///< a number outside [min, max] (inf and nan included)
  not_a_choice,    ///< a text field with choices given none of them
  other,           ///< a text field's own check refused it (its message says why)
};

/// How `text` (spaces and tabs around it ignored, as set_field_from_text reads it) is refused as field `d`'s
/// value on its own; FieldRefusal::none when set_field_from_text would take it but for the cross-field rules.
[[nodiscard]] FieldRefusal field_refusal(const FieldDescriptor& d, std::string_view text);

/// The value of field `d` in `s` as the panel shows it for editing: reals in the shortest text that
/// reads back exactly, plain decimal where that is short ("800", "0.0005", "5e-324"), integers in
/// decimal, text as is (no quotes). set_field_from_text() of this text gives back the same value.
[[nodiscard]] std::string field_text(const Settings& s, const FieldDescriptor& d);

}  // namespace hk::config
