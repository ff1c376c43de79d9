#pragma once
/// @file scene_builder.hpp
/// Scenes built off the window thread. The window thread must never wait on a decode or an edge detection
/// (a frame is 16.7 ms; a 13-megapixel PNG takes a third of a second), so every build of a library picture,
/// a capture rebuilt on Apply, and a picture built ahead of the visitor runs here, on one worker thread, and
/// the window thread polls for what has finished.
///
/// Two kinds of job, in this order:
/// - the **wanted** scene, the one the visitor asked for: one slot; a newer want replaces one still waiting
///   (Next pressed three times quickly builds the first, which had started, and the third, never the second);
///   a running build is never abandoned half-way (it takes at most a few hundred ms, and its scene may be
///   kept as built ahead);
/// - scenes **built ahead** (prefetch): the next and previous pictures, run only when no want waits, at most
///   kMaxAhead waiting (the oldest is dropped).
/// A job asked for again while it waits or runs is not queued twice: a want for a scene being built ahead
/// takes that build over.
///
/// Threads: construct, call and destroy on one thread (the window thread); the worker is owned here and
/// joined by the destructor (after the build it is running, if any).

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pictures/image_scene.hpp"

namespace hk::app {

/// A build: returns the scene, or throws (vision::InputError and the like) with a one-line reason.
using SceneJob = std::function<ImageScene()>;

/// A build that has ended.
struct BuiltScene {
  int id = 0;                       ///< the id it was asked for with (a library index, a capture's scene id, ...)
  std::uint64_t generation = 0;     ///< the generation it was asked for with (the settings it was built with)
  bool wanted = false;              ///< the visitor asked for it (else it was built ahead and nobody asked yet)
  std::optional<ImageScene> scene;  ///< the scene; empty when the build failed
  std::string error;                ///< why it failed (the exception's one line); empty on success
  double queued_ms = 0;             ///< from being asked for to the start of the build [ms]
  double build_ms = 0;              ///< the build itself [ms]
};

/// One worker thread building scenes (see the file comment).
class SceneBuilder {
 public:
  /// Scenes built ahead that may wait at once; an older one is dropped for a newer.
  static constexpr std::size_t kMaxAhead = 2;

  SceneBuilder();
  ~SceneBuilder();
  SceneBuilder(const SceneBuilder&) = delete;
  SceneBuilder& operator=(const SceneBuilder&) = delete;

  /// The visitor asks for scene `id` (of settings `generation`), built by `job` (must not be empty): it
  /// replaces a want still waiting; if the same id and generation is being built or waits as built ahead,
  /// that build becomes the want and `job` is not run.
  /// @throws hk::ArgumentError for an empty job.
  void want(int id, std::uint64_t generation, SceneJob job);
  /// Builds scene `id` ahead of the visitor, after every want; nothing when the same id and generation
  /// already waits, runs, or is the want. @throws hk::ArgumentError for an empty job.
  void ahead(int id, std::uint64_t generation, SceneJob job);
  /// Drops the scenes waiting to be built ahead (a running one finishes; poll returns it).
  void drop_ahead();
  /// The builds that have ended since the last poll, in the order they ended.
  std::vector<BuiltScene> poll();
  /// Whether scene `id` of `generation` waits or runs (wanted or ahead).
  bool has(int id, std::uint64_t generation) const;
  /// Whether a want waits, runs, or has ended and not yet been polled.
  bool want_pending() const;
  /// Blocks until the want has ended (tests and scripted runs; never the kiosk's frame loop), at most
  /// `timeout_s` [s]. Returns whether it has ended (poll() then returns it).
  bool wait_want(double timeout_s);
  /// Builds started since construction (wanted and ahead): what the visitor's keys cost.
  std::uint64_t builds_started() const;

 private:
  struct Job {
    int id = 0;
    std::uint64_t generation = 0;
    SceneJob job;
    std::chrono::steady_clock::time_point asked;
  };
  void run();
  bool matches_running(int id, std::uint64_t generation) const;  // m_ held

  mutable std::mutex m_;
  std::condition_variable cv_;
  std::condition_variable done_cv_;
  std::optional<Job> want_;        // guarded by m_: the visitor's, waiting
  std::deque<Job> ahead_;          // guarded by m_: built ahead, waiting
  bool running_ = false;           // guarded by m_
  int running_id_ = 0;             // guarded by m_
  std::uint64_t running_gen_ = 0;  // guarded by m_
  bool running_wanted_ = false;    // guarded by m_: the running build is (or became) the want
  std::vector<BuiltScene> done_;   // guarded by m_
  std::uint64_t started_ = 0;      // guarded by m_
  bool stop_ = false;              // guarded by m_
  std::thread worker_;             // last: started when the rest is ready
};

}  // namespace hk::app
