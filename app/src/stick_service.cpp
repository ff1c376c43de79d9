#include "stick_service.hpp"

#include <spdlog/spdlog.h>

#include <chrono>

#include "vision/intake.hpp"

namespace hk::app {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// The problem part of a one-line error "kind 'name': problem", for speech (the name is said separately).
std::string problem_of(const std::string& what) {
  const std::size_t k = what.find("': ");
  return k == std::string::npos ? what : what.substr(k + 3);
}

}  // namespace

StickService::StickService(const config::Settings& settings, std::unique_ptr<vision::BlockEventSource> events, std::string mount_root)
    : s_(settings), events_(std::move(events)), mount_root_(std::move(mount_root)) {
  helper_path_ = vision::stick_helper_path();
  mounter_ = vision::choose_stick_mounter(vision::have_mount_capability(), helper_path_);
  if (events_ && mounter_ == vision::StickMounter::None) {
    spdlog::warn("usb sticks: not mounted: this process lacks CAP_SYS_ADMIN and there is no mount helper at {}. {}", helper_path_,
                 vision::mount_capability_hint());
  } else if (events_ && mounter_ == vision::StickMounter::Helper) {
    spdlog::info("usb sticks: mounted read-only by the helper {} under {}", helper_path_, vision::kDefaultStickMountRoot);
  }
  watcher_ = std::thread([this] { watch(); });
  loader_ = std::thread([this] { serve(); });
}

StickService::~StickService() {
  {
    const std::lock_guard<std::mutex> lock(m_);
    stop_ = true;
  }
  cv_.notify_all();
  watcher_.join();
  loader_.join();
  mounted_.reset();  // unmounts
}

void StickService::insert_folder(const std::string& folder) {
  const std::lock_guard<std::mutex> lock(m_);
  folder_inserts_.push_back(folder);
}

void StickService::remove_folder() {
  const std::lock_guard<std::mutex> lock(m_);
  folder_remove_ = true;
}

std::vector<StickNews> StickService::poll_news() {
  const std::lock_guard<std::mutex> lock(m_);
  std::vector<StickNews> out;
  out.swap(news_);
  return out;
}

void StickService::load(int stick, int document, int page) {
  {
    const std::lock_guard<std::mutex> lock(m_);
    request_ = Request{stick, document, page};
  }
  cv_.notify_all();
}

std::vector<LoadedDocument> StickService::poll_loaded() {
  const std::lock_guard<std::mutex> lock(m_);
  std::vector<LoadedDocument> out;
  out.swap(loaded_);
  return out;
}

void StickService::forget() {
  const std::lock_guard<std::mutex> lock(m_);
  stick_id_ = 0;
  stick_root_.clear();
  stick_docs_.clear();
  request_.reset();
}

void StickService::post(StickNews n) {
  const std::lock_guard<std::mutex> lock(m_);
  news_.push_back(std::move(n));
}

void StickService::scan_root(const std::string& root, double started_ms) {
  const auto t0 = std::chrono::steady_clock::now();
  const int id = next_stick_++;
  try {
    StickListing l = list_stick(root, s_);
    for (const vision::RefusedEntry& r : l.refused) spdlog::info("stick {}: left out '{}': {}", id, r.path, r.reason);
    StickNews n;
    n.kind = StickNews::Kind::Inserted;
    n.stick = id;
    n.documents = l.documents;
    n.refused_entries = l.refused.size();
    n.scan_ms = started_ms + ms_since(t0);
    spdlog::info("stick {}: {} documents ({} pictures, {} PDFs), {} entries left out, {} ms", id, l.documents.size(), l.pictures(), l.pdfs(),
                 l.refused.size(), n.scan_ms);
    {
      const std::lock_guard<std::mutex> lock(m_);
      stick_id_ = id;
      stick_root_ = root;
      stick_docs_ = std::move(l.documents);
    }
    post(std::move(n));
  } catch (const std::exception& e) {
    spdlog::warn("stick: {}", e.what());
    StickNews n;
    n.kind = StickNews::Kind::Refused;
    n.stick = id;
    n.reason = problem_of(e.what());
    post(std::move(n));
  }
}

