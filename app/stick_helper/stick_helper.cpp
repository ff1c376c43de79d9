// hk-stick-mount: argument checks and the two verbs (see stick_helper.hpp). The mounting itself is
// sticks::MountedStick's and sticks::unmount_stick_slot's code, compiled into this executable.

#include "stick_helper.hpp"

#include <libudev.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>

#include "sticks/usb_stick.hpp"

namespace hk::stick_helper {

const char* const kMountRoot = sticks::kDefaultStickMountRoot;
const char* const kWriteRoot = sticks::kDefaultStickWriteRoot;

namespace {

constexpr const char* kUsage =
    "usage: hk-stick-mount mount DEVNODE SLOT | hk-stick-mount unmount SLOT | hk-stick-mount mount-rw DEVNODE SLOT | "
    "hk-stick-mount unmount-rw DEVNODE SLOT";
constexpr unsigned kLoopMajor = 7;

/// `s` on one line, control characters shown as '?', cut at 200 bytes: what a message echoes of an argument.
std::string shown(const std::string& s) {
  std::string out;
  for (char c : s.substr(0, 200)) out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
  if (s.size() > 200) out += "...";
  return out;
}

[[noreturn]] void refuse_device(const std::string& devnode, const std::string& what) {
  throw HelperError("device '" + shown(devnode) + "': " + what);
}

/// Whether the usage line is the right answer (a command line error, exit status 2).
struct UsageError : HelperError {
  using HelperError::HelperError;
};

}  // namespace

int parse_slot(const std::string& text) {
  const std::string why =
      "slot '" + shown(text) + "': not a whole number from 0 to " + std::to_string(sticks::kMaxStickSlot);
  if (text.empty() || text.size() > 3 || (text.size() > 1 && text[0] == '0')) throw UsageError(why);
  int v = 0;
  for (char c : text) {
    if (c < '0' || c > '9') throw UsageError(why);
    v = v * 10 + (c - '0');
  }
  if (v > sticks::kMaxStickSlot) throw UsageError(why);
  return v;
}

Request parse_request(const std::vector<std::string>& args, uid_t real_uid) {
  std::size_t i = 0;
  Request r;
  if (i < args.size() && args[i] == "--allow-loop") {
    if (real_uid != 0) throw UsageError("--allow-loop: only root may mount loop devices (it is for the tests)");
    r.allow_loop = true;
    ++i;
  }
  if (i >= args.size()) throw UsageError(std::string("no verb given; ") + kUsage);
  const std::string verb = args[i++];
  const std::size_t rest = args.size() - i;
  if (verb == "mount" || verb == "mount-rw" || verb == "unmount-rw") {
    if (rest != 2)
      throw UsageError(verb + ": expected DEVNODE SLOT, got " + std::to_string(rest) + " argument" +
                       (rest == 1 ? "" : "s") + "; " + kUsage);
    r.verb = verb == "mount"      ? Request::Verb::Mount
             : verb == "mount-rw" ? Request::Verb::MountRw
                                  : Request::Verb::UnmountRw;
    r.devnode = args[i];
    r.slot = parse_slot(args[i + 1]);
  } else if (verb == "unmount") {
    if (rest != 1) throw UsageError("unmount: expected SLOT, got " + std::to_string(rest) + " arguments; " + kUsage);
    r.verb = Request::Verb::Unmount;
    r.slot = parse_slot(args[i]);
  } else {
    throw UsageError("verb '" + shown(verb) + "': not mount, unmount, mount-rw or unmount-rw; " + kUsage);
  }
  return r;
}

void udev_probe(DeviceFacts& facts) {
  std::unique_ptr<udev, decltype(&udev_unref)> ctx(udev_new(), &udev_unref);
  if (!ctx) return;
  std::unique_ptr<udev_device, decltype(&udev_device_unref)> dev(
      udev_device_new_from_devnum(ctx.get(), 'b', makedev(facts.major, facts.minor)), &udev_device_unref);
  if (!dev) return;
  // The parent is owned by the child (not unref'd separately).
  facts.on_usb = udev_device_get_parent_with_subsystem_devtype(dev.get(), "usb", "usb_device") != nullptr;
  const char* sysname = udev_device_get_sysname(dev.get());
  facts.loop = facts.major == kLoopMajor && sysname != nullptr && std::strncmp(sysname, "loop", 4) == 0;
}

DeviceFacts check_devnode(const std::string& devnode, bool allow_loop, const UsbProbe& probe) {
  if (devnode.rfind("/dev/", 0) != 0) refuse_device(devnode, "not a device node under /dev/");
  if (devnode.find('\0') != std::string::npos || devnode.size() >= PATH_MAX)
    refuse_device(devnode, "not a usable path");
  char buf[PATH_MAX];
  if (::realpath(devnode.c_str(), buf) == nullptr)
    refuse_device(devnode, std::string("cannot be resolved: ") + std::strerror(errno));
  DeviceFacts f;
  f.resolved = buf;
  if (f.resolved.rfind("/dev/", 0) != 0)
    refuse_device(devnode, "leads to '" + shown(f.resolved) + "', which is not under /dev/");
  // Only nodes in folders that root alone may change (not /dev/shm or /dev/mqueue): nobody can swap the
  // node between these checks and the mount.
  const std::string folder = f.resolved.substr(0, f.resolved.rfind('/'));
  struct stat dir {};
  if (::stat(folder.c_str(), &dir) != 0 || dir.st_uid != 0 || (dir.st_mode & (S_IWGRP | S_IWOTH)) != 0) {
    refuse_device(devnode, "its folder " + shown(folder) + " is not one only root may change");
  }
  struct stat st {};
  if (::stat(f.resolved.c_str(), &st) != 0)
    refuse_device(devnode, std::string("cannot examine it: ") + std::strerror(errno));
  f.block = S_ISBLK(st.st_mode);
  if (!f.block) refuse_device(devnode, "not a block device");
  f.major = major(st.st_rdev);
  f.minor = minor(st.st_rdev);
  f.loop = f.major == kLoopMajor;
  probe(f);
  if (f.loop) {
    if (!allow_loop)
      refuse_device(devnode,
                    "a loop device, not a USB stick (only the tests mount loop devices, with --allow-loop as root)");
    return f;
  }
  if (!f.on_usb) {
    refuse_device(devnode, "not on the USB bus (block device " + std::to_string(f.major) + ":" +
                               std::to_string(f.minor) +
                               " has no USB device among its parents in sysfs), so it is not mounted");
  }
  return f;
}

std::string run_request(const Request& r, const std::string& mount_root, const UsbProbe& probe) {
  const std::string point = mount_root + "/" + std::to_string(r.slot);
  if (r.verb == Request::Verb::Unmount) {
    return sticks::unmount_stick_slot(mount_root, r.slot) ? "unmounted " + point : "nothing mounted at " + point;
  }
  const DeviceFacts f = check_devnode(r.devnode, r.allow_loop, probe);
  const std::string write_root = sticks::write_root_of(mount_root);
  if (r.verb == Request::Verb::UnmountRw) {
    const std::string folder = write_root + "/" + std::to_string(r.slot);
    return sticks::close_writable_slot(f.resolved, write_root, r.slot) ? "unmounted-rw " + folder
                                                                       : "nothing mounted at " + folder;
  }
  if (r.verb == Request::Verb::MountRw) {
    sticks::WritableStick stick(f.resolved, mount_root, r.slot, write_root);
    stick.release();  // stays writable for the kiosk until unmount-rw
    return "mounted-rw " + stick.filesystem() + " at " + stick.folder() + " from " + shown(r.devnode);
  }
  sticks::MountedStick stick(f.resolved, mount_root, r.slot);
  // MountedStick checked that what is mounted is what it probed; this checks that it is what was validated.
  struct stat mounted {};
  if (::stat(stick.mount_point().c_str(), &mounted) != 0 || major(mounted.st_dev) != f.major ||
      minor(mounted.st_dev) != f.minor) {
    stick.unmount();
    refuse_device(r.devnode, "changed while it was being mounted, so it was unmounted again");
  }
  stick.release();  // stays mounted for the kiosk after this process ends
  return "mounted " + stick.filesystem() + " at " + stick.mount_point() + " from " + shown(r.devnode);
}

int helper_main(int argc, char** argv, std::FILE* out, std::FILE* err) {
  // Nothing from the caller's environment reaches libudev, libblkid or the kernel's mount options.
  ::clearenv();
  ::umask(077);
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  try {
    const Request r = parse_request(args, ::getuid());
    std::fprintf(out, "%s\n", run_request(r).c_str());
    return 0;
  } catch (const UsageError& e) {
    std::fprintf(err, "hk-stick-mount: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::string line = e.what();
    for (char& c : line) {
      if (c == '\n' || c == '\r') c = ' ';
    }
    std::fprintf(err, "hk-stick-mount: %s\n", line.c_str());
    return 1;
  }
}

}  // namespace hk::stick_helper
