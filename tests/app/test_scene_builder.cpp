// Scenes built off the window thread: the builder's order (the visitor's want first, a newer want replacing a
// waiting one, a build ahead taken over rather than run twice), and the kiosk on top of it: Next pressed three
// times builds at most two scenes, the picture felt before stays until the new one is on the device, the next
// picture built ahead is a swap, a picture that cannot be read is said with the old one kept.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "hk/error.hpp"
#include "pictures/scene_builder.hpp"
#include "pictures/scene_cache.hpp"
#include "show_now.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"
#include "wait_until.hpp"

namespace fs = std::filesystem;

namespace hk::app {
namespace {

const fs::path kData = HK_TEST_DATA_DIR;

/// A build that waits for the test to let it finish, and says when it has started.
struct Gate {
  std::promise<void> open;
  std::shared_future<void> opened = open.get_future().share();
  std::promise<void> started;
  std::future<void> has_started = started.get_future();
  SceneJob job(int marker) {
    return [this, marker] {
      started.set_value();
      opened.wait();
      ImageScene is;
      is.page = marker;  // which build this was
      return is;
    };
  }
};

SceneJob marked(int marker, std::atomic<int>* runs) {
  return [marker, runs] {
    runs->fetch_add(1);
    ImageScene is;
    is.page = marker;
    return is;
  };
}

TEST(SceneBuilder, ANewerWantReplacesAWaitingOneAndTheRunningOneFinishes) {
  SceneBuilder b;
  Gate first;
  std::atomic<int> runs{0};
  b.want(1, 1, first.job(1));
  first.has_started.wait();        // 1 runs
  b.want(2, 1, marked(2, &runs));  // waits...
  b.want(3, 1, marked(3, &runs));  // ...and is replaced
  first.open.set_value();
  ASSERT_TRUE(b.wait_want(60.0));
  std::vector<BuiltScene> done = b.poll();
  ASSERT_EQ(done.size(), 2u);
  EXPECT_EQ(done[0].id, 1);
  EXPECT_FALSE(done[0].wanted) << "superseded while it ran";
  EXPECT_EQ(done[1].id, 3);
  EXPECT_TRUE(done[1].wanted);
  EXPECT_EQ(done[1].scene->page, 3);
  EXPECT_EQ(runs.load(), 1) << "2 was never built";
  EXPECT_EQ(b.builds_started(), 2u);
}

TEST(SceneBuilder, AWantForASceneBeingBuiltAheadTakesThatBuildOver) {
  SceneBuilder b;
  Gate ahead;
  std::atomic<int> runs{0};
  b.ahead(5, 1, ahead.job(5));
  ahead.has_started.wait();
  b.want(5, 1, marked(55, &runs));  // the same scene: not built again
  EXPECT_TRUE(b.want_pending());
  ahead.open.set_value();
  ASSERT_TRUE(b.wait_want(60.0));
  std::vector<BuiltScene> done = b.poll();
  ASSERT_EQ(done.size(), 1u);
  EXPECT_TRUE(done[0].wanted);
  EXPECT_EQ(done[0].scene->page, 5);
  EXPECT_EQ(runs.load(), 0);
  EXPECT_EQ(b.builds_started(), 1u);
}

TEST(SceneBuilder, WantsGoBeforeBuildsAheadAndAnotherGenerationIsAnotherScene) {
  SceneBuilder b;
  Gate hold;
  std::atomic<int> runs{0};
  b.ahead(9, 1, hold.job(9));  // keeps the worker busy while the queue is set up
  hold.has_started.wait();
  b.ahead(1, 1, marked(1, &runs));
  b.ahead(2, 1, marked(2, &runs));
  b.ahead(3, 1, marked(3, &runs));   // kMaxAhead waiting: the oldest (1) is dropped
  b.ahead(2, 1, marked(22, &runs));  // already waiting: not queued twice
  EXPECT_TRUE(b.has(2, 1));
  EXPECT_FALSE(b.has(2, 2)) << "another generation (other settings) is another scene";
  EXPECT_FALSE(b.has(1, 1)) << "dropped for a newer one";
  b.want(7, 1, marked(7, &runs));
  hold.open.set_value();
  ASSERT_TRUE(b.wait_want(60.0));
  std::vector<int> order;
  // The two ahead finish after the want: polled until all four came or nothing more is being built.
  EXPECT_TRUE(hk::test::wait_until([&] { return order.size() >= 4 || (!b.has(2, 1) && !b.has(3, 1)); },
                                   [&] {
                                     for (const BuiltScene& d : b.poll()) order.push_back(d.scene->page);
                                   }));
  for (const BuiltScene& d : b.poll()) order.push_back(d.scene->page);
  ASSERT_EQ(order.size(), 4u);
  EXPECT_EQ(order[0], 9);
  EXPECT_EQ(order[1], 7) << "the visitor's want before the builds ahead";
  EXPECT_EQ(order[2], 2);
  EXPECT_EQ(order[3], 3);
}

TEST(SceneBuilder, AFailedBuildComesBackWithItsReason) {
  SceneBuilder b;
  b.want(4, 1, []() -> ImageScene { throw std::runtime_error("image 'x.png': truncated"); });
  ASSERT_TRUE(b.wait_want(60.0));
  std::vector<BuiltScene> done = b.poll();
  ASSERT_EQ(done.size(), 1u);
  EXPECT_FALSE(done[0].scene);
  EXPECT_EQ(done[0].error, "image 'x.png': truncated");
}

TEST(FitPicture, AScreensWorthOfPixelsCoveringTheSameWorkspaceRectangle) {
  ImageScene is;
  is.picture = cv::Mat(2000, 4000, CV_8UC3, cv::Scalar(10, 20, 30));
  is.picture(cv::Rect(0, 0, 2000, 2000)).setTo(cv::Scalar(200, 200, 200));  // left half light
  is.px_to_m = {0.1 / 4000, -0.05, 0.025};                                  // 10 cm wide, centred
  const vision::PxToM before = is.px_to_m;
  fit_picture(is, 1920);
  EXPECT_EQ(is.picture.cols, 1920);
  EXPECT_EQ(is.picture.rows, 960);
  // The picture's outer edges (pixel corners) land where they did: x from -5 cm to 5 cm, y from 2.5 cm down.
  EXPECT_NEAR(is.px_to_m.x_m(-0.5), before.x_m(-0.5), 1e-12);
  EXPECT_NEAR(is.px_to_m.x_m(1920 - 0.5), before.x_m(4000 - 0.5), 1e-12);
  EXPECT_NEAR(is.px_to_m.y_m(-0.5), before.y_m(-0.5), 1e-12);
  EXPECT_NEAR(is.px_to_m.y_m(960 - 0.5), before.y_m(2000 - 0.5), 1e-12);
  // The light half stays where it was: the boundary between pixel 959 and 960 is the old one at 2000.
  EXPECT_NEAR(is.px_to_m.x_m(959.5), before.x_m(1999.5), 1e-12);
  EXPECT_EQ(is.picture.at<cv::Vec3b>(480, 959)[0], 200);
  EXPECT_EQ(is.picture.at<cv::Vec3b>(480, 960)[0], 10);
  const vision::PxToM fitted = is.px_to_m;
  fit_picture(is, 1920);  // small enough: untouched
  EXPECT_EQ(is.picture.cols, 1920);
  EXPECT_EQ(is.px_to_m.scale_m_per_px, fitted.scale_m_per_px);
  EXPECT_THROW(fit_picture(is, 0), hk::ArgumentError);
}

// ---- the kiosk on the builder ----

struct LibraryRig {
  fs::path lib;
  std::unique_ptr<KioskRuntime> rt;
  std::unique_ptr<KioskFlow> flow;
  std::vector<std::string> said;
  config::Settings settings;

