// A picture's title and description from its sidecar: read_picture_notes on good and bad
// files written here, and on the shipped library.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <exiv2/exiv2.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <png.h>
#include <zlib.h>

#include "formats/picture_notes.hpp"
#include "formats/png_text.hpp"
#include "kiosk_exe.hpp"
#include "pictures/picture_library.hpp"
#include "test_paths.hpp"

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
  const PictureNotes n = read_picture_notes(with_sidecar(
      dir,
      "title = \"  a horse, seen from the side \"\ndescription = \"\"\"\nA horse standing.\nIts head is up.\"\"\"\n"));
  EXPECT_EQ(n.title, "a horse, seen from the side");
  EXPECT_EQ(n.description, "A horse standing.\nIts head is up.");
  const PictureNotes only =
      read_picture_notes(with_sidecar(dir, "title = \"Ein Pferd, von der Seite gesehen — müde\"\n"));
  EXPECT_EQ(only.title, "Ein Pferd, von der Seite gesehen — müde");
  EXPECT_TRUE(only.description.empty());
  fs::remove_all(dir);
}

TEST(PictureNotes, EachLanguageHasItsOwnTitleAndDescription) {
  const fs::path dir = fresh_dir("notes_languages");
  const PictureNotes n = read_picture_notes(
      with_sidecar(dir,
                   "title = \"a horse\"\ndescription = \"A horse standing.\"\n[fr]\ntitle = \"un cheval\"\n"
                   "description = \"Un cheval debout.\"\n[de]\ntitle = \"ein Pferd\"\n"));
  EXPECT_EQ(notes_in(n, "en").title, "a horse");
  EXPECT_EQ(notes_in(n, "fr").title, "un cheval");
  EXPECT_EQ(notes_in(n, "fr-CA").description, "Un cheval debout.") << "the language subtag's table";
  EXPECT_EQ(notes_in(n, "de").title, "ein Pferd");
  EXPECT_EQ(notes_in(n, "de").description, "A horse standing.") << "no German description: the top-level one";
  EXPECT_EQ(notes_in(n, "es").title, "a horse");
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
      {"titel = \"a horse\"\n",
       "picture notes 'pic.toml': unknown key 'titel' (title, description, guesses and a table per language such as "
       "[fr] are known)"},
      {"[fr]\ntitre = \"un cheval\"\n",
       "picture notes 'pic.toml': unknown key 'fr.titre' (title and description are known)"},
      {"[FR]\ntitle = \"un cheval\"\n", "picture notes 'pic.toml': unknown key 'FR'"},
      {"[de]\ntitle = \"   \"\n", "picture notes 'pic.toml': de.title is blank"},
      {"guesses = \"no\"\n", "picture notes 'pic.toml': guesses must be true or false"},
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
  const std::string cam = picture_with_metadata(dir, "cam.jpg", [](Exiv2::Image& im) {
    im.exifData()["Exif.Image.ImageDescription"] = "OLYMPUS DIGITAL CAMERA";
  });
  EXPECT_TRUE(embedded_notes(cam).title.empty());
  // A title of two lines or over 200 bytes is skipped, not refused.
  const std::string two = picture_with_metadata(
      dir, "two.png", [](Exiv2::Image& im) { im.xmpData()["Xmp.dc.title"] = "lang=x-default one\ntwo"; });
  EXPECT_TRUE(embedded_notes(two).title.empty());
  // No metadata, a damaged file, no file: nothing said, nothing thrown.
  EXPECT_TRUE(embedded_notes(picture_with_metadata(dir, "plain.png", [](Exiv2::Image&) {})).title.empty());
  const unsigned char broken[] = {0xff, 0xd8, 0xff, 0xe1, 0x00, 0x10, 'E', 'x', 'i', 'f',
                                  0,    0,    'g',  'a',  'r',  'b',  'a', 'g', 'e'};
  std::ofstream(dir / "broken.jpg", std::ios::binary).write(reinterpret_cast<const char*>(broken), sizeof broken);
  EXPECT_TRUE(embedded_notes((dir / "broken.jpg").string()).title.empty());
  EXPECT_TRUE(embedded_notes((dir / "missing.png").string()).title.empty());
  fs::remove_all(dir);
}

/// A text chunk to write: keyword, value (UTF-8 for iTXt, Latin-1 bytes for tEXt and zTXt), libpng's
/// compression code (PNG_TEXT_COMPRESSION_NONE: tEXt, _zTXt: zTXt, PNG_ITXT_COMPRESSION_NONE: iTXt).
struct Chunk {
  const char* key;
  std::string value;
  int compression;
};

