#include "kiosk_runtime.hpp"

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

#include "app_error.hpp"
#include "audio_settings.hpp"
#include "config/load.hpp"
#include "describe.hpp"
#include "device_setup.hpp"
#include "haptics/io/tty_transport.hpp"
#include "haptics/tolerance_cut.hpp"
#include "picture_library.hpp"
#include "settings_params.hpp"
#include "simulation.hpp"
#include "vision/intake.hpp"

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

}  // namespace

KioskRuntime::KioskRuntime(const RuntimeOptions& o, const config::Settings& given)
    : KioskRuntime(o, with_usable_ocr(given), 0) {}

KioskRuntime::KioskRuntime(const RuntimeOptions& o, const config::Settings& s, int /*checked*/)
    : opt_(o), s_(s), audio_(audio_params(s, o.open_audio_output)), half_{s.workspace.width_m / 2, s.workspace.height_m / 2},
      sp_(servo_params_from(s)), sim_(sim_params_from(s), {0.0, -0.9 * s.workspace.height_m / 2}),
      core_(cue_params(), &audio_.cues()),
      capture_(s, o.probe_camera || s.camera.source != "auto" ? choose_camera(s.camera) : CameraChoice{{}, {}, "not looked for (a scripted run)"}),
      sticks_(s, block_events(o.hotplug), o.mount_root.empty() ? std::string(vision::kDefaultStickMountRoot) : o.mount_root) {
  pictures_ = list_pictures(o.library);
  if (!o.scene_cache_dir.empty()) {
    cache_ = std::make_shared<SceneCache>(o.scene_cache_dir);
    spdlog::info("scenes: kept in {}", o.scene_cache_dir);
  }
  sim_.open();
  hand_ = hand_params_from(s);
  // The cursor's hand may press harder than a model visitor: a cursor held well past a wall (about 2 cm at
  // the hand's 200 N/m) pushes through it, as a visitor at the real handle would.
  hand_.max_force_n = std::max(hand_.max_force_n, 1.5 * s.haptics.pop_force_n);
  if (!o.device.empty()) {
    open_emulated_board(o.device);
    adopt_board_profile();
  } else if (s.device.type != "simulated" && o.probe_usb_device) {
    if (try_open_usb()) {
      adopt_board_profile();
      check_home(true);
    }
    try {
      // Any product of the first id's vendor (Arduino's, for every Haply board): an arrival only starts a probe,
      // and the probe takes the ids of [device] usb_ids alone.
      const std::vector<config::UsbId> ids = config::parse_usb_ids(s.device.usb_ids);
      if (!ids.empty())
        usb_watch_ = std::make_unique<io::UsbHotplugMonitor>(ids.front().vid, -1, [this](bool arrived) { if (arrived) usb_arrived_.store(true); });
    } catch (const std::exception& e) {
      spdlog::warn("device: no USB hot-plug ({}); the kiosk probes for the handle every 10 s", e.what());
    }
  }
  cursor_.back() = sim_.true_position_m();
  cursor_.publish();
  cursor_in_ = sim_.true_position_m();
  level_ = s.haptics.level;
  auto_level_ = s.haptics.level_mode != "fixed";
  high_contrast_ = said_contrast_ = o.high_contrast;
  overlay_ = said_overlay_ = o.overlay;
}

KioskRuntime::~KioskRuntime() {
  stop_servo();
  usb_watch_.reset();
  if (usb_) usb_->close();  // zero torque, then the transport closes
  if (board_pty_) board_pty_->stop();
}

void KioskRuntime::start_servo() {
  ServoThreadParams tp;
  tp.rate_hz = s_.haptics.servo_rate_hz;
  if (usb_) {
    servo_ = std::make_unique<ServoThread>(core_, *usb_, tp);
    return;
  }
  servo_ = std::make_unique<ServoThread>(core_, sim_, tp, [this](double dt) {
    // The simulated pantograph: the model hand pulls the handle towards the cursor (limp during a tour:
    // it follows the handle, giving only its damping).
    const Vec2 target = hand_limp_.load(std::memory_order_relaxed) ? sim_.true_position_m() : cursor_.read();
    sim_.step(dt, model_hand_force(hand_, target, sim_.true_position_m(), sim_.velocity_m_per_s()));
  });
}

