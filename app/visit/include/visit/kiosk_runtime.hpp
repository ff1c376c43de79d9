#pragma once
/// @file kiosk_runtime.hpp
/// Everything the kiosk runs apart from its window, wired together: the device and its servo thread
/// (DeviceHost: the USB pantograph when one answers — [device] type "auto" or "haply" — else the simulated
/// pantograph driven by the cursor through the model hand), the library's scenes (PictureShelf), the spoken
/// lines (Voice), the audio side, the USB stick service, the camera, the text reader and what is shown
/// (scene on the device, curves for the screen). It implements the visitor's flow's KioskEffects, and
/// applies settings changed by the operator while it runs (apply_settings). No OpenGL here: the window
/// layer (app/kiosk) draws what `shown()` holds, and tests drive the runtime headless.
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
#include "pictures/picture_shelf.hpp"
#include "pictures/stick_service.hpp"
#include "pictures/text_reader.hpp"
#include "runtime/device_host.hpp"
#include "runtime/guided_tour.hpp"
#include "runtime/servo_step.hpp"
#include "runtime/servo_thread.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/tour_desk.hpp"
#include "visit/voice.hpp"

namespace hk::app {

/// What the runtime is started with besides the settings.
struct RuntimeOptions {
  std::string library;            ///< picture folder (already resolved; must hold at least one picture)
  bool hotplug = true;            ///< watch for USB sticks (libudev)
  std::string mount_root;         ///< where sticks are mounted; empty: vision::kDefaultStickMountRoot
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

/// What is on the device and on the screen.
struct Shown {
  std::vector<Polyline> polylines;                     ///< level-0 source curves [m] (for Describe)
  std::vector<std::vector<std::vector<Vec2>>> levels;  ///< [curve][level] → points [m]
  /// With level_mode = "cut": [curve][tolerance step] → the cut's segments (tolerance_cut) and its joined
  /// polyline (joined_cut_points) [m], what the walls are at that cut step; empty otherwise.
  std::vector<std::vector<std::vector<SegmentRef>>> cut_segments;
  std::vector<std::vector<std::vector<Vec2>>> cuts;
  std::vector<bool> closed;             ///< [curve]
  cv::Mat picture;                      ///< BGR, empty for tutorial shapes
  vision::PxToM px_to_m{1, 0, 0};       ///< picture pixels → workspace metres
  const Scene* scene = nullptr;         ///< the published scene (read-only here; for the overlay)
  std::vector<TextBlockM> text_blocks;  ///< a document page's text (Describe reads the one under the hand)
  PictureNotes notes;                   ///< a library picture's title and description (its sidecar)
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

/// The kiosk without its window. Not thread-safe: one thread.
class KioskRuntime final : public KioskEffects {
 public:
  /// Opens the device (the USB pantograph when [device] type is "auto" or "haply" and one answers, else the
  /// simulated pantograph), the audio side and the stick service. Call start_servo() next.
  /// OCR ([vision] ocr) is turned off, said once in the log, when a language it needs has no traineddata.
  /// @throws AppError (one line) for an empty library; audio::MessageError for a bad catalogue.
  KioskRuntime(const RuntimeOptions& options, const config::Settings& settings);
  ~KioskRuntime() override;
  KioskRuntime(const KioskRuntime&) = delete;
  KioskRuntime& operator=(const KioskRuntime&) = delete;

