// A take-home copy saved on the visitor's stick (copies/stick_copy.hpp, sticks::WritableStick): names FAT and exFAT
// accept; a new folder with the PDF, SVG and BRF, never over anything; a folder that cannot be written is one line
// and leaves nothing. Then real filesystem images on loop devices, mounted read-only as a visit mounts them in a
// private mount namespace: the copy written through a second, read-write mount while the visit's stays read-only,
// and found on the image afterwards; a full stick, a write-protected stick and a stick that is not FAT or exFAT
// each left as they were. The loop tests need root (CI runs them); the FAT one needs a kernel with a vfat driver.
#include <gtest/gtest.h>

#include <sys/ioctl.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "copies/stick_copy.hpp"
#include "curves.hpp"
#include "loop_stick.hpp"
#include "sticks/usb_stick.hpp"
#include "temp_dir.hpp"
#include "test_paths.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;
using hk::test::Checks;
using hk::test::ChildReport;
using hk::test::in_private_namespace;
using hk::test::LoopDevice;
using sticks::have_mount_capability;

constexpr const char* kPattern = "{title} (tactile copy)";

/// Two circles laid out on A4: a small copy, quick to make.
TactileGraphic circles(const std::string& title) {
  const auto circle = [](Vec2 c, double r_m) { return hk::test::circle_points(c, r_m); };
  TactileInput in;
  in.title = title;
  in.grade = BrailleGrade::one;
  in.picture_lo_m = {-0.07, -0.045};
  in.picture_hi_m = {0.07, 0.045};
  in.curves = {{circle({-0.03, 0.0}, 0.02), true, "sun", 1, 0.126},
               {circle({0.035, 0.0}, 0.015), true, "moon", 2, 0.09}};
  return lay_out_tactile(in, Paper::a4);
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Every file and folder under `dir` (lost+found left out) with its bytes ("" for a folder).
std::map<std::string, std::string> tree_of(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string rel = fs::relative(e.path(), dir).string();
    if (rel.rfind("lost+found", 0) == 0) continue;
    out[rel] = e.is_regular_file() ? read_bytes(e.path()) : std::string();
  }
  return out;
}

/// The copy's three files are in `folder`: a PDF, an SVG naming the shapes, a BRF.
void expect_copy_files(Checks& c, const fs::path& folder, const std::string& base) {
  const std::string pdf = read_bytes(folder / (base + ".pdf"));
  CHILD_CHECK(c, pdf.rfind("%PDF-", 0) == 0 && pdf.find("%%EOF") != std::string::npos, "the PDF is whole");
  const std::string svg = read_bytes(folder / (base + ".svg"));
  CHILD_CHECK(c, svg.find("<svg") != std::string::npos && svg.find("aria-label=\"sun\"") != std::string::npos,
              "the SVG names the sun");
  CHILD_CHECK(c, !read_bytes(folder / (base + ".brf")).empty(), "the BRF is there");
  CHILD_CHECK(c, std::distance(fs::directory_iterator(folder), fs::directory_iterator()) == 3, "three files");
}

/// Reports a forked child's checks to gtest.
void report(const ChildReport& r) {
  for (const auto& f : r.failures) ADD_FAILURE() << f;
  if (!r.skip.empty()) GTEST_SKIP() << r.skip;
}

TEST(StickSafeName, CharactersFatRefusesBecomeDashesAndTheNameStaysWithinItsLength) {
  EXPECT_EQ(stick_safe_name("Sun: and moon?", "x"), "Sun- and moon-");
  EXPECT_EQ(stick_safe_name("a/b\\c*d\"e<f>g|h", "x"), "a-b-c-d-e-f-g-h");
  EXPECT_EQ(stick_safe_name(" ..hidden. ", "x"), "hidden");
  EXPECT_EQ(stick_safe_name("...", "fallback"), "fallback");
  EXPECT_EQ(stick_safe_name("tab\there", "x"), "tab-here");
  // 100 two-byte letters: cut at a letter's boundary, within the limit.
  std::string long_name;
  for (int i = 0; i < 100; ++i) long_name += "\xC3\xA9";  // é
  const std::string cut = stick_safe_name(long_name, "x");
  EXPECT_EQ(cut.size(), kCopyNameMaxBytes);
  EXPECT_EQ(cut.substr(cut.size() - 2), "\xC3\xA9");
}