bool KioskRuntime::try_open_usb() {
  try {
    std::unique_ptr<io::HaplyDevice> dev = open_board(s_, nullptr);
    spdlog::info("device: {} ({} profile: {:.2f} N everywhere)", dev->name(), config::device_profile(board_profile_type(s_)).name,
                 io::min_force_capability_n(dev->params()));
    usb_ = std::move(dev);
    device_note_.clear();
    return true;
  } catch (const std::exception& e) {
    // Said once per reason: a kiosk without its handle probes every 10 s for months, and the journal
    // should not fill with the same line (the boot of the package showed 360 an hour).
    const bool news = device_note_ != e.what();
    device_note_ = e.what();
    spdlog::log(news ? spdlog::level::warn : spdlog::level::debug, "device: no USB pantograph ({}); the simulated pantograph stands in",
                e.what());
    return false;
  }
}

void KioskRuntime::adopt_board_profile() {
  std::vector<std::string> notes;
  s_ = settings_for_board(s_, &notes);
  for (const std::string& n : notes) spdlog::warn("device: {}", n);
  sp_ = servo_params_from(s_);
  hand_ = hand_params_from(s_);
  hand_.max_force_n = std::max(hand_.max_force_n, 1.5 * s_.haptics.pop_force_n);
  core_.set_gains(servo_gains_from(s_));
  capture_.set_settings(s_);
}

std::string KioskRuntime::profile_type() const { return usb_ ? board_profile_type(s_) : s_.device.type; }

bool KioskRuntime::calibrate_usb(double* offset1_deg, double* offset2_deg, std::string* why) {
  if (!usb_) {
    *why = "no USB pantograph is in use" + (device_note_.empty() ? std::string{} : " (" + device_note_ + ")");
    return false;
  }
  if (usb_->status() != DeviceStatus::Ok) {
    *why = "the handle does not answer";
    return false;
  }
  if (!usb_->calibrate({s_.device.park_x_m, s_.device.park_y_m}, offset1_deg, offset2_deg)) {
    *why = "the park place is out of the links' reach";
    return false;
  }
  home_note_.clear();  // the handle rests at home, and now reads there
  return true;
}

void KioskRuntime::open_emulated_board(const std::string& text) {
  const DeviceChoice choice = parse_device_choice(text);
  if (choice.kind != DeviceChoice::Kind::HaplyEmulator)
    throw DeviceChoiceError("--device '" + text + "': the kiosk takes 'haply-emulator[:FAULT=VALUE,...]' (or nothing: [device])");
  const io::HaplyDeviceParams dp = haply_params_from(s_);
  const double scale = io::workspace_scale(dp);
  const Vec2 centre = dp.rect_center_device_m;
  // The board's handle follows the cursor through the model hand (workspace frame ↔ device frame).
  Vec2 start_device = (1.0 / scale) * cursor_.read() + centre;
  const hapi::EmulatorParams ep = choice.rest_at_park ? emulator_resting_at_park(s_, choice, &start_device) : emulator_params_from(s_, choice);
  board_ = std::make_unique<hapi::FirmwareEmulator>(
      ep, start_device,
      [this, scale, centre](double, Vec2 handle_device_m, Vec2 velocity_device_m_per_s) {
        const Vec2 handle = scale * (handle_device_m - centre);
        const Vec2 target = hand_limp_.load(std::memory_order_relaxed) ? handle : cursor_.read();
        return model_hand_force(hand_, target, handle, scale * velocity_device_m_per_s);
      });
  board_pty_ = std::make_unique<hapi::PtyEmulator>(*board_);
  const std::string path = board_pty_->device_path();
  usb_ = std::make_unique<io::HaplyDevice>(dp, [path] { return std::make_unique<io::TtyTransport>(path); });
  usb_->open();
  spdlog::info("device: {} on the firmware emulator", usb_->name());
  if (choice.rest_at_park) check_home(true);  // a board at rest, as a real one waits for the kiosk to start
}

void KioskRuntime::check_home(bool at_start) {
  const HomeCheck c = check_home_pose(*usb_, s_);
  home_note_ = c.at_home ? std::string{} : home_check_line(c);
  home_unspoken_ = at_start && !c.at_home;
  if (!c.at_home) spdlog::warn("device: {}", home_note_);
}

