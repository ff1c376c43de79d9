// The metrics endpoint under a scrape load far above a Prometheus's (100 requests/s on localhost, a fresh
// connection each, for 10 s) while the kiosk runs headless: its servo thread at 1 kHz on the simulated
// pantograph, the window thread played at 60 Hz (the runtime's poll once a frame, which publishes the servo's
// totals to the metrics). Timed: each request from connect to the end of the answer (p50, p99, max), and the
// servo's missed deadlines over the same 10 s without the load and with it.
// Usage: bench_metrics_endpoint [--out FILE.md] [--seconds S]
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "runtime_ticks.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"

using namespace hk;
using namespace hk::app;
using Clock = std::chrono::steady_clock;

namespace {

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

/// One GET /metrics on a fresh connection; its bytes (0 on failure).
std::size_t scrape(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::size_t got = 0;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) {
    const std::string req = "GET /metrics HTTP/1.1\r\nHost: kiosk\r\nConnection: close\r\n\r\n";
    (void)!::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
    std::array<char, 16384> buf;
    for (;;) {
      const ssize_t n = ::recv(fd, buf.data(), buf.size(), 0);
      if (n <= 0) break;
      got += static_cast<std::size_t>(n);
    }
  }
  ::close(fd);
  return got;
}

struct Window {
  std::int64_t missed = 0, ticks = 0;
};

/// Plays the window thread for `seconds` [s]; the servo's missed deadlines and ticks meanwhile.
Window play(KioskRuntime& rt, KioskFlow& flow, double seconds, double& now_s) {
  const ServoThread::Totals t0 = rt.devices().servo()->totals();
  const Clock::time_point end =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  while (Clock::now() < end) {
    const Clock::time_point f0 = Clock::now();
    rt.poll(&flow, now_s);
    rt.poll_after_input();
    now_s += 1.0 / 60.0;
    std::this_thread::sleep_until(f0 + std::chrono::microseconds(16667));
  }
  const ServoThread::Totals t1 = rt.devices().servo()->totals();
  return {t1.missed_deadlines - t0.missed_deadlines, t1.ticks - t0.ticks};
}

}  // namespace

int main(int argc, char** argv) {
  std::string out;
  double seconds = 10.0;
  CLI::App cli("GET /metrics at 100 requests/s while the kiosk runs");
  cli.add_option("--out", out, "Write the table (Markdown) to this file too");
  cli.add_option("--seconds", seconds, "Seconds of each window, without and with the load")->check(CLI::PositiveNumber);
  CLI11_PARSE(cli, argc, argv);
  spdlog::set_level(spdlog::level::warn);
  config::Settings s;
  s.kiosk.names_dir = "off";
  s.metrics.listen = "127.0.0.1:0";
  KioskRuntime rt(hk::test::headless_runtime_options(HK_SHIPPED_PICTURES_DIR), s);
  rt.start_servo();
  KioskFlow flow(rt.effects(), rt.audio().messages(), flow_params_from(s, false));
  double now_s = 0.0;
  play(rt, flow, 1.0, now_s);  // settle
  const Window quiet = play(rt, flow, seconds, now_s);

  std::vector<double> lat_ms;
  std::atomic<bool> stop{false};
  std::size_t bytes = 0;
  int failed = 0;
  std::thread client([&] {
    Clock::time_point next = Clock::now();
    while (!stop) {
      const Clock::time_point t0 = Clock::now();
      const std::size_t n = scrape(rt.metrics_port());
      lat_ms.push_back(ms_between(t0, Clock::now()));
      if (n == 0) ++failed;
      bytes = n;
      next += std::chrono::milliseconds(10);  // 100 requests/s
      std::this_thread::sleep_until(next);
    }
  });
  const Window loaded = play(rt, flow, seconds, now_s);
  stop = true;
  client.join();
  std::sort(lat_ms.begin(), lat_ms.end());
  auto pct = [&](double p) { return lat_ms[static_cast<std::size_t>(p * static_cast<double>(lat_ms.size() - 1))]; };
  char md[2048];
  std::snprintf(md, sizeof md,
                "# The metrics endpoint under load\n\n"
                "`build/bench/bench_metrics_endpoint` (bench/metrics_endpoint.cpp): GET /metrics on a fresh connection "
                "100 times a second for %.0f s on localhost, while the kiosk runs headless (servo at 1 kHz, window "
                "thread at 60 Hz). Target: p99 <= 5 ms, and no change in the servo's missed deadlines.\n\n"
                "| requests | failed | answer [bytes] | p50 [ms] | p99 [ms] | max [ms] |\n|---|---|---|---|---|---|\n"
                "| %zu | %d | %zu | %.3f | %.3f | %.3f |\n\n"
                "| servo over %.0f s | ticks | missed deadlines |\n|---|---|---|\n"
                "| without the load | %lld | %lld |\n| with the load | %lld | %lld |\n",
                seconds, lat_ms.size(), failed, bytes, pct(0.5), pct(0.99), lat_ms.back(), seconds,
                static_cast<long long>(quiet.ticks), static_cast<long long>(quiet.missed),
                static_cast<long long>(loaded.ticks), static_cast<long long>(loaded.missed));
  std::fputs(md, stdout);
  if (!out.empty()) std::ofstream(out) << md;
  return 0;
}
