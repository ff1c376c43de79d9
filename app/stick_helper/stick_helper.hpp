#pragma once
/// @file stick_helper.hpp
/// hk-stick-mount, the narrow mount helper of the installed kiosk.
///
/// The kiosk runs as the unprivileged user haptic-kiosk; mounting a USB stick needs CAP_SYS_ADMIN (and
/// opening the stick's block device, owned root:disk, needs CAP_DAC_READ_SEARCH). Instead of giving the
/// kiosk those, the package installs this helper root:haptic-kiosk mode 0750 with the file capabilities
/// cap_dac_read_search,cap_sys_admin+ep. It does four things, with sticks::MountedStick's and sticks::WritableStick's
/// code:
///
///   hk-stick-mount mount DEVNODE SLOT   mounts DEVNODE read-only at /run/haptic-kiosk/usb/SLOT
///   hk-stick-mount unmount SLOT         detaches /run/haptic-kiosk/usb/SLOT and removes the folder
///   hk-stick-mount mount-rw DEVNODE SLOT
///                                       mounts the FAT or exFAT stick DEVNODE, already mounted read-only at
///                                       /run/haptic-kiosk/usb/SLOT, a second time read-write at
///                                       /run/haptic-kiosk/usb-rw/SLOT (sticks::WritableStick), for a copy
///   hk-stick-mount unmount-rw DEVNODE SLOT
///                                       syncs, detaches /run/haptic-kiosk/usb-rw/SLOT and sets DEVNODE read-only
///
/// and prints one line: on standard output "mounted FSTYPE at MOUNT_POINT from DEVNODE", "unmounted
/// MOUNT_POINT", "mounted-rw FSTYPE at FOLDER from DEVNODE", "unmounted-rw FOLDER" or "nothing mounted at
/// MOUNT_POINT" (exit 0); on standard error "hk-stick-mount: ..."
/// (exit 1 refused or failed, 2 bad command line).
///
/// It accepts only: DEVNODE an absolute path under /dev/ (a link there, such as /dev/disk/by-id/usb-...,
/// is resolved and must lead to a node under /dev/ too) of a block device that sits on the USB bus (its
/// sysfs device has a USB device among its parents, as libudev reports it); SLOT a whole number from 0
/// to sticks::kMaxStickSlot written without sign or leading zeros. The mount root is fixed. Loop devices
/// are accepted only with the first argument --allow-loop, and only when the real user is root (the
/// tests, which have no USB stick). The environment is cleared before anything else runs.

#include <sys/types.h>

#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "hk/error.hpp"

namespace hk::stick_helper {

/// The fixed mount root, sticks::kDefaultStickMountRoot.
extern const char* const kMountRoot;
/// The fixed root of the read-write mounts, sticks::kDefaultStickWriteRoot.
extern const char* const kWriteRoot;

/// A refused command line or device. what() is one line naming the argument: "slot '12a': ...",
/// "device '/etc/passwd': ...".
class HelperError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// What the helper was asked to do.
struct Request {
  enum class Verb { Mount, Unmount, MountRw, UnmountRw };
  Verb verb = Verb::Mount;
  std::string devnode;      ///< Mount, MountRw, UnmountRw: as given
  int slot = 0;             ///< 0 .. sticks::kMaxStickSlot
  bool allow_loop = false;  ///< --allow-loop was given (only root may)
};

/// The facts about a device node the helper decides on.
struct DeviceFacts {
  std::string resolved;  ///< the node's path with every link resolved (realpath)
  bool block = false;    ///< a block device
  unsigned major = 0, minor = 0;
  bool on_usb = false;  ///< its sysfs device has a USB device (subsystem usb, devtype usb_device) among its parents
  bool loop = false;    ///< a loop device (major 7)
};

/// Looks a resolved device node up in sysfs through libudev: on_usb and loop for the block device
/// `major:minor`. Used by check_devnode; tests pass their own.
using UsbProbe = std::function<void(DeviceFacts&)>;

/// The real probe: libudev (udev_device_new_from_devnum, then its parents).
void udev_probe(DeviceFacts& facts);

/// Parses the arguments after the program name: [--allow-loop] mount DEVNODE SLOT | [--allow-loop]
/// unmount SLOT | [--allow-loop] mount-rw DEVNODE SLOT | [--allow-loop] unmount-rw DEVNODE SLOT. `real_uid` is getuid()
/// (--allow-loop is refused unless it is 0).
/// @throws HelperError, one line naming the bad argument (an unknown verb, a missing or extra argument,
/// a bad slot, --allow-loop without root).
Request parse_request(const std::vector<std::string>& args, uid_t real_uid);

/// SLOT text -> number: digits only, no sign, no leading zero (but "0"), at most sticks::kMaxStickSlot.
/// @throws HelperError "slot '<text>': not a whole number from 0 to 999".
int parse_slot(const std::string& text);

/// Checks DEVNODE as the helper accepts it and returns its facts (the path to mount is `resolved`).
/// @throws HelperError "device '<devnode>': ..." for a relative path or one outside /dev/, a path that
/// leads outside /dev/ or does not exist, a node in a folder others than root may change (/dev/shm), a
/// node that is not a block device, a block device not on the USB bus, or a loop device without
/// `allow_loop`.
DeviceFacts check_devnode(const std::string& devnode, bool allow_loop, const UsbProbe& probe = udev_probe);

/// Does what `r` asks under `mount_root` (kMountRoot in the helper; tests may pass another; the read-write
/// mounts go to sticks::write_root_of(mount_root)) and returns the result line (without "\n").
/// @throws HelperError or sticks::StickMountError (one line) when it is refused or fails.
std::string run_request(const Request& r, const std::string& mount_root = kMountRoot,
                        const UsbProbe& probe = udev_probe);

/// The whole helper: clears the environment, parses `argc`/`argv`, runs the request and prints its one
/// line to `out` (success) or `err` ("hk-stick-mount: ..."). Returns the exit status: 0 done, 1 refused
/// or failed, 2 bad command line.
int helper_main(int argc, char** argv, std::FILE* out, std::FILE* err);

}  // namespace hk::stick_helper