void StickService::handle_add(const std::string& devnode) {
  if (!can_mount()) return;  // said once at start
  if (mounted_) {
    spdlog::info("stick '{}': ignored, '{}' is in use (one stick at a time)", devnode, mounted_->devnode());
    return;
  }
  const auto t0 = std::chrono::steady_clock::now();
  try {
    const int slot = next_slot_;
    next_slot_ = (next_slot_ + 1) % (vision::kMaxStickSlot + 1);  // one stick at a time: slots are reused after 1000
    mounted_ = vision::mount_stick(mounter_, devnode, mount_root_, slot, helper_path_);
  } catch (const std::exception& e) {
    spdlog::warn("{}", e.what());
    StickNews n;
    n.kind = StickNews::Kind::Refused;
    n.reason = problem_of(e.what());
    post(std::move(n));
    return;
  }
  spdlog::info("stick '{}': {} mounted read-only at {}", devnode, mounted_->filesystem(), mounted_->mount_point());
  scan_root(mounted_->mount_point(), ms_since(t0));
}

void StickService::handle_remove(const std::string& devnode) {
  if (!mounted_ || mounted_->devnode() != devnode) return;
  mounted_.reset();  // MNT_DETACH: a read in progress on the loader finishes or fails, nothing hangs
  {
    const std::lock_guard<std::mutex> lock(m_);
    stick_id_ = 0;
    stick_root_.clear();
    stick_docs_.clear();
  }
  spdlog::info("stick '{}': taken out, unmounted", devnode);
  StickNews n;
  n.kind = StickNews::Kind::Removed;
  post(std::move(n));
}

void StickService::watch() {
  for (;;) {
    std::deque<std::string> inserts;
    bool remove_folder = false;
    {
      const std::lock_guard<std::mutex> lock(m_);
      if (stop_) return;
      inserts.swap(folder_inserts_);
      std::swap(remove_folder, folder_remove_);
    }
    if (remove_folder) {
      {
        const std::lock_guard<std::mutex> lock(m_);
        stick_id_ = 0;
        stick_root_.clear();
        stick_docs_.clear();
      }
      StickNews n;
      n.kind = StickNews::Kind::Removed;
      post(std::move(n));
    }
    for (const std::string& f : inserts) scan_root(f, 0.0);
    if (!events_) {
      std::unique_lock<std::mutex> lock(m_);
      cv_.wait_for(lock, std::chrono::milliseconds(50), [this] { return stop_ || !folder_inserts_.empty() || folder_remove_; });
      continue;
    }
    std::optional<vision::BlockEvent> e;
    try {
      e = events_->next(50);
    } catch (const std::exception& ex) {
      spdlog::warn("usb sticks: event source failed, hot-plug off: {}", ex.what());
      events_.reset();
      continue;
    }
    if (!e) continue;
    if (e->action == vision::BlockEvent::Action::Add) handle_add(e->devnode);
    else handle_remove(e->devnode);
  }
}

LoadedDocument StickService::build(const Request& r) {
  const auto t0 = std::chrono::steady_clock::now();
  LoadedDocument out;
  out.stick = r.stick;
  out.document = r.document;
  out.page = r.page;
  std::string root;
  ListedDocument doc;
  {
    const std::lock_guard<std::mutex> lock(m_);
    if (r.stick != stick_id_ || r.document < 0 || r.document >= static_cast<int>(stick_docs_.size())) {
      out.reason = "the USB stick is no longer there";
      return out;
    }
    root = stick_root_;
    doc = stick_docs_[static_cast<std::size_t>(r.document)];
  }
  try {
    const std::vector<std::uint8_t> bytes = vision::read_stick_file(root, doc.doc.path, s_.stick.max_file_bytes);
    loads_started_.fetch_add(1);
    out.scene = doc.doc.kind == vision::DocumentKind::Pdf ? build_pdf_page_scene(bytes, doc.doc.display_name, r.page, s_, pdf_fault_.load(), TextTiming::later)
                                                          : build_image_scene_from_bytes(bytes, doc.doc.display_name, s_, TextTiming::later);
    if (out.scene) fit_picture(*out.scene);  // the screen's copy, made here rather than on the window thread
  } catch (const std::exception& e) {  // InputError, PdfError, StickError: this page only
    spdlog::warn("stick {}: {}", r.stick, e.what());
    out.reason = problem_of(e.what());
  }
  out.load_ms = ms_since(t0);
  if (out.scene) spdlog::info("stick {}: '{}' page {} built in {:.0f} ms", r.stick, doc.doc.display_name, r.page, out.load_ms);
  return out;
}

void StickService::serve() {
  for (;;) {
    Request r;
    {
      std::unique_lock<std::mutex> lock(m_);
      cv_.wait(lock, [this] { return stop_ || request_.has_value(); });
      if (stop_) return;
      r = *request_;
      request_.reset();
    }
    LoadedDocument d = build(r);
    const std::lock_guard<std::mutex> lock(m_);
    loaded_.push_back(std::move(d));
  }
}

}  // namespace hk::app
