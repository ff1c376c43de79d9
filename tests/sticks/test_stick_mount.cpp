// Who mounts a stick (sticks/stick_mount.hpp): the choice between the kiosk itself and the mount helper,
// and the kiosk's side of the helper's protocol, against fake helpers (shell scripts) that answer as
// hk-stick-mount does, refuse, hang, die or talk nonsense. No root needed: nothing is mounted.

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "sticks/stick_mount.hpp"

namespace hk::sticks {
namespace {

namespace fs = std::filesystem;

/// A scratch folder with fake helpers in it, removed at the end.
class FakeHelpers : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/hk_fake_helper_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
    log_ = dir_ / "calls.log";
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  /// An executable shell script `name` whose body is `body`; every call appends its arguments to log_.
  std::string helper(const std::string& name, const std::string& body) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << "#!/bin/sh\necho \"$*\" >> '" << log_.string() << "'\n" << body << "\n";
    fs::permissions(p, fs::perms(0755));
    return p.string();
  }
  std::string calls() const {
    std::ifstream in(log_);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  fs::path dir_, log_;
};

/// The StickMountError text of `f()`, or "" when it did not throw one.
template <class F>
std::string refusal(F f) {
  try {
    f();
  } catch (const StickMountError& e) {
    return e.what();
  }
  return "";
}

bool one_line(const std::string& s) {
  return !s.empty() && s.find('\n') == std::string::npos && s.find('\r') == std::string::npos;
}

const char* kAnswers =
    "case \"$1\" in\n"
    "  mount) echo \"mounted vfat at /run/haptic-kiosk/usb/$3 from $2\" ;;\n"
    "  unmount) echo \"unmounted /run/haptic-kiosk/usb/$2\" ;;\n"
    "esac";

TEST_F(FakeHelpers, TheCapabilityComesFirstThenAnExecutableHelper) {
  const std::string exe = helper("hk-stick-mount", kAnswers);
  EXPECT_EQ(choose_stick_mounter(true, ""), StickMounter::Direct);
  EXPECT_EQ(choose_stick_mounter(true, exe), StickMounter::Direct);
  EXPECT_EQ(choose_stick_mounter(false, exe), StickMounter::Helper);
  EXPECT_EQ(choose_stick_mounter(false, ""), StickMounter::None);
  EXPECT_EQ(choose_stick_mounter(false, (dir_ / "missing").string()), StickMounter::None);
  EXPECT_EQ(choose_stick_mounter(false, dir_.string()), StickMounter::None);  // a folder is not a helper
  const fs::path plain = dir_ / "not-executable";
  std::ofstream(plain) << "#!/bin/sh\n";
  fs::permissions(plain, fs::perms(0644));
  EXPECT_EQ(choose_stick_mounter(false, plain.string()),
            StickMounter::None);  // access(X_OK) wants an x bit, even for root
  EXPECT_STREQ(stick_mounter_name(StickMounter::Direct), "direct");
  EXPECT_STREQ(stick_mounter_name(StickMounter::Helper), "helper");
  EXPECT_STREQ(stick_mounter_name(StickMounter::None), "none");
}

TEST_F(FakeHelpers, HelperPathFromTheEnvironment) {
  const char* old = std::getenv("HK_STICK_HELPER");
  const std::string saved = old != nullptr ? old : "";
  ::setenv("HK_STICK_HELPER", "/opt/x/hk-stick-mount", 1);
  EXPECT_EQ(stick_helper_path(), "/opt/x/hk-stick-mount");
  ::setenv("HK_STICK_HELPER", "", 1);
  EXPECT_EQ(stick_helper_path(), kDefaultStickHelperPath);
  ::unsetenv("HK_STICK_HELPER");
  EXPECT_EQ(stick_helper_path(), "/usr/libexec/haptic-kiosk/hk-stick-mount");
  if (old != nullptr) ::setenv("HK_STICK_HELPER", saved.c_str(), 1);
}

TEST_F(FakeHelpers, MountedThroughTheHelperAndUnmountedWhenDestroyed) {
  const std::string exe = helper("hk-stick-mount", kAnswers);
  {
    auto m = mount_stick(StickMounter::Helper, "/dev/sdz1", "/ignored/by/the/helper", 4, exe);
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(m->devnode(), "/dev/sdz1");
    EXPECT_EQ(m->filesystem(), "vfat");
    EXPECT_EQ(m->mount_point(), "/run/haptic-kiosk/usb/4");
    EXPECT_EQ(calls(), "mount /dev/sdz1 4\n");
  }
  EXPECT_EQ(calls(), "mount /dev/sdz1 4\nunmount 4\n");
}

TEST_F(FakeHelpers, WrittenThroughTheHelpersReadWriteMountAndClosedOnce) {
  const std::string exe = helper("hk-stick-mount",
                                 "case \"$1\" in\n"
                                 "  mount) echo \"mounted vfat at /run/haptic-kiosk/usb/$3 from $2\" ;;\n"
                                 "  mount-rw) echo \"mounted-rw vfat at /run/haptic-kiosk/usb-rw/$3 from $2\" ;;\n"
                                 "  unmount-rw) echo \"unmounted-rw /run/haptic-kiosk/usb-rw/$3\" ;;\n"
                                 "  unmount) echo \"unmounted /run/haptic-kiosk/usb/$2\" ;;\n"
                                 "esac");
  auto m = mount_stick(StickMounter::Helper, "/dev/sdz1", "", 6, exe);
  {
    auto rw = m->mount_writable();
    EXPECT_EQ(rw->folder(), "/run/haptic-kiosk/usb-rw/6");
    rw->close();
    rw->close();  // once is enough
  }
  { auto forgotten = m->mount_writable(); }  // closed when it goes, too
  m.reset();
  EXPECT_EQ(calls(),
            "mount /dev/sdz1 6\nmount-rw /dev/sdz1 6\nunmount-rw /dev/sdz1 6\nmount-rw /dev/sdz1 6\n"
            "unmount-rw /dev/sdz1 6\nunmount 6\n");
}

TEST_F(FakeHelpers, TheHelpersWriteRefusalsKeepTheirKind) {
  const std::string exe = helper(
      "hk-stick-mount",
      "case \"$1\" in\n"
      "  mount) echo \"mounted vfat at /run/haptic-kiosk/usb/$3 from $2\" ;;\n"
      "  mount-rw) echo \"hk-stick-mount: stick '$2': it is write-protected, so nothing was written\" >&2; exit 1 ;;\n"
      "esac");
  auto m = mount_stick(StickMounter::Helper, "/dev/sdz1", "", 0, exe);
  const std::string why = refusal([&] { (void)m->mount_writable(); });
  EXPECT_EQ(why, "stick '/dev/sdz1': it is write-protected, so nothing was written");
  EXPECT_EQ(stick_write_refusal(why), StickWriteRefusal::WriteProtected);
  EXPECT_EQ(stick_write_refusal("stick '/dev/sdz1': its filesystem (ntfs) is not one the kiosk writes (FAT, exFAT)"),
            StickWriteRefusal::Format);
  EXPECT_EQ(stick_write_refusal("stick '/dev/sdz1': the kernel refused"), StickWriteRefusal::Other);
  // An answer that is not the result line: refused, and whatever it did is undone.
  const std::string odd = helper("hk-stick-mount2",
                                 "case \"$1\" in mount) echo \"mounted vfat at /run/haptic-kiosk/usb/$3 from $2\" ;;"
                                 " mount-rw) echo \"all good\" ;; esac");
  auto m2 = mount_stick(StickMounter::Helper, "/dev/sdz2", "", 1, odd);
  EXPECT_NE(refusal([&] { (void)m2->mount_writable(); }).find("not 'mounted-rw FSTYPE at FOLDER'"), std::string::npos);
}

TEST_F(FakeHelpers, UnmountIsIdempotentAndReportsFailure) {
  const std::string exe =
      helper("hk-stick-mount",
             "case \"$1\" in mount) echo \"mounted ext4 at /run/haptic-kiosk/usb/$3 from $2\" ;; *) exit 1 ;; esac");
  auto m = mount_stick(StickMounter::Helper, "/dev/sdz1", "", 0, exe);
  EXPECT_FALSE(m->unmount());  // the helper said no
  EXPECT_TRUE(m->unmount());   // nothing left to do
  m.reset();
  EXPECT_EQ(calls(), "mount /dev/sdz1 0\nunmount 0\n");
}

TEST_F(FakeHelpers, TheHelpersRefusalIsPassedOnInOneLine) {
  const std::string exe =
      helper("hk-stick-mount",
             "echo \"hk-stick-mount: stick '$2': its filesystem (swap) is not one the kiosk reads (FAT, exFAT, NTFS, "
             "ext4, ISO 9660)\" >&2; exit 1");
  const std::string what = refusal([&] { (void)mount_stick(StickMounter::Helper, "/dev/sdz1", "", 1, exe); });
  EXPECT_EQ(what,
            "stick '/dev/sdz1': its filesystem (swap) is not one the kiosk reads (FAT, exFAT, NTFS, ext4, ISO 9660)");
  EXPECT_EQ(calls(), "mount /dev/sdz1 1\n");  // nothing to unmount after a refusal
}

TEST_F(FakeHelpers, ARefusalAboutTheArgumentsNamesTheDevice) {
  const std::string exe =
      helper("hk-stick-mount", "echo \"hk-stick-mount: device '$2': not on the USB bus\" >&2; exit 1");
  const std::string what = refusal([&] { (void)mount_stick(StickMounter::Helper, "/dev/vda", "", 1, exe); });
  EXPECT_TRUE(one_line(what)) << what;
  EXPECT_EQ(what, "stick '/dev/vda': the mount helper refused: device '/dev/vda': not on the USB bus");
}

TEST_F(FakeHelpers, SilenceNonsenseDeathAndHangsAreErrorsNamingTheDevice) {
  struct Case {
    const char* name;
    const char* body;
    const char* must_contain;
  };
  const Case cases[] = {
      {"silent", "exit 3", "the mount helper failed without saying why (exit status 3)"},
      {"nonsense", "echo hello", "the mount helper answered 'hello', not 'mounted FSTYPE at MOUNT_POINT'"},
      {"killed", "kill -9 $$", "the mount helper died of signal 9"},
  };
  for (const Case& c : cases) {
    const std::string exe = helper(c.name, c.body);
    const std::string what = refusal([&] { (void)mount_stick(StickMounter::Helper, "/dev/sdz1", "", 2, exe); });
    EXPECT_TRUE(one_line(what)) << c.name << ": " << what;
    EXPECT_EQ(what.rfind("stick '/dev/sdz1': ", 0), 0U) << c.name << ": " << what;
    EXPECT_NE(what.find(c.must_contain), std::string::npos) << c.name << ": " << what;
  }
  // After an answer it could not use, the kiosk asks the helper to undo whatever it did at the slot.
  EXPECT_NE(calls().find("mount /dev/sdz1 2\nunmount 2\n"), std::string::npos) << calls();

  const std::string slow = helper("slow", "case \"$1\" in mount) exec sleep 30 ;; esac");
  const auto t0 = std::chrono::steady_clock::now();
  const std::string what = refusal([&] { (void)mount_stick(StickMounter::Helper, "/dev/sdz1", "", 5, slow, 0.3); });
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(what, "stick '/dev/sdz1': the mount helper did not answer within 0.3 s");
  EXPECT_LT(s, 5.0);
}

TEST_F(FakeHelpers, NoWayToMountSaysHowToGetOne) {
  const std::string what = refusal([] { (void)mount_stick(StickMounter::None, "/dev/sdz1", "/run/x", 0, ""); });
  EXPECT_TRUE(one_line(what)) << what;
  EXPECT_EQ(what.rfind("stick '/dev/sdz1': cannot mount it: ", 0), 0U) << what;
  EXPECT_NE(what.find("CAP_SYS_ADMIN"), std::string::npos) << what;
  EXPECT_NE(what.find("/usr/libexec/haptic-kiosk/hk-stick-mount"), std::string::npos) << what;
}

TEST_F(FakeHelpers, MissingHelperIsAnErrorNamingIt) {
  const std::string missing = (dir_ / "gone").string();
  const std::string what = refusal([&] { (void)mount_stick(StickMounter::Helper, "/dev/sdz1", "", 0, missing); });
  EXPECT_EQ(what, "stick '/dev/sdz1': cannot start the mount helper " + missing + ": No such file or directory");
}

}  // namespace
}  // namespace hk::sticks
