#include "visit/kiosk_runtime.hpp"

#include "config/device_profile.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <future>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "config/load.hpp"
#include "formats/app_error.hpp"
#include "haptics/io/tty_transport.hpp"
#include "haptics/tolerance_cut.hpp"
#include "pictures/picture_library.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/device_setup.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/simulation.hpp"
#include "vision/intake.hpp"
#include "visit/describe.hpp"

namespace hk::app {
namespace {

std::unique_ptr<vision::BlockEventSource> block_events(bool hotplug) {
  if (!hotplug) return nullptr;
  try {
    return std::make_unique<vision::UdevBlockEventSource>();
  } catch (const std::exception& e) {
    spdlog::warn("usb sticks: no hot-plug ({}); the kiosk runs on without sticks", e.what());
    return nullptr;
  }
}

audio::AudioSystemParams audio_params(const config::Settings& s, bool open_output) {
  audio::AudioSystemParams p = audio_params_from(s);
  p.open_output = open_output;
  return p;
}

/// The settings the kiosk runs with: as given, but with OCR off when a language it needs has no traineddata
/// (said once in the log; the kiosk runs on without reading text).
config::Settings with_usable_ocr(const config::Settings& s) {
  if (s.vision.ocr == "off") return s;
  const std::string why = vision::ocr_languages_problem(ocr_params_from(s));
  if (why.empty()) return s;
  spdlog::error("ocr: {}; text in pictures is not read (set [vision] ocr_languages, or install the language)", why);
  config::Settings off = s;
  off.vision.ocr = "off";
  return off;
}

/// The library's pictures (list_pictures: throws AppError for an empty or unreadable folder) on a shelf, with
/// the scene cache of `o` (none when its folder is empty).
PictureShelf library_shelf(const RuntimeOptions& o, const config::Settings& s) {
  std::shared_ptr<SceneCache> cache;
  if (!o.scene_cache_dir.empty()) {
    cache = std::make_shared<SceneCache>(o.scene_cache_dir);
    spdlog::info("scenes: kept in {}", o.scene_cache_dir);
  }
  return PictureShelf(list_pictures(o.library), std::move(cache), s);
}

}  // namespace

KioskRuntime::KioskRuntime(const RuntimeOptions& o, const config::Settings& given)
    : KioskRuntime(o, with_usable_ocr(given), 0) {}

KioskRuntime::KioskRuntime(const RuntimeOptions& o, const config::Settings& s, int /*checked*/)
    : opt_(o),
      s_(s),
      audio_(audio_params(s, o.open_audio_output)),
      voice_(audio_),
      half_{s.workspace.width_m / 2, s.workspace.height_m / 2},
      sp_(servo_params_from(s)),
      core_(cue_params(), &audio_.cues()),
      devices_(s),
      tour_(core_, devices_, voice_, audio_, s_, half_, devices_.simulated_handle_m()),
      shelf_(library_shelf(o, s)),
      capture_(s, o.probe_camera || s.camera.source != "auto"
                      ? choose_camera(s.camera)
                      : CameraChoice{{}, {}, "not looked for (a scripted run)"}),
      sticks_(s, block_events(o.hotplug),
              o.mount_root.empty() ? std::string(vision::kDefaultStickMountRoot) : o.mount_root) {
  if (!o.device.empty()) {
    devices_.open_emulated_board(o.device);
    adopt_board_profile();
  } else if (s.device.type != "simulated" && o.probe_usb_device) {
    if (devices_.try_open_usb()) {
      adopt_board_profile();
      devices_.check_home(true);
    }
    devices_.watch_hotplug();
  }
  level_ = s.haptics.level;
  auto_level_ = s.haptics.level_mode != "fixed";
  high_contrast_ = said_contrast_ = o.high_contrast;
  overlay_ = said_overlay_ = o.overlay;
}

KioskRuntime::~KioskRuntime() { devices_.stop_servo(); }

void KioskRuntime::start_servo() { devices_.start_servo(core_); }

void KioskRuntime::stop_servo() { devices_.stop_servo(); }

void KioskRuntime::adopt_board_profile() {
  std::vector<std::string> notes;
  s_ = settings_for_board(s_, &notes);
  for (const std::string& n : notes) spdlog::warn("device: {}", n);
  sp_ = servo_params_from(s_);
  devices_.set_settings(s_);
  shelf_.set_settings(s_, false);
  core_.set_gains(servo_gains_from(s_));
  capture_.set_settings(s_);
}

std::string KioskRuntime::profile_type() const { return devices_.usb() ? board_profile_type(s_) : s_.device.type; }

void KioskRuntime::announce_device() {
  if (s_.device.type == "simulated" && opt_.device.empty()) return;  // chosen: nothing to tell
  if (!opt_.probe_usb_device && opt_.device.empty()) return;
  const bool usb = devices_.usb() != nullptr;
  std::string text = audio_.messages().text(usb ? audio::MessageId::device_ready : audio::MessageId::device_simulated);
  // A handle that did not start at home is the staff's to fix: said at start only, before any visitor.
  if (devices_.take_home_unspoken() && usb) text += " " + audio_.messages().text(audio::MessageId::device_not_home);
  say(text);
}

void KioskRuntime::announce_camera() {
  const CameraChoice& c = capture_.camera();
  if (c.spec) {
    spdlog::info("camera: {}", c.name);
    say(audio_.messages().text(audio::MessageId::camera_ready, {}, key_args(s_.keys)));
    return;
  }
  spdlog::info("camera: none ({})", c.why);
  if (s_.camera.source == "none" || (s_.camera.source == "auto" && !opt_.probe_camera)) return;
  say(audio_.messages().text(audio::MessageId::camera_none));
}

bool KioskRuntime::start_capture() {
  const bool started = capture_.start();
  if (started) shelf_.drop_want();  // the visitor's own picture comes next, not a library picture still being built
  return started;
}

void KioskRuntime::cancel_capture() { capture_.cancel(); }

void KioskRuntime::poll_capture(KioskFlow& flow, double now_s) {
  for (CaptureNews& n : capture_.poll()) {
    switch (n.kind) {
      case CaptureNews::Kind::Advice:
        flow.capture_advice(advice_message(n.advice), now_s);
        break;
      case CaptureNews::Kind::Captured: {
        audio_.play(audio::CueKind::Shutter);
        const int shapes = static_cast<int>(n.scene->scene->curve_count());
        show_built(*n.scene, kFirstCaptureId - captures_++);
        shown_.notes = {};
        shown_picture_ = -1;
        shown_document_ = -1;
        shown_page_ = 0;
        flow.capture_done(shapes, now_s);
        break;
      }
      case CaptureNews::Kind::Failed:
        flow.capture_failed(false, now_s);
        break;
      case CaptureNews::Kind::TimedOut:
        flow.capture_failed(true, now_s);
        break;
    }
  }
}

void KioskRuntime::poll_device(double now_s) {
  const bool probe = s_.device.type != "simulated" && opt_.probe_usb_device;
  switch (devices_.poll(now_s, core_.display().device_status, probe)) {
    case DeviceNews::None:
      return;
    case DeviceNews::Lost:
      say(audio_.messages().text(audio::MessageId::device_lost));
      return;
    case DeviceNews::Back:
      say(audio_.messages().text(audio::MessageId::device_back));
      return;
    case DeviceNews::Arrived: {
      const bool running = devices_.servo() != nullptr;
      adopt_board_profile();
      devices_.check_home(false);  // a visitor may be there: the log and the panel only
      rebuild_shown();             // the groove depth is built into the scene
      if (running) devices_.start_servo(core_);
      announce_device();
      return;
    }
  }
}

void KioskRuntime::say(const std::string& text) { voice_.say(text); }

void KioskRuntime::say_brief(const std::string& text) { voice_.say_brief(text); }

bool KioskRuntime::repeat() { return voice_.repeat(); }

bool KioskRuntime::quiet_hours() const {
  const std::optional<config::QuietHours> hours = config::parse_quiet_hours(s_.kiosk.quiet_hours);
  if (!hours) return false;
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  if (localtime_r(&now, &local) == nullptr) return false;
  return config::in_quiet_hours(*hours, local.tm_hour * 60 + local.tm_min);
}

std::string KioskRuntime::where() {
  const ServoDisplayState& d = core_.display();
  const std::string place = place_words(d.handle_m, half_);
  const audio::MessageCatalog& m = audio_.messages();
  if (const TextBlockM* b = text_block_at(shown_.text_blocks, d.handle_m)) {
    const auto index = b - shown_.text_blocks.data();
    return m.text(audio::MessageId::where_text,
                  {{"block", std::to_string(index + 1)},
                   {"blocks", std::to_string(shown_.text_blocks.size())},
                   {"where", place},
                   {"text", first_words(name_unclear_words(b->text, m), kWhereTextWords)}});
  }
  const ShapeAtHand at = shape_at_hand(shown_.polylines, d.handle_m, d.scene_id == shown_id_ ? d.curve : -1);
  // A practice shape: far and near explained with the first answer of the visit, not again.
  const bool explain = showing_tutorial() && !far_near_said_;
  far_near_said_ = far_near_said_ || explain;
  const std::string far_near = explain ? " " + m.text(audio::MessageId::far_near) : std::string();
  if (at.curve < 0) return m.text(audio::MessageId::where_none, {{"where", place}}) + far_near;
  return m.text(at.on ? audio::MessageId::where_on : audio::MessageId::where_near,
                {{"shape", std::to_string(at.curve + 1)},
                 {"shapes", std::to_string(shown_.polylines.size())},
                 {"description", shape_words(static_cast<std::size_t>(at.curve))},
                 {"where", place}}) +
         far_near;
}

bool KioskRuntime::showing_tutorial() const { return shown_id_ <= -1 && shown_id_ >= -3; }

std::string KioskRuntime::shape_words(std::size_t curve) const {
  if (showing_tutorial() && !shown_.notes.title.empty()) return shown_.notes.title;  // "a square"
  return describe_one_shape(shown_.polylines, curve, half_, false);
}

void KioskRuntime::poll_display_modes() {
  if (high_contrast_ != said_contrast_) {
    said_contrast_ = high_contrast_;
    say_brief(audio_.messages().text(high_contrast_ ? audio::MessageId::high_contrast_on
                                                    : audio::MessageId::high_contrast_off));
  }
  if (overlay_ != said_overlay_) {
    said_overlay_ = overlay_;
    say_brief(audio_.messages().text(overlay_ ? audio::MessageId::overlay_on : audio::MessageId::overlay_off));
  }
}

void KioskRuntime::show_tutorial(TutorialShape shape) {
  shelf_.drop_want();  // a picture still being built is not wanted any more
  Shown sh;
  sh.polylines = {tutorial_polyline(shape, half_)};
  static constexpr audio::MessageId kNames[] = {audio::MessageId::shape_square, audio::MessageId::shape_circle,
                                                audio::MessageId::shape_triangle};
  sh.notes.title = audio_.messages().text(kNames[static_cast<int>(shape)]);  // Where, Describe and the tour name it
  publish(std::move(sh),
          std::make_unique<Scene>(Scene::build({tutorial_polyline(shape, half_)}, s_.haptics.max_levels)),
          -1 - static_cast<int>(shape));
  text_.cancel();
  text_news_.clear();
  shown_picture_ = -1;
  shown_document_ = -1;
  shown_page_ = 0;
}

int KioskRuntime::show_picture(int index) {
  reset_level();  // a level the visitor chose holds for one picture
  if (std::unique_ptr<ImageScene> is = shelf_.take_or_want(index)) return put_picture(index, *is);
  return KioskEffects::kPicturePending;
}

int KioskRuntime::put_picture(int index, ImageScene& is) {
  const int shapes = static_cast<int>(is.scene->curve_count());
  PictureNotes notes = std::move(is.notes);  // read on the worker
  show_built(is, index);
  shown_.notes = std::move(notes);
  shown_picture_ = index;
  shown_document_ = -1;
  shown_page_ = 0;
  shelf_.build_ahead(shown_picture_);
  return shapes;
}

void KioskRuntime::poll_pictures(KioskFlow* flow, double now_s) {
  if (std::optional<ShelfDelivery> d = shelf_.poll()) {
    BuiltScene& b = d->built;
    spdlog::info("scene {}: built in {:.0f} ms (waited {:.0f} ms to start)", b.id, b.build_ms, b.queued_ms);
    if (!b.scene) {
      spdlog::warn("scene {}: {}; the picture felt before stays", b.id, b.error);
      if (d->kind == ShelfDelivery::Kind::Picture && flow)
        flow->picture_failed(b.id, problem_of(b.error), now_s);  // "Picture N of M" names it
    } else if (d->kind == ShelfDelivery::Kind::Rebuild) {
      PictureNotes notes = std::move(shown_.notes);
      show_built(*b.scene, b.id);  // the same picture with the new settings: no new announcement
      shown_.notes = std::move(notes);
      if (b.id >= 0 && b.id < picture_count()) shelf_.build_ahead(shown_picture_);
    } else {
      const int shapes = put_picture(b.id, *b.scene);
      if (flow) flow->picture_ready(b.id, shapes, now_s);
    }
  }
  shelf_.build_ahead(shown_picture_);
}

bool KioskRuntime::finish_picture(KioskFlow* flow, double now_s, double timeout_s) {
  if (!shelf_.busy()) return true;
  const bool came = shelf_.wait(timeout_s);
  poll_pictures(flow, now_s);
  return came;
}

void KioskRuntime::show_built(ImageScene& is, int id) {
  Shown sh;
  sh.polylines = is.polylines;
  sh.picture = is.picture;  // the pixels the scene was built from (a picture file decoded once, reduced)
  sh.px_to_m = is.px_to_m;
  sh.text_blocks = is.text_blocks;
  publish(std::move(sh), std::move(is.scene), id, text_block_regions(is.text_blocks));
  text_news_.clear();
  if (is.text_pending && is.with_text) {
    text_.start(id, [read = std::move(is.with_text), side_px = screen_side_px_](const std::atomic<bool>* cancel) {
      ImageScene with_text = read(cancel);
      fit_picture(with_text, side_px);  // on the reader's worker, not the window thread
      return with_text;
    });
    text_since_s_ = -1.0;
    text_said_ = false;
  } else {
    text_.cancel();
  }
}

void KioskRuntime::poll_text(double now_s) {
  if (!text_news_.empty() && (text_news_id_ != shown_id_ || !audio_.speaking())) {
    if (text_news_id_ == shown_id_) say(text_news_);
    text_news_.clear();
  }
  if (!text_.pending()) return;
  if (text_.pending_id() != shown_id_) {  // another picture came meanwhile
    text_.cancel();
    return;
  }
  if (text_since_s_ < 0) text_since_s_ = now_s;
  if (std::optional<TextRead> read = text_.poll()) {
    text_arrived(*read);
    return;
  }
  if (!text_said_ && now_s - text_since_s_ > kTextWait_s && !audio_.speaking()) {
    text_said_ = true;
    say_brief(audio_.messages().text(audio::MessageId::text_reading));
  }
}

void KioskRuntime::text_arrived(TextRead& read) {
  ImageScene& is = read.scene;
  spdlog::info("text of scene {}: {}, {} words in {} blocks, read in {:.0f} ms", read.id, is.ocr.why, is.ocr.words,
               is.text_blocks.size(), read.wall_ms);
  const audio::MessageCatalog& m = audio_.messages();
  text_news_id_ = read.id;
  const bool built = is.scene != nullptr;
  if (built) {
    PictureNotes notes = std::move(shown_.notes);
    show_built(is, read.id);  // the fade: no force step as the letters' curves go and the blocks come
    shown_.notes = std::move(notes);
  }
  if (built && !is.text_blocks.empty()) {
    text_news_ =
        m.text(audio::MessageId::text_ready,
               {{"description", describe_page(static_cast<int>(is.text_blocks.size()), count_figures(is.polylines))}});
  } else if (is.ocr.why.rfind("failed", 0) == 0 || !built) {
    text_news_ = m.text(audio::MessageId::text_unavailable);
  } else if (text_said_) {
    text_news_ = m.text(audio::MessageId::text_none);
  }
}

std::string KioskRuntime::describe() {
  // Its text still being read: said first, so the visitor knows more is coming.
  const std::string reading =
      text_.pending() ? audio_.messages().text(audio::MessageId::text_reading) + " " : std::string();
  return reading + describe_shown();
}

PageText KioskRuntime::page_text() {
  PageText page;
  for (const TextBlockM& b : shown_.text_blocks)
    page.paragraphs.push_back(name_unclear_words(b.text, audio_.messages()));
  if (const TextBlockM* b = text_block_at(shown_.text_blocks, core_.display().proxy_m))
    page.at_hand = static_cast<int>(b - shown_.text_blocks.data());
  return page;
}

std::string KioskRuntime::describe_shown() {
  if (shown_page_ > 0 || !shown_.text_blocks.empty()) {
    // A page (or a picture of one): the block of text under the hand is read; elsewhere, what the page holds.
    if (const TextBlockM* b = text_block_at(shown_.text_blocks, core_.display().proxy_m)) {
      return audio_.messages().text(audio::MessageId::text_block,
                                    {{"text", name_unclear_words(b->text, audio_.messages())}});
    }
    const std::string page =
        describe_page(static_cast<int>(shown_.text_blocks.size()), count_figures(shown_.polylines));
    return shown_.polylines.empty() ? page
                                    : page + " " + describe_scene(shown_.polylines, half_, 3, core_.display().handle_m);
  }
  if (showing_tutorial() && !shown_.notes.title.empty()) {  // a practice shape: "A square, in the middle."
    std::string words = shown_.notes.title + ", " + place_words({0.0, 0.0}, half_) + ".";
    words[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(words[0])));
    return words;
  }
  // A picture: what a person wrote of it first ("A horse, seen from the side. A horse standing, ..."), then
  // its shapes.
  std::string words;
  if (!shown_.notes.title.empty()) {
    words = shown_.notes.title;
    words[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(words[0])));
    if (words.back() != '.' && words.back() != '!' && words.back() != '?') words += '.';
    words += ' ';
  }
  if (!shown_.notes.description.empty()) words += shown_.notes.description + ' ';
  return words + describe_scene(shown_.polylines, half_, 3, core_.display().handle_m);
}

