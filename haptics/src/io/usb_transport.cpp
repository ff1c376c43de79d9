// CDC-ACM over libusb with an event thread and SPSC byte rings (usb_transport.hpp).
#include "haptics/io/usb_transport.hpp"

#include <libusb.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>

#include "haptics/io/byte_channel.hpp"
#include "haptics/io/usb_cdc.hpp"

namespace hk::io {
static_assert(ByteTransport::kGone == -1, "ByteChannel returns -1 for a closed channel");
namespace {

constexpr unsigned kControlTimeoutMs = 1000;
constexpr int kOutTransferBytes = 4096;
constexpr int kMaxConsecutiveErrors = 8;
constexpr auto kCancelWait = std::chrono::seconds(2);

std::string vidpid(std::uint16_t vid, std::uint16_t pid) {
  char s[16];
  std::snprintf(s, sizeof s, "%04x:%04x", vid, pid);
  return s;
}

std::string usb_error(const char* call, int code) {
  return std::string(call) + ": " + libusb_error_name(code) + " (" + libusb_strerror(code) + ")";
}

void signal_fd(int fd) noexcept {
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t r = ::write(fd, &one, sizeof one);
}

void drain_fd(int fd) noexcept {
  std::uint64_t v;
  [[maybe_unused]] const ssize_t r = ::read(fd, &v, sizeof v);
}

}  // namespace

struct UsbCdcTransport::Impl {
  struct Slot {
    Impl* impl = nullptr;
    libusb_transfer* t = nullptr;
    bool active = false;  // submitted, callback pending (event thread only once it runs)
  };

  libusb_context* ctx = nullptr;
  libusb_device_handle* h = nullptr;
  CdcEndpoints ep;
  int bus = 0, address = 0;
  bool claimed_control = false, claimed_data = false;
  ByteChannel in{kRingBytes};   // event thread → caller
  ByteChannel out{kRingBytes};  // caller → event thread (its data_fd() wakes the event thread)
  int wake_fd = -1;             // stop and pollfd changes
  int in_transfer_bytes = kInTransferBytes;
  std::unique_ptr<std::uint8_t[]> in_bufs, out_buf;
  Slot in_slots[kInTransfers];
  Slot out_slot;
  int in_flight = 0;  // event thread (and open() before the thread starts)
  int consecutive_errors = 0;
  std::atomic<bool> gone{false}, stop{false}, fds_changed{true};
  std::atomic<std::uint64_t> dropped{0};
  bool leaked = false;  // transfers still pending after close gave up waiting: never freed
  std::thread thread;

  ~Impl() { teardown(); }

  void mark_gone() noexcept {
    gone.store(true, std::memory_order_release);
    out.close();  // first: a reader that sees kGone from `in` then also gets kGone from write()
    in.close();
  }

  bool submit(Slot& s) noexcept {
    const int r = libusb_submit_transfer(s.t);
    if (r != 0) {
      mark_gone();  // LIBUSB_ERROR_NO_DEVICE, or the endpoint is unusable: either way the stream is over
      return false;
    }
    s.active = true;
    ++in_flight;
    return true;
  }

  // Event thread: moves bytes from the out ring into the OUT transfer when it is idle.
  void kick_out() noexcept {
    if (out_slot.active || stop.load(std::memory_order_relaxed) || gone.load(std::memory_order_relaxed)) return;
    const std::size_t n = out.pop(out_buf.get(), kOutTransferBytes);  // wakes a writer waiting for room
    if (n == 0) return;
    out_slot.t->length = static_cast<int>(n);
    submit(out_slot);
  }

  static void LIBUSB_CALL on_in(libusb_transfer* t) {
    auto* s = static_cast<Slot*>(t->user_data);
    Impl& m = *s->impl;
    s->active = false;
    --m.in_flight;
    switch (t->status) {
      case LIBUSB_TRANSFER_COMPLETED: {
        const auto n = static_cast<std::size_t>(t->actual_length);
        const std::size_t pushed = m.in.push(t->buffer, n);  // wakes a waiting reader
        if (pushed < n) m.dropped.fetch_add(n - pushed, std::memory_order_relaxed);
        m.consecutive_errors = 0;
        break;
      }
      case LIBUSB_TRANSFER_CANCELLED:
        return;
      case LIBUSB_TRANSFER_NO_DEVICE:
        m.mark_gone();
        return;
      default:  // ERROR, STALL, OVERFLOW, TIMED_OUT: retry a few times, then give up
        if (++m.consecutive_errors > kMaxConsecutiveErrors) {
          m.mark_gone();
          return;
        }
        break;
    }
    if (!m.stop.load(std::memory_order_relaxed) && !m.gone.load(std::memory_order_relaxed)) m.submit(*s);
  }

