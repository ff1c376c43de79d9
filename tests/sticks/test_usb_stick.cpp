// USB sticks: real filesystem images on loop devices, mounted by MountedStick inside a private mount
// namespace of a forked child (so nothing is ever mounted in the test's own namespace or on the host),
// checked for read-only-ness from the block layer up, and compared byte for byte before and after.
// Needs root, loop devices and unshare(CLONE_NEWNS); each test skips with the reason where one is missing.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <linux/capability.h>
#include <sys/ioctl.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/syscall.h>
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
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "loop_stick.hpp"
#include "sticks/usb_stick.hpp"
#include "test_paths.hpp"
#include "vision/stick_scan.hpp"

#ifndef ST_NOSYMFOLLOW
#define ST_NOSYMFOLLOW 0x2000  // linux/statfs.h; glibc 2.36 does not name it
#endif

namespace hk::sticks {
using namespace hk::vision;  // the stick's scan (stick_scan.hpp)
using namespace hk::test;    // loop devices and mount namespaces (loop_stick.hpp)
namespace {

namespace fs = std::filesystem;

const std::string kData = HK_TEST_DATA_DIR;
const std::string kSupportedList = "(FAT, exFAT, NTFS, ext4, ISO 9660)";

// ---------------------------------------------------------------------------------------------------
// Helpers (the rest: tests/support/loop_stick.hpp)

/// A scratch folder, removed with its contents at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string tmpl = (fs::temp_directory_path() / "hk_usb_XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// The files a test stick carries: two pictures and a PDF from tests/data, in nested folders.
void copy_documents(const fs::path& src) {
  fs::create_directories(src / "docs" / "deeper");
  fs::copy_file(kData + "/images/horse.png", src / "horse.png");
  fs::copy_file(kData + "/documents/horse_and_page.pdf", src / "docs" / "horse_and_page.pdf");
  fs::copy_file(kData + "/images/butterfly.jpg", src / "docs" / "deeper" / "butterfly.jpg");
}

/// The ext4 stick's tree: the documents, an executable script and a symbolic link to /etc/passwd.
void make_ext4_tree(const fs::path& src) {
  copy_documents(src);
  {
    std::ofstream script(src / "run.sh");
    script << "#!/bin/sh\necho should never run\n";
  }
  fs::permissions(src / "run.sh", fs::perms(0755));
  fs::create_symlink("/etc/passwd", src / "passwd_link");
}

/// Relative paths of everything under `dir` (prefixed with `prefix`), never following a link (the
/// stick is mounted nosymfollow, so even asking where a link leads fails), lost+found left out.
void walk(const fs::path& dir, const std::string& prefix, std::set<std::string>& out) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (prefix.empty() && name == "lost+found") continue;
    const std::string rel = prefix.empty() ? name : prefix + "/" + name;
    out.insert(rel);
    std::error_code ec2;
    if (fs::is_directory(fs::symlink_status(it->path(), ec2))) walk(it->path(), rel, out);
  }
}

std::set<std::string> tree(const fs::path& root) {
  std::set<std::string> out;
  walk(root, "", out);
  return out;
}

/// The mounted tree mirrors `src`: same names, regular files with the same sizes and bytes, folders,
/// and the same symbolic links (not followed).
void check_same_tree(Checks& c, const fs::path& src, const fs::path& mounted) {
  const auto want = tree(src);
  const auto got = tree(mounted);
  std::string listed;
  for (const auto& p : got) listed += p + " ";
  CHILD_CHECK(c, want == got, "listed under the mount point: " + listed);
  for (const auto& rel : want) {
    struct stat s {
    }, m{};
    if (::lstat((src / rel).c_str(), &s) != 0 || ::lstat((mounted / rel).c_str(), &m) != 0) {
      c.expect(false, "cannot lstat " + rel + " on the stick");
      continue;
    }
    if (S_ISREG(s.st_mode)) {
      CHILD_CHECK(c, S_ISREG(m.st_mode), rel);
      CHILD_CHECK(c, m.st_size == s.st_size, rel + " size " + std::to_string(m.st_size));
      CHILD_CHECK(c, read_bytes(mounted / rel) == read_bytes(src / rel), rel + " bytes differ");
    } else if (S_ISDIR(s.st_mode)) {
      CHILD_CHECK(c, S_ISDIR(m.st_mode), rel);
    } else if (S_ISLNK(s.st_mode)) {
      CHILD_CHECK(c, S_ISLNK(m.st_mode), rel);
      std::error_code ec;
      CHILD_CHECK(c, fs::read_symlink(mounted / rel, ec) == fs::read_symlink(src / rel), rel);
    }
  }
}

