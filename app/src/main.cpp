// haptic-kiosk: command line entry. Subcommands: explore (headless run, DESIGN.md contract), capture (one camera capture),
// cameras (the cameras found), stick (what a USB stick offers), pin
// (set or check the operator's PIN), speak (a message or text rendered to WAV), devices (USB and serial devices
// found) and calibrate (the USB pantograph's encoder offsets).
#include <CLI/CLI.hpp>
#include <spdlog/cfg/env.h>
#include <cstdio>
#include <exception>
#include <string>

#include "audio_settings.hpp"
#include "capture.hpp"
#include "device_command.hpp"
#include "explore.hpp"
#include "kiosk_app.hpp"
#include "pin_command.hpp"
#include "stick_command.hpp"
#include "app_error.hpp"

namespace {

// Errors reach the visitor's operator as exactly one line: fold any line breaks a library put in.
void print_error(const std::string& what) {
  std::string line = what;
  for (char& ch : line) {
    if (ch == '\n' || ch == '\r') ch = ' ';
  }
  std::fprintf(stderr, "haptic-kiosk: %s\n", line.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  spdlog::cfg::load_env_levels();  // SPDLOG_LEVEL=debug shows e.g. each piece of speech as it is handed on
  CLI::App cli{"haptic-kiosk: feel the shapes in a picture through a force-feedback pantograph"};
  cli.require_subcommand(0, 1);
  hk::app::KioskOptions ko;
  cli.add_flag("--windowed", ko.windowed, "A 1280 x 720 window instead of full screen (development)");
  cli.add_option("--config", ko.config_path, "Settings file (TOML)");
  cli.add_option("--library", ko.library, "Picture folder (default: the shipped data/pictures)");
  cli.add_option("--show", ko.show, "Start on this picture, past the welcome and tutorial (documentation, tests)");
  cli.add_flag("--high-contrast", ko.high_contrast, "Start in high contrast: dimmed picture, thick bright curves (also in the operator's panel)");
  cli.add_flag("--overlay", ko.overlay, "Start with the operator overlay (also in the operator's panel)");
  cli.add_option("--screenshot", ko.screenshot, "Run --frames frames (scripted input from --script), write the last as PNG, quit");
  cli.add_option("--frames", ko.frames, "Frames to run before the screenshot (60 per second)");
  cli.add_option("--script", ko.script, "Scripted input: lines 'FRAME key NAME', 'FRAME cursor X_M Y_M', 'FRAME move', 'FRAME stick DIR', 'FRAME unstick', 'FRAME wait_loaded'");
  cli.add_option("--stick", ko.stick, "A folder treated as a USB stick inserted at start");
  cli.add_flag("!--no-hotplug", ko.hotplug, "Do not watch for USB sticks");
  cli.add_option("--mount-root", ko.mount_root, "Where USB sticks are mounted (default /run/haptic-kiosk/usb)");
  cli.add_option("--device", ko.device,
                 "haply-emulator[:FAULT=V,...]: the USB pantograph's driver on the firmware emulator behind a pty, pulled by the mouse "
                 "(default: the device of [device])");
  hk::app::ExploreOptions eo;
  CLI::App* explore = cli.add_subcommand("explore", "Run the whole pipeline headless on the simulated pantograph");
  CLI::Option* input = explore->add_option("input", eo.image_path, "Picture (PNG, JPEG, BMP, TIFF, WebP) or PDF to explore");
  CLI::Option* source = explore->add_option("--source", eo.source,
                                            "A camera capture in place of the input: file:PATH (an image or a folder of frames), "
                                            "libcamera:N or v4l2:DEV; capture.png and capture.json go beside the outputs");
  input->excludes(source);
  source->excludes(input);
  explore->add_option("--page", eo.page, "Page of a PDF, from 1 (default 1)")->check(CLI::PositiveNumber);
  explore->add_option("--out", eo.out_dir, "Folder for scene.json, trace.csv, summary.json, overlay.png")->required();
  explore->add_option("--hand", eo.hand,
                      "Model hand: 'raster', 'explorer' (sweeps, traces outlines, pushes through walls it knows) or a CSV file "
                      "with header t_s,x_m,y_m")
      ->default_val("raster");
  std::string seed_text = "1";
  explore->add_option("--seed", seed_text, "The explorer's seed, a whole number >= 0 (default 1): same seed, same run");
  explore->add_option("--duration", eo.duration_s, "Run length [s]; default: the hand path's length, 120 s for the explorer")
      ->check(CLI::PositiveNumber);
  explore->add_option("--config", eo.config_path, "Settings file (TOML)");
  explore->add_option("--audio-out", eo.audio_out, "Also render the run's earcons to this WAV file (tick k at t = k / servo rate)");
  explore->add_option("--device", eo.device,
                      "sim, or haply-emulator[:FAULT=VALUE,...] (the firmware emulator behind a pty; faults disconnect_at_s, "
                      "drop_every, garbage_every, wrong_id_every, stall_at_s, stall_s, seed, calib_error1_deg, calib_error2_deg)")
      ->default_val("sim");
  hk::app::CaptureOptions cao;
  CLI::App* capture = cli.add_subcommand("capture", "Capture a picture from a camera or frames once: the page found, guided, rectified");
  capture->add_option("--source", cao.source, "file:PATH (an image or a folder of frames), libcamera:N or v4l2:DEV")->required();
  capture->add_option("--out", cao.out_dir, "Folder for capture.png and capture.json")->required();
  capture->add_option("--config", cao.config_path, "Settings file (TOML): [camera]");
  CLI::App* cameras = cli.add_subcommand("cameras", "List the cameras found (libcamera, then V4L2)");
  hk::app::DevicesOptions dvo;
  CLI::App* devices = cli.add_subcommand("devices", "List the USB and serial devices found, and ask each way to a board for an hAPI reply");
  devices->add_option("--config", dvo.config_path, "Settings file (TOML): [device] usb_ids, transport, serial_path");
  hk::app::CalibrateOptions co;
  CLI::App* calibrate = cli.add_subcommand("calibrate", "With the handle resting at the park place, set the encoder offsets");
  calibrate->add_option("--config", co.config_path, "Settings file (TOML) to read and to write the offsets into")->required();
  calibrate->add_option("--device", co.device, "haply (the board) or haply-emulator[:calib_error1_deg=V,...]")->default_val("haply");
  hk::app::SpeakOptions so;
  CLI::App* speak = cli.add_subcommand("speak", "Render a message of the catalogue, or any text, as speech into a WAV file");
  speak->add_option("what", so.what, "A message key (welcome, help, picture_loaded, ...) or text to say")->required();
  speak->add_option("--wav", so.wav_path, "WAV file to write")->required();
  speak->add_option("--config", so.config_path, "Settings file (TOML): [audio] speech_rate_wpm");
  speak->add_option("--messages", so.messages_path, "A translated message catalogue (see audio-cues/messages/en.toml)");
  hk::app::StickOptions sto;
  CLI::App* stick = cli.add_subcommand("stick", "What a USB stick (a folder, or a device mounted read-only) offers, and what was refused and why");
  stick->add_option("folder", sto.folder, "A mounted stick or any folder");
  stick->add_option("--device", sto.device, "A block device (e.g. /dev/sdb1): mounted read-only, scanned, unmounted (needs CAP_SYS_ADMIN)");
  stick->add_option("--json", sto.json_path, "Write the listing to this file (default: standard output)");
  stick->add_option("--config", sto.config_path, "Settings file (TOML): [stick] limits");
  stick->add_option("--mount-root", sto.mount_root, "Where --device is mounted (default /run/haptic-kiosk/usb)");
  hk::app::PinOptions po;
  CLI::App* pin = cli.add_subcommand("pin", "Set or check the operator's PIN (read from standard input)");
  pin->add_option("action", po.action, "set: a new PIN (4 to 12 digits); check: exit 0 right, 1 wrong, 2 locked, 3 no PIN or unusable settings")
      ->required()
      ->check(CLI::IsMember({"set", "check"}));
  pin->add_option("--config", po.config_path, "Settings file (TOML) holding [operator] pin_hash")->required();
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cli.exit(e);
  }
  try {
    if (*explore) {
      if (eo.image_path.empty() && eo.source.empty()) throw hk::app::AppError("explore: give a picture or PDF to explore, or --source");
      eo.seed = hk::app::parse_seed(seed_text);
      const auto sum = hk::app::run_explore(eo);
      std::printf("explore: %ld ticks, %zu curves, contact %ld edge + %ld vertex ticks, max force %.3f N -> %s\n", sum.ticks,
                  sum.curves, sum.edge_ticks, sum.vertex_ticks, sum.max_force_n, eo.out_dir.c_str());
    } else if (*capture) {
      return hk::app::run_capture_command(cao);
    } else if (*cameras) {
      return hk::app::run_cameras_command();
    } else if (*devices) {
      return hk::app::run_devices(dvo);
    } else if (*calibrate) {
      return hk::app::run_calibrate(co);
    } else if (*stick) {
      return hk::app::run_stick(sto);
    } else if (*pin) {
      return hk::app::run_pin(po);
    } else if (!*speak) {
      return hk::app::run_kiosk(ko);
    } else if (*speak) {
      const std::string text = hk::app::run_speak(so);
      std::printf("speak: \"%s\" -> %s\n", text.c_str(), so.wav_path.c_str());
    }
  } catch (const std::exception& e) {
    print_error(e.what());
    return 1;
  }
  return 0;
}