  static void LIBUSB_CALL on_out(libusb_transfer* t) {
    auto* s = static_cast<Slot*>(t->user_data);
    Impl& m = *s->impl;
    s->active = false;
    --m.in_flight;
    if (t->status == LIBUSB_TRANSFER_NO_DEVICE) {
      m.mark_gone();
      return;
    }
    if (t->status != LIBUSB_TRANSFER_COMPLETED && t->status != LIBUSB_TRANSFER_CANCELLED &&
        ++m.consecutive_errors > kMaxConsecutiveErrors) {
      m.mark_gone();
      return;
    }
    m.kick_out();
  }

  static void LIBUSB_CALL on_pollfd_added(int, short, void* user) {
    auto* m = static_cast<Impl*>(user);
    m->fds_changed.store(true, std::memory_order_release);
    signal_fd(m->wake_fd);
  }
  static void LIBUSB_CALL on_pollfd_removed(int, void* user) { on_pollfd_added(0, 0, user); }

  void event_loop() {
    std::vector<pollfd> fds;
    bool own_poll = true, cancelled = false;
    auto cancel_deadline = std::chrono::steady_clock::now();
    for (;;) {
      if (fds_changed.exchange(false, std::memory_order_acq_rel)) {
        fds.assign({pollfd{wake_fd, POLLIN, 0}, pollfd{out.data_fd(), POLLIN, 0}});
        const libusb_pollfd** list = libusb_get_pollfds(ctx);
        own_poll = list != nullptr;
        for (int i = 0; list != nullptr && list[i] != nullptr; ++i) fds.push_back({list[i]->fd, list[i]->events, 0});
        libusb_free_pollfds(list);
      }
      if (stop.load(std::memory_order_acquire) && !cancelled) {
        for (Slot& s : in_slots) {
          if (s.active) libusb_cancel_transfer(s.t);
        }
        if (out_slot.active) libusb_cancel_transfer(out_slot.t);
        cancelled = true;
        cancel_deadline = std::chrono::steady_clock::now() + kCancelWait;
      }
      if (cancelled && (in_flight == 0 || std::chrono::steady_clock::now() > cancel_deadline)) {
        leaked = in_flight != 0;
        return;
      }
      int timeout_ms = 100;
      timeval next{};
      if (libusb_get_next_timeout(ctx, &next) == 1) {
        timeout_ms = std::min<int>(timeout_ms, static_cast<int>(next.tv_sec * 1000 + (next.tv_usec + 999) / 1000));
      }
      if (own_poll) {
        for (auto& p : fds) p.revents = 0;
        ::poll(fds.data(), fds.size(), timeout_ms);
        if (fds[0].revents & POLLIN) drain_fd(wake_fd);
        if (fds[1].revents & POLLIN) out.drain_data_signal();  // kick_out() below re-checks the ring
        timeval zero{0, 0};
        libusb_handle_events_timeout_completed(ctx, &zero, nullptr);
      } else {  // platforms without pollfds: let libusb wait, bounded to 1 ms so writes are picked up
        out.drain_data_signal();
        timeval tv{0, 1000};
        libusb_handle_events_timeout_completed(ctx, &tv, nullptr);
      }
      kick_out();
    }
  }

