// A page of text is felt at once and its text read meanwhile: a scan built with TextTiming::later is a scene
// at once, its printed lines already kept out of the curves (at most 5 curves inside the text blocks OCR finds
// later, against the dozens of word outlines felt with OCR off), and its with_text gives the blocks (recall
// >= 0.9); a raised cancel flag leaves the page as it is felt. The TextReader keeps only the newest page's
// reading (an older one is cancelled and never delivered), and the kiosk runtime says "Reading the text." when
// it takes longer than a second, swaps the page with its blocks in, and says "The text is ready. ...";
// another picture shown meanwhile cancels it and nothing is said of it.
#include <gtest/gtest.h>

#include <sys/types.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "kiosk_exe.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/text_reader.hpp"
#include "scans.hpp"
#include "show_now.hpp"
#include "test_paths.hpp"
#include "vision/ocr.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"

namespace fs = std::filesystem;

namespace hk::app {
namespace {

const fs::path kData = HK_TEST_DATA_DIR;
const fs::path kSpec = kData / "documents" / "shared-mime-info-spec.pdf";

bool have_ocr() { return vision::ocr_languages_problem(vision::OcrParams{}).empty(); }

std::string all_text(const ImageScene& is) {
  std::string t;
  for (const TextBlockM& b : is.text_blocks) t += b.text + "\n";
  return t;
}

/// Curves of `polylines` whose bounding box's centre lies in one of `blocks`.
int curves_in(const std::vector<Polyline>& polylines, const std::vector<TextBlockM>& blocks) {
  int n = 0;
  for (const Polyline& p : polylines) {
    Vec2 lo = p.points_m[0], hi = p.points_m[0];
    for (Vec2 q : p.points_m) {
      lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
      hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
    }
    const Vec2 c = 0.5 * (lo + hi);
    n += std::any_of(blocks.begin(), blocks.end(), [&](const TextBlockM& b) { return b.contains(c); });
  }
  return n;
}

struct ScanRig {
  fs::path dir = test::fresh_dir("text_reading");
  std::vector<std::uint8_t> jpeg;
  std::vector<std::string> truth;
  ScanRig() {
    jpeg = test::scan_jpeg(kSpec, 3, 150, 1.5, dir);
    truth = test::words_of(test::pdftotext_page(kSpec, 3, dir));
  }
  ~ScanRig() { fs::remove_all(dir); }
};

TEST(TextLater, AScanIsFeltAtOnceWithoutItsLettersAndItsTextComesFromWithText) {
  if (!test::have_poppler_utils())
    GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  if (!have_ocr()) GTEST_SKIP() << "Tesseract's eng traineddata is not installed (scripts/install-deps.sh installs it)";
  ScanRig r;
  ASSERT_FALSE(r.jpeg.empty());
  const config::Settings s;  // shipped: ocr "auto"
  ASSERT_EQ(s.vision.ocr, "auto");
  ImageScene quick = build_image_scene_from_bytes(r.jpeg, "scan.jpg", s, TextTiming::later);
  EXPECT_TRUE(quick.text_pending);
  ASSERT_TRUE(static_cast<bool>(quick.with_text));
  EXPECT_FALSE(quick.ocr.ran);
  EXPECT_EQ(quick.ocr.why, "a page of text");
  EXPECT_TRUE(quick.text_blocks.empty());
  ASSERT_TRUE(quick.scene);

  const ImageScene read = quick.with_text(TextRun{});
  EXPECT_FALSE(read.text_pending);
  EXPECT_TRUE(read.ocr.ran) << read.ocr.why;
  ASSERT_GE(read.text_blocks.size(), 3u);
  EXPECT_GE(test::word_recall(r.truth, test::words_of(all_text(read))), 0.9);
  EXPECT_EQ(read.width_px, quick.width_px);
  EXPECT_EQ(read.height_px, quick.height_px);

  // What the hand feels before the text comes: the letters of printed lines kept out already.
  config::Settings off = s;
  off.vision.ocr = "off";
  const ImageScene felt = build_image_scene_from_bytes(r.jpeg, "scan.jpg", off);
  const int bumps_off = curves_in(felt.polylines, read.text_blocks);
  const int bumps_quick = curves_in(quick.polylines, read.text_blocks);
  EXPECT_GT(bumps_off, 10) << "with OCR off the words are felt as outlines";
  EXPECT_LE(bumps_quick, 5) << "of " << quick.polylines.size() << " curves (" << bumps_off << " with OCR off)";
}

TEST(TextLater, ACancelledReadingGivesThePageWithoutItsText) {
  if (!test::have_poppler_utils())
    GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  if (!have_ocr()) GTEST_SKIP() << "Tesseract's eng traineddata is not installed (scripts/install-deps.sh installs it)";
  ScanRig r;
  ImageScene quick = build_image_scene_from_bytes(r.jpeg, "scan.jpg", config::Settings{}, TextTiming::later);
  ASSERT_TRUE(static_cast<bool>(quick.with_text));
  const std::atomic<bool> cancelled{true};
  const ImageScene read = quick.with_text(TextRun{&cancelled, {}});
  EXPECT_FALSE(read.ocr.ran);
  EXPECT_EQ(read.ocr.why, "cancelled");
  EXPECT_TRUE(read.text_blocks.empty());
  ASSERT_TRUE(read.scene);
  EXPECT_GT(read.polylines.size(), 0u);
}

TEST(TextLater, PicturesThatAreNotPagesAreCompleteAtOnce) {
  const config::Settings s;
  for (const char* name : {"horse.png", "butterfly.jpg"}) {
    const ImageScene is = build_image_scene((kData / "images" / name).string(), s, TextTiming::later);
    EXPECT_FALSE(is.text_pending) << name;
    EXPECT_FALSE(static_cast<bool>(is.with_text)) << name;
    EXPECT_EQ(is.ocr.why, "not a page of text") << name;
  }
}

TEST(OcrCancel, ARaisedFlagKillsTheWorkerAndSaysCancelled) {
  if (!have_ocr()) GTEST_SKIP() << "Tesseract's eng traineddata is not installed (scripts/install-deps.sh installs it)";
  const cv::Mat grey(200, 300, CV_8UC1, cv::Scalar(255));
  vision::OcrParams p;
  p.fault = vision::OcrFault::Hang;  // would run into the 30 s wall-clock limit
  std::atomic<bool> cancel{false};
  p.cancel = &cancel;
  std::thread raiser([&] { cancel.store(true); });
  try {
    (void)vision::recognise_text(grey, "hanging.png", p);
    ADD_FAILURE() << "a cancelled reading returned";
  } catch (const vision::OcrError& e) {
    EXPECT_EQ(e.kind(), vision::OcrError::Kind::Cancelled) << e.what();
    EXPECT_EQ(std::string(e.what()), "ocr 'hanging.png': reading the text was cancelled");
  }
  raiser.join();
}

/// A TextBuild that raises `started`, waits until it is cancelled or `release` is raised, then gives a scene
/// named `name`.
TextBuild waiting_build(const std::string& name, std::atomic<bool>& release, std::atomic<bool>& saw_cancel,
                        std::atomic<bool>* started = nullptr) {
  return [name, &release, &saw_cancel, started](const TextRun& run) {
    const std::atomic<bool>* cancel = run.cancel;
    if (started) started->store(true);
    while (!release.load() && !(cancel && cancel->load())) std::this_thread::yield();
    if (cancel && cancel->load()) saw_cancel.store(true);
    ImageScene is;
    is.image_path = name;
    return is;
  };
}

std::optional<TextRead> wait_for(TextReader& reader) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    if (std::optional<TextRead> r = reader.poll()) return r;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return std::nullopt;
}

TEST(TextReader, ANewerPageCancelsTheOlderAndOnlyTheNewestIsDelivered) {
  TextReader reader;
  EXPECT_FALSE(reader.pending());
  std::atomic<bool> release1{false}, cancel1{false}, release2{true}, cancel2{false};
  reader.start(1, waiting_build("first", release1, cancel1));
  EXPECT_TRUE(reader.pending());
  EXPECT_EQ(reader.pending_id(), 1);
  reader.start(2, waiting_build("second", release2, cancel2));
  EXPECT_EQ(reader.pending_id(), 2);
  const std::optional<TextRead> r = wait_for(reader);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->id, 2);
  EXPECT_EQ(r->scene.image_path, "second");
  EXPECT_FALSE(reader.pending());
  EXPECT_FALSE(reader.poll()) << "delivered once";
  EXPECT_FALSE(cancel2.load());
}

