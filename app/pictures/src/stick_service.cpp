#include "pictures/stick_service.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>

#include "formats/app_error.hpp"
#include "vision/intake.hpp"

namespace hk::app {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

StickService::StickService(const config::Settings& settings, std::unique_ptr<sticks::BlockEventSource> events,
                           std::string mount_root)
    : s_(settings), events_(std::move(events)), mount_root_(std::move(mount_root)) {
  helper_path_ = sticks::stick_helper_path();
  mounter_ = sticks::choose_stick_mounter(sticks::have_mount_capability(), helper_path_);
  if (events_ && mounter_ == sticks::StickMounter::None) {
    spdlog::warn("usb sticks: not mounted: this process lacks CAP_SYS_ADMIN and there is no mount helper at {}. {}",
                 helper_path_, sticks::mount_capability_hint());
  } else if (events_ && mounter_ == sticks::StickMounter::Helper) {
    spdlog::info("usb sticks: mounted read-only by the helper {} under {}", helper_path_,
                 sticks::kDefaultStickMountRoot);
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
  folder_ops_.emplace_back(folder);
}

std::future<StickWriteOutcome> StickService::write_to_stick(std::function<void(const std::string& top)> write) {
  WriteJob job;
  job.write = std::move(write);
  std::future<StickWriteOutcome> f = job.done.get_future();
  {
    const std::lock_guard<std::mutex> lock(m_);
    writes_.push_back(std::move(job));
  }
  cv_.notify_all();
  return f;
}

void StickService::run_write(WriteJob& job) {
  StickWriteOutcome out;
  if (folder_stick_) {
    try {
      job.write(*folder_stick_);
      out.kind = StickWriteOutcome::Kind::Written;
      job.done.set_value(out);
    } catch (...) {
      job.done.set_exception(std::current_exception());
    }
    return;
  }
  if (!mounted_) {
    out.kind = StickWriteOutcome::Kind::NoStick;
    job.done.set_value(out);
    return;
  }
  std::unique_ptr<sticks::StickWriteMount> rw;
  try {
    rw = mounted_->mount_writable();
  } catch (const std::exception& e) {
    switch (sticks::stick_write_refusal(e.what())) {
      case sticks::StickWriteRefusal::WriteProtected:
        out.kind = StickWriteOutcome::Kind::WriteProtected;
        break;
      case sticks::StickWriteRefusal::Format:
        out.kind = StickWriteOutcome::Kind::Format;
        break;
      case sticks::StickWriteRefusal::Other:
        out.kind = StickWriteOutcome::Kind::Failed;
        break;
    }
    out.error = e.what();
    job.done.set_value(out);
    return;
  }
  std::exception_ptr failed;
  try {
    job.write(rw->folder());
  } catch (...) {
    failed = std::current_exception();
  }
  try {
    rw->close();  // synced, read-only again, the second mount gone
    out.kind = StickWriteOutcome::Kind::Written;
  } catch (const std::exception& e) {
    out.kind = StickWriteOutcome::Kind::Failed;
    out.error = e.what();
  }
  if (failed)
    job.done.set_exception(failed);
  else
    job.done.set_value(out);
}

void StickService::remove_folder() {
  const std::lock_guard<std::mutex> lock(m_);
  folder_ops_.emplace_back(std::nullopt);
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
    const Request r{stick, document, page};
    at_ = r;
    request_.reset();
    building_wanted_.reset();  // a build ahead asked for before this is no longer wanted
    // Kept: the neighbours of the page asked for; the page itself, built ahead, goes to the visitor.
    const std::vector<Request> near = neighbours();
    std::vector<AheadPage> kept;
    bool served = false;
    for (AheadPage& a : ahead_) {
      if (a.at == r) {
        served = true;
        a.loaded.load_ms = 0;
        spdlog::info("stick {}: page {} of document {} built ahead, on the device at once", r.stick, r.page,
                     r.document + 1);
        loaded_.push_back(std::move(a.loaded));
      } else if (std::find(near.begin(), near.end(), a.at) != near.end()) {
        kept.push_back(std::move(a));
      }
    }
    ahead_ = std::move(kept);
    if (!served) {
      if (building_ && *building_ == r) {
        building_wanted_ = std::chrono::steady_clock::now();  // handed over when its build ends
      } else {
        request_ = r;
      }
    }
  }
  cv_.notify_all();
}

void StickService::set_settings(const config::Settings& s) {
  const std::lock_guard<std::mutex> lock(m_);
  s_ = s;
  drop_ahead();
  ahead_refused_.clear();
}

void StickService::set_pdf_fault(vision::PdfFault fault) {
  pdf_fault_.store(fault);
  const std::lock_guard<std::mutex> lock(m_);
  drop_ahead();
}

int StickService::pages_ahead() const {
  const std::lock_guard<std::mutex> lock(m_);
  return static_cast<int>(ahead_.size());
}

void StickService::drop_ahead() {
  ahead_.clear();
  ++ahead_generation_;
}

std::vector<StickService::Request> StickService::neighbours() const {
  std::vector<Request> out;
  if (!at_ || at_->stick != stick_id_ || stick_docs_.empty()) return out;
  if (at_->document < 0 || at_->document >= static_cast<int>(stick_docs_.size())) return out;
  std::vector<int> pages;
  pages.reserve(stick_docs_.size());
  for (const ListedDocument& d : stick_docs_) pages.push_back(d.pages);
  for (const int delta : {+1, -1}) {
    const StickPage p = step_stick_page(pages, {at_->document, at_->page}, delta);
    const Request r{at_->stick, p.document, p.page};
    if (r != *at_ && std::find(out.begin(), out.end(), r) == out.end()) out.push_back(r);
  }
  return out;
}

std::size_t StickService::ahead_budget_bytes() const { return static_cast<std::size_t>(s_.kiosk.prefetch_mb) << 20; }

std::size_t StickService::ahead_bytes() const {
  std::size_t used = 0;
  for (const AheadPage& a : ahead_) used += a.bytes;
  return used;
}

std::optional<StickService::Request> StickService::next_ahead() const {
  const std::size_t budget = ahead_budget_bytes();
  if (budget == 0 || ahead_bytes() >= budget) return std::nullopt;
  for (const Request& r : neighbours()) {
    const bool have = std::any_of(ahead_.begin(), ahead_.end(), [&](const AheadPage& a) { return a.at == r; });
    const bool refused = std::find(ahead_refused_.begin(), ahead_refused_.end(), r) != ahead_refused_.end();
    if (!have && !refused) return r;
  }
  return std::nullopt;
}

void StickService::keep_ahead(const Request& r, LoadedDocument d, std::uint64_t generation) {
  if (generation != ahead_generation_) return;  // settings, fault or stick changed meanwhile
  const std::vector<Request> near = neighbours();
  if (std::find(near.begin(), near.end(), r) == near.end()) return;  // the visitor went elsewhere
  if (!d.scene) {  // said when the visitor asks for it (built again then)
    ahead_refused_.push_back(r);
    return;
  }
  const std::size_t bytes = approx_scene_bytes(*d.scene);
  if (ahead_bytes() + bytes > ahead_budget_bytes()) {
    spdlog::info("stick {}: page {} of document {} ({} MiB) is over [kiosk] prefetch_mb; built when asked for", r.stick,
                 r.page, r.document + 1, bytes >> 20);
    ahead_refused_.push_back(r);
    return;
  }
  ahead_.push_back(AheadPage{r, std::move(d), bytes});
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
  at_.reset();
  drop_ahead();
  ahead_refused_.clear();
}

void StickService::post(StickNews n) {
  const std::lock_guard<std::mutex> lock(m_);
  news_.push_back(std::move(n));
}

void StickService::scan_root(const std::string& root, double started_ms) {
  const auto t0 = std::chrono::steady_clock::now();
  const int id = next_stick_++;
  config::Settings s;
  {
    const std::lock_guard<std::mutex> lock(m_);
    s = s_;
  }
  try {
    StickListing l = list_stick(root, s);
    for (const vision::RefusedEntry& r : l.refused) spdlog::info("stick {}: left out '{}': {}", id, r.path, r.reason);
    StickNews n;
    n.kind = StickNews::Kind::Inserted;
    n.stick = id;
    n.documents = l.documents;
    n.refused_entries = l.refused.size();
    n.unreadable_documents = static_cast<int>(
        std::count_if(l.refused.begin(), l.refused.end(), [](const vision::RefusedEntry& r) { return r.document; }));
    n.refused = l.refused;
    n.scan_ms = started_ms + ms_since(t0);
    spdlog::info("stick {}: {} documents ({} pictures, {} PDFs), {} entries left out, {} ms", id, l.documents.size(),
                 l.pictures(), l.pdfs(), l.refused.size(), n.scan_ms);
    {
      const std::lock_guard<std::mutex> lock(m_);
      stick_id_ = id;
      stick_root_ = root;
      stick_docs_ = std::move(l.documents);
      at_.reset();
      drop_ahead();
      ahead_refused_.clear();
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
    next_slot_ = (next_slot_ + 1) % (sticks::kMaxStickSlot + 1);  // one stick at a time: slots are reused after 1000
    mounted_ = sticks::mount_stick(mounter_, devnode, mount_root_, slot, helper_path_);
  } catch (const std::exception& e) {
    spdlog::warn("{}", e.what());
    StickNews n;
    n.kind = StickNews::Kind::Refused;
    n.reason = problem_of(e.what());
    post(std::move(n));
    return;
  }
  stick_in_ = true;
  spdlog::info("stick '{}': {} mounted read-only at {}", devnode, mounted_->filesystem(), mounted_->mount_point());
  scan_root(mounted_->mount_point(), ms_since(t0));
}

void StickService::handle_remove(const std::string& devnode) {
  if (!mounted_ || mounted_->devnode() != devnode) return;
  mounted_.reset();  // MNT_DETACH: a read in progress on the loader finishes or fails, nothing hangs
  stick_in_ = folder_stick_.has_value();
  {
    const std::lock_guard<std::mutex> lock(m_);
    stick_id_ = 0;
    stick_root_.clear();
    stick_docs_.clear();
    drop_ahead();
  }
  spdlog::info("stick '{}': taken out, unmounted", devnode);
  StickNews n;
  n.kind = StickNews::Kind::Removed;
  post(std::move(n));
}

void StickService::watch() {
  for (;;) {
    std::deque<std::optional<std::string>> ops;
    std::deque<WriteJob> writes;
    {
      const std::lock_guard<std::mutex> lock(m_);
      if (stop_) return;
      ops.swap(folder_ops_);
      writes.swap(writes_);
    }
    // In the order asked: a folder put in and taken out at once ends taken out.
    for (const std::optional<std::string>& op : ops) {
      folder_stick_ = op;
      stick_in_ = folder_stick_.has_value() || mounted_ != nullptr;
      if (op) {
        scan_root(*op, 0.0);
        continue;
      }
      {
        const std::lock_guard<std::mutex> lock(m_);
        stick_id_ = 0;
        stick_root_.clear();
        stick_docs_.clear();
        drop_ahead();
      }
      StickNews n;
      n.kind = StickNews::Kind::Removed;
      post(std::move(n));
    }
    for (WriteJob& job : writes) run_write(job);
    if (!events_) {
      std::unique_lock<std::mutex> lock(m_);
      cv_.wait_for(lock, std::chrono::milliseconds(50),
                   [this] { return stop_ || !folder_ops_.empty() || !writes_.empty(); });
      continue;
    }
    std::optional<sticks::BlockEvent> e;
    try {
      e = events_->next(50);
    } catch (const std::exception& ex) {
      spdlog::warn("usb sticks: event source failed, hot-plug off: {}", ex.what());
      events_.reset();
      continue;
    }
    if (!e) continue;
    if (e->action == sticks::BlockEvent::Action::Add)
      handle_add(e->devnode);
    else
      handle_remove(e->devnode);
  }
}

LoadedDocument StickService::build(const Request& r, bool ahead) {
  const auto t0 = std::chrono::steady_clock::now();
  LoadedDocument out;
  out.stick = r.stick;
  out.document = r.document;
  out.page = r.page;
  std::string root;
  ListedDocument doc;
  config::Settings s;
  {
    const std::lock_guard<std::mutex> lock(m_);
    if (r.stick != stick_id_ || r.document < 0 || r.document >= static_cast<int>(stick_docs_.size())) {
      out.reason = "the USB stick is no longer there";
      return out;
    }
    root = stick_root_;
    doc = stick_docs_[static_cast<std::size_t>(r.document)];
    s = s_;
  }
  try {
    const std::vector<std::uint8_t> bytes = vision::read_stick_file(root, doc.doc.path, s.stick.max_file_bytes);
    (ahead ? ahead_started_ : loads_started_).fetch_add(1);
    const int side_px = screen_side_px_.load();
    out.scene = doc.doc.kind == vision::DocumentKind::Pdf
                    ? build_pdf_page_scene(bytes, doc.doc.display_name, r.page, s, pdf_fault_.load(), TextTiming::later,
                                           side_px)
                    : build_image_scene_from_bytes(bytes, doc.doc.display_name, s, TextTiming::later);
    if (out.scene) fit_picture(*out.scene, side_px);  // the screen's copy, made here rather than on the window thread
  } catch (const std::exception& e) {                 // InputError, PdfError, StickError: this page only
    spdlog::warn("stick {}: {}", r.stick, e.what());
    out.reason = problem_of(e.what());
  }
  out.load_ms = ms_since(t0);
  if (out.scene)
    spdlog::info("stick {}: '{}' page {} built{} in {:.0f} ms", r.stick, doc.doc.display_name, r.page,
                 ahead ? " ahead" : "", out.load_ms);
  return out;
}

void StickService::serve() {
  std::unique_lock<std::mutex> lock(m_);
  for (;;) {
    std::optional<Request> ahead;
    cv_.wait(lock, [&] {
      if (stop_ || request_) return true;
      ahead = next_ahead();  // between requests: the neighbours of the page last asked for
      return ahead.has_value();
    });
    if (stop_) return;
    if (request_) {
      const Request r = *request_;
      request_.reset();
      lock.unlock();
      LoadedDocument d = build(r, false);
      lock.lock();
      loaded_.push_back(std::move(d));
      loads_done_.fetch_add(1);
      continue;
    }
    const std::uint64_t generation = ahead_generation_;
    building_ = *ahead;
    building_wanted_.reset();
    lock.unlock();
    LoadedDocument d = build(*ahead, true);
    lock.lock();
    building_.reset();
    if (!building_wanted_) {
      keep_ahead(*ahead, std::move(d), generation);
    } else if (generation == ahead_generation_) {  // the visitor asked for it while it was built
      d.load_ms = ms_since(*building_wanted_);
      loaded_.push_back(std::move(d));
    } else if (!request_) {  // asked for, but built with what no longer holds: built again
      request_ = *ahead;
    }
    building_wanted_.reset();
  }
}

}  // namespace hk::app