TEST(StickCopy, ANewFolderWithTheThreeFilesAndNeverOverAnything) {
  hk::test::TempDir tmp("hk_stick_copy");
  const fs::path top = tmp.path();
  const TactileGraphic g = circles("Sun: and moon?");
  const SavedCopy first = save_copy_folder(g, top.string(), kPattern, BrailleGrade::one);
  EXPECT_EQ(first.folder, "Sun- and moon- (tactile copy)");
  EXPECT_EQ(first.files, (std::vector<std::string>{"Sun- and moon-.pdf", "Sun- and moon-.svg", "Sun- and moon-.brf"}));
  Checks c;
  expect_copy_files(c, top / first.folder, "Sun- and moon-");
  for (const auto& f : c.failures) ADD_FAILURE() << f;
  // A file where the second folder would go is left alone: the copy goes to the next name.
  { std::ofstream(top / "Sun- and moon- (tactile copy) 2") << "the visitor's own file"; }
  const SavedCopy second = save_copy_folder(g, top.string(), kPattern, BrailleGrade::one);
  EXPECT_EQ(second.folder, "Sun- and moon- (tactile copy) 3");
  EXPECT_EQ(read_bytes(top / "Sun- and moon- (tactile copy) 2"), "the visitor's own file");
  EXPECT_EQ(tree_of(top / first.folder).size(), 3u);
}

TEST(StickCopy, AFolderThatCannotBeWrittenIsOneLineAndLeavesNothing) {
  hk::test::TempDir tmp("hk_stick_copy");
  const fs::path missing = fs::path(tmp.path()) / "not-there";
  try {
    (void)save_copy_folder(circles("sun"), missing.string(), kPattern, BrailleGrade::one);
    ADD_FAILURE() << "a copy into a missing folder";
  } catch (const CopyNoRoomError&) {
    ADD_FAILURE() << "a missing folder is not a full stick";
  } catch (const CopyError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_NE(what.find(missing.string()), std::string::npos) << what;
  }
  EXPECT_TRUE(fs::is_empty(tmp.path()));
}

// ---------------------------------------------------------------------------------------------------
// Loop devices

#define SKIP_UNLESS_LOOP_STICKS()                                                        \
  do {                                                                                   \
    if (::geteuid() != 0) GTEST_SKIP() << "needs root (loop devices, mount namespaces)"; \
    if (!have_mount_capability()) GTEST_SKIP() << "needs CAP_SYS_ADMIN";                 \
    for (const char* tool : {"losetup", "mkfs.ext4"})                                    \
      if (!hk::test::have_tool(tool)) GTEST_SKIP() << tool << " is not installed";       \
  } while (0)

/// An 8 MB ext4 image holding one picture, on a loop device; where the visit's and the copy's mounts go.
class StickCopyOnALoopStick : public ::testing::Test {
 protected:
  hk::test::TempDir tmp_{"hk_stick_copy_loop"};
  fs::path dir_ = tmp_.path();
  fs::path image_ = dir_ / "stick.img";
  fs::path mount_root_ = dir_ / "run" / "usb";
  std::string write_root_ = sticks::write_root_of(mount_root_.string());

  bool make_ext4_image() {
    fs::create_directories(dir_ / "src");
    fs::copy_file(std::string(HK_TEST_DATA_DIR) + "/images/horse.png", dir_ / "src" / "horse.png");
    std::string out;
    const int rc =
        hk::test::run("mkfs.ext4 -q -d '" + (dir_ / "src").string() + "' '" + image_.string() + "' 8M", &out);
    if (rc != 0) ADD_FAILURE() << "mkfs.ext4 failed: " << out;
    return rc == 0;
  }
};