  /// Starts the servo thread at [haptics] servo_rate_hz. @throws hk::ArgumentError for a bad rate.
  void start_servo();
  /// Stops it (idempotent).
  void stop_servo();
  /// Says which device is in use: "The handle is ready." or that the kiosk runs on its simulated handle
  /// (nothing when the simulated pantograph was chosen: [device] type "simulated", or probe_usb_device off).
  /// The first time after a start whose board did not read its home pose, the staff's line follows
  /// (device_not_home); never again, so no visitor hears it.
  void announce_device();
  /// Says which camera there is: "There is a camera: press … to feel a picture of your own." or "No
  /// camera was found." (nothing when [camera] source is "none", or "auto" was not probed). Logged either way.
  void announce_camera();
  /// Whether there is a camera to capture from.
  bool has_camera() const { return capture_.available(); }
  /// Window thread, every frame (`now_s` the frame clock [s]): says when the handle has been lost for
  /// 0.5 s and, after that, when it works again (the servo thread's display state carries the device
  /// status; shorter losses are not spoken), and, while the simulated pantograph stands in for a USB
  /// pantograph that was not found, switches to one that arrives (USB hot-plug, or a probe every 10 s).
  /// A probe that fails logs a warning only when its reason differs from the last one's (else at debug).
  void poll_device(double now_s);
  /// The device, its servo thread and the model hand (device_host.hpp): the device the servo thread drives,
  /// the USB pantograph in use (or null), Calibrate, and why the simulated pantograph stands in.
  DeviceHost& devices() { return devices_; }
  const DeviceHost& devices() const { return devices_; }
  /// The device profile in force (config/device_profile.hpp): the board's ("haply", "haply-gen2") while a USB
  /// pantograph or the emulated board is in use, else [device] type ("auto" and "simulated" both mean the
  /// simulated pantograph's). The operator's panel shows and applies its limits.
  std::string profile_type() const;

  // ---- KioskEffects (kiosk_flow.hpp) ----
  /// Logs "say: TEXT", shows it as the caption and speaks it; Repeat says it again.
  void say(const std::string& text) override;
  /// As say(), but Repeat passes it over.
  void say_brief(const std::string& text) override;
  /// Says the last text given to say() again (false when there is none in this visit).
  bool repeat() override;
  std::uint64_t kept_texts() const override { return voice_.kept_texts(); }
  /// Texts given to say() or say_brief() since the start: a key press that leaves it unchanged said nothing.
  std::uint64_t texts_said() const { return voice_.texts_said(); }
  /// The piece of the last text given to say() being heard (audio::AudioSystem::piece_heard); −1 once an
  /// acknowledgement (say_brief) has cut it off.
  int heard_piece() const override { return voice_.heard_piece(); }
  /// The blocks of text of the page shown, and the one under the proxy (as Describe reads it).
  PageText page_text() override;
  bool speaking() const override { return audio_.speaking(); }
  bool pause_speech() override { return audio_.pause_speech(); }
  bool resume_speech() override { return audio_.resume_speech(); }
  /// Whether the local time of day lies in [kiosk] quiet_hours.
  bool quiet_hours() const override;
  /// Words of a block of text that Where reads (Describe reads it whole).
  static constexpr int kWhereTextWords = 8;
  /// "What is here": on a document page, the block of text under the hand (its number and first words);
  /// else the shape the proxy touches or the hand is nearest (describe.hpp shape_at_hand: its number, size,
  /// kind, what lies in it and what it lies in), and where the hand is (place_words).
  std::string where() override;
  void show_tutorial(TutorialShape shape) override;
  /// Picture `index` of the library: put on the device at once when it was built ahead (returns its shapes),
  /// else asked of the scene builder (returns kPicturePending; poll_pictures puts it on the device and tells
  /// the flow). The picture felt before stays until then.
  int show_picture(int index) override;
  int picture_count() const override { return shelf_.count(); }
  PictureNotes shown_notes() const override { return shown_.notes; }
  /// What the picture or page holds (describe.hpp), led by "Reading the text." while its text is read.
  std::string describe() override;
  void show_document(int document, int page) override;
  void forget_stick() override;
  bool change_level(int delta) override;
  bool auto_level() const override { return auto_level_; }
  bool change_volume(int delta) override;
  void new_session() override;
  void key_pressed() override;
  /// The Capture key: starts a capture on the camera's worker (CaptureService::start); false without a camera.
  bool start_capture() override;
  /// Stops the capture under way.
  void cancel_capture() override;
  /// Window thread, every frame: the capture's news handed to the flow: advice to say; a picture taken (the
  /// Shutter earcon, its scene put on the device with the fade, KioskFlow::capture_done); a failure or a
  /// time-out (KioskFlow::capture_failed).
  void poll_capture(KioskFlow& flow, double now_s);
  /// The capture under way's latest frame and page (for the preview), empty when none is under way.
  CapturePreview capture_preview() const { return capture_.busy() ? capture_.preview() : CapturePreview{}; }
  /// The Guide key: when the picture shown has a shape not yet touched in this visit (plan_tour), asks
  /// first: "I will guide your hand to a shape. Hold the handle lightly." The tour is planned from where the
  /// handle is then and handed to the servo thread once that has been said (poll_tour: the announcement's
  /// length in servo ticks, kTourAskMargin_s more), so no guide force comes before the visitor has heard it.
  /// Nothing left: says so (tour_all_touched, or tour_nothing for a picture without shapes). A press that
  /// stopped a running or announced tour says tour_stopped instead. With the simulated pantograph the model
  /// hand goes limp while the tour runs (it follows the handle), so the tour leads the handle.
  void guide() override;
  /// Window thread, every frame: keeps what the handle touches (the servo's contact curve) in this visit's
  /// touches; hands an announced tour to the servo thread when it is due; and when the tour handed over has
  /// ended, says what it traced and what remains ("That was shape 2, a small closed shape, on the left. 3
  /// shapes not yet touched."; "Tour stopped. …" instead of what it traced when the hand held it back or the
  /// device was lost; nothing when a key or the mouse stopped it, or a new picture or visitor came) and gives
  /// the handle back to the cursor where it is.
  void poll_tour();
  /// Whether a tour announced or handed to the servo thread has not yet been reported ended (poll_tour).
  bool tour_running() const { return tour_.running(); }
  /// A tour is announced and not yet handed to the servo thread.
  bool tour_announced() const { return tour_.announced(); }
  /// Extra time after the tour's announcement before its force may start [s] (the sound device's latency).
  static constexpr double kTourAskMargin_s = TourDesk::kAskMargin_s;
  /// The shapes touched in this visit of the picture shown.
  const VisitTouches& touches() const { return tour_.touches(); }

