// USB discovery through libusb (usb_devices.hpp).
#include "haptics/io/usb_devices.hpp"

#include <libusb.h>

#include <sys/time.h>

namespace hk::io {
namespace {

std::string usb_error(const char* call, int code) {
  return std::string(call) + ": " + libusb_error_name(code) + " (" + libusb_strerror(code) + ")";
}

std::string read_string(libusb_device_handle* h, std::uint8_t index) {
  if (h == nullptr || index == 0) return {};
  unsigned char buf[256];
  const int n = libusb_get_string_descriptor_ascii(h, index, buf, sizeof buf);
  return n > 0 ? std::string(reinterpret_cast<char*>(buf), static_cast<std::size_t>(n)) : std::string();
}

int LIBUSB_CALL on_hotplug(libusb_context*, libusb_device*, libusb_hotplug_event event, void* user) {
  auto* cb = static_cast<std::function<void(bool)>*>(user);
  if (*cb) (*cb)(event == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED);
  return 0;  // stay registered
}

}  // namespace

std::vector<UsbDeviceInfo> list_usb_devices(std::string* reason) {
  std::vector<UsbDeviceInfo> out;
  if (reason) reason->clear();
  libusb_context* ctx = nullptr;
  if (const int r = libusb_init(&ctx); r != 0) {
    if (reason) *reason = usb_error("libusb_init", r);
    return out;
  }
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(ctx, &list);
  if (n < 0) {
    if (reason) *reason = usb_error("libusb_get_device_list", static_cast<int>(n));
    libusb_exit(ctx);
    return out;
  }
  for (ssize_t i = 0; i < n; ++i) {
    libusb_device_descriptor desc{};
    if (libusb_get_device_descriptor(list[i], &desc) != 0) continue;
    UsbDeviceInfo info;
    info.vid = desc.idVendor;
    info.pid = desc.idProduct;
    info.bus = libusb_get_bus_number(list[i]);
    info.address = libusb_get_device_address(list[i]);
    libusb_device_handle* h = nullptr;
    if (libusb_open(list[i], &h) == 0) {  // fails without permission: strings stay empty
      info.manufacturer = read_string(h, desc.iManufacturer);
      info.product = read_string(h, desc.iProduct);
      info.serial = read_string(h, desc.iSerialNumber);
      libusb_close(h);
    }
    out.push_back(std::move(info));
  }
  libusb_free_device_list(list, 1);
  libusb_exit(ctx);
  return out;
}

UsbHotplugMonitor::UsbHotplugMonitor(std::uint16_t vid, int pid, std::function<void(bool)> on_change)
    : on_change_(std::move(on_change)) {
  libusb_context* ctx = nullptr;
  if (const int r = libusb_init(&ctx); r != 0) {
    reason_ = usb_error("libusb_init", r);
    return;
  }
  ctx_ = ctx;
  if (libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG) == 0) {
    reason_ = "libusb has no hotplug support on this platform (LIBUSB_CAP_HAS_HOTPLUG)";
    return;
  }
  libusb_hotplug_callback_handle handle = 0;
  const int r = libusb_hotplug_register_callback(
      ctx, static_cast<libusb_hotplug_event>(LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED | LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT),
      LIBUSB_HOTPLUG_ENUMERATE, vid, pid < 0 ? LIBUSB_HOTPLUG_MATCH_ANY : pid, LIBUSB_HOTPLUG_MATCH_ANY, &on_hotplug,
      &on_change_, &handle);
  if (r != LIBUSB_SUCCESS) {
    reason_ = usb_error("libusb_hotplug_register_callback", r);
    return;
  }
  handle_ = handle;
  supported_ = true;
  thread_ = std::thread([this, ctx] {
    while (!stop_.load(std::memory_order_acquire)) {
      timeval tv{0, 200000};  // bound: the destructor also interrupts the handler
      libusb_handle_events_timeout_completed(ctx, &tv, nullptr);
    }
  });
}

UsbHotplugMonitor::~UsbHotplugMonitor() {
  auto* ctx = static_cast<libusb_context*>(ctx_);
  if (thread_.joinable()) {
    stop_.store(true, std::memory_order_release);
    libusb_hotplug_deregister_callback(ctx, handle_);
    libusb_interrupt_event_handler(ctx);
    thread_.join();
  }
  if (ctx != nullptr) libusb_exit(ctx);
}

}  // namespace hk::io
