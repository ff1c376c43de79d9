#pragma once
/// @file settings.hpp
/// Typed settings of the kiosk with their defaults. Every field carries its unit in its name and
/// its allowed range in its comment; `config/load.hpp` reads them from TOML and enforces the ranges.
/// The TOML table and key of each field are given as [table] key.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace hk::config {

/// [haptics] — force rendering and the servo loop.
struct HapticsSettings {
  double stiffness_n_per_m =
      800.0;  ///< key stiffness_n_per_m, wall stiffness, [10, 5000] N/m and at most the device profile's stable limit
  double damping_n_s_per_m = 0.0;  ///< key damping_n_s_per_m, rendered damping in contact, [0, 20] N·s/m
  double max_force_n = 3.5;  ///< key max_force_n, force clamp, [0.1, 20] N and at most what the device gives everywhere
                             ///< (device_profile.hpp; the simulated pantograph 3.78 N)
  double servo_rate_hz = 1000.0;  ///< key servo_rate_hz, [100, 10000] Hz
  int level = 1;  ///< key level, resolution level at the start (and always, when level_mode = "fixed"), [0, 12] and <=
                  ///< max_levels; 0 = finest
  std::string level_mode =
      "auto";  ///< key level_mode, "auto" (a level from hand speed), "tolerance" (a tolerance from hand speed, each
               ///< curve at its own level within it), "cut" (a tolerance from hand speed, each segment refined only
               ///< while its error box exceeds it: the tolerance cut) or "fixed" (always `level`)
  double level_error_at_rest_m = 1e-4;  ///< key level_error_at_rest_m, deviation a slow fingertip cannot feel, [0,
                                        ///< 0.01] m; 0 = the finest level whenever the hand rests
  double level_blur_time_s =
      0.010;  ///< key level_blur_time_s, tolerable deviation grows by hand speed x this, [0, 0.1] s
  double level_hysteresis =
      0.3;  ///< key level_hysteresis, go coarser only when the bound is this fraction under the tolerance, [0, 0.9]
  double level_min_dwell_s = 0.15;       ///< key level_min_dwell_s, least time between two level changes, [0, 5] s
  double level_max_force_step_n = 0.05;  ///< key level_max_force_step_n, largest force change per tick a level change
                                         ///< or a live gains change (operator panel) may cause, [0.001, 5] N
  double static_friction =
      0.4;  ///< key static_friction, Coulomb static coefficient of the walls, [0, 2]; >= dynamic_friction
  double dynamic_friction = 0.3;  ///< key dynamic_friction, Coulomb dynamic coefficient, [0, 2]; 0 and 0 = frictionless
  int max_levels = 6;             ///< key max_levels, levels built above level 0, [1, 12]
  int query_box_budget = 4000;    ///< key query_box_budget, box tests the collision queries and level-change checks of
                                ///< one servo tick may do, [0, 10000000] box tests; 0 = no limit (default measured: see
                                ///< hk::kDefaultQueryBoxBudget in haptics/servo.hpp)
  double force_ramp_s = 0.5;  ///< key force_ramp_s, start-up force ramp, [0, 10] s
  double pop_force_n = 3.0;   ///< key pop_force_n, pressing a wall harder than this for pop_hold_s lets the proxy
                              ///< through, [0, 20] N; 0 = walls never give way
  double pop_hold_s = 0.3;    ///< key pop_hold_s, how long the press must last, [0.01, 5] s
  double pop_release_s =
      0.02;  ///< key pop_release_s, the force falls to zero over this after a push-through, [0.001, 1] s
  std::string render = "walls";  ///< key render, "walls" (the seed paper's god-object walls) or "grooves" (each curve
                                 ///< an engraved line that pulls the hand in, never blocks)
  double groove_capture_radius_m =
      0.003;  ///< key groove_capture_radius_m, a groove pulls within this distance of its curve, [0.0005, 0.02] m
  double groove_depth_n = 1.0;  ///< key groove_depth_n, the groove's depth as felt: its strongest pull, [0.05, 10] N
                                ///< (at most stiffness x radius / 2)
  double tour_max_force_n =
      1.2;  ///< key tour_max_force_n, the guided tour never pulls harder than this, [0.1, 5] N; below pop_force_n
  double tour_speed_m_per_s =
      0.03;  ///< key tour_speed_m_per_s, speed of the guided tour along an outline, [0.005, 0.2] m/s

