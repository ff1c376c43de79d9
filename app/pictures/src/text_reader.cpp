// The page's text read on a worker thread (see text_reader.hpp).
#include "pictures/text_reader.hpp"

#include <chrono>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "hk/error.hpp"

namespace hk::app {

TextReader::TextReader() : worker_([this] { run(); }) {}

TextReader::~TextReader() {
  {
    std::lock_guard<std::mutex> lock(m_);
    stop_ = true;
    waiting_.reset();
    if (running_) running_->store(true);
  }
  cv_.notify_all();
  worker_.join();
}

void TextReader::start(int id, TextBuild build) {
  if (!build) throw hk::ArgumentError("TextReader::start: no text build given");
  {
    std::lock_guard<std::mutex> lock(m_);
    if (running_) running_->store(true);
    done_.reset();
    blocks_.clear();
    blocks_id_ = id;
    waiting_ = Job{id, std::move(build), std::make_shared<std::atomic<bool>>(false)};
  }
  pending_ = true;
  pending_id_ = id;
  cv_.notify_all();
}

void TextReader::cancel() {
  {
    std::lock_guard<std::mutex> lock(m_);
    waiting_.reset();
    if (running_) running_->store(true);
    done_.reset();
    blocks_.clear();
  }
  pending_ = false;
}

std::vector<TextReader::Block> TextReader::blocks_so_far() const {
  if (!pending_) return {};
  std::lock_guard<std::mutex> lock(m_);
  return blocks_id_ == pending_id_ ? blocks_ : std::vector<Block>{};
}

std::optional<TextRead> TextReader::poll() {
  if (!pending_) return std::nullopt;
  std::lock_guard<std::mutex> lock(m_);
  if (!done_ || done_->id != pending_id_) return std::nullopt;
  std::optional<TextRead> out = std::move(done_);
  done_.reset();
  blocks_.clear();
  pending_ = false;
  return out;
}

void TextReader::run() {
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(m_);
      cv_.wait(lock, [this] { return stop_ || waiting_.has_value(); });
      if (stop_) return;
      job = std::move(*waiting_);
      waiting_.reset();
      running_ = job.cancel;
    }
    const auto t0 = std::chrono::steady_clock::now();
    TextRead read{job.id, {}, 0.0};
    TextRun run;
    run.cancel = job.cancel.get();
    run.on_block = [this, &job](const std::string& text, const std::string& language) {
      std::lock_guard<std::mutex> lock(m_);
      if (!job.cancel->load() && blocks_id_ == job.id) blocks_.push_back({text, language});
    };
    try {
      read.scene = job.build(run);
    } catch (const std::exception& e) {  // the page stays as it is felt; only its text is lost
      spdlog::warn("reading the text of scene {}: {}", job.id, e.what());
      read.scene = ImageScene{};
      read.scene.ocr.why = std::string("failed: ") + e.what();
    }
    read.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::lock_guard<std::mutex> lock(m_);
    running_.reset();
    if (!job.cancel->load()) done_ = std::move(read);
  }
}

}  // namespace hk::app
