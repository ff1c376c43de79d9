#pragma once
/// @file stick_service.hpp
/// The kiosk's USB-stick work off the window and servo threads.
///
/// Two worker threads:
/// - the watcher takes block events (sticks::BlockEventSource), mounts an inserted stick read-only
///   (sticks::mount_stick: itself with CAP_SYS_ADMIN, else through the mount helper hk-stick-mount when it
///   is installed), scans it and counts its PDFs' pages (list_stick), and unmounts it when it is taken out;
///   with neither it says once in the log how to grant the capability and ignores sticks;
/// - the loader builds the scene of a document page on request (the PDF drawn in its worker process,
///   edges, multiresolution, trees; OCR's text left for the kiosk's TextReader: TextTiming::later), so a slow
///   or hostile page never blocks the window. Between requests it builds the pages Next and Previous lead to
///   from the page last asked for (step_stick_page), the next one first, and keeps them within the prefetch
///   budget ([kiosk] prefetch_mb), so Next on a stick is a swap: a request for a page built ahead is
///   answered at once, and one for the page being built ahead takes that build over.
/// The window thread polls both with poll_news() and poll_loaded() each frame (mutex-guarded queues: neither
/// thread is real-time). A folder can stand in for a stick (insert_folder), for tests and `--stick DIR`.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "config/settings.hpp"
#include "pictures/documents.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/stick_pages.hpp"
#include "sticks/stick_mount.hpp"
#include "sticks/usb_stick.hpp"

namespace hk::app {

/// Something that happened to the stick.
struct StickNews {
  enum class Kind { Inserted, Refused, Removed };
  Kind kind = Kind::Inserted;
  int stick = 0;                              ///< the stick's number (every insertion gets a new one)
  std::vector<ListedDocument> documents;      ///< Inserted: what it offers
  std::size_t refused_entries = 0;            ///< Inserted: entries left out (reasons in the log and in `refused`)
  std::vector<vision::RefusedEntry> refused;  ///< Inserted: those entries and why (for the operator's panel)
  int unreadable_documents = 0;  ///< Inserted: of those, pictures and PDFs that cannot be read (RefusedEntry::document)
  std::string reason;            ///< Refused: why, one line for speech
  double scan_ms = 0;            ///< Inserted: mount + scan + page counting [ms]
};

/// A finished load.
struct LoadedDocument {
  int stick = 0, document = 0, page = 1;
  std::optional<ImageScene> scene;  ///< set when it could be built
  std::string reason;               ///< why not, one line for speech (the problem without the file name)
  double load_ms = 0;               ///< request to result [ms]
};

/// What became of a write onto the stick (StickService::write_to_stick).
struct StickWriteOutcome {
  enum class Kind {
    Written,         ///< the writer ran and what it wrote is on the stick (synced)
    NoStick,         ///< no stick is in the kiosk
    WriteProtected,  ///< its lock switch is on (or the device is read-only)
    Format,          ///< not FAT or exFAT: the kiosk does not write to it
    Failed,          ///< anything else; `error` says what (one line, for the log)
  };
  Kind kind = Kind::Failed;
  std::string error;
};

/// Watcher and loader threads. Construct and use from the window thread.
class StickService {
 public:
  /// `events` may be null (no hot-plug: only insert_folder). `mount_root` is where sticks are mounted (the
  /// helper always mounts under sticks::kDefaultStickMountRoot). Who mounts is chosen once here:
  /// sticks::choose_stick_mounter(have_mount_capability(), stick_helper_path()).
  StickService(const config::Settings& settings, std::unique_ptr<sticks::BlockEventSource> events,
               std::string mount_root);
  /// Stops both threads (a load in progress finishes first: at most the page time limit) and unmounts.
  ~StickService();
  StickService(const StickService&) = delete;
  StickService& operator=(const StickService&) = delete;

  /// Treat a folder as an inserted stick (scanned on the watcher thread; news as for a stick).
  void insert_folder(const std::string& folder);
  /// Treat the folder stick as taken out.
  void remove_folder();
  /// News since the last call, oldest first.
  std::vector<StickNews> poll_news();
  /// Ask for page `page` of document `document` of stick `stick`; supersedes a request not yet started. A
  /// page built ahead is handed over at once (poll_loaded returns it, load_ms 0); a page being built ahead is
  /// handed over when that build ends.
  void load(int stick, int document, int page);
  /// New settings ([kiosk] prefetch_mb and the scene-shaping ones; the [stick] limits are read at start):
  /// pages built ahead with other settings are dropped, and later loads use these.
  void set_settings(const config::Settings& s);
  /// Finished loads since the last call.
  std::vector<LoadedDocument> poll_loaded();
  /// Forget the stick's listing (a new session): later loads of it are refused. The mount stays until removal.
  void forget();
  /// Writes onto the stick in the kiosk, on the watcher thread (so it never races the stick's removal): a mounted
  /// stick is opened for writing for the time of `write` (StickMount::mount_writable: FAT and exFAT only, synced
  /// and read-only again after); a folder stick is written directly. `write` gets the stick's top folder. An
  /// exception from `write` reaches the future (after the stick is read-only again). Any thread.
  std::future<StickWriteOutcome> write_to_stick(std::function<void(const std::string& top)> write);
  /// A stick (or a folder standing in for one) is in the kiosk now, as the watcher last saw it. Any thread.
  bool stick_in() const { return stick_in_.load(); }
  /// Whether sticks can be mounted (CAP_SYS_ADMIN, or the mount helper); folders work regardless.
  bool can_mount() const { return mounter_ != sticks::StickMounter::None; }
  /// Who mounts sticks: this process, the helper, or nobody.
  sticks::StickMounter mounter() const { return mounter_; }
  /// Loads that have read their document and begun drawing and building it (for the operator's status and
  /// for tests that need a load to be under way).
  /// Pages built ahead are not counted.
  int loads_started() const { return loads_started_.load(); }
  /// Loads asked for whose result (a page or why not) has been posted for poll_loaded, whether or not anyone
  /// still wants it (for tests that wait for a load to end). Pages built ahead are not counted.
  int loads_done() const { return loads_done_.load(); }
  /// Pages whose building ahead has begun (for tests and the benchmark).
  int ahead_started() const { return ahead_started_.load(); }
  /// The longest side of the pictures it builds [px] (fit_picture), kScreenPictureMaxSidePx until set.
  void set_screen_picture_side_px(int px) { screen_side_px_.store(px); }
  /// Pages built ahead and kept now.
  int pages_ahead() const;
  /// Test hook: the PDF worker of every later load fails on purpose (vision::PdfFault). None in the kiosk.
  /// Pages built ahead before it are dropped (they were drawn without the fault).
  void set_pdf_fault(vision::PdfFault fault);