  /// Field-by-field equality (exact for doubles); used by round-trip checks.
  bool operator==(const HapticsSettings&) const = default;
};

/// [device] — which device drives the handle: the simulated pantograph's physics, and the USB pantograph
/// (Haply 2DIY gen3 speaking hAPI over CDC serial): where to find it, its board layout (which
/// actuator and encoder sit on which port, their directions, offsets and resolutions), its links, its
/// torque limit, its usable rectangle and its calibration pose. The defaults are the gen3 2DIY's (Haply's
/// hAPI examples and firmware Haply_M0_Firmware_V0_3; ports cross-wired: actuator/encoder 1 on port 2).
struct DeviceSettings {
  std::string type =
      "auto";  ///< key type, "auto" (the USB pantograph when one answers, else simulated), "simulated", "haply" (2DIY
               ///< gen3) or "haply-gen2" (the original 2DIY); picks the device profile (device_profile.hpp)
  double handle_mass_kg = 0.08;           ///< key handle_mass_kg, effective handle mass, [0.001, 5] kg
  double handle_damping_n_s_per_m = 2.0;  ///< key handle_damping_n_s_per_m, device viscous damping, [0, 100] N·s/m
  int encoder_counts_per_rev = 16384;     ///< key encoder_counts_per_rev, [64, 1048576] counts/rev
  double max_torque_n_m = 0.5;            ///< key max_torque_n_m, per-motor torque limit, [0.02, 10] N·m
  std::string transport = "auto";         ///< key transport, "auto" (libusb, then the kernel's tty), "usb" or "tty"
  std::string usb_ids =
      "2341:003e,2341:804d,2341:004d,2341:824d,2341:024d";  ///< key usb_ids, the USB ids a board is looked for at,
                                                            ///< "VVVV:PPPP" (hex) comma-separated, 1 to 16, in order:
                                                            ///< Haply's boards enumerate as an Arduino Due's native
                                                            ///< port (2341:003e, the original dev board and M3) or an
                                                            ///< Arduino Zero's (804d, 004d, 824d, 024d: the M0 boards);
                                                            ///< each found is taken only once it answers hAPI
  std::string serial_path;  ///< key serial_path, tty of the board for the tty transport; empty = the first
                            ///< /dev/serial/by-id entry
  int device_id = 5;        ///< key device_id, hAPI device id, [1, 255]
  int lost_after_ticks =
      3;  ///< key lost_after_ticks, ticks without a valid reply before the device counts as lost, [1, 1000]
  int actuator1_port = 2;            ///< key actuator1_port, board port of actuator 1 (Haply joint 1), [1, 4]
  std::string actuator1_dir = "cw";  ///< key actuator1_dir, "cw" or "ccw"
  int actuator2_port = 1;            ///< key actuator2_port, [1, 4]
  std::string actuator2_dir = "cw";  ///< key actuator2_dir, "cw" or "ccw"
  int encoder1_port = 2;             ///< key encoder1_port, [1, 4]
  std::string encoder1_dir = "ccw";  ///< key encoder1_dir, "cw" or "ccw"
  double encoder1_offset_deg =
      180.0;  ///< key encoder1_offset_deg, joint 1 angle at the calibration pose, [-360, 360] deg
  double encoder1_resolution =
      4880.0;             ///< key encoder1_resolution, counts per revolution as the firmware takes it, [1, 1000000]
  int encoder2_port = 1;  ///< key encoder2_port, [1, 4]
  std::string encoder2_dir = "ccw";     ///< key encoder2_dir, "cw" or "ccw"
  double encoder2_offset_deg = 0.0;     ///< key encoder2_offset_deg, [-360, 360] deg
  double encoder2_resolution = 4880.0;  ///< key encoder2_resolution, [1, 1000000]
  double link_proximal_m = 0.07;        ///< key link_proximal_m, motor-to-elbow link l, [0.01, 0.5] m
  double link_distal_m = 0.09;          ///< key link_distal_m, elbow-to-handle link L, [0.01, 0.5] m
  double motor_spacing_m = 0.038;       ///< key motor_spacing_m, distance between the motor axes d, [0, 0.5] m
  double torque_limit_n_m = 0.123;      ///< key torque_limit_n_m, the board's torque limit per motor, [0.001, 10] N·m
  double rect_width_m =
      0.112;  ///< key rect_width_m, the USB pantograph's usable rectangle, mapped onto [workspace], [0.01, 1] m
  double rect_height_m = 0.072;     ///< key rect_height_m, [0.01, 1] m
  double rect_center_y_m = -0.088;  ///< key rect_center_y_m, its centre's distance from the motor axis line (negative:
                                    ///< towards the user), [-1, 1] m
  double park_x_m = 0.0;  ///< key park_x_m, where the handle rests for calibration, workspace frame, [-0.5, 0.5] m; the
                          ///< default is the board's home pose, the pose the encoder offsets name (both arms stretched
                          ///< out sideways: device_profile.hpp home_park_place)
  double park_y_m = 0.093276;  ///< key park_y_m, [-0.5, 0.5] m (beyond the far edge of the usable rectangle)

