// Fake libusb for test_haptics_io_fakeusb (fake_libusb.hpp).
#include "fake_libusb.hpp"

#include <libusb.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <mutex>
#include <set>

struct libusb_context {
  int unused = 0;
};
struct libusb_device {
  int unused = 0;
};
struct libusb_device_handle {
  libusb_device* dev = nullptr;
};

namespace {

struct State {
  std::mutex mu;
  std::condition_variable cv;
  fake_usb::Options opt;
  libusb_device device;
  std::vector<fake_usb::ControlRequest> requests;
  std::set<int> claimed;
  bool auto_detach = false, unplugged = false;
  int transfers = 0, contexts = 0, handles = 0;
  std::deque<libusb_transfer*> pending;  // submitted, not completed
  std::set<libusb_transfer*> cancelled;  // cancel requested
  std::deque<std::uint8_t> to_host;      // device → host bytes not yet delivered
  std::vector<std::uint8_t> from_host;   // host → device bytes
  int event_fd = -1;                     // readable when there is something to complete
  libusb_pollfd pollfd{};
};

State& st() {
  static State s;
  return s;
}

void poke() {
  const std::uint64_t one = 1;
  [[maybe_unused]] ssize_t r = ::write(st().event_fd, &one, sizeof one);
}

}  // namespace

namespace fake_usb {

void reset(const Options& o) {
  State& s = st();
  std::lock_guard<std::mutex> l(s.mu);
  s.opt = o;
  s.requests.clear();
  s.claimed.clear();
  s.auto_detach = s.unplugged = false;
  s.pending.clear();
  s.cancelled.clear();
  s.to_host.clear();
  s.from_host.clear();
  if (s.event_fd < 0) s.event_fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  s.pollfd.fd = s.event_fd;
  s.pollfd.events = POLLIN;
}

void device_send(const std::vector<std::uint8_t>& bytes) {
  {
    std::lock_guard<std::mutex> l(st().mu);
    st().to_host.insert(st().to_host.end(), bytes.begin(), bytes.end());
  }
  poke();
}

std::vector<std::uint8_t> wait_host_bytes(std::size_t n, int timeout_ms) {
  State& s = st();
  std::unique_lock<std::mutex> l(s.mu);
  s.cv.wait_for(l, std::chrono::milliseconds(timeout_ms), [&] { return s.from_host.size() >= n; });
  return s.from_host;
}

void unplug() {
  {
    std::lock_guard<std::mutex> l(st().mu);
    st().unplugged = true;
  }
  poke();
}

std::vector<ControlRequest> class_requests() {
  std::lock_guard<std::mutex> l(st().mu);
  return st().requests;
}
std::vector<int> claimed() {
  std::lock_guard<std::mutex> l(st().mu);
  return {st().claimed.begin(), st().claimed.end()};
}
bool auto_detach() {
  std::lock_guard<std::mutex> l(st().mu);
  return st().auto_detach;
}
int live_transfers() {
  std::lock_guard<std::mutex> l(st().mu);
  return st().transfers;
}
int live_contexts() {
  std::lock_guard<std::mutex> l(st().mu);
  return st().contexts;
}
int live_handles() {
  std::lock_guard<std::mutex> l(st().mu);
  return st().handles;
}

}  // namespace fake_usb

