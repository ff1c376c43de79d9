// The picture library folder watched (library_watch.hpp).
#include "pictures/library_watch.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/inotify.h>
#include <sys/stat.h>
#include <unistd.h>

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include "formats/app_error.hpp"
#include "pictures/picture_library.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;

constexpr double kBurstQuiet_s = 0.1;   // a look comes this long after the last event of a burst
constexpr double kFolderRetry_s = 2.0;  // a missing folder is looked for again this often
constexpr int kReducedSidePx = 256;     // the check decodes at reduced detail (a whole pass over the file's bytes)

std::int64_t ns_of(const struct timespec& t) { return std::int64_t{t.tv_sec} * 1'000'000'000 + t.tv_nsec; }

double steady_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

/// The picture `name`'s stem and a dot: its companions' names start with it.
std::string companion_prefix(const std::string& name) { return fs::path(name).stem().string() + "."; }

}  // namespace

std::vector<WatchedFile> look_at_folder(const std::string& folder, std::string* why) {
  std::vector<WatchedFile> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder, ec)) {
    struct stat st {};
    if (::stat(e.path().c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;  // gone meanwhile, or not a file
    out.push_back(
        {e.path().filename().string(), static_cast<std::uint64_t>(st.st_size), ns_of(st.st_mtim), ns_of(st.st_ctim)});
  }
  if (ec) {
    if (why) *why = ec.message();
    out.clear();
  }
  std::sort(out.begin(), out.end(), [](const WatchedFile& a, const WatchedFile& b) { return a.name < b.name; });
  return out;
}

LibrarySettler::LibrarySettler(double settle_s, PictureCheck check) : settle_s_(settle_s), check_(std::move(check)) {
  if (!(settle_s > 0.0)) throw AppError("library watch: the quiet time must be > 0 s");
}

namespace {

/// Each picture of `files` (by name) with its stamp and the newest mtime of its files [ns].
struct Stamped {
  std::string name, stamp;
  std::int64_t newest_mtime_ns = 0;
};

std::vector<Stamped> stamps_of(const std::vector<WatchedFile>& files) {
  std::vector<Stamped> out;
  for (const WatchedFile& f : files) {
    if (!is_picture_name(f.name)) continue;
    Stamped s{f.name, {}, 0};
    const std::string prefix = companion_prefix(f.name);
    for (const WatchedFile& g : files) {  // `files` is sorted: the companions sit together
      if (g.name.compare(0, prefix.size(), prefix) != 0) continue;
      s.stamp += g.name + '\0' + std::to_string(g.bytes) + '\0' + std::to_string(g.mtime_ns) + '\0' +
                 std::to_string(g.ctime_ns) + '\n';
      s.newest_mtime_ns = std::max(s.newest_mtime_ns, g.mtime_ns);
    }
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace

void LibrarySettler::adopt(const std::vector<WatchedFile>& files, std::int64_t now_ns) {
  const auto settle_ns = static_cast<std::int64_t>(settle_s_ * 1e9);
  for (Stamped& s : stamps_of(files)) {
    if (now_ns - s.newest_mtime_ns < settle_ns) continue;  // written lately: the first look starts its quiet time
    Picture& p = pictures_[s.name];
    p.stamp = s.stamp;
    p.live_stamp = std::move(s.stamp);
  }
}

bool LibrarySettler::look(const std::vector<WatchedFile>& files, double now_s) {
  bool changed = false;
  std::vector<Stamped> now = stamps_of(files);
  // Removed: not live at once.
  for (auto it = pictures_.begin(); it != pictures_.end();) {
    const bool there = std::any_of(now.begin(), now.end(), [&](const Stamped& s) { return s.name == it->first; });
    if (there) {
      ++it;
      continue;
    }
    changed = changed || !it->second.live_stamp.empty();
    it = pictures_.erase(it);
  }
  for (Stamped& s : now) {
    Picture& p = pictures_[s.name];
    if (p.stamp != s.stamp) {  // new, or changed: its quiet time starts again
      p.stamp = std::move(s.stamp);
      p.since_s = now_s;
    }
    if (now_s - p.since_s < settle_s_ || p.stamp == p.live_stamp || p.stamp == p.refused) continue;
    const std::string why = check_(s.name);
    const bool was_live = !p.live_stamp.empty();
    if (why.empty()) {
      p.live_stamp = p.stamp;
      p.refused.clear();
      if (was_live) changed_.push_back(s.name);
      spdlog::info("library: {} {}", s.name, was_live ? "changed: taken" : "taken");
    } else {
      p.refused = p.stamp;
      p.live_stamp.clear();
      spdlog::warn("library: {}: {}; not shown until it changes", s.name, why);
    }
    changed = changed || why.empty() || was_live;
  }
  return changed;
}

std::vector<std::string> LibrarySettler::live() const {
  std::vector<std::string> out;
  for (const auto& [name, p] : pictures_)
    if (!p.live_stamp.empty()) out.push_back(name);
  return out;  // std::map: sorted by name
}

std::vector<std::string> LibrarySettler::take_changed() { return std::exchange(changed_, {}); }

double LibrarySettler::next_due_s() const {
  double due = std::numeric_limits<double>::infinity();
  for (const auto& [name, p] : pictures_)
    if (p.stamp != p.live_stamp && p.stamp != p.refused) due = std::min(due, p.since_s + settle_s_);
  return due;
}

LibraryWatch::LibraryWatch(std::string folder, double settle_s, vision::ImageLimits limits)
    : folder_(std::move(folder)), settler_(settle_s, [this, limits](const std::string& name) -> std::string {
        try {
          (void)vision::load_image_reduced((fs::path(folder_) / name).string(), limits, kReducedSidePx);
          return {};
        } catch (const std::exception& e) {
          refused_.fetch_add(1);
          return e.what();
        }
      }) {
  inotify_fd_ = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (inotify_fd_ < 0) throw AppError("library '" + folder_ + "': cannot watch it (" + std::strerror(errno) + ")");
  stop_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (stop_fd_ < 0) {
    ::close(inotify_fd_);
    throw AppError("library '" + folder_ + "': cannot watch it (" + std::strerror(errno) + ")");
  }
  watch_folder();  // before the first look: nothing written after it is missed
  const auto now_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  settler_.adopt(look_at_folder(folder_), now_ns);
  for (const std::string& name : settler_.live()) first_.push_back((fs::path(folder_) / name).string());
  thread_ = std::thread([this] { run(); });
}

LibraryWatch::~LibraryWatch() {
  const std::uint64_t one = 1;
  if (::write(stop_fd_, &one, sizeof one) < 0) spdlog::warn("library watch: cannot stop it ({})", std::strerror(errno));
  if (thread_.joinable()) thread_.join();
  ::close(stop_fd_);
  ::close(inotify_fd_);
}

std::optional<LibraryListing> LibraryWatch::take() {
  std::lock_guard lock(mu_);
  return std::exchange(waiting_, std::nullopt);
}

bool LibraryWatch::watch_folder() {
  constexpr std::uint32_t kEvents = IN_CREATE | IN_DELETE | IN_MODIFY | IN_CLOSE_WRITE | IN_MOVED_FROM | IN_MOVED_TO |
                                    IN_ATTRIB | IN_DELETE_SELF | IN_MOVE_SELF | IN_ONLYDIR;
  watch_ = inotify_add_watch(inotify_fd_, folder_.c_str(), kEvents);
  return watch_ >= 0;
}

void LibraryWatch::publish() {
  LibraryListing l;
  for (const std::string& name : settler_.live()) l.pictures.push_back((fs::path(folder_) / name).string());
  for (const std::string& name : settler_.take_changed()) l.changed.push_back((fs::path(folder_) / name).string());
  std::lock_guard lock(mu_);
  if (waiting_)  // not taken yet: what changed then still changed
    l.changed.insert(l.changed.begin(), waiting_->changed.begin(), waiting_->changed.end());
  waiting_ = std::move(l);
}

void LibraryWatch::run() {
  double burst_until_s = -1.0;  // a look is due once the events have been quiet until then
  bool look_now = true;         // the first look: pictures adopt() left waiting
  for (;;) {
    const double now_s = steady_s();
    if (look_now || (burst_until_s >= 0.0 && now_s >= burst_until_s)) {
      look_now = false;
      burst_until_s = -1.0;
      if (watch_ < 0 && watch_folder()) spdlog::info("library: watching {}", folder_);
      if (settler_.look(look_at_folder(folder_), now_s)) publish();
      looks_.fetch_add(1);
      continue;
    }
    double due_s = settler_.next_due_s();
    if (burst_until_s >= 0.0) due_s = std::min(due_s, burst_until_s);
    if (watch_ < 0) due_s = std::min(due_s, now_s + kFolderRetry_s);
    int timeout_ms = -1;
    if (std::isfinite(due_s)) timeout_ms = static_cast<int>(std::ceil(std::max(0.0, due_s - now_s) * 1000.0));
    std::array<pollfd, 2> fds{{{inotify_fd_, POLLIN, 0}, {stop_fd_, POLLIN, 0}}};
    const int n = ::poll(fds.data(), fds.size(), timeout_ms);
    if (n < 0 && errno != EINTR) {
      spdlog::error("library watch: {}; the library is no longer watched", std::strerror(errno));
      return;
    }
    if (fds[1].revents & POLLIN) return;
    if (n == 0) {  // a deadline: a picture's quiet time, the burst's end or the folder's retry
      look_now = true;
      continue;
    }
    if (fds[0].revents & POLLIN) {
      alignas(inotify_event) std::array<char, 16384> buf;
      for (;;) {
        const ssize_t got = ::read(inotify_fd_, buf.data(), buf.size());
        if (got <= 0) break;
        for (ssize_t at = 0; at < got;) {
          const auto* ev = reinterpret_cast<const inotify_event*>(buf.data() + at);
          if (ev->wd == watch_ && (ev->mask & (IN_IGNORED | IN_DELETE_SELF | IN_MOVE_SELF))) {
            spdlog::warn("library: {} went away; the shipped pictures until it is back", folder_);
            if (!(ev->mask & IN_IGNORED)) inotify_rm_watch(inotify_fd_, watch_);  // a moved folder is not ours
            watch_ = -1;
          }
          at += static_cast<ssize_t>(sizeof(inotify_event) + ev->len);
        }
      }
      burst_until_s = steady_s() + kBurstQuiet_s;
    }
  }
}

}  // namespace hk::app