  /// Field-by-field equality (exact for doubles); used by round-trip checks.
  bool operator==(const DeviceSettings&) const = default;
};

/// [hand] — the model hand that drives the simulated pantograph in headless runs.
struct HandSettings {
  double stiffness_n_per_m = 200.0;    ///< key stiffness_n_per_m, hand spring to the target, [1, 5000] N/m
  double damping_n_s_per_m = 4.0;      ///< key damping_n_s_per_m, [0, 200] N·s/m
  double max_force_n = 2.0;            ///< key max_force_n, the most a visitor pushes with, [0.01, 50] N
  double raster_speed_m_per_s = 0.08;  ///< key raster_speed_m_per_s, target speed of the raster, [0.001, 5] m/s
  double raster_spacing_m = 0.006;     ///< key raster_spacing_m, line spacing of the raster, [0.0005, 0.05] m

  /// Field-by-field equality (exact for doubles); used by round-trip checks.
  bool operator==(const HandSettings&) const = default;
};

/// [vision] — image intake limits, edge detection and linking.
struct VisionSettings {
  std::int64_t max_file_bytes = 64LL << 20;  ///< key max_file_bytes, [1024, 2^31] bytes
  int max_width_px = 10000;                  ///< key max_width_px, [16, 100000] px
  int max_height_px = 10000;                 ///< key max_height_px, [16, 100000] px
  std::int64_t max_pixels = 40'000'000;      ///< key max_pixels, width·height limit, [256, 2^31] px
  double blur_sigma_px = 1.5;                ///< key blur_sigma_px, Gaussian pre-blur, [0, 20] px
  double canny_low = 0.0;                    ///< key canny_low, hysteresis low threshold, [0, 2000]; 0 = from the image
  double canny_high = 0.0;  ///< key canny_high, hysteresis high threshold, [0, 2000]; 0 = from the image; canny_low <=
                            ///< canny_high when both nonzero
  double min_chain_length_m = 0.004;  ///< key min_chain_length_m, drop shorter chains (can't be felt), [0, 0.1] m
  int max_image_side_px = 800;        ///< key max_image_side_px, images are downscaled to this, [64, 10000] px
  int max_segments =
      30000;  ///< key max_segments, scene budget: level-0 segments kept, most salient curves first, [100, 1000000]
  int max_shapes = 30;  ///< key max_shapes, shape budget: curves kept, most salient first (long, sure, closed,
                        ///< enclosing much), [1, 1000]
  double thin_line_max_width_m = 0.001;  ///< key thin_line_max_width_m, the two edges of a line thinner than this
                                         ///< become one curve, [0, 0.01] m; 0 = off
  double gap_close_m = 0.001;  ///< key gap_close_m, chain ends facing each other across a gap up to this are joined,
                               ///< [0, 0.005] m; 0 = off
  double surround_inhibition = 1.5;  ///< key surround_inhibition, texture test α of the "surround" detector
                                     ///< (vision::stands_out), [0, 4]; 0 = none
  std::string detector =
      "auto";  ///< key detector, how boundaries are found: "auto" (two-tone pictures traced from a threshold, line
               ///< drawings "canny", others "surround"), "canny", "surround", "bilateral", "edpf" or "outline"
  std::string ocr = "auto";   ///< key ocr, text in pictures read aloud (Tesseract): "auto" (pictures that look like a
                              ///< page of text, PDF pages without a text layer), "always" (every picture), "off"; the
                              ///< kiosk feels the picture at once and reads its text meanwhile (about 10 s a page)
  std::string ocr_languages;  ///< key ocr_languages, Tesseract languages '+'-joined ("eng", "eng+deu"); empty = the
                              ///< kiosk's language ([kiosk] language) and English ("fra+eng")
  double ocr_min_confidence =
      0.6;  ///< key ocr_min_confidence, marks with no letter or digit Tesseract is less sure of are said as "unclear
            ///< word" (words are said as read), a paragraph with no word this sure is left out, [0, 1]