void KioskRuntime::set_screen_picture_side_px(int px) {
  screen_side_px_ = std::clamp(px, 256, kScreenPictureMaxSidePx);
  shelf_.set_side_px(screen_side_px_);
  sticks_.set_screen_picture_side_px(screen_side_px_);
}

void KioskRuntime::show_document(int document, int page) {
  reset_level();       // a level the visitor chose holds for one page
  shelf_.drop_want();  // the stick's page, not a library picture still being built
  sticks_.load(stick_id_, document, page);
}

void KioskRuntime::forget_stick() {
  sticks_.forget();
  stick_id_ = 0;
  stick_busy_ = false;  // a page still being built for the forgotten stick is dropped when it comes
  rebuild_page_id_ = 0;
}

void KioskRuntime::poll_sticks(KioskFlow& flow, double now_s) {
  for (StickNews& n : sticks_.poll_news()) {
    stick_folder_ops_ = std::max(0, stick_folder_ops_ - 1);
    if (n.kind == StickNews::Kind::Inserted) {
      stick_id_ = n.stick;
      std::vector<StickEntry> entries;
      for (const ListedDocument& d : n.documents)
        entries.push_back(
            {d.doc.display_name, d.doc.kind == vision::DocumentKind::Pdf, d.pages, d.title, d.pages_in_file});
      stick_busy_ = !entries.empty();
      stick_problems_.clear();
      // Pictures and PDFs first: what the visitor was told of; then the rest left out.
      for (const bool documents : {true, false})
        for (const vision::RefusedEntry& r : n.refused)
          if (r.document == documents) note_stick_problem("'" + r.path + "': " + r.reason);
      flow.stick_inserted(entries, now_s, n.unreadable_documents);
    } else if (n.kind == StickNews::Kind::Refused) {
      stick_busy_ = false;
      flow.stick_refused(n.reason, now_s);
    } else {
      stick_id_ = 0;
      stick_busy_ = false;
      rebuild_page_id_ = 0;
      flow.stick_removed(now_s);
    }
  }
  for (LoadedDocument& d : sticks_.poll_loaded()) {
    if (d.stick != stick_id_) continue;  // a stick taken out or forgotten meanwhile
    const int id = 1000 + d.document * 100000 + d.page;
    if (rebuild_page_id_ == id && !flow.loading()) {
      // The page shown, rebuilt with new settings (apply_settings): swapped in without a new announcement.
      rebuild_page_id_ = 0;
      if (d.scene) show_built(*d.scene, id);
      stick_busy_ = false;
      continue;
    }
    if (!flow.awaits_document(d.document, d.page))
      continue;  // superseded by a later Next or Previous: never on the device
    DocumentResult r;
    r.document = d.document;
    r.page = d.page;
    if (d.scene) {
      ImageScene& is = *d.scene;
      r.ok = true;
      // A page, or a picture of one (its text read): blocks of text and figures; its text still being read:
      // said so at once; else shapes.
      r.description = is.text_pending && is.text_likely ? audio_.messages().text(audio::MessageId::text_reading)
                      : is.page > 0 || !is.text_blocks.empty()
                          ? describe_page(static_cast<int>(is.text_blocks.size()), count_figures(is.polylines))
                          : describe_shapes(static_cast<int>(is.scene->curve_count()));
      const bool said_reading = is.text_pending && is.text_likely;
      show_built(is, id);
      text_said_ = said_reading;
      shown_page_ = is.page;
      shown_document_ = d.document;
      shown_picture_ = -1;
    } else {
      r.reason = d.reason;
      const std::vector<StickEntry>& docs = flow.stick_documents();
      const std::string name = d.document >= 0 && d.document < static_cast<int>(docs.size())
                                   ? docs[static_cast<std::size_t>(d.document)].name
                                   : "?";
      note_stick_problem("'" + name + "' page " + std::to_string(d.page) + ": " + d.reason);
    }
    stick_busy_ = false;
    flow.document_ready(r, now_s);
  }
  if (flow.loading()) stick_busy_ = true;
}