  void teardown() noexcept {
    if (thread.joinable()) {
      stop.store(true, std::memory_order_release);
      signal_fd(wake_fd);
      thread.join();
    }
    if (h != nullptr) {
      if (claimed_control && !gone.load()) {  // drop DTR/RTS, best effort
        libusb_control_transfer(h, kCdcRequestTypeOut, kCdcSetControlLineState, 0,
                                static_cast<std::uint16_t>(ep.control_interface), nullptr, 0, 200);
      }
      if (claimed_data) libusb_release_interface(h, ep.data_interface);
      if (claimed_control) libusb_release_interface(h, ep.control_interface);
      claimed_control = claimed_data = false;
    }
    if (!leaked) {
      for (Slot& s : in_slots) {
        if (s.t != nullptr) libusb_free_transfer(s.t);
        s.t = nullptr;
      }
      if (out_slot.t != nullptr) libusb_free_transfer(out_slot.t);
      out_slot.t = nullptr;
    }
    if (h != nullptr) libusb_close(h);
    h = nullptr;
    if (wake_fd >= 0) ::close(wake_fd);
    wake_fd = -1;
    if (ctx != nullptr && !leaked) {
      libusb_set_pollfd_notifiers(ctx, nullptr, nullptr, nullptr);
      libusb_exit(ctx);
    }
    ctx = nullptr;
  }

