#pragma once
/// @file library_watch.hpp
/// The picture library folder watched ([kiosk] library): pictures added, changed and removed there are taken
/// without a restart, by one rule that fits every way a folder is filled (Ansible's copy, rsync, Syncthing's
/// temporary name then rename, a person dragging files):
///
///   | what happens in the folder                        | what the kiosk does                                   |
///   |---------------------------------------------------|-------------------------------------------------------|
///   | a picture appears or its files change             | waits until its files are unchanged for settle_s (2 s) |
///   | …then its picture file decodes within the limits  | it is live: listed, reachable by Next                  |
///   | …then it does not decode (half written, broken)   | not live; one log line, again only when it changes     |
///   | a picture's file is removed                       | not live at once                                      |
///   | a hidden file (".name", a sync tool's temporary)  | passed over                                           |
///
/// A picture's files are the picture and its companions: every file whose name starts with the picture's stem and
/// a dot (NAME.toml sidecar, NAME.annotations.json). "Unchanged" compares each file's size, mtime and ctime (a copy
/// that keeps mtime still changes ctime). What the window thread does with a new listing (the picture a visitor
/// explores stays until they move on) is LibraryDesk's.

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "vision/intake.hpp"

namespace hk::app {

/// One file of the folder as a look saw it.
struct WatchedFile {
  std::string name;                         ///< file name in the folder (no directory)
  std::uint64_t bytes = 0;                  ///< size [bytes]
  std::int64_t mtime_ns = 0, ctime_ns = 0;  ///< [ns since the epoch]
};

/// The regular files of `folder` (no subfolders, hidden ones included: the settler passes over them). Empty when
/// the folder cannot be read (`*why` then says why, one line, when given).
std::vector<WatchedFile> look_at_folder(const std::string& folder, std::string* why = nullptr);

/// The quiet rule of the file comment, without threads or clocks of its own: fed what the folder holds at a time,
/// it says which pictures are live. Not thread-safe.
class LibrarySettler {
 public:
  /// Why picture `name` cannot be taken ("" when it decodes): a whole decode within the limits (LibraryWatch), a
  /// stand-in in tests.
  using PictureCheck = std::function<std::string(const std::string& name)>;

  /// `settle_s`: how long a picture's files must be unchanged before it is taken [s]. @throws AppError when it is
  /// not > 0.
  LibrarySettler(double settle_s, PictureCheck check);

  /// The folder as it is when the kiosk starts: every picture whose files were last written (mtime) at least
  /// settle_s before `now_ns` (wall clock, [ns since the epoch]) is live at once, without a decode (as a restart
  /// would list it); the rest go through the rule. mtime, not ctime: a finished file renamed in keeps the mtime
  /// its writer gave it, and a file still being written has a fresh one.
  void adopt(const std::vector<WatchedFile>& files, std::int64_t now_ns);
  /// One look at the folder at `now_s` (a steady clock [s]). Returns whether the live listing changed.
  bool look(const std::vector<WatchedFile>& files, double now_s);
  /// Live pictures' file names, sorted.
  std::vector<std::string> live() const;
  /// Live pictures whose files changed since they were last handed out (cleared by the call).
  std::vector<std::string> take_changed();
  /// When a picture waiting for the quiet time is due to be looked at again [s, the look's clock]; +infinity when
  /// none waits.
  double next_due_s() const;

 private:
  struct Picture {
    std::string stamp;       // its files' names, sizes, mtimes and ctimes
    double since_s = 0.0;    // when the stamp last changed (look's clock)
    std::string live_stamp;  // the stamp it was taken with ("" = not live)
    std::string refused;     // the stamp it was refused with ("" = none)
  };
  double settle_s_;
  PictureCheck check_;
  std::map<std::string, Picture> pictures_;  // by file name
  std::vector<std::string> changed_;
};

/// A listing handed to the window thread.
struct LibraryListing {
  std::vector<std::string> pictures;  ///< live pictures' paths, sorted by file name (may be empty)
  std::vector<std::string> changed;   ///< paths of live pictures whose files changed since the listing before
};

/// A thread that watches `folder` with inotify and keeps a LibrarySettler fed: a look after each burst of events
/// (100 ms after the last), and at each settler deadline. A folder that is missing or goes away is looked for again
/// every 2 s. Never blocks its caller: take() swaps out the newest listing.
class LibraryWatch {
 public:
  /// Starts watching. `settle_s` > 0 [s]; `limits`: the image limits a picture must decode within.
  /// @throws AppError (one line) when inotify cannot be started.
  LibraryWatch(std::string folder, double settle_s, vision::ImageLimits limits);
  ~LibraryWatch();
  LibraryWatch(const LibraryWatch&) = delete;
  LibraryWatch& operator=(const LibraryWatch&) = delete;

  /// The folder watched.
  const std::string& folder() const { return folder_; }
  /// The live pictures' paths as the watch began (adopt: what a restart would list), sorted by file name.
  std::vector<std::string> first_listing() const { return first_; }
  /// The newest listing since the last call, if the live pictures changed meanwhile. Any thread.
  std::optional<LibraryListing> take();
  /// Looks since the start (tests wait on it: a look after a change means the change was seen).
  std::uint64_t looks() const { return looks_.load(); }
  /// Pictures refused since the start (each picture once per change of its files: it did not decode).
  std::uint64_t refused() const { return refused_.load(); }

 private:
  void run();
  bool watch_folder();  // (re)adds the inotify watch; false when the folder is not there
  void publish();       // the settler's live pictures as the listing waiting

  std::string folder_;
  LibrarySettler settler_;  // the thread's once it runs
  int inotify_fd_ = -1;
  int watch_ = -1;    // the folder's inotify watch, −1 while it is missing
  int stop_fd_ = -1;  // eventfd: the destructor's word to stop
  std::vector<std::string> first_;
  std::mutex mu_;
  std::optional<LibraryListing> waiting_;  // guarded by mu_
  std::atomic<std::uint64_t> looks_{0}, refused_{0};
  std::thread thread_;
};

}  // namespace hk::app