/// The mount is read-only, nosuid, nodev, noexec, noatime and nosymfollow, in mountinfo and statvfs,
/// and nothing can be created or written through it.
void check_locked_down(Checks& c, const MountedStick& stick, const std::string& fstype) {
  const std::string& mp = stick.mount_point();
  const auto entry = find_mount(mp);
  CHILD_CHECK(c, entry.has_value(), mp + " missing from /proc/self/mountinfo");
  if (entry) {
    for (const char* opt : {"ro", "nosuid", "nodev", "noexec", "noatime", "nosymfollow"}) {
      CHILD_CHECK(c, has_option(entry->options, opt), std::string(opt) + " not in " + entry->options);
    }
    CHILD_CHECK(c, entry->fstype == fstype, entry->fstype);
    CHILD_CHECK(c, entry->source == stick.devnode(), entry->source);
    CHILD_CHECK(c, has_option(entry->super_options, "ro"), entry->super_options);
    if (fstype == "ext4") {
      // "noload" is shown under its other name.
      CHILD_CHECK(c, has_option(entry->super_options, "norecovery") || has_option(entry->super_options, "noload"),
                  entry->super_options);
    }
  }
  struct statvfs sv {};
  CHILD_CHECK(c, ::statvfs(mp.c_str(), &sv) == 0, std::strerror(errno));
  using Flag = std::pair<unsigned long, const char*>;
  for (const auto& [flag, name] :
       {Flag{ST_RDONLY, "ST_RDONLY"}, Flag{ST_NOSUID, "ST_NOSUID"}, Flag{ST_NODEV, "ST_NODEV"},
        Flag{ST_NOEXEC, "ST_NOEXEC"}, Flag{ST_NOATIME, "ST_NOATIME"}, Flag{ST_NOSYMFOLLOW, "ST_NOSYMFOLLOW"}}) {
    CHILD_CHECK(c, (sv.f_flag & flag) != 0, name);
  }
  CHILD_CHECK(c, block_read_only(stick.devnode()) == 1, "BLKROGET");

  errno = 0;
  int fd = ::open((mp + "/new.txt").c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  CHILD_CHECK(c, fd < 0 && errno == EROFS, std::string("create: ") + std::strerror(errno));
  if (fd >= 0) ::close(fd);
  errno = 0;
  fd = ::open((mp + "/horse.png").c_str(), O_WRONLY | O_CLOEXEC);
  CHILD_CHECK(c, fd < 0 && errno == EROFS, std::string("open for writing: ") + std::strerror(errno));
  if (fd >= 0) ::close(fd);
  errno = 0;
  CHILD_CHECK(c, ::mkdir((mp + "/newdir").c_str(), 0700) != 0 && errno == EROFS,
              std::string("mkdir: ") + std::strerror(errno));
  errno = 0;
  CHILD_CHECK(c, ::unlink((mp + "/horse.png").c_str()) != 0 && errno == EROFS,
              std::string("unlink: ") + std::strerror(errno));
}

/// unmount() detaches the stick and removes its mount point; a second call is harmless.
void check_unmount(Checks& c, MountedStick& stick) {
  const std::string mp = stick.mount_point();
  CHILD_CHECK(c, stick.unmount(), "unmount() failed");
  CHILD_CHECK(c, !find_mount(mp).has_value(), mp + " still in /proc/self/mountinfo");
  CHILD_CHECK(c, !fs::exists(fs::symlink_status(mp)), mp + " not removed");
  CHILD_CHECK(c, stick.unmount(), "second unmount() failed");
}

/// StickMountError's what() is one line naming the device.
void check_error_line(Checks& c, const std::string& what, const std::string& dev) {
  CHILD_CHECK(c, one_line(what), what);
  CHILD_CHECK(c, what.rfind("stick '" + dev + "': ", 0) == 0, what);
}

/// Nothing is mounted at, and no folder is left for, `<root>/<slot>`.
void check_nothing_mounted(Checks& c, const fs::path& root, int slot) {
  const std::string mp = (root / std::to_string(slot)).string();
  CHILD_CHECK(c, !find_mount(mp).has_value(), mp + " is mounted");
  CHILD_CHECK(c, !fs::exists(fs::symlink_status(mp)), mp + " was left behind");
}

// ---------------------------------------------------------------------------------------------------
// Without devices: names, hints, capability, errors

TEST(UsbStickBasics, SupportedFilesystems) {
  for (const char* t : {"vfat", "exfat", "ntfs", "ext4", "iso9660"}) EXPECT_TRUE(filesystem_supported(t)) << t;
  for (const char* t :
       {"", "ntfs3", "ext2", "ext3", "btrfs", "xfs", "swap", "squashfs", "udf", "hfsplus", "crypto_LUKS", "VFAT"}) {
    EXPECT_FALSE(filesystem_supported(t)) << t;
  }
}

TEST(UsbStickBasics, CapabilityHintIsOneLineNamingBothWays) {
  const std::string hint = mount_capability_hint();
  EXPECT_TRUE(one_line(hint)) << hint;
  EXPECT_NE(hint.find("CAP_SYS_ADMIN"), std::string::npos) << hint;
  EXPECT_NE(hint.find("setcap cap_sys_admin+ep"), std::string::npos) << hint;
  EXPECT_NE(hint.find("AmbientCapabilities=CAP_SYS_ADMIN"), std::string::npos) << hint;
}

TEST(UsbStickBasics, CapabilityAgreesWithProcStatus) {
  std::ifstream in("/proc/self/status");
  std::string line;
  std::optional<unsigned long long> eff;
  while (std::getline(in, line)) {
    if (line.rfind("CapEff:", 0) == 0) eff = std::stoull(line.substr(7), nullptr, 16);
  }
  if (!eff) GTEST_SKIP() << "no CapEff in /proc/self/status";
  EXPECT_EQ(have_mount_capability(), ((*eff >> CAP_SYS_ADMIN) & 1ULL) != 0);
}

TEST(UsbStickBasics, MissingDeviceIsOneLineNamingIt) {
  const std::string dev = "/nonexistent/hk-sdz9";
  try {
    (void)identify_filesystem(dev);
    ADD_FAILURE() << "identify_filesystem accepted a missing device";
  } catch (const StickMountError& e) {
    Checks c;
    check_error_line(c, e.what(), dev);
    for (const auto& f : c.failures) ADD_FAILURE() << f;
    EXPECT_NE(std::string(e.what()).find("No such file"), std::string::npos) << e.what();
  }
  TempDir tmp;
  try {
    MountedStick stick(dev, (tmp.path() / "mnt").string(), 0);
    ADD_FAILURE() << "MountedStick accepted a missing device";
  } catch (const StickMountError& e) {
    EXPECT_TRUE(one_line(e.what())) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind("stick '" + dev + "': ", 0), 0U) << e.what();
  }
  EXPECT_FALSE(fs::exists(tmp.path() / "mnt" / "0"));
}