TEST_F(StickCopyOnALoopStick, SavedThroughASecondMountWhileTheVisitsStaysReadOnly) {
  SKIP_UNLESS_LOOP_STICKS();
  ASSERT_TRUE(make_ext4_image());
  const TactileGraphic g = circles("Horse");
  {
    LoopDevice loop(image_, /*read_only=*/false);
    if (loop.dev().empty()) GTEST_SKIP() << loop.error();
    report(in_private_namespace([&](Checks& c) {
      sticks::MountedStick visit(loop.dev(), mount_root_.string(), 4);
      const fs::path seen = visit.mount_point();
      {
        // The kernel these tests run on may have no FAT driver: ext4 stands in, by the test-only list.
        sticks::WritableStick rw(loop.dev(), mount_root_.string(), 4, write_root_, {"ext4"});
        CHILD_CHECK(c, rw.folder() == write_root_ + "/4", rw.folder());
        CHILD_CHECK(c, hk::test::block_read_only(loop.dev()) == 0, "the device is writable for the write");
        const auto rw_entry = hk::test::find_mount(rw.folder());
        CHILD_CHECK(c, rw_entry && hk::test::has_option(rw_entry->options, "rw"), "the second mount is read-write");
        const auto ro_entry = hk::test::find_mount(seen.string());
        CHILD_CHECK(c, ro_entry && hk::test::has_option(ro_entry->options, "ro"), "the visit's mount stays read-only");
        errno = 0;
        CHILD_CHECK(c, ::mkdir((seen / "through-the-visit").c_str(), 0755) != 0 && errno == EROFS,
                    std::string("mkdir through the visit's mount: ") + std::strerror(errno));
        const SavedCopy saved = save_copy_folder(g, rw.folder(), kPattern, BrailleGrade::one);
        CHILD_CHECK(c, saved.folder == "Horse (tactile copy)", saved.folder);
        rw.close();
        CHILD_CHECK(c, !hk::test::find_mount(rw.folder()).has_value(), "the second mount is gone");
        CHILD_CHECK(c, !fs::exists(rw.folder()), "its folder is removed");
      }
      CHILD_CHECK(c, hk::test::block_read_only(loop.dev()) == 1, "the device is read-only again");
      const auto ro_entry = hk::test::find_mount(seen.string());
      CHILD_CHECK(c, ro_entry && hk::test::has_option(ro_entry->options, "ro"), "the visit's mount is still read-only");
      expect_copy_files(c, seen / "Horse (tactile copy)", "Horse");  // seen by the visit too
      CHILD_CHECK(c, read_bytes(seen / "horse.png") == read_bytes(std::string(HK_TEST_DATA_DIR) + "/images/horse.png"),
                  "the picture on the stick is untouched");
    }));
  }
  // On the image itself: attached anew, mounted read-only, the copy is there.
  LoopDevice again(image_, /*read_only=*/true);
  if (again.dev().empty()) GTEST_SKIP() << again.error();
  report(in_private_namespace([&](Checks& c) {
    sticks::MountedStick visit(again.dev(), mount_root_.string(), 5);
    expect_copy_files(c, fs::path(visit.mount_point()) / "Horse (tactile copy)", "Horse");
  }));
}

TEST_F(StickCopyOnALoopStick, AFullStickIsLeftAsItWas) {
  SKIP_UNLESS_LOOP_STICKS();
  ASSERT_TRUE(make_ext4_image());
  LoopDevice loop(image_, /*read_only=*/false);
  if (loop.dev().empty()) GTEST_SKIP() << loop.error();
  report(in_private_namespace([&](Checks& c) {
    sticks::MountedStick visit(loop.dev(), mount_root_.string(), 0);
    {
      // The visitor's stick, filled to the last block.
      sticks::WritableStick rw(loop.dev(), mount_root_.string(), 0, write_root_, {"ext4"});
      std::ofstream filler(fs::path(rw.folder()) / "filler.bin", std::ios::binary);
      const std::string block(64 * 1024, 'x');
      while (filler.write(block.data(), static_cast<std::streamsize>(block.size()))) {
      }
      filler.close();
      for (int i = 0; i < 64; ++i) std::ofstream(fs::path(rw.folder()) / ("small" + std::to_string(i))) << "x";
      rw.close();
    }
    const auto before = tree_of(visit.mount_point());
    sticks::WritableStick rw(loop.dev(), mount_root_.string(), 0, write_root_, {"ext4"});
    try {
      (void)save_copy_folder(circles("Horse"), rw.folder(), kPattern, BrailleGrade::one);
      c.expect(false, "a copy saved on a full stick");
    } catch (const CopyNoRoomError& e) {
      CHILD_CHECK(c, hk::test::one_line(e.what()), e.what());
    }
    rw.close();
    CHILD_CHECK(c, tree_of(visit.mount_point()) == before, "the full stick's files changed");
  }));
}

