// How the kiosk mounts a USB stick: itself (MountedStick) or through the mount helper hk-stick-mount
// (see stick_mount.hpp for the helper's command line and answers).

#include "sticks/stick_mount.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <utility>
#include <vector>

extern char** environ;

namespace hk::sticks {
namespace {

/// "stick '<devnode>': <what>" on one line.
std::string stick_line(const std::string& devnode, const std::string& what) {
  std::string line = "stick '" + devnode + "': " + what;
  for (char& c : line) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return line;
}

/// What one run of the helper gave.
struct HelperRun {
  std::string first_line;  ///< the first line it wrote (standard output and error together), without "\n"
  bool timed_out = false;
  int status = 0;  ///< from waitpid
};

/// Runs `helper args...` with standard output and error into one pipe and standard input from /dev/null,
/// waits at most `timeout_s` (then SIGKILL), and returns its first line and exit status.
/// Throws StickMountError (naming `devnode`) when it cannot be started.
HelperRun run_helper(const std::string& helper, std::vector<std::string> args, double timeout_s,
                     const std::string& devnode) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    throw StickMountError(
        stick_line(devnode, std::string("cannot start the mount helper (pipe: ") + std::strerror(errno) + ")"));
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&fa, fds[1], 1);
  posix_spawn_file_actions_adddup2(&fa, fds[1], 2);
  args.insert(args.begin(), helper);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = ::posix_spawn(&pid, helper.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  ::close(fds[1]);
  if (rc != 0) {
    ::close(fds[0]);
    throw StickMountError(stick_line(devnode, "cannot start the mount helper " + helper + ": " + std::strerror(rc)));
  }

  HelperRun run;
  std::string text;
  const auto deadline =
      std::chrono::steady_clock::now() +
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(timeout_s));
  char buf[4096];
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      run.timed_out = true;
      ::kill(pid, SIGKILL);
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int n_ready = ::poll(&p, 1, static_cast<int>(std::min<long long>(left, INT_MAX)));
    if (n_ready < 0 && errno == EINTR) continue;
    if (n_ready < 0) break;
    if (n_ready == 0) continue;
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) break;  // EOF: the helper has finished
    if (text.size() < 4096) text.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  while (::waitpid(pid, &run.status, 0) < 0 && errno == EINTR) {
  }
  run.first_line = text.substr(0, text.find('\n'));
  return run;
}

/// The helper's line as an error about `devnode`: its "hk-stick-mount: " prefix dropped, and the
/// "stick '<devnode>': " form kept or added.
std::string helper_refusal(const std::string& devnode, const HelperRun& run) {
  std::string line = run.first_line;
  const std::string prefix = "hk-stick-mount: ";
  if (line.rfind(prefix, 0) == 0) line = line.substr(prefix.size());
  if (line.empty()) {
    if (WIFSIGNALED(run.status))
      return stick_line(devnode, "the mount helper died of signal " + std::to_string(WTERMSIG(run.status)));
    return stick_line(devnode, "the mount helper failed without saying why (exit status " +
                                   std::to_string(WIFEXITED(run.status) ? WEXITSTATUS(run.status) : -1) + ")");
  }
  if (line.rfind("stick '", 0) == 0) {
    for (char& c : line) {
      if (c == '\r') c = ' ';
    }
    return line;
  }
  return stick_line(devnode, "the mount helper refused: " + line);
}

/// A stick the kiosk opened for writing itself.
class DirectWriteMount final : public StickWriteMount {
 public:
  DirectWriteMount(const std::string& devnode, const std::string& mount_root, int slot)
      : stick_(devnode, mount_root, slot, write_root_of(mount_root)) {}
  const std::string& folder() const override { return stick_.folder(); }
  void close() override { stick_.close(); }

 private:
  WritableStick stick_;
};