void KioskRuntime::note_stick_problem(std::string line) {
  if (stick_problems_.size() < kStickProblems) stick_problems_.push_back(std::move(line));
}

void KioskRuntime::insert_stick_folder(const std::string& dir) {
  stick_busy_ = true;
  ++stick_folder_ops_;
  sticks_.insert_folder(dir);
}

void KioskRuntime::remove_stick_folder() {
  stick_busy_ = true;  // until the news of the removal arrives
  ++stick_folder_ops_;
  sticks_.remove_folder();
}

bool KioskRuntime::change_level(int delta) {
  // From the level in use (chosen by hand speed in auto mode): the visitor's choice then holds until
  // another picture or page is asked for (reset_level) or the session ends. With a tolerance or cut step in use
  // (level_mode = "tolerance" or "cut") the keys move along the steps, so finer and coarser keep their order (and their
  // earcons) without comparing a step with a level.
  const int now = level();
  const int next = now + delta;
  const bool in_range = is_tolerance_level(now) ? is_tolerance_level(next)
                        : is_cut_level(now)     ? is_cut_level(next)
                                                : (next >= 0 && next <= s_.haptics.max_levels);
  if (!in_range) return false;
  level_ = next;
  auto_level_ = false;
  core_.request_level(level_);
  return true;
}

