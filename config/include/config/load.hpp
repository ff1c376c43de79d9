#pragma once
/// @file load.hpp
/// Reading, checking and writing the kiosk settings (`settings.hpp`) as TOML.
///
/// The file layout is one TOML table per settings struct ([haptics], [device], [hand], [vision],
/// [workspace], [audio], [kiosk], [stick], [camera], [keys], [operator]) with one key per field, named exactly as the
/// field. Every key is optional: a key that is absent keeps its default. Everything else is refused with a ConfigError
/// whose message is one line naming the file, the key (as `table.key`), the bad value and what is allowed, e.g.
///   config 'k.toml': haptics.stiffness_n_per_m = -5 is out of range [10, 5000] N/m (line 3)
///
/// All field knowledge (table, key, range, unit, help) lives in one descriptor table,
/// field_descriptors(), which load, validate and to_toml share.

#include <cstdint>
#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include "hk/error.hpp"

#include "config/settings.hpp"

namespace hk::config {

/// Bad settings or a settings file that can't be read or written.
/// what() is a single line (no newline characters; control characters in values are escaped)
/// naming the source (the file path, or "settings" for an in-memory Settings), the key as
/// `table.key` when one key is at fault, the bad value, and the allowed range or type.
class ConfigError : public hk::Error {
 public:
  /// @param source  the file path or "settings"; @param key  `table.key` or empty;
  /// @param message the full one-line message returned by what().
  ConfigError(std::string source, std::string key, const std::string& message);

  /// The file path (as given by the caller) or "settings".
  [[nodiscard]] const std::string& source() const noexcept { return source_; }
  /// The offending key as `table.key` (or `[table]` for a bad table), empty when the error is not
  /// about one key (missing file, syntax error, I/O failure).
  [[nodiscard]] const std::string& key() const noexcept { return key_; }