  /// Window thread, every frame (`now_s` the frame clock [s]): scenes the builder has finished. The one asked
  /// for is put on the device with the fade and handed to `flow` (picture_ready or picture_failed; null: a
  /// headless caller that only wants it felt); scenes built ahead are kept within [kiosk] prefetch_mb; then
  /// the next and previous pictures of the one shown are asked for ahead (the first picture while none is
  /// shown: the one the tutorial leads to).
  void poll_pictures(KioskFlow* flow, double now_s);
  /// Whether a scene asked for (a picture, or a rebuild after Apply) is not yet on the device (scripted runs
  /// hold their frames for it).
  bool picture_busy() const { return shelf_.busy(); }
  /// Blocks until the scene asked for is built, then poll_pictures(flow, now_s) (tests, scripted and headless
  /// runs; never the frame loop). At most `timeout_s` [s]; returns whether it came.
  bool finish_picture(KioskFlow* flow, double now_s, double timeout_s = 60.0);
  /// Scene builds started since the start (asked for and built ahead): what the visitor's keys cost.
  std::uint64_t scene_builds() const { return shelf_.builds_started(); }
  /// Scenes put on the device so far (publish): what tests count to see that a superseded page never was.
  std::uint64_t scenes_published() const { return scenes_published_; }
  /// The longest side the screen shows a picture at [px] (the kiosk's window: picture_side_px), clamped to
  /// [256, kScreenPictureMaxSidePx] (the default). Pictures built after this call (library, stick pages, text
  /// read) are shrunk to it on their workers (fit_picture). Window thread.
  void set_screen_picture_side_px(int px);
  /// Library pictures built ahead and waiting (their indices).
  std::vector<int> pictures_ahead() const { return shelf_.ahead(); }
  /// Window thread, every frame: news of sticks and finished loads, handed to the flow.
  void poll_sticks(KioskFlow& flow, double now_s);
  /// Window thread, every frame (`now_s` the frame clock [s]): the text of the page shown, read by the
  /// TextReader since it was shown (a page or picture built with its text pending is felt at once). Says
  /// "Reading the text." once when the reading has taken more than kTextWait_s and nothing else is being
  /// said (a stick page's announcement says it at once). When the text comes, the scene with the words
  /// masked and its blocks is swapped in with the fade, and, once nothing else is being said, "The text is
  /// ready. It has 3 blocks of text and one figure."; or "No text was found." (only after "Reading the
  /// text."); or "The text could not be read." (a worker that crashed, hung or ran out of memory).
  void poll_text(double now_s);
  /// Whether the text of the page shown is being read, or its news not yet said (scripted runs wait for it).
  bool text_busy() const { return text_.pending() || !text_news_.empty(); }
  /// How long a reading may take before "Reading the text." is said [s].
  static constexpr double kTextWait_s = 1.0;
  /// Whether stick work (scan or load) may still bring news (scripted runs wait for it).
  bool stick_busy() const { return stick_busy_ || stick_folder_ops_ > 0; }
  /// What the last stick could not give, for the operator's panel (a visitor hears only a count): one line a
  /// file, "'bad_crc.png': corrupt PNG header: …" for pictures and PDFs left out at the scan and "'manual.pdf'
  /// page 3: …" for pages that could not be built, then other entries left out (links, other files); at most
  /// kStickProblems (the log has them all). Kept until the next stick is inserted.
  const std::vector<std::string>& stick_problems() const { return stick_problems_; }
  static constexpr std::size_t kStickProblems = 200;
  /// A folder treated as an inserted USB stick / taken out again (documentation, tests).
  void insert_stick_folder(const std::string& dir);
  void remove_stick_folder();

