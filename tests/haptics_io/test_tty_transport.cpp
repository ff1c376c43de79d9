// TtyTransport against a pseudo-terminal (openpty): bytes both ways, timeouts, hang-up, exclusivity,
// errors naming the path, and the refused 1200 baud.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <pty.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "haptics/io/tty_transport.hpp"

namespace hk::io {
namespace {

using Clock = std::chrono::steady_clock;

long elapsed_us(Clock::time_point t0) {
  return static_cast<long>(std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - t0).count());
}

// A pty pair: the transport opens the slave by path, the test plays the device on the master.
struct Pty {
  int master = -1;
  std::string slave_path;
  Pty() {
    int slave = -1;
    char name[256] = {};
    if (openpty(&master, &slave, name, nullptr, nullptr) != 0) return;
    // raw on the master side too, so bytes pass unchanged (no echo, no CR/LF mapping)
    termios t{};
    tcgetattr(slave, &t);
    cfmakeraw(&t);
    tcsetattr(slave, TCSANOW, &t);
    ::close(slave);
    slave_path = name;
    fcntl(master, F_SETFL, fcntl(master, F_GETFL) | O_NONBLOCK);
  }
  ~Pty() {
    if (master >= 0) ::close(master);
  }
  bool ok() const { return master >= 0; }
  // Reads exactly n bytes from the master (bounded by 2 s of polling for the data to arrive).
  std::vector<std::uint8_t> read_master(std::size_t n) const {
    std::vector<std::uint8_t> out;
    const auto t0 = Clock::now();
    while (out.size() < n && Clock::now() - t0 < std::chrono::seconds(2)) {
      pollfd p{master, POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      std::uint8_t buf[256];
      const ssize_t r = ::read(master, buf, std::min(sizeof buf, n - out.size()));
      if (r > 0) out.insert(out.end(), buf, buf + r);
    }
    return out;
  }
};

TEST(TtyTransport, BytesBothWays) {
  Pty pty;
  ASSERT_TRUE(pty.ok()) << "openpty failed: " << std::strerror(errno);
  TtyTransport t(pty.slave_path);
  EXPECT_FALSE(t.is_open());
  t.open();
  EXPECT_TRUE(t.is_open());
  EXPECT_EQ(t.name(), "tty " + pty.slave_path);

  const std::vector<std::uint8_t> to_device = {0x00, 0x0A, 0x0D, 0xFF, 0x03, 0x11, 0x13, 0x7F};  // no tty mangling
  ASSERT_EQ(t.write(to_device.data(), static_cast<int>(to_device.size()), 100000), 8);
  EXPECT_EQ(pty.read_master(8), to_device);

  const std::vector<std::uint8_t> from_device = {0x04, 0x1A, 0x0A, 0x0D, 0x00, 0x80};
  ASSERT_EQ(::write(pty.master, from_device.data(), from_device.size()), 6);
  std::vector<std::uint8_t> got;
  std::uint8_t buf[16];
  while (got.size() < from_device.size()) {
    const int n = t.read(buf, sizeof buf, 1000000);
    ASSERT_GT(n, 0) << "no byte within 1 s";
    got.insert(got.end(), buf, buf + n);
  }
  EXPECT_EQ(got, from_device);
}

TEST(TtyTransport, ReadTimesOutWithZeroBytes) {
  Pty pty;
  ASSERT_TRUE(pty.ok());
  TtyTransport t(pty.slave_path);
  t.open();
  std::uint8_t buf[8];
  EXPECT_EQ(t.read(buf, sizeof buf, 0), 0);
  const auto t0 = Clock::now();
  EXPECT_EQ(t.read(buf, sizeof buf, 20000), 0);
  const long us = elapsed_us(t0);
  EXPECT_GE(us, 19000) << "returned before the timeout";
  EXPECT_LT(us, 1000000) << "blocked far beyond the 20 ms timeout";
}

TEST(TtyTransport, WriteTimesOutWhenNobodyReads) {
  Pty pty;
  ASSERT_TRUE(pty.ok());
  TtyTransport t(pty.slave_path);
  t.open();
  std::vector<std::uint8_t> chunk(4096, 0x55);
  // The pty moves data to the master side in the background, so room can reappear for a while after a
  // write returned short; keep writing with a 20 ms timeout until one call gets nothing at all.
  long total = 0, last_us = 0;
  int n = 1;
  for (int i = 0; i < 4096 && n > 0; ++i) {
    const auto t0 = Clock::now();
    n = t.write(chunk.data(), static_cast<int>(chunk.size()), 20000);
    last_us = elapsed_us(t0);
    ASSERT_GE(n, 0);
    total += n;
  }
  ASSERT_EQ(n, 0) << "the pty never filled after " << total << " bytes";
  EXPECT_GE(last_us, 19000) << "gave up before the timeout";
  EXPECT_LT(last_us, 1000000) << "blocked far beyond the 20 ms timeout";
  EXPECT_GT(total, 0);
}

TEST(TtyTransport, MasterClosedIsGone) {
  Pty pty;
  ASSERT_TRUE(pty.ok());
  TtyTransport t(pty.slave_path);
  t.open();
  ::close(pty.master);
  pty.master = -1;
  std::uint8_t buf[8] = {1, 2, 3};
  EXPECT_EQ(t.read(buf, sizeof buf, 0), ByteTransport::kGone);
  EXPECT_EQ(t.read(buf, sizeof buf, 50000), ByteTransport::kGone);
  EXPECT_EQ(t.write(buf, 3, 0), ByteTransport::kGone);
  EXPECT_TRUE(t.is_open()) << "still open until close(), even though the device is gone";
  t.close();
  EXPECT_FALSE(t.is_open());
  EXPECT_EQ(t.read(buf, sizeof buf, 0), ByteTransport::kGone) << "closed reads as gone";
}

TEST(TtyTransport, FlushInputDropsPendingBytes) {
  Pty pty;
  ASSERT_TRUE(pty.ok());
  TtyTransport t(pty.slave_path);
  t.open();
  // One master write reaches the slave's line discipline in one piece, so once its first byte can be
  // read the other four are queued too.
  const std::uint8_t stale[5] = {1, 2, 3, 4, 5};
  ASSERT_EQ(::write(pty.master, stale, 5), 5);
  std::uint8_t buf[8];
  ASSERT_EQ(t.read(buf, 1, 1000000), 1);
  ASSERT_EQ(buf[0], 1);
  t.flush_input();
  EXPECT_EQ(t.read(buf, sizeof buf, 0), 0);
  const std::uint8_t fresh[1] = {9};
  ASSERT_EQ(::write(pty.master, fresh, 1), 1);
  ASSERT_EQ(t.read(buf, sizeof buf, 1000000), 1);
  EXPECT_EQ(buf[0], 9);
}

TEST(TtyTransport, MissingPathNamesThePath) {
  TtyTransport t("/dev/no-such-ttyACM9");
  try {
    t.open();
    FAIL() << "opened a missing path";
  } catch (const DeviceError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("/dev/no-such-ttyACM9"), std::string::npos) << m;
    EXPECT_NE(m.find("No such file"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << "one line";
  }
  EXPECT_FALSE(t.is_open());
}

TEST(TtyTransport, NotATtyIsRefused) {
  TtyTransport t("/dev/null");
  EXPECT_THROW(t.open(), DeviceError) << "TIOCEXCL / tcgetattr fail on a non-tty";
  EXPECT_FALSE(t.is_open());
}

TEST(TtyTransport, Baud1200AndOddRatesAreRefused) {
  try {
    TtyTransport t("/dev/ttyACM0", 1200);
    FAIL() << "1200 accepted";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("1200"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("bootloader"), std::string::npos);
  }
  EXPECT_THROW(TtyTransport("/dev/ttyACM0", 12345), DeviceError);
  EXPECT_NO_THROW(TtyTransport("/dev/ttyACM0", 921600));
}

// TIOCEXCL: while the transport holds the tty, another process's open fails with EBUSY. Root
// (CAP_SYS_ADMIN) bypasses TIOCEXCL, so when run as root the child drops to uid/gid 65534 first.
// Returns the child's errno of open (0 = opened).
int open_in_other_process(const std::string& path) {
  const pid_t pid = fork();
  if (pid == 0) {
    if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0)) _exit(200);
    const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    _exit(fd >= 0 ? 0 : (errno & 0x7F));
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 255;
}

TEST(TtyTransport, SecondOpenByAnotherProcessFails) {
  Pty pty;
  ASSERT_TRUE(pty.ok());
  if (geteuid() == 0) ::chmod(pty.slave_path.c_str(), 0666);  // so the unprivileged child may open it at all
  const int before = open_in_other_process(pty.slave_path);
  if (before == 200) GTEST_SKIP() << "running as root and cannot drop to uid 65534, and root bypasses TIOCEXCL";
  ASSERT_EQ(before, 0) << "control: another process can open the free tty (errno " << before << ")";
  TtyTransport t(pty.slave_path);
  t.open();
  EXPECT_EQ(open_in_other_process(pty.slave_path), EBUSY) << "TIOCEXCL did not keep the tty exclusive";
  t.close();
  EXPECT_EQ(open_in_other_process(pty.slave_path), 0) << "close() releases the tty";
}

TEST(TtyTransport, SecondTransportInThisProcessFailsUnlessRoot) {
  if (geteuid() == 0)
    GTEST_SKIP() << "root (CAP_SYS_ADMIN) bypasses TIOCEXCL; covered by SecondOpenByAnotherProcessFails";
  Pty pty;
  ASSERT_TRUE(pty.ok());
  TtyTransport a(pty.slave_path), b(pty.slave_path);
  a.open();
  try {
    b.open();
    FAIL() << "second open succeeded";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find(pty.slave_path), std::string::npos);
  }
}

TEST(TtyTransport, ListSerialByIdIsSortedAndEmptyWhenMissing) {
  EXPECT_TRUE(list_serial_by_id("/nonexistent/serial/by-id").empty());
  const auto dir = std::filesystem::temp_directory_path() / ("hk-by-id-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  for (const char* n : {"usb-Haply_2DIY_B-if00", "usb-Arduino_Zero_A-if00"}) {
    std::filesystem::create_symlink("../../ttyACM0", dir / n);
  }
  const auto list = list_serial_by_id(dir.string());
  std::filesystem::remove_all(dir);
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0], (dir / "usb-Arduino_Zero_A-if00").string());
  EXPECT_EQ(list[1], (dir / "usb-Haply_2DIY_B-if00").string());
  EXPECT_NO_THROW(list_serial_by_id());
}

}  // namespace
}  // namespace hk::io
