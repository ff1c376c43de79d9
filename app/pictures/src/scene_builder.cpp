// Scenes built on a worker thread (see scene_builder.hpp).
#include "pictures/scene_builder.hpp"

#include <spdlog/spdlog.h>

#include "hk/error.hpp"

namespace hk::app {
namespace {

double ms_between(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

}  // namespace

SceneBuilder::SceneBuilder() : worker_([this] { run(); }) {}

SceneBuilder::~SceneBuilder() {
  {
    std::lock_guard<std::mutex> lock(m_);
    stop_ = true;
    want_.reset();
    ahead_.clear();
  }
  cv_.notify_all();
  worker_.join();
}

bool SceneBuilder::matches_running(int id, std::uint64_t generation) const {
  return running_ && running_id_ == id && running_gen_ == generation;
}

void SceneBuilder::want(int id, std::uint64_t generation, SceneJob job) {
  if (!job) throw hk::ArgumentError("SceneBuilder::want: no build given");
  {
    std::lock_guard<std::mutex> lock(m_);
    want_.reset();
    // The want is the latest ask: an older want that already ran and waits to be polled is no longer one.
    for (BuiltScene& b : done_) b.wanted = b.wanted && b.id == id && b.generation == generation;
    if (running_) running_wanted_ = matches_running(id, generation);
    if (!matches_running(id, generation)) {
      bool taken = false;
      for (auto it = ahead_.begin(); it != ahead_.end(); ++it) {
        if (it->id == id && it->generation == generation) {
          want_ = std::move(*it);  // the build ahead becomes the want, asked for when it was
          ahead_.erase(it);
          taken = true;
          break;
        }
      }
      if (!taken) want_ = Job{id, generation, std::move(job), std::chrono::steady_clock::now()};
    }
  }
  cv_.notify_all();
}

void SceneBuilder::ahead(int id, std::uint64_t generation, SceneJob job) {
  if (!job) throw hk::ArgumentError("SceneBuilder::ahead: no build given");
  {
    std::lock_guard<std::mutex> lock(m_);
    if (matches_running(id, generation) || (want_ && want_->id == id && want_->generation == generation)) return;
    for (const Job& j : ahead_)
      if (j.id == id && j.generation == generation) return;
    if (ahead_.size() >= kMaxAhead) ahead_.pop_front();
    ahead_.push_back(Job{id, generation, std::move(job), std::chrono::steady_clock::now()});
  }
  cv_.notify_all();
}

void SceneBuilder::drop_ahead() {
  std::lock_guard<std::mutex> lock(m_);
  ahead_.clear();
}

std::vector<BuiltScene> SceneBuilder::poll() {
  std::lock_guard<std::mutex> lock(m_);
  std::vector<BuiltScene> out = std::move(done_);
  done_.clear();
  return out;
}

bool SceneBuilder::has(int id, std::uint64_t generation) const {
  std::lock_guard<std::mutex> lock(m_);
  if (matches_running(id, generation) || (want_ && want_->id == id && want_->generation == generation)) return true;
  for (const Job& j : ahead_)
    if (j.id == id && j.generation == generation) return true;
  return false;
}

bool SceneBuilder::want_pending() const {
  std::lock_guard<std::mutex> lock(m_);
  if (want_ || (running_ && running_wanted_)) return true;
  for (const BuiltScene& b : done_)
    if (b.wanted) return true;
  return false;
}

bool SceneBuilder::wait_want(double timeout_s) {
  std::unique_lock<std::mutex> lock(m_);
  return done_cv_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                           [this] { return !want_ && !(running_ && running_wanted_); });
}

std::uint64_t SceneBuilder::builds_started() const {
  std::lock_guard<std::mutex> lock(m_);
  return started_;
}

void SceneBuilder::run() {
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(m_);
      cv_.wait(lock, [this] { return stop_ || want_ || !ahead_.empty(); });
      if (stop_) return;
      running_wanted_ = want_.has_value();
      if (want_) {
        job = std::move(*want_);
        want_.reset();
      } else {
        job = std::move(ahead_.front());
        ahead_.pop_front();
      }
      running_ = true;
      running_id_ = job.id;
      running_gen_ = job.generation;
      ++started_;
    }
    const auto t0 = std::chrono::steady_clock::now();
    BuiltScene b;
    b.id = job.id;
    b.generation = job.generation;
    b.queued_ms = ms_between(job.asked, t0);
    try {
      b.scene = job.job();
    } catch (const std::exception& e) {  // the picture felt before stays; the reason is said
      spdlog::warn("building scene {}: {}", job.id, e.what());
      b.scene.reset();
      b.error = e.what();
    }
    b.build_ms = ms_between(t0, std::chrono::steady_clock::now());
    {
      std::lock_guard<std::mutex> lock(m_);
      b.wanted = running_wanted_;
      running_ = false;
      running_wanted_ = false;
      done_.push_back(std::move(b));
    }
    done_cv_.notify_all();
  }
}

}  // namespace hk::app
