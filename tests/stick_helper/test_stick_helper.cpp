// hk-stick-mount, the USB-stick mount helper (app/stick_helper/stick_helper.hpp): what it refuses, each
// refusal one line naming the argument, and, as root with a loop device, a mount and an unmount through
// the executable itself inside a private mount namespace with its own /run (so nothing reaches the host).
// Tests that need root, loop devices, unshare(1) or mkfs.ext4 skip with the reason where one is missing.

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "stick_helper.hpp"
#include "sticks/usb_stick.hpp"
#include "test_paths.hpp"

namespace hk::stick_helper {
namespace {

namespace fs = std::filesystem;

const std::string kHelper = HK_STICK_HELPER_EXE;

bool one_line(const std::string& s) {
  return !s.empty() && s.find('\n') == std::string::npos && s.find('\r') == std::string::npos;
}

/// The HelperError text of `f()`, or "" when it did not throw one.
template <class F>
std::string refusal(F f) {
  try {
    f();
  } catch (const HelperError& e) {
    return e.what();
  }
  return "";
}

/// Runs a shell command line; its exit status (-1 when it did not exit) and its standard output and error.
struct Shell {
  int status = -1;
  std::string out, err;
};

Shell run(const std::string& cmd) {
  char out_tmpl[] = "/tmp/hk_helper_out_XXXXXX";
  char err_tmpl[] = "/tmp/hk_helper_err_XXXXXX";
  const int o = ::mkstemp(out_tmpl), e = ::mkstemp(err_tmpl);
  Shell r;
  if (o < 0 || e < 0) return r;
  ::close(o);
  ::close(e);
  const int st = std::system((cmd + " >" + out_tmpl + " 2>" + err_tmpl).c_str());
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  auto slurp = [](const char* p) {
    std::ifstream in(p);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  r.out = slurp(out_tmpl);
  r.err = slurp(err_tmpl);
  ::unlink(out_tmpl);
  ::unlink(err_tmpl);
  return r;
}

bool have_tool(const std::string& name) { return run("command -v " + name).status == 0; }

/// `s` as one shell word.
std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string chomp(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

// ---------------------------------------------------------------------------------------------------
// The command line

TEST(StickHelperArgs, MountAndUnmountAreParsed) {
  const Request m = parse_request({"mount", "/dev/sdb1", "3"}, 1000);
  EXPECT_EQ(m.verb, Request::Verb::Mount);
  EXPECT_EQ(m.devnode, "/dev/sdb1");
  EXPECT_EQ(m.slot, 3);
  EXPECT_FALSE(m.allow_loop);
  const Request u = parse_request({"unmount", "999"}, 1000);
  EXPECT_EQ(u.verb, Request::Verb::Unmount);
  EXPECT_EQ(u.slot, 999);
  EXPECT_TRUE(parse_request({"--allow-loop", "mount", "/dev/loop0", "0"}, 0).allow_loop);
  const Request rw = parse_request({"mount-rw", "/dev/sdb1", "7"}, 1000);
  EXPECT_EQ(rw.verb, Request::Verb::MountRw);
  EXPECT_EQ(rw.devnode, "/dev/sdb1");
  EXPECT_EQ(rw.slot, 7);
  const Request done = parse_request({"unmount-rw", "/dev/sdb1", "7"}, 1000);
  EXPECT_EQ(done.verb, Request::Verb::UnmountRw);
  EXPECT_EQ(done.devnode, "/dev/sdb1");
}

TEST(StickHelperArgs, BadCommandLinesAreRefusedInOneLineNamingTheArgument) {
  struct Case {
    std::vector<std::string> args;
    uid_t uid;
    std::string must_contain;
  };
  const std::vector<Case> cases{
      {{}, 1000, "no verb given"},
      {{"format", "/dev/sdb1"}, 1000, "verb 'format'"},
      {{"mount", "/dev/sdb1"}, 1000, "mount: expected DEVNODE SLOT, got 1 argument"},
      {{"mount", "/dev/sdb1", "1", "2"}, 1000, "got 3 arguments"},
      {{"unmount"}, 1000, "unmount: expected SLOT, got 0 arguments"},
      {{"unmount", "1", "2"}, 1000, "got 2 arguments"},
      {{"mount", "/dev/sdb1", "x"}, 1000, "slot 'x'"},
      {{"--allow-loop", "mount", "/dev/loop0", "0"}, 1000, "--allow-loop: only root"},
      {{"mount", "--allow-loop", "/dev/loop0", "0"}, 0, "got 3 arguments"},  // the flag comes first or not at all
      {{"verb\nwith a newline"}, 1000, "verb 'verb?with a newline'"},
      {{"mount-rw", "/dev/sdb1"}, 1000, "mount-rw: expected DEVNODE SLOT, got 1 argument"},
      {{"unmount-rw", "3"}, 1000, "unmount-rw: expected DEVNODE SLOT, got 1 argument"},
      {{"mount-rw", "/dev/sdb1", "1000"}, 1000, "slot '1000'"},
  };
  for (const Case& c : cases) {
    std::string joined;
    for (const auto& a : c.args) joined += "[" + a + "]";
    const std::string what = refusal([&] { (void)parse_request(c.args, c.uid); });
    EXPECT_TRUE(one_line(what)) << joined << " -> " << what;
    EXPECT_NE(what.find(c.must_contain), std::string::npos) << joined << " -> " << what;
  }
}

TEST(StickHelperArgs, SlotsAreSmallWholeNumbersOnly) {
  EXPECT_EQ(parse_slot("0"), 0);
  EXPECT_EQ(parse_slot("7"), 7);
  EXPECT_EQ(parse_slot("999"), sticks::kMaxStickSlot);
  for (const std::string bad :
       {"", "-1", "+1", "01", "000", "1000", "12a", " 1", "1 ", "0x1", "1e2", "99999999999999999999", "\xd9\xa3"}) {
    const std::string what = refusal([&] { (void)parse_slot(bad); });
    EXPECT_TRUE(one_line(what)) << "'" << bad << "' -> " << what;
    EXPECT_EQ(what.rfind("slot '", 0), 0U) << what;
    EXPECT_NE(what.find("not a whole number from 0 to 999"), std::string::npos) << what;
  }
}

// ---------------------------------------------------------------------------------------------------
// The device

/// A probe that says what the test wants and records that it was asked.
UsbProbe fake_probe(bool on_usb, int* calls = nullptr) {
  return [on_usb, calls](DeviceFacts& f) {
    f.on_usb = on_usb;
    if (calls != nullptr) ++*calls;
  };
}

TEST(StickHelperDevice, PathsOutsideDevAreRefused) {
  for (const std::string bad :
       {"sdb1", "dev/sdb1", "./dev/sdb1", "/etc/passwd", "/tmp/stick.img", "/devx/sdb1", "/proc/self/fd/0", ""}) {
    int calls = 0;
    const std::string what = refusal([&] { (void)check_devnode(bad, true, fake_probe(true, &calls)); });
    EXPECT_TRUE(one_line(what)) << bad << " -> " << what;
    EXPECT_EQ(what, "device '" + bad + "': not a device node under /dev/") << what;
    EXPECT_EQ(calls, 0) << "probed " << bad;
  }
}

TEST(StickHelperDevice, PathsLeadingOutOfDevAreRefused) {
  const std::string what = refusal([] { (void)check_devnode("/dev/../etc/passwd", true, fake_probe(true)); });
  EXPECT_TRUE(one_line(what)) << what;
  EXPECT_EQ(what, "device '/dev/../etc/passwd': leads to '/etc/passwd', which is not under /dev/") << what;
}

TEST(StickHelperDevice, MissingNodeIsRefused) {
  const std::string what = refusal([] { (void)check_devnode("/dev/hk-no-such-stick", true, fake_probe(true)); });
  EXPECT_TRUE(one_line(what)) << what;
  EXPECT_EQ(what.rfind("device '/dev/hk-no-such-stick': cannot be resolved: ", 0), 0U) << what;
}

TEST(StickHelperDevice, NonBlockDevicesAreRefused) {
  for (const std::string bad : {"/dev/null", "/dev/zero", "/dev/shm"}) {
    if (!fs::exists(bad)) continue;
    int calls = 0;
    const std::string what = refusal([&] { (void)check_devnode(bad, true, fake_probe(true, &calls)); });
    EXPECT_TRUE(one_line(what)) << what;
    EXPECT_EQ(what, "device '" + bad + "': not a block device") << what;
    EXPECT_EQ(calls, 0);
  }
}

TEST(StickHelperDevice, NodesInFoldersOthersMayChangeAreRefused) {
  if (!fs::is_directory("/dev/shm")) GTEST_SKIP() << "no /dev/shm";
  const std::string planted = "/dev/shm/hk-stick-helper-test-" + std::to_string(::getpid());
  std::ofstream(planted) << "not a stick";
  const std::string what = refusal([&] { (void)check_devnode(planted, true, fake_probe(true)); });
  ::unlink(planted.c_str());
  EXPECT_TRUE(one_line(what)) << what;
  EXPECT_EQ(what, "device '" + planted + "': its folder /dev/shm is not one only root may change") << what;
}

/// The first block device under /dev that is not a loop device, or "".
std::string some_disk() {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/dev", ec)) {
    struct stat st {};
    if (::lstat(e.path().c_str(), &st) == 0 && S_ISBLK(st.st_mode) && major(st.st_rdev) != 7) return e.path().string();
  }
  return "";
}

/// The first loop device node under /dev, or "".
std::string some_loop() {
  for (int i = 0; i < 8; ++i) {
    const std::string p = "/dev/loop" + std::to_string(i);
    struct stat st {};
    if (::stat(p.c_str(), &st) == 0 && S_ISBLK(st.st_mode)) return p;
  }
  return "";
}

TEST(StickHelperDevice, BlockDeviceOffTheUsbBusIsRefused) {
  const std::string disk = some_disk();
  if (disk.empty()) GTEST_SKIP() << "no block device other than loop devices under /dev";
  // The real probe (libudev over sysfs): this machine's disks are not USB sticks... unless it runs from one.
  DeviceFacts f;
  struct stat st {};
  ASSERT_EQ(::stat(disk.c_str(), &st), 0);
  f.major = major(st.st_rdev);
  f.minor = minor(st.st_rdev);
  udev_probe(f);
  if (f.on_usb) GTEST_SKIP() << disk << " is on the USB bus here";
  const std::string what = refusal([&] { (void)check_devnode(disk, false); });
  EXPECT_TRUE(one_line(what)) << what;
  EXPECT_EQ(what.rfind("device '" + disk + "': not on the USB bus (block device " + std::to_string(f.major) + ":", 0),
            0U)
      << what;
  // The same node, were it on USB, passes (nothing is opened or mounted by check_devnode).
  const DeviceFacts ok = check_devnode(disk, false, fake_probe(true));
  EXPECT_EQ(ok.resolved, fs::canonical(disk).string());
  EXPECT_TRUE(ok.block);
}

TEST(StickHelperDevice, LoopDevicesOnlyWhenAllowed) {
  const std::string loop = some_loop();
  if (loop.empty()) GTEST_SKIP() << "no loop device node under /dev";
  const std::string what = refusal([&] { (void)check_devnode(loop, false); });
  EXPECT_TRUE(one_line(what)) << what;
  EXPECT_EQ(what.rfind("device '" + loop + "': a loop device, not a USB stick", 0), 0U) << what;
  // Even a probe claiming USB does not make a loop device acceptable.
  EXPECT_FALSE(refusal([&] { (void)check_devnode(loop, false, fake_probe(true)); }).empty());
  const DeviceFacts f = check_devnode(loop, true);
  EXPECT_TRUE(f.loop);
  EXPECT_EQ(f.major, 7U);
}

// ---------------------------------------------------------------------------------------------------
// The executable

TEST(StickHelperExe, RefusalsAreOneLineOnStandardErrorWithTheirExitStatus) {
  struct Case {
    std::string args;
    int status;
    std::string err;
  };
  const std::vector<Case> cases{
      {"", 2,
       "hk-stick-mount: no verb given; usage: hk-stick-mount mount DEVNODE SLOT | hk-stick-mount unmount SLOT | "
       "hk-stick-mount mount-rw DEVNODE SLOT | hk-stick-mount unmount-rw DEVNODE SLOT"},
      {"mount /dev/sdb1 1000", 2, "hk-stick-mount: slot '1000': not a whole number from 0 to 999"},
      {"unmount -1", 2, "hk-stick-mount: slot '-1': not a whole number from 0 to 999"},
      {"mount /etc/passwd 1", 1, "hk-stick-mount: device '/etc/passwd': not a device node under /dev/"},
      {"mount /dev/null 1", 1, "hk-stick-mount: device '/dev/null': not a block device"},
  };
  for (const Case& c : cases) {
    const Shell r = run(quote(kHelper) + " " + c.args);
    EXPECT_EQ(r.status, c.status) << c.args;
    EXPECT_EQ(r.out, "") << c.args;
    EXPECT_EQ(r.err, c.err + "\n") << c.args;
  }
  if (::getuid() != 0) {
    const Shell r = run(quote(kHelper) + " --allow-loop mount /dev/loop0 1");
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.err, "hk-stick-mount: --allow-loop: only root may mount loop devices (it is for the tests)\n");
  }
}

/// Skips unless this test can make loop devices and private mount namespaces.
#define SKIP_UNLESS_ROOT_TOOLS()                                                                             \
  do {                                                                                                       \
    if (::geteuid() != 0) GTEST_SKIP() << "needs root (loop devices, mount namespaces)";                     \
    for (const char* tool : {"unshare", "losetup", "mkfs.ext4"}) {                                           \
      if (!have_tool(tool)) GTEST_SKIP() << tool << " is not installed";                                     \
    }                                                                                                        \
    if (run("unshare -m --propagation private true").status != 0) GTEST_SKIP() << "unshare -m refused here"; \
  } while (0)

/// An ext4 image holding hello.txt on a read-only loop device, detached at the end.
class LoopStick {
 public:
  LoopStick() {
    char tmpl[] = "/tmp/hk_helper_XXXXXX";
    if (::mkdtemp(tmpl) == nullptr) return;
    dir_ = tmpl;
    std::ofstream(dir_ / "hello.txt") << "hello from the stick\n";
    fs::create_directories(dir_ / "src");
    fs::rename(dir_ / "hello.txt", dir_ / "src" / "hello.txt");
    const Shell mk =
        run("mkfs.ext4 -q -d " + quote((dir_ / "src").string()) + " " + quote((dir_ / "stick.img").string()) + " 4M");
    if (mk.status != 0) {
      error_ = "mkfs.ext4 failed: " + mk.err;
      return;
    }
    const Shell lo = run("losetup -r -f --show " + quote((dir_ / "stick.img").string()));
    if (lo.status != 0 || chomp(lo.out).rfind("/dev/loop", 0) != 0) {
      error_ = "losetup failed: " + lo.err;
      return;
    }
    dev_ = chomp(lo.out);
  }
  ~LoopStick() {
    if (!dev_.empty()) (void)run("blockdev --setrw " + dev_ + "; losetup -d " + dev_);
    std::error_code ec;
    if (!dir_.empty()) fs::remove_all(dir_, ec);
  }
  LoopStick(const LoopStick&) = delete;
  LoopStick& operator=(const LoopStick&) = delete;
  const std::string& dev() const { return dev_; }
  const std::string& error() const { return error_; }

