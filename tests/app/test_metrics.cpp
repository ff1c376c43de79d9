// The kiosk's metrics: the text a Prometheus scrapes (checked by promtool where it is installed), counters that only
// rise, and the endpoint's answers to good requests, bad ones and a flood of held-open connections.
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "runtime/event_log.hpp"
#include "runtime/metrics.hpp"
#include "runtime/metrics_server.hpp"
#include "runtime_ticks.hpp"
#include "temp_dir.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_flow.hpp"
#include "wait_until.hpp"

namespace {

using hk::app::KioskCount;
using hk::app::KioskError;
using hk::app::KioskMetrics;
using hk::app::KioskTiming;
using hk::app::MetricsServer;

/// The samples of an exposition: "name{labels}" → value. Comment lines are left out; a line that is neither is a
/// test failure.
std::map<std::string, double> samples(const std::string& text) {
  std::map<std::string, double> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const std::size_t space = line.rfind(' ');
    EXPECT_NE(space, std::string::npos) << line;
    if (space == std::string::npos) continue;
    const std::string v = line.substr(space + 1);
    out[line.substr(0, space)] = v == "+Inf" ? INFINITY : std::stod(v);
  }
  return out;
}

/// promtool's verdict on `text` ("" when it passes), or nullopt when promtool is not installed.
std::optional<std::string> promtool_check(const std::string& text) {
  if (std::system("command -v promtool > /dev/null 2>&1") != 0) return std::nullopt;
  hk::test::TempDir dir("hk_promtool");
  const std::string in = dir.path() + "/metrics.txt", out = dir.path() + "/out.txt";
  std::ofstream(in) << text;
  const int rc = std::system(("promtool check metrics < '" + in + "' > '" + out + "' 2>&1").c_str());
  std::ifstream f(out);
  std::string said((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  return rc == 0 ? std::string{} : "exit " + std::to_string(rc) + ": " + said;
}

TEST(KioskMetrics, TheExpositionPassesPromtoolAndNamesEveryMetricOfTheTable) {
  KioskMetrics m;
  m.set_device("haply", true);
  m.set_servo(5000, 2, 1000.0);
  m.add(KioskCount::visits_started);
  m.observe(KioskTiming::scene_build, 0.3);
  const std::string text = m.exposition("1.2.3");
  const std::optional<std::string> verdict = promtool_check(text);
  if (verdict) {
    EXPECT_EQ(*verdict, "") << text;
  }
  const auto s = samples(text);
  EXPECT_EQ(s.at("haptic_kiosk_build_info{version=\"1.2.3\"}"), 1);
  EXPECT_EQ(s.at("haptic_kiosk_device_connected{device=\"haply\"}"), 1);
  EXPECT_EQ(s.at("haptic_kiosk_servo_rate_hz"), 1000);
  EXPECT_EQ(s.at("haptic_kiosk_servo_ticks_total"), 5000);
  EXPECT_EQ(s.at("haptic_kiosk_servo_missed_deadlines_total"), 2);
  EXPECT_EQ(s.at("haptic_kiosk_visits_started_total"), 1);
  for (const char* name :
       {"haptic_kiosk_visits_finished_total", "haptic_kiosk_pictures_explored_total", "haptic_kiosk_sticks_read_total",
        "haptic_kiosk_copies_made_total", "haptic_kiosk_settings_applied_total", "haptic_kiosk_contact_seconds_total",
        "haptic_kiosk_library_pictures", "haptic_kiosk_errors_total{kind=\"device_lost\"}",
        "haptic_kiosk_errors_total{kind=\"visitor_action\"}", "haptic_kiosk_errors_total{kind=\"library_refused\"}"})
    EXPECT_EQ(s.count(name), 1u) << name;
  // The histogram, cumulative: 0.3 s lies in (0.25, 0.5].
  EXPECT_EQ(s.at("haptic_kiosk_scene_build_seconds_bucket{le=\"0.25\"}"), 0);
  EXPECT_EQ(s.at("haptic_kiosk_scene_build_seconds_bucket{le=\"0.5\"}"), 1);
  EXPECT_EQ(s.at("haptic_kiosk_scene_build_seconds_bucket{le=\"+Inf\"}"), 1);
  EXPECT_EQ(s.at("haptic_kiosk_scene_build_seconds_count"), 1);
  EXPECT_DOUBLE_EQ(s.at("haptic_kiosk_scene_build_seconds_sum"), 0.3);
  EXPECT_EQ(s.at("haptic_kiosk_ocr_seconds_count"), 0);
  // No visitor data: no label but the version, the device, the bucket bounds and the error kinds.
  for (const auto& [key, v] : s) {
    const std::size_t brace = key.find('{');
    if (brace == std::string::npos) continue;
    const std::string label = key.substr(brace + 1, key.find('=') - brace - 1);
    EXPECT_TRUE(label == "version" || label == "device" || label == "le" || label == "kind") << key;
  }
}

TEST(KioskMetrics, CountersOnlyRiseAcrossScrapesAndAServoStartedAnew) {
  KioskMetrics m;
  m.set_servo(10000, 3, 1000.0);
  m.add_contact(1.5);
  const auto before = samples(m.exposition("v"));
  m.set_servo(200, 0, 1000.0);  // the servo thread started again (a board plugged in): its totals start at 0
  m.add(KioskCount::pictures_explored);
  m.error(KioskError::picture_unreadable);
  m.observe(KioskTiming::ocr, 2.0);
  m.add_contact(0.25);
  m.add_contact(-1.0);  // ignored
  m.observe(KioskTiming::ocr, std::nan(""));
  const auto after = samples(m.exposition("v"));
  ASSERT_EQ(before.size(), after.size());
  for (const auto& [key, v] : before) {
    const bool rises = key.find("_total") != std::string::npos || key.find("_bucket") != std::string::npos ||
                       key.find("_sum") != std::string::npos || key.find("_count") != std::string::npos;
    if (rises) {
      EXPECT_GE(after.at(key), v) << key;
    }
  }
  EXPECT_EQ(after.at("haptic_kiosk_servo_ticks_total"), 10200);
  EXPECT_EQ(after.at("haptic_kiosk_servo_missed_deadlines_total"), 3);
  EXPECT_DOUBLE_EQ(after.at("haptic_kiosk_contact_seconds_total"), 1.75);
  EXPECT_EQ(after.at("haptic_kiosk_ocr_seconds_count"), 1);
  EXPECT_EQ(after.at("haptic_kiosk_errors_total{kind=\"picture_unreadable\"}"), 1);
}

TEST(KioskMetrics, TheJournalsEventsAreCounted) {
  KioskMetrics& m = hk::app::kiosk_metrics();
  const std::uint64_t visits = m.count(KioskCount::visits_started), lost = m.errors(KioskError::device_lost),
                      sticks = m.count(KioskCount::sticks_read);
  hk::app::log_event(hk::app::KioskEvent::visit_started, spdlog::level::info, "visit: started");
  hk::app::log_event(hk::app::KioskEvent::device_lost, spdlog::level::warn, "device: lost");
  EXPECT_EQ(m.count(KioskCount::visits_started), visits + 1);
  EXPECT_EQ(m.errors(KioskError::device_lost), lost + 1);
  EXPECT_EQ(m.count(KioskCount::sticks_read), sticks);
}

/// A connection to 127.0.0.1:`port` (blocking), or −1.
int connect_to(int port, bool nonblocking = false) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | (nonblocking ? SOCK_NONBLOCK : 0), 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 && !(nonblocking && errno == EINPROGRESS)) {
    ::close(fd);
    return -1;
  }
  return fd;
}

