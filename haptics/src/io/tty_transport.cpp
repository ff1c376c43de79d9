// ByteTransport over a POSIX tty (tty_transport.hpp).
#include "haptics/io/tty_transport.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace hk::io {
namespace {

struct BaudEntry {
  int baud;
  speed_t speed;
};
constexpr BaudEntry kBauds[] = {
    {9600, B9600},       {19200, B19200},     {38400, B38400},     {57600, B57600},     {115200, B115200},
    {230400, B230400},   {460800, B460800},   {500000, B500000},   {576000, B576000},   {921600, B921600},
    {1000000, B1000000}, {1152000, B1152000}, {1500000, B1500000}, {2000000, B2000000}, {2500000, B2500000},
    {3000000, B3000000}, {3500000, B3500000}, {4000000, B4000000},
};

speed_t speed_of(int baud) {
  for (const auto& e : kBauds) {
    if (e.baud == baud) return e.speed;
  }
  return B0;
}

std::int64_t now_us() noexcept {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Waits for `events` on fd until deadline_us (steady clock). Returns revents, 0 on timeout.
short wait_fd(int fd, short events, std::int64_t deadline_us) noexcept {
  for (;;) {
    const std::int64_t left = std::max<std::int64_t>(0, deadline_us - now_us());
    pollfd p{fd, events, 0};
    timespec ts{static_cast<time_t>(left / 1000000), static_cast<long>((left % 1000000) * 1000)};
    const int r = ::ppoll(&p, 1, &ts, nullptr);
    if (r > 0) return p.revents;
    if (r == 0) return 0;
    if (errno != EINTR) return POLLERR;
  }
}

constexpr short kHangup = POLLHUP | POLLERR | POLLNVAL;

bool gone_errno(int e) noexcept { return e == EIO || e == ENXIO || e == ENODEV || e == EPIPE || e == EBADF; }

}  // namespace

TtyTransport::TtyTransport(std::string path, int baud) : path_(std::move(path)), baud_(baud) {
  if (baud == 1200) {
    throw DeviceError("tty " + path_ +
                      ": baud 1200 refused (the 1200 baud touch resets SAMD boards into the bootloader)");
  }
  if (speed_of(baud) == B0) {
    throw DeviceError("tty " + path_ + ": baud " + std::to_string(baud) +
                      " is not a standard termios rate (9600..4000000, not 1200)");
  }
}

TtyTransport::~TtyTransport() { close(); }

void TtyTransport::open() {
  if (fd_ >= 0) return;
  const int fd = ::open(path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    throw DeviceError("tty " + path_ + ": " + std::strerror(errno) + " (open)");
  }
  auto fail = [&](const char* step) {
    const int e = errno;
    ::close(fd);
    throw DeviceError("tty " + path_ + ": " + std::strerror(e) + " (" + step + ")");
  };
  if (::ioctl(fd, TIOCEXCL) != 0) fail("ioctl TIOCEXCL");
  termios t{};
  if (::tcgetattr(fd, &t) != 0) fail("tcgetattr");
  ::cfmakeraw(&t);
  t.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | CSTOPB | CRTSCTS);
  t.c_cflag |= CS8 | CLOCAL | CREAD;
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  if (::cfsetispeed(&t, speed_of(baud_)) != 0 || ::cfsetospeed(&t, speed_of(baud_)) != 0) fail("cfsetspeed");
  if (::tcsetattr(fd, TCSANOW, &t) != 0) fail("tcsetattr");
  ::tcflush(fd, TCIOFLUSH);
  fd_ = fd;
}

void TtyTransport::close() noexcept {
  if (fd_ < 0) return;
  ::ioctl(fd_, TIOCNXCL);
  ::close(fd_);
  fd_ = -1;
}

int TtyTransport::write(const std::uint8_t* data, int n, int timeout_us) noexcept {
  if (fd_ < 0) return kGone;
  if (n <= 0) return 0;
  const std::int64_t deadline = now_us() + std::max(0, timeout_us);
  int done = 0;
  while (done < n) {
    const ssize_t w = ::write(fd_, data + done, static_cast<std::size_t>(n - done));
    if (w > 0) {
      done += static_cast<int>(w);
      continue;
    }
    if (w < 0 && errno == EINTR) continue;
    if (w < 0 && errno != EAGAIN) return gone_errno(errno) ? (done > 0 ? done : kGone) : done;
    if (now_us() >= deadline) break;
    const short ev = wait_fd(fd_, POLLOUT, deadline);
    if (ev & kHangup) return done > 0 ? done : kGone;
    if (ev == 0) break;
  }
  return done;
}

int TtyTransport::read(std::uint8_t* buf, int capacity, int timeout_us) noexcept {
  if (fd_ < 0) return kGone;
  if (capacity <= 0) return 0;
  // With VMIN=0 VTIME=0 the tty returns 0 both for "no data" and after a hangup, so poll first and
  // tell them apart by POLLHUP/POLLERR.
  const short ev = wait_fd(fd_, POLLIN, now_us() + std::max(0, timeout_us));
  if (ev == 0) return 0;
  if (ev & POLLNVAL) return kGone;
  if (ev & POLLIN) {
    for (;;) {
      const ssize_t r = ::read(fd_, buf, static_cast<std::size_t>(capacity));
      if (r > 0) return static_cast<int>(r);
      if (r < 0 && errno == EINTR) continue;
      if (r < 0 && gone_errno(errno)) return kGone;
      break;
    }
  }
  return (ev & kHangup) ? kGone : 0;
}

void TtyTransport::flush_input() noexcept {
  if (fd_ >= 0) ::tcflush(fd_, TCIFLUSH);
}

std::string TtyTransport::name() const { return "tty " + path_; }

std::vector<std::string> list_serial_by_id() { return list_serial_by_id("/dev/serial/by-id"); }

std::vector<std::string> list_serial_by_id(const std::string& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    out.push_back(it->path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace hk::io