 private:
  std::string source_;
  std::string key_;
};

/// How a field is stored and written in TOML.
enum class FieldKind {
  real,     ///< double; TOML float or integer accepted; must be finite and within [min, max]
  integer,  ///< int or std::int64_t; TOML integer only; within [min, max]
  text,     ///< std::string; TOML string; one of `choices`, or (no choices) accepted by `check`
};

/// Where a field sits in the operator's panel. `hidden` fields are never shown
/// (the PIN's hash).
enum class FieldGroup { haptics, levels, scene, audio, kiosk, keys, devices, hidden };

/// Display name of a group: "Haptics", "Levels", "Scene", "Audio", "Kiosk", "Keys", "Devices", "".
[[nodiscard]] std::string_view group_name(FieldGroup g) noexcept;

/// When a change made in the running kiosk takes effect.
enum class ApplyWhen {
  live,     ///< at once: servo gains through the lock-free hand-over, keys, session timing
  scene,    ///< the scene is rebuilt off the servo thread and swapped in with the fade
  session,  ///< at the next visitor's session
  restart,  ///< at the next start of the kiosk
};

/// Mutable view of one field inside a Settings.
using FieldRef = std::variant<double*, int*, std::int64_t*, std::string*>;
/// Read-only view of one field inside a Settings.
using ConstFieldRef = std::variant<const double*, const int*, const std::int64_t*, const std::string*>;

/// Describes one settings field: where it lives in TOML, its allowed values and its unit.
/// Bounds are inclusive; for integer fields they are whole numbers (exact in a double).
struct FieldDescriptor {
  std::string_view table;                     ///< TOML table, e.g. "haptics"
  std::string_view key;                       ///< key in that table, e.g. "stiffness_n_per_m" (= the field name)
  FieldKind kind;                             ///< storage kind
  double min;                                 ///< inclusive lower bound (real, integer); unused for text
  double max;                                 ///< inclusive upper bound (real, integer); unused for text
  std::string_view unit;                      ///< unit shown to the operator, e.g. "N/m"; empty when dimensionless
  std::string_view help;                      ///< one-line description for the operator
  std::span<const std::string_view> choices;  ///< allowed values of a text field (empty: `check` decides)
  /// For a text field without choices: why `value` is not allowed (one phrase, e.g. "is longer than 4096
  /// bytes"), or empty when it is. Null for every other field.
  std::string (*check)(std::string_view value);
  FieldGroup group;                        ///< where the operator's panel shows it
  ApplyWhen apply;                         ///< when a change in the running kiosk takes effect
  FieldRef (*ref)(Settings&);              ///< the field inside a Settings
  ConstFieldRef (*cref)(const Settings&);  ///< the field inside a const Settings
};

/// Every settings field, grouped by table in file order (haptics, device, hand, vision,
/// workspace, audio, kiosk, stick, keys, operator). The span refers to static storage.
[[nodiscard]] std::span<const FieldDescriptor> field_descriptors() noexcept;

/// The descriptor of `table.key`, or nullptr when there is no such field.
[[nodiscard]] const FieldDescriptor* find_field(std::string_view table, std::string_view key) noexcept;

/// What `d` allows, as the loader's messages say it: "[10, 5000] N/m", "one of \"auto\", \"fixed\"", "text".
[[nodiscard]] std::string field_allowed_text(const FieldDescriptor& d);
/// A text field's choices as TOML strings joined by ", " ("\"auto\", \"fixed\""); empty for a field without.
[[nodiscard]] std::string field_choices_text(const FieldDescriptor& d);

/// The field's name in staff words, for the operator's panel: its help's first phrase (up to the first full stop,
/// colon, semicolon, comma or opening parenthesis, and before another setting's key), at most kMaxFieldLabelBytes
/// (cut at a word), e.g. "Speaking rate" for [audio] speech_rate_wpm; the key when the help is empty.
[[nodiscard]] std::string field_label(const FieldDescriptor& d);
/// The same label made from a help text in any language (the panel's translation of FieldDescriptor::help), `key`
/// when it gives none.
[[nodiscard]] std::string field_label(std::string_view help, std::string_view key);
inline constexpr std::size_t kMaxFieldLabelBytes = 48;

/// Largest settings file load_settings() reads, in bytes (1 MiB).
inline constexpr std::uintmax_t kMaxConfigFileBytes = 1u << 20;

/// Reads settings from the TOML file at `path`: starts from the defaults (Settings{}) and
/// overrides every key present, then validate()s the result.
/// @throws ConfigError if the file is missing, not a regular file, larger than
///   kMaxConfigFileBytes or unreadable; on a TOML syntax error (message gives line and column);
///   on an unknown table or key (named, with a suggestion for a likely typo); on a wrong type
///   (an integer is accepted where a real is expected, nothing else is converted); on a
///   non-finite or out-of-range value; on a failed cross-field check (see validate()).
[[nodiscard]] Settings load_settings(const std::string& path);

/// As load_settings(), but from TOML text in memory. `source_name` names the input in messages
/// (use the file path or e.g. "operator panel").
/// @throws ConfigError as load_settings() (except the file errors).
[[nodiscard]] Settings parse_settings(std::string_view toml_text, const std::string& source_name);

/// Checks every field against its range (reals must be finite) and the cross-field rules:
/// - haptics.level <= haptics.max_levels (only levels 0..max_levels are built);
/// - vision.canny_low <= vision.canny_high when both are nonzero (0 = derive from the image);
/// - haptics.dynamic_friction <= haptics.static_friction;
/// - each [keys] action on its own key;
/// - device.type is one of the known device types (FieldDescriptor::choices).
/// @throws ConfigError (source "settings") naming the first bad key.
void validate(const Settings& settings);

/// Writes every key of every table as TOML, each preceded by a comment giving its meaning, unit,
/// allowed range and default, so an operator can edit the file by hand. Reals are written with
/// the shortest representation that reads back to the same double, so
/// parse_settings(to_toml(s)) == s for every valid s. Does not validate.
[[nodiscard]] std::string to_toml(const Settings& settings);

/// Points of save_settings_atomic() at which a test may inject a fault through SaveOptions::hook
/// (the hook may throw, or _exit to simulate a crash). Every save passes all three, in this order.
enum class SaveStage {
  temp_written,  ///< the new text is in a temporary file beside `path`, fsync'ed; nothing renamed yet
  backup_kept,   ///< the file being replaced is now also `<path>.bak` (when there was one and
                 ///< SaveOptions::keep_backup); `path` itself is still the old file
  renamed,       ///< the temporary file has been renamed over `path`; the directory is not yet fsync'ed
};

/// Options of save_settings_atomic().
struct SaveOptions {
  bool keep_backup = true;              ///< keep the file being replaced as `<path>.bak`
  std::function<void(SaveStage)> hook;  ///< fault injection for tests; empty in production
};

/// validate()s `settings`, then writes to_toml(settings) to `path` atomically, keeping the file it
/// replaces as `<path>.bak`:
///  1. the text goes to a new temporary file in the same directory (`.<name>.tmp.XXXXXX`), which is
///     fsync'ed; hook(temp_written);
///  2. when `path` is an existing regular file and options.keep_backup: it is hard-linked to a temporary
///     name, which is renamed over `<path>.bak` (so `.bak` is at every instant a complete file: the
///     previous backup or the file being replaced); where the file system has no hard links it is
///     copied (written, fsync'ed, renamed) instead; hook(backup_kept);
///  3. the temporary file is renamed over `path` (the commit point); hook(renamed);
///  4. the directory is fsync'ed (best effort).
/// A crash at any point leaves `path` either the old or the new complete file, and `<path>.bak`
/// either the previous backup or the old file (a crash may leave a `.<name>.tmp.*` file behind).
/// A new file gets mode 0644, an existing file keeps its mode, and a file with a PIN hash
/// ([operator] pin_hash) is always 0600; `.bak` is the old file itself, with its mode. Not safe against
/// concurrent writers of the same path. A two-argument call keeps a backup.
/// @throws ConfigError if validation fails or any step before the rename over `path` fails (missing or
///   read-only directory, disk full, `<path>.bak` can't be replaced, ...); `path` is then untouched
///   (`.bak` may already hold the old file) and the temporary files are removed.
/// If the hook throws, the temporary files are removed where they still exist and the exception
/// propagates unchanged.
void save_settings_atomic(const Settings& settings, const std::string& path, const SaveOptions& options = {});

/// A file write_file_atomic() could not write. what() is one line, "<what could not be done>: <the system's
/// reason>" ("cannot create a temporary file in '/srv/names': Permission denied"); `path` is the file being written
/// and error_number() the errno value (0 when the failure had none, e.g. a path naming no file).
class FileWriteError : public hk::Error {
 public:
  /// @param path  the file being written; @param error_number  errno (0: none); @param message  what() (one line)
  FileWriteError(std::string path, int error_number, const std::string& message);
  /// The file being written, as given.
  [[nodiscard]] const std::string& path() const noexcept { return path_; }
  /// The errno value of the failing call (EACCES, ENOSPC, ...), 0 when there was none.
  [[nodiscard]] int error_number() const noexcept { return error_number_; }

 private:
  std::string path_;
  int error_number_ = 0;
};

/// Writes `text` to `path` the way save_settings_atomic() writes settings (the steps and the crash guarantee
/// above: a temporary file in the same folder, fsync'ed, the old file kept as `<path>.bak` when
/// options.keep_backup, renamed over `path`, the folder fsync'ed), for any file the kiosk keeps (settings, staff
/// names). A new file gets `new_file_mode` (permission bits, e.g. 0644); an existing one keeps its own unless
/// `force_mode`, which gives it `new_file_mode` too. The folder must exist. Not safe against concurrent writers.
/// @throws FileWriteError (one line, the errno kept) if any step before the rename over `path` fails; `path` is
///   then untouched (`.bak` may already hold the old file) and the temporary files are removed. A throwing
///   hook's exception propagates unchanged, as in save_settings_atomic().
void write_file_atomic(const std::string& text, const std::string& path, unsigned new_file_mode = 0644,
                       bool force_mode = false, const SaveOptions& options = {});

}  // namespace hk::config
