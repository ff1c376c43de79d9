#pragma once
/// @file window.hpp
/// The kiosk's window and its input (the window and input set-up kept apart from the core, as
/// Dear ImGui keeps its backends apart): GLFW (full screen on the primary monitor, or a 1280 x 720 window),
/// an OpenGL 2 context, Dear ImGui with its GLFW and OpenGL 2 backends. GLFW's key, character and mouse
/// button callbacks only queue events; the kiosk routes each one (to the visitor's flow, the operator's
/// key chord, or ImGui when the operator's panel has the keyboard), and scripted input enters the same
/// queue, so a script exercises the path a real key takes.

#include <optional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

struct GLFWwindow;

namespace hk::app {

/// One input event, as GLFW reports it.
struct InputEvent {
  enum class Kind { key, character, mouse_button };
  Kind kind = Kind::key;
  int key = 0;             ///< GLFW key code (key)
  int scancode = 0;        ///< (key)
  int action = 0;          ///< GLFW_PRESS, GLFW_RELEASE or GLFW_REPEAT (key, mouse_button)
  int mods = 0;            ///< GLFW_MOD_* bits (key, mouse_button)
  unsigned codepoint = 0;  ///< Unicode code point (character)
  int button = 0;          ///< mouse button (mouse_button)
};

/// The pointer as a script sets it for one frame [window px], overriding the real one for ImGui.
struct ScriptedMouse {
  float x = 0, y = 0;
  bool down = false;  ///< left button
};

/// The window, its GL context and Dear ImGui. One per process; the window thread only.
class KioskWindow {
 public:
  /// @throws AppError (one line) when GLFW cannot start (no display) or the window cannot open.
  explicit KioskWindow(bool windowed);
  ~KioskWindow();
  KioskWindow(const KioskWindow&) = delete;
  KioskWindow& operator=(const KioskWindow&) = delete;

  bool should_close() const;
  void request_close();
  /// Processes the window system's events; returns the input events queued since the last call, in order.
  std::vector<InputEvent> poll();
  /// Hands an event to Dear ImGui's GLFW backend (its callbacks, as if it had installed them).
  void to_imgui(const InputEvent& e);
  /// Starts an ImGui frame; `mouse` (scripted runs) replaces the real pointer for this frame.
  void begin_frame(const std::optional<ScriptedMouse>& mouse);
  /// Renders the ImGui frame over what was drawn.
  void end_frame();
  /// Shows the frame (waits for the display's refresh).
  void swap();
  /// Framebuffer size [px] (what GL draws), window size [screen px] (what the pointer reports).
  std::pair<int, int> framebuffer_size() const;
  std::pair<int, int> window_size() const;
  /// The real pointer [window px].
  std::pair<double, double> cursor() const;
  /// The frame drawn so far as an 8-bit BGR image, top row first (for --screenshot).
  cv::Mat read_pixels() const;

 private:
  GLFWwindow* win_ = nullptr;
  std::vector<InputEvent> queue_;
};

}  // namespace hk::app
