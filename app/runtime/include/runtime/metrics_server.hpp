#pragma once
/// @file metrics_server.hpp
/// The metrics endpoint ([metrics] listen): GET /metrics answered with the text a Render gives (KioskMetrics::
/// exposition), served by GNU libmicrohttpd on one thread of its own, so neither the servo nor the window thread
/// ever waits on a client.
///
/// | request | answer |
/// |---|---|
/// | `GET /metrics` (or HEAD) | 200, `text/plain; version=0.0.4; charset=utf-8` |
/// | another method on /metrics | 405, `Allow: GET, HEAD` |
/// | another path | 404 |
/// | a request line and headers over 8 KiB | refused by the library (4xx) or the connection closed |
/// | connections over 16 open at once | closed as soon as accepted (the rest wait in the kernel's backlog of 16) |
/// | a connection idle for 10 s | closed, so held-open connections free their places |
///
/// libmicrohttpd rather than cpp-httplib: cpp-httplib 0.11 (Debian 12) queues every accepted connection for its
/// worker pool and has no way to close the ones over a limit, which is what a flood of held-open connections must
/// meet here.

#include <functional>
#include <string>

struct MHD_Daemon;

namespace hk::app {

/// Serves GET /metrics until destroyed. Thread-safe to destroy from the thread that made it.
class MetricsServer {
 public:
  /// The text of one answer (called on the server's thread for each GET; must be thread-safe).
  using Render = std::function<std::string()>;
  /// Connections open at once; more are closed as they come.
  static constexpr unsigned kMaxConnections = 16;
  /// Largest request line and headers read [bytes].
  static constexpr std::size_t kMaxRequestBytes = 8192;
  /// A connection that sends nothing for this long is closed [s].
  static constexpr unsigned kIdleTimeout_s = 10;

  /// Starts listening on `listen`: "ADDRESS:PORT" as [metrics] listen takes it (a numeric IPv4 address, or an IPv6
  /// one in brackets); port 0 picks a free port (tests; port() says which).
  /// @throws AppError (one line naming `listen`) when it does not parse or cannot be bound.
  MetricsServer(const std::string& listen, Render render);
  ~MetricsServer();
  MetricsServer(const MetricsServer&) = delete;
  MetricsServer& operator=(const MetricsServer&) = delete;

  /// The port listened on.
  int port() const { return port_; }
  /// The text of one answer (the server's thread).
  std::string render() const { return render_(); }

 private:
  Render render_;
  MHD_Daemon* daemon_ = nullptr;
  int port_ = 0;
};

}  // namespace hk::app