TEST(TextReader, CancelStopsTheRunningReadingAndNothingComes) {
  std::atomic<bool> release{false}, saw_cancel{false}, started{false};
  {
    TextReader reader;
    reader.start(7, waiting_build("page", release, saw_cancel, &started));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!started.load() && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
    ASSERT_TRUE(started.load());
    reader.cancel();
    EXPECT_FALSE(reader.pending());
    EXPECT_FALSE(reader.poll());
  }  // the destructor joins the worker: only the cancel can have ended the build
  EXPECT_TRUE(saw_cancel.load());
}

TEST(TextReader, EachBlockReadIsThereToSayWhileTheRestIsRead) {
  TextReader reader;
  std::atomic<bool> release{false}, told{false};
  reader.start(4, [&](const TextRun& run) {
    run.on_block("Opening hours.", "en");
    run.on_block("Nine to five.", "en");
    told.store(true);
    while (!release.load() && !run.cancel->load()) std::this_thread::yield();
    return ImageScene{};
  });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!told.load() && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
  ASSERT_TRUE(told.load());
  EXPECT_EQ(reader.blocks_so_far(), (std::vector<TextReader::Block>{{"Opening hours.", "en"}, {"Nine to five.", "en"}}))
      << "both blocks, in reading order, before the reading has ended";
  EXPECT_FALSE(reader.poll());
  release.store(true);
  ASSERT_TRUE(wait_for(reader));
  EXPECT_TRUE(reader.blocks_so_far().empty()) << "the whole text has come: no blocks of it any more";
  // A newer page's reading starts with none of the older one's blocks.
  std::atomic<bool> release2{false}, saw_cancel{false};
  reader.start(5, waiting_build("next", release2, saw_cancel));
  EXPECT_TRUE(reader.blocks_so_far().empty());
  reader.cancel();
}

