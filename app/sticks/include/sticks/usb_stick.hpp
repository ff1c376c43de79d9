#pragma once
/// @file usb_stick.hpp
/// USB sticks coming and going: block-device events, filesystem identification, and a
/// read-only mount that nothing can write through.
///
/// Events come through the small BlockEventSource interface: UdevBlockEventSource watches the kernel's
/// uevents with a libudev monitor (subsystem "block", ID_BUS=usb, partitions and whole disks that carry a
/// filesystem); tests feed events for loop devices through FakeBlockEventSource.
///
/// Mounting follows one order, each step refusing with a one-line StickMountError:
/// 1. identify the filesystem with libblkid on the device node (probe of superblocks, TYPE tag);
///    only vfat, exfat, ntfs3 (blkid says "ntfs"), ext4 and iso9660 are accepted;
/// 2. make the block device read-only with ioctl(BLKROSET, 1), so not even the filesystem driver's
///    journal replay or a "dirty" flag can write to the stick;
/// 3. mount(2) under `<mount_root>/<N>` with MS_RDONLY | MS_NOSUID | MS_NODEV | MS_NOEXEC |
///    MS_NOSYMFOLLOW | MS_NOATIME (plus, for ext4, "noload" so no journal is replayed);
/// 4. on removal or destruction, umount2(MNT_DETACH) and remove the mount point.
/// The kiosk needs CAP_SYS_ADMIN for steps 2 and 3; have_mount_capability() tells beforehand. Without it,
/// the installed kiosk mounts through the narrow helper hk-stick-mount (app/stick_helper, reached through
/// sticks/stick_mount.hpp), which runs this same code with the capability.
///
/// The mount root and the mount point are reached from "/" one folder at a time without following any
/// symbolic link, and mount(2) and umount2(2) are given the opened folder (/proc/self/fd/N), never a path
/// looked up again: the helper runs with CAP_SYS_ADMIN for a user who owns /run/haptic-kiosk, and a link
/// or a folder swapped in there must not move a mount anywhere else.

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hk/error.hpp"

