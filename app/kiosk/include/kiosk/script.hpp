#pragma once
/// @file script.hpp
/// Scripted input for documentation runs and tests (`--script FILE` with `--screenshot`): one command per
/// line, "FRAME COMMAND [ARGUMENT]", '#' starts a comment. FRAME counts rendered frames (60 per second of
/// kiosk time); lines run in file order once their frame is reached.
///   key ACTION      a visitor's action straight to the flow (help, next, previous, describe, finer, coarser,
///                   volume_up, volume_down, tutorial, guide, capture, repeat, pause, where, finish,
///                   next_sentence, previous_sentence, next_paragraph, previous_paragraph, language, copy,
///                   other)
///   press KEYS      a key as the keyboard sends it, through the same routing as a real key: a key name of
///                   the settings (F1, A, UP, ENTER, ESCAPE, BACKSPACE, TAB, O, ...) or a chord (CTRL+ALT+O);
///                   pressed in this frame, released in the next
///   type TEXT       the rest of the line typed as characters (into whatever has the keyboard)
///   click NAME      the left mouse button on a widget of the operator's panel, by name (operator_panel.hpp):
///                   the pointer moves there, the button goes down a frame later and up the frame after
///   shows NAME      the run fails (exit 1, one line) unless the widget NAME of the operator's panel was drawn in
///                   the last frame: what a test reads off the panel ("sticks:idle")
///   cursor X Y      the model hand's target [m]
///   move            the handle moved (wakes the kiosk)
///   stick DIR       a folder inserted as a USB stick; unstick: taken out
///   wait            the frame count holds while the kiosk works (stick scans and loads, a PIN check);
///                   wait_loaded is the same
/// A script that cannot be read or has a bad line is refused with one line naming the file and the line.

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "hk/vec2.hpp"
#include "kiosk/operator_panel.hpp"
#include "kiosk/window.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {

/// One line of a script.
struct ScriptLine {
  int frame = 0;
  std::string what;                   ///< the command
  std::string arg;                    ///< ACTION, KEYS, TEXT, NAME or DIR
  Vec2 cursor_m;                      ///< cursor
  KioskKey action = KioskKey::Other;  ///< key
  int glfw_key = 0, glfw_mods = 0;    ///< press
  int number = 0;                     ///< line number in the file
};

/// Reads a script. @throws AppError (one line: the file, the line number, what is allowed).
std::vector<ScriptLine> load_script(const std::string& path);

/// What a script acts on.
class ScriptTarget {
 public:
  virtual ~ScriptTarget() = default;
  virtual void action_key(KioskKey k) = 0;                                ///< key ACTION
  virtual void input(const InputEvent& e) = 0;                            ///< press, type: routed like a real event
  virtual void cursor(Vec2 m) = 0;                                        ///< cursor
  virtual void moved() = 0;                                               ///< move
  virtual void stick(const std::string& dir) = 0;                         ///< stick
  virtual void unstick() = 0;                                             ///< unstick
  virtual bool busy() = 0;                                                ///< wait holds while true
  virtual std::optional<WidgetRect> widget(const std::string& name) = 0;  ///< click
};

/// Plays a script frame by frame.
class ScriptPlayer {
 public:
  ScriptPlayer(std::vector<ScriptLine> lines, std::string path) : lines_(std::move(lines)), path_(std::move(path)) {}
  /// Runs the lines due at `frame` (and the releases and clicks under way). Returns true when a wait line
  /// holds: the caller must not count this frame. @throws AppError when a wait lasts more than 60 s
  /// of frames or a click names a widget not on screen.
  bool step(int frame, ScriptTarget& target);
  /// The scripted pointer for this frame, once a click has been played (it then stays where it clicked).
  const std::optional<ScriptedMouse>& mouse() const { return mouse_; }

 private:
  std::vector<ScriptLine> lines_;
  std::string path_;
  std::size_t next_ = 0;
  int held_ = 0;
  std::vector<InputEvent> releases_;  // keys pressed last frame
  std::deque<ScriptedMouse> clicks_;  // pointer states of the next frames
  std::optional<ScriptedMouse> mouse_;
};

}  // namespace hk::app
