// Log lines with an event word (runtime/event_log.hpp): the journal's fields for a line (golden, from the journal's
// documented field names and syslog's priorities); the event a sink sees while log_event writes and not after;
// standard error's "[word]" after the level; JOURNAL_STREAM recognised only for the real standard error; every event
// named once and listed in the header's table; the flow's visit_started and visit_finished. A line sent to a real
// journal runs where journald listens (not in CI's container).
#include <gtest/gtest.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>

#include "every_effect.hpp"
#include "runtime/event_log.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {
namespace {

/// Records each line and the event the sink saw while writing it.
class RecordingSink final : public spdlog::sinks::base_sink<std::mutex> {
 public:
  std::vector<std::pair<KioskEvent, std::string>> lines;

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    lines.emplace_back(event_being_logged(), std::string(msg.payload.data(), msg.payload.size()));
  }
  void flush_() override {}
};

/// The default logger replaced by `sink` for the scope.
struct LoggerSwap {
  std::shared_ptr<spdlog::logger> before = spdlog::default_logger();
  explicit LoggerSwap(std::shared_ptr<spdlog::sinks::sink> sink) {
    auto l = std::make_shared<spdlog::logger>("test", std::move(sink));
    l->set_level(spdlog::level::trace);
    spdlog::set_default_logger(l);
  }
  ~LoggerSwap() { spdlog::set_default_logger(before); }
};

TEST(EventLog, TheJournalsFieldsForALine) {
  EXPECT_EQ(journal_fields("device: Haply lost", spdlog::level::warn, KioskEvent::device_lost),
            (std::vector<std::string>{"MESSAGE=device: Haply lost", "PRIORITY=4", "SYSLOG_IDENTIFIER=haptic-kiosk",
                                      "HK_EVENT=device_lost"}));
  EXPECT_EQ(journal_fields("two\nlines\r", spdlog::level::info, KioskEvent::none, "hk-test"),
            (std::vector<std::string>{"MESSAGE=two lines ", "PRIORITY=6", "SYSLOG_IDENTIFIER=hk-test"}));
  const std::pair<spdlog::level::level_enum, std::string> priorities[] = {
      {spdlog::level::critical, "PRIORITY=2"}, {spdlog::level::err, "PRIORITY=3"},
      {spdlog::level::warn, "PRIORITY=4"},     {spdlog::level::info, "PRIORITY=6"},
      {spdlog::level::debug, "PRIORITY=7"},    {spdlog::level::trace, "PRIORITY=7"}};
  for (const auto& [level, field] : priorities) EXPECT_EQ(journal_fields("x", level, KioskEvent::none)[1], field);
}

TEST(EventLog, TheSinkSeesTheEventWhileTheLineIsWrittenAndNotAfter) {
  auto sink = std::make_shared<RecordingSink>();
  {
    LoggerSwap swap(sink);
    log_event(KioskEvent::copy_made, spdlog::level::info, "copy: printed");
    spdlog::info("an ordinary line");
  }
  ASSERT_EQ(sink->lines.size(), 2u);
  EXPECT_EQ(sink->lines[0], std::make_pair(KioskEvent::copy_made, std::string("copy: printed")));
  EXPECT_EQ(sink->lines[1], std::make_pair(KioskEvent::none, std::string("an ordinary line")));
  EXPECT_EQ(event_being_logged(), KioskEvent::none);
}

TEST(EventLog, StandardErrorCarriesTheEventsWordAfterTheLevel) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("hk_event_log_" + std::to_string(::getpid()))).string();
  std::fflush(stderr);
  const int saved = ::dup(2);
  std::FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr);
  ::dup2(::fileno(f), 2);
  {
    LoggerSwap swap(stderr_event_sink());
    log_event(KioskEvent::visit_started, spdlog::level::info, "visit: started");
    spdlog::warn("plain");
    spdlog::default_logger()->flush();
  }
  std::fflush(stderr);
  ::dup2(saved, 2);
  ::close(saved);
  std::fclose(f);
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  std::filesystem::remove(path);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NE(lines[0].find("info] [visit_started] visit: started"), std::string::npos) << lines[0];
  EXPECT_EQ(lines[1].find("[visit_started]"), std::string::npos) << lines[1];
  EXPECT_NE(lines[1].find("] plain"), std::string::npos) << lines[1];
}

TEST(EventLog, JournalStreamIsRecognisedOnlyForTheRealStandardError) {
  const char* old = std::getenv("JOURNAL_STREAM");
  const std::string saved = old != nullptr ? old : "";
  struct stat st {};
  ASSERT_EQ(::fstat(2, &st), 0);
  ::setenv("JOURNAL_STREAM", (std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino)).c_str(), 1);
  EXPECT_TRUE(stderr_is_journal());
  ::setenv("JOURNAL_STREAM", (std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino + 1)).c_str(), 1);
  EXPECT_FALSE(stderr_is_journal()) << "a stream inherited from a parent, not ours";
  ::setenv("JOURNAL_STREAM", "garbage", 1);
  EXPECT_FALSE(stderr_is_journal());
  ::unsetenv("JOURNAL_STREAM");
  EXPECT_FALSE(stderr_is_journal());
  if (old != nullptr) ::setenv("JOURNAL_STREAM", saved.c_str(), 1);
}

TEST(EventLog, EveryEventHasOneWordAndTheHeadersTableListsIt) {
  std::ifstream in(std::string(HK_TEST_DATA_DIR) + "/../../app/runtime/include/runtime/event_log.hpp");
  std::stringstream header;
  header << in.rdbuf();
  ASSERT_FALSE(header.str().empty());
  std::set<std::string> words;
  EXPECT_STREQ(kiosk_event_name(KioskEvent::none), "");
  for (int i = 1; i < kKioskEventCount; ++i) {
    const std::string w = kiosk_event_name(static_cast<KioskEvent>(i));
    EXPECT_FALSE(w.empty()) << i;
    EXPECT_TRUE(words.insert(w).second) << w << " twice";
    EXPECT_NE(header.str().find("/// | `" + w + "` |"), std::string::npos) << w << " is not in the table";
  }
}

/// The flow's effects, doing nothing.
struct Quiet final : hk::test::EveryEffect {
  void say(const std::string&) override {}
  void show_tutorial(TutorialShape) override {}
  int show_picture(int) override { return 4; }
  int picture_count() const override { return 3; }
  std::string describe() override { return ""; }
  bool change_level(int) override { return false; }
  bool change_volume(int) override { return false; }
  void new_session() override {}
  void show_document(int, int) override {}
  void forget_stick() override {}
};

TEST(EventLog, AVisitIsStartedAndFinishedInTheLog) {
  auto sink = std::make_shared<RecordingSink>();
  Quiet fx;
  {
    LoggerSwap swap(sink);
    KioskFlow flow(fx, audio::MessageCatalog::english());
    flow.key(KioskKey::Other, 10.0);  // wakes the kiosk
    flow.key(KioskKey::Finish, 70.0);
    flow.key(KioskKey::Finish, 71.0);
  }
  std::vector<std::string> visit_lines;
  for (const auto& [e, text] : sink->lines) {
    if (e == KioskEvent::visit_started || e == KioskEvent::visit_finished)
      visit_lines.push_back(std::string(kiosk_event_name(e)) + ": " + text);
  }
  EXPECT_EQ(visit_lines, (std::vector<std::string>{"visit_started: visit: started",
                                                   "visit_finished: visit: finished after 61 s, 0 copies made"}));
}

}  // namespace
}  // namespace hk::app