TEST(UsbStickBasics, FolderIsNotAFilesystem) {
  TempDir tmp;
  EXPECT_THROW((void)identify_filesystem(tmp.path().string()), StickMountError);
}

// ---------------------------------------------------------------------------------------------------
// FakeBlockEventSource

TEST(UsbStickFakeEvents, EmptyQueueReturnsNothingWithoutWaiting) {
  FakeBlockEventSource src;
  EXPECT_FALSE(src.next(0).has_value());
  EXPECT_FALSE(src.next(0).has_value());
}

TEST(UsbStickFakeEvents, EventsPushedFromAnotherThreadArriveInOrder) {
  FakeBlockEventSource src;
  std::thread producer([&src] {
    src.push({BlockEvent::Action::Add, "/dev/sdb1", "HOLIDAY"});
    src.push({BlockEvent::Action::Remove, "/dev/sdb1", ""});
    src.push({BlockEvent::Action::Add, "/dev/sdc", "PICS"});
  });
  // A generous timeout: it only bounds a failure, the producer decides when each wait ends.
  const auto a = src.next(60000);
  const auto b = src.next(60000);
  const auto c = src.next(60000);
  producer.join();
  ASSERT_TRUE(a && b && c);
  EXPECT_EQ(a->action, BlockEvent::Action::Add);
  EXPECT_EQ(a->devnode, "/dev/sdb1");
  EXPECT_EQ(a->label, "HOLIDAY");
  EXPECT_EQ(b->action, BlockEvent::Action::Remove);
  EXPECT_EQ(b->devnode, "/dev/sdb1");
  EXPECT_EQ(c->devnode, "/dev/sdc");
  EXPECT_EQ(c->label, "PICS");
  EXPECT_FALSE(src.next(0).has_value());
}

