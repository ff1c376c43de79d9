#pragma once
/// @file event_log.hpp
/// What happens at a kiosk, as a museum's tools see it: log lines that carry one event word (`HK_EVENT=` in the
/// journal) besides their message, so `journalctl -t haptic-kiosk HK_EVENT=device_lost` finds every lost handle of a
/// fleet gathered by systemd-journal-remote, and a query or alert can count visits without parsing sentences.
/// Counts only: no event carries anything a visitor said, chose or brought (a stick's file names stay out).
///
/// | HK_EVENT | when | priority |
/// |---|---|---|
/// | `kiosk_started` | the kiosk's window is up, the servo running | info |
/// | `visit_started` | a visitor woke the kiosk (key or handle) | info |
/// | `visit_finished` | goodbye: Finish pressed twice or the time-out; message: its length and pictures seen | info |
/// | `stick_inserted` | a USB stick was read; message: documents and problems counted | info |
/// | `stick_refused` | a USB stick could not be read | warning |
/// | `copy_made` | a take-home copy was printed or saved on the visitor's stick | info |
/// | `copy_failed` | a take-home copy reached neither | warning |
/// | `device_connected` | the pantograph answered (at start, or back after a loss) | info |
/// | `device_lost` | the pantograph stopped answering | warning |
/// | `settings_applied` | the operator applied settings at the panel | info |
/// | `settings_refused` | settings (a file, or the panel's values) were refused | warning |
///
/// The journal itself: journal_sink() sends each line with sd_journal_sendv (libsystemd) when standard error is the
/// journal's stream (stderr_is_journal: the kiosk runs under its systemd unit); elsewhere lines go to standard error
/// as before, the event's word after the level ("[info] [visit_started] …").

#include <spdlog/common.h>
#include <spdlog/sinks/sink.h>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace hk::app {

/// An event of the table above; `none` for an ordinary log line.
enum class KioskEvent : std::uint8_t {
  none,
  kiosk_started,
  visit_started,
  visit_finished,
  stick_inserted,
  stick_refused,
  copy_made,
  copy_failed,
  device_connected,
  device_lost,
  settings_applied,
  settings_refused,
};
inline constexpr int kKioskEventCount = 12;  ///< none included

/// The event's word ("visit_started"; "" for none).
const char* kiosk_event_name(KioskEvent e);

/// Logs `message` (one line) at `level` with `e` attached (the journal's HK_EVENT; "[word] " on standard error), and
/// counts it in kiosk_metrics() (metrics.hpp: visits, sticks, copies, settings applied; refusals, failures and lost
/// devices as errors). Not for the servo thread (spdlog allocates and locks).
void log_event(KioskEvent e, spdlog::level::level_enum level, std::string_view message);

/// The event of the line being logged on this thread: `e` inside log_event, `none` otherwise (the sinks read it).
KioskEvent event_being_logged();

/// The journal's fields for one line, each "KEY=value": MESSAGE, PRIORITY (syslog's: critical 2, error 3, warning 4,
/// info 6, debug and trace 7), SYSLOG_IDENTIFIER (`identifier`), HK_EVENT when `e` is not none. A message's line
/// breaks become spaces (one line a message).
std::vector<std::string> journal_fields(std::string_view message, spdlog::level::level_enum level, KioskEvent e,
                                        std::string_view identifier = "haptic-kiosk");

/// Whether standard error is connected to the journal: $JOURNAL_STREAM ("DEVICE:INODE", set by systemd) names the
/// device and inode of file descriptor 2.
bool stderr_is_journal();

/// A sink that sends each line to the journal with journal_fields (sd_journal_sendv). Thread-safe.
std::shared_ptr<spdlog::sinks::sink> journal_sink();

/// A sink for standard error, in colour where it is a terminal, that puts the event's word after the level of a line
/// that has one ("[…] [warning] [device_lost] device: …"). Thread-safe.
std::shared_ptr<spdlog::sinks::sink> stderr_event_sink();

/// The process's default logger: to the journal when stderr_is_journal(), else to standard error (stderr_event_sink),
/// named "haptic-kiosk". Call once at start, before other threads log.
void use_kiosk_logger();

}  // namespace hk::app