void KioskRuntime::reset_level() {
  level_ = s_.haptics.level;
  auto_level_ = s_.haptics.level_mode != "fixed";
  core_.request_level(auto_level_ ? ServoStep::kAutoLevel : level_);
}

bool KioskRuntime::change_volume(int delta) { return delta > 0 ? audio_.volume_up() : audio_.volume_down(); }

void KioskRuntime::new_session() {
  far_near_said_ = false;
  if (ServoThread* servo = devices_.servo()) {  // the servo thread's timing, once per visitor's session
    const ServoTimingStats t = servo->take_stats();
    spdlog::info(
        "session: servo {} ticks, {} missed deadlines, lateness p50 {:.0f} p99 {:.0f} max {:.0f} us, tick work p99 "
        "{:.0f} us",
        t.ticks, t.missed_deadlines, t.lateness_p50_us, t.lateness_p99_us, t.lateness_max_us, t.compute_p99_us);
  }
  capture_.cancel();
  shelf_.drop_want();
  audio_.new_session();
  voice_.forget();
  reset_level();
  high_contrast_ = said_contrast_ = opt_.high_contrast;
  tour_.new_visitor(shown_id_, shown_.scene ? static_cast<int>(shown_.scene->curve_count()) : 0);
}

void KioskRuntime::set_cursor(Vec2 m) { tour_.set_cursor(m); }

