// The metrics endpoint (metrics_server.hpp).
#include "runtime/metrics_server.hpp"

#include <arpa/inet.h>
#include <microhttpd.h>
#include <netinet/in.h>

#include <cstring>

#include "formats/app_error.hpp"

namespace hk::app {
namespace {

constexpr const char* kPath = "/metrics";
constexpr const char* kContentType = "text/plain; version=0.0.4; charset=utf-8";

/// An answer with `body` (copied) and `status`, queued on `c`.
MHD_Result answer(MHD_Connection* c, unsigned status, const std::string& body, const char* content_type,
                  bool allow = false) {
  MHD_Response* r = MHD_create_response_from_buffer(body.size(), const_cast<char*>(body.data()), MHD_RESPMEM_MUST_COPY);
  if (!r) return MHD_NO;
  MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, content_type);
  if (allow) MHD_add_response_header(r, MHD_HTTP_HEADER_ALLOW, "GET, HEAD");
  const MHD_Result ok = MHD_queue_response(c, status, r);
  MHD_destroy_response(r);
  return ok;
}

MHD_Result on_request(void* cls, MHD_Connection* c, const char* url, const char* method, const char* /*version*/,
                      const char* /*upload_data*/, size_t* upload_size, void** /*req_cls*/) {
  const auto* server = static_cast<const MetricsServer*>(cls);
  *upload_size = 0;  // a body is never read: every answer below is final
  if (std::strcmp(url, kPath) != 0) return answer(c, MHD_HTTP_NOT_FOUND, "not found: only /metrics\n", "text/plain");
  const bool get = std::strcmp(method, MHD_HTTP_METHOD_GET) == 0, head = std::strcmp(method, MHD_HTTP_METHOD_HEAD) == 0;
  if (!get && !head) return answer(c, MHD_HTTP_METHOD_NOT_ALLOWED, "only GET\n", "text/plain", true);
  try {
    return answer(c, MHD_HTTP_OK, server->render(), kContentType);
  } catch (const std::exception& e) {
    return answer(c, MHD_HTTP_INTERNAL_SERVER_ERROR, std::string("metrics: ") + e.what() + "\n", "text/plain");
  }
}

/// `listen` as a socket address; false when it does not parse.
bool parse_listen(const std::string& listen, sockaddr_storage& addr, bool& v6) {
  const std::string::size_type colon = listen.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 >= listen.size() || listen.size() - colon > 6) return false;
  int port = 0;
  for (char ch : listen.substr(colon + 1)) {
    if (ch < '0' || ch > '9') return false;
    port = port * 10 + (ch - '0');
  }
  if (port > 65535) return false;
  std::string host = listen.substr(0, colon);
  std::memset(&addr, 0, sizeof addr);
  v6 = host.size() > 2 && host.front() == '[' && host.back() == ']';
  if (v6) {
    auto& a = reinterpret_cast<sockaddr_in6&>(addr);
    a.sin6_family = AF_INET6;
    a.sin6_port = htons(static_cast<std::uint16_t>(port));
    return inet_pton(AF_INET6, host.substr(1, host.size() - 2).c_str(), &a.sin6_addr) == 1;
  }
  auto& a = reinterpret_cast<sockaddr_in&>(addr);
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  return inet_pton(AF_INET, host.c_str(), &a.sin_addr) == 1;
}

}  // namespace

MetricsServer::MetricsServer(const std::string& listen, Render render) : render_(std::move(render)) {
  sockaddr_storage addr{};
  bool v6 = false;
  if (!parse_listen(listen, addr, v6))
    throw AppError("metrics: listen = \"" + listen + "\" is not ADDRESS:PORT (\"127.0.0.1:9471\", \"[::1]:9471\")");
  unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_EPOLL;
  if (v6) flags |= MHD_USE_IPv6;
  // The memory a connection may use holds its request line and headers; twice the limit leaves room for the
  // answer's own headers, so a request over kMaxRequestBytes is what runs out.
  daemon_ = MHD_start_daemon(flags, 0, nullptr, nullptr, &on_request, this, MHD_OPTION_SOCK_ADDR, &addr,
                             MHD_OPTION_CONNECTION_LIMIT, kMaxConnections, MHD_OPTION_CONNECTION_TIMEOUT,
                             kIdleTimeout_s, MHD_OPTION_CONNECTION_MEMORY_LIMIT, size_t{kMaxRequestBytes},
                             MHD_OPTION_LISTEN_BACKLOG_SIZE, kMaxConnections, MHD_OPTION_END);
  if (!daemon_) throw AppError("metrics: cannot listen on " + listen + " (in use, or not an address of this machine)");
  if (const MHD_DaemonInfo* info = MHD_get_daemon_info(daemon_, MHD_DAEMON_INFO_BIND_PORT)) port_ = info->port;
}

MetricsServer::~MetricsServer() {
  if (daemon_) MHD_stop_daemon(daemon_);
}

}  // namespace hk::app