TEST(UsbStickFakeEvents, NoTimeoutWaitsForThePush) {
  FakeBlockEventSource src;
  std::thread producer([&src] { src.push({BlockEvent::Action::Add, "/dev/loop7", ""}); });
  const auto e = src.next(-1);
  producer.join();
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->devnode, "/dev/loop7");
}

// ---------------------------------------------------------------------------------------------------
// UdevBlockEventSource

TEST(UsbStickUdev, MonitorStartsOrSaysWhyNot) {
  const bool udevd = ::access("/run/udev/control", F_OK) == 0;
  if (!udevd) {
    // No udevd here (a container): the source refuses with one line instead of never reporting anything.
    try {
      UdevBlockEventSource src;
      ADD_FAILURE() << "UdevBlockEventSource started without udevd";
    } catch (const StickMountError& e) {
      const std::string what = e.what();
      EXPECT_TRUE(one_line(what)) << what;
      EXPECT_EQ(what.rfind("stick monitor: ", 0), 0U) << what;
      EXPECT_NE(what.find("/run/udev/control"), std::string::npos) << what;
    }
    return;
  }
  std::optional<UdevBlockEventSource> src;
  try {
    src.emplace();
  } catch (const StickMountError& e) {
    GTEST_SKIP() << "udevd runs but the monitor cannot start here: " << e.what();
  }
  // Whatever is reported at once (sticks already present) is a device node.
  for (int i = 0; i < 256; ++i) {
    const auto e = src->next(0);
    if (!e) break;
    EXPECT_EQ(e->devnode.rfind("/dev/", 0), 0U) << e->devnode;
    EXPECT_EQ(e->action, BlockEvent::Action::Add);
  }
}

// ---------------------------------------------------------------------------------------------------
// Real images on loop devices

/// An image, its bytes when made (to prove nothing wrote to it), and a loop device over it.
class UsbStickImage : public ::testing::Test {
 protected:
  TempDir tmp_;
  fs::path image_ = tmp_.path() / "stick.img";
  fs::path src_ = tmp_.path() / "src";
  fs::path mount_root_ = tmp_.path() / "run" / "usb";
  std::string original_;

  /// Runs `cmd`, failing (not skipping) the test if it does not succeed.
  bool make(const std::string& cmd) {
    std::string out;
    const int rc = run(cmd, &out);
    if (rc != 0) ADD_FAILURE() << cmd << " failed (" << rc << "): " << out;
    return rc == 0;
  }
  void remember_image() { original_ = read_bytes(image_); }
  /// Makes image_ an 8 MB ext4 filesystem holding src_ and remembers its bytes.
  bool make_ext4_image() {
    if (!make("mkfs.ext4 -q -d '" + src_.string() + "' '" + image_.string() + "' 8M")) return false;
    remember_image();
    return true;
  }
  void expect_image_unchanged() {
    ASSERT_FALSE(original_.empty());
    EXPECT_TRUE(read_bytes(image_) == original_) << "the image changed";
  }
};

