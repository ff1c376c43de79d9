// USB sticks coming and going: block events pushed by hand (FakeBlockEventSource) or from libudev's monitor
// (UdevBlockEventSource); see usb_stick.hpp.

#include <libudev.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <mutex>
#include <string_view>
#include <utility>

#include "sticks/usb_stick.hpp"

namespace hk::sticks {

// ---------------------------------------------------------------------------------------------------
// FakeBlockEventSource

struct FakeBlockEventSource::Queue {
  std::mutex mutex;
  std::condition_variable ready;
  std::deque<BlockEvent> events;
};

std::shared_ptr<FakeBlockEventSource::Queue> FakeBlockEventSource::make_queue() { return std::make_shared<Queue>(); }

void FakeBlockEventSource::push(BlockEvent e) {
  {
    std::lock_guard lock(q_->mutex);
    q_->events.push_back(std::move(e));
  }
  q_->ready.notify_one();
}

std::optional<BlockEvent> FakeBlockEventSource::next(int timeout_ms) {
  std::unique_lock lock(q_->mutex);
  const auto has_event = [this] { return !q_->events.empty(); };
  if (timeout_ms < 0) {
    q_->ready.wait(lock, has_event);
  } else if (!q_->ready.wait_for(lock, std::chrono::milliseconds(timeout_ms), has_event)) {
    return std::nullopt;
  }
  BlockEvent e = std::move(q_->events.front());
  q_->events.pop_front();
  return e;
}

// ---------------------------------------------------------------------------------------------------
// UdevBlockEventSource

namespace {

std::string property(udev_device* dev, const char* key) {
  const char* v = udev_device_get_property_value(dev, key);
  return v != nullptr ? std::string(v) : std::string();
}

/// A USB block device that carries a filesystem, or a USB partition.
bool is_usb_stick(udev_device* dev) {
  if (property(dev, "ID_BUS") != "usb") return false;
  const char* devtype = udev_device_get_devtype(dev);
  const bool partition = devtype != nullptr && std::string_view(devtype) == "partition";
  return property(dev, "ID_FS_USAGE") == "filesystem" || partition;
}

std::optional<BlockEvent> to_event(udev_device* dev, BlockEvent::Action action) {
  const char* node = udev_device_get_devnode(dev);
  if (node == nullptr || !is_usb_stick(dev)) return std::nullopt;
  BlockEvent e;
  e.action = action;
  e.devnode = node;
  e.label = property(dev, "ID_FS_LABEL");
  return e;
}

}  // namespace

struct UdevBlockEventSource::Impl {
  udev* ctx = nullptr;
  udev_monitor* monitor = nullptr;
  int fd = -1;
  std::deque<BlockEvent> pending;  ///< sticks found by the enumeration at construction

  ~Impl() {
    if (monitor != nullptr) udev_monitor_unref(monitor);
    if (ctx != nullptr) udev_unref(ctx);
  }

  void enumerate() {
    udev_enumerate* en = udev_enumerate_new(ctx);
    if (en == nullptr) return;
    udev_enumerate_add_match_subsystem(en, "block");
    udev_enumerate_add_match_property(en, "ID_BUS", "usb");
    if (udev_enumerate_scan_devices(en) >= 0) {
      udev_list_entry* entry = nullptr;
      udev_list_entry_foreach(entry, udev_enumerate_get_list_entry(en)) {
        udev_device* dev = udev_device_new_from_syspath(ctx, udev_list_entry_get_name(entry));
        if (dev == nullptr) continue;
        if (auto e = to_event(dev, BlockEvent::Action::Add)) pending.push_back(std::move(*e));
        udev_device_unref(dev);
      }
    }
    udev_enumerate_unref(en);
  }
};

UdevBlockEventSource::UdevBlockEventSource() : impl_(std::make_unique<Impl>()) {
  const std::string who = "stick monitor";
  // Without udevd, libudev quietly opens a monitor that never receives anything (events carry ID_BUS
  // only once udevd has processed them): say so instead of waiting forever.
  if (::access("/run/udev/control", F_OK) != 0) {
    throw StickMountError(who + ": udev is not running (no /run/udev/control), so USB sticks would never be seen");
  }
  impl_->ctx = udev_new();
  if (impl_->ctx == nullptr) throw StickMountError(who + ": cannot start libudev: " + std::strerror(errno));
  impl_->monitor = udev_monitor_new_from_netlink(impl_->ctx, "udev");
  if (impl_->monitor == nullptr)
    throw StickMountError(who + ": cannot open the udev netlink socket: " + std::strerror(errno));
  if (udev_monitor_filter_add_match_subsystem_devtype(impl_->monitor, "block", nullptr) < 0 ||
      udev_monitor_enable_receiving(impl_->monitor) < 0) {
    throw StickMountError(who + ": cannot listen to udev block events: " + std::strerror(errno));
  }
  impl_->fd = udev_monitor_get_fd(impl_->monitor);
  if (impl_->fd < 0) throw StickMountError(who + ": the udev monitor has no socket");
  // Enumerate after the monitor listens, so a stick inserted in between is not lost (it may be reported
  // twice; consumers treat a second Add of a mounted devnode as nothing new).
  impl_->enumerate();
}

UdevBlockEventSource::~UdevBlockEventSource() = default;

std::optional<BlockEvent> UdevBlockEventSource::next(int timeout_ms) {
  if (!impl_->pending.empty()) {
    BlockEvent e = std::move(impl_->pending.front());
    impl_->pending.pop_front();
    return e;
  }
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::milliseconds(timeout_ms < 0 ? 0 : timeout_ms);
  for (;;) {
    int wait_ms = -1;
    if (timeout_ms >= 0) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      wait_ms = left > 0 ? static_cast<int>(left) : 0;
    }
    pollfd p{impl_->fd, POLLIN, 0};
    const int n = ::poll(&p, 1, wait_ms);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return std::nullopt;
    udev_device* dev = udev_monitor_receive_device(impl_->monitor);
    if (dev != nullptr) {
      std::optional<BlockEvent> e;
      const char* action = udev_device_get_action(dev);
      if (action != nullptr && std::string_view(action) == "add") e = to_event(dev, BlockEvent::Action::Add);
      if (action != nullptr && std::string_view(action) == "remove") e = to_event(dev, BlockEvent::Action::Remove);
      udev_device_unref(dev);
      if (e) return e;
    }
  }
}

}  // namespace hk::sticks