void KioskRuntime::announce_device() {
  if (s_.device.type == "simulated" && opt_.device.empty()) return;  // chosen: nothing to tell
  if (!opt_.probe_usb_device && opt_.device.empty()) return;
  std::string text = audio_.messages().text(usb_ ? audio::MessageId::device_ready : audio::MessageId::device_simulated);
  // A handle that did not start at home is the staff's to fix: said at start only, before any visitor.
  if (usb_ && home_unspoken_) text += " " + audio_.messages().text(audio::MessageId::device_not_home);
  home_unspoken_ = false;
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
  if (started) drop_want();  // the visitor's own picture comes next, not a library picture still being built
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
  // A loss is spoken once it has lasted kLostSpeech_s (a board that misses a few replies and comes back
  // within it is not worth interrupting the visitor for: the force was off for those ticks and ramped
  // back in), and the return only after a loss that was spoken.
  constexpr double kLostSpeech_s = 0.5;
  const DeviceStatus st = core_.display().device_status;
  if (usb_) {
    if (st != DeviceStatus::Ok && last_status_ == DeviceStatus::Ok) lost_since_s_ = now_s;
    if (st != DeviceStatus::Ok && !lost_spoken_ && now_s - lost_since_s_ >= kLostSpeech_s) {
      spdlog::warn("device: {} lost", usb_->name());
      say(audio_.messages().text(audio::MessageId::device_lost));
      lost_spoken_ = true;
    }
    if (st == DeviceStatus::Ok && lost_spoken_) {
      spdlog::info("device: {} back", usb_->name());
      say(audio_.messages().text(audio::MessageId::device_back));
      lost_spoken_ = false;
    }
  }
  last_status_ = st;
  // The simulated pantograph stands in: take a USB pantograph that arrives.
  if (usb_ || s_.device.type == "simulated" || !opt_.probe_usb_device) return;
  const bool arrived = usb_arrived_.exchange(false);
  if (!arrived && now_s < next_probe_s_) return;
  next_probe_s_ = now_s + 10.0;
  const bool running = servo_ != nullptr;
  if (!try_open_usb()) return;
  adopt_board_profile();
  check_home(false);  // a visitor may be there: the log and the panel only
  rebuild_shown();  // the groove depth is built into the scene
  if (running) {
    servo_->stop();
    servo_.reset();
    start_servo();
  }
  last_status_ = DeviceStatus::Ok;
  announce_device();
}

void KioskRuntime::stop_servo() {
  if (servo_) servo_->stop();
}

namespace {

/// `text` with its line breaks (a reading's sentences are joined by them) as spaces: one line of the log.
std::string one_line(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text;
}

}  // namespace

void KioskRuntime::say(const std::string& text) {
  spdlog::info("say: {}", one_line(text));
  last_said_ = text;
  repeatable_ = text;
  ++kept_texts_;
  ++texts_said_;
  brief_last_ = false;
  audio_.say_text(text);
}

void KioskRuntime::say_brief(const std::string& text) {
  spdlog::info("say: {}", one_line(text));
  last_said_ = text;
  ++texts_said_;
  brief_last_ = true;
  audio_.say_text(text, false);
}

bool KioskRuntime::repeat() {
  if (repeatable_.empty()) return false;
  say(std::string(repeatable_));
  return true;
}

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
    return m.text(audio::MessageId::where_text, {{"block", std::to_string(index + 1)}, {"blocks", std::to_string(shown_.text_blocks.size())},
                                                  {"where", place}, {"text", first_words(name_unclear_words(b->text, m), kWhereTextWords)}});
  }
  const ShapeAtHand at = shape_at_hand(shown_.polylines, d.handle_m, d.scene_id == shown_id_ ? d.curve : -1);
  // A practice shape: far and near explained with the first answer of the visit, not again.
  const bool explain = showing_tutorial() && !far_near_said_;
  far_near_said_ = far_near_said_ || explain;
  const std::string far_near = explain ? " " + m.text(audio::MessageId::far_near) : std::string();
  if (at.curve < 0) return m.text(audio::MessageId::where_none, {{"where", place}}) + far_near;
  return m.text(at.on ? audio::MessageId::where_on : audio::MessageId::where_near,
                {{"shape", std::to_string(at.curve + 1)}, {"shapes", std::to_string(shown_.polylines.size())},
                 {"description", shape_words(static_cast<std::size_t>(at.curve))}, {"where", place}}) + far_near;
}

bool KioskRuntime::showing_tutorial() const { return shown_id_ <= -1 && shown_id_ >= -3; }

std::string KioskRuntime::shape_words(std::size_t curve) const {
  if (showing_tutorial() && !shown_.notes.title.empty()) return shown_.notes.title;  // "a square"
  return describe_one_shape(shown_.polylines, curve, half_, false);
}

void KioskRuntime::poll_display_modes() {
  if (high_contrast_ != said_contrast_) {
    said_contrast_ = high_contrast_;
    say_brief(audio_.messages().text(high_contrast_ ? audio::MessageId::high_contrast_on : audio::MessageId::high_contrast_off));
  }
  if (overlay_ != said_overlay_) {
    said_overlay_ = overlay_;
    say_brief(audio_.messages().text(overlay_ ? audio::MessageId::overlay_on : audio::MessageId::overlay_off));
  }
}