  /// Field-by-field equality (exact for doubles); used by round-trip checks.
  bool operator==(const VisionSettings&) const = default;
};

/// [workspace] — the device's usable rectangle, centred on the workspace origin.
struct WorkspaceSettings {
  double width_m = 0.14;   ///< key width_m, [0.01, 1] m
  double height_m = 0.09;  ///< key height_m, [0.01, 1] m

  /// Field-by-field equality (exact for doubles); used by round-trip checks.
  bool operator==(const WorkspaceSettings&) const = default;
};

/// [audio] — earcons, speech and volume (audio-cues).
struct AudioSettings {
  int volume_default_step =
      7;  ///< key volume_default_step, volume at the start of every session, [1, 10] (10 = loudest)
  double volume_step_db = 3.0;      ///< key volume_step_db, loudness change per volume step, [1, 6] dB
  double earcon_gain = 0.5;         ///< key earcon_gain, level of the earcons before the volume, [0, 1]
  double duck_db = -14.0;           ///< key duck_db, earcons are this much quieter while speech plays, [-40, 0] dB
  int speech_rate_wpm = 165;        ///< key speech_rate_wpm, speaking rate, [80, 450] words/min
  std::string voice = "flite-slt";  ///< key voice, English's voice: "flite-slt", "flite-kal", "flite-awb", "flite-rms"
                                    ///< (CMU Flite) or "espeak" (espeak-ng); other languages speak with espeak-ng
  int buffer_frames = 256;  ///< key buffer_frames, audio output buffer, [32, 4096] frames (at 48 kHz: 256 = 5.3 ms)

  /// Field-by-field equality (exact for doubles); used by round-trip checks.
  bool operator==(const AudioSettings&) const = default;
};

/// [kiosk] — the visitor's session.
struct KioskSettings {
  double timeout_s = 120.0;  ///< key timeout_s, no key, no handle motion, no contact and no speech for this long ends
                             ///< the session, [20, 3600] s
  double warning_s = 20.0;   ///< key warning_s, the spoken warning comes this long before the end, [10, 600] s (at most
                             ///< half of timeout_s)
  double attract_every_s = 30.0;  ///< key attract_every_s, while nobody is there a short spoken invitation comes this
                                  ///< often, [0, 3600] s (0 = never)
  std::string quiet_hours;  ///< key quiet_hours, local times with no invitation, "HH:MM-HH:MM" (may pass midnight:
                            ///< "22:00-07:00"); empty = none
  int prefetch_mb = 256;    ///< key prefetch_mb, memory for the next and previous pictures' scenes built ahead of the
                            ///< visitor, [0, 4096] MiB (0 = none built ahead)
  std::string scene_cache =
      "auto";  ///< key scene_cache, where built scenes of library pictures are kept on disk: "auto"
               ///< ($CACHE_DIRECTORY/scenes under the service, else $XDG_CACHE_HOME/haptic-kiosk/scenes, else
               ///< ~/.cache/haptic-kiosk/scenes), "off", or an absolute folder
  std::string names_dir =
      "auto";  ///< key names_dir, where names staff give shapes at the kiosk are kept (NAME.annotations.json; they
               ///< win over the file beside the picture): "auto" ($STATE_DIRECTORY/names under the service, else
               ///< $XDG_DATA_HOME/haptic-kiosk/names, else ~/.local/share/haptic-kiosk/names), "off" (only the files
               ///< beside the pictures), or an absolute folder
  std::string library =
      "auto";  ///< key library, the picture library folder, watched: a picture added, changed or removed there is
               ///< taken without a restart once its files have been unchanged for 2 s and it decodes. "auto"
               ///< ($STATE_DIRECTORY/library under the service, else the shipped pictures) or an absolute folder;
               ///< the shipped pictures while it holds none. The command line's --library wins
  std::string say_names_on_touch = "on";  ///< key say_names_on_touch, "on": the first touch of a named shape in a visit
                                          ///< of a picture says its name, once; "off": names only when asked
  std::string languages = "en, fr, de, es";  ///< key languages, the languages offered to visitors, BCP 47 tags
                                             ///< separated by commas, in the order the Language key steps through
  std::string language = "en";               ///< key language, the language each visit starts in, one of languages

