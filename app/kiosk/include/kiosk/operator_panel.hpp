#pragma once
/// @file operator_panel.hpp
/// The operator's panel drawn with Dear ImGui: the PIN prompt, notices, and the panel
/// with every setting of the field table grouped in tabs (Haptics, Levels, Scene, Audio, Kiosk, Keys,
/// Devices), each with its unit, range, help text and when a change takes effect, plus a Status tab with
/// the servo's lateness and missed deadlines, the device, sound, the stick, the level in use and a live
/// plot of force and penetration, and a Names tab where staff name the shapes of the picture on show. Its logic lives
/// in OperatorSession (GL-free); this file only draws and turns clicks and keys into the session's actions.
///
/// Scripted runs click widgets by name (script lines "FRAME click NAME"): every clickable widget drawn in a
/// frame is recorded with its screen rectangle — a setting's edit box by its `table.key`, buttons by their
/// label ("OK", "Apply", "Save", "Reset to defaults", "Reset", "Keep", "Close"), tabs as "tab:Haptics", and
/// the PIN box as "pin". Some lines of the Status tab are recorded by what they say, for "FRAME shows NAME":
/// the USB stick line as "sticks:idle" or "sticks:working", the last stick's list of files left out as
/// "stick_problems".
///
/// The Names tab ("tab:Names") names the shapes of the library picture on show (NamesEditor, GL-free): the list of
/// names (each "name:<index>", click to select), "Pick the shape at the handle", the name box "names.name" and the
/// description box "names.description" (click, then type), "Save names" and "Delete name", and a status line
/// recorded as "names:saved" or "names:failed" after a save (with "names:status" always). A save puts the names on
/// what is shown at once (Stage::set_names).

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "config/device_profile.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"
#include "visit/names_editor.hpp"
#include "visit/operator_session.hpp"

namespace hk::app {

/// A widget's rectangle in window pixels (y down).
struct WidgetRect {
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

/// Draws the panel of one OperatorSession.
class OperatorPanel {
 public:
  explicit OperatorPanel(OperatorSession& session) : s_(session) {}

  /// Inside an ImGui frame: draws whatever the session's state calls for, for a `fw` x `fh` pixel screen.
  /// `now_s` frame clock [s], `now_unix_s` wall clock [s].
  void draw(KioskRuntime& runtime, const KioskFlow& flow, int fw, int fh, double now_s, std::int64_t now_unix_s);

  /// Rectangle of the widget named `name` in the last frame drawn, if it was drawn.
  std::optional<WidgetRect> widget(const std::string& name) const;

 private:
  void draw_notice(int fw, int fh);
  void draw_pin_prompt(int fw, int fh, double now_s, std::int64_t now_unix_s);
  void draw_panel(KioskRuntime& runtime, const KioskFlow& flow, int fw, int fh, double now_s, std::int64_t now_unix_s);
  void draw_status(KioskRuntime& runtime, const KioskFlow& flow, std::int64_t now_unix_s);
  void draw_device(KioskRuntime& runtime, std::int64_t now_unix_s);
  /// What the last stick could not give, file by file (the visitor hears only how many), folded.
  void draw_stick_problems(KioskRuntime& runtime);
  /// The settings of `group`, each with its range and, for the force budget, the limit of the device
  /// profile in force (`profile_type`, KioskRuntime::profile_type) beside it.
  void draw_fields(config::FieldGroup group, const std::string& profile_type, std::int64_t now_unix_s);
  void draw_actions(std::int64_t now_unix_s);
  /// The Names tab: the editor opened again on the picture on show whenever another scene is shown.
  void draw_names(KioskRuntime& runtime);
  /// The Names tab's list of names, each selectable ("name:<index>").
  void draw_name_list();
  void sample_plot(KioskRuntime& runtime);
  void record(const std::string& name);
  /// `english` in the staff's language (the session's PanelText; the panel catalogue's template takes every tr("…")).
  const char* tr(const char* english) const { return s_.words()(english); }
  /// What the device profile allows for a field, in the staff's words.
  std::string profile_limit_line(const config::ProfileLimit& limit) const;

  OperatorSession& s_;
  std::string pin_;             // the PIN being typed (wiped at submit and close)
  std::string calibrate_note_;  // what the last Calibrate did
  bool focus_pin_ = false;
  std::map<std::string, WidgetRect> widgets_, drawing_;
  static constexpr int kPlotSamples = 300;  // 5 s of frames at 60 Hz
  std::array<float, kPlotSamples> force_n_{}, penetration_mm_{};
  int plot_at_ = 0;
  std::unique_ptr<NamesEditor> names_;  // the Names tab's editor, made when the tab is first drawn
  std::uint64_t names_scene_ = 0;       // Stage::scenes_published() when it was last opened
};

}  // namespace hk::app