/// Sends `request` and reads the answer until the server closes (at most 10 s): the whole answer, "" when the
/// connection was closed without one.
std::string http_exchange(int port, const std::string& request) {
  const int fd = connect_to(port);
  if (fd < 0) return {};
  (void)!::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
  std::string out;
  std::array<char, 4096> buf;
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 10000) <= 0) break;
    const ssize_t n = ::recv(fd, buf.data(), buf.size(), 0);
    if (n <= 0) break;
    out.append(buf.data(), static_cast<std::size_t>(n));
  }
  ::close(fd);
  return out;
}

std::string get(const std::string& path, const std::string& method = "GET", const std::string& extra = "") {
  return method + " " + path + " HTTP/1.1\r\nHost: kiosk\r\nConnection: close\r\n" + extra + "\r\n";
}

int status_of(const std::string& answer) {
  if (answer.rfind("HTTP/1.1 ", 0) != 0) return 0;
  return std::stoi(answer.substr(9, 3));
}

TEST(MetricsServer, AnswersGetOfItsPathAndRefusesOtherMethodsPathsAndOversizedRequests) {
  int renders = 0;
  MetricsServer server("127.0.0.1:0", [&renders] {
    ++renders;
    return std::string("# TYPE haptic_kiosk_up gauge\nhaptic_kiosk_up 1\n");
  });
  ASSERT_GT(server.port(), 0);
  const std::string ok = http_exchange(server.port(), get("/metrics"));
  EXPECT_EQ(status_of(ok), 200) << ok;
  EXPECT_NE(ok.find("Content-Type: text/plain; version=0.0.4; charset=utf-8"), std::string::npos) << ok;
  EXPECT_NE(ok.find("\r\n\r\n# TYPE haptic_kiosk_up gauge\nhaptic_kiosk_up 1\n"), std::string::npos) << ok;
  const std::string post = http_exchange(server.port(), get("/metrics", "POST", "Content-Length: 3\r\n") + "a=b");
  EXPECT_EQ(status_of(post), 405) << post;
  EXPECT_NE(post.find("Allow: GET, HEAD"), std::string::npos) << post;
  EXPECT_EQ(status_of(http_exchange(server.port(), get("/metrics", "DELETE"))), 405);
  EXPECT_EQ(status_of(http_exchange(server.port(), get("/"))), 404);
  EXPECT_EQ(status_of(http_exchange(server.port(), get("/metrics/../etc/passwd"))), 404);
  EXPECT_EQ(renders, 1);  // only the GET rendered
  // A request over 8 KiB: refused with a 4xx, or the connection closed without an answer; never rendered.
  const std::string big =
      http_exchange(server.port(), get("/metrics", "GET", "X-Pad: " + std::string(9000, 'a') + "\r\n"));
  const int big_status = status_of(big);
  EXPECT_TRUE(big.empty() || (big_status >= 400 && big_status < 500)) << big.substr(0, 200);
  EXPECT_EQ(renders, 1);
  // And it still answers.
  EXPECT_EQ(status_of(http_exchange(server.port(), get("/metrics"))), 200);
}