/// A stick the kiosk mounted itself.
class DirectStickMount final : public StickMount {
 public:
  DirectStickMount(const std::string& devnode, const std::string& mount_root, int slot)
      : stick_(devnode, mount_root, slot), root_(mount_root), slot_(slot) {}
  const std::string& devnode() const override { return stick_.devnode(); }
  const std::string& mount_point() const override { return stick_.mount_point(); }
  const std::string& filesystem() const override { return stick_.filesystem(); }
  bool unmount() override { return stick_.unmount(); }
  std::unique_ptr<StickWriteMount> mount_writable() override {
    return std::make_unique<DirectWriteMount>(stick_.devnode(), root_, slot_);
  }

 private:
  MountedStick stick_;
  std::string root_;
  int slot_ = 0;
};

/// A stick the helper opened for writing (mount-rw); its unmount-rw verb undoes it.
class HelperWriteMount final : public StickWriteMount {
 public:
  HelperWriteMount(std::string helper, std::string devnode, int slot, std::string folder, double timeout_s)
      : helper_(std::move(helper)),
        devnode_(std::move(devnode)),
        folder_(std::move(folder)),
        slot_(slot),
        timeout_s_(timeout_s) {}
  ~HelperWriteMount() override {
    try {
      close();
    } catch (const StickMountError&) {
      // the caller who wanted to know called close() itself
    }
  }
  HelperWriteMount(const HelperWriteMount&) = delete;
  HelperWriteMount& operator=(const HelperWriteMount&) = delete;
  const std::string& folder() const override { return folder_; }
  void close() override {
    if (!open_) return;
    open_ = false;
    const HelperRun run = run_helper(helper_, {"unmount-rw", devnode_, std::to_string(slot_)}, timeout_s_, devnode_);
    if (run.timed_out) throw StickMountError(stick_line(devnode_, "the mount helper did not finish the write in time"));
    if (!WIFEXITED(run.status) || WEXITSTATUS(run.status) != 0) throw StickMountError(helper_refusal(devnode_, run));
  }

 private:
  std::string helper_, devnode_, folder_;
  int slot_ = 0;
  double timeout_s_ = 30.0;
  bool open_ = true;
};

/// A stick the helper mounted; the helper's "unmount" verb undoes it.
class HelperStickMount final : public StickMount {
 public:
  HelperStickMount(std::string helper, std::string devnode, int slot, std::string mount_point, std::string fs,
                   double timeout_s)
      : helper_(std::move(helper)),
        devnode_(std::move(devnode)),
        mount_point_(std::move(mount_point)),
        fs_(std::move(fs)),
        slot_(slot),
        timeout_s_(timeout_s) {}
  ~HelperStickMount() override { (void)unmount(); }
  HelperStickMount(const HelperStickMount&) = delete;
  HelperStickMount& operator=(const HelperStickMount&) = delete;
  const std::string& devnode() const override { return devnode_; }
  const std::string& mount_point() const override { return mount_point_; }
  const std::string& filesystem() const override { return fs_; }
  std::unique_ptr<StickWriteMount> mount_writable() override {
    const HelperRun run = run_helper(helper_, {"mount-rw", devnode_, std::to_string(slot_)}, timeout_s_, devnode_);
    if (run.timed_out) {
      (void)run_helper(helper_, {"unmount-rw", devnode_, std::to_string(slot_)}, timeout_s_, devnode_);
      throw StickMountError(stick_line(devnode_, "the mount helper did not open it for writing in time"));
    }
    if (!WIFEXITED(run.status) || WEXITSTATUS(run.status) != 0) throw StickMountError(helper_refusal(devnode_, run));
    // "mounted-rw FSTYPE at FOLDER from DEVNODE"
    std::istringstream in(run.first_line);
    std::string word, fs, at, folder;
    in >> word >> fs >> at >> folder;
    if (word != "mounted-rw" || fs.empty() || at != "at" || folder.empty()) {
      (void)run_helper(helper_, {"unmount-rw", devnode_, std::to_string(slot_)}, timeout_s_, devnode_);
      throw StickMountError(stick_line(
          devnode_, "the mount helper answered '" + run.first_line + "', not 'mounted-rw FSTYPE at FOLDER'"));
    }
    return std::make_unique<HelperWriteMount>(helper_, devnode_, slot_, folder, timeout_s_);
  }
  bool unmount() override {
    if (!mounted_) return true;
    mounted_ = false;
    try {
      const HelperRun run = run_helper(helper_, {"unmount", std::to_string(slot_)}, timeout_s_, devnode_);
      return !run.timed_out && WIFEXITED(run.status) && WEXITSTATUS(run.status) == 0;
    } catch (const StickMountError&) {
      return false;
    }
  }