TEST_F(UsbStickImage, Ext4MountedReadOnlyAndReadBack) {
  SKIP_UNLESS_ROOT();
  SKIP_UNLESS_TOOL("mkfs.ext4");
  SKIP_UNLESS_TOOL("losetup");
  make_ext4_tree(src_);
  ASSERT_TRUE(make_ext4_image());
  {
    LoopDevice loop(image_, /*read_only=*/true);
    if (loop.dev().empty()) GTEST_SKIP() << loop.error();
    EXPECT_EQ(identify_filesystem(loop.dev()), "ext4");
    EXPECT_EQ(identify_filesystem(image_.string()), "ext4");

    const auto report = in_private_namespace([&](Checks& c) {
      MountedStick stick(loop.dev(), mount_root_.string(), 3);
      CHILD_CHECK(c, stick.devnode() == loop.dev(), stick.devnode());
      CHILD_CHECK(c, stick.filesystem() == "ext4", stick.filesystem());
      CHILD_CHECK(c, stick.mount_point() == (mount_root_ / "3").string(), stick.mount_point());
      struct stat root_st {};
      CHILD_CHECK(c, ::stat(mount_root_.c_str(), &root_st) == 0 && (root_st.st_mode & 07777) == 0700,
                  "mount root mode " + std::to_string(root_st.st_mode & 07777));
      const fs::path mp = stick.mount_point();
      check_same_tree(c, src_, mp);
      check_locked_down(c, stick, "ext4");

      // nosymfollow: the link to /etc/passwd is there but cannot be followed.
      errno = 0;
      const int fd = ::open((mp / "passwd_link").c_str(), O_RDONLY | O_CLOEXEC);
      CHILD_CHECK(c, fd < 0 && errno == ELOOP, std::string("open through the link: ") + std::strerror(errno));
      if (fd >= 0) ::close(fd);
      // noexec: the script keeps its x bits on the stick, but cannot be executed from it.
      struct stat script {};
      CHILD_CHECK(c, ::stat((mp / "run.sh").c_str(), &script) == 0 && (script.st_mode & S_IXUSR) != 0, "run.sh mode");
      errno = 0;
      CHILD_CHECK(c, ::access((mp / "run.sh").c_str(), X_OK) != 0 && errno == EACCES,
                  std::string("access(X_OK): ") + std::strerror(errno));

      // The stick scan sees the two pictures and the PDF, and refuses the link.
      const StickScan scan = scan_stick(mp.string(), ScanLimits{});
      std::set<std::string> docs;
      for (const auto& d : scan.documents) docs.insert(d.path + ":" + d.format);
      CHILD_CHECK(c,
                  (docs == std::set<std::string>{"docs/deeper/butterfly.jpg:jpeg", "docs/horse_and_page.pdf:pdf",
                                                 "horse.png:png"}),
                  std::to_string(docs.size()) + " documents");
      const bool link_refused = std::any_of(scan.refused.begin(), scan.refused.end(),
                                            [](const RefusedEntry& r) { return r.path == "passwd_link"; });
      CHILD_CHECK(c, link_refused, "the symbolic link was not refused");
      CHILD_CHECK(c, scan.complete, scan.stopped_by);

      check_unmount(c, stick);
    });
    REPORT_CHILD(report);
  }
  expect_image_unchanged();
}

TEST_F(UsbStickImage, WritableDeviceIsMadeReadOnlyBeforeMounting) {
  SKIP_UNLESS_ROOT();
  SKIP_UNLESS_TOOL("mkfs.ext4");
  SKIP_UNLESS_TOOL("losetup");
  copy_documents(src_);
  ASSERT_TRUE(make_ext4_image());
  {
    LoopDevice loop(image_, /*read_only=*/false);
    if (loop.dev().empty()) GTEST_SKIP() << loop.error();
    ASSERT_EQ(block_read_only(loop.dev()), 0) << "the loop device should start writable";
    // A folder left at the slot by an earlier run is replaced.
    fs::create_directories(mount_root_ / "0");
    const auto report = in_private_namespace([&](Checks& c) {
      std::string mp;
      {
        MountedStick stick(loop.dev(), mount_root_.string(), 0);
        mp = stick.mount_point();
        CHILD_CHECK(c, block_read_only(loop.dev()) == 1, "BLKROSET did not take");
        check_same_tree(c, src_, mp);
        check_locked_down(c, stick, "ext4");
        // Even the raw device refuses writing now.
        const int fd = ::open(loop.dev().c_str(), O_WRONLY | O_CLOEXEC);
        if (fd >= 0) {
          std::string junk(4096, '\xA5');  // would change the image, which is checked afterwards too
          CHILD_CHECK(c, ::pwrite(fd, junk.data(), junk.size(), 0) < 0, "wrote to the read-only device");
          ::close(fd);
        }
      }  // destructor unmounts
      CHILD_CHECK(c, !find_mount(mp).has_value(), mp + " still mounted after the destructor");
      CHILD_CHECK(c, !fs::exists(fs::symlink_status(mp)), mp + " not removed by the destructor");
    });
    REPORT_CHILD(report);
    // The flag stays on the device after unmounting (documented); LoopDevice resets it.
    EXPECT_EQ(block_read_only(loop.dev()), 1);
  }
  expect_image_unchanged();
}