  /// The operator changed settings. Compared with the settings in use, field by field
  /// (config::FieldDescriptor::apply): servo gains go to the servo thread at once (no force step beyond
  /// level_max_force_step_n per tick: ServoStep::set_gains); level and scene settings rebuild what is shown
  /// here, off the servo thread, and it is swapped in with the fade; keys and the session's timing change
  /// in `flow` at once; the rest is kept for the next visitor or the next start (listed in the report).
  /// `settings` must be valid (config::validate). Returns what was done.
  ApplyReport apply_settings(const config::Settings& settings, KioskFlow& flow);
  /// The settings in use (the last applied).
  const config::Settings& settings() const { return s_; }

  /// The model hand's target [m] (the mouse or a script stands in for the visitor's hand). After a guided
  /// tour the hand keeps the place the tour led the handle to: later cursors are offset by it (until the
  /// next visitor). While a tour runs, a cursor more than 3 mm from where it was at its start stops the
  /// tour (the visitor's hand takes over).
  void set_cursor(Vec2 m);
  ServoStep& core() { return core_; }
  audio::AudioSystem& audio() { return audio_; }
  const Shown& shown() const { return shown_; }
  /// SceneBundle id of what is shown (tutorial −1..−3, picture index, 1000 + stick page, camera captures
  /// kFirstCaptureId, kFirstCaptureId − 1, ...).
  int shown_id() const { return shown_id_; }
  /// Level in use (the servo thread's, which follows the hand's speed in auto mode).
  int level() { return core_.display().level; }
  /// Half the workspace's extent [m].
  Vec2 half() const { return half_; }
  /// The operator's display switches (the panel's checkboxes). A change is announced by poll_display_modes.
  bool& high_contrast() { return high_contrast_; }
  bool& overlay() { return overlay_; }
  /// Window thread, every frame: says and logs a change of high contrast or the overlay ("High contrast on.").
  void poll_display_modes();
  /// Index of `path` in the library, −1 when it is not there.
  int find_picture(const std::string& path) const;
  /// Puts `path` first in the library (documentation runs: --show of a picture from elsewhere).
  void add_picture_first(const std::string& path) { shelf_.add_first(path); }
  /// Frees scene bundles the servo thread has let go of (every frame).
  void collect() { core_.collect_retired(); }
  /// The last text said (the caption).
  const std::string& last_said() const { return voice_.last_said(); }
  /// The stick service, for the operator's status.
  const StickService& sticks() const { return sticks_; }