TEST_F(StickCopyOnALoopStick, AWriteProtectedStickIsRefusedAndLeftAsItWas) {
  SKIP_UNLESS_LOOP_STICKS();
  ASSERT_TRUE(make_ext4_image());
  const std::string original = read_bytes(image_);
  {
    LoopDevice loop(image_, /*read_only=*/true);  // as a stick with its lock switch on
    if (loop.dev().empty()) GTEST_SKIP() << loop.error();
    report(in_private_namespace([&](Checks& c) {
      sticks::MountedStick visit(loop.dev(), mount_root_.string(), 1);
      try {
        sticks::WritableStick rw(loop.dev(), mount_root_.string(), 1, write_root_, {"ext4"});
        c.expect(false, "opened a write-protected stick for writing");
      } catch (const sticks::StickMountError& e) {
        CHILD_CHECK(c, sticks::stick_write_refusal(e.what()) == sticks::StickWriteRefusal::WriteProtected, e.what());
        CHILD_CHECK(c, hk::test::one_line(e.what()) && std::string(e.what()).find(loop.dev()) != std::string::npos,
                    e.what());
      }
      CHILD_CHECK(c, !fs::exists(write_root_ + "/1"), "no second mount point is left");
      CHILD_CHECK(c, hk::test::block_read_only(loop.dev()) == 1, "the device stays read-only");
      const auto ro_entry = hk::test::find_mount(visit.mount_point());
      CHILD_CHECK(c, ro_entry && hk::test::has_option(ro_entry->options, "ro"), "the visit's mount stays");
    }));
  }
  EXPECT_TRUE(read_bytes(image_) == original) << "the image changed";
}

TEST_F(StickCopyOnALoopStick, OnlyFatAndExfatSticksAreWritten) {
  SKIP_UNLESS_LOOP_STICKS();
  ASSERT_TRUE(make_ext4_image());
  const std::string original = read_bytes(image_);
  {
    LoopDevice loop(image_, /*read_only=*/false);
    if (loop.dev().empty()) GTEST_SKIP() << loop.error();
    report(in_private_namespace([&](Checks& c) {
      sticks::MountedStick visit(loop.dev(), mount_root_.string(), 2);
      try {
        sticks::WritableStick rw(loop.dev(), mount_root_.string(), 2, write_root_);
        c.expect(false, "opened an ext4 stick for writing");
      } catch (const sticks::StickMountError& e) {
        CHILD_CHECK(c, sticks::stick_write_refusal(e.what()) == sticks::StickWriteRefusal::Format, e.what());
        CHILD_CHECK(c,
                    std::string(e.what()).find("(ext4) is not one the kiosk writes (FAT, exFAT)") != std::string::npos,
                    e.what());
      }
      CHILD_CHECK(c, hk::test::block_read_only(loop.dev()) == 1, "the device stays read-only");
    }));
  }
  EXPECT_TRUE(read_bytes(image_) == original) << "the image changed";
}

TEST_F(StickCopyOnALoopStick, AFatStickTakesTheCopyWhereTheKernelReadsFat) {
  SKIP_UNLESS_LOOP_STICKS();
  if (!hk::test::have_tool("mkfs.vfat")) GTEST_SKIP() << "mkfs.vfat is not installed";
  if (!hk::test::kernel_has_filesystem("vfat"))
    GTEST_SKIP() << "this kernel has no vfat driver (CONFIG_VFAT_FS): the FAT route is tested with ext4 standing in";
  std::string out;
  ASSERT_EQ(hk::test::run("mkfs.vfat -C -n KIOSKTEST '" + image_.string() + "' 8192 >/dev/null", &out), 0) << out;
  LoopDevice loop(image_, /*read_only=*/false);
  if (loop.dev().empty()) GTEST_SKIP() << loop.error();
  report(in_private_namespace([&](Checks& c) {
    sticks::MountedStick visit(loop.dev(), mount_root_.string(), 3);
    sticks::WritableStick rw(loop.dev(), mount_root_.string(), 3, write_root_);
    const SavedCopy saved = save_copy_folder(circles("Horse"), rw.folder(), kPattern, BrailleGrade::one);
    rw.close();
    expect_copy_files(c, fs::path(visit.mount_point()) / saved.folder, "Horse");
  }));
}

}  // namespace
}  // namespace hk::app