void KioskRuntime::key_pressed() { tour_.key_pressed(); }

void KioskRuntime::guide() { tour_.guide(tour_picture()); }

void KioskRuntime::poll_tour() { tour_.poll(tour_picture()); }

TourPicture KioskRuntime::tour_picture() const {
  TourPicture p;
  p.scene = shown_.scene;
  p.id = shown_id_;
  p.described = shown_.polylines.size();
  p.words = [this](std::size_t curve) { return shape_words(curve); };
  return p;
}

int KioskRuntime::find_picture(const std::string& path) const { return shelf_.find(path); }

CueTrackerParams KioskRuntime::cue_params() const { return cue_params_from(s_); }

void KioskRuntime::publish(Shown sh, std::unique_ptr<Scene> scene, int id, std::vector<Aabb> text_boxes) {
  ++scenes_published_;
  const Scene& sc = *scene;
  sh.levels.resize(sc.curve_count());
  sh.closed.resize(sc.curve_count());
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    sh.closed[c] = sc.curve(c).closed;
    for (int l = 0; l < sc.curve(c).levels; ++l) {
      const Vec2* p = sc.points(c, l);
      sh.levels[c].emplace_back(p, p + sc.curve(c).point_count[l]);
    }
  }
  sh.cut_segments.clear();
  sh.cuts.clear();
  if (s_.haptics.level_mode == "cut") {
    sh.cut_segments.assign(sc.curve_count(), std::vector<std::vector<SegmentRef>>(kToleranceSteps));
    sh.cuts.assign(sc.curve_count(), std::vector<std::vector<Vec2>>(kToleranceSteps));
    for (std::size_t c = 0; c < sc.curve_count(); ++c) {
      for (int t = 0; t < kToleranceSteps; ++t) {
        std::vector<SegmentRef>& cut = sh.cut_segments[c][static_cast<std::size_t>(t)];
        tolerance_cut(sc, c, kToleranceLadder_m[t], &cut);
        sh.cuts[c][static_cast<std::size_t>(t)] = joined_cut_points(sc, c, cut.data(), cut.size());
      }
    }
  }
  ServoParams sp = sp_;
  sp.level = auto_level_ ? s_.haptics.level : level_;  // auto: where the policy starts
  sp.auto_level = auto_level_;
  auto bundle = std::make_unique<SceneBundle>(std::move(scene), sp);
  bundle->id = id;
  bundle->text_blocks_m = std::move(text_boxes);
  sh.scene = bundle->scene.get();
  shown_ = std::move(sh);
  shown_id_ = id;
  tour_.picture_changed(id, static_cast<int>(sc.curve_count()));
  core_.publish(std::move(bundle));
}

