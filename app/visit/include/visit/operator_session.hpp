#pragma once
/// @file operator_session.hpp
/// The operator's panel without its drawing: the key chord asks for the PIN, the PIN
/// is checked on a worker thread (PinVerifier) under the persisted lockout, and the panel then edits a
/// working copy of the settings, field by field, each checked exactly as the TOML loader checks it. Apply
/// hands the copy to the running kiosk (KioskRuntime::apply_settings); Save writes the settings file
/// atomically keeping the previous one as `.bak`; every change applied and every save, reset, opening and
/// refused PIN goes to the audit log. The panel closes itself after [operator] idle_close_s without input.
/// The PIN is never kept longer than the check, never logged and never shown.
///
/// Clock: `now_s` is any monotonic clock [s] (the window's frame clock); `now_unix_s` the wall clock [s] for
/// the lockout and the audit, which outlive the process. Not thread-safe: the window thread.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/load.hpp"
#include "config/settings.hpp"
#include "visit/panel_text.hpp"

namespace hk::app {

class PinVerifier;

/// Where the panel stands.
enum class PanelState {
  closed,     ///< the visitor's kiosk; the chord opens the PIN prompt
  notice,     ///< a message instead of the PIN prompt (no PIN set, no settings file); closes after a while
  pin_entry,  ///< asking for the PIN (a wait is shown while the lockout holds)
  checking,   ///< the PIN is being verified on the worker thread
  open,       ///< the settings and the live status
};

/// True while the keyboard belongs to the panel in state `s` (prompt or panel): visitor keys are not acted on.
inline bool captures_keyboard(PanelState s) {
  return s == PanelState::pin_entry || s == PanelState::checking || s == PanelState::open;
}

/// The files an operator session works on, and what start-up found wrong with the settings file.
struct SessionFiles {
  std::string settings_path;  ///< the settings file (empty: the kiosk runs on defaults)
  std::string audit_path;     ///< the audit log beside it
  std::string load_notice;    ///< what start-up found wrong with the settings file; empty when it loaded
  std::string fleet_path;     ///< the museum's fleet file in force (fleet_settings.hpp); empty: none
};

/// What apply_settings did with a change, for the operator panel and the audit.
struct ApplyReport {
  bool gains = false;                     ///< stiffness, damping, force, friction or deadline went to the servo thread
  bool scene_rebuilt = false;             ///< the scene was rebuilt and swapped in with the fade
  bool keys = false;                      ///< the visitor's keys (and what the kiosk says of them) changed
  bool timing = false;                    ///< the session's time-out changed
  std::vector<std::string> next_session;  ///< keys (table.key) that take effect with the next visitor
  std::vector<std::string> restart;       ///< keys that take effect at the next start
  std::vector<std::string> refused;  ///< values the device's profile refused, each "<table.key> = <value> <why>; ..."
                                     ///< (the profile's value is used)
};

/// The operator's panel's state and actions.
class OperatorSession {
 public:
  /// Called by apply() with the working copy; says what took effect (the session makes the panel's line of it).
  using ApplyFn = std::function<ApplyReport(const config::Settings&)>;

  /// `settings_path`: the settings file (empty: the kiosk runs on defaults and the panel cannot open).
  /// `in_use`: the settings the kiosk runs with. `load_notice`: what start-up found wrong with the file
  /// (config::LoadedSettings::notice), shown at the top of the panel; empty when it loaded.
  OperatorSession(std::string settings_path, const config::Settings& in_use, std::string load_notice, ApplyFn apply);
  ~OperatorSession();
  OperatorSession(const OperatorSession&) = delete;
  OperatorSession& operator=(const OperatorSession&) = delete;

  /// The key chord was pressed: the PIN prompt (or a notice saying why the panel cannot open).
  void chord(double now_s, std::int64_t now_unix_s);
  /// Any input while the panel or the prompt is up (keeps it from closing itself).
  void touch(double now_s) { last_input_s_ = now_s; }
  /// Every frame: the PIN check's outcome, the lockout's countdown, the idle close.
  void tick(double now_s, std::int64_t now_unix_s);
  /// The PIN typed (digits; wiped here after the hand-over). Ignored while a check is under way or the
  /// lockout holds.
  void submit_pin(std::string pin, double now_s, std::int64_t now_unix_s);
  /// Closes the panel or the prompt (Escape, the Close button). The working copy is dropped; what was
  /// applied stays applied.
  void close(std::int64_t now_unix_s);

