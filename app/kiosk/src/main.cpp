// haptic-kiosk: command line entry. Subcommands: explore (headless run, DESIGN.md contract), capture (one camera
// capture), cameras (the cameras found), stick (what a USB stick offers), pin (set or check the operator's PIN), speak
// (a message or text rendered to WAV), devices (USB and serial devices found) and calibrate (the USB pantograph's
// encoder offsets), tactile (a take-home copy of a picture) and library check (a picture library checked before
// roll-out).
#include <spdlog/cfg/env.h>
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>

#include "cli/audio_settings.hpp"
#include "cli/device_command.hpp"
#include "cli/explore.hpp"
#include "cli/library_command.hpp"
#include "cli/pin_command.hpp"
#include "cli/stick_command.hpp"
#include "cli/tactile_command.hpp"
#include "formats/app_error.hpp"
#include "kiosk/kiosk_app.hpp"
#include "pictures/capture.hpp"
#include "runtime/event_log.hpp"

namespace {

/// Errors reach the visitor's operator as exactly one line: fold any line breaks a library put in.
void print_error(const std::string& what) {
  std::string line = what;
  for (char& ch : line) {
    if (ch == '\n' || ch == '\r') ch = ' ';
  }
  std::fprintf(stderr, "haptic-kiosk: %s\n", line.c_str());
}

/// The options of every subcommand, bound to the command line and filled as CLI11 parses it (so it must stay
/// where it is while `cli` lives), and the subcommands, to tell which one was given.
struct Commands {
  hk::app::KioskOptions ko;
  hk::app::ExploreOptions eo;
  std::string seed_text = "1";  // explore --seed, checked by parse_seed
  hk::app::CaptureOptions cao;
  hk::app::DevicesOptions dvo;
  hk::app::CalibrateOptions co;
  hk::app::SpeakOptions so;
  hk::app::StickOptions sto;
  hk::app::PinOptions po;
  hk::app::TactileOptions to;
  hk::app::LibraryOptions lo;
  CLI::App* explore = nullptr;
  CLI::App* capture = nullptr;
  CLI::App* cameras = nullptr;
  CLI::App* devices = nullptr;
  CLI::App* calibrate = nullptr;
  CLI::App* speak = nullptr;
  CLI::App* stick = nullptr;
  CLI::App* pin = nullptr;
  CLI::App* tactile = nullptr;
  CLI::App* library = nullptr;
  CLI::App* library_check = nullptr;
};

/// The kiosk's own options (no subcommand: the window with the picture library).
void add_kiosk_options(CLI::App& cli, hk::app::KioskOptions& ko) {
  cli.add_flag("--windowed", ko.windowed, "A 1280 x 720 window instead of full screen (development)");
  cli.add_option("--config", ko.config_path, "Settings file (TOML)");
  cli.add_option("--library", ko.library,
                 "Picture folder, watched for pictures added, changed or removed (default: [kiosk] library)");
  cli.add_option("--show", ko.show, "Start on this picture, past the welcome and tutorial (documentation, tests)");
  cli.add_flag("--high-contrast", ko.high_contrast,
               "Start in high contrast: dimmed picture, thick bright curves (also in the operator's panel)");
  cli.add_flag("--overlay", ko.overlay, "Start with the operator overlay (also in the operator's panel)");
  CLI::Option* screenshot = cli.add_option(
      "--screenshot", ko.screenshot, "Run --frames frames (scripted input from --script), write the last as PNG, quit");
  cli.add_option("--frames", ko.frames, "Frames to run before the screenshot (60 per second)");
  cli.add_option(
      "--frame-stats", ko.frame_stats,
      "At exit (after --frames, or when the window closes) write the window's frame times as JSON: frames, "
      "p50/p95/p99/max ms "
      "and frames over 20 ms, for all frames and for those while a picture changes (Next/Previous key to the new scene "
      "drawn). 'interval' is frame start to next frame start, the buffer swap included: with --screenshot it also "
      "holds "
      "a fixed 16.7 ms pause per frame, live it is paced by vsync (under Xvfb, no vsync: by the software GL's swap); "
      "'work' is frame start to before the swap");
  cli.add_option("--script", ko.script,
                 "Scripted input (with --screenshot: a scripted run's clock is its frames): lines 'FRAME key NAME', "
                 "'FRAME cursor X_M Y_M', 'FRAME move', 'FRAME stick DIR', 'FRAME unstick', 'FRAME wait_loaded'")
      ->needs(screenshot);
  cli.add_option("--stick", ko.stick, "A folder treated as a USB stick inserted at start");
  cli.add_flag("!--no-hotplug", ko.hotplug, "Do not watch for USB sticks");
  cli.add_option("--mount-root", ko.mount_root, "Where USB sticks are mounted (default /run/haptic-kiosk/usb)");
  cli.add_option("--device", ko.device,
                 "haply-emulator[:FAULT=V,...]: the USB pantograph's driver on the firmware emulator behind a pty, "
                 "pulled by the mouse "
                 "(default: the device of [device])");
}

/// `explore`: the whole pipeline headless on a picture, a PDF page or a camera capture (DESIGN.md contract).
void add_explore_command(CLI::App& cli, Commands& c) {
  c.explore = cli.add_subcommand("explore", "Run the whole pipeline headless on the simulated pantograph");
  CLI::Option* input =
      c.explore->add_option("input", c.eo.image_path, "Picture (PNG, JPEG, BMP, TIFF, WebP) or PDF to explore");
  CLI::Option* source =
      c.explore->add_option("--source", c.eo.source,
                            "A camera capture in place of the input: file:PATH (an image or a folder of frames), "
                            "libcamera:N or v4l2:DEV; capture.png and capture.json go beside the outputs");
  input->excludes(source);
  source->excludes(input);
  c.explore->add_option("--page", c.eo.page, "Page of a PDF, from 1 (default 1)")->check(CLI::PositiveNumber);
  CLI::Option* out =
      c.explore->add_option("--out", c.eo.out_dir, "Folder for scene.json, trace.csv, summary.json, overlay.png");
  CLI::Option* where = c.explore->add_option(
      "--where", c.eo.where, "X_M,Y_M: print what Where would say with the hand there [m], and run nothing else");
  CLI::Option* describe =
      c.explore->add_flag("--describe", c.eo.describe, "Print what Describe would say, and run nothing else");
  where->excludes(out)->excludes(describe);
  describe->excludes(out);
  c.explore
      ->add_option(
          "--hand", c.eo.hand,
          "Model hand: 'raster', 'explorer' (sweeps, traces outlines, pushes through walls it knows) or a CSV file "
          "with header t_s,x_m,y_m")
      ->default_val("raster");
  c.explore->add_option("--seed", c.seed_text,
                        "The explorer's seed, a whole number >= 0 (default 1): same seed, same run");
  c.explore
      ->add_option("--duration", c.eo.duration_s,
                   "Run length [s]; default: the hand path's length, 120 s for the explorer")
      ->check(CLI::PositiveNumber);
  c.explore->add_option("--config", c.eo.config_path, "Settings file (TOML)");
  c.explore->add_option("--audio-out", c.eo.audio_out,
                        "Also render the run's earcons to this WAV file (tick k at t = k / servo rate)");
  c.explore
      ->add_option(
          "--device", c.eo.device,
          "sim, or haply-emulator[:FAULT=VALUE,...] (the firmware emulator behind a pty; faults disconnect_at_s, "
          "drop_every, garbage_every, wrong_id_every, stall_at_s, stall_s, seed, calib_error1_deg, calib_error2_deg)")
      ->default_val("sim");
}

/// The camera and device tools: `capture`, `cameras`, `devices` and `calibrate`.
void add_camera_and_device_commands(CLI::App& cli, Commands& c) {
  c.capture = cli.add_subcommand("capture",
                                 "Capture a picture from a camera or frames once: the page found, guided, rectified");
  c.capture->add_option("--source", c.cao.source, "file:PATH (an image or a folder of frames), libcamera:N or v4l2:DEV")
      ->required();
  c.capture->add_option("--out", c.cao.out_dir, "Folder for capture.png and capture.json")->required();
  c.capture->add_option("--config", c.cao.config_path, "Settings file (TOML): [camera]");
  c.cameras = cli.add_subcommand("cameras", "List the cameras found (libcamera, then V4L2)");
  c.devices = cli.add_subcommand(
      "devices", "List the USB and serial devices found, and ask each way to a board for an hAPI reply");
  c.devices->add_option("--config", c.dvo.config_path,
                        "Settings file (TOML): [device] usb_ids, transport, serial_path");
  c.calibrate = cli.add_subcommand("calibrate", "With the handle resting at the park place, set the encoder offsets");
  c.calibrate->add_option("--config", c.co.config_path, "Settings file (TOML) to read and to write the offsets into")
      ->required();
  c.calibrate->add_option("--device", c.co.device, "haply (the board) or haply-emulator[:calib_error1_deg=V,...]")
      ->default_val("haply");
}

/// The speech, stick and operator tools: `speak`, `stick` and `pin`.
void add_speak_stick_pin_commands(CLI::App& cli, Commands& c) {
  c.speak = cli.add_subcommand("speak", "Render a message of the catalogue, or any text, as speech into a WAV file");
  c.speak->add_option("what", c.so.what, "A message key (welcome, help, picture_loaded, ...) or text to say")
      ->required();
  c.speak->add_option("--wav", c.so.wav_path, "WAV file to write")->required();
  c.speak->add_option("--config", c.so.config_path, "Settings file (TOML): [audio] speech_rate_wpm");
  c.speak->add_option("--language", c.so.language,
                      "The catalogue's language (a BCP 47 tag: en, fr, de, es; default en), its voice too");
  c.stick = cli.add_subcommand(
      "stick", "What a USB stick (a folder, or a device mounted read-only) offers, and what was refused and why");
  c.stick->add_option("folder", c.sto.folder, "A mounted stick or any folder");
  c.stick->add_option("--device", c.sto.device,
                      "A block device (e.g. /dev/sdb1): mounted read-only, scanned, unmounted (needs CAP_SYS_ADMIN)");
  c.stick->add_option("--json", c.sto.json_path, "Write the listing to this file (default: standard output)");
  c.stick->add_option("--config", c.sto.config_path, "Settings file (TOML): [stick] limits");
  c.stick->add_option("--mount-root", c.sto.mount_root, "Where --device is mounted (default /run/haptic-kiosk/usb)");
  c.pin = cli.add_subcommand("pin", "Set or check the operator's PIN (read from standard input)");
  c.pin
      ->add_option(
          "action", c.po.action,
          "set: a new PIN (4 to 12 digits); check: exit 0 right, 1 wrong, 2 locked, 3 no PIN or unusable settings; "
          "hash: print the PIN's hash (for a museum's roll-out); set-hash: a hash read (as hash prints it) becomes "
          "the settings file's (\"unchanged\" when it already is)")
      ->required()
      ->check(CLI::IsMember({"set", "check", "hash", "set-hash"}));
  c.pin->add_option("--config", c.po.config_path,
                    "Settings file (TOML) holding [operator] pin_hash (every action but hash)");
}

/// The take-home copy: `tactile`.
void add_tactile_command(CLI::App& cli, Commands& c) {
  c.tactile = cli.add_subcommand(
      "tactile", "A take-home copy of a picture as a tactile graphic with braille labels: PDF, SVG or BRF");
  c.tactile->add_option("picture", c.to.picture, "A picture file or a PDF")->required();
  c.tactile->add_option("--out", c.to.out, "Files to write: FILE.pdf (swell paper, embossers), FILE.svg, FILE.brf")
      ->required();
  c.tactile->add_option("--page", c.to.page, "A PDF's page (from 1)");
  c.tactile->add_option("--level", c.to.level, "Resolution level, 0 = finest (default: [haptics] level)");
  c.tactile->add_option("--paper", c.to.paper, "a4 (default), letter or 11x11.5in");
  c.tactile->add_option("--language", c.to.language, "Names and braille in this language (default: [kiosk] language)");
  c.tactile->add_option("--grade", c.to.grade, "Braille grade: 2 contracted (default) or 1 uncontracted");
  c.tactile->add_option("--title", c.to.title, "The copy's title (default: the picture's own, else its file name)");
  c.tactile->add_option("--config", c.to.config_path, "Settings file (TOML)");
}

/// The library's own: `library check`.
void add_library_command(CLI::App& cli, Commands& c) {
  c.library = cli.add_subcommand("library", "The picture library: check one before it is rolled out");
  c.library->require_subcommand(1);
  c.library_check = c.library->add_subcommand(
      "check",
      "Check a library folder: every picture decodes within the limits, every sidecar and annotation file loads; "
      "one line per problem (FILE: reason); exit 0 all well, 1 problems, 2 the folder cannot be read");
  c.library_check->add_option("folder", c.lo.folder, "The library folder")->required();
  c.library_check->add_option("--config", c.lo.config_path, "Settings file (TOML) whose [vision] limits apply");
}

/// Runs the subcommand given (the kiosk when none) and returns the process's exit status.
/// @throws whatever the command throws (hk::Error and the like); main prints it as one line.
int run_command(Commands& c) {
  if (*c.explore) {
    if (c.eo.image_path.empty() && c.eo.source.empty())
      throw hk::app::AppError("explore: give a picture or PDF to explore, or --source");
    if (!c.eo.where.empty() || c.eo.describe) {
      std::printf("%s\n", hk::app::explore_answer(c.eo).c_str());
      return 0;
    }
    if (c.eo.out_dir.empty()) throw hk::app::AppError("explore: --out is required (or --where X_M,Y_M, or --describe)");
    c.eo.seed = hk::app::parse_seed(c.seed_text);
    const auto sum = hk::app::run_explore(c.eo);
    std::printf("explore: %ld ticks, %zu curves, contact %ld edge + %ld vertex ticks, max force %.3f N -> %s\n",
                sum.ticks, sum.curves, sum.edge_ticks, sum.vertex_ticks, sum.max_force_n, c.eo.out_dir.c_str());
  } else if (*c.capture) {
    return hk::app::run_capture_command(c.cao);
  } else if (*c.cameras) {
    return hk::app::run_cameras_command();
  } else if (*c.devices) {
    return hk::app::run_devices(c.dvo);
  } else if (*c.calibrate) {
    return hk::app::run_calibrate(c.co);
  } else if (*c.stick) {
    return hk::app::run_stick(c.sto);
  } else if (*c.pin) {
    return hk::app::run_pin(c.po);
  } else if (*c.tactile) {
    return hk::app::run_tactile(c.to);
  } else if (*c.library) {
    return hk::app::run_library_check(c.lo);
  } else if (!*c.speak) {
    return hk::app::run_kiosk(c.ko);
  } else if (*c.speak) {
    const std::string text = hk::app::run_speak(c.so);
    std::printf("speak: \"%s\" -> %s\n", text.c_str(), c.so.wav_path.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  hk::app::use_kiosk_logger();     // the journal under the service (HK_EVENT fields), else standard error
  spdlog::cfg::load_env_levels();  // SPDLOG_LEVEL=debug shows e.g. each piece of speech as it is handed on
  CLI::App cli{"haptic-kiosk: feel the shapes in a picture through a force-feedback pantograph"};
  cli.require_subcommand(0, 1);
  Commands c;
  add_kiosk_options(cli, c.ko);
  add_explore_command(cli, c);
  add_camera_and_device_commands(cli, c);
  add_speak_stick_pin_commands(cli, c);
  add_tactile_command(cli, c);
  add_library_command(cli, c);
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cli.exit(e);
  }
  try {
    return run_command(c);
  } catch (const std::exception& e) {
    print_error(e.what());
    return 1;
  }
}