TEST(TextReader, AFailingBuildIsReportedAsAFailureNotLost) {
  TextReader reader;
  reader.start(3, [](const TextRun&) -> ImageScene { throw std::runtime_error("picture 'x': broken"); });
  const std::optional<TextRead> r = wait_for(reader);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->id, 3);
  EXPECT_FALSE(r->scene.scene);
  EXPECT_EQ(r->scene.ocr.why, "failed: picture 'x': broken");
}

/// A kiosk runtime (no servo thread, no sound device) whose library holds one scan of a page and a horse.
struct KioskRig {
  ScanRig scan;
  fs::path lib = scan.dir / "library";
  std::unique_ptr<KioskRuntime> rt;
  KioskRig() {
    fs::create_directories(lib);
    std::ofstream(lib / "a_scan.jpg", std::ios::binary)
        .write(reinterpret_cast<const char*>(scan.jpeg.data()), static_cast<std::streamsize>(scan.jpeg.size()));
    fs::copy_file(kData / "images" / "horse.png", lib / "b_horse.png");
    RuntimeOptions ro;
    ro.library = lib.string();
    ro.hotplug = false;
    ro.open_audio_output = false;
    ro.probe_usb_device = false;
    rt = std::make_unique<KioskRuntime>(ro, config::Settings{});
  }
  /// Frames of 0.1 s until the text is read and its news said (at most 60 s of wall time); the texts said.
  std::vector<std::string> frames_until_read(double& now_s) {
    std::vector<std::string> said;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (rt->stage().text_busy() && std::chrono::steady_clock::now() < deadline) {
      const std::string before = rt->voice().last_said();
      rt->stage().poll_text(now_s);
      if (rt->voice().last_said() != before) said.push_back(rt->voice().last_said());
      now_s += 0.1;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return said;
  }
};

TEST(KioskText, APageIsFeltAtOnceThenItsTextComesWithoutLeavingThePage) {
  if (!test::have_poppler_utils())
    GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  if (!have_ocr()) GTEST_SKIP() << "Tesseract's eng traineddata is not installed (scripts/install-deps.sh installs it)";
  KioskRig k;
  const int scan = k.rt->library().find((k.lib / "a_scan.jpg").string());
  ASSERT_GE(scan, 0);
  ASSERT_GE(test::show_now(*k.rt, scan), 0);
  const int id = k.rt->stage().shown_id();
  EXPECT_TRUE(k.rt->stage().text_busy());
  EXPECT_TRUE(k.rt->stage().shown().text_blocks.empty()) << "not read yet";
  ASSERT_NE(k.rt->stage().shown().scene, nullptr) << "felt at once";
  EXPECT_EQ(k.rt->stage().describe().rfind("Reading the text. ", 0), 0u) << k.rt->stage().describe();
  double now_s = 0.0;
  const std::vector<std::string> said = k.frames_until_read(now_s);
  ASSERT_FALSE(k.rt->stage().text_busy()) << "no text within 60 s";
  ASSERT_EQ(said.size(), 2u) << (said.empty() ? "" : said.front());
  EXPECT_EQ(said[0], "Reading the text.");
  EXPECT_EQ(said[1].rfind("The text is ready. It has ", 0), 0u) << said[1];
  EXPECT_EQ(k.rt->stage().shown_id(), id) << "the same page";
  EXPECT_GE(k.rt->stage().shown().text_blocks.size(), 3u);
  for (const TextBlockM& b : k.rt->stage().shown().text_blocks) EXPECT_EQ(b.source, "ocr");
  const std::string d =
      k.rt->stage().describe();  // a block's text where the proxy rests on one, else the page's blocks
  EXPECT_TRUE(d.rfind("Text: ", 0) == 0 || d.find("blocks of text") != std::string::npos) << d;
}

TEST(KioskText, AnotherPictureCancelsTheReadingAndNothingIsSaidOfIt) {
  if (!test::have_poppler_utils())
    GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  if (!have_ocr()) GTEST_SKIP() << "Tesseract's eng traineddata is not installed (scripts/install-deps.sh installs it)";
  KioskRig k;
  ASSERT_GE(test::show_now(*k.rt, k.rt->library().find((k.lib / "a_scan.jpg").string())), 0);
  ASSERT_TRUE(k.rt->stage().text_busy());
  ASSERT_GE(test::show_now(*k.rt, k.rt->library().find((k.lib / "b_horse.png").string())), 0);
  EXPECT_FALSE(k.rt->stage().text_busy()) << "the horse has no text to read";
  double now_s = 0.0;
  for (int frame = 0; frame < 30; ++frame, now_s += 0.1) k.rt->stage().poll_text(now_s);
  EXPECT_EQ(k.rt->voice().last_said(), "") << "nothing said of the page left";
  EXPECT_TRUE(k.rt->stage().shown().text_blocks.empty());
}

TEST(KioskText, AScanOnAStickIsAnnouncedAsBeingReadThenItsTextIsReady) {
  if (!test::have_poppler_utils())
    GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  if (!have_ocr()) GTEST_SKIP() << "Tesseract's eng traineddata is not installed (scripts/install-deps.sh installs it)";
  KioskRig k;
  const fs::path stick = k.scan.dir / "stick";
  fs::create_directories(stick);
  std::ofstream(stick / "letter.jpg", std::ios::binary)
      .write(reinterpret_cast<const char*>(k.scan.jpeg.data()), static_cast<std::streamsize>(k.scan.jpeg.size()));
  KioskFlowParams fp;
  KioskFlow flow(k.rt->effects(), k.rt->audio().messages(), fp);
  double now_s = 0.0;
  flow.key(KioskKey::Other, now_s);  // a visitor is there
  k.rt->sticks().insert_folder(stick.string());
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  std::string announced;
  while (std::chrono::steady_clock::now() < deadline && announced.empty()) {
    k.rt->sticks().poll(flow, now_s);
    if (k.rt->voice().last_said().find("Document 1 of 1, letter") != std::string::npos && !k.rt->sticks().busy())
      announced = k.rt->voice().last_said();
    now_s += 0.1;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_FALSE(announced.empty()) << "the stick's picture was not shown within 60 s; last said: "
                                  << k.rt->voice().last_said();
  EXPECT_NE(announced.find("letter. Reading the text."), std::string::npos) << announced;
  EXPECT_TRUE(k.rt->stage().text_busy());
  const std::vector<std::string> said = k.frames_until_read(now_s);
  ASSERT_EQ(said.size(), 1u) << "'Reading the text.' is not said twice";
  EXPECT_EQ(said[0].rfind("The text is ready. It has ", 0), 0u) << said[0];
  EXPECT_GE(k.rt->stage().shown().text_blocks.size(), 3u);
}

}  // namespace
}  // namespace hk::app
