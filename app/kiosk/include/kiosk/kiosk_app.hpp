#pragma once
/// @file kiosk_app.hpp
/// The kiosk a visitor walks up to: `haptic-kiosk` with no subcommand. One window (full screen
/// on the primary monitor, or `--windowed`), the servo thread driving the simulated pantograph from the
/// mouse (the model hand pulls the handle towards the cursor), the audio side, and the visitor's flow
/// (kiosk_flow.hpp) on the keyboard. USB sticks are watched, mounted read-only and scanned, and their
/// documents built, on worker threads (stick_service.hpp). The operator's panel (operator_panel.hpp) opens
/// with the [operator] open_chord and the PIN.
///
/// The pieces, each in a file of its own: window.hpp (GLFW, GL context, Dear ImGui, the
/// input queue), view.hpp (the scene drawn), hud.hpp (captions, overlay status), operator_panel.hpp and
/// app/visit/include/visit/operator_session.hpp (the panel and its logic), script.hpp (scripted input), keymap.hpp (key
/// names), app/visit/include/visit/kiosk_runtime.hpp (everything but the window); this file's run_kiosk puts them
/// together.
///
/// View mapping (tests rely on it): workspace metres → window pixels with one uniform scale
/// s = 0.9 · min(W / width_m, 0.8 · H / height_m) [px/m], y up, the bottom 14 % left to the captions:
///   px = W/2 + s·x,  py = 0.43·H − s·y   (py counted from the top row).

#include <string>

namespace hk::app {

/// What `haptic-kiosk` (no subcommand) was asked to do.
struct KioskOptions {
  bool windowed = false;       ///< a 1280 x 720 window instead of full screen
  std::string config_path;     ///< TOML settings; empty: defaults
  std::string library;         ///< picture folder; empty: the shipped data/pictures
  std::string show;            ///< start on this picture (skips attract and tutorial): for documentation and tests
  bool high_contrast = false;  ///< start in high contrast (dimmed picture, thick bright curves)
  bool overlay = false;        ///< start with the operator overlay
  std::string screenshot;      ///< write the last frame here as PNG and quit
  int frames = 0;              ///< frames to run before the screenshot (at 60 Hz)
  /// Write the window's frame times here as JSON at exit (frame_stats.hpp); empty: not measured.
  std::string frame_stats;
  std::string script;      ///< scripted input (script.hpp): key, press, type, click, cursor, move, stick, unstick, wait
  std::string stick;       ///< a folder treated as a USB stick inserted at start (documentation, tests)
  bool hotplug = true;     ///< watch for USB sticks (libudev); off: only --stick and scripted sticks
  std::string mount_root;  ///< where sticks are mounted; empty: /run/haptic-kiosk/usb
  /// Empty: the device [device] names. "haply-emulator[:FAULT=V,...]": the USB pantograph's driver on the
  /// firmware emulator behind a pty, its handle pulled by the mouse (demonstrations, documentation).
  std::string device;
};

/// Runs the kiosk until the window closes (or, with a screenshot, for `frames` frames). Returns the exit
/// status. A settings file that does not load is kept aside and the kiosk runs on its .bak or the defaults
/// (config/store.hpp). @throws on bad input (one line naming it): a missing settings file, library, script,
/// screenshot path, no display.
int run_kiosk(const KioskOptions& options);

}  // namespace hk::app