void KioskRuntime::drop_want() {
  wanted_id_ = kNoWant;
  wanted_done_.reset();
}

void KioskRuntime::show_tutorial(TutorialShape shape) {
  drop_want();  // a picture still being built is not wanted any more
  Shown sh;
  sh.polylines = {tutorial_polyline(shape, half_)};
  static constexpr audio::MessageId kNames[] = {audio::MessageId::shape_square, audio::MessageId::shape_circle, audio::MessageId::shape_triangle};
  sh.notes.title = audio_.messages().text(kNames[static_cast<int>(shape)]);  // Where, Describe and the tour name it
  publish(std::move(sh), std::make_unique<Scene>(Scene::build({tutorial_polyline(shape, half_)}, s_.haptics.max_levels)),
          -1 - static_cast<int>(shape));
  text_.cancel();
  text_news_.clear();
  shown_picture_ = -1;
  shown_document_ = -1;
  shown_page_ = 0;
}

namespace {

/// Library picture `path`'s scene, with what the file itself says of it (file_notes): from the scene cache
/// when it holds one for this file and these settings (found by the file's stamp without reading it, else
/// by its bytes' key), else built from the bytes read once and stored; a scene whose text is still to be
/// read is stored once it has been read (its with_text stores what it builds). Runs on the builder's worker.
ImageScene cached_or_built(const std::string& path, const config::Settings& s, const std::shared_ptr<SceneCache>& cache, int side_px) {
  // What the file says of itself is read beside the build: exiv2 reads a PNG's chunks through its image
  // data (tens of milliseconds for a 20 MB photo PNG), which need not delay the scene.
  const auto notes_beside = [&path] { return std::async(std::launch::async, [path] { return embedded_notes(path); }); };
  if (!cache) {
    std::future<PictureNotes> notes = notes_beside();
    ImageScene is = build_image_scene(path, s, TextTiming::later);
    fit_picture(is, side_px);
    is.file_notes = notes.get();
    return is;
  }
  const std::optional<FileStamp> stamp = SceneCache::stamp(path);  // before the bytes are read
  if (stamp) {
    if (const std::optional<std::string> known = cache->known_key(*stamp, s)) {
      if (std::optional<ImageScene> hit = cache->load(*known, s)) {
        hit->image_path = path;
        fit_picture(*hit, side_px);  // kept at the size of the screen that stored it
        return std::move(*hit);
      }
    }
  }
  const std::vector<std::uint8_t> bytes = vision::read_input_file(path, extract_params_from(s).limits.max_file_bytes);
  const std::string key = SceneCache::key(bytes, s);
  if (std::optional<ImageScene> hit = cache->load(key, s)) {
    if (stamp) cache->remember_key(*stamp, s, key);
    hit->image_path = path;
    fit_picture(*hit, side_px);
    return std::move(*hit);
  }
  std::future<PictureNotes> notes = notes_beside();
  ImageScene is = build_image_scene_from_bytes(bytes, path, s, TextTiming::later);
  fit_picture(is, side_px);
  is.file_notes = notes.get();
  auto keep = [cache, key, stamp, s](const ImageScene& built) {
    if (cache->store(key, built) && stamp) cache->remember_key(*stamp, s, key);
  };
  if (!is.text_pending) {
    keep(is);
    return is;
  }
  is.with_text = [read = std::move(is.with_text), keep, file_notes = is.file_notes, side_px](const std::atomic<bool>* cancel) {
    ImageScene with_text = read(cancel);
    fit_picture(with_text, side_px);
    with_text.file_notes = file_notes;
    const bool whole = with_text.scene && with_text.ocr.why != "cancelled" && with_text.ocr.why.rfind("failed", 0) != 0;
    if (whole) keep(with_text);
    return with_text;
  };
  return is;
}

/// A library picture's notes: its sidecar's, else `file_notes` (what the file says, read with its scene);
/// a sidecar that cannot be used is logged and the picture shown without notes.
PictureNotes notes_of(const std::string& path, const PictureNotes& file_notes) {
  try {
    return read_picture_notes(path, &file_notes);
  } catch (const PictureNotesError& e) {
    spdlog::warn("{}; the picture is shown without it", e.what());
    return {};
  }
}

}  // namespace

SceneJob KioskRuntime::picture_job(int index) const {
  // A copy of what the build needs: the worker never touches the runtime.
  return [path = pictures_[static_cast<std::size_t>(index)], s = s_, cache = cache_, side_px = screen_side_px_] {
    ImageScene is = cached_or_built(path, s, cache, side_px);
    is.notes = notes_of(path, is.file_notes);
    return is;
  };
}