  /// Field-by-field equality (exact for doubles); used by round-trip checks.
  bool operator==(const KioskSettings&) const = default;
};

/// [stick] — documents from USB sticks: how far a scan goes and how PDF pages are drawn. A stick
/// is a stranger's: every limit here bounds what one can make the kiosk do.
struct StickSettings {
  int max_depth = 8;        ///< key max_depth, deepest folder entered (the stick's root is 0), [1, 64]
  int max_entries = 10000;  ///< key max_entries, directory entries looked at per scan, [10, 1000000]
  int max_documents = 500;  ///< key max_documents, documents offered per stick, [1, 100000]
  std::int64_t max_file_bytes = 200LL << 20;  ///< key max_file_bytes, largest document, [1024, 2^31] bytes
  double scan_timeout_s = 2.0;                ///< key scan_timeout_s, wall-clock limit of one scan, [0.1, 60] s
  int max_pdf_pages = 1000;  ///< key max_pdf_pages, pages offered per PDF (the first ones), [1, 100000]
  double page_max_pixels =
      4e6;  ///< key page_max_pixels, a PDF page is drawn at the DPI that keeps it within this, [1e5, 4e7] px
  double page_max_dpi = 300.0;  ///< key page_max_dpi, never drawn finer than this, [10, 1200] dpi
  double page_timeout_s =
      5.0;  ///< key page_timeout_s, the worker drawing a page is stopped after this (wall clock and CPU), [0.5, 120] s

  /// Field-by-field equality (exact for doubles); used by round-trip checks.
  bool operator==(const StickSettings&) const = default;
};

/// [camera] — the camera a visitor puts a picture under: which source, the frame size asked
/// for, and when the framing guide captures.
struct CameraSettings {
  std::string source = "auto";  ///< key source, "auto" (the first camera found: libcamera, then V4L2), "none" (no
                                ///< capture), or a source "file:PATH" | "libcamera:N" | "v4l2:DEV"
  int width_px = 1280;          ///< key width_px, frame width asked of the camera, [64, 8192] px
  int height_px = 960;          ///< key height_px, frame height asked of the camera, [64, 8192] px
  double still_s =
      1.0;  ///< key still_s, the page must be whole, centred and still this long before it is captured, [0.2, 10] s
  double timeout_s =
      60.0;  ///< key timeout_s, a capture that has not happened after this long is given up (said so), [5, 600] s

  /// Field-by-field equality (exact for doubles); used by round-trip checks.
  bool operator==(const CameraSettings&) const = default;
};