  /// A library of `files` (names in tests/data/images, copied as 0_name, 1_name, ... to keep their order).
  LibraryRig(const std::vector<std::string>& files, int prefetch_mb, const std::string& tag,
             const std::string& cache_dir = "") {
    lib = fs::temp_directory_path() / ("hk_builder_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(lib);
    fs::create_directories(lib);
    for (std::size_t i = 0; i < files.size(); ++i)
      fs::copy_file(kData / "images" / files[i], lib / (std::to_string(i) + "_" + files[i]));
    RuntimeOptions ro;
    ro.scene_cache_dir = cache_dir;
    ro.library = lib.string();
    ro.hotplug = false;
    ro.open_audio_output = false;
    ro.probe_usb_device = false;
    config::Settings s;
    s.kiosk.prefetch_mb = prefetch_mb;
    s.vision.ocr = "off";
    settings = s;
    rt = std::make_unique<KioskRuntime>(ro, s);
    flow = std::make_unique<KioskFlow>(rt->effects(), rt->audio().messages(), KioskFlowParams{});
  }
  ~LibraryRig() {
    flow.reset();
    rt.reset();
    fs::remove_all(lib);
  }
  /// Frames until nothing asked for is pending (at most 60 s of waiting in all).
  void settle(double now_s) { ASSERT_TRUE(rt->library().finish(flow.get(), now_s)); }
  /// A folder holding the shipped spec PDF (tests/data/documents), to insert as a stick; the test removes it.
  fs::path spec_stick(const std::string& tag) const {
    const fs::path stick = lib.parent_path() / ("hk_builder_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(stick);
    fs::create_directories(stick);
    fs::copy_file(kData / "documents" / "shared-mime-info-spec.pdf", stick / "spec.pdf");
    return stick;
  }
  /// Polls the stick service every 10 ms until scene `id` is shown (or 60 s pass), advancing `now_s`.
  bool stick_shows(int id, double& now_s) {
    return hk::test::wait_until([&] { return rt->stage().shown_id() == id; },
                                [&] {
                                  rt->sticks().poll(*flow, now_s);
                                  now_s += 0.01;
                                });
  }
  /// Polls until the pictures built ahead are `want` (or 60 s pass).
  bool ahead_becomes(std::vector<int> want) {
    std::sort(want.begin(), want.end());
    return hk::test::wait_until(
        [&] {
          std::vector<int> have = rt->library().ahead();
          std::sort(have.begin(), have.end());
          return have == want;
        },
        [&] { rt->library().poll(flow.get(), 0.0); });
  }
};

TEST(KioskBuilds, ThreeQuickNextPressesBuildAtMostTwoScenesAndLandOnTheThird) {
  LibraryRig r({"horse.png", "coins.png", "apple.jpg", "fruits.jpg", "butterfly.jpg"}, 0,
               "next3");              // nothing built ahead
  r.flow->key(KioskKey::Other, 0.0);  // wake: the tutorial
  for (int i = 0; i < 3; ++i) r.flow->key(KioskKey::Next, 0.0);
  r.settle(0.0);  // picture 1 of the library
  ASSERT_EQ(r.rt->stage().shown_id(), 0);
  const std::uint64_t before = r.rt->library().builds_started();
  for (int i = 0; i < 3; ++i) r.flow->key(KioskKey::Next, 0.1);
  EXPECT_EQ(r.rt->stage().shown_id(), 0) << "the picture felt before stays while the new one is built";
  r.settle(0.2);
  EXPECT_LE(r.rt->library().builds_started() - before, 2u) << "the second picture is not built";
  EXPECT_EQ(r.rt->stage().shown_id(), 3);
  EXPECT_EQ(r.rt->voice().last_said().rfind("Picture 4 of 5", 0), 0u) << r.rt->voice().last_said();
}

TEST(KioskBuilds, TheNextPictureBuiltAheadIsASwapAndThePreviousIsKept) {
  LibraryRig r({"horse.png", "coins.png", "apple.jpg", "fruits.jpg"}, 256, "ahead");
  ASSERT_GE(test::show_now(*r.rt, 1), 0);
  ASSERT_TRUE(r.ahead_becomes({0, 2})) << "the neighbours of picture 2 are built ahead";
  const std::uint64_t before = r.rt->library().builds_started();
  const int shapes = r.rt->library().show_picture(2);
  EXPECT_NE(shapes, KioskEffects::kPicturePending) << "on the device at once";
  EXPECT_EQ(r.rt->stage().shown_id(), 2);
  EXPECT_EQ(shapes, static_cast<int>(r.rt->stage().shown().scene->curve_count()));
  EXPECT_LE(r.rt->library().builds_started() - before, 1u)
      << "picture 3 is being built ahead; picture 2 was not built again";
  ASSERT_TRUE(r.ahead_becomes({1, 3})) << "picture 2's neighbours: 1 (built before) and 3";
}

TEST(KioskBuilds, TheFirstPictureIsBuiltDuringTheTutorialSoItsEndIsASwap) {
  LibraryRig r({"fruits.jpg", "horse.png", "apple.jpg"}, 256, "first");
  r.flow->key(KioskKey::Other, 0.0);  // wake: the tutorial's square
  ASSERT_TRUE(r.ahead_becomes({0})) << "picture 1 is built while the visitor learns the shapes";
  for (int i = 0; i < 2; ++i) r.flow->key(KioskKey::Next, 1.0);  // circle, triangle
  r.flow->key(KioskKey::Next, 2.0);                              // the first picture
  EXPECT_EQ(r.rt->stage().shown_id(), 0) << "on the device at the key, not after a build";
  EXPECT_FALSE(r.rt->library().busy());
  EXPECT_NE(r.rt->voice().last_said().find("Picture 1 of 3"), std::string::npos) << r.rt->voice().last_said();
}

TEST(KioskBuilds, NothingIsBuiltAheadOverTheBudgetAndNothingIsBuiltTwice) {
  LibraryRig r({"horse.png", "fruits.jpg", "apple.jpg"}, 0, "budget0");
  ASSERT_GE(test::show_now(*r.rt, 0), 0);
  const std::uint64_t after_first = r.rt->library().builds_started();
  for (int i = 0; i < 50; ++i) r.rt->library().poll(r.flow.get(), 0.0);
  EXPECT_EQ(r.rt->library().builds_started(), after_first) << "prefetch_mb = 0: nothing built ahead";
  EXPECT_TRUE(r.rt->library().ahead().empty());
}

/// The level-0 points of every curve of the scene shown.
std::vector<std::vector<Vec2>> shown_points(KioskRuntime& rt) {
  std::vector<std::vector<Vec2>> out;
  for (const Polyline& p : rt.stage().shown().polylines) out.push_back(p.points_m);
  return out;
}

TEST(KioskBuilds, ACorruptCacheEntryIsRebuiltAndAnUnwritableCacheCostsOnlyTheCache) {
  const fs::path cache = fs::temp_directory_path() / ("hk_builder_cache_" + std::to_string(::getpid()));
  fs::remove_all(cache);
  std::vector<std::vector<Vec2>> built;
  fs::path entry;
  {
    LibraryRig r({"horse.png", "coins.png"}, 0, "cache1", cache.string());
    ASSERT_GT(test::show_now(*r.rt, 0), 0);
    built = shown_points(*r.rt);
    for (const auto& e : fs::directory_iterator(cache / ""))
      if (e.path().extension() == ".scene") entry = e.path();
    ASSERT_FALSE(entry.empty()) << "the scene was kept";
  }
  {  // a byte flipped in the middle of the entry, as a failing disk leaves it
    std::fstream f(entry, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(static_cast<std::streamoff>(fs::file_size(entry) / 2));
    char c = 0;
    f.read(&c, 1);
    c = static_cast<char>(c ^ 0x5a);
    f.seekp(static_cast<std::streamoff>(fs::file_size(entry) / 2));
    f.write(&c, 1);
  }
  {
    LibraryRig r({"horse.png", "coins.png"}, 0, "cache2", cache.string());
    ASSERT_GT(test::show_now(*r.rt, 0), 0) << "built again";
    EXPECT_EQ(shown_points(*r.rt), built);
    const fs::path horse = r.lib / "0_horse.png";
    std::ifstream in(horse, std::ios::binary);
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_TRUE(SceneCache(cache.string()).load(SceneCache::key(bytes, r.settings), r.settings))
        << "and kept again, whole";
  }
  fs::remove_all(cache);
  {  // the cache's folder cannot be made (a file stands where it should be): the pictures are felt all the same
    std::ofstream(cache) << "not a folder";
    LibraryRig r({"horse.png", "coins.png"}, 0, "cache3", (cache / "scenes").string());
    ASSERT_GT(test::show_now(*r.rt, 0), 0);
    EXPECT_EQ(shown_points(*r.rt), built);
    ASSERT_GT(test::show_now(*r.rt, 1), 0);
  }
  fs::remove(cache);
}

TEST(KioskBuilds, AStickTakenOutWhileItsPageIsBuiltLeavesTheStickAndFeelsTheLibrary) {
  LibraryRig r({"horse.png", "coins.png"}, 0, "stick");
  const fs::path stick = r.spec_stick("stickdir");
  r.flow->key(KioskKey::Other, 0.0);
  for (int i = 0; i < 3; ++i) r.flow->key(KioskKey::Next, 0.0);
  r.settle(0.0);
  ASSERT_EQ(r.rt->stage().shown_id(), 0);
  r.rt->sticks().insert_folder(stick.string());
  double now_s = 1.0;
  ASSERT_TRUE(r.stick_shows(1001, now_s)) << "the stick's first page is felt";
  r.flow->key(KioskKey::Next, now_s);  // page 2 asked for...
  r.rt->sticks().remove_folder();      // ...and the stick pulled out while it is drawn
  ASSERT_TRUE(hk::test::wait_until([&] { return !r.rt->sticks().busy() && !r.rt->library().busy(); },
                                   [&] {
                                     r.rt->sticks().poll(*r.flow, now_s);
                                     r.rt->library().poll(r.flow.get(), now_s);
                                     now_s += 0.01;
                                   }));
  for (int i = 0; i < 50; ++i, now_s += 0.01)
    r.rt->sticks().poll(*r.flow, now_s);  // page 2's drawing, if it ends now, is dropped
  EXPECT_EQ(r.rt->stage().shown_id(), 0) << "back on the library's picture, never page 2";
  EXPECT_EQ(r.flow->view().failures, 0);
  fs::remove_all(stick);
}

// Finish pressed twice while a stick's page is drawn: the visit ends, the stick is forgotten, and the page that
// arrives afterwards is dropped without leaving the stick "busy" (a scripted `wait` would never return, and the
// operator's panel would say "working" for good).
TEST(KioskBuilds, FinishWhileAStickPageIsBuiltLeavesNothingBusy) {
  LibraryRig r({"horse.png"}, 0, "stickfinish");
  const fs::path stick = r.spec_stick("stickfinish");
  r.flow->key(KioskKey::Other, 0.0);
  r.rt->sticks().insert_folder(stick.string());
  double now_s = 1.0;
  ASSERT_TRUE(r.stick_shows(1001, now_s)) << "the stick's first page is felt";
  const int loads = r.rt->sticks().service().loads_started();
  const int done = r.rt->sticks().service().loads_done();
  r.flow->key(KioskKey::Next, now_s);  // page 2...
  ASSERT_TRUE(hk::test::wait_until([&] { return !(r.rt->sticks().service().loads_started() == loads); }));
  ASSERT_EQ(r.rt->sticks().service().loads_started(), loads + 1) << "page 2 is being drawn";
  r.rt->sticks().poll(*r.flow, now_s);
  ASSERT_TRUE(r.rt->sticks().busy()) << "the kiosk waits for page 2";
  r.flow->key(KioskKey::Finish, now_s);  // ...and Finish, twice, before it is done
  r.flow->key(KioskKey::Finish, now_s + 0.5);
  ASSERT_EQ(r.flow->view().state, KioskState::Attract);
  EXPECT_FALSE(r.rt->sticks().busy()) << "nothing of the forgotten stick is awaited";
  // Page 2's drawing ends (or has ended), and the window polls it in.
  ASSERT_TRUE(hk::test::wait_until([&] { return !(r.rt->sticks().service().loads_done() == done); }));
  ASSERT_EQ(r.rt->sticks().service().loads_done(), done + 1) << "page 2's load ended within 60 s";
  r.rt->sticks().poll(*r.flow, now_s);
  EXPECT_FALSE(r.rt->sticks().busy()) << "the page that arrived for the forgotten stick left nothing busy";
  EXPECT_EQ(r.flow->view().state, KioskState::Attract) << "and did not wake the kiosk";
  EXPECT_EQ(r.flow->view().failures, 0);
  fs::remove_all(stick);
}

// The visitor hears how many files of a stick cannot be read; the operator's panel lists which and why: files
// left out at the scan (a picture whose header is damaged) and pages that could not be built (a picture whose
// pixels are damaged, found when it is loaded), kept until the next stick.
TEST(KioskBuilds, WhatAStickCouldNotGiveIsListedForTheOperator) {
  LibraryRig r({"horse.png"}, 0, "stickproblems");
  const fs::path stick = r.spec_stick("stickproblems");
  fs::copy_file(kData / "bad" / "bad_crc.png", stick / "bad_crc.png");
  fs::copy_file(kData / "bad" / "damaged_idat.png", stick / "a_damaged.png");  // sorted first: the first page asked for
  r.flow->key(KioskKey::Other, 0.0);
  EXPECT_TRUE(r.rt->sticks().problems().empty());
  r.rt->sticks().insert_folder(stick.string());
  double now_s = 1.0;
  EXPECT_TRUE(hk::test::wait_until([&] { return r.rt->sticks().problems().size() >= 2; },
                                   [&] {
                                     r.rt->sticks().poll(*r.flow, now_s);
                                     now_s += 0.01;
                                   }));
  const std::vector<std::string>& problems = r.rt->sticks().problems();
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].rfind("'bad_crc.png': ", 0), 0u) << problems[0];
  EXPECT_NE(problems[0].find("CRC"), std::string::npos) << "why, as the log says it: " << problems[0];
  EXPECT_EQ(problems[1].rfind("'a_damaged.png' page 1: ", 0), 0u) << problems[1];
  EXPECT_EQ(r.flow->view().failures, 0);
  fs::remove_all(stick);
}

TEST(KioskBuilds, StickPagesPassedByQuicklyAreNeverPutOnTheDevice) {
  LibraryRig r({"horse.png"}, 0, "stickquick");  // prefetch_mb 0: each page is built when asked for
  const fs::path stick = r.spec_stick("stickquick");
  r.flow->key(KioskKey::Other, 0.0);
  r.rt->sticks().insert_folder(stick.string());
  double now_s = 1.0;
  ASSERT_TRUE(r.stick_shows(1001, now_s)) << "the stick's first page is felt";
  const std::uint64_t published = r.rt->stage().scenes_published();
  const int loads = r.rt->sticks().service().loads_started();
  r.flow->key(KioskKey::Next, now_s);  // page 2...
  ASSERT_TRUE(hk::test::wait_until([&] { return !(r.rt->sticks().service().loads_started() == loads); }));
  ASSERT_EQ(r.rt->sticks().service().loads_started(), loads + 1) << "page 2 is being drawn";
  for (int i = 0; i < 2; ++i) r.flow->key(KioskKey::Next, now_s);  // ...then pages 3 and 4 before it is done
  ASSERT_TRUE(r.stick_shows(1004, now_s));
  for (int i = 0; i < 50; ++i, now_s += 0.01) r.rt->sticks().poll(*r.flow, now_s);
  EXPECT_EQ(r.rt->stage().scenes_published() - published, 1u)
      << "page 2, drawn before Next was pressed again, was dropped, not shown";
  EXPECT_EQ(r.rt->stage().shown_id(), 1004);
  EXPECT_EQ(r.rt->voice().last_said().rfind("Page 4 of ", 0), 0u) << r.rt->voice().last_said();
  EXPECT_EQ(r.flow->view().failures, 0);
  fs::remove_all(stick);
}

TEST(KioskBuilds, APictureThatCannotBeReadIsSaidAndTheOldOneStays) {
  LibraryRig r({"horse.png", "coins.png", "apple.jpg"}, 0, "bad");
  {  // the second picture is cut short, as a copy to a stick pulled too soon leaves it
    const fs::path bad = r.lib / "1_coins.png";
    const auto size = fs::file_size(bad);
    fs::resize_file(bad, size / 2);
  }
  r.flow->key(KioskKey::Other, 0.0);
  for (int i = 0; i < 3; ++i) r.flow->key(KioskKey::Next, 0.0);
  r.settle(0.0);
  ASSERT_EQ(r.rt->stage().shown_id(), 0);
  const Scene* before = r.rt->stage().shown().scene;
  r.flow->key(KioskKey::Next, 1.0);
  r.settle(1.0);
  EXPECT_EQ(r.rt->stage().shown_id(), 0) << "the horse is still felt";
  EXPECT_EQ(r.rt->stage().shown().scene, before);
  EXPECT_EQ(r.rt->voice().last_said().rfind("Picture 2 of 3 cannot be read. ", 0), 0u) << r.rt->voice().last_said();
  EXPECT_EQ(r.rt->voice().last_said().find("1_coins.png"), std::string::npos)
      << "the picture's number names it, not its path";
  EXPECT_EQ(r.rt->voice().last_said().find("PNG"), std::string::npos)
      << "what is wrong with it is the operator's to read (the log), not the visitor's";
  r.flow->key(KioskKey::Next, 2.0);  // steps past it
  r.settle(2.0);
  EXPECT_EQ(r.rt->stage().shown_id(), 2);
  EXPECT_EQ(r.flow->view().failures, 0);
}

}  // namespace
}  // namespace hk::app
