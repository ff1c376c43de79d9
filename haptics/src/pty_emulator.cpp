/// @file pty_emulator.cpp
/// FirmwareEmulator on a pseudo-terminal. See pty_emulator.hpp.

#include "haptics/pty_emulator.hpp"

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <string>

#include "haptics/device.hpp"

namespace hk::hapi {

namespace {

void make_raw(int fd) {
  termios tio{};
  if (tcgetattr(fd, &tio) != 0) throw hk::DeviceError(std::string("pty emulator: tcgetattr: ") + std::strerror(errno));
  cfmakeraw(&tio);
  if (tcsetattr(fd, TCSANOW, &tio) != 0) {
    throw hk::DeviceError(std::string("pty emulator: tcsetattr: ") + std::strerror(errno));
  }
}

/// Writes all n bytes to fd, waiting (poll, 1 ms slices) while the pty buffer is full. Gives up when
/// stop is set or on an error other than EINTR/EAGAIN.
void write_all_fd(int fd, const std::uint8_t* p, int n, const std::atomic<bool>& stop) {
  while (n > 0 && !stop.load(std::memory_order_relaxed)) {
    const ssize_t w = ::write(fd, p, static_cast<std::size_t>(n));
    if (w > 0) {
      p += w;
      n -= static_cast<int>(w);
    } else if (w < 0 && (errno == EINTR || errno == EAGAIN)) {
      pollfd pfd{fd, POLLOUT, 0};
      ::poll(&pfd, 1, 1);
    } else {
      return;
    }
  }
}

}  // namespace

PtyEmulator::PtyEmulator(FirmwareEmulator& emulator) : emulator_(emulator) {
  char name[256] = {};
  if (::openpty(&master_fd_, &slave_fd_, name, nullptr, nullptr) != 0) {
    throw hk::DeviceError(std::string("pty emulator: openpty: ") + std::strerror(errno));
  }
  try {
    make_raw(slave_fd_);
    make_raw(master_fd_);
    const int flags = ::fcntl(master_fd_, F_GETFL);
    if (flags < 0 || ::fcntl(master_fd_, F_SETFL, flags | O_NONBLOCK) != 0) {
      throw hk::DeviceError(std::string("pty emulator: fcntl: ") + std::strerror(errno));
    }
  } catch (...) {
    ::close(master_fd_);
    ::close(slave_fd_);
    throw;
  }
  path_ = name;
  thread_ = std::thread([this] { run(); });
}

PtyEmulator::~PtyEmulator() {
  stop();
  if (master_fd_ >= 0) ::close(master_fd_);
  if (slave_fd_ >= 0) ::close(slave_fd_);
}

std::string PtyEmulator::device_path() const { return path_; }

void PtyEmulator::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void PtyEmulator::with_emulator(const std::function<void(FirmwareEmulator&)>& f) {
  const std::lock_guard<std::mutex> lock(mutex_);
  f(emulator_);
}

void PtyEmulator::run() {
  std::uint8_t in[512];
  std::uint8_t out[512];
  while (!stop_.load(std::memory_order_relaxed)) {
    pollfd pfd{master_fd_, POLLIN, 0};
    const int r = ::poll(&pfd, 1, 1);
    int got = 0;
    if (r > 0 && (pfd.revents & POLLIN)) {
      const ssize_t n = ::read(master_fd_, in, sizeof in);
      if (n > 0) got = static_cast<int>(n);
    }
    for (;;) {
      int n_out = 0;
      {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (got > 0) {
          emulator_.receive(in, got);
          got = 0;
        }
        n_out = emulator_.take_output(out, static_cast<int>(sizeof out));
      }
      if (n_out <= 0) break;
      write_all_fd(master_fd_, out, n_out, stop_);
    }
  }
}

}  // namespace hk::hapi