/// [keys] — the key for each of the visitor's actions (keys a blind visitor can find). Each value
/// is one key name: F1..F12, A..Z, 0..9, SPACE, ENTER, TAB, BACKSPACE, LEFT, RIGHT, UP, DOWN, PAGE_UP,
/// PAGE_DOWN, HOME, END, INSERT, DELETE, MINUS, EQUAL, KP_0..KP_9, KP_ADD, KP_SUBTRACT, KP_ENTER.
/// O, C and ESCAPE are never a visitor's (ESCAPE quits in windowed mode).
struct KeysSettings {
  std::string help = "F1";                ///< key help
  std::string next = "RIGHT";             ///< key next, next picture (next tutorial shape)
  std::string previous = "LEFT";          ///< key previous
  std::string describe = "D";             ///< key describe, speak what the picture holds and where
  std::string finer = "UP";               ///< key finer, more detail (finer level)
  std::string coarser = "DOWN";           ///< key coarser, less detail
  std::string volume_up = "PAGE_UP";      ///< key volume_up
  std::string volume_down = "PAGE_DOWN";  ///< key volume_down
  std::string tutorial = "T";             ///< key tutorial, start the tutorial again
  std::string guide =
      "G";  ///< key guide, the guided tour: the handle is led to the next shape not yet touched and round it
  std::string capture = "SPACE";  ///< key capture, capture a picture with the camera, guided by voice (any key cancels)
  std::string repeat = "R";       ///< key repeat, the last thing said, again from its start
  std::string pause = "P";        ///< key pause, speech stops where it is; pressed again, it goes on
  std::string where = "W";  ///< key where, "what is here": the shape under or nearest the hand, and where the hand is
  std::string finish =
      "END";  ///< key finish, ends the visit (pressed twice: goodbye, defaults restored, waiting for the next visitor)
  std::string next_sentence = "K";      ///< key next_sentence, reading a text: on from the next sentence
  std::string previous_sentence = "J";  ///< key previous_sentence, reading a text: back to the sentence before
  std::string next_paragraph = "I";  ///< key next_paragraph, reading a text: on from the next paragraph (block of text)
  std::string previous_paragraph = "U";  ///< key previous_paragraph, reading a text: back to the paragraph before
  std::string language = "L";            ///< key language, the next of the offered languages ([kiosk] languages)
  std::string copy = "H";                ///< key copy, pressed twice: a copy of the picture to take home ([copy])

  /// Field-by-field equality; used by round-trip checks.
  bool operator==(const KeysSettings&) const = default;
};

/// Visitor actions in [keys].
inline constexpr std::size_t kKeyActionCount = 21;

/// Each [keys] action's name and its key, in table order: help, next, previous, describe, finer, coarser,
/// volume_up, volume_down, tutorial, guide, capture, repeat, pause, where, finish, next_sentence,
/// previous_sentence, next_paragraph, previous_paragraph, language, copy. The one list that the
/// validation, the spoken key placeholders (audio::kKeyPlaceholders, the same order) and the window's key map
/// follow. The views point into `keys`: keep it alive while they are used.
inline std::array<std::pair<std::string_view, std::string_view>, kKeyActionCount> key_actions(const KeysSettings& k) {
  return {{{"help", k.help},
           {"next", k.next},
           {"previous", k.previous},
           {"describe", k.describe},
           {"finer", k.finer},
           {"coarser", k.coarser},
           {"volume_up", k.volume_up},
           {"volume_down", k.volume_down},
           {"tutorial", k.tutorial},
           {"guide", k.guide},
           {"capture", k.capture},
           {"repeat", k.repeat},
           {"pause", k.pause},
           {"where", k.where},
           {"finish", k.finish},
           {"next_sentence", k.next_sentence},
           {"previous_sentence", k.previous_sentence},
           {"next_paragraph", k.next_paragraph},
           {"previous_paragraph", k.previous_paragraph},
           {"language", k.language},
           {"copy", k.copy}}};
}

/// One USB id of [device] usb_ids.
struct UsbId {
  std::uint16_t vid = 0;  ///< vendor id
  std::uint16_t pid = 0;  ///< product id
  bool operator==(const UsbId&) const = default;
};

/// Reads [device] usb_ids: "VVVV:PPPP" with four hex digits each (either case), comma-separated, spaces
/// around the commas allowed, 1 to 16 of them. On a malformed value returns an empty list and, when `why`
/// is given, sets it to one phrase saying what is wrong.
std::vector<UsbId> parse_usb_ids(std::string_view text, std::string* why = nullptr);

/// Quiet hours as minutes after local midnight: from `first` (inclusive) to `second` (exclusive), passing
/// midnight when second < first.
using QuietHours = std::pair<int, int>;