  // The phases of UsbCdcTransport::open, in order (each defined below with what it does).
  void start_libusb(std::uint16_t vid, std::uint16_t pid);
  void open_device(std::uint16_t vid, std::uint16_t pid, const std::string& serial, const std::string& who);
  int active_config_index(const std::string& here);
  void read_cdc_endpoints(const std::string& here);
  void set_up_line(int baud, const std::string& here);
  void allocate_transfers(const std::string& here);
  void start_reading(const std::string& here);
};

// The phases of UsbCdcTransport::open, in order. Each throws DeviceError naming the device and the libusb call
// that failed; what a phase leaves behind is undone by ~Impl (teardown), so a failed open leaks nothing.

// Starts this transport's own libusb context.
void UsbCdcTransport::Impl::start_libusb(std::uint16_t vid, std::uint16_t pid) {
  if (const int r = libusb_init(&ctx); r != 0) {
    ctx = nullptr;
    throw DeviceError("no USB device " + vidpid(vid, pid) + " found (" + usb_error("libusb_init", r) + ")");
  }
}

// Opens the first device with this vendor and product id (and this serial string, when one is asked for), so
// that two boards of one kind can be told apart; notes its bus and address for the messages that follow.
void UsbCdcTransport::Impl::open_device(std::uint16_t vid, std::uint16_t pid, const std::string& serial,
                                        const std::string& who) {
  libusb_device** list = nullptr;
  const ssize_t count = libusb_get_device_list(ctx, &list);
  if (count < 0) throw DeviceError(who + ": " + usb_error("libusb_get_device_list", static_cast<int>(count)));
  std::string open_error;
  for (ssize_t i = 0; i < count && h == nullptr; ++i) {
    libusb_device_descriptor desc{};
    if (libusb_get_device_descriptor(list[i], &desc) != 0 || desc.idVendor != vid || desc.idProduct != pid) continue;
    libusb_device_handle* opened = nullptr;
    if (const int r = libusb_open(list[i], &opened); r != 0) {
      open_error = usb_error("libusb_open", r);
      continue;
    }
    if (!serial.empty()) {
      unsigned char s[256];
      const int n =
          desc.iSerialNumber ? libusb_get_string_descriptor_ascii(opened, desc.iSerialNumber, s, sizeof s) : 0;
      if (n <= 0 || std::string(reinterpret_cast<char*>(s), static_cast<std::size_t>(n)) != serial) {
        libusb_close(opened);
        continue;
      }
    }
    h = opened;
    bus = libusb_get_bus_number(list[i]);
    address = libusb_get_device_address(list[i]);
  }
  libusb_free_device_list(list, 1);  // the handle keeps its own reference to the device
  if (h == nullptr) {
    const std::string what = serial.empty() ? vidpid(vid, pid) : vidpid(vid, pid) + " serial " + serial;
    if (!open_error.empty()) throw DeviceError(who + ": " + open_error);
    throw DeviceError("no USB device " + what + " found");
  }
}

// The index of the device's active configuration among its configurations (GET_DESCRIPTOR takes an index, the
// active configuration is known by its value); 0 when none matches.
int UsbCdcTransport::Impl::active_config_index(const std::string& here) {
  libusb_device* dev = libusb_get_device(h);
  libusb_config_descriptor* active = nullptr;
  if (const int r = libusb_get_active_config_descriptor(dev, &active); r != 0) {
    throw DeviceError(here + ": " + usb_error("libusb_get_active_config_descriptor", r));
  }
  const std::uint8_t value = active->bConfigurationValue;
  libusb_free_config_descriptor(active);
  libusb_device_descriptor desc{};
  libusb_get_device_descriptor(dev, &desc);
  for (int i = 0; i < desc.bNumConfigurations; ++i) {
    libusb_config_descriptor* c = nullptr;
    if (libusb_get_config_descriptor(dev, static_cast<std::uint8_t>(i), &c) != 0) continue;
    const bool match = c->bConfigurationValue == value;
    libusb_free_config_descriptor(c);
    if (match) return i;
  }
  return 0;
}

// Reads the raw bytes of the active configuration and finds the CDC-ACM function's interfaces and bulk endpoints in
// them (find_cdc_endpoints), after letting libusb detach any kernel driver from the interfaces it claims.
void UsbCdcTransport::Impl::read_cdc_endpoints(const std::string& here) {
  if (const int r = libusb_set_auto_detach_kernel_driver(h, 1); r != 0 && r != LIBUSB_ERROR_NOT_SUPPORTED) {
    throw DeviceError(here + ": " + usb_error("libusb_set_auto_detach_kernel_driver", r));
  }
  const int config_index = active_config_index(here);
  std::vector<std::uint8_t> raw(4096);
  const int raw_n = libusb_get_descriptor(h, LIBUSB_DT_CONFIG, static_cast<std::uint8_t>(config_index), raw.data(),
                                          static_cast<int>(raw.size()));
  if (raw_n < 0) throw DeviceError(here + ": " + usb_error("libusb_get_descriptor(CONFIGURATION)", raw_n));
  try {
    ep = find_cdc_endpoints(raw.data(), raw_n);
  } catch (const DeviceError& e) {
    throw DeviceError(here + ": " + e.what());
  }
}

// Claims both interfaces and sets the line as a serial port's open would: the line coding for `baud`, then DTR and
// RTS raised.
void UsbCdcTransport::Impl::set_up_line(int baud, const std::string& here) {
  if (const int r = libusb_claim_interface(h, ep.control_interface); r != 0) {
    throw DeviceError(here + ": " + usb_error("libusb_claim_interface(control)", r));
  }
  claimed_control = true;
  if (const int r = libusb_claim_interface(h, ep.data_interface); r != 0) {
    throw DeviceError(here + ": " + usb_error("libusb_claim_interface(data)", r));
  }
  claimed_data = true;
  auto coding = line_coding_bytes(baud);
  const auto ctl_if = static_cast<std::uint16_t>(ep.control_interface);
  if (const int r = libusb_control_transfer(h, kCdcRequestTypeOut, kCdcSetLineCoding, 0, ctl_if, coding.data(),
                                            static_cast<std::uint16_t>(coding.size()), kControlTimeoutMs);
      r < 0) {
    throw DeviceError(here + ": " + usb_error("SET_LINE_CODING", r));
  }
  if (const int r = libusb_control_transfer(h, kCdcRequestTypeOut, kCdcSetControlLineState, kCdcDtr | kCdcRts, ctl_if,
                                            nullptr, 0, kControlTimeoutMs);
      r < 0) {
    throw DeviceError(here + ": " + usb_error("SET_CONTROL_LINE_STATE", r));
  }
}

// Everything the real-time path needs, allocated now: the wake-up eventfd, the IN transfers and their buffers (a
// whole number of packets each, at least one: a short buffer would overflow on a full packet), the OUT transfer.
void UsbCdcTransport::Impl::allocate_transfers(const std::string& here) {
  wake_fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (wake_fd < 0) throw DeviceError(here + ": eventfd: " + std::strerror(errno));
  const int mps_in = ep.max_packet_in;
  in_transfer_bytes = std::max(mps_in, kInTransferBytes / mps_in * mps_in);
  in_bufs = std::make_unique<std::uint8_t[]>(static_cast<std::size_t>(kInTransfers) * in_transfer_bytes);
  out_buf = std::make_unique<std::uint8_t[]>(kOutTransferBytes);
  for (int i = 0; i < kInTransfers; ++i) {
    Slot& s = in_slots[i];
    s.impl = this;
    s.t = libusb_alloc_transfer(0);
    if (s.t == nullptr) throw DeviceError(here + ": libusb_alloc_transfer failed");
    libusb_fill_bulk_transfer(s.t, h, ep.bulk_in, in_bufs.get() + i * in_transfer_bytes, in_transfer_bytes,
                              &Impl::on_in, &s, 0);
  }
  out_slot.impl = this;
  out_slot.t = libusb_alloc_transfer(0);
  if (out_slot.t == nullptr) throw DeviceError(here + ": libusb_alloc_transfer failed");
  libusb_fill_bulk_transfer(out_slot.t, h, ep.bulk_out, out_buf.get(), 0, &Impl::on_out, &out_slot, 0);
  out_slot.t->flags = LIBUSB_TRANSFER_ADD_ZERO_PACKET;
}

// Submits every IN transfer and starts the event thread that reaps them. When a submit fails, the ones submitted
// are cancelled and the thread still starts, to reap them, before the error is thrown.
void UsbCdcTransport::Impl::start_reading(const std::string& here) {
  libusb_set_pollfd_notifiers(ctx, &Impl::on_pollfd_added, &Impl::on_pollfd_removed, this);
  for (Slot& s : in_slots) {
    if (!submit(s)) {
      for (Slot& o : in_slots) {
        if (o.active) libusb_cancel_transfer(o.t);
      }
      thread = std::thread([p = this] { p->event_loop(); });  // reaps the cancelled transfers
      throw DeviceError(here + ": libusb_submit_transfer(bulk IN) failed");
    }
  }
  thread = std::thread([p = this] { p->event_loop(); });
}

UsbCdcTransport::UsbCdcTransport(std::uint16_t vid, std::uint16_t pid, int baud, std::string serial)
    : vid_(vid), pid_(pid), baud_(baud), serial_(std::move(serial)) {
  try {
    (void)line_coding_bytes(baud);
  } catch (const DeviceError& e) {
    throw DeviceError("usb " + vidpid(vid, pid) + ": " + e.what());
  }
}

UsbCdcTransport::~UsbCdcTransport() { close(); }

void UsbCdcTransport::open() {
  if (impl_) return;
  const std::string who = "usb " + vidpid(vid_, pid_);
  auto m = std::make_unique<Impl>();
  m->start_libusb(vid_, pid_);
  m->open_device(vid_, pid_, serial_, who);
  const std::string here = who + " bus " + std::to_string(m->bus) + " addr " + std::to_string(m->address);
  m->read_cdc_endpoints(here);
  m->set_up_line(baud_, here);
  m->allocate_transfers(here);
  m->start_reading(here);
  impl_ = std::move(m);
}

void UsbCdcTransport::close() noexcept { impl_.reset(); }

bool UsbCdcTransport::is_open() const noexcept { return impl_ != nullptr; }

int UsbCdcTransport::write(const std::uint8_t* data, int n, int timeout_us) noexcept {
  Impl* m = impl_.get();
  if (m == nullptr) return kGone;
  return m->out.push_wait(data, n, timeout_us);  // -1 == kGone once the device is gone
}

int UsbCdcTransport::read(std::uint8_t* buf, int capacity, int timeout_us) noexcept {
  Impl* m = impl_.get();
  if (m == nullptr) return kGone;
  return m->in.pop_wait(buf, capacity, timeout_us);  // received bytes first, then -1 == kGone
}

void UsbCdcTransport::flush_input() noexcept {
  if (impl_) impl_->in.clear();
}

std::string UsbCdcTransport::name() const {
  std::string s = "usb " + vidpid(vid_, pid_);
  if (impl_) s += " bus " + std::to_string(impl_->bus) + " addr " + std::to_string(impl_->address);
  return s;
}

std::uint64_t UsbCdcTransport::dropped_in_bytes() const noexcept {
  return impl_ ? impl_->dropped.load(std::memory_order_relaxed) : 0;
}

}  // namespace hk::io