namespace hk::sticks {

/// A block device appearing or disappearing.
struct BlockEvent {
  enum class Action { Add, Remove };
  Action action = Action::Add;
  std::string devnode;  ///< e.g. "/dev/sdb1" or "/dev/loop3"
  std::string label;    ///< filesystem label if the event carries one (ID_FS_LABEL), else ""
};

/// Where block events come from. Not thread-safe: one consumer thread polls it.
class BlockEventSource {
 public:
  virtual ~BlockEventSource() = default;
  /// The next event, waiting at most timeout_ms [ms] (0: do not wait; negative: wait without limit).
  /// nullopt when none came.
  virtual std::optional<BlockEvent> next(int timeout_ms) = 0;
};

/// libudev monitor on the "udev" netlink group, filtered to subsystem "block", ID_BUS=usb, with a
/// filesystem (ID_FS_USAGE=filesystem) or a partition. Also reports the sticks already present at
/// construction as Add events (enumeration), so a stick inserted before the kiosk started is seen (one
/// inserted during construction may be reported twice). Only "add" and "remove" actions are reported.
class UdevBlockEventSource final : public BlockEventSource {
 public:
  /// @throws StickMountError when libudev cannot create the monitor (no /run/udev/control, i.e. udevd is
  /// not running; no netlink). what() is one line starting "stick monitor: ".
  UdevBlockEventSource();
  ~UdevBlockEventSource() override;
  std::optional<BlockEvent> next(int timeout_ms) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Events pushed by hand (tests, and the `stick --device` command's single mount). Thread-safe: push
/// from any thread, next() from the consumer.
class FakeBlockEventSource final : public BlockEventSource {
 public:
  void push(BlockEvent e);
  std::optional<BlockEvent> next(int timeout_ms) override;

 private:
  struct Queue;
  std::shared_ptr<Queue> q_ = make_queue();
  static std::shared_ptr<Queue> make_queue();
};

/// A refused stick or failed mount. what() is one line naming the device: "stick '/dev/sdb1': ...".
class StickMountError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// The filesystem type libblkid finds on `devnode` ("vfat", "exfat", "ntfs", "ext4", "iso9660", "swap",
/// ...), probing superblocks only (no writes; the device is opened O_RDONLY). `devnode` is a block device
/// node, or an image file.
/// @throws StickMountError if the device cannot be opened, is neither a block device nor a regular file,
/// carries no recognisable filesystem, or carries signatures of several (ambiguous).
std::string identify_filesystem(const std::string& devnode);

/// Whether the filesystem type (as identify_filesystem returns it) is one the kiosk mounts.
bool filesystem_supported(const std::string& type);

/// Whether this thread holds CAP_SYS_ADMIN in its effective set (needed to mount and for BLKROSET), as
/// capget(2) reports it. False if capget fails.
bool have_mount_capability();

/// One line for the log on how to grant the capability (setcap on the executable, or the systemd unit's
/// AmbientCapabilities=CAP_SYS_ADMIN).
std::string mount_capability_hint();

/// A stick mounted read-only. Unmounts (MNT_DETACH) and removes its mount point when destroyed.
class MountedStick {
 public:
  /// Identifies, sets the device read-only, and mounts it under `<mount_root>/<slot>` (the folder is
  /// created with mode 0700; mount_root and its missing parents are created with mode 0700; a folder left
  /// at `<mount_root>/<slot>` by an earlier run is detached and replaced). `devnode` must be a block
  /// device; the filesystem is checked before the capability, so an unsupported stick is named as such.
  /// On vfat/exfat/ntfs3 every file belongs to the kiosk's uid/gid and is readable by it only; on ext4
  /// and iso9660 the stick's own owners and modes apply. After mounting, the mounted filesystem's device is
  /// checked to be the one probed (a device node swapped meanwhile is unmounted and refused).
  /// The read-only flag stays set on the device after unmounting (a removed stick takes it along; a loop
  /// device keeps it until `blockdev --setrw`).
  /// A device in use (mounted elsewhere, or a disk with a partition mounted: its exclusive open fails) is
  /// refused before it is made read-only, so a disk the system runs from is never touched. `mount_root`
  /// must be an absolute path without symbolic links in it; the mount point must be a folder this process's
  /// effective user owns (it created it), or nothing is mounted.
  /// @throws StickMountError (not a block device, slot outside [0, kMaxStickSlot], unsupported filesystem,
  /// no capability, device in use, BLKROSET refused, a symbolic link in the mount root, mount refused by
  /// the kernel, e.g. no driver for the filesystem), one line naming devnode.
  /// Nothing stays mounted and no mount point is left when it throws.
  MountedStick(const std::string& devnode, const std::string& mount_root, int slot);
  ~MountedStick();
  MountedStick(const MountedStick&) = delete;
  MountedStick& operator=(const MountedStick&) = delete;

  const std::string& devnode() const { return devnode_; }
  const std::string& mount_point() const { return mount_point_; }
  const std::string& filesystem() const { return fs_; }
  /// Unmounts now (umount2 with MNT_DETACH, then removes the mount point; idempotent). Never throws; a
  /// failure is logged by the caller through the return value (false: the detach or the rmdir failed).
  /// Files still open on the stick stay readable until closed (lazy detach).
  bool unmount();
  /// Forgets the mount without unmounting it, so the destructor leaves the stick mounted. For the mount
  /// helper (hk-stick-mount), whose process ends while the kiosk goes on reading the stick; the kiosk has it
  /// unmounted later through unmount_stick_slot() (the helper's "unmount" verb).
  void release() { mounted_ = false; }

 private:
  std::string devnode_, mount_point_, fs_;
  std::string root_;  ///< the mount root, without trailing slashes
  bool mounted_ = false;
};

/// The highest slot MountedStick accepts: slots are 0 to kMaxStickSlot.
inline constexpr int kMaxStickSlot = 999;

/// Detaches whatever is mounted at `<mount_root>/<slot>` (umount2 with MNT_DETACH) and removes that
/// folder, as MountedStick::unmount() does for its own mount; the mount helper's "unmount" verb. The path is
/// walked from "/" without following symbolic links. Returns true when a filesystem was mounted there,
/// false when there was none (a missing folder, or an empty one, which is removed).
/// @throws StickMountError, one line starting "stick slot N: ": a slot outside [0, kMaxStickSlot], a part of
/// the path that is a symbolic link or not a folder, or a detach or removal the kernel refused.
bool unmount_stick_slot(const std::string& mount_root, int slot);

/// The default mount root, "/run/haptic-kiosk/usb".
inline constexpr const char* kDefaultStickMountRoot = "/run/haptic-kiosk/usb";

/// The default root of the read-write mounts, "/run/haptic-kiosk/usb-rw" (write_root_of the default mount root).
inline constexpr const char* kDefaultStickWriteRoot = "/run/haptic-kiosk/usb-rw";

/// Where the read-write mounts of sticks mounted under `mount_root` go: `<mount_root>-rw` (a sibling, so a
/// slot's read-only and read-write mounts never share a folder).
std::string write_root_of(const std::string& mount_root);

/// Whether a copy may be written to a filesystem of this type: FAT ("vfat") and exFAT, which every computer at
/// home reads and writes and whose writes leave no journal to replay. NTFS, ext4 and ISO 9660 are read only.
bool filesystem_writable(const std::string& type);

/// Why a stick could not be opened for writing, for the visitor's sentence.
enum class StickWriteRefusal {
  WriteProtected,  ///< its lock switch is on, or the device is read-only at the block layer
  Format,          ///< its filesystem is not FAT or exFAT
  Other,           ///< anything else (named in the log line)
};

/// The refusal a StickMountError line from WritableStick (directly or through the mount helper, which runs the
/// same code and passes its line on) stands for: it carries "write-protected" or "not one the kiosk writes".
StickWriteRefusal stick_write_refusal(const std::string& line);

/// A stick mounted read-only by MountedStick, opened for writing for a moment: a second mount of the same
/// filesystem, read-write, at `<write_root>/<slot>`, while the read-only mount at `<mount_root>/<slot>` stays
/// as it is (a mount of its own flagged read-only: nothing reads or writes through it differently). Steps:
/// 1. the device's filesystem must be one of `writable_types` (FAT, exFAT: filesystem_writable);
/// 2. the read-only mount must be there and be of this device;
/// 3. the block device is made writable (ioctl BLKROSET 0); a device that stays read-only (a stick's lock
///    switch, a read-only loop device) is refused as write-protected and set read-only again;
/// 4. the read-only mount is bind-mounted at `<write_root>/<slot>` (a fresh folder, mode 0700) and the
///    filesystem remounted read-write there (MS_REMOUNT; nosuid, nodev, noexec, nosymfollow, noatime), which the
///    kernel refuses for a write-protected device.
/// close() undoes them: syncfs, the filesystem read-only again, the second mount detached and its folder removed,
/// the device read-only again (BLKROSET 1). Needs CAP_SYS_ADMIN, as MountedStick; the installed kiosk has the mount
/// helper do it (its mount-rw and unmount-rw verbs).
class WritableStick {
 public:
  /// @throws StickMountError, one line naming devnode, with nothing left changed: not a block device, a slot
  /// outside [0, kMaxStickSlot], a filesystem not in `writable_types` ("its filesystem (ext4) is not one the kiosk
  /// writes (FAT, exFAT)"), no capability, no read-only mount of it at the slot, "it is write-protected", a mount
  /// the kernel refuses. `writable_types` is for the tests, whose kernels may have no FAT driver.
  WritableStick(const std::string& devnode, const std::string& mount_root, int slot, const std::string& write_root,
                const std::vector<std::string>& writable_types = {"vfat", "exfat"});
  /// close(), its error swallowed (unless released).
  ~WritableStick();
  WritableStick(const WritableStick&) = delete;
  WritableStick& operator=(const WritableStick&) = delete;

  /// The read-write mount point: the stick's top folder, writable.
  const std::string& folder() const { return folder_; }
  /// The filesystem type (identify_filesystem's name).
  const std::string& filesystem() const { return fs_; }
  /// Syncs and undoes the read-write mount (close_writable_slot); idempotent.
  /// @throws StickMountError when what was written may not be on the stick (the sync reported an error) or the
  /// read-write mount could not be undone.
  void close();
  /// Forgets the mount without closing it (the mount helper's process ends while the kiosk writes).
  void release() { open_ = false; }

 private:
  std::string devnode_, root_, folder_, fs_;
  int slot_ = 0;
  bool open_ = false;
};

/// Undoes the read-write mount at `<write_root>/<slot>` of `devnode`: syncfs, remount read-only, detach, remove
/// the folder, BLKROSET 1 on the device (which is set read-only even when nothing was mounted there). The mount
/// helper's unmount-rw verb. Returns false when nothing was mounted there.
/// @throws StickMountError, one line naming devnode: a slot outside [0, kMaxStickSlot], a link or non-folder on
/// the way, a mount there of another device, a sync that reported an error (what was written may not be on the
/// stick: everything else is still undone), a remount or detach the kernel refused.
bool close_writable_slot(const std::string& devnode, const std::string& write_root, int slot);

}  // namespace hk::sticks