int KioskRuntime::show_picture(int index) {
  reset_level();  // a level the visitor chose holds for one picture
  absorb_built();
  for (auto it = ahead_.begin(); it != ahead_.end(); ++it) {
    if (it->index != index) continue;
    std::unique_ptr<ImageScene> is = std::move(it->scene);
    ahead_.erase(it);
    wanted_id_ = kNoWant;  // the visitor moved on: an older ask is not wanted any more
    wanted_done_.reset();
    spdlog::info("picture {}: built ahead, on the device at once", index + 1);
    return put_picture(index, *is);
  }
  wanted_id_ = index;
  wanted_kind_ = WantKind::Picture;
  wanted_done_.reset();
  builder_.want(index, generation_, picture_job(index));
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
  build_ahead();
  return shapes;
}

void KioskRuntime::absorb_built() {
  for (BuiltScene& b : builder_.poll()) {
    if (b.generation != generation_) continue;  // built with settings no longer in use
    if (b.id == wanted_id_) {
      wanted_done_ = std::move(b);
      continue;
    }
    if (b.id < 0 || b.id >= picture_count()) continue;  // a rebuild nobody waits for
    if (!b.scene) {  // not asked again until the settings change (the visitor asking for it hears why)
      ahead_refused_.push_back(b.id);
      continue;
    }
    Ahead a;
    a.index = b.id;
    a.bytes = approx_scene_bytes(*b.scene);
    a.scene = std::make_unique<ImageScene>(std::move(*b.scene));
    ahead_.push_back(std::move(a));
  }
}

void KioskRuntime::poll_pictures(KioskFlow* flow, double now_s) {
  absorb_built();
  if (wanted_done_) {
    BuiltScene b = std::move(*wanted_done_);
    wanted_done_.reset();
    const WantKind kind = wanted_kind_;
    wanted_id_ = kNoWant;
    spdlog::info("scene {}: built in {:.0f} ms (waited {:.0f} ms to start)", b.id, b.build_ms, b.queued_ms);
    if (!b.scene) {
      spdlog::warn("scene {}: {}; the picture felt before stays", b.id, b.error);
      if (kind == WantKind::Picture && flow) flow->picture_failed(b.id, problem_of(b.error), now_s);  // "Picture N of M" names it
    } else if (kind == WantKind::Rebuild) {
      PictureNotes notes = std::move(shown_.notes);
      show_built(*b.scene, b.id);  // the same picture with the new settings: no new announcement
      shown_.notes = std::move(notes);
      if (b.id >= 0 && b.id < picture_count()) build_ahead();
    } else {
      const int shapes = put_picture(b.id, *b.scene);
      if (flow) flow->picture_ready(b.id, shapes, now_s);
    }
  }
  build_ahead();
}

bool KioskRuntime::finish_picture(KioskFlow* flow, double now_s, double timeout_s) {
  if (wanted_id_ == kNoWant) return true;
  const bool came = builder_.wait_want(timeout_s);
  poll_pictures(flow, now_s);
  return came;
}

std::vector<int> KioskRuntime::pictures_ahead() const {
  std::vector<int> out;
  for (const Ahead& a : ahead_) out.push_back(a.index);
  return out;
}

void KioskRuntime::build_ahead() {
  const int n = picture_count();
  const int at = wanted_id_ >= 0 && wanted_id_ < n ? wanted_id_ : shown_picture_;
  // No library picture under the hand (the tutorial, a stick, a capture): the first picture is the one a
  // visitor reaches next (after the tutorial), so it is built ahead, from the scene cache after a restart.
  const int next = at < 0 ? 0 : (at + 1) % n, previous = at < 0 ? 0 : (at + n - 1) % n;
  // Kept: the neighbours of where the visitor is (and is going), within the budget, the next one first.
  const std::size_t budget = static_cast<std::size_t>(s_.kiosk.prefetch_mb) << 20;
  std::vector<Ahead> kept;
  std::size_t used = 0;
  for (const int want : {next, previous}) {
    for (Ahead& a : ahead_) {
      if (a.index != want || !a.scene) continue;
      if (used + a.bytes > budget) {
        spdlog::info("picture {}: its scene ({} MiB) is over [kiosk] prefetch_mb; built when asked for", a.index + 1, a.bytes >> 20);
        ahead_refused_.push_back(a.index);
        continue;
      }
      used += a.bytes;
      kept.push_back(std::move(a));
    }
  }
  ahead_ = std::move(kept);
  if (budget == 0 || n < 2) return;
  for (const int want : {next, previous}) {
    if (want == shown_picture_) continue;
    const bool have = std::any_of(ahead_.begin(), ahead_.end(), [&](const Ahead& a) { return a.index == want; });
    const bool refused = std::find(ahead_refused_.begin(), ahead_refused_.end(), want) != ahead_refused_.end();
    if (!have && !refused && !builder_.has(want, generation_)) builder_.ahead(want, generation_, picture_job(want));
  }
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
  spdlog::info("text of scene {}: {}, {} words in {} blocks, read in {:.0f} ms", read.id, is.ocr.why, is.ocr.words, is.text_blocks.size(), read.wall_ms);
  const audio::MessageCatalog& m = audio_.messages();
  text_news_id_ = read.id;
  const bool built = is.scene != nullptr;
  if (built) {
    PictureNotes notes = std::move(shown_.notes);
    show_built(is, read.id);  // the fade: no force step as the letters' curves go and the blocks come
    shown_.notes = std::move(notes);
  }
  if (built && !is.text_blocks.empty()) {
    text_news_ = m.text(audio::MessageId::text_ready, {{"description", describe_page(static_cast<int>(is.text_blocks.size()), count_figures(is.polylines))}});
  } else if (is.ocr.why.rfind("failed", 0) == 0 || !built) {
    text_news_ = m.text(audio::MessageId::text_unavailable);
  } else if (text_said_) {
    text_news_ = m.text(audio::MessageId::text_none);
  }
}