extern "C" {

int LIBUSB_CALL libusb_init(libusb_context** ctx) {
  std::lock_guard<std::mutex> l(st().mu);
  ++st().contexts;
  *ctx = new libusb_context;
  return 0;
}
void LIBUSB_CALL libusb_exit(libusb_context* ctx) {
  std::lock_guard<std::mutex> l(st().mu);
  --st().contexts;
  delete ctx;
}
const char* LIBUSB_CALL libusb_error_name(int code) {
  switch (code) {
    case LIBUSB_ERROR_ACCESS:
      return "LIBUSB_ERROR_ACCESS";
    case LIBUSB_ERROR_NO_DEVICE:
      return "LIBUSB_ERROR_NO_DEVICE";
    default:
      return "LIBUSB_ERROR_OTHER";
  }
}
const char* LIBUSB_CALL libusb_strerror(int) { return "fake"; }

ssize_t LIBUSB_CALL libusb_get_device_list(libusb_context*, libusb_device*** list) {
  auto** l = static_cast<libusb_device**>(std::calloc(2, sizeof(libusb_device*)));
  std::lock_guard<std::mutex> g(st().mu);
  if (st().opt.present) l[0] = &st().device;
  *list = l;
  return st().opt.present ? 1 : 0;
}
void LIBUSB_CALL libusb_free_device_list(libusb_device** list, int) { std::free(list); }

int LIBUSB_CALL libusb_get_device_descriptor(libusb_device*, libusb_device_descriptor* d) {
  std::lock_guard<std::mutex> l(st().mu);
  *d = {};
  d->bLength = 18;
  d->bDescriptorType = LIBUSB_DT_DEVICE;
  d->idVendor = st().opt.vid;
  d->idProduct = st().opt.pid;
  d->iSerialNumber = 3;
  d->bNumConfigurations = 1;
  return 0;
}
uint8_t LIBUSB_CALL libusb_get_bus_number(libusb_device*) { return 1; }
uint8_t LIBUSB_CALL libusb_get_device_address(libusb_device*) { return 5; }

int LIBUSB_CALL libusb_open(libusb_device* dev, libusb_device_handle** h) {
  std::lock_guard<std::mutex> l(st().mu);
  if (st().opt.open_error != 0) return st().opt.open_error;
  ++st().handles;
  *h = new libusb_device_handle{dev};
  return 0;
}
void LIBUSB_CALL libusb_close(libusb_device_handle* h) {
  std::lock_guard<std::mutex> l(st().mu);
  --st().handles;
  delete h;
}
libusb_device* LIBUSB_CALL libusb_get_device(libusb_device_handle* h) { return h->dev; }

int LIBUSB_CALL libusb_get_string_descriptor_ascii(libusb_device_handle*, uint8_t index, unsigned char* data,
                                                   int length) {
  std::lock_guard<std::mutex> l(st().mu);
  if (index != 3) return LIBUSB_ERROR_OTHER;
  const std::string& s = st().opt.serial;
  const int n = std::min<int>(length, static_cast<int>(s.size()));
  std::memcpy(data, s.data(), static_cast<std::size_t>(n));
  return n;
}

int LIBUSB_CALL libusb_set_auto_detach_kernel_driver(libusb_device_handle*, int enable) {
  std::lock_guard<std::mutex> l(st().mu);
  st().auto_detach = enable != 0;
  return 0;
}

int LIBUSB_CALL libusb_get_active_config_descriptor(libusb_device*, libusb_config_descriptor** c) {
  *c = static_cast<libusb_config_descriptor*>(std::calloc(1, sizeof(libusb_config_descriptor)));
  (*c)->bConfigurationValue = 1;
  return 0;
}
int LIBUSB_CALL libusb_get_config_descriptor(libusb_device* d, uint8_t, libusb_config_descriptor** c) {
  return libusb_get_active_config_descriptor(d, c);
}
void LIBUSB_CALL libusb_free_config_descriptor(libusb_config_descriptor* c) { std::free(c); }

int LIBUSB_CALL libusb_control_transfer(libusb_device_handle*, uint8_t request_type, uint8_t request, uint16_t value,
                                        uint16_t index, unsigned char* data, uint16_t length, unsigned int) {
  std::lock_guard<std::mutex> l(st().mu);
  if (st().unplugged) return LIBUSB_ERROR_NO_DEVICE;
  if (request_type == LIBUSB_ENDPOINT_IN && request == LIBUSB_REQUEST_GET_DESCRIPTOR &&
      value == (LIBUSB_DT_CONFIG << 8)) {
    const auto& c = st().opt.config_descriptor;
    const int n = std::min<int>(length, static_cast<int>(c.size()));
    std::memcpy(data, c.data(), static_cast<std::size_t>(n));
    return n;
  }
  st().requests.push_back(
      {request_type, request, value, index, std::vector<std::uint8_t>(data, data + (data ? length : 0))});
  return length;
}

int LIBUSB_CALL libusb_claim_interface(libusb_device_handle*, int n) {
  std::lock_guard<std::mutex> l(st().mu);
  st().claimed.insert(n);
  return 0;
}
int LIBUSB_CALL libusb_release_interface(libusb_device_handle*, int n) {
  std::lock_guard<std::mutex> l(st().mu);
  st().claimed.erase(n);
  return 0;
}

libusb_transfer* LIBUSB_CALL libusb_alloc_transfer(int iso) {
  std::lock_guard<std::mutex> l(st().mu);
  ++st().transfers;
  return static_cast<libusb_transfer*>(
      std::calloc(1, sizeof(libusb_transfer) + static_cast<std::size_t>(iso) * sizeof(libusb_iso_packet_descriptor)));
}
void LIBUSB_CALL libusb_free_transfer(libusb_transfer* t) {
  std::lock_guard<std::mutex> l(st().mu);
  --st().transfers;
  std::free(t);
}
int LIBUSB_CALL libusb_submit_transfer(libusb_transfer* t) {
  {
    std::lock_guard<std::mutex> l(st().mu);
    if (st().unplugged) return LIBUSB_ERROR_NO_DEVICE;
    st().pending.push_back(t);
  }
  poke();
  return 0;
}
int LIBUSB_CALL libusb_cancel_transfer(libusb_transfer* t) {
  {
    std::lock_guard<std::mutex> l(st().mu);
    if (std::find(st().pending.begin(), st().pending.end(), t) == st().pending.end()) return LIBUSB_ERROR_NOT_FOUND;
    st().cancelled.insert(t);
  }
  poke();
  return 0;
}

const libusb_pollfd** LIBUSB_CALL libusb_get_pollfds(libusb_context*) {
  auto** l = static_cast<const libusb_pollfd**>(std::calloc(2, sizeof(libusb_pollfd*)));
  l[0] = &st().pollfd;
  return l;
}
void LIBUSB_CALL libusb_free_pollfds(const libusb_pollfd** l) { std::free(l); }
void LIBUSB_CALL libusb_set_pollfd_notifiers(libusb_context*, libusb_pollfd_added_cb, libusb_pollfd_removed_cb, void*) {
}
int LIBUSB_CALL libusb_get_next_timeout(libusb_context*, timeval*) { return 0; }

// Completes what can be completed: cancelled → CANCELLED, unplugged → NO_DEVICE, OUT → COMPLETED (bytes
// appended to from_host), IN → COMPLETED when device bytes are queued. Callbacks run without the lock.
int LIBUSB_CALL libusb_handle_events_timeout_completed(libusb_context*, timeval*, int*) {
  std::vector<libusb_transfer*> done;
  {
    State& s = st();
    std::lock_guard<std::mutex> l(s.mu);
    std::uint64_t v;
    [[maybe_unused]] ssize_t r = ::read(s.event_fd, &v, sizeof v);
    for (auto it = s.pending.begin(); it != s.pending.end();) {
      libusb_transfer* t = *it;
      const bool in = (t->endpoint & LIBUSB_ENDPOINT_IN) != 0;
      if (s.cancelled.erase(t)) {
        t->status = LIBUSB_TRANSFER_CANCELLED;
        t->actual_length = 0;
      } else if (s.unplugged) {
        t->status = LIBUSB_TRANSFER_NO_DEVICE;
        t->actual_length = 0;
      } else if (!in) {
        s.from_host.insert(s.from_host.end(), t->buffer, t->buffer + t->length);
        t->status = LIBUSB_TRANSFER_COMPLETED;
        t->actual_length = t->length;
        s.cv.notify_all();
      } else if (!s.to_host.empty()) {
        const int n = std::min<int>(t->length, static_cast<int>(s.to_host.size()));
        std::copy_n(s.to_host.begin(), n, t->buffer);
        s.to_host.erase(s.to_host.begin(), s.to_host.begin() + n);
        t->status = LIBUSB_TRANSFER_COMPLETED;
        t->actual_length = n;
      } else {
        ++it;
        continue;
      }
      done.push_back(t);
      it = s.pending.erase(it);
    }
  }
  for (libusb_transfer* t : done) t->callback(t);
  return 0;
}

}  // extern "C"