  /// The panel's words in `language` ([operator] language, a BCP 47 tag) from `locale_dir` (PanelText::load),
  /// read again only when the language changes. Every line composed after this is in that language; the audit
  /// log and the journal stay English.
  void set_language(const std::string& language, const std::filesystem::path& locale_dir);
  /// The panel's words in the staff's language.
  const PanelText& words() const { return words_; }
  /// The museum's fleet file in force (`path`) and the settings it manages ("table.key"): shown locked, refused
  /// by commit_field, kept by reset_to_defaults, and saved with settings.toml's own values (fleet_settings.hpp).
  void set_fleet(std::string path, std::vector<std::string> managed);
  /// Whether the museum manages `d` (set_fleet).
  bool managed(const config::FieldDescriptor& d) const;

  PanelState state() const { return state_; }
  /// The line shown under the PIN prompt or as the notice ("Wrong PIN. 2 failed attempts.", "Try again in 27 s.").
  const std::string& message() const { return message_; }
  /// Seconds until a PIN is heard (0 = now); infinity when locked until `pin set`.
  double wait_s() const { return wait_s_; }

  // ---- the open panel ----
  /// The settings being edited.
  const config::Settings& working() const { return working_; }
  /// The text in a field's edit box (what the operator typed, refused or not).
  std::string& edit_text(const config::FieldDescriptor& d);
  /// Commits a field's edit box to the working copy: empty on success, else one line saying why not (also kept
  /// as field_error(d) and shown beside the field): in the staff's words for a value that is no number, no whole
  /// number, out of range or no allowed choice (config::field_refusal), else the loader's own message; a field the
  /// museum manages is refused as such and its box shows its value again.
  std::string commit_field(const config::FieldDescriptor& d, std::int64_t now_unix_s);
  /// The refusal of a field's last edit, empty when none.
  const std::string& field_error(const config::FieldDescriptor& d) const;
  /// The working copy differs from the settings in use.
  bool dirty() const { return !(working_ == in_use_); }
  /// Settings in use differ from the file (applied, not saved).
  bool unsaved() const { return !(in_use_ == saved_); }
  /// Hands the working copy to the kiosk; audit lines for every change. Returns the status line.
  std::string apply(std::int64_t now_unix_s);
  /// Applies, then saves the settings in use (atomic, .bak kept); the PIN hash on disk is kept (a
  /// `pin set` made meanwhile is not undone), and so are the file's own values of the fields the museum manages.
  /// Returns the status line (the error, one line, on failure: nothing in use is lost).
  std::string save(std::int64_t now_unix_s);
  /// The working copy back to the defaults (the [operator] table kept: the PIN and where the records go; the fields
  /// the museum manages keep their values).
  /// Not applied or saved yet: the panel asks for confirmation before calling this.
  void reset_to_defaults(std::int64_t now_unix_s);
  /// The last status line (apply, save, reset).
  const std::string& status() const { return status_; }
  /// The settings file and the audit log in use, and what start-up found wrong with the file.
  const SessionFiles& files() const { return files_; }

 private:
  void open_panel(double now_s, std::int64_t now_unix_s);
  void audit_event(std::int64_t now_unix_s, const std::string& event);
  std::size_t index_of(const config::FieldDescriptor& d) const;
  /// The PIN prompt's line while a wait of `wait_s` [s] holds (infinite: locked until `pin set`), else the prompt.
  std::string prompt_line(double wait_s) const;
  /// What a refused edit `typed` of `d` says; `loader_line` when it is none of the refusals put in staff words.
  std::string refusal_line(const config::FieldDescriptor& d, const std::string& typed,
                           const std::string& loader_line) const;
  /// One line of what `r` took effect as.
  std::string applied_line(const ApplyReport& r) const;
  const char* tr(const char* english) const { return words_(english); }
  const char* trn(const char* one, const char* many, long n) const { return words_(one, many, n); }

  SessionFiles files_;
  ApplyFn apply_fn_;
  PanelText words_;
  std::unique_ptr<PinVerifier> verifier_;
  PanelState state_ = PanelState::closed;
  double last_input_s_ = 0, notice_until_s_ = 0;
  double wait_s_ = 0;
  std::string message_, status_;
  config::Settings in_use_, saved_, working_;
  std::vector<std::string> edit_texts_, field_errors_;
  std::vector<std::string> managed_;  // "table.key" the museum's fleet file sets
};

}  // namespace hk::app