void KioskRuntime::rebuild_shown() {
  // New settings: what was built ahead, or is being built, with the old ones is not used.
  shelf_.set_settings(s_, true);
  if (shown_id_ <= -1 && shown_id_ >= -3) {
    const int shape = -1 - shown_id_;
    show_tutorial(static_cast<TutorialShape>(shape));
  } else if (shown_picture_ >= 0) {
    shelf_.want_rebuild_picture(shown_picture_);
  } else if (shown_id_ <= kFirstCaptureId && !shown_.picture.empty()) {
    shelf_.want_rebuild(shown_id_, [picture = shown_.picture.clone(), s = s_] {
      return build_image_scene_from_picture(picture, "camera capture", s, TextTiming::later);
    });
  } else if (shown_document_ >= 0 && stick_id_ != 0) {
    rebuild_page_id_ = 1000 + shown_document_ * 100000 + shown_page_;
    stick_busy_ = true;
    sticks_.load(stick_id_, shown_document_, shown_page_);
  }
}

ApplyReport KioskRuntime::apply_settings(const config::Settings& next, KioskFlow& flow) {
  ApplyReport r;
  const config::Settings before = s_;
  bool rebuild = false;
  for (const config::FieldDescriptor& d : config::field_descriptors()) {
    const bool same = std::visit(
        [&](const auto* a) {
          using P = decltype(a);
          return *a == *std::get<P>(d.cref(next));
        },
        d.cref(before));
    if (same) continue;
    const std::string key = std::string(d.table) + "." + std::string(d.key);
    switch (d.apply) {
      case config::ApplyWhen::live:
        if (d.table == "haptics") r.gains = true;
        if (d.table == "keys") r.keys = true;
        if (d.table == "kiosk") r.timing = true;
        break;
      case config::ApplyWhen::scene:
        rebuild = true;
        break;
      case config::ApplyWhen::session:
        r.next_session.push_back(key);
        break;
      case config::ApplyWhen::restart:
        r.restart.push_back(key);
        break;
    }
  }
  // What the next start needs stays as it was in the running kiosk (its threads, device and view were made
  // with it); everything else is taken.
  config::Settings in_use = next;
  for (const config::FieldDescriptor& d : config::field_descriptors()) {
    if (d.apply != config::ApplyWhen::restart) continue;
    std::visit(
        [&](auto* dst) {
          using P = decltype(dst);
          *dst = *std::get<std::add_pointer_t<std::add_const_t<std::remove_pointer_t<P>>>>(d.cref(before));
        },
        d.ref(in_use));
  }
  // A board's profile bounds what the panel may ask of it (device_profile.hpp): refused values take the profile's.
  if (devices_.usb()) {
    in_use = settings_for_board(in_use, &r.refused);
    for (const std::string& n : r.refused) spdlog::warn("settings: {}", n);
  }
  s_ = in_use;
  shelf_.set_settings(s_, false);
  capture_.set_settings(s_);
  sticks_.set_settings(s_);  // pages built ahead with the old settings are dropped
  sp_ = servo_params_from(s_);
  if (r.gains) core_.set_gains(servo_gains_from(s_));
  if (r.keys) flow.set_keys(s_.keys);
  if (r.timing) flow.set_timing(s_.kiosk.timeout_s, s_.kiosk.warning_s, s_.kiosk.attract_every_s);
  if (rebuild) {
    level_ = s_.haptics.level;
    auto_level_ = s_.haptics.level_mode != "fixed";
    rebuild_shown();
    r.scene_rebuilt = true;
  }
  return r;
}

}  // namespace hk::app