 private:
  struct Request {
    int stick = 0, document = 0, page = 1;
    friend bool operator==(const Request&, const Request&) = default;
  };
  /// A page built ahead and kept.
  struct AheadPage {
    Request at;
    LoadedDocument loaded;
    std::size_t bytes = 0;  ///< approx_scene_bytes
  };
  void watch();
  void serve();
  /// [kiosk] prefetch_mb [bytes] (m_ held).
  std::size_t ahead_budget_bytes() const;
  /// What the pages built ahead hold [bytes] (m_ held; approx_scene_bytes each).
  std::size_t ahead_bytes() const;
  /// The page to build ahead next, if any (m_ held): a neighbour of at_ not built, not refused, within budget.
  std::optional<Request> next_ahead() const;
  /// The pages Next and Previous lead to from at_ (m_ held; empty when at_ is not a page of the current stick).
  std::vector<Request> neighbours() const;
  /// Drops every page built ahead and makes a build ahead under way unusable (m_ held).
  void drop_ahead();
  /// Keeps or drops a page just built ahead (m_ held; `generation` the ahead_generation_ it began under).
  void keep_ahead(const Request& r, LoadedDocument d, std::uint64_t generation);
  /// A write onto the stick, waiting for the watcher.
  struct WriteJob {
    std::function<void(const std::string&)> write;
    std::promise<StickWriteOutcome> done;
  };
  /// Runs `job` on the watcher thread.
  void run_write(WriteJob& job);
  void handle_add(const std::string& devnode);
  void handle_remove(const std::string& devnode);
  void scan_root(const std::string& root, double started_ms_offset);
  void post(StickNews n);
  /// Builds page r (m_ not held); `ahead`: for the budget, not asked for yet (counted in ahead_started_).
  LoadedDocument build(const Request& r, bool ahead);

  config::Settings s_;  // guarded by m_ (set_settings); each job works on a copy
  std::unique_ptr<sticks::BlockEventSource> events_;
  std::string mount_root_;
  sticks::StickMounter mounter_ = sticks::StickMounter::None;
  std::string helper_path_;
  std::atomic<vision::PdfFault> pdf_fault_{vision::PdfFault::None};
  std::atomic<int> loads_started_{0};
  std::atomic<int> loads_done_{0};
  std::atomic<int> ahead_started_{0};
  std::atomic<int> screen_side_px_{kScreenPictureMaxSidePx};

  mutable std::mutex m_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::deque<std::optional<std::string>>
      folder_ops_;                          // guarded by m_: folders put in (a path) and taken out (nullopt), in order
  std::deque<WriteJob> writes_;             // guarded by m_: writes onto the stick asked for
  std::vector<StickNews> news_;             // guarded by m_
  std::optional<Request> request_;          // guarded by m_
  std::vector<LoadedDocument> loaded_;      // guarded by m_
  int stick_id_ = 0;                        // guarded by m_: the stick whose listing is current (0: none)
  std::string stick_root_;                  // guarded by m_
  std::vector<ListedDocument> stick_docs_;  // guarded by m_
  std::optional<Request> at_;               // guarded by m_: the page last asked for (its neighbours are built ahead)
  std::vector<AheadPage> ahead_;            // guarded by m_: pages built ahead, the next one first
  std::vector<Request> ahead_refused_;      // guarded by m_: neighbours that failed or did not fit (not tried again)
  std::optional<Request> building_;         // guarded by m_: the page being built ahead now
  std::optional<std::chrono::steady_clock::time_point> building_wanted_;  // guarded by m_: asked for meanwhile, when
  std::uint64_t ahead_generation_ = 0;  // guarded by m_: bumped when pages built so far must not be used

  std::atomic<bool> stick_in_{false};  // the watcher's: a stick mounted or a folder stick in

  // watcher thread only
  std::unique_ptr<sticks::StickMount> mounted_;
  std::optional<std::string> folder_stick_;  // the folder standing in for a stick
  int next_stick_ = 1;
  int next_slot_ = 0;

  std::thread watcher_, loader_;
};

}  // namespace hk::app
