#pragma once
/// @file text_reader.hpp
/// Reading a shown page's text off the window thread. A page or a picture of one is felt at once (built with
/// TextTiming::later: its curves, the letters of printed lines kept out); its text is read here, on one worker
/// thread, by the scene's own ImageScene::with_text (OCR in its worker process, then the scene built again
/// with the words masked and the blocks kept). The window thread polls for the finished scene and swaps it in.
///
/// One page at a time: a newer page's reading replaces a waiting one and cancels a running one (its OCR
/// worker is killed within 50 ms), so the visitor never waits on a page they have left.
///
/// Threads: construct, call and destroy on one thread (the window thread); the worker is owned here and
/// joined by the destructor.

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pictures/image_scene.hpp"

namespace hk::app {

/// A reading that has ended.
struct TextRead {
  int id = 0;  ///< the scene id it was started for (Stage::shown_id)
  /// The scene with its text (OcrReport says how the reading went); without a built scene (scene.scene null,
  /// ocr.why "failed: ...") when building it failed: the page stays as it is felt.
  ImageScene scene;
  double wall_ms = 0;  ///< from start() to the end [ms]
};

/// One worker thread reading the text of the page shown.
class TextReader {
 public:
  TextReader();
  ~TextReader();
  TextReader(const TextReader&) = delete;
  TextReader& operator=(const TextReader&) = delete;

  /// Reads the text of scene `id` with `build` (ImageScene::with_text; must not be empty). A reading waiting
  /// is dropped; one running is cancelled and its result never comes back from poll().
  void start(int id, TextBuild build);
  /// Drops the waiting reading and cancels the running one (a page without text to read was shown).
  void cancel();
  /// The reading of the latest start() once it has ended; nothing while it runs, after cancel(), or twice.
  std::optional<TextRead> poll();
  /// A block of text read so far: its text and language (BCP 47, "" unknown).
  struct Block {
    std::string text, language;
    bool operator==(const Block&) const = default;
  };
  /// The blocks the running reading of the latest start() has read so far (TextRun::on_block), in reading order:
  /// a page's first words to say while the rest is read. Empty once it is polled or cancelled.
  std::vector<Block> blocks_so_far() const;
  /// Whether a reading was started and not yet polled or cancelled.
  bool pending() const { return pending_; }
  /// Its scene id (meaningful while pending()).
  int pending_id() const { return pending_id_; }

 private:
  struct Job {
    int id = 0;
    TextBuild build;
    std::shared_ptr<std::atomic<bool>> cancel;
  };
  void run();

  mutable std::mutex m_;
  std::condition_variable cv_;
  std::optional<Job> waiting_;                  // guarded by m_
  std::shared_ptr<std::atomic<bool>> running_;  // guarded by m_: the running job's cancel flag
  std::optional<TextRead> done_;                // guarded by m_
  std::vector<Block> blocks_;                   // guarded by m_: blocks_so_far of the latest job
  int blocks_id_ = 0;                           // guarded by m_: the job they are of
  bool stop_ = false;                           // guarded by m_
  bool pending_ = false;                        // window thread only
  int pending_id_ = 0;                          // window thread only
  std::thread worker_;                          // last: started when the rest is ready
};

}  // namespace hk::app