TEST_F(UsbStickImage, VfatIdentifiedAndMountedOrRefusedByThisKernel) {
  SKIP_UNLESS_ROOT();
  SKIP_UNLESS_TOOL("mkfs.vfat");
  SKIP_UNLESS_TOOL("mcopy");
  SKIP_UNLESS_TOOL("losetup");
  copy_documents(src_);
  ASSERT_TRUE(make("mkfs.vfat -C -n KIOSKTEST '" + image_.string() + "' 8192 >/dev/null"));
  ASSERT_TRUE(make("MTOOLS_SKIP_CHECK=1 mcopy -s -i '" + image_.string() + "' '" + (src_ / "horse.png").string() +
                   "' '" + (src_ / "docs").string() + "' ::/"));
  remember_image();
  const bool kernel_vfat = kernel_has_filesystem("vfat");
  {
    LoopDevice loop(image_, /*read_only=*/true);
    if (loop.dev().empty()) GTEST_SKIP() << loop.error();
    EXPECT_EQ(identify_filesystem(loop.dev()), "vfat");
    const auto report = in_private_namespace([&](Checks& c) {
      if (!kernel_vfat) {
        try {
          MountedStick stick(loop.dev(), mount_root_.string(), 1);
          c.expect(false, "mounted vfat although the kernel lists no vfat driver");
        } catch (const StickMountError& e) {
          check_error_line(c, e.what(), loop.dev());
          CHILD_CHECK(c, std::string(e.what()).find("no vfat driver") != std::string::npos, e.what());
        }
        check_nothing_mounted(c, mount_root_, 1);
        return;
      }
      MountedStick stick(loop.dev(), mount_root_.string(), 1);
      CHILD_CHECK(c, stick.filesystem() == "vfat", stick.filesystem());
      check_same_tree(c, src_, stick.mount_point());
      check_locked_down(c, stick, "vfat");
      struct stat st {};
      CHILD_CHECK(c, ::stat((fs::path(stick.mount_point()) / "horse.png").c_str(), &st) == 0 && st.st_uid == ::getuid(),
                  "files belong to the kiosk");
      check_unmount(c, stick);
    });
    REPORT_CHILD(report);
  }
  expect_image_unchanged();
  if (!kernel_vfat)
    GTEST_SKIP() << "this kernel has no vfat driver (CONFIG_VFAT_FS); checked identification and the refusal only";
}

/// The image, attached read-only, is identified as `type` and refused by MountedStick with the one-line
/// reason, and nothing is mounted.
void expect_refused_filesystem(const fs::path& image, const fs::path& mount_root, const std::string& type) {
  LoopDevice loop(image, /*read_only=*/true);
  if (loop.dev().empty()) GTEST_SKIP() << loop.error();
  EXPECT_EQ(identify_filesystem(loop.dev()), type);
  const auto report = in_private_namespace([&](Checks& c) {
    try {
      MountedStick stick(loop.dev(), mount_root.string(), 2);
      c.expect(false, "mounted a " + type + " stick");
    } catch (const StickMountError& e) {
      const std::string want =
          "stick '" + loop.dev() + "': its filesystem (" + type + ") is not one the kiosk reads " + kSupportedList;
      CHILD_CHECK(c, std::string(e.what()) == want, e.what());
    }
    check_nothing_mounted(c, mount_root, 2);
  });
  REPORT_CHILD(report);
}

TEST_F(UsbStickImage, SwapIsRefused) {
  SKIP_UNLESS_ROOT();
  SKIP_UNLESS_TOOL("mkswap");
  SKIP_UNLESS_TOOL("losetup");
  ASSERT_TRUE(make("truncate -s 8M '" + image_.string() + "' && mkswap '" + image_.string() + "' >/dev/null"));
  remember_image();
  expect_refused_filesystem(image_, mount_root_, "swap");
  expect_image_unchanged();
}

