// The Copy key as a visitor meets it (KioskFlow with a recorded CopyEffects): the first press asks, the second
// within 10 s makes the copy, a late second press asks again, any other key in between cancels; the copies a
// visit allows and the day's limit each say so; a kiosk without copies, and a visit without a picture yet, say
// that. Then the CopyDesk itself on a real picture: what it sends the printer is the copy's PDF, the staff's
// line is said when it is queued, a printer that refuses gives the sorry line, and a failed copy does not count
// against the day.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "audio/messages.hpp"
#include "cups_server.hpp"
#include "every_effect.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"

namespace hk::app {
namespace {

using audio::MessageId;

struct Recorder final : hk::test::EveryEffect, CopyEffects {
  std::vector<std::string> said;
  void say(const std::string& t) override { said.push_back(t); }
  void show_tutorial(TutorialShape) override {}
  int show_picture(int) override { return 4; }
  int picture_count() const override { return 3; }
  std::string describe() override { return "4 shapes."; }
  bool change_level(int) override { return false; }
  bool change_volume(int) override { return false; }
  void new_session() override {}
  void show_document(int, int) override {}
  void forget_stick() override {}
  // CopyEffects
  bool offered = true, day_full = false, can_start = true, no_stick = false;
  int started = 0;
  bool copies_offered() const override { return offered; }
  bool stick_missing() const override { return no_stick; }
  bool day_limit_reached() const override { return day_full; }
  bool start_copy() override {
    if (!can_start) return false;
    ++started;
    return true;
  }
};

const audio::MessageCatalog& en() { return audio::MessageCatalog::english(); }
std::string line(MessageId id) {
  static const config::KeysSettings keys;
  return en().text(id, {}, key_args(keys));
}

/// A flow on the first library picture, copies offered (per visit: `per_visit`).
struct Visit {
  Recorder fx;
  KioskFlow flow;
  explicit Visit(int per_visit = 1) : flow(effects(fx), en(), params(per_visit)) {
    flow.key(KioskKey::Other, 0.0);                                 // wake
    for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, 1.0 + i);  // the tutorial, then picture 1
  }
  static KioskEffects effects(Recorder& fx) {
    KioskEffects e(fx);
    e.copies = &fx;
    return e;
  }
  static KioskFlowParams params(int per_visit) {
    KioskFlowParams p;
    p.copies = true;
    p.copy_per_visit = per_visit;
    return p;
  }
};

TEST(CopyKey, TheFirstPressAsksTheSecondWithin10sMakesTheCopy) {
  Visit v;
  v.flow.key(KioskKey::Copy, 10.0);
  EXPECT_EQ(v.fx.said.back(), line(MessageId::copy_confirm));
  EXPECT_NE(v.fx.said.back().find("Press the H key again within 10 seconds"), std::string::npos) << v.fx.said.back();
  EXPECT_EQ(v.fx.started, 0) << "one press makes nothing";
  v.flow.key(KioskKey::Copy, 19.5);
  EXPECT_EQ(v.fx.started, 1);
  EXPECT_EQ(v.fx.said.back(), line(MessageId::copy_making));
  // The desk reports: the staff's line, else the catalogue's.
  using Route = CopyReport::Route;
  v.flow.copy_finished({Route::Done, Route::NotAsked, "Your copy will be at the front desk.", ""}, 25.0);
  EXPECT_EQ(v.fx.said.back(), "Your copy will be at the front desk.");
  v.flow.copy_finished({Route::Done, Route::NotAsked, "", ""}, 26.0);
  EXPECT_EQ(v.fx.said.back(), line(MessageId::copy_printed));
  v.flow.copy_finished({Route::Failed, Route::NotAsked, "", ""}, 27.0);
  EXPECT_EQ(v.fx.said.back(), line(MessageId::copy_failed));
}

TEST(CopyKey, EachRouteIsOneSentencePrintedFirstAndTheStickSaysWhereTheCopyIs) {
  using Route = CopyReport::Route;
  Visit v;
  v.flow.copy_finished({Route::NotAsked, Route::Done, "", "Butterfly (tactile copy)"}, 25.0);
  EXPECT_EQ(v.fx.said.back(),
            "Your copy is on your stick, in the folder Butterfly (tactile copy). You can take your stick now.");
  v.flow.copy_finished({Route::Done, Route::Done, "At the desk.", "Butterfly (tactile copy) 2"}, 26.0);
  EXPECT_EQ(
      v.fx.said.back(),
      "At the desk. Your copy is on your stick, in the folder Butterfly (tactile copy) 2. You can take your stick "
      "now.");
  v.flow.copy_finished({Route::Done, Route::Full, "At the desk.", ""}, 27.0);
  EXPECT_EQ(v.fx.said.back(), "At the desk. " + line(MessageId::copy_stick_full));
  const std::pair<Route, MessageId> refusals[] = {{Route::WriteProtected, MessageId::copy_stick_locked},
                                                  {Route::Format, MessageId::copy_stick_format},
                                                  {Route::NoStick, MessageId::copy_no_stick},
                                                  {Route::Failed, MessageId::copy_stick_failed}};
  for (const auto& [route, id] : refusals) {
    v.flow.copy_finished({Route::NotAsked, route, "", ""}, 28.0);
    EXPECT_EQ(v.fx.said.back(), line(id));
  }
}

TEST(CopyKey, ACopyThatReachedNeitherRouteDoesNotCountAgainstTheVisit) {
  using Route = CopyReport::Route;
  Visit v;  // one copy a visit
  v.flow.key(KioskKey::Copy, 10.0);
  v.flow.key(KioskKey::Copy, 11.0);
  EXPECT_EQ(v.fx.started, 1);
  v.flow.copy_finished({Route::NotAsked, Route::Full, "", ""}, 12.0);  // a full stick: try another
  v.flow.key(KioskKey::Copy, 13.0);
  v.flow.key(KioskKey::Copy, 14.0);
  EXPECT_EQ(v.fx.started, 2);
  v.flow.copy_finished({Route::NotAsked, Route::Done, "", "x"}, 15.0);
  v.flow.key(KioskKey::Copy, 16.0);
  EXPECT_EQ(v.fx.said.back(), "You have had your copy for this visit.");
  EXPECT_EQ(v.fx.started, 2);
}

TEST(CopyKey, CopiesForSticksOnlyAskForTheStickFirst) {
  Visit v;
  v.fx.no_stick = true;
  v.flow.key(KioskKey::Copy, 10.0);
  EXPECT_EQ(v.fx.said.back(), line(MessageId::copy_no_stick));
  v.flow.key(KioskKey::Copy, 11.0);
  EXPECT_EQ(v.fx.started, 0) << "no confirmation was asked, so no copy is started";
  v.fx.no_stick = false;
  v.flow.key(KioskKey::Copy, 12.0);
  EXPECT_EQ(v.fx.said.back(), line(MessageId::copy_confirm));
}

TEST(CopyKey, ALateSecondPressAsksAgainAndAnyOtherKeyInBetweenCancels) {
  Visit v;
  v.flow.key(KioskKey::Copy, 10.0);
  v.flow.key(KioskKey::Copy, 20.5);  // 10.5 s later: too late, it asks again
  EXPECT_EQ(v.fx.started, 0);
  EXPECT_EQ(v.fx.said.back(), line(MessageId::copy_confirm));
  v.flow.key(KioskKey::Where, 21.0);
  v.flow.key(KioskKey::Copy, 22.0);  // Where came between: this press asks again
  EXPECT_EQ(v.fx.started, 0);
  v.flow.key(KioskKey::Copy, 23.0);
  EXPECT_EQ(v.fx.started, 1);
}

TEST(CopyKey, TheVisitsCopiesAndTheDaysLimitAreSaidAndNothingMore) {
  Visit v(2);
  for (double t : {10.0, 11.0, 12.0, 13.0}) v.flow.key(KioskKey::Copy, t);
  EXPECT_EQ(v.fx.started, 2);
  v.flow.key(KioskKey::Copy, 14.0);
  EXPECT_EQ(v.fx.said.back(), "You have had the 2 copies of this visit.");
  EXPECT_EQ(v.fx.started, 2);
  // A new visitor may have theirs again, unless the day's copies are made.
  v.flow.key(KioskKey::Finish, 20.0);
  v.flow.key(KioskKey::Finish, 20.5);
  v.flow.key(KioskKey::Other, 30.0);
  for (int i = 0; i < 3; ++i) v.flow.key(KioskKey::Next, 31.0 + i);
  v.fx.day_full = true;
  v.flow.key(KioskKey::Copy, 40.0);
  EXPECT_EQ(v.fx.said.back(), line(MessageId::copy_day_limit));
  v.fx.day_full = false;
  v.flow.key(KioskKey::Copy, 41.0);
  v.flow.key(KioskKey::Copy, 42.0);
  EXPECT_EQ(v.fx.started, 3);
  Visit one;
  one.flow.key(KioskKey::Copy, 10.0);
  one.flow.key(KioskKey::Copy, 11.0);
  one.flow.key(KioskKey::Copy, 12.0);
  EXPECT_EQ(one.fx.said.back(), "You have had your copy for this visit.");
}

TEST(CopyKey, NoCopiesOfferedOrNoPictureYetIsSaid) {
  Visit v;
  v.fx.offered = false;
  v.flow.key(KioskKey::Copy, 10.0);
  EXPECT_EQ(v.fx.said.back(), line(MessageId::copy_not_set_up));
  // Without a CopyEffects at all, the same.
  Recorder fx;
  KioskFlow none(fx, en());
  none.key(KioskKey::Other, 0.0);
  none.key(KioskKey::Copy, 1.0);
  EXPECT_EQ(fx.said.back(), line(MessageId::copy_not_set_up));
  // In the tutorial there is no picture to copy.
  Recorder fx2;
  KioskEffects e(fx2);
  e.copies = &fx2;
  KioskFlow tutorial(e, en());
  tutorial.key(KioskKey::Other, 0.0);
  tutorial.key(KioskKey::Copy, 1.0);
  EXPECT_EQ(fx2.said.back(), line(MessageId::copy_nothing));
  EXPECT_EQ(fx2.started, 0);
}

TEST(CopyKey, TheHelpNamesTheCopyKeyWhereCopiesAreOffered) {
  Visit v;
  v.flow.key(KioskKey::Help, 10.0);
  v.flow.key(KioskKey::Help, 10.5);  // every key, group by group
  std::string all;
  for (int i = 0; i < 10; ++i) {
    all += v.fx.said.back();
    v.flow.key(KioskKey::Next, 11.0 + i);
  }
  EXPECT_NE(all.find("Press the H key twice for a copy of the picture to take home."), std::string::npos) << all;
}

/// The kiosk's runtime without its window on a library of the shipped butterfly (named by its annotations),
/// copies printed on `queue`; the flow on the butterfly.
struct KioskWithCopies {
  std::filesystem::path lib;
  config::Settings s;
  std::unique_ptr<KioskRuntime> rt;
  std::unique_ptr<KioskFlow> flow;
  KioskWithCopies(const std::string& queue, const std::string& line, int per_day = 50,
                  const std::string& to = "printer") {
    namespace fs = std::filesystem;
    lib = fs::temp_directory_path() / ("hk_copy_lib_" + std::to_string(::getpid()));
    fs::remove_all(lib);
    fs::create_directories(lib);
    for (const char* f : {"butterfly.jpg", "butterfly.annotations.json", "butterfly.toml"})
      fs::copy_file(fs::path(HK_SHIPPED_PICTURES_DIR) / f, lib / f);
    RuntimeOptions ro;
    ro.library = lib.string();
    ro.hotplug = false;
    ro.open_audio_output = false;
    ro.probe_usb_device = false;
    ro.probe_camera = false;
    s.copy.to = to;
    s.copy.printer = queue;
    s.copy.printed_line = line;
    s.copy.per_day = per_day;
    s.kiosk.names_dir = "off";
    rt = std::make_unique<KioskRuntime>(ro, s);
    flow = std::make_unique<KioskFlow>(rt->effects(), rt->audio().messages(), flow_params_from(s, false));
    flow->key(KioskKey::Other, 0.0);
    for (int i = 0; i < 3; ++i) flow->key(KioskKey::Next, 1.0 + i);  // the tutorial, then the butterfly
  }
  ~KioskWithCopies() { std::filesystem::remove_all(lib); }
  /// Polls the runtime (frames of 20 ms) until `done` holds, at most 60 s; true when it did.
  template <typename F>
  bool run_until(F done, double& now_s) {
    return hk::test::CupsServer::wait_for(
        [&] {
          now_s += 0.02;
          rt->poll(flow.get(), now_s);
          return done();
        },
        std::chrono::seconds(60));
  }
};

TEST(CopyDesk, ThePictureShownIsPrintedAndTheStaffsLineSaid) {
  hk::test::CupsServer cups;
  const std::string why = cups.start();
  if (!why.empty()) GTEST_SKIP() << why;
  KioskWithCopies k(hk::test::CupsServer::kQueue, "Your copy will be at the front desk.");
  double now = 5.0;
  ASSERT_TRUE(k.run_until([&] { return !k.rt->stage().shown().image_path.empty(); }, now)) << "the butterfly is shown";
  k.flow->key(KioskKey::Copy, now);
  k.flow->key(KioskKey::Copy, now + 1.0);
  EXPECT_EQ(k.rt->voice().last_said(), line(MessageId::copy_making));
  ASSERT_TRUE(k.run_until([&] { return k.rt->voice().last_said() != line(MessageId::copy_making); }, now));
  EXPECT_EQ(k.rt->voice().last_said(), "Your copy will be at the front desk.");
  // The job is the copy's PDF: a PDF, titled with the picture's title, its shapes named in braille.
  const std::filesystem::path job = cups.job_file(1);
  const auto whole_pdf = [&] {  // the backend writes the job while we look: wait for all of it
    std::ifstream f(job, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    return bytes.rfind("%PDF-", 0) == 0 && bytes.find("%%EOF") != std::string::npos;
  };
  EXPECT_TRUE(hk::test::CupsServer::wait_for(whole_pdf, std::chrono::seconds(30))) << cups.log();
  EXPECT_FALSE(k.rt->copies().busy());
}

TEST(CopyDesk, APrinterThatRefusesGivesTheSorryLineAndDoesNotCountAgainstTheDay) {
  hk::test::CupsServer cups;
  const std::string why = cups.start();
  if (!why.empty()) GTEST_SKIP() << why;
  ASSERT_EQ(cups.sh(std::string("cupsdisable ") + hk::test::CupsServer::kQueue), 0);
  KioskWithCopies k(hk::test::CupsServer::kQueue, "", 1);
  double now = 5.0;
  ASSERT_TRUE(k.run_until([&] { return !k.rt->stage().shown().image_path.empty(); }, now));
  k.flow->key(KioskKey::Copy, now);
  k.flow->key(KioskKey::Copy, now + 1.0);
  ASSERT_TRUE(k.run_until([&] { return k.rt->voice().last_said() != line(MessageId::copy_making); }, now));
  EXPECT_EQ(k.rt->voice().last_said(), line(MessageId::copy_failed));
  EXPECT_FALSE(k.rt->copies().day_limit_reached()) << "a copy not made does not count";
  EXPECT_TRUE(std::filesystem::is_empty(cups.out()));
}

TEST(CopyDesk, ACopyForTheStickIsANewFolderOnItAndTheVisitorHearsWhere) {
  KioskWithCopies k("", "", 50, "stick");
  double now = 5.0;
  ASSERT_TRUE(k.run_until([&] { return !k.rt->stage().shown().image_path.empty(); }, now));
  k.flow->key(KioskKey::Copy, now);
  EXPECT_EQ(k.rt->voice().last_said(), line(MessageId::copy_no_stick));
  // A folder stands in for the visitor's stick (the loop-device tests write real images).
  const std::filesystem::path stick = k.lib.string() + "_stick";
  std::filesystem::create_directories(stick);
  k.rt->sticks().insert_folder(stick.string());
  ASSERT_TRUE(k.run_until([&] { return k.rt->sticks().service().stick_in() && !k.rt->sticks().busy(); }, now));
  k.flow->key(KioskKey::Copy, now);
  k.flow->key(KioskKey::Copy, now + 1.0);
  EXPECT_EQ(k.rt->voice().last_said(), line(MessageId::copy_making));
  ASSERT_TRUE(k.run_until([&] { return k.rt->voice().last_said() != line(MessageId::copy_making); }, now));
  std::vector<std::filesystem::path> folders;
  for (const auto& e : std::filesystem::directory_iterator(stick)) folders.push_back(e.path());
  ASSERT_EQ(folders.size(), 1u) << k.rt->voice().last_said();
  const std::string folder = folders[0].filename().string();
  EXPECT_NE(folder.find("(tactile copy)"), std::string::npos) << folder;
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(folders[0]), std::filesystem::directory_iterator()), 3);
  EXPECT_EQ(k.rt->voice().last_said(),
            "Your copy is on your stick, in the folder " + folder + ". You can take your stick now.");
  std::filesystem::remove_all(stick);
}

}  // namespace
}  // namespace hk::app
