#pragma once
/// @file kiosk_runtime.hpp
/// Everything the kiosk runs apart from its window, wired together: the device and its servo thread
/// (DeviceHost: the USB pantograph when one answers — [device] type "auto" or "haply" — else the simulated
/// pantograph driven by the cursor through the model hand), the audio side and the parts that answer the
/// visitor's flow (kiosk_effects.hpp): the spoken lines (Voice), what is shown (Stage), the library's pictures
/// (LibraryDesk over the PictureShelf), USB sticks (StickDesk), the camera (CameraDesk) and the guided tour
/// (TourDesk). It applies settings changed by the operator while it runs (apply_settings). No OpenGL here:
/// the window layer (app/kiosk) draws what `stage().shown()` holds, and tests drive the runtime headless.
///
/// Threads: construct, call and destroy on one thread (the window thread); the servo thread, the scene
/// builder's worker (every library picture and every rebuild after Apply is built there, never on the window
/// thread: scene_builder.hpp), the text reader's and the stick service's threads are owned here.

#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "audio/system.hpp"
#include "config/settings.hpp"
#include "formats/picture_notes.hpp"
#include "pictures/capture_service.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/library_watch.hpp"
#include "pictures/picture_shelf.hpp"
#include "pictures/stick_service.hpp"
#include "pictures/text_reader.hpp"
#include "runtime/device_host.hpp"
#include "runtime/guided_tour.hpp"
#include "runtime/metrics_server.hpp"
#include "runtime/servo_step.hpp"
#include "runtime/servo_thread.hpp"
#include "visit/camera_desk.hpp"
#include "visit/copy_desk.hpp"
#include "visit/display_switches.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/library_desk.hpp"
#include "visit/operator_session.hpp"
#include "visit/stage.hpp"
#include "visit/stick_desk.hpp"
#include "visit/tour_desk.hpp"
#include "visit/voice.hpp"

namespace hk::app {

/// What the runtime is started with besides the settings.
struct RuntimeOptions {
  std::string library;  ///< picture folder (already resolved); without library_settle_s it must hold a picture
  /// > 0: `library` is watched (library_watch.hpp) with this quiet time [s], and the pictures there are live as
  /// they settle; while it holds none, the pictures of `shipped_library` are the library. 0: read once at start.
  double library_settle_s = 0.0;
  std::string shipped_library;    ///< the shipped pictures' folder (with library_settle_s)
  bool hotplug = true;            ///< watch for USB sticks (libudev)
  std::string mount_root;         ///< where sticks are mounted; empty: sticks::kDefaultStickMountRoot
  bool high_contrast = false;     ///< start (and every session) in high contrast
  bool overlay = false;           ///< start with the operator overlay
  bool open_audio_output = true;  ///< false: no PortAudio (tests)
  /// Look for the USB pantograph ([device] type "auto" or "haply"); false: always the simulated one (tests,
  /// documentation runs).
  bool probe_usb_device = true;
  /// Empty: the device of [device]. "haply-emulator[:FAULT=V,...]" (parse_device_choice): the USB
  /// pantograph's driver on the firmware emulator behind a pty, its handle pulled by the cursor through the
  /// model hand (demonstrations, documentation, tests). @throws DeviceChoiceError for anything else.
  std::string device;
  /// Where built scenes of library pictures are kept (scene_cache.hpp; KioskApp passes scene_cache_dir of the
  /// settings); empty: none kept (tests, scripted runs).
  std::string scene_cache_dir;
  /// Look for a camera when [camera] source is "auto" (list_cameras); false: "auto" means no camera (scripted
  /// runs, tests). A source named in the settings ("file:...", "libcamera:N", "v4l2:DEV") is used either way.
  bool probe_camera = false;
};

/// The kiosk without its window. Not thread-safe: one thread.
class KioskRuntime final : private SessionEffects {
 public:
  /// Opens the device (the USB pantograph when [device] type is "auto" or "haply" and one answers, else the
  /// simulated pantograph), the audio side and the stick service. Call start_servo() next.
  /// OCR ([vision] ocr) is turned off, said once in the log, when a language it needs has no traineddata.
  /// @throws AppError (one line) for an empty library; audio::MessageError for a bad catalogue.
  KioskRuntime(const RuntimeOptions& options, const config::Settings& settings);
  ~KioskRuntime() override;
  KioskRuntime(const KioskRuntime&) = delete;
  KioskRuntime& operator=(const KioskRuntime&) = delete;

  /// Starts the servo thread at [haptics] servo_rate_hz (devices().stop_servo() stops it; so does the
  /// destructor). @throws hk::ArgumentError for a bad rate.
  void start_servo() { devices_.start_servo(core_); }
  /// Says which device is in use: "The handle is ready." or that the kiosk runs on its simulated handle
  /// (nothing when the simulated pantograph was chosen: [device] type "simulated", or probe_usb_device off).
  /// The first time after a start whose board did not read its home pose, the staff's line follows
  /// (device_not_home); never again, so no visitor hears it.
  void announce_device();
  /// What the visitor's flow asks of the kiosk, each answered by the part that does it (kiosk_effects.hpp).
  KioskEffects effects();