 private:
  KioskRuntime(const RuntimeOptions& options, const config::Settings& checked_settings,
               int);  // settings already checked
  CueTrackerParams cue_params() const;
  void show_built(ImageScene& is, int id);     // publishes it; starts reading its text when pending
  int put_picture(int index, ImageScene& is);  // library picture `index` on the device, with its notes; its shapes
  void reset_level();                          // the operator's level and mode again (a new picture or visitor)
  bool showing_tutorial() const;               // a practice shape is shown (ids -1 .. -3)
  std::string shape_words(std::size_t curve) const;  // what curve `curve` of what is shown is, for Where and the tour
  TourPicture tour_picture() const;                  // what is shown, as the tour sees it
  void text_arrived(TextRead& read);                 // swaps in the page with its text and words what came
  std::string describe_shown();                      // describe() of what is shown, without the reading's news
  void publish(Shown sh, std::unique_ptr<Scene> scene, int id, std::vector<Aabb> text_boxes = {});
  void rebuild_shown();
  void adopt_board_profile();  // the board's profile in force: settings_for_board, then servo params, hand and gains
                               // from them

  RuntimeOptions opt_;
  config::Settings s_;
  audio::AudioSystem audio_;
  Voice voice_;  // every line said: the caption, Repeat
  Vec2 half_;
  ServoParams sp_;
  ServoStep core_;
  DeviceHost devices_;  // after core_: its servo thread steps core_, and stops before core_ goes
  TourDesk tour_;       // the guided tour's window-thread half
  PictureShelf shelf_;  // the library's scenes, asked for and built ahead
  Shown shown_;
  int level_ = 1;           // the fixed level (auto_level_ false)
  bool auto_level_ = true;  // levels from hand speed
  bool high_contrast_ = false, overlay_ = false;
  bool said_contrast_ = false, said_overlay_ = false;  // the switches as last announced
  int shown_id_ = -100;
  std::uint64_t scenes_published_ = 0;
  int shown_picture_ = -1;                        // library index shown, −1 for none
  int shown_page_ = 0;                            // a document page shown (from 1), 0 for a picture
  int screen_side_px_ = kScreenPictureMaxSidePx;  // set_screen_picture_side_px
  int shown_document_ = -1;                       // stick document shown, −1 for none
  int rebuild_page_id_ = 0;  // a stick page re-requested by apply_settings (shown without a new announcement)
  static constexpr int kFirstCaptureId = -100;  // shown_id_ of the first camera capture; later ones count down
  int captures_ = 0;                            // camera captures shown so far
  int stick_id_ = 0;                            // the stick the flow browses (StickNews::stick), 0 for none
  bool stick_busy_ = false;
  int stick_folder_ops_ = 0;                 // folders put in or taken out whose news has not come yet (one news each)
  std::vector<std::string> stick_problems_;  // stick_problems()
  void note_stick_problem(std::string line);
  bool far_near_said_ = false;  // Where on a practice shape has said what far and near mean in this visit
  // The text of the page shown (window thread).
  TextReader text_;
  double text_since_s_ = -1.0;  // poll_text's clock when the reading was first seen, −1 before
  bool text_said_ = false;      // "Reading the text." was said for it
  std::string text_news_;       // what came of it, said once nothing else is being said
  int text_news_id_ = 0;        // the scene it is about
  CaptureService capture_;      // the camera; its worker stops before the rest goes
  StickService sticks_;         // last: its threads stop first
};

}  // namespace hk::app
