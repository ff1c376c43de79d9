// Ring + eventfd waits (byte_channel.hpp).
#include "haptics/io/byte_channel.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>

namespace hk::io {
namespace {

std::int64_t now_us() noexcept {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void signal_fd(int fd) noexcept {
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t r = ::write(fd, &one, sizeof one);  // EAGAIN only at counter overflow
}

void drain_fd(int fd) noexcept {
  std::uint64_t v;
  [[maybe_unused]] const ssize_t r = ::read(fd, &v, sizeof v);
}

// ppoll for POLLIN on fd, at most until deadline_us; EINTR returns early (callers loop on the deadline).
void wait_readable(int fd, std::int64_t deadline_us) noexcept {
  const std::int64_t left = std::max<std::int64_t>(0, deadline_us - now_us());
  pollfd p{fd, POLLIN, 0};
  timespec ts{static_cast<time_t>(left / 1000000), static_cast<long>((left % 1000000) * 1000)};
  ::ppoll(&p, 1, &ts, nullptr);
}

}  // namespace

ByteChannel::ByteChannel(std::size_t capacity_bytes) : ring_(capacity_bytes) {
  data_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  space_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (data_fd_ < 0 || space_fd_ < 0) {
    const int e = errno;
    if (data_fd_ >= 0) ::close(data_fd_);
    if (space_fd_ >= 0) ::close(space_fd_);
    throw DeviceError(std::string("byte channel: eventfd: ") + std::strerror(e));
  }
}

ByteChannel::~ByteChannel() {
  ::close(data_fd_);
  ::close(space_fd_);
}

std::size_t ByteChannel::push(const std::uint8_t* src, std::size_t n) noexcept {
  const std::size_t k = ring_.push(src, n);
  if (k > 0) signal_fd(data_fd_);
  return k;
}

int ByteChannel::push_wait(const std::uint8_t* src, int n, int timeout_us) noexcept {
  if (closed()) return -1;
  if (n <= 0) return 0;
  const std::int64_t deadline = now_us() + std::max(0, timeout_us);
  auto total = push(src, static_cast<std::size_t>(n));
  while (total < static_cast<std::size_t>(n) && !closed() && now_us() < deadline) {
    drain_fd(space_fd_);  // drain, re-check, then wait
    const auto more = push(src + total, static_cast<std::size_t>(n) - total);
    if (more > 0) {
      total += more;
      continue;
    }
    wait_readable(space_fd_, deadline);
  }
  return total == 0 && closed() ? -1 : static_cast<int>(total);
}

std::size_t ByteChannel::pop(std::uint8_t* dst, std::size_t n) noexcept {
  const std::size_t k = ring_.pop(dst, n);
  if (k > 0) signal_fd(space_fd_);
  return k;
}

int ByteChannel::pop_wait(std::uint8_t* dst, int n, int timeout_us) noexcept {
  if (n <= 0) return 0;
  const std::int64_t deadline = now_us() + std::max(0, timeout_us);
  for (;;) {
    drain_fd(data_fd_);
    const auto k = pop(dst, static_cast<std::size_t>(n));
    if (k > 0) return static_cast<int>(k);
    if (closed()) {  // bytes pushed just before close() are still returned first
      const auto last = pop(dst, static_cast<std::size_t>(n));
      return last > 0 ? static_cast<int>(last) : -1;
    }
    if (now_us() >= deadline) return 0;
    wait_readable(data_fd_, deadline);
  }
}

void ByteChannel::clear() noexcept {
  ring_.clear();
  signal_fd(space_fd_);
}

void ByteChannel::close() noexcept {
  closed_.store(true, std::memory_order_release);
  signal_fd(data_fd_);
  signal_fd(space_fd_);
}

void ByteChannel::drain_data_signal() noexcept { drain_fd(data_fd_); }

}  // namespace hk::io