TEST_F(UsbStickImage, Ext2IsRefusedThoughTheKernelCouldMountIt) {
  SKIP_UNLESS_ROOT();
  SKIP_UNLESS_TOOL("mkfs.ext2");
  SKIP_UNLESS_TOOL("losetup");
  copy_documents(src_);
  ASSERT_TRUE(make("mkfs.ext2 -q -d '" + src_.string() + "' '" + image_.string() + "' 8M"));
  remember_image();
  expect_refused_filesystem(image_, mount_root_, "ext2");
  expect_image_unchanged();
}

TEST_F(UsbStickImage, BlankDeviceIsRefused) {
  SKIP_UNLESS_ROOT();
  SKIP_UNLESS_TOOL("losetup");
  ASSERT_TRUE(make("truncate -s 8M '" + image_.string() + "'"));
  remember_image();
  {
    LoopDevice loop(image_, /*read_only=*/true);
    if (loop.dev().empty()) GTEST_SKIP() << loop.error();
    try {
      (void)identify_filesystem(loop.dev());
      ADD_FAILURE() << "identified a filesystem on zeros";
    } catch (const StickMountError& e) {
      Checks c;
      check_error_line(c, e.what(), loop.dev());
      for (const auto& f : c.failures) ADD_FAILURE() << f;
      EXPECT_NE(std::string(e.what()).find("no filesystem"), std::string::npos) << e.what();
    }
    const auto report = in_private_namespace([&](Checks& c) {
      try {
        MountedStick stick(loop.dev(), mount_root_.string(), 0);
        c.expect(false, "mounted a blank device");
      } catch (const StickMountError& e) {
        check_error_line(c, e.what(), loop.dev());
      }
      check_nothing_mounted(c, mount_root_, 0);
      // An image file is not a block device: MountedStick mounts devices only.
      try {
        MountedStick stick(image_.string(), mount_root_.string(), 0);
        c.expect(false, "mounted an image file");
      } catch (const StickMountError& e) {
        check_error_line(c, e.what(), image_.string());
        CHILD_CHECK(c, std::string(e.what()).find("not a block device") != std::string::npos, e.what());
      }
      check_nothing_mounted(c, mount_root_, 0);
    });
    REPORT_CHILD(report);
  }
  expect_image_unchanged();
}

TEST_F(UsbStickImage, WithoutCapabilityNothingIsMounted) {
  SKIP_UNLESS_ROOT();
  SKIP_UNLESS_TOOL("mkfs.ext4");
  SKIP_UNLESS_TOOL("losetup");
  copy_documents(src_);
  ASSERT_TRUE(make_ext4_image());
  {
    LoopDevice loop(image_, /*read_only=*/false);
    if (loop.dev().empty()) GTEST_SKIP() << loop.error();
    const auto report = in_private_namespace([&](Checks& c) {
      // Drop CAP_SYS_ADMIN from the effective, permitted and inheritable sets of this (only) thread.
      __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
      __user_cap_data_struct data[_LINUX_CAPABILITY_U32S_3]{};
      if (::syscall(SYS_capget, &header, data) != 0) {
        c.skip = std::string("capget: ") + std::strerror(errno);
        return;
      }
      const unsigned bit = 1u << (CAP_SYS_ADMIN % 32);
      data[CAP_SYS_ADMIN / 32].effective &= ~bit;
      data[CAP_SYS_ADMIN / 32].permitted &= ~bit;
      data[CAP_SYS_ADMIN / 32].inheritable &= ~bit;
      if (::syscall(SYS_capset, &header, data) != 0) {
        c.skip = std::string("capset: ") + std::strerror(errno);
        return;
      }
      CHILD_CHECK(c, !have_mount_capability(), "CAP_SYS_ADMIN still reported");
      CHILD_CHECK(c, identify_filesystem(loop.dev()) == "ext4", "identification needs no capability");
      try {
        MountedStick stick(loop.dev(), mount_root_.string(), 0);
        c.expect(false, "mounted without CAP_SYS_ADMIN");
      } catch (const StickMountError& e) {
        check_error_line(c, e.what(), loop.dev());
        CHILD_CHECK(c, std::string(e.what()).find("CAP_SYS_ADMIN") != std::string::npos, e.what());
      }
      check_nothing_mounted(c, mount_root_, 0);
      CHILD_CHECK(c, block_read_only(loop.dev()) == 0, "the device was touched");
    });
    REPORT_CHILD(report);
  }
  expect_image_unchanged();
}

}  // namespace
}  // namespace hk::sticks
