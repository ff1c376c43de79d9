// Log lines with an event word, to the journal or standard error (event_log.hpp).
#include "runtime/event_log.hpp"
#include "runtime/metrics.hpp"

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <sys/uio.h>

#define SD_JOURNAL_SUPPRESS_LOCATION  // CODE_FILE / CODE_LINE would name this file, not the caller
#include <systemd/sd-journal.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <mutex>

namespace hk::app {
namespace {

thread_local KioskEvent t_event = KioskEvent::none;

constexpr std::array<const char*, kKioskEventCount> kNames{
    "",          "kiosk_started", "visit_started",    "visit_finished", "stick_inserted",   "stick_refused",
    "copy_made", "copy_failed",   "device_connected", "device_lost",    "settings_applied", "settings_refused",
};

/// syslog's priority for an spdlog level.
int priority_of(spdlog::level::level_enum level) {
  switch (level) {
    case spdlog::level::critical:
      return 2;
    case spdlog::level::err:
      return 3;
    case spdlog::level::warn:
      return 4;
    case spdlog::level::info:
      return 6;
    default:
      return 7;
  }
}

/// Each line to the journal.
class JournalSink final : public spdlog::sinks::base_sink<std::mutex> {
 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    const std::vector<std::string> fields =
        journal_fields(std::string_view(msg.payload.data(), msg.payload.size()), msg.level, event_being_logged());
    std::vector<iovec> iov;
    iov.reserve(fields.size());
    for (const std::string& f : fields) iov.push_back({const_cast<char*>(f.data()), f.size()});
    (void)sd_journal_sendv(iov.data(), static_cast<int>(iov.size()));  // nowhere to say that the journal is gone
  }
  void flush_() override {}
};

/// The pattern flag %* : "[word] " for a line with an event, nothing otherwise.
class EventFlag final : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg&, const std::tm&, spdlog::memory_buf_t& dest) override {
    const KioskEvent e = event_being_logged();
    if (e == KioskEvent::none) return;
    const std::string word = std::string("[") + kiosk_event_name(e) + "] ";
    dest.append(word.data(), word.data() + word.size());
  }
  std::unique_ptr<custom_flag_formatter> clone() const override { return std::make_unique<EventFlag>(); }
};

}  // namespace

const char* kiosk_event_name(KioskEvent e) {
  const auto i = static_cast<std::size_t>(e);
  return i < kNames.size() ? kNames[i] : "";
}

namespace {

/// The metrics an event counts (metrics.hpp).
void count_event(KioskEvent e) {
  KioskMetrics& m = kiosk_metrics();
  switch (e) {
    case KioskEvent::visit_started:
      return m.add(KioskCount::visits_started);
    case KioskEvent::visit_finished:
      return m.add(KioskCount::visits_finished);
    case KioskEvent::stick_inserted:
      return m.add(KioskCount::sticks_read);
    case KioskEvent::stick_refused:
      return m.error(KioskError::stick_refused);
    case KioskEvent::copy_made:
      return m.add(KioskCount::copies_made);
    case KioskEvent::copy_failed:
      return m.error(KioskError::copy_failed);
    case KioskEvent::device_lost:
      return m.error(KioskError::device_lost);
    case KioskEvent::settings_applied:
      return m.add(KioskCount::settings_applied);
    case KioskEvent::settings_refused:
      return m.error(KioskError::settings_refused);
    case KioskEvent::none:
    case KioskEvent::kiosk_started:
    case KioskEvent::device_connected:
      return;
  }
}

}  // namespace

void log_event(KioskEvent e, spdlog::level::level_enum level, std::string_view message) {
  count_event(e);
  const KioskEvent before = t_event;
  t_event = e;
  spdlog::log(level, "{}", message);
  t_event = before;
}

KioskEvent event_being_logged() { return t_event; }

std::vector<std::string> journal_fields(std::string_view message, spdlog::level::level_enum level, KioskEvent e,
                                        std::string_view identifier) {
  std::string text(message);
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  std::vector<std::string> out{"MESSAGE=" + text, "PRIORITY=" + std::to_string(priority_of(level)),
                               "SYSLOG_IDENTIFIER=" + std::string(identifier)};
  if (e != KioskEvent::none) out.push_back(std::string("HK_EVENT=") + kiosk_event_name(e));
  return out;
}

bool stderr_is_journal() {
  const char* stream = std::getenv("JOURNAL_STREAM");
  if (stream == nullptr) return false;
  unsigned long long dev = 0, ino = 0;
  if (std::sscanf(stream, "%llu:%llu", &dev, &ino) != 2) return false;
  struct stat st {};
  return ::fstat(2, &st) == 0 && static_cast<unsigned long long>(st.st_dev) == dev &&
         static_cast<unsigned long long>(st.st_ino) == ino;
}

std::shared_ptr<spdlog::sinks::sink> journal_sink() { return std::make_shared<JournalSink>(); }

std::shared_ptr<spdlog::sinks::sink> stderr_event_sink() {
  auto formatter = std::make_unique<spdlog::pattern_formatter>();
  formatter->add_flag<EventFlag>('*').set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%^%l%$] %*%v");
  auto sink = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  sink->set_formatter(std::move(formatter));
  return sink;
}

void use_kiosk_logger() {
  auto logger =
      std::make_shared<spdlog::logger>("haptic-kiosk", stderr_is_journal() ? journal_sink() : stderr_event_sink());
  logger->set_level(spdlog::get_level());
  spdlog::set_default_logger(std::move(logger));
}

}  // namespace hk::app
