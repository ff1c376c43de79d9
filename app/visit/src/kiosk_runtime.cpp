#include "visit/kiosk_runtime.hpp"

#include "runtime/event_log.hpp"
#include "runtime/metrics.hpp"

#include "config/device_profile.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "config/load.hpp"
#include "formats/app_error.hpp"
#include "haptics/io/tty_transport.hpp"
#include "pictures/picture_library.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/device_setup.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/simulation.hpp"
#include "vision/intake.hpp"

namespace hk::app {
namespace {

std::unique_ptr<sticks::BlockEventSource> block_events(bool hotplug) {
  if (!hotplug) return nullptr;
  try {
    return std::make_unique<sticks::UdevBlockEventSource>();
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

/// The library folder of `o` watched, when it asks for that (null otherwise, or when inotify cannot start: logged,
/// the folder is then read once).
std::unique_ptr<LibraryWatch> library_watch(const RuntimeOptions& o, const config::Settings& s) {
  if (!(o.library_settle_s > 0.0)) return nullptr;
  try {
    auto w = std::make_unique<LibraryWatch>(o.library, o.library_settle_s, extract_params_from(s).limits);
    spdlog::info("library: watching {} ({} pictures now)", o.library, w->first_listing().size());
    return w;
  } catch (const AppError& e) {
    spdlog::error("{}; its pictures are read once", e.what());
    return nullptr;
  }
}

/// The shipped pictures when the library folder is watched (empty otherwise, or when they cannot be read: logged).
std::vector<std::string> shipped_pictures(const RuntimeOptions& o) {
  if (!(o.library_settle_s > 0.0) || o.shipped_library.empty()) return {};
  try {
    return list_pictures(o.shipped_library);
  } catch (const AppError& e) {
    spdlog::warn("{}", e.what());
    return {};
  }
}

/// The library's pictures on a shelf, with the scene cache of `o` (none when its folder is empty): the folder
/// watched's live pictures, else the shipped ones; a folder not watched is read once (list_pictures).
/// @throws AppError (one line) when there is no picture to show.
PictureShelf library_shelf(const RuntimeOptions& o, const config::Settings& s, const LibraryWatch* watch,
                           const std::vector<std::string>& shipped) {
  std::shared_ptr<SceneCache> cache;
  if (!o.scene_cache_dir.empty()) {
    cache = std::make_shared<SceneCache>(o.scene_cache_dir);
    spdlog::info("scenes: kept in {}", o.scene_cache_dir);
  }
  std::vector<std::string> pictures;
  if (watch) {
    pictures = watch->first_listing();
    if (pictures.empty()) {
      if (shipped.empty())
        throw AppError("picture library '" + o.library + "': holds no picture, nor do the shipped ones");
      spdlog::info("library: {} holds no picture yet; the {} shipped pictures meanwhile", o.library, shipped.size());
      pictures = shipped;
    }
  } else {
    pictures = list_pictures(o.library);
  }
  return PictureShelf(std::move(pictures), std::move(cache), s);
}

/// The metrics endpoint of [metrics] listen (null when off, or when it cannot listen: logged, the kiosk runs on).
std::unique_ptr<MetricsServer> metrics_server(const config::Settings& s) {
  if (s.metrics.listen.empty()) return nullptr;
  try {
    auto m = std::make_unique<MetricsServer>(s.metrics.listen,
                                             [] { return kiosk_metrics().exposition(HK_PROGRAM_VERSION); });
    spdlog::info("metrics: serving http://{}/metrics", s.metrics.listen);
    return m;
  } catch (const AppError& e) {
    spdlog::error("{}; the kiosk runs on without its metrics", e.what());
    return nullptr;
  }
}

/// The camera of [camera] source: looked for when the source is named, or "auto" and `probe` (else none).
CameraChoice camera_of(const config::Settings& s, bool probe) {
  if (probe || s.camera.source != "auto") return choose_camera(s.camera);
  return CameraChoice{{}, {}, "not looked for (a scripted run)"};
}

/// Whether announce() says that no camera was found: one was looked for.
bool camera_looked_for(const config::Settings& s, bool probe) {
  return s.camera.source != "none" && !(s.camera.source == "auto" && !probe);
}

}  // namespace

KioskRuntime::KioskRuntime(const RuntimeOptions& o, const config::Settings& given)
    : KioskRuntime(o, with_usable_ocr(given), 0) {}

KioskRuntime::KioskRuntime(const RuntimeOptions& o, const config::Settings& s, int /*checked*/)
    : opt_(o),
      s_(s),
      audio_(audio_params(s, o.open_audio_output)),
      voice_(audio_, s_),
      half_{s.workspace.width_m / 2, s.workspace.height_m / 2},
      core_(cue_params_from(s), &audio_.cues()),
      devices_(s),
      tour_(core_, devices_, voice_, audio_, s_, half_, devices_.simulated_handle_m()),
      watch_(library_watch(o, s)),
      shipped_(shipped_pictures(o)),
      shelf_(library_shelf(o, s, watch_.get(), shipped_)),
      stage_(core_, voice_, audio_, tour_, shelf_, s_, half_),
      library_(shelf_, stage_),
      switches_(o.high_contrast, o.overlay),
      camera_(s, camera_of(s, o.probe_camera), camera_looked_for(s, o.probe_camera), stage_, shelf_, voice_, audio_),
      sticks_(s, block_events(o.hotplug),
              o.mount_root.empty() ? std::string(sticks::kDefaultStickMountRoot) : o.mount_root, stage_, shelf_,
              audio_),
      copies_(
          s_, stage_, [this] { return copy_language(); }, &sticks_.service()),
      metrics_(metrics_server(s)) {
  tour_.set_picture([this] { return stage_.tour_picture(); });
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
}

KioskRuntime::~KioskRuntime() { devices_.stop_servo(); }

KioskEffects KioskRuntime::effects() {
  KioskEffects e(voice_, stage_, library_, sticks_, camera_, tour_, static_cast<SessionEffects&>(*this));
  e.copies = &copies_;
  return e;
}

CopyDesk::Language KioskRuntime::copy_language() const {
  const audio::MessageCatalog& m = audio_.messages();
  CopyDesk::Language l;
  l.tag = m.language();
  l.words.key = m.raw(audio::MessageId::copy_key_title);
  l.words.shape = m.raw(audio::MessageId::copy_shape);
  l.words.left_out = m.raw(audio::MessageId::copy_left_out);
  l.words.not_labelled = m.raw(audio::MessageId::copy_not_labelled);
  l.folder = m.raw(audio::MessageId::copy_folder);
  return l;
}

void KioskRuntime::adopt_board_profile() {
  std::vector<std::string> notes;
  s_ = settings_for_board(s_, &notes);
  for (const std::string& n : notes) spdlog::warn("device: {}", n);
  devices_.set_settings(s_);
  shelf_.set_settings(s_, false);
  core_.set_gains(servo_gains_from(s_));
  camera_.set_settings(s_);
}

std::string profile_type(const KioskRuntime& rt) {
  return rt.devices().usb() ? board_profile_type(rt.settings()) : rt.settings().device.type;
}

void KioskRuntime::announce_device() {
  if (s_.device.type == "simulated" && opt_.device.empty()) return;  // chosen: nothing to tell
  if (!opt_.probe_usb_device && opt_.device.empty()) return;
  const bool usb = devices_.usb() != nullptr;
  std::string text = audio_.messages().text(usb ? audio::MessageId::device_ready : audio::MessageId::device_simulated);
  // A handle that did not start at home is the staff's to fix: said at start only, before any visitor.
  if (devices_.take_home_unspoken() && usb) text += " " + audio_.messages().text(audio::MessageId::device_not_home);
  voice_.say(text);
}

void KioskRuntime::poll(KioskFlow* flow, double now_s) {
  if (watch_)
    if (std::optional<LibraryListing> l = watch_->take())
      library_.offer_listing(l->pictures.empty() ? shipped_ : std::move(l->pictures), std::move(l->changed));
  library_.poll(flow, now_s);
  if (flow) {
    sticks_.poll(*flow, now_s);
    camera_.poll(*flow, now_s);
    copies_.poll(*flow, now_s);
  }
  stage_.poll_text(now_s);
  poll_device(now_s);
  poll_metrics(now_s);
  if (flow) kiosk_metrics().set_visit_active(flow->view().state != KioskState::Attract);
}

void KioskRuntime::poll_metrics(double now_s) {
  KioskMetrics& m = kiosk_metrics();
  const ServoDisplayState& d = core_.display();
  if (contact_clock_s_ >= 0.0 && d.state != ContactState::Free) m.add_contact(now_s - contact_clock_s_);
  contact_clock_s_ = now_s;
  if (ServoThread* servo = devices_.servo()) {
    const ServoThread::Totals t = servo->totals();
    m.set_servo(t.ticks, t.missed_deadlines, s_.haptics.servo_rate_hz);
  }
  const char* device = !opt_.device.empty() ? "emulator" : devices_.usb() ? nullptr : "simulated";
  const std::string name = device ? device : board_profile_type(s_);
  const bool connected = d.device_status == DeviceStatus::Ok;
  if (name != metrics_device_ || connected != metrics_connected_) {  // the registry's lock only on a change
    metrics_device_ = name;
    metrics_connected_ = connected;
    m.set_device(name, connected);
  }
  m.set_library_pictures(library_.picture_count());
  if (watch_)
    for (const std::uint64_t refused = watch_->refused(); library_refused_ < refused; ++library_refused_)
      m.error(KioskError::library_refused);
}

void KioskRuntime::poll_after_input() {
  tour_.poll();
  switches_.poll(voice_, audio_.messages());
  core_.collect_retired();
}

void KioskRuntime::poll_device(double now_s) {
  const bool probe = s_.device.type != "simulated" && opt_.probe_usb_device;
  switch (devices_.poll(now_s, core_.display().device_status, probe)) {
    case DeviceNews::None:
      return;
    case DeviceNews::Lost:
      voice_.say(audio_.messages().text(audio::MessageId::device_lost));
      return;
    case DeviceNews::Back:
      voice_.say(audio_.messages().text(audio::MessageId::device_back));
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

void KioskRuntime::set_screen_picture_side_px(int px) {
  const int side_px = std::clamp(px, 256, kScreenPictureMaxSidePx);
  stage_.set_screen_picture_side_px(side_px);
  shelf_.set_side_px(side_px);
  sticks_.set_screen_picture_side_px(side_px);
}

bool KioskRuntime::change_volume(int delta) { return delta > 0 ? audio_.volume_up() : audio_.volume_down(); }

void KioskRuntime::new_session() {
  if (ServoThread* servo = devices_.servo()) {  // the servo thread's timing, once per visitor's session
    const ServoTimingStats t = servo->take_stats();
    spdlog::info(
        "session: servo {} ticks, {} missed deadlines, lateness p50 {:.0f} p99 {:.0f} max {:.0f} us, tick work p99 "
        "{:.0f} us",
        t.ticks, t.missed_deadlines, t.lateness_p50_us, t.lateness_p99_us, t.lateness_max_us, t.compute_p99_us);
  }
  camera_.cancel_capture();
  shelf_.drop_want();
  audio_.new_session();
  voice_.forget();
  switches_.new_visitor();
  stage_.new_visitor();
}

void KioskRuntime::rebuild_shown() {
  // New settings: what was built ahead, or is being built, with the old ones is not used.
  shelf_.set_settings(s_, true);
  const int id = stage_.shown_id();
  const ShownSource& source = stage_.source();
  if (id <= -1 && id >= -3) {
    stage_.show_tutorial(static_cast<TutorialShape>(-1 - id));
  } else if (source.picture >= 0) {
    shelf_.want_rebuild_picture(source.picture);
  } else if (id <= kFirstCaptureId && !stage_.shown().picture.empty()) {
    shelf_.want_rebuild(id, [picture = stage_.shown().picture.clone(), s = s_] {
      return build_image_scene_from_picture(picture, "camera capture", s, TextTiming::later);
    });
  } else if (source.document >= 0) {
    sticks_.rebuild_page(source.document, source.page);
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
  camera_.set_settings(s_);
  sticks_.set_settings(s_);  // pages built ahead with the old settings are dropped
  if (r.gains) core_.set_gains(servo_gains_from(s_));
  if (r.keys) flow.set_keys(s_.keys);
  if (r.timing) flow.set_timing(s_.kiosk.timeout_s, s_.kiosk.warning_s, s_.kiosk.attract_every_s);
  flow.set_copies(s_.copy.to != "off", s_.copy.per_visit);  // the desk reads the rest of [copy] at each copy
  if (rebuild) {
    stage_.reset_level(false);  // the rebuilt scene starts there
    rebuild_shown();
    r.scene_rebuilt = true;
  }
  log_event(r.refused.empty() ? KioskEvent::settings_applied : KioskEvent::settings_refused,
            r.refused.empty() ? spdlog::level::info : spdlog::level::warn,
            fmt::format("settings: applied at the panel{}{}", r.scene_rebuilt ? ", scene rebuilt" : "",
                        r.refused.empty() ? "" : fmt::format(", {} refused for the board", r.refused.size())));
  return r;
}

}  // namespace hk::app