TEST(MetricsServer, AListenThatDoesNotParseOrIsTakenIsOneLine) {
  for (const char* bad : {"9471", "localhost:9471", "127.0.0.1:99999", "[::1:9471"}) {
    try {
      MetricsServer s(bad, [] { return std::string{}; });
      ADD_FAILURE() << bad << " was taken";
    } catch (const std::exception& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(bad), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  MetricsServer first("127.0.0.1:0", [] { return std::string{}; });
  const std::string taken = "127.0.0.1:" + std::to_string(first.port());
  EXPECT_THROW(MetricsServer(taken, [] { return std::string{}; }), std::exception);
}

int open_fds() {
  int n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator("/proc/self/fd")) ++n;
  return n;
}

TEST(MetricsServer, AThousandHeldOpenConnectionsNeitherStopTheKioskNorItsServoNorHoldItsFiles) {
  hk::config::Settings s;
  s.metrics.listen = "127.0.0.1:0";  // any free port (the settings' own check wants a real one)
  s.kiosk.names_dir = "off";
  hk::app::RuntimeOptions ro = hk::test::headless_runtime_options(HK_SHIPPED_PICTURES_DIR);
  ro.probe_camera = false;
  hk::app::KioskRuntime rt(ro, s);
  const int port = rt.metrics_port();
  ASSERT_GT(port, 0);
  rt.start_servo();
  ASSERT_NE(rt.devices().servo(), nullptr);

  const int fds_before = open_fds();
  std::vector<int> held;
  for (int i = 0; i < 1000; ++i) {
    const int fd = connect_to(port, true);
    if (fd >= 0) held.push_back(fd);
  }
  ASSERT_GT(held.size(), 900u);
  // The kiosk goes on: its servo ticks, its frames run, and a flow key is answered.
  const std::int64_t ticks = rt.devices().servo()->totals().ticks;
  hk::app::KioskFlow flow(rt.effects(), rt.audio().messages(), hk::app::flow_params_from(s, false));
  double now_s = 0.0;
  flow.key(hk::app::KioskKey::Other, now_s);
  EXPECT_TRUE(hk::test::wait_until([&] { return rt.devices().servo()->totals().ticks > ticks + 500; },
                                   [&] { rt.poll(&flow, now_s += 0.02); }, 30.0));
  EXPECT_EQ(flow.view().state, hk::app::KioskState::Tutorial);
  // The server holds at most its limit of connections: the rest are the test's own sockets.
  const int server_side = open_fds() - fds_before - static_cast<int>(held.size());
  EXPECT_LE(server_side, static_cast<int>(MetricsServer::kMaxConnections) + 4) << server_side;
  for (int fd : held) ::close(fd);
  // Once they are gone, a scrape is answered again, with the servo's ticks in it.
  std::string answer;
  EXPECT_TRUE(hk::test::wait_until(
      [&] {
        answer = http_exchange(port, get("/metrics"));
        return status_of(answer) == 200;
      },
      [&] { rt.poll(&flow, now_s += 0.02); }, 30.0));
  const auto sm = samples(answer.substr(answer.find("\r\n\r\n") + 4));
  EXPECT_GT(sm.at("haptic_kiosk_servo_ticks_total"), 0);
  EXPECT_EQ(sm.at("haptic_kiosk_device_connected{device=\"simulated\"}"), 1);
  EXPECT_GE(sm.at("haptic_kiosk_visits_started_total"), 1);
}

}  // namespace
