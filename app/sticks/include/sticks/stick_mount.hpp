#pragma once
/// @file stick_mount.hpp
/// How the kiosk mounts a USB stick: itself, or through the mount helper.
///
/// Mounting needs CAP_SYS_ADMIN. A kiosk that holds it (root, or a developer's setcap) mounts directly
/// with MountedStick (usb_stick.hpp). The installed kiosk runs as the unprivileged user haptic-kiosk and
/// asks the narrow helper /usr/libexec/haptic-kiosk/hk-stick-mount (app/stick_helper; file capabilities
/// cap_sys_admin and cap_dac_read_search, executable by the group haptic-kiosk only) to do the same steps:
///   hk-stick-mount mount DEVNODE SLOT   ->  "mounted FSTYPE at MOUNT_POINT from DEVNODE"
///   hk-stick-mount unmount SLOT         ->  "unmounted MOUNT_POINT" or "nothing mounted at MOUNT_POINT"
///   hk-stick-mount mount-rw DEVNODE SLOT   ->  "mounted-rw FSTYPE at FOLDER from DEVNODE"
///   hk-stick-mount unmount-rw DEVNODE SLOT ->  "unmounted-rw FOLDER" or "nothing mounted at FOLDER"
/// Refusals are one line on standard error, "hk-stick-mount: stick 'DEVNODE': why", exit status 1.
/// The helper accepts only USB block devices and mounts only under /run/haptic-kiosk/usb.

#include <memory>
#include <string>

#include "sticks/usb_stick.hpp"

namespace hk::sticks {

/// Where the package installs the helper.
inline constexpr const char* kDefaultStickHelperPath = "/usr/libexec/haptic-kiosk/hk-stick-mount";

/// A stick opened for writing for a moment (WritableStick, itself or through the helper's mount-rw verb).
/// Undone when destroyed (errors swallowed); close() to know that what was written is on the stick.
class StickWriteMount {
 public:
  virtual ~StickWriteMount() = default;
  /// The stick's top folder, writable.
  virtual const std::string& folder() const = 0;
  /// Syncs and undoes the read-write mount; idempotent.
  /// @throws StickMountError (one line naming the stick) when what was written may not be on it.
  virtual void close() = 0;
};

/// A stick mounted read-only, however it was mounted. Unmounts when destroyed.
class StickMount {
 public:
  virtual ~StickMount() = default;
  /// The device node it was mounted from, as given.
  virtual const std::string& devnode() const = 0;
  /// Where its files are.
  virtual const std::string& mount_point() const = 0;
  /// Its filesystem, as identify_filesystem() names it ("vfat", "ext4", ...).
  virtual const std::string& filesystem() const = 0;
  /// Unmounts now (lazy detach, mount point removed); idempotent, never throws. False when that failed.
  virtual bool unmount() = 0;
  /// Opens it for writing: a second, read-write mount (WritableStick; FAT and exFAT only) while this read-only
  /// one stays. One at a time.
  /// @throws StickMountError, one line naming the stick (stick_write_refusal tells write-protected and a format
  /// not written from the rest).
  virtual std::unique_ptr<StickWriteMount> mount_writable() = 0;
};

/// Who mounts sticks.
enum class StickMounter {
  Direct,  ///< this process, with CAP_SYS_ADMIN (MountedStick)
  Helper,  ///< the mount helper executable
  None,    ///< neither: sticks are not mounted
};

/// "direct", "helper" or "none", for the log.
const char* stick_mounter_name(StickMounter m);

/// The helper's path: $HK_STICK_HELPER when set and not empty (tests, a development build), else
/// kDefaultStickHelperPath.
std::string stick_helper_path();

/// Direct when `have_capability`; else Helper when `helper_path` names a regular file this process may
/// execute (access X_OK); else None.
StickMounter choose_stick_mounter(bool have_capability, const std::string& helper_path);

/// Mounts `devnode` as `how` says: Direct mounts under `<mount_root>/<slot>` (MountedStick); Helper runs
/// `helper_path mount DEVNODE SLOT` (the helper's root is always kDefaultStickMountRoot, whatever
/// `mount_root` says) and waits at most `timeout_s` for it.
/// @throws StickMountError, one line naming devnode: None; the helper's own refusal (its line, without the
/// "hk-stick-mount: " prefix); a helper that cannot be started, does not answer in time, dies, or answers
/// something else than the result line.
std::unique_ptr<StickMount> mount_stick(StickMounter how, const std::string& devnode, const std::string& mount_root,
                                        int slot, const std::string& helper_path, double timeout_s = 30.0);

}  // namespace hk::sticks