 private:
  std::string helper_, devnode_, mount_point_, fs_;
  int slot_ = 0;
  double timeout_s_ = 30.0;
  bool mounted_ = true;
};

std::unique_ptr<StickMount> mount_through_helper(const std::string& helper, const std::string& devnode, int slot,
                                                 double timeout_s) {
  const HelperRun run = run_helper(helper, {"mount", devnode, std::to_string(slot)}, timeout_s, devnode);
  if (run.timed_out) {
    // It may have mounted meanwhile: undo whatever it did at this slot.
    (void)run_helper(helper, {"unmount", std::to_string(slot)}, timeout_s, devnode);
    std::ostringstream s;
    s << "the mount helper did not answer within " << timeout_s << " s";
    throw StickMountError(stick_line(devnode, s.str()));
  }
  if (!WIFEXITED(run.status) || WEXITSTATUS(run.status) != 0) throw StickMountError(helper_refusal(devnode, run));
  // "mounted FSTYPE at MOUNT_POINT from DEVNODE"
  std::istringstream in(run.first_line);
  std::string word, fs, at, mount_point;
  in >> word >> fs >> at >> mount_point;
  if (word != "mounted" || fs.empty() || at != "at" || mount_point.empty()) {
    (void)run_helper(helper, {"unmount", std::to_string(slot)}, timeout_s, devnode);
    throw StickMountError(
        stick_line(devnode, "the mount helper answered '" + run.first_line + "', not 'mounted FSTYPE at MOUNT_POINT'"));
  }
  return std::make_unique<HelperStickMount>(helper, devnode, slot, mount_point, fs, timeout_s);
}

}  // namespace

const char* stick_mounter_name(StickMounter m) {
  switch (m) {
    case StickMounter::Direct:
      return "direct";
    case StickMounter::Helper:
      return "helper";
    case StickMounter::None:
      return "none";
  }
  return "none";
}

std::string stick_helper_path() {
  if (const char* env = std::getenv("HK_STICK_HELPER"); env != nullptr && *env != '\0') return env;
  return kDefaultStickHelperPath;
}

StickMounter choose_stick_mounter(bool have_capability, const std::string& helper_path) {
  if (have_capability) return StickMounter::Direct;
  struct stat st {};
  if (!helper_path.empty() && ::stat(helper_path.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
      ::access(helper_path.c_str(), X_OK) == 0) {
    return StickMounter::Helper;
  }
  return StickMounter::None;
}

std::unique_ptr<StickMount> mount_stick(StickMounter how, const std::string& devnode, const std::string& mount_root,
                                        int slot, const std::string& helper_path, double timeout_s) {
  switch (how) {
    case StickMounter::Direct:
      return std::make_unique<DirectStickMount>(devnode, mount_root, slot);
    case StickMounter::Helper:
      return mount_through_helper(helper_path, devnode, slot, timeout_s);
    case StickMounter::None:
      break;
  }
  throw StickMountError(stick_line(devnode, "cannot mount it: " + mount_capability_hint() +
                                                ", or install the mount helper " + kDefaultStickHelperPath));
}

}  // namespace hk::sticks