std::string KioskRuntime::describe() {
  // Its text still being read: said first, so the visitor knows more is coming.
  const std::string reading = text_.pending() ? audio_.messages().text(audio::MessageId::text_reading) + " " : std::string();
  return reading + describe_shown();
}

PageText KioskRuntime::page_text() {
  PageText page;
  for (const TextBlockM& b : shown_.text_blocks) page.paragraphs.push_back(name_unclear_words(b.text, audio_.messages()));
  if (const TextBlockM* b = text_block_at(shown_.text_blocks, core_.display().proxy_m)) page.at_hand = static_cast<int>(b - shown_.text_blocks.data());
  return page;
}

std::string KioskRuntime::describe_shown() {
  if (shown_page_ > 0 || !shown_.text_blocks.empty()) {
    // A page (or a picture of one): the block of text under the hand is read; elsewhere, what the page holds.
    if (const TextBlockM* b = text_block_at(shown_.text_blocks, core_.display().proxy_m)) {
      return audio_.messages().text(audio::MessageId::text_block, {{"text", name_unclear_words(b->text, audio_.messages())}});
    }
    const std::string page = describe_page(static_cast<int>(shown_.text_blocks.size()), count_figures(shown_.polylines));
    return shown_.polylines.empty() ? page : page + " " + describe_scene(shown_.polylines, half_, 3, core_.display().handle_m);
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
  sticks_.set_screen_picture_side_px(screen_side_px_);
}

void KioskRuntime::show_document(int document, int page) {
  reset_level();  // a level the visitor chose holds for one page
  drop_want();  // the stick's page, not a library picture still being built
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
        entries.push_back({d.doc.display_name, d.doc.kind == vision::DocumentKind::Pdf, d.pages, d.title, d.pages_in_file});
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
    if (!flow.awaits_document(d.document, d.page)) continue;  // superseded by a later Next or Previous: never on the device
    DocumentResult r;
    r.document = d.document;
    r.page = d.page;
    if (d.scene) {
      ImageScene& is = *d.scene;
      r.ok = true;
      // A page, or a picture of one (its text read): blocks of text and figures; its text still being read:
      // said so at once; else shapes.
      r.description = is.text_pending && is.text_likely ? audio_.messages().text(audio::MessageId::text_reading)
                      : is.page > 0 || !is.text_blocks.empty() ? describe_page(static_cast<int>(is.text_blocks.size()), count_figures(is.polylines))
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
      const std::string name = d.document >= 0 && d.document < static_cast<int>(docs.size()) ? docs[static_cast<std::size_t>(d.document)].name : "?";
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
  // another picture or page is asked for (reset_level) or the session ends. With a tolerance or cut step in use (level_mode = "tolerance" or "cut") the keys move along
  // the steps, so finer and coarser keep their order (and their earcons) without comparing a step with a level.
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
  core_.request_level(auto_level_ ? ServoCore::kAutoLevel : level_);
}

bool KioskRuntime::change_volume(int delta) { return delta > 0 ? audio_.volume_up() : audio_.volume_down(); }

void KioskRuntime::new_session() {
  far_near_said_ = false;
  if (servo_) {  // the servo thread's timing, once per visitor's session
    const ServoTimingStats t = servo_->take_stats();
    spdlog::info("session: servo {} ticks, {} missed deadlines, lateness p50 {:.0f} p99 {:.0f} max {:.0f} us, tick work p99 {:.0f} us",
                 t.ticks, t.missed_deadlines, t.lateness_p50_us, t.lateness_p99_us, t.lateness_max_us, t.compute_p99_us);
  }
  capture_.cancel();
  drop_want();
  audio_.new_session();
  repeatable_.clear();
  tour_asked_ = false;
  reset_level();
  high_contrast_ = said_contrast_ = opt_.high_contrast;
  if (tour_running_) {
    core_.cancel_tour();
    tour_quiet_ = true;
  }
  touches_.reset(shown_id_, shown_.scene ? static_cast<int>(shown_.scene->curve_count()) : 0);
  cursor_offset_ = {};
}

void KioskRuntime::set_cursor(Vec2 m) {
  cursor_in_ = m;
  if (tour_running_ && !tour_quiet_ && length(m - tour_cursor_ref_) > 0.003) {
    core_.cancel_tour();  // the visitor's hand takes over
    tour_quiet_ = true;
    spdlog::info("tour: stopped by the hand");
  }
  const Vec2 c = m + cursor_offset_;
  const bool offset = cursor_offset_.x != 0.0 || cursor_offset_.y != 0.0;
  cursor_.back() = offset ? Vec2{std::clamp(c.x, -half_.x, half_.x), std::clamp(c.y, -half_.y, half_.y)} : m;
  cursor_.publish();
}

void KioskRuntime::key_pressed() {
  guide_stops_ = tour_running_ != 0 || tour_asked_;
  tour_asked_ = false;  // an announced tour does not start
  if (tour_running_) {
    core_.cancel_tour();
    tour_quiet_ = true;
  }
}

void KioskRuntime::guide() {
  if (guide_stops_) {
    guide_stops_ = false;
    say(audio_.messages().text(audio::MessageId::tour_stopped));
    return;
  }
  if (!shown_.scene) return;
  const TourParams tp = tour_params_from(s_);
  if (!plan_tour(*shown_.scene, shown_id_, core_.display().handle_m, touches_, tp)) {
    bool any_shape = false;
    for (std::size_t c = 0; c < shown_.scene->curve_count(); ++c) any_shape = any_shape || is_tour_shape(*shown_.scene, c, tp);
    say(audio_.messages().text(any_shape ? audio::MessageId::tour_all_touched : audio::MessageId::tour_nothing));
    return;
  }
  // Ask first: the pull starts once the visitor has heard what is coming (counted in servo ticks, so the
  // same in a headless run as at the kiosk).
  const std::string ask = audio_.messages().text(audio::MessageId::tour_ask);
  say_brief(ask);
  tour_asked_ = true;
  tour_scene_ = shown_id_;
  tour_due_tick_ = core_.display().tick +
                   static_cast<std::int64_t>(std::ceil((audio_.speech_duration_s(ask) + kTourAskMargin_s) * s_.haptics.servo_rate_hz));
}

void KioskRuntime::hand_over_tour() {
  tour_asked_ = false;
  if (!shown_.scene || tour_scene_ != shown_id_) return;  // another picture came meanwhile
  const TourParams tp = tour_params_from(s_);
  std::optional<TourPath> plan = plan_tour(*shown_.scene, shown_id_, core_.display().handle_m, touches_, tp);
  if (!plan) return;  // touched meanwhile: nothing left to lead to
  plan->id = ++tour_seq_;
  tour_running_ = plan->id;
  tour_quiet_ = false;
  tour_cursor_ref_ = cursor_in_;
  spdlog::info("tour {}: to shape {} ({:.1f} s)", plan->id, plan->curve, plan->duration_s());
  hand_limp_.store(true, std::memory_order_relaxed);
  core_.publish_tour(std::make_unique<TourPath>(std::move(*plan)));
}

void KioskRuntime::poll_tour() {
  const ServoDisplayState& d = core_.display();
  if (d.scene_id == touches_.scene_id() && d.curve >= 0) touches_.touch(d.scene_id, d.curve);
  if (tour_asked_ && d.tick >= tour_due_tick_) hand_over_tour();
  if (!tour_running_ || d.tour_id != tour_running_ || !tour_ended(d.tour_phase)) return;
  if (d.tour_phase == TourPhase::Done) touches_.touch(tour_scene_, d.tour_curve);
  tour_running_ = 0;
  // The hand lets go where the tour left the handle (unless the visitor's own hand took over).
  if (hand_limp_.load(std::memory_order_relaxed)) {
    if (!tour_quiet_ || length(cursor_in_ - tour_cursor_ref_) <= 0.003) cursor_offset_ = d.handle_m - cursor_in_;
    set_cursor(cursor_in_);
    hand_limp_.store(false, std::memory_order_relaxed);
  }
  if (tour_quiet_ || !shown_.scene || tour_scene_ != shown_id_) return;
  report_tour_end(d);
}

void KioskRuntime::report_tour_end(const ServoDisplayState& d) {
  const audio::MessageCatalog& m = audio_.messages();
  std::string text;
  if (d.tour_phase == TourPhase::Stopped) {
    text = m.text(audio::MessageId::tour_stopped) + " ";
  } else if (d.tour_phase == TourPhase::Stuck) {
    spdlog::warn("tour {}: stuck on shape {} (no progress), let go", d.tour_id, d.tour_curve);
    text = m.text(audio::MessageId::tour_stuck) + " ";
  } else if (d.tour_curve >= 0 && static_cast<std::size_t>(d.tour_curve) < shown_.polylines.size()) {
    text = m.text(audio::MessageId::tour_traced, {{"shape", std::to_string(d.tour_curve + 1)},
                                                   {"description", shape_words(static_cast<std::size_t>(d.tour_curve))}}) + " ";
  }
  const int left = shapes_remaining(*shown_.scene, touches_, tour_params_from(s_));
  if (left == 0) text += m.text(audio::MessageId::tour_all_touched);
  else if (left == 1) text += m.text(audio::MessageId::tour_one_remaining);
  else text += m.text(audio::MessageId::tour_remaining, {{"count", std::to_string(left)}});
  say(text);
}

int KioskRuntime::find_picture(const std::string& path) const {
  for (std::size_t i = 0; i < pictures_.size(); ++i) {
    std::error_code ec;
    if (std::filesystem::equivalent(pictures_[i], path, ec)) return static_cast<int>(i);
  }
  return -1;
}

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
  touches_.reset(id, static_cast<int>(sc.curve_count()));  // touches are kept per picture
  tour_asked_ = false;
  if (tour_running_) {
    core_.cancel_tour();  // the servo stops it at the swap anyway; nothing to say of it
    tour_quiet_ = true;
  }
  core_.publish(std::move(bundle));
}

void KioskRuntime::rebuild_shown() {
  // New settings: what was built ahead, or is being built, with the old ones is not used.
  ++generation_;
  ahead_.clear();
  ahead_refused_.clear();
  builder_.drop_ahead();
  drop_want();
  if (shown_id_ <= -1 && shown_id_ >= -3) {
    const int shape = -1 - shown_id_;
    show_tutorial(static_cast<TutorialShape>(shape));
  } else if (shown_picture_ >= 0) {
    wanted_id_ = shown_picture_;
    wanted_kind_ = WantKind::Rebuild;
    wanted_done_.reset();
    builder_.want(shown_picture_, generation_, picture_job(shown_picture_));
  } else if (shown_id_ <= kFirstCaptureId && !shown_.picture.empty()) {
    wanted_id_ = shown_id_;
    wanted_kind_ = WantKind::Rebuild;
    wanted_done_.reset();
    builder_.want(shown_id_, generation_, [picture = shown_.picture.clone(), s = s_] {
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
    const bool same = std::visit([&](const auto* a) {
      using P = decltype(a);
      return *a == *std::get<P>(d.cref(next));
    }, d.cref(before));
    if (same) continue;
    const std::string key = std::string(d.table) + "." + std::string(d.key);
    switch (d.apply) {
      case config::ApplyWhen::live:
        if (d.table == "haptics") r.gains = true;
        if (d.table == "keys") r.keys = true;
        if (d.table == "kiosk") r.timing = true;
        break;
      case config::ApplyWhen::scene: rebuild = true; break;
      case config::ApplyWhen::session: r.next_session.push_back(key); break;
      case config::ApplyWhen::restart: r.restart.push_back(key); break;
    }
  }
  // What the next start needs stays as it was in the running kiosk (its threads, device and view were made
  // with it); everything else is taken.
  config::Settings in_use = next;
  for (const config::FieldDescriptor& d : config::field_descriptors()) {
    if (d.apply != config::ApplyWhen::restart) continue;
    std::visit([&](auto* dst) {
      using P = decltype(dst);
      *dst = *std::get<std::add_pointer_t<std::add_const_t<std::remove_pointer_t<P>>>>(d.cref(before));
    }, d.ref(in_use));
  }
  // A board's profile bounds what the panel may ask of it (device_profile.hpp): refused values take the profile's.
  if (usb_) {
    in_use = settings_for_board(in_use, &r.refused);
    for (const std::string& n : r.refused) spdlog::warn("settings: {}", n);
  }
  s_ = in_use;
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
