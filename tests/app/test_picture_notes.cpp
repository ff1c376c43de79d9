// A picture's title and description from its sidecar (issue 15, item 4): read_picture_notes on good and bad
// files written here, and on the shipped library.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <exiv2/exiv2.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "kiosk_exe.hpp"
#include "picture_library.hpp"
#include "picture_notes.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;
using test::fresh_dir;

/// Writes `text` as the sidecar of dir/pic.png and returns the picture's path (the picture need not exist).
std::string with_sidecar(const fs::path& dir, const std::string& text) {
  std::ofstream(dir / "pic.toml", std::ios::binary) << text;
  return (dir / "pic.png").string();
}

/// The one-line error read_picture_notes gives for `text`, or "" when it reads.
std::string error_of(const fs::path& dir, const std::string& text) {
  try {
    read_picture_notes(with_sidecar(dir, text));
  } catch (const PictureNotesError& e) {
    return e.what();
  }
  return "";
}

TEST(PictureNotes, ASidecarGivesTheTitleAndDescriptionTrimmed) {
  const fs::path dir = fresh_dir("notes_good");
  EXPECT_EQ(notes_path((dir / "horse.png").string()), (dir / "horse.toml").string());
  const PictureNotes none = read_picture_notes((dir / "nothing.png").string());
  EXPECT_TRUE(none.title.empty());
  EXPECT_TRUE(none.description.empty());
  const PictureNotes n = read_picture_notes(with_sidecar(dir, "title = \"  a horse, seen from the side \"\ndescription = \"\"\"\nA horse standing.\nIts head is up.\"\"\"\n"));
  EXPECT_EQ(n.title, "a horse, seen from the side");
  EXPECT_EQ(n.description, "A horse standing.\nIts head is up.");
  const PictureNotes only = read_picture_notes(with_sidecar(dir, "title = \"Ein Pferd, von der Seite gesehen — müde\"\n"));
  EXPECT_EQ(only.title, "Ein Pferd, von der Seite gesehen — müde");
  EXPECT_TRUE(only.description.empty());
  fs::remove_all(dir);
}