/// Writes a 16 x 8 grey PNG with libpng, `before` its image data and `after` it.
void write_png_with_text(const fs::path& file, const std::vector<Chunk>& before, const std::vector<Chunk>& after) {
  std::FILE* f = std::fopen(file.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png), end = png_create_info_struct(png);
  png_init_io(png, f);
  png_set_IHDR(png, info, 16, 8, 8, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  const auto texts = [](const std::vector<Chunk>& chunks) {
    std::vector<png_text> t(chunks.size());
    for (std::size_t i = 0; i < chunks.size(); ++i) {
      t[i] = png_text{};
      t[i].compression = chunks[i].compression;
      t[i].key = const_cast<char*>(chunks[i].key);
      t[i].text = const_cast<char*>(chunks[i].value.c_str());
      t[i].text_length = chunks[i].value.size();
    }
    return t;
  };
  std::vector<png_text> b = texts(before), a = texts(after);
  if (!b.empty()) png_set_text(png, info, b.data(), static_cast<int>(b.size()));
  png_write_info(png, info);
  std::vector<png_byte> row(16, 128);
  for (int y = 0; y < 8; ++y) png_write_row(png, row.data());
  if (!a.empty()) png_set_text(png, end, a.data(), static_cast<int>(a.size()));
  png_write_end(png, end);
  png_destroy_info_struct(png, &end);
  png_destroy_write_struct(&png, &info);
  std::fclose(f);
}

TEST(PngText, TitleAndDescriptionFromEveryKindOfTextChunkBeforeOrAfterTheImage) {
  const fs::path dir = fresh_dir("png_text");
  // tEXt before the image data; the Latin-1 "é" (0xE9) comes out as UTF-8.
  write_png_with_text(
      dir / "text.png",
      {{"Title", "A horse at the caf\xe9", PNG_TEXT_COMPRESSION_NONE}, {"Author", "me", PNG_TEXT_COMPRESSION_NONE}},
      {});
  PngText t = read_png_text((dir / "text.png").string());
  EXPECT_EQ(t.title, "A horse at the caf\u00e9");
  EXPECT_EQ(t.description, "");
  // zTXt after the image data, iTXt (UTF-8) before it.
  write_png_with_text(dir / "mixed.png", {{"Title", "Ein Pferd \u2014 von der Seite", PNG_ITXT_COMPRESSION_NONE}},
                      {{"Description", std::string(3000, 'a') + " standing", PNG_TEXT_COMPRESSION_zTXt}});
  t = read_png_text((dir / "mixed.png").string());
  EXPECT_EQ(t.title, "Ein Pferd \u2014 von der Seite");
  EXPECT_EQ(t.description, std::string(3000, 'a') + " standing");
  // Through the notes: the PNG's title is spoken; the 3000-byte description is over the limit and skipped.
  const PictureNotes notes = read_picture_notes((dir / "mixed.png").string());
  EXPECT_EQ(notes.title, "Ein Pferd \u2014 von der Seite");
  EXPECT_EQ(notes.description, "");
  // Not a PNG, no file, a PNG cut short: nothing, no throw.
  EXPECT_EQ(read_png_text((fs::path(HK_TEST_DATA_DIR) / "images" / "apple.jpg").string()).title, "");
  EXPECT_EQ(read_png_text((dir / "missing.png").string()).title, "");
  std::ifstream in(dir / "mixed.png", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(dir / "cut.png", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_EQ(read_png_text((dir / "cut.png").string()).description, "");
  // The image data is skipped, not decoded: with its deflate stream replaced by noise (its CRC made right),
  // the words before and after it are read all the same.
  std::string noisy = bytes;
  for (std::size_t at = 8; at + 12 <= noisy.size();) {
    const auto u = [&](std::size_t i) { return static_cast<std::uint32_t>(static_cast<unsigned char>(noisy[i])); };
    const std::uint32_t len = (u(at) << 24) | (u(at + 1) << 16) | (u(at + 2) << 8) | u(at + 3);
    if (noisy.compare(at + 4, 4, "IDAT") == 0) {
      for (std::uint32_t i = 0; i < len; ++i) noisy[at + 8 + i] = static_cast<char>((i * 151u + 7u) & 0xff);
      const uLong sum = crc32(0L, reinterpret_cast<const Bytef*>(noisy.data() + at + 4), len + 4);
      for (int k = 0; k < 4; ++k) noisy[at + 8 + len + k] = static_cast<char>((sum >> (24 - 8 * k)) & 0xff);
    }
    at += 12 + len;
  }
  ASSERT_NE(noisy, bytes);
  std::ofstream(dir / "noisy.png", std::ios::binary) << noisy;
  t = read_png_text((dir / "noisy.png").string());
  EXPECT_EQ(t.title, "Ein Pferd \u2014 von der Seite");
  EXPECT_EQ(t.description, std::string(3000, 'a') + " standing");
  fs::remove_all(dir);
}

TEST(PngText, ACompressedTextBombIsNotExpanded) {
  // 4 MiB of zeros in a zTXt chunk deflate to about 4 KiB; read_png_text inflates no chunk past 1 MiB.
  const fs::path dir = fresh_dir("png_bomb");
  write_png_with_text(dir / "bomb.png",
                      {{"Title", "fine", PNG_TEXT_COMPRESSION_NONE},
                       {"Description", std::string(4u << 20, '0'), PNG_TEXT_COMPRESSION_zTXt}},
                      {});
  EXPECT_LT(fs::file_size(dir / "bomb.png"), 64u << 10);
  const PngText t = read_png_text((dir / "bomb.png").string());
  EXPECT_EQ(t.description, "") << "refused, not expanded";
  EXPECT_EQ(t.title, "fine") << "the rest of the file is read";
  fs::remove_all(dir);
}

TEST(PictureNotes, EveryShippedPictureHasATitle) {
  const std::vector<std::string> pictures = list_pictures(std::string(HK_TEST_DATA_DIR) + "/../../data/pictures");
  ASSERT_FALSE(pictures.empty());
  for (const std::string& p : pictures) {
    const PictureNotes n = read_picture_notes(p);
    EXPECT_FALSE(n.title.empty()) << p;
    EXPECT_FALSE(n.description.empty()) << p;
    for (const char* lang : {"fr", "de", "es"}) {  // each offered language has its own words
      ASSERT_EQ(n.translations.count(lang), 1u) << p << " has no [" << lang << "]";
      EXPECT_FALSE(n.translations.at(lang).title.empty()) << p << " " << lang;
      EXPECT_FALSE(n.translations.at(lang).description.empty()) << p << " " << lang;
    }
  }
}

}  // namespace
}  // namespace hk::app
