// The library folder watched: the quiet rule on its own (a clock of the test's), the watch on a real folder, and
// the kiosk taking a new listing while a visitor explores another picture.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "audio/messages.hpp"
#include "pictures/library_watch.hpp"
#include "runtime_ticks.hpp"
#include "temp_dir.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"
#include "wait_until.hpp"

namespace {

using hk::app::LibrarySettler;
using hk::app::WatchedFile;
namespace fs = std::filesystem;

/// A check that counts its calls and refuses the names in `broken`.
struct CountingCheck {
  std::vector<std::string> broken;
  int calls = 0;
  LibrarySettler::PictureCheck fn() {
    return [this](const std::string& name) -> std::string {
      ++calls;
      return std::count(broken.begin(), broken.end(), name) ? "does not decode" : "";
    };
  }
};

WatchedFile file(const std::string& name, std::uint64_t bytes, std::int64_t time_ns = 1) {
  return WatchedFile{name, bytes, time_ns, time_ns};
}

using Names = std::vector<std::string>;

TEST(LibrarySettler, APictureIsTakenOnceItsFilesHaveBeenQuietForTheSettleTime) {
  CountingCheck check;
  LibrarySettler s(2.0, check.fn());
  EXPECT_FALSE(s.look({file("horse.png", 100)}, 10.0));
  EXPECT_FALSE(s.look({file("horse.png", 200)}, 11.5));  // still being written: the quiet time starts again
  EXPECT_FALSE(s.look({file("horse.png", 200)}, 13.4));
  EXPECT_TRUE(s.live().empty());
  EXPECT_DOUBLE_EQ(s.next_due_s(), 13.5);
  EXPECT_EQ(check.calls, 0);  // nothing is decoded before it is quiet
  EXPECT_TRUE(s.look({file("horse.png", 200)}, 13.5));
  EXPECT_EQ(s.live(), Names{"horse.png"});
  EXPECT_EQ(check.calls, 1);
  EXPECT_TRUE(s.take_changed().empty());  // new, not changed
  EXPECT_FALSE(s.look({file("horse.png", 200)}, 20.0));
  EXPECT_EQ(check.calls, 1);  // taken once
  EXPECT_EQ(s.next_due_s(), std::numeric_limits<double>::infinity());
}

TEST(LibrarySettler, ACompanionsChangeRestartsTheQuietTimeAndThePictureIsReportedChanged) {
  CountingCheck check;
  LibrarySettler s(2.0, check.fn());
  const std::vector<WatchedFile> before{file("horse.annotations.json", 50), file("horse.png", 200)};
  ASSERT_FALSE(s.look(before, 0.0));
  ASSERT_TRUE(s.look(before, 2.0));
  // The annotations are rewritten (a name added): the picture stays live, with the old files, until quiet again.
  const std::vector<WatchedFile> after{file("horse.annotations.json", 80, 5), file("horse.png", 200)};
  EXPECT_FALSE(s.look(after, 3.0));
  EXPECT_EQ(s.live(), Names{"horse.png"});
  EXPECT_TRUE(s.take_changed().empty());
  EXPECT_TRUE(s.look(after, 5.0));
  EXPECT_EQ(s.take_changed(), Names{"horse.png"});
  EXPECT_TRUE(s.take_changed().empty());  // handed out once
  EXPECT_EQ(check.calls, 2);
}

TEST(LibrarySettler, ARemovedPictureIsGoneAtOnceAndHiddenOrOtherFilesAreNeverPictures) {
  CountingCheck check;
  LibrarySettler s(2.0, check.fn());
  const std::vector<WatchedFile> files{file(".syncthing.apple.jpg.tmp", 10), file("._coins.png", 10),
                                       file("coins.png", 10), file("horse.png", 10), file("README.md", 10)};
  ASSERT_FALSE(s.look(files, 0.0));
  ASSERT_TRUE(s.look(files, 2.0));
  EXPECT_EQ(s.live(), (Names{"coins.png", "horse.png"}));
  EXPECT_TRUE(s.look({file("horse.png", 10)}, 2.1));  // coins removed: no quiet time to wait for
  EXPECT_EQ(s.live(), Names{"horse.png"});
}

TEST(LibrarySettler, APictureThatDoesNotDecodeIsRefusedOnceAndLookedAtAgainOnlyWhenItChanges) {
  CountingCheck check{{"coins.png"}};
  LibrarySettler s(1.0, check.fn());
  ASSERT_FALSE(s.look({file("coins.png", 10)}, 0.0));
  EXPECT_FALSE(s.look({file("coins.png", 10)}, 1.0));  // half a file, the writer gone: refused
  EXPECT_TRUE(s.live().empty());
  EXPECT_EQ(check.calls, 1);
  EXPECT_EQ(s.next_due_s(), std::numeric_limits<double>::infinity());  // nothing waits
  EXPECT_FALSE(s.look({file("coins.png", 10)}, 9.0));
  EXPECT_EQ(check.calls, 1);
  check.broken.clear();  // the rest of it arrives
  EXPECT_FALSE(s.look({file("coins.png", 20, 7)}, 10.0));
  EXPECT_TRUE(s.look({file("coins.png", 20, 7)}, 11.0));
  EXPECT_EQ(s.live(), Names{"coins.png"});
  // A live picture replaced by one that does not decode is no longer live.
  check.broken = {"coins.png"};
  EXPECT_FALSE(s.look({file("coins.png", 5, 9)}, 12.0));
  EXPECT_TRUE(s.look({file("coins.png", 5, 9)}, 13.0));
  EXPECT_TRUE(s.live().empty());
}

TEST(LibrarySettler, AtStartSettledPicturesAreLiveAtOnceAndRecentOnesWait) {
  CountingCheck check;
  LibrarySettler s(2.0, check.fn());
  const std::int64_t now_ns = 100'000'000'000;
  s.adopt({file("coins.png", 10, now_ns - 5'000'000'000), file("horse.png", 10, now_ns - 500'000'000)}, now_ns);
  EXPECT_EQ(s.live(), Names{"coins.png"});
  EXPECT_EQ(check.calls, 0);  // a restart lists what is there without decoding it
  const std::vector<WatchedFile> same{file("coins.png", 10, now_ns - 5'000'000'000),
                                      file("horse.png", 10, now_ns - 500'000'000)};
  EXPECT_FALSE(s.look(same, 50.0));  // horse: its quiet time starts at the first look
  EXPECT_TRUE(s.look(same, 52.0));
  EXPECT_EQ(s.live(), (Names{"coins.png", "horse.png"}));
}

TEST(LibrarySettler, ANonPositiveQuietTimeIsRefused) {
  EXPECT_THROW(LibrarySettler(0.0, [](const std::string&) { return std::string{}; }), std::exception);
}

std::vector<std::uint8_t> bytes_of(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& p, const std::vector<std::uint8_t>& b, std::size_t n) {
  std::ofstream(p, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(n));
}

std::string names_of(const std::vector<std::string>& paths) {
  std::string out;
  for (const std::string& p : paths) out += fs::path(p).filename().string() + " ";
  return out;
}

TEST(LibraryWatch, APictureRenamedInIsListedAndAHalfWrittenOneNeverIs) {
  hk::test::TempDir dir("hk_watch");
  const fs::path lib = dir.path(), images = fs::path(HK_TEST_DATA_DIR) / "images";
  fs::copy_file(images / "horse.png", lib / "horse.png");
  std::filesystem::last_write_time(lib / "horse.png", fs::file_time_type::clock::now() - std::chrono::hours(1));
  hk::app::LibraryWatch watch(lib.string(), 0.3, hk::vision::ImageLimits{});
  ASSERT_EQ(names_of(watch.first_listing()), "horse.png ");

  // A half-written PNG that stays half written (the copy died), and a JPEG that arrives Syncthing's way.
  const std::vector<std::uint8_t> coins = bytes_of(images / "coins.png");
  write_bytes(lib / "coins.png", coins, coins.size() / 2);
  const std::vector<std::uint8_t> apple = bytes_of(images / "apple.jpg");
  write_bytes(lib / ".syncthing.apple.jpg.tmp", apple, apple.size());
  fs::rename(lib / ".syncthing.apple.jpg.tmp", lib / "apple.jpg");

  std::vector<std::string> seen;  // every picture ever listed
  std::vector<std::string> last;
  auto take = [&] {
    if (auto l = watch.take()) {
      last = l->pictures;
      for (const std::string& p : l->pictures) seen.push_back(fs::path(p).filename().string());
    }
  };
  ASSERT_TRUE(hk::test::wait_until([&] { return names_of(last) == "apple.jpg horse.png " && watch.refused() >= 1; },
                                   take, 30.0))
      << names_of(last) << " refused " << watch.refused();
  EXPECT_EQ(std::count(seen.begin(), seen.end(), "coins.png"), 0);

  // The rest of the file arrives: now it decodes, and is listed.
  write_bytes(lib / "coins.png", coins, coins.size());
  ASSERT_TRUE(hk::test::wait_until([&] { return names_of(last) == "apple.jpg coins.png horse.png "; }, take, 30.0))
      << names_of(last);

  // A picture removed is gone from the next listing.
  fs::remove(lib / "horse.png");
  ASSERT_TRUE(hk::test::wait_until([&] { return names_of(last) == "apple.jpg coins.png "; }, take, 30.0))
      << names_of(last);
}

TEST(LibraryWatch, AFolderThatGoesAwayListsNothingAndIsWatchedAgainWhenItIsBack) {
  hk::test::TempDir dir("hk_watch");
  const fs::path lib = fs::path(dir.path()) / "library", images = fs::path(HK_TEST_DATA_DIR) / "images";
  hk::app::LibraryWatch watch(lib.string(), 0.2, hk::vision::ImageLimits{});  // not there yet
  EXPECT_TRUE(watch.first_listing().empty());
  fs::create_directories(lib);
  fs::copy_file(images / "horse.png", lib / "horse.png");
  std::vector<std::string> last;
  auto take = [&] {
    if (auto l = watch.take()) last = l->pictures;
  };
  ASSERT_TRUE(hk::test::wait_until([&] { return names_of(last) == "horse.png "; }, take, 30.0)) << names_of(last);
  fs::remove_all(lib);
  ASSERT_TRUE(hk::test::wait_until([&] { return last.empty(); }, take, 30.0)) << names_of(last);
}

/// The kiosk's runtime without its window on a watched library folder (quiet time 0.3 s), the shipped pictures
/// behind it.
struct WatchedKiosk {
  hk::test::TempDir dir{"hk_watched_kiosk"};
  fs::path lib = fs::path(dir.path());
  hk::config::Settings s;
  std::unique_ptr<hk::app::KioskRuntime> rt;
  std::unique_ptr<hk::app::KioskFlow> flow;
  double now_s = 0.0;

  void start() {
    hk::app::RuntimeOptions ro = hk::test::headless_runtime_options(lib);
    ro.library_settle_s = 0.3;
    ro.shipped_library = HK_SHIPPED_PICTURES_DIR;
    s.kiosk.names_dir = "off";
    s.kiosk.say_names_on_touch = "off";
    rt = std::make_unique<hk::app::KioskRuntime>(ro, s);
    flow = std::make_unique<hk::app::KioskFlow>(rt->effects(), rt->audio().messages(),
                                                hk::app::flow_params_from(s, false));
  }
  void add(const std::string& name, const fs::path& from) {
    fs::copy_file(from, lib / name, fs::copy_options::overwrite_existing);
  }
  /// Frames of 20 ms until `done`, at most 30 s of the wall clock.
  template <typename F>
  bool run_until(F done) {
    return hk::test::wait_until(
        done,
        [&] {
          now_s += 0.02;
          rt->poll(flow.get(), now_s);
        },
        30.0);
  }
  std::string shown() const { return fs::path(rt->stage().shown().image_path).filename().string(); }
  std::string said() const { return rt->voice().last_said(); }
};

TEST(LibraryReload, APictureAddedChangedAndRemovedWhileAVisitorExploresAnotherWaitsUntilTheyMoveOn) {
  WatchedKiosk k;
  const fs::path images = fs::path(HK_TEST_DATA_DIR) / "images", shipped = HK_SHIPPED_PICTURES_DIR;
  k.add("butterfly.jpg", shipped / "butterfly.jpg");
  k.add("coins.png", shipped / "coins.png");
  k.add("horse.png", images / "horse.png");
  for (const char* f : {"butterfly.jpg", "coins.png", "horse.png"})
    fs::last_write_time(k.lib / f, fs::file_time_type::clock::now() - std::chrono::hours(1));
  k.start();
  ASSERT_EQ(k.rt->library().picture_count(), 3);
  k.flow->key(hk::app::KioskKey::Other, k.now_s);
  for (int i = 0; i < 4; ++i) k.flow->key(hk::app::KioskKey::Next, k.now_s);  // the tutorial, butterfly, coins
  ASSERT_TRUE(k.run_until([&] { return k.shown() == "coins.png"; }));
  ASSERT_NE(k.said().find("Picture 2 of 3"), std::string::npos) << k.said();

  // While the visitor explores the coins: a picture added (first by name), one changed, one removed.
  k.add("apple.jpg", images / "apple.jpg");
  k.add("horse.png", images / "silhouette_3.png");  // the same name, another picture (626 px wide, not 400)
  fs::remove(k.lib / "butterfly.jpg");
  const auto& waiting = k.rt->library().waiting();
  ASSERT_TRUE(k.run_until([&] {
    return waiting && names_of(waiting->pictures) == "apple.jpg coins.png horse.png " &&
           std::count(waiting->changed.begin(), waiting->changed.end(), (k.lib / "horse.png").string()) == 1;
  })) << (waiting ? names_of(waiting->pictures) : std::string("no listing"));
  // The visitor still explores the coins, as picture 2 of 3: nothing moved under their hand.
  EXPECT_EQ(k.shown(), "coins.png");
  EXPECT_EQ(k.rt->library().picture_count(), 3);
  EXPECT_EQ(k.flow->view().picture, 1);

  // Next: the new listing is taken; the horse, as it is now (not the one built ahead before it changed).
  k.flow->key(hk::app::KioskKey::Next, k.now_s);
  ASSERT_TRUE(k.run_until([&] { return k.shown() == "horse.png"; }));
  EXPECT_FALSE(k.rt->library().waiting().has_value());
  EXPECT_EQ(k.rt->library().picture_count(), 3);
  EXPECT_EQ(k.rt->stage().shown().file_width_px, 626);
  EXPECT_NE(k.said().find("Picture 3 of 3"), std::string::npos) << k.said();
  // Previous, twice: the coins, then the apple that was added; the butterfly is gone.
  k.flow->key(hk::app::KioskKey::Previous, k.now_s);
  ASSERT_TRUE(k.run_until([&] { return k.shown() == "coins.png"; }));
  EXPECT_NE(k.said().find("Picture 2 of 3"), std::string::npos) << k.said();
  k.flow->key(hk::app::KioskKey::Previous, k.now_s);
  ASSERT_TRUE(k.run_until([&] { return k.shown() == "apple.jpg"; }));
  EXPECT_NE(k.said().find("Picture 1 of 3"), std::string::npos) << k.said();
}

TEST(LibraryReload, NextFromAPictureThatWasRemovedGoesToTheOneAfterItByName) {
  WatchedKiosk k;
  const fs::path images = fs::path(HK_TEST_DATA_DIR) / "images";
  for (const char* f : {"apple.jpg", "coins.png", "horse.png"}) {
    k.add(f, images / f);
    fs::last_write_time(k.lib / f, fs::file_time_type::clock::now() - std::chrono::hours(1));
  }
  k.start();
  k.flow->key(hk::app::KioskKey::Other, k.now_s);
  for (int i = 0; i < 4; ++i) k.flow->key(hk::app::KioskKey::Next, k.now_s);  // the tutorial, apple, coins
  ASSERT_TRUE(k.run_until([&] { return k.shown() == "coins.png"; }));
  fs::remove(k.lib / "coins.png");  // the picture under the visitor's hand
  fs::remove(k.lib / "horse.png");
  k.add("fruits.jpg", images / "fruits.jpg");
  const auto& waiting = k.rt->library().waiting();
  ASSERT_TRUE(k.run_until([&] { return waiting && names_of(waiting->pictures) == "apple.jpg fruits.jpg "; }));
  EXPECT_EQ(k.shown(), "coins.png");  // it stays until they move on
  k.flow->key(hk::app::KioskKey::Next, k.now_s);
  ASSERT_TRUE(k.run_until([&] { return k.shown() == "fruits.jpg"; }));
  EXPECT_NE(k.said().find("Picture 2 of 2"), std::string::npos) << k.said();
}

TEST(LibraryReload, AnEmptyFolderShowsTheShippedPicturesUntilItsOwnArriveWhileNobodyIsThere) {
  WatchedKiosk k;
  k.start();
  const int shipped = static_cast<int>(hk::app::list_pictures(HK_SHIPPED_PICTURES_DIR).size());
  EXPECT_EQ(k.rt->library().picture_count(), shipped);
  k.add("horse.png", fs::path(HK_TEST_DATA_DIR) / "images" / "horse.png");
  // The kiosk waits in attract: the listing is taken at once.
  ASSERT_TRUE(k.run_until([&] { return k.rt->library().picture_count() == 1; }));
  EXPECT_FALSE(k.rt->library().waiting().has_value());
  k.flow->key(hk::app::KioskKey::Other, k.now_s);
  for (int i = 0; i < 3; ++i) k.flow->key(hk::app::KioskKey::Next, k.now_s);
  ASSERT_TRUE(k.run_until([&] { return k.shown() == "horse.png"; }));
  EXPECT_NE(k.said().find("Picture 1 of 1"), std::string::npos) << k.said();
}

}  // namespace