TEST(PictureNotes, BadSidecarsAreRefusedWithOneLineNamingTheFileAndTheLimit) {
  const fs::path dir = fresh_dir("notes_bad");
  const std::string long_title = "title = \"" + std::string(201, 'a') + "\"\n";
  const std::string big = "description = \"" + std::string(17000, 'b') + "\"\n";
  const struct {
    std::string text, expected;
  } cases[] = {
      {"title = \"a horse\n", "picture notes 'pic.toml': TOML syntax error at line 1"},
      {"title = 3\n", "picture notes 'pic.toml': title must be a string"},
      {"titel = \"a horse\"\n", "picture notes 'pic.toml': unknown key 'titel' (title and description are known)"},
      {long_title, "picture notes 'pic.toml': title is 201 bytes, at most 200"},
      {"title = \"   \"\n", "picture notes 'pic.toml': title is blank"},
      {"title = \"two\\nlines\"\n", "picture notes 'pic.toml': title holds a control character (one line, please)"},
      {"description = \"a bell \\u0007\"\n", "picture notes 'pic.toml': description holds a control character"},
      {big, "picture notes 'pic.toml': is 17017 bytes, at most 16384"},
      {"title = \"caf\xe9\"\n", "picture notes 'pic.toml': "},  // Latin-1, not UTF-8: toml++ or our check refuses it
  };
  for (const auto& c : cases) {
    const std::string e = error_of(dir, c.text);
    EXPECT_EQ(e.rfind(c.expected, 0), 0u) << "got: " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  fs::create_directory(dir / "dir.toml");
  EXPECT_THROW(read_picture_notes((dir / "dir.png").string()), PictureNotesError);
  fs::remove_all(dir);
}

/// A small picture written by OpenCV as `name` in dir, its metadata then set by `set` through exiv2.
template <typename F>
std::string picture_with_metadata(const fs::path& dir, const std::string& name, F&& set) {
  const std::string path = (dir / name).string();
  EXPECT_TRUE(cv::imwrite(path, cv::Mat(40, 60, CV_8UC3, cv::Scalar(200, 200, 200))));
  Exiv2::Image::AutoPtr image = Exiv2::ImageFactory::open(path);
  image->readMetadata();
  set(*image);
  image->writeMetadata();
  return path;
}

TEST(PictureNotes, WithoutASidecarThePicturesOwnMetadataSpeaks) {
  const fs::path dir = fresh_dir("notes_embedded");
  // XMP title and description (as photo managers write them), on a PNG.
  const std::string png = picture_with_metadata(dir, "bike.png", [](Exiv2::Image& im) {
    im.xmpData()["Xmp.dc.title"] = "lang=x-default a bicycle leaning on a wall";
    im.xmpData()["Xmp.dc.description"] = "lang=x-default A red bicycle, its front wheel turned to the left.";
  });
  PictureNotes n = read_picture_notes(png);
  EXPECT_EQ(n.title, "a bicycle leaning on a wall");
  EXPECT_EQ(n.description, "A red bicycle, its front wheel turned to the left.");
  // A sidecar wins: it is the operator's.
  std::ofstream(dir / "bike.toml") << "title = \"my bike\"\n";
  n = read_picture_notes(png);
  EXPECT_EQ(n.title, "my bike");
  EXPECT_TRUE(n.description.empty());
  // EXIF ImageDescription and the comment, on a JPEG; a camera's placeholder is no title.
  const std::string jpg = picture_with_metadata(dir, "apple.jpg", [](Exiv2::Image& im) {
    im.exifData()["Exif.Image.ImageDescription"] = "  a red apple on a table ";
    im.setComment("Taken in the kitchen.");
  });
  n = embedded_notes(jpg);
  EXPECT_EQ(n.title, "a red apple on a table");
  EXPECT_EQ(n.description, "Taken in the kitchen.");
  const std::string cam = picture_with_metadata(dir, "cam.jpg", [](Exiv2::Image& im) { im.exifData()["Exif.Image.ImageDescription"] = "OLYMPUS DIGITAL CAMERA"; });
  EXPECT_TRUE(embedded_notes(cam).title.empty());
  // A title of two lines or over 200 bytes is skipped, not refused.
  const std::string two = picture_with_metadata(dir, "two.png", [](Exiv2::Image& im) { im.xmpData()["Xmp.dc.title"] = "lang=x-default one\ntwo"; });
  EXPECT_TRUE(embedded_notes(two).title.empty());
  // No metadata, a damaged file, no file: nothing said, nothing thrown.
  EXPECT_TRUE(embedded_notes(picture_with_metadata(dir, "plain.png", [](Exiv2::Image&) {})).title.empty());
  const unsigned char broken[] = {0xff, 0xd8, 0xff, 0xe1, 0x00, 0x10, 'E', 'x', 'i', 'f', 0, 0, 'g', 'a', 'r', 'b', 'a', 'g', 'e'};
  std::ofstream(dir / "broken.jpg", std::ios::binary).write(reinterpret_cast<const char*>(broken), sizeof broken);
  EXPECT_TRUE(embedded_notes((dir / "broken.jpg").string()).title.empty());
  EXPECT_TRUE(embedded_notes((dir / "missing.png").string()).title.empty());
  fs::remove_all(dir);
}

TEST(PictureNotes, EveryShippedPictureHasATitle) {
  const std::vector<std::string> pictures = list_pictures(std::string(HK_TEST_DATA_DIR) + "/../../data/pictures");
  ASSERT_FALSE(pictures.empty());
  for (const std::string& p : pictures) {
    const PictureNotes n = read_picture_notes(p);
    EXPECT_FALSE(n.title.empty()) << p;
    EXPECT_FALSE(n.description.empty()) << p;
  }
}

}  // namespace
}  // namespace hk::app
