#pragma once
/// @file frame_stats.hpp
/// The window's frame times (`haptic-kiosk --frame-stats FILE`): how long each frame of the window loop
/// took, summed up as percentiles, so "the window never stalls" can be measured (target: p99 ≤ 20 ms while
/// pictures change). Two times per frame, both on the steady clock:
///   interval — from one frame's start to the next frame's start: everything the window thread did,
///              including the buffer swap and, in scripted runs (--screenshot), the fixed 16.7 ms pause
///              that gives each frame 1/60 s of kiosk time;
///   work     — from the frame's start to just before the swap: input, the visitor's flow, drawing.
/// Each is kept for all frames and, separately, for the frames during which a picture was changing: from
/// the frame in which a Next or Previous key was handled up to and including the frame in which a
/// different scene was first drawn (or kMaxChangeS later if none was).
///
/// Frame times go into fixed-size histograms (kBinMs wide bins up to kRangeMs, one bin above): recording
/// never allocates, however long the kiosk runs. A percentile is the nearest-rank percentile of the
/// recorded times to the bin: the upper edge of the bin holding it (never more than the largest time
/// recorded), so it errs by at most kBinMs and never low. The largest time and the count of frames over
/// kSlowFrameMs are exact.

#include <array>
#include <chrono>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace hk::app {

/// A frame longer than this is a slow frame (the target: p99 within it) [ms].
inline constexpr double kSlowFrameMs = 20.0;

/// A histogram summed up.
struct FrameTimeSummary {
  std::int64_t frames = 0;      ///< frames recorded
  double p50_ms = 0;            ///< median [ms] (0 when no frames)
  double p95_ms = 0;            ///< 95th percentile [ms]
  double p99_ms = 0;            ///< 99th percentile [ms]
  double max_ms = 0;            ///< longest [ms], exact
  double mean_ms = 0;           ///< mean [ms], exact
  std::int64_t over_20_ms = 0;  ///< frames longer than kSlowFrameMs, exact
};

/// Frame times in fixed bins: add() never allocates.
class FrameTimeHistogram {
 public:
  static constexpr double kBinMs = 0.1;       ///< bin width [ms]
  static constexpr double kRangeMs = 1000.0;  ///< times from here up share the last bin (max_ms stays exact)
  static constexpr int kBins = static_cast<int>(kRangeMs / kBinMs) + 1;

  /// Records one frame time [ms]; negative times count as 0.
  void add_ms(double ms);
  /// Nearest-rank percentile, `p` in (0, 100]: the upper edge of the bin holding the ⌈p/100 · n⌉-th
  /// shortest time, at most max_ms() [ms]; 0 when empty.
  double percentile_ms(double p) const;
  std::int64_t frames() const { return n_; }
  double max_ms() const { return max_ms_; }
  FrameTimeSummary summary() const;

 private:
  std::array<std::uint32_t, kBins> bins_{};
  std::int64_t n_ = 0;
  std::int64_t over_ = 0;
  double max_ms_ = 0;
  double sum_ms_ = 0;
};

/// The window loop's frame times: interval and work (see the file comment), for all frames and for the
/// frames during which a picture was changing, and how long each change took to show. Window thread only.
class FrameStats {
 public:
  using Clock = std::chrono::steady_clock;
  /// A change not shown this long after its key ends its "changing" frames anyway [s].
  static constexpr double kMaxChangeS = 5.0;

  /// A frame starts at `t`: the previous frame's interval (from its start to `t`) is recorded.
  void frame_started(Clock::time_point t);
  /// A Next or Previous key was handled in this frame; `scene_at_start` identifies what was shown when
  /// the frame started (any value that changes when the shown scene does).
  void picture_key(const void* scene_at_start, int id_at_start);
  /// The frame is drawn, not yet swapped (`t`): its work is recorded; `scene` and `id` are what was drawn.
  void frame_drawn(Clock::time_point t, const void* scene, int id);

  const FrameTimeHistogram& interval_all() const { return interval_all_; }
  const FrameTimeHistogram& interval_changing() const { return interval_changing_; }
  const FrameTimeHistogram& work_all() const { return work_all_; }
  const FrameTimeHistogram& work_changing() const { return work_changing_; }
  /// Picture changes seen (Next / Previous keys whose scene was shown) and the longest from the key's frame
  /// start to the end of the frame that first drew the new scene [ms].
  std::int64_t changes() const { return changes_; }
  double max_change_ms() const { return max_change_ms_; }

  /// Everything as JSON: {"interval": {"all": summary, "changing": summary}, "work": {...}, "changes": n,
  /// "max_change_ms": ms, "bin_ms": kBinMs, "slow_frame_ms": kSlowFrameMs, "measured": text}.
  nlohmann::json to_json(const std::string& measured) const;
  /// One line for the log: frames and interval p50/p95/p99/max, over 20 ms, and the same while changing.
  std::string log_line() const;

 private:
  FrameTimeHistogram interval_all_, interval_changing_, work_all_, work_changing_;
  bool started_ = false;
  Clock::time_point start_{};
  bool this_changing_ = false;  // the frame under way (until the next starts: its interval) is a change's
  bool pending_ = false;        // a change's new scene is not drawn yet
  const void* pending_scene_ = nullptr;
  int pending_id_ = 0;
  Clock::time_point pending_since_{};
  std::int64_t changes_ = 0;
  double max_change_ms_ = 0;
};

/// Writes `stats.to_json(measured)` to `path` (indented). @throws AppError (one line) when it cannot.
void write_frame_stats(const FrameStats& stats, const std::string& path, const std::string& measured);

}  // namespace hk::app