  /// Window thread, every frame (`now_s` the frame clock [s]), before the frame's input: a new listing of the
  /// library folder watched (LibraryDesk::offer_listing), the news of the library's scenes (LibraryDesk::poll), of
  /// sticks (StickDesk::poll) and of the camera (CameraDesk::poll) handed to `flow` (null: a headless caller; the
  /// library's pictures are still felt, stick and camera news wait), the text of the page shown (Stage::poll_text), and
  /// the device: says when the handle has been lost for 0.5 s and, after that, when it works again (shorter losses are
  /// not spoken), and, while the simulated pantograph stands in for a USB pantograph that was not found, switches to
  /// one that arrives (USB hot-plug, or a probe every 10 s); then the metrics of the frame (servo totals, device, time
  /// in contact, library size; metrics.hpp).
  void poll(KioskFlow* flow, double now_s);
  /// The metrics endpoint's port (0: [metrics] listen is off, or it could not listen: logged).
  int metrics_port() const { return metrics_ ? metrics_->port() : 0; }
  /// Window thread, every frame, after the frame's input: the guided tour (TourDesk::poll), the display
  /// switches said (DisplaySwitches::poll), and scene bundles the servo thread has let go of freed.
  void poll_after_input();

  /// The operator changed settings. Compared with the settings in use, field by field
  /// (config::FieldDescriptor::apply): servo gains go to the servo thread at once (no force step beyond
  /// level_max_force_step_n per tick: ServoStep::set_gains); level and scene settings rebuild what is shown
  /// here, off the servo thread, and it is swapped in with the fade; keys and the session's timing change
  /// in `flow` at once; the rest is kept for the next visitor or the next start (listed in the report).
  /// `settings` must be valid (config::validate). Returns what was done.
  ApplyReport apply_settings(const config::Settings& settings, KioskFlow& flow);
  /// The settings in use (the last applied).
  const config::Settings& settings() const { return s_; }
  /// The longest side the screen shows a picture at [px] (the kiosk's window: picture_side_px), clamped to
  /// [256, kScreenPictureMaxSidePx] (the default). Pictures built after this call (library, stick pages, text
  /// read) are shrunk to it on their workers (fit_picture). Window thread.
  void set_screen_picture_side_px(int px);
  /// Half the workspace's extent [m].
  Vec2 half() const { return half_; }

  /// The device, its servo thread and the model hand (device_host.hpp): the device the servo thread drives,
  /// the USB pantograph in use (or null), Calibrate, and why the simulated pantograph stands in.
  DeviceHost& devices() { return devices_; }
  const DeviceHost& devices() const { return devices_; }
  /// The servo step the servo thread runs (its display state, gains, levels).
  ServoStep& core() { return core_; }
  audio::AudioSystem& audio() { return audio_; }
  /// Every line said: the caption, Repeat, Pause.
  Voice& voice() { return voice_; }
  /// What is shown on the device and the screen, Describe and Where, the level, the page's text.
  Stage& stage() { return stage_; }
  /// The library's pictures.
  LibraryDesk& library() { return library_; }
  /// USB sticks.
  StickDesk& sticks() { return sticks_; }
  /// The camera.
  CameraDesk& camera() { return camera_; }
  CopyDesk& copies() { return copies_; }
  /// The guided tour, and the model hand's target (TourDesk::set_cursor: the mouse or a script stands in
  /// for the visitor's hand).
  TourDesk& tour() { return tour_; }
  /// High contrast and the overlay (the operator panel's checkboxes).
  DisplaySwitches& switches() { return switches_; }

 private:
  KioskRuntime(const RuntimeOptions& options, const config::Settings& checked_settings,
               int);  // settings already checked
  bool change_volume(int delta) override;
  void new_session() override;
  void poll_device(double now_s);
  void rebuild_shown();
  void poll_metrics(double now_s);  // the frame's servo totals, device, time in contact and library size
  void adopt_board_profile();  // the board's profile in force: settings_for_board, then servo params, hand and gains
                               // from them

  /// The visitor's language and the key page's words in it, for a copy.
  CopyDesk::Language copy_language() const;

  RuntimeOptions opt_;
  config::Settings s_;  // the settings in use: every part below reads them by reference
  audio::AudioSystem audio_;
  Voice voice_;
  Vec2 half_;
  ServoStep core_;
  DeviceHost devices_;  // after core_: its servo thread steps core_, and stops before core_ goes
  TourDesk tour_;
  std::unique_ptr<LibraryWatch> watch_;  // the library folder watched (null: read once)
  std::vector<std::string> shipped_;     // the shipped pictures, the library while the folder watched holds none
  PictureShelf shelf_;                   // the library's scenes, asked for and built ahead
  Stage stage_;
  LibraryDesk library_;
  DisplaySwitches switches_;
  CameraDesk camera_;                       // its worker stops before the rest goes
  StickDesk sticks_;                        // its threads stop before the parts above go
  CopyDesk copies_;                         // its worker, which may wait on sticks_, stops before sticks_ goes
  std::unique_ptr<MetricsServer> metrics_;  // last, so it stops first: [metrics] listen (null: off)
  double contact_clock_s_ = -1.0;           // poll's clock at its last call, for the time in contact
  std::uint64_t library_refused_ = 0;       // the watch's refusals already counted
  std::string metrics_device_;              // the device as the metrics last had it
  bool metrics_connected_ = false;
};

/// The device profile in force (config/device_profile.hpp): the board's ("haply", "haply-gen2") while a USB
/// pantograph or the emulated board is in use, else [device] type ("auto" and "simulated" both mean the
/// simulated pantograph's). The operator's panel shows and applies its limits.
std::string profile_type(const KioskRuntime& rt);

}  // namespace hk::app