/// Reads [kiosk] quiet_hours: "HH:MM-HH:MM" (00:00 to 23:59 each, two digits each; the two times differ).
/// Empty → nullopt with no error. On a malformed value returns nullopt and, when `why` is given, sets it to
/// one phrase saying what is wrong.
std::optional<QuietHours> parse_quiet_hours(std::string_view text, std::string* why = nullptr);

/// Whether `minute_of_day` [0, 1440) lies in `hours`.
inline bool in_quiet_hours(const QuietHours& hours, int minute_of_day) {
  return hours.first <= hours.second ? minute_of_day >= hours.first && minute_of_day < hours.second
                                     : minute_of_day >= hours.first || minute_of_day < hours.second;
}

/// [copy] — take-home copies of a picture (a tactile graphic with braille), made when a visitor presses the Copy
/// key twice.
struct CopySettings {
  std::string to = "off";    ///< key to, where copies go: "off" (none offered), "printer" (a CUPS queue), "stick"
                             ///< (a new folder on the visitor's FAT or exFAT stick) or "both"
  std::string printer;       ///< key printer, the CUPS queue copies are printed on ("" = none)
  std::string printed_line;  ///< key printed_line, said when a copy went to the printer, staff's words ("" = the
                             ///< catalogue's "Your copy is being printed. Ask for it at the front desk.")
  int per_visit = 1;         ///< key per_visit, copies a visitor may have, [0, 20]
  int per_day = 50;          ///< key per_day, copies the kiosk makes a day (counted since midnight), [0, 10000]
  std::string paper = "a4";  ///< key paper, "a4", "letter" or "11x11.5in" (swell paper, embossers)
  int braille_grade = 2;     ///< key braille_grade, 1 uncontracted or 2 contracted braille, [1, 2]

  bool operator==(const CopySettings&) const = default;
};

/// [metrics] — the Prometheus metrics endpoint that a museum's monitoring scrapes (counts only, no visitor data).
struct MetricsSettings {
  std::string listen;  ///< key listen, "ADDRESS:PORT" the endpoint listens on for GET /metrics (an IPv4 address, or
                       ///< an IPv6 one in brackets: "127.0.0.1:9471", "[::1]:9471"); "" = off

  bool operator==(const MetricsSettings&) const = default;
};

/// [operator] — the operator's panel: how it is opened, its PIN and where its records go.
/// Paths left empty are beside the settings file: `<settings>.state` and `<settings>.audit.log`.
struct OperatorSettings {
  std::string open_chord =
      "CTRL+ALT+O";  ///< key open_chord, the key chord that asks for the PIN: modifiers (CTRL, ALT, SHIFT, SUPER; at
                     ///< least one of CTRL, ALT, SUPER) and one key, joined by '+'
  double idle_close_s =
      60.0;                ///< key idle_close_s, the panel closes itself after this long without input, [10, 3600] s
  std::string pin_hash;    ///< key pin_hash, argon2id hash of the PIN (libsodium crypto_pwhash_str), written by
                           ///< `haptic-kiosk pin set`; empty = no PIN, the panel stays shut
  std::string state_file;  ///< key state_file, failed PIN attempts and the time of the last (the lockout), survives
                           ///< restarts; empty = `<settings>.state`
  std::string audit_log;   ///< key audit_log, one line per change made in the panel; empty = `<settings>.audit.log`
  std::string language = "en";  ///< key language, the panel's language (BCP 47); English where it has no catalogue

  /// Field-by-field equality; used by round-trip checks.
  bool operator==(const OperatorSettings&) const = default;
};

/// All settings. Default-constructed = the shipped defaults.
struct Settings {
  HapticsSettings haptics;
  DeviceSettings device;
  HandSettings hand;
  VisionSettings vision;
  WorkspaceSettings workspace;
  AudioSettings audio;
  KioskSettings kiosk;
  StickSettings stick;
  CameraSettings camera;
  KeysSettings keys;
  CopySettings copy;
  MetricsSettings metrics;
  OperatorSettings operator_;  ///< TOML table [operator] (`operator` is a C++ keyword)

  /// Field-by-field equality (exact for doubles); used by round-trip checks.
  bool operator==(const Settings&) const = default;
};

}  // namespace hk::config
