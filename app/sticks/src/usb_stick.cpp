// USB sticks as block devices: libblkid identification, the read-only mount and the read-write one for a copy
// (see usb_stick.hpp for the order of the steps and why each one is there).

#include "sticks/usb_stick.hpp"

#include "hk/unique_fd.hpp"

#include <blkid/blkid.h>
#include <fcntl.h>
#include <linux/capability.h>
#include <sys/ioctl.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <utility>

#ifndef MS_NOSYMFOLLOW
#define MS_NOSYMFOLLOW 256  // Linux 5.10
#endif

namespace hk::sticks {
namespace {

/// "stick '<devnode>': <what>", kept on one line (a device name from udev cannot hold a newline, but a
/// devnode given on the command line could).
std::string stick_message(const std::string& devnode, const std::string& what) {
  std::string line = "stick '" + devnode + "': " + what;
  for (char& c : line) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return line;
}

[[noreturn]] void refuse(const std::string& devnode, const std::string& what) {
  throw StickMountError(stick_message(devnode, what));
}

std::string errno_text(int err) { return std::strerror(err); }

using Fd = hk::UniqueFd;

/// Opens `devnode` read-only for probing; refuses anything that is neither a block device nor a regular
/// file (an image). Never creates, never writes.
int open_for_probe(const std::string& devnode, struct stat* st) {
  const int fd = ::open(devnode.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
  if (fd < 0) refuse(devnode, "cannot open the device: " + errno_text(errno));
  if (::fstat(fd, st) != 0) {
    const int err = errno;
    ::close(fd);
    refuse(devnode, "cannot examine the device: " + errno_text(err));
  }
  if (!S_ISBLK(st->st_mode) && !S_ISREG(st->st_mode)) {
    ::close(fd);
    refuse(devnode, "not a block device");
  }
  return fd;
}

/// The TYPE libblkid finds through the open descriptor `fd`; refuses when there is none.
std::string probe_type(const std::string& devnode, int fd) {
  blkid_probe pr = blkid_new_probe();
  if (pr == nullptr) refuse(devnode, "cannot probe the device (libblkid out of memory)");
  struct ProbeGuard {
    blkid_probe p;
    ~ProbeGuard() { blkid_free_probe(p); }
  } guard{pr};
  if (blkid_probe_set_device(pr, fd, 0, 0) != 0) refuse(devnode, "cannot probe the device (libblkid refused it)");
  blkid_probe_enable_superblocks(pr, 1);
  blkid_probe_set_superblocks_flags(pr, BLKID_SUBLKS_TYPE);
  const int rc = blkid_do_safeprobe(pr);
  if (rc == 1) refuse(devnode, "it carries no filesystem the kiosk recognises");
  if (rc == -2) refuse(devnode, "it carries signatures of more than one filesystem, so it is not mounted");
  if (rc != 0) refuse(devnode, "cannot read the device to find its filesystem");
  const char* type = nullptr;
  size_t len = 0;
  if (blkid_probe_lookup_value(pr, "TYPE", &type, &len) != 0 || type == nullptr || *type == '\0') {
    refuse(devnode, "it carries no filesystem the kiosk recognises");
  }
  return std::string(type);
}

/// mount(2)'s filesystem type for a libblkid TYPE (only differs for NTFS, read by the ntfs3 driver).
std::string kernel_fs_type(const std::string& type) { return type == "ntfs" ? "ntfs3" : type; }

/// Filesystem-specific mount data: ext4 never replays its journal; on the filesystems without Unix
/// owners, every file belongs to the kiosk and is readable by it alone; names are read as UTF-8.
std::string mount_data(const std::string& type) {
  const std::string ids = "uid=" + std::to_string(::getuid()) + ",gid=" + std::to_string(::getgid());
  if (type == "ext4") return "noload";
  if (type == "vfat") return ids + ",fmask=0177,dmask=0077,utf8";
  if (type == "exfat") return ids + ",fmask=0177,dmask=0077,iocharset=utf8";
  if (type == "ntfs") return ids + ",fmask=0177,dmask=0077,iocharset=utf8";
  if (type == "iso9660") return ids + ",utf8";
  return "";
}

/// Why mount(2) refused, for a visitor or an attendant.
std::string mount_failure(int err, const std::string& type) {
  switch (err) {
    case ENODEV:
      return "this computer's kernel cannot read " + type + " (no " + kernel_fs_type(type) + " driver)";
    case EPERM:
    case EACCES:
      return "mounting was not permitted (" + errno_text(err) + "); " + mount_capability_hint();
    case EINVAL:
      return "the kernel refused to mount its " + type + " filesystem (damaged, or an option it does not know)";
    default:
      return "the kernel refused to mount its " + type + " filesystem: " + errno_text(err);
  }
}

/// "/proc/self/fd/N": the path that reaches exactly what descriptor N holds open, whatever happens to
/// the names on the way to it meanwhile.
std::string fd_path(int fd) { return "/proc/self/fd/" + std::to_string(fd); }

/// `root` without trailing slashes ("/" stays "/").
std::string trimmed_root(std::string root) {
  while (root.size() > 1 && root.back() == '/') root.pop_back();
  return root;
}

/// Opens the folder `root` (absolute) from "/" one component at a time with O_PATH | O_DIRECTORY |
/// O_NOFOLLOW, so no symbolic link anywhere in it is followed; with `create`, missing folders are made
/// with mode 0700. Returns the descriptor, or -1 when a component is missing and !create. Throws
/// StickMountError "<who>: ..." for a relative path, "..", a link or a non-folder on the way.
int open_root(const std::string& who, const std::string& root, bool create) {
  const auto fail = [&who](const std::string& what) -> void {
    std::string line = who + ": " + what;
    for (char& c : line) {
      if (c == '\n' || c == '\r') c = ' ';
    }
    throw StickMountError(line);
  };
  if (root.empty() || root.front() != '/') fail("the mount root '" + root + "' is not an absolute path");
  Fd dir(::open("/", O_PATH | O_DIRECTORY | O_CLOEXEC));
  if (dir.get() < 0) fail("cannot open / (" + errno_text(errno) + ")");
  std::string walked;
  std::size_t pos = 0;
  while (pos < root.size()) {
    const std::size_t next = root.find('/', pos);
    const std::string part = root.substr(pos, next == std::string::npos ? std::string::npos : next - pos);
    pos = next == std::string::npos ? root.size() : next + 1;
    if (part.empty() || part == ".") continue;
    if (part == "..") fail("the mount root '" + root + "' contains '..'");
    walked += "/" + part;
    int fd = ::openat(dir.get(), part.c_str(), O_PATH | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0 && errno == ENOENT) {
      if (!create) return -1;
      if (::mkdirat(dir.get(), part.c_str(), 0700) != 0 && errno != EEXIST) {
        fail("cannot create the mount root " + walked + ": " + errno_text(errno));
      }
      fd = ::openat(dir.get(), part.c_str(), O_PATH | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    }
    if (fd < 0) {
      if (errno == ENOTDIR || errno == ELOOP)
        fail("the mount root's part " + walked + " is a symbolic link or not a folder");
      fail("cannot open the mount root's part " + walked + ": " + errno_text(errno));
    }
    dir.reset(fd);
  }
  const int out = ::fcntl(dir.get(), F_DUPFD_CLOEXEC, 0);
  if (out < 0) fail("cannot open the mount root " + root + ": " + errno_text(errno));
  return out;
}

/// umount2(MNT_DETACH) of the filesystem mounted on the folder `name` in `root_fd`, reached without
/// following a link. 0, or the errno (EINVAL: nothing is mounted there; ENOENT: no such folder).
int detach_at(int root_fd, const std::string& name) {
  Fd fd(::openat(root_fd, name.c_str(), O_PATH | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
  if (fd.get() < 0) return errno;
  return ::umount2(fd_path(fd.get()).c_str(), MNT_DETACH) == 0 ? 0 : errno;
}

/// Makes `name` in the folder `root_fd` an empty folder with mode 0700 that is not a mount point (a
/// folder left by a kiosk that crashed while a stick was mounted is detached and removed first) and
/// returns a descriptor of it, checked to be a folder of this process's effective user (one swapped in
/// by someone else between the mkdir and the open is refused). `shown` names it in messages.
int fresh_mount_point(const std::string& devnode, int root_fd, const std::string& name, const std::string& shown) {
  struct stat st {};
  if (::fstatat(root_fd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0) {
    if (!S_ISDIR(st.st_mode)) refuse(devnode, "the mount point " + shown + " exists and is not a folder");
    (void)detach_at(root_fd, name);  // EINVAL when nothing is mounted there
    if (::unlinkat(root_fd, name.c_str(), AT_REMOVEDIR) != 0) {
      refuse(devnode, "cannot clear the old mount point " + shown + ": " + errno_text(errno));
    }
  } else if (errno != ENOENT) {
    refuse(devnode, "cannot examine the mount point " + shown + ": " + errno_text(errno));
  }
  if (::mkdirat(root_fd, name.c_str(), 0700) != 0)
    refuse(devnode, "cannot create the mount point " + shown + ": " + errno_text(errno));
  const int fd = ::openat(root_fd, name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    (void)::unlinkat(root_fd, name.c_str(), AT_REMOVEDIR);
    refuse(devnode, "cannot open the mount point " + shown + ": " + errno_text(err));
  }
  if (::fstat(fd, &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != ::geteuid()) {
    ::close(fd);
    refuse(devnode, "the mount point " + shown + " was replaced while it was being made, so nothing is mounted");
  }
  (void)::fchmod(fd, 0700);  // exactly 0700, whatever the umask
  return fd;
}

/// Whether the block device is free: its exclusive open (O_EXCL) succeeds, which the kernel refuses with
/// EBUSY while a filesystem is mounted from it or, for a whole disk, from one of its partitions.
void check_not_in_use(const std::string& devnode) {
  const int fd = ::open(devnode.c_str(), O_RDONLY | O_EXCL | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
  if (fd >= 0) {
    ::close(fd);
    return;
  }
  if (errno == EBUSY)
    refuse(devnode, "it is in use (mounted elsewhere, or a disk with a partition in use), so it is not mounted");
  refuse(devnode, "cannot open the device exclusively: " + errno_text(errno));
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Identification and capability

std::string identify_filesystem(const std::string& devnode) {
  struct stat st {};
  Fd fd(open_for_probe(devnode, &st));
  return probe_type(devnode, fd.get());
}

bool filesystem_supported(const std::string& type) {
  return type == "vfat" || type == "exfat" || type == "ntfs" || type == "ext4" || type == "iso9660";
}

bool have_mount_capability() {
  __user_cap_header_struct header{};
  header.version = _LINUX_CAPABILITY_VERSION_3;
  header.pid = 0;  // this thread
  __user_cap_data_struct data[_LINUX_CAPABILITY_U32S_3]{};
  if (::syscall(SYS_capget, &header, data) != 0) return false;
  constexpr int kBit = CAP_SYS_ADMIN;  // 21: in the first 32-bit word
  return (data[kBit / 32].effective & (1u << (kBit % 32))) != 0;
}

std::string mount_capability_hint() {
  return "the kiosk needs CAP_SYS_ADMIN to mount sticks: sudo setcap cap_sys_admin+ep /usr/bin/haptic-kiosk, "
         "or AmbientCapabilities=CAP_SYS_ADMIN in its systemd unit";
}

// ---------------------------------------------------------------------------------------------------
// MountedStick

MountedStick::MountedStick(const std::string& devnode, const std::string& mount_root, int slot) : devnode_(devnode) {
  if (slot < 0 || slot > kMaxStickSlot) {
    refuse(devnode, "invalid mount slot " + std::to_string(slot) + " (0 to " + std::to_string(kMaxStickSlot) + ")");
  }
  struct stat st {};
  Fd fd(open_for_probe(devnode, &st));
  if (!S_ISBLK(st.st_mode)) refuse(devnode, "not a block device");

  // 1. Identify.
  fs_ = probe_type(devnode, fd.get());
  if (!filesystem_supported(fs_)) {
    refuse(devnode, "its filesystem (" + fs_ + ") is not one the kiosk reads (FAT, exFAT, NTFS, ext4, ISO 9660)");
  }
  if (!have_mount_capability()) refuse(devnode, "cannot mount it: " + mount_capability_hint());

  // The mount point, reached without links (a stale mount on it is detached here, which frees the device).
  root_ = trimmed_root(mount_root);
  const std::string name = std::to_string(slot);
  mount_point_ = (root_ == "/" ? "" : root_) + "/" + name;
  Fd root_fd(open_root("stick '" + devnode + "'", root_, true));
  Fd point(fresh_mount_point(devnode, root_fd.get(), name, mount_point_));
  const auto drop_point = [&] {
    point.reset();
    (void)::unlinkat(root_fd.get(), name.c_str(), AT_REMOVEDIR);
  };

  // 2. Read-only at the block layer, before any filesystem driver sees the device; never a device in use.
  try {
    check_not_in_use(devnode);
  } catch (...) {
    drop_point();
    throw;
  }
  const int one = 1;
  if (::ioctl(fd.get(), BLKROSET, &one) != 0) {
    const int err = errno;
    drop_point();
    refuse(devnode, "cannot make the device read-only (BLKROSET: " + errno_text(err) + "), so it is not mounted");
  }
  int ro = 0;
  if (::ioctl(fd.get(), BLKROGET, &ro) != 0 || ro != 1) {
    drop_point();
    refuse(devnode, "the device did not become read-only, so it is not mounted");
  }

  // 3. Mount, onto the folder held open (not a path looked up again).
  const unsigned long flags = MS_RDONLY | MS_NOSUID | MS_NODEV | MS_NOEXEC | MS_NOSYMFOLLOW | MS_NOATIME;
  const std::string data = mount_data(fs_);
  if (::mount(devnode.c_str(), fd_path(point.get()).c_str(), kernel_fs_type(fs_).c_str(), flags,
              data.empty() ? nullptr : data.c_str()) != 0) {
    const int err = errno;
    drop_point();
    refuse(devnode, mount_failure(err, fs_));
  }
  point.reset();
  mounted_ = true;

  // The device node is looked up again by mount(2): make sure it is still the device probed above.
  struct stat mounted {};
  const int top = ::openat(root_fd.get(), name.c_str(), O_PATH | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  const bool same = top >= 0 && ::fstat(top, &mounted) == 0 && mounted.st_dev == st.st_rdev;
  if (top >= 0) ::close(top);
  if (!same) {
    unmount();
    refuse(devnode, "the device changed while it was being mounted, so it was unmounted again");
  }
}

MountedStick::~MountedStick() { (void)unmount(); }

bool MountedStick::unmount() {
  if (!mounted_) return true;
  mounted_ = false;
  const std::string name = mount_point_.substr(mount_point_.rfind('/') + 1);
  try {
    Fd root_fd(open_root("stick '" + devnode_ + "'", root_, false));
    if (root_fd.get() < 0) return false;
    bool ok = detach_at(root_fd.get(), name) == 0;
    ok = ::unlinkat(root_fd.get(), name.c_str(), AT_REMOVEDIR) == 0 && ok;
    return ok;
  } catch (const StickMountError&) {
    return false;
  }
}

bool unmount_stick_slot(const std::string& mount_root, int slot) {
  const std::string who = "stick slot " + std::to_string(slot);
  if (slot < 0 || slot > kMaxStickSlot) {
    throw StickMountError(who + ": not a slot (0 to " + std::to_string(kMaxStickSlot) + ")");
  }
  const std::string root = trimmed_root(mount_root);
  const std::string name = std::to_string(slot);
  const std::string shown = (root == "/" ? "" : root) + "/" + name;
  Fd root_fd(open_root(who, root, false));
  if (root_fd.get() < 0) return false;  // no mount root: nothing was ever mounted there
  struct stat st {};
  if (::fstatat(root_fd.get(), name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) {
    if (errno == ENOENT) return false;
    throw StickMountError(who + ": cannot examine " + shown + ": " + errno_text(errno));
  }
  if (!S_ISDIR(st.st_mode)) throw StickMountError(who + ": " + shown + " is not a folder, so nothing is unmounted");
  const int err = detach_at(root_fd.get(), name);
  if (err != 0 && err != EINVAL) throw StickMountError(who + ": cannot unmount " + shown + ": " + errno_text(err));
  if (::unlinkat(root_fd.get(), name.c_str(), AT_REMOVEDIR) != 0) {
    throw StickMountError(who + ": cannot remove " + shown + ": " + errno_text(errno));
  }
  return err == 0;
}

// ---------------------------------------------------------------------------------------------------
// WritableStick

std::string write_root_of(const std::string& mount_root) { return trimmed_root(mount_root) + "-rw"; }

bool filesystem_writable(const std::string& type) { return type == "vfat" || type == "exfat"; }

StickWriteRefusal stick_write_refusal(const std::string& line) {
  if (line.find("write-protected") != std::string::npos) return StickWriteRefusal::WriteProtected;
  if (line.find("not one the kiosk writes") != std::string::npos) return StickWriteRefusal::Format;
  return StickWriteRefusal::Other;
}

namespace {

/// The flags of the read-write mount: as the read-only one's, but writable.
constexpr unsigned long kWriteMountFlags = MS_NOSUID | MS_NODEV | MS_NOEXEC | MS_NOSYMFOLLOW | MS_NOATIME;

/// BLKROSET on `devnode` (opened read-only: the ioctl needs no write access). 0, or the errno.
int set_device_read_only(const std::string& devnode, bool read_only) {
  Fd fd(::open(devnode.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK));
  if (fd.get() < 0) return errno;
  const int v = read_only ? 1 : 0;
  return ::ioctl(fd.get(), BLKROSET, &v) == 0 ? 0 : errno;
}

/// The slot's folder name and the path shown in messages.
std::string slot_path(const std::string& root, const std::string& name) {
  return (root == "/" ? "" : root) + "/" + name;
}

}  // namespace

WritableStick::WritableStick(const std::string& devnode, const std::string& mount_root, int slot,
                             const std::string& write_root, const std::vector<std::string>& writable_types)
    : devnode_(devnode), root_(trimmed_root(write_root)), slot_(slot) {
  if (slot < 0 || slot > kMaxStickSlot) {
    refuse(devnode, "invalid mount slot " + std::to_string(slot) + " (0 to " + std::to_string(kMaxStickSlot) + ")");
  }
  struct stat dev {};
  Fd fd(open_for_probe(devnode, &dev));
  if (!S_ISBLK(dev.st_mode)) refuse(devnode, "not a block device");

  // 1. Only filesystems a home computer writes back without a journal.
  fs_ = probe_type(devnode, fd.get());
  if (std::find(writable_types.begin(), writable_types.end(), fs_) == writable_types.end()) {
    refuse(devnode, "its filesystem (" + fs_ + ") is not one the kiosk writes (FAT, exFAT)");
  }
  if (!have_mount_capability()) refuse(devnode, "cannot write to it: " + mount_capability_hint());

  // 2. The visit's read-only mount of this very device.
  const std::string name = std::to_string(slot);
  const std::string ro_point = slot_path(trimmed_root(mount_root), name);
  Fd ro_root(open_root("stick '" + devnode + "'", trimmed_root(mount_root), false));
  if (ro_root.get() < 0) refuse(devnode, "it is not mounted at " + ro_point);
  Fd ro(::openat(ro_root.get(), name.c_str(), O_PATH | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
  struct stat ro_st {};
  if (ro.get() < 0 || ::fstat(ro.get(), &ro_st) != 0 || ro_st.st_dev != dev.st_rdev) {
    refuse(devnode, "it is not mounted at " + ro_point);
  }

  // 3. The device writable, unless it is write-protected.
  const int zero = 0;
  if (::ioctl(fd.get(), BLKROSET, &zero) != 0) {
    refuse(devnode, "cannot make the device writable (BLKROSET: " + errno_text(errno) + ")");
  }
  int ro_now = 1;
  if (::ioctl(fd.get(), BLKROGET, &ro_now) != 0 || ro_now != 0) {
    (void)set_device_read_only(devnode, true);
    refuse(devnode, "it is write-protected, so nothing was written");
  }
  const auto undo_device = [&] { (void)set_device_read_only(devnode, true); };

  // 4. A second mount, then the filesystem read-write through it.
  folder_ = slot_path(root_, name);
  Fd rw_root;
  Fd point;
  try {
    rw_root.reset(open_root("stick '" + devnode + "'", root_, true));
    point.reset(fresh_mount_point(devnode, rw_root.get(), name, folder_));
  } catch (...) {
    undo_device();
    throw;
  }
  const auto undo_point = [&] {
    point.reset();
    (void)::unlinkat(rw_root.get(), name.c_str(), AT_REMOVEDIR);
    undo_device();
  };
  if (::mount(fd_path(ro.get()).c_str(), fd_path(point.get()).c_str(), nullptr, MS_BIND, nullptr) != 0) {
    const int err = errno;
    undo_point();
    refuse(devnode, "cannot mount it a second time for writing: " + errno_text(err));
  }
  point.reset();
  Fd top(::openat(rw_root.get(), name.c_str(), O_PATH | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
  struct stat top_st {};
  const bool same = top.get() >= 0 && ::fstat(top.get(), &top_st) == 0 && top_st.st_dev == dev.st_rdev;
  const int rc =
      same ? ::mount(nullptr, fd_path(top.get()).c_str(), nullptr, MS_REMOUNT | kWriteMountFlags, nullptr) : -1;
  const int err = same ? errno : EXDEV;
  if (rc != 0) {
    (void)detach_at(rw_root.get(), name);
    top.reset();
    undo_point();
    if (err == EACCES || err == EROFS) refuse(devnode, "it is write-protected, so nothing was written");
    if (err == EXDEV) refuse(devnode, "the device changed while it was being mounted for writing");
    refuse(devnode, "the kernel refused to make its " + fs_ + " filesystem writable: " + errno_text(err));
  }
  open_ = true;
}

WritableStick::~WritableStick() {
  try {
    close();
  } catch (const StickMountError&) {
    // the caller who wanted to know called close() itself
  }
}

void WritableStick::close() {
  if (!open_) return;
  open_ = false;
  (void)close_writable_slot(devnode_, root_, slot_);
}

bool close_writable_slot(const std::string& devnode, const std::string& write_root, int slot) {
  if (slot < 0 || slot > kMaxStickSlot) {
    refuse(devnode, "invalid mount slot " + std::to_string(slot) + " (0 to " + std::to_string(kMaxStickSlot) + ")");
  }
  struct stat dev {};
  {
    Fd fd(open_for_probe(devnode, &dev));
    if (!S_ISBLK(dev.st_mode)) refuse(devnode, "not a block device");
  }
  const std::string root = trimmed_root(write_root);
  const std::string name = std::to_string(slot);
  const std::string shown = slot_path(root, name);
  Fd root_fd(open_root("stick '" + devnode + "'", root, false));
  if (root_fd.get() < 0) {
    (void)set_device_read_only(devnode, true);
    return false;
  }
  Fd top(::openat(root_fd.get(), name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
  if (top.get() < 0) {
    if (errno != ENOENT) refuse(devnode, "cannot open " + shown + ": " + errno_text(errno));
    (void)set_device_read_only(devnode, true);
    return false;
  }
  struct stat st {
  }, parent{};
  if (::fstat(top.get(), &st) != 0 || ::fstat(root_fd.get(), &parent) != 0) {
    refuse(devnode, "cannot examine " + shown + ": " + errno_text(errno));
  }
  if (st.st_dev == parent.st_dev) {  // an empty folder: nothing mounted
    top.reset();
    (void)::unlinkat(root_fd.get(), name.c_str(), AT_REMOVEDIR);
    (void)set_device_read_only(devnode, true);
    return false;
  }
  if (st.st_dev != dev.st_rdev) refuse(devnode, shown + " holds another device's filesystem, so it was left alone");

  // Written through, then read-only again; each step is tried whatever the one before gave.
  std::string problem;
  if (::syncfs(top.get()) != 0) problem = "what was written may not be on it (sync: " + errno_text(errno) + ")";
  if (::mount(nullptr, fd_path(top.get()).c_str(), nullptr, MS_REMOUNT | MS_RDONLY | kWriteMountFlags, nullptr) != 0 &&
      problem.empty()) {
    problem = "cannot make its filesystem read-only again: " + errno_text(errno);
  }
  top.reset();
  const int detach = detach_at(root_fd.get(), name);
  if (detach != 0 && problem.empty()) problem = "cannot unmount " + shown + ": " + errno_text(detach);
  if (::unlinkat(root_fd.get(), name.c_str(), AT_REMOVEDIR) != 0 && problem.empty()) {
    problem = "cannot remove " + shown + ": " + errno_text(errno);
  }
  const int ro = set_device_read_only(devnode, true);
  if (ro != 0 && problem.empty()) problem = "cannot make the device read-only again (BLKROSET: " + errno_text(ro) + ")";
  if (!problem.empty()) refuse(devnode, problem);
  return true;
}

}  // namespace hk::sticks