 private:
  fs::path dir_;
  std::string dev_, error_;
};

/// Runs `script` (sh) in a private mount namespace whose /run is a fresh tmpfs; $H is the helper.
Shell in_private_run(const std::string& script) {
  return run("unshare -m --propagation private sh -c " +
             quote("mount -t tmpfs tmpfs /run && H=" + kHelper + " && " + script));
}

TEST(StickHelperExe, MountsALoopStickReadOnlyAndUnmountsIt) {
  SKIP_UNLESS_ROOT_TOOLS();
  LoopStick stick;
  if (stick.dev().empty()) GTEST_SKIP() << stick.error();
  const Shell r = in_private_run("\"$H\" --allow-loop mount " + stick.dev() +
                                 " 3 && "
                                 "cat /run/haptic-kiosk/usb/3/hello.txt && "
                                 "grep ' /run/haptic-kiosk/usb/3 ' /proc/self/mountinfo | cut -d' ' -f6 && "
                                 "stat -c '%a %U' /run/haptic-kiosk/usb /run/haptic-kiosk && "
                                 "\"$H\" unmount 3 && "
                                 "(test -e /run/haptic-kiosk/usb/3 && echo still there || echo gone) && "
                                 "\"$H\" unmount 3");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(r.err, "");
  std::istringstream lines(r.out);
  std::vector<std::string> l;
  for (std::string line; std::getline(lines, line);) l.push_back(line);
  ASSERT_EQ(l.size(), 8U) << r.out;
  EXPECT_EQ(l[0], "mounted ext4 at /run/haptic-kiosk/usb/3 from " + stick.dev());
  EXPECT_EQ(l[1], "hello from the stick");
  for (const char* opt : {"ro", "nosuid", "nodev", "noexec", "noatime", "nosymfollow"}) {
    EXPECT_NE(("," + l[2] + ",").find(std::string(",") + opt + ","), std::string::npos) << opt << " not in " << l[2];
  }
  EXPECT_EQ(l[3], "700 root");
  EXPECT_EQ(l[4], "700 root");
  EXPECT_EQ(l[5], "unmounted /run/haptic-kiosk/usb/3");
  EXPECT_EQ(l[6], "gone");
  EXPECT_EQ(l[7], "nothing mounted at /run/haptic-kiosk/usb/3");
}

TEST(StickHelperExe, OnlyAFatOrExfatStickIsMountedForWriting) {
  SKIP_UNLESS_ROOT_TOOLS();
  LoopStick stick;  // ext4
  if (stick.dev().empty()) GTEST_SKIP() << stick.error();
  const Shell r = in_private_run("\"$H\" --allow-loop mount " + stick.dev() + " 3 >/dev/null && " +
                                 "{ \"$H\" --allow-loop mount-rw " + stick.dev() + " 3; echo \"status $?\"; } && " +
                                 "(test -e /run/haptic-kiosk/usb-rw/3 && echo left || echo none) && " +
                                 "grep -c ' /run/haptic-kiosk/usb/3 ' /proc/self/mountinfo && " +
                                 "\"$H\" --allow-loop unmount-rw " + stick.dev() + " 3 && \"$H\" unmount 3");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  std::istringstream lines(r.out);
  std::vector<std::string> l;
  for (std::string line; std::getline(lines, line);) l.push_back(line);
  ASSERT_EQ(l.size(), 5U) << r.out << r.err;
  EXPECT_EQ(l[0], "status 1");
  EXPECT_EQ(l[1], "none") << "no read-write mount point is left";
  EXPECT_EQ(l[2], "1") << "the visit's read-only mount stays";
  EXPECT_EQ(l[3], "nothing mounted at /run/haptic-kiosk/usb-rw/3");
  EXPECT_EQ(l[4], "unmounted /run/haptic-kiosk/usb/3");
  EXPECT_TRUE(one_line(r.err.substr(0, r.err.size() - 1))) << r.err;
  EXPECT_NE(r.err.find("hk-stick-mount: stick '" + stick.dev() +
                       "': its filesystem (ext4) is not one the kiosk "
                       "writes (FAT, exFAT)"),
            std::string::npos)
      << r.err;
}

TEST(StickHelperExe, ALinkInTheMountRootIsNotFollowed) {
  SKIP_UNLESS_ROOT_TOOLS();
  LoopStick stick;
  if (stick.dev().empty()) GTEST_SKIP() << stick.error();
  // /run/haptic-kiosk/usb pointing elsewhere (the kiosk's user owns /run/haptic-kiosk and could plant it).
  const Shell r = in_private_run(
      "mkdir -p /run/haptic-kiosk /run/elsewhere && ln -s /run/elsewhere /run/haptic-kiosk/usb && "
      "\"$H\" --allow-loop mount " +
      stick.dev() +
      " 1; echo \"status $?\"; ls -A /run/elsewhere; "
      "\"$H\" unmount 1; echo \"status $?\"");
  EXPECT_EQ(r.out, "status 1\nstatus 1\n");
  EXPECT_EQ(r.err, "hk-stick-mount: stick '" + stick.dev() +
                       "': the mount root's part /run/haptic-kiosk/usb is a symbolic link or not a folder\n"
                       "hk-stick-mount: stick slot 1: the mount root's part /run/haptic-kiosk/usb is a symbolic link "
                       "or not a folder\n");
}

TEST(StickHelperExe, ADeviceInUseIsRefusedAndNoMountPointIsLeft) {
  SKIP_UNLESS_ROOT_TOOLS();
  LoopStick stick;
  if (stick.dev().empty()) GTEST_SKIP() << stick.error();
  const Shell r = in_private_run("mkdir /run/other && mount -o ro " + stick.dev() +
                                 " /run/other && "
                                 "\"$H\" --allow-loop mount " +
                                 stick.dev() +
                                 " 2; echo \"status $?\"; "
                                 "test -e /run/haptic-kiosk/usb/2 && echo left || echo clean");
  EXPECT_EQ(r.out, "status 1\nclean\n") << r.err;
  EXPECT_EQ(r.err,
            "hk-stick-mount: stick '" + stick.dev() +
                "': it is in use (mounted elsewhere, or a disk with a partition in use), so it is not mounted\n");
}

}  // namespace
}  // namespace hk::stick_helper
