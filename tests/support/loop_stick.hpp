#pragma once
/// @file loop_stick.hpp
/// USB sticks for tests: filesystem images on loop devices, and a forked child in a private mount namespace to
/// mount them in (so nothing is ever mounted in the test's own namespace or on the host). Needs root, loop devices
/// and unshare(CLONE_NEWNS): SKIP_UNLESS_ROOT and SKIP_UNLESS_TOOL skip with the reason where one is missing.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sticks/usb_stick.hpp"

namespace hk::test {

namespace fs = std::filesystem;
using sticks::have_mount_capability;

inline std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs a shell command; returns its exit status (-1 if it could not run) and its output (stdout+stderr).
inline int run(const std::string& cmd, std::string* out = nullptr) {
  FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  if (p == nullptr) return -1;
  std::string text;
  char buf[512];
  size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) text.append(buf, n);
  const int status = ::pclose(p);
  if (out != nullptr) *out = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline bool have_tool(const std::string& name) { return run("command -v " + name + " >/dev/null") == 0; }

inline bool kernel_has_filesystem(const std::string& type) {
  std::ifstream in("/proc/filesystems");
  std::string line;
  while (std::getline(in, line)) {
    const auto tab = line.rfind('\t');
    if (tab != std::string::npos && line.substr(tab + 1) == type) return true;
  }
  return false;
}

inline bool one_line(const std::string& s) {
  return !s.empty() && s.find('\n') == std::string::npos && s.find('\r') == std::string::npos;
}

/// A loop device over an image file, detached (and made writable again, since MountedStick leaves its
/// BLKROSET flag on the device) on scope exit, also when a test fails.
class LoopDevice {
 public:
  LoopDevice(const fs::path& image, bool read_only) {
    std::string out;
    const int rc = run(std::string("losetup ") + (read_only ? "-r " : "") + "-f --show '" + image.string() + "'", &out);
    while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
    if (rc == 0 && out.rfind("/dev/loop", 0) == 0 && out.find('\n') == std::string::npos) {
      dev_ = out;
    } else {
      error_ = "losetup failed: " + out;
    }
  }
  ~LoopDevice() {
    if (dev_.empty()) return;
    const int fd = ::open(dev_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd >= 0) {
      const int zero = 0;
      (void)::ioctl(fd, BLKROSET, &zero);
      ::close(fd);
    }
    (void)run("losetup -d " + dev_);
  }
  LoopDevice(const LoopDevice&) = delete;
  LoopDevice& operator=(const LoopDevice&) = delete;
  const std::string& dev() const { return dev_; }
  const std::string& error() const { return error_; }

 private:
  std::string dev_, error_;
};

/// 1 if the block device is read-only, 0 if writable, -1 if it cannot be asked.
inline int block_read_only(const std::string& dev) {
  const int fd = ::open(dev.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return -1;
  int ro = -1;
  if (::ioctl(fd, BLKROGET, &ro) != 0) ro = -1;
  ::close(fd);
  return ro;
}

/// One line of /proc/self/mountinfo.
struct MountEntry {
  std::string mount_point, options, fstype, source, super_options;
};

inline std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string field;
  std::istringstream in(s);
  while (std::getline(in, field, sep)) out.push_back(field);
  return out;
}

inline std::optional<MountEntry> find_mount(const std::string& mount_point) {
  std::ifstream in("/proc/self/mountinfo");
  std::string line;
  while (std::getline(in, line)) {
    const auto f = split(line, ' ');
    if (f.size() < 10 || f[4] != mount_point) continue;
    const auto dash = std::find(f.begin() + 6, f.end(), "-");
    if (dash == f.end() || f.end() - dash < 4) continue;
    return MountEntry{f[4], f[5], *(dash + 1), *(dash + 2), *(dash + 3)};
  }
  return std::nullopt;
}

inline bool has_option(const std::string& options, const std::string& opt) {
  const auto v = split(options, ',');
  return std::find(v.begin(), v.end(), opt) != v.end();
}

/// Failures found in the forked child, reported to the parent line by line.
struct Checks {
  std::vector<std::string> failures;
  std::string skip;  ///< non-empty: the child could not run its checks, and why
  void expect(bool ok, const std::string& what) {
    if (!ok) failures.push_back(what);
  }
};

#define CHILD_CHECK(c, cond, msg) (c).expect((cond), "line " + std::to_string(__LINE__) + ": " #cond "; " + (msg))

/// What a forked child reported.
struct ChildReport {
  std::vector<std::string> failures;
  std::string skip;
};

/// Runs `body` in a forked child that first enters a private mount namespace (unshare(CLONE_NEWNS), then
/// makes "/" recursively private), so whatever it mounts vanishes with it and never reaches the host.
inline ChildReport in_private_namespace(const std::function<void(Checks&)>& body) {
  int fds[2];
  if (::pipe(fds) != 0) return {{std::string("pipe: ") + std::strerror(errno)}, ""};
  const pid_t pid = ::fork();
  if (pid < 0) return {{std::string("fork: ") + std::strerror(errno)}, ""};
  if (pid == 0) {
    ::close(fds[0]);
    Checks c;
    if (::unshare(CLONE_NEWNS) != 0) {
      c.skip = std::string("unshare(CLONE_NEWNS) refused: ") + std::strerror(errno);
    } else if (::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0) {
      c.skip = std::string("cannot make / private in the new namespace: ") + std::strerror(errno);
    } else {
      try {
        body(c);
      } catch (const std::exception& e) {
        c.failures.push_back(std::string("unexpected exception: ") + e.what());
      } catch (...) {
        c.failures.push_back("unexpected exception");
      }
    }
    std::string text;
    for (std::string f : c.failures) {
      std::replace(f.begin(), f.end(), '\n', '|');
      text += "FAIL " + f + "\n";
    }
    if (!c.skip.empty()) text += "SKIP " + c.skip + "\n";
    size_t off = 0;
    while (off < text.size()) {
      const ssize_t n = ::write(fds[1], text.data() + off, text.size() - off);
      if (n <= 0) break;
      off += static_cast<size_t>(n);
    }
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string text;
  char buf[1024];
  for (;;) {
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    text.append(buf, static_cast<size_t>(n));
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  ChildReport r;
  for (const auto& line : split(text, '\n')) {
    if (line.rfind("FAIL ", 0) == 0) r.failures.push_back(line.substr(5));
    if (line.rfind("SKIP ", 0) == 0) r.skip = line.substr(5);
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    r.failures.push_back("the child did not exit cleanly (status " + std::to_string(status) + ")");
  }
  return r;
}

/// Reports the child's failures to gtest, then its skip reason if it had one.
#define REPORT_CHILD(report)                                \
  do {                                                      \
    const ChildReport& r_ = (report);                       \
    for (const auto& f_ : r_.failures) ADD_FAILURE() << f_; \
    if (!r_.skip.empty()) GTEST_SKIP() << r_.skip;          \
  } while (0)

#define SKIP_UNLESS_ROOT()                                                               \
  do {                                                                                   \
    if (::geteuid() != 0) GTEST_SKIP() << "needs root (loop devices, mount namespaces)"; \
    if (!have_mount_capability()) GTEST_SKIP() << "needs CAP_SYS_ADMIN";                 \
  } while (0)

#define SKIP_UNLESS_TOOL(name)                                         \
  do {                                                                 \
    if (!have_tool(name)) GTEST_SKIP() << name << " is not installed"; \
  } while (0)

}  // namespace hk::test
