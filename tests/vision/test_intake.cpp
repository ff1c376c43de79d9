// Image intake: the header parser must agree with the real decoder on every file it accepts, and
// every bad file (the committed ones in tests/data/bad and byte-crafted ones here) must be
// refused with one line that names the file, before any large allocation.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"
#include "temp_dir.hpp"
#include "test_paths.hpp"
#include "vision/intake.hpp"

namespace hk::vision {
namespace {

namespace fs = std::filesystem;

const std::string kData = HK_TEST_DATA_DIR;

std::vector<fs::path> test_images() {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(kData + "/images")) {
    const std::string ext = e.path().extension().string();
    if (ext == ".png" || ext == ".jpg") out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

using test::TempDir;  // a scratch folder for the test, removed at its end

/// Runs f, which must throw InputError; returns its message after checking it is one line and
/// names the file.
template <class F>
std::string refusal(F&& f, const std::string& file_name) {
  try {
    f();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_NE(msg.find(file_name), std::string::npos) << msg;
    return msg;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected InputError for " << file_name;
  return {};
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(ReadImageHeader, AgreesWithTheDecoderOnEveryTestImage) {
  const auto images = test_images();
  ASSERT_GE(images.size(), 20u);
  for (const fs::path& p : images) {
    SCOPED_TRACE(p.filename().string());
    const ImageHeader h = read_image_header(p.string());
    const cv::Mat m = cv::imread(p.string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(m.empty());
    EXPECT_EQ(h.width_px, m.cols);
    EXPECT_EQ(h.height_px, m.rows);
    EXPECT_EQ(h.format, p.extension() == ".png" ? "png" : "jpeg");
  }
}

TEST(ReadImageHeader, AgreesWithTheDecoderForEveryFormatOpenCvWrites) {
  TempDir tmp;
  cv::Mat bgra(23, 37, CV_8UC4, cv::Scalar(10, 200, 30, 255));
  cv::circle(bgra, {18, 11}, 7, cv::Scalar(250, 20, 20, 128), -1);
  struct Case {
    const char* ext;
    std::vector<int> params;
    const char* format;
  };
  const std::vector<Case> cases = {
      {".png", {}, "png"},
      {".jpg", {}, "jpeg"},
      {".jpg", {cv::IMWRITE_JPEG_PROGRESSIVE, 1}, "jpeg"},
      {".bmp", {}, "bmp"},
      {".tiff", {}, "tiff"},
      {".webp", {cv::IMWRITE_WEBP_QUALITY, 80}, "webp"},   // lossy: VP8 or VP8X + ALPH
      {".webp", {cv::IMWRITE_WEBP_QUALITY, 101}, "webp"},  // lossless: VP8L
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    for (const int channels : {1, 3, 4}) {
      const Case& c = cases[i];
      SCOPED_TRACE(std::string(c.ext) + " case " + std::to_string(i) + ", " + std::to_string(channels) + " channels");
      cv::Mat img;
      if (channels == 4) img = bgra;
      if (channels == 3) cv::cvtColor(bgra, img, cv::COLOR_BGRA2BGR);
      if (channels == 1) cv::cvtColor(bgra, img, cv::COLOR_BGRA2GRAY);
      std::vector<std::uint8_t> bytes;
      if (!cv::imencode(c.ext, img, bytes, c.params)) continue;  // e.g. 4-channel JPEG
      const std::string path = tmp.write("img" + std::to_string(i) + "_" + std::to_string(channels) + c.ext, bytes);
      const ImageHeader h = read_image_header(path);
      const cv::Mat decoded = cv::imread(path, cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(decoded.empty());
      EXPECT_EQ(h.width_px, decoded.cols);
      EXPECT_EQ(h.height_px, decoded.rows);
      EXPECT_EQ(h.format, c.format);
      const cv::Mat loaded = load_image(path, {});
      EXPECT_EQ(loaded.type(), CV_8UC3);
      EXPECT_EQ(loaded.size(), decoded.size());
    }
  }
}

std::vector<std::uint8_t> be16(unsigned v) { return {std::uint8_t(v >> 8), std::uint8_t(v)}; }
std::vector<std::uint8_t> be32(std::uint32_t v) {
  return {std::uint8_t(v >> 24), std::uint8_t(v >> 16), std::uint8_t(v >> 8), std::uint8_t(v)};
}
std::vector<std::uint8_t> le16(unsigned v) { return {std::uint8_t(v), std::uint8_t(v >> 8)}; }
std::vector<std::uint8_t> le32(std::uint32_t v) {
  return {std::uint8_t(v), std::uint8_t(v >> 8), std::uint8_t(v >> 16), std::uint8_t(v >> 24)};
}
std::vector<std::uint8_t> le64(std::uint64_t v) {
  std::vector<std::uint8_t> out;
  for (int i = 0; i < 8; ++i) out.push_back(std::uint8_t(v >> (8 * i)));
  return out;
}
std::vector<std::uint8_t> cat(std::initializer_list<std::vector<std::uint8_t>> parts) {
  std::vector<std::uint8_t> out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}
std::vector<std::uint8_t> str(const char* s, std::size_t n) { return {s, s + n}; }

TEST(ReadImageHeader, ParsesHeaderLayoutsOpenCvDoesNotWrite) {
  // Big-endian TIFF, width as SHORT and height as LONG; BigTIFF with LONG8; BMP core header;
  // JPEG whose frame header comes after a large APP segment and fill bytes.
  TempDir tmp;
  const auto mm_tiff = cat({str("MM\0*", 4), be32(8), be16(2),                //
                            be16(256), be16(3), be32(1), be16(300), be16(0),  // ImageWidth SHORT
                            be16(257), be16(4), be32(1), be32(70000),         // ImageLength LONG
                            be32(0)});
  const ImageHeader t = read_image_header(tmp.write("mm.tif", mm_tiff));
  EXPECT_EQ(t.width_px, 300);
  EXPECT_EQ(t.height_px, 70000);
  EXPECT_EQ(t.format, "tiff");

  const auto big_tiff = cat({str("II+\0", 4), le16(8), le16(0), le64(16), le64(2),  //
                             le16(256), le16(16), le64(1), le64(123456),            // LONG8
                             le16(257), le16(3), le64(1), le64(77),                 // SHORT
                             le64(0)});
  const ImageHeader bt = read_image_header(tmp.write("big.tif", big_tiff));
  EXPECT_EQ(bt.width_px, 123456);
  EXPECT_EQ(bt.height_px, 77);

  const auto core_bmp =
      cat({str("BM", 2), le32(26), le32(0), le32(26), le32(12), le16(640), le16(480), le16(1), le16(24)});
  const ImageHeader b = read_image_header(tmp.write("core.bmp", core_bmp));
  EXPECT_EQ(b.width_px, 640);
  EXPECT_EQ(b.height_px, 480);
  EXPECT_EQ(b.format, "bmp");

  std::vector<std::uint8_t> app(3000, 0xAB);
  const auto jpeg = cat({{0xFF, 0xD8},
                         {0xFF, 0xE1},
                         be16(2 + 3000),
                         app,  // APP1
                         {0xFF, 0xFF, 0xFF, 0xC2},
                         be16(11),
                         {8},
                         be16(1234),
                         be16(4321),
                         {1, 1, 0x11, 0},
                         {0xFF, 0xD9}});
  const ImageHeader j = read_image_header(tmp.write("p.jpg", jpeg));
  EXPECT_EQ(j.width_px, 4321);
  EXPECT_EQ(j.height_px, 1234);
  EXPECT_EQ(j.format, "jpeg");
}

TEST(ReadImageHeader, RefusesWhatItCannotParse) {
  const std::string bad = kData + "/bad/";
  EXPECT_TRUE(contains(refusal([&] { read_image_header(bad + "not_an_image.png"); }, "not_an_image.png"),
                       "unknown image format"));
  EXPECT_TRUE(contains(refusal([&] { read_image_header(bad + "empty.png"); }, "empty.png"), "empty"));
  EXPECT_TRUE(contains(refusal([&] { read_image_header(bad + "no_such_file.png"); }, "no_such_file.png"), "not found"));
  EXPECT_TRUE(contains(refusal([&] { read_image_header(bad + "bad_crc.png"); }, "bad_crc.png"), "CRC"));
  refusal([&] { read_image_header(kData + "/bad"); }, "bad");  // a directory

  TempDir tmp;
  const auto zero_width = cat({{0xFF, 0xD8, 0xFF, 0xC0}, be16(11), {8}, be16(10), be16(0), {1, 1, 0x11, 0}});
  refusal([&] { read_image_header(tmp.write("zero.jpg", zero_width)); }, "zero.jpg");
  const auto cut_png = str("\x89PNG\r\n\x1A\n\0\0\0\x0DIHDR\0\0", 18);
  EXPECT_TRUE(contains(refusal([&] { read_image_header(tmp.write("cut.png", cut_png)); }, "cut.png"), "truncated"));
  const auto scan_first = cat({{0xFF, 0xD8, 0xFF, 0xDA}, be16(8), {1, 1, 0, 0, 63, 0}});
  refusal([&] { read_image_header(tmp.write("scan.jpg", scan_first)); }, "scan.jpg");
  const auto tiff_loop = cat({str("II*\0", 4), le32(0xFFFFFFF0)});
  refusal([&] { read_image_header(tmp.write("far.tif", tiff_loop)); }, "far.tif");
}

TEST(ReadImageHeader, ReportsAHugeDeclaredSizeWithoutDecoding) {
  const ImageHeader h = read_image_header(kData + "/bad/huge_declared.png");
  EXPECT_EQ(h.width_px, 100000);
  EXPECT_EQ(h.height_px, 100000);
}

TEST(LoadImage, RefusesEveryCommittedBadFile) {
  const std::string bad = kData + "/bad/";
  const auto load = [&](const std::string& name) { return [&, name] { load_image(bad + name, {}); }; };
  EXPECT_TRUE(contains(refusal(load("not_an_image.png"), "not_an_image.png"), "unknown image format"));
  EXPECT_TRUE(contains(refusal(load("empty.png"), "empty.png"), "empty"));
  EXPECT_TRUE(contains(refusal(load("no_such_file.png"), "no_such_file.png"), "not found"));
  EXPECT_TRUE(contains(refusal(load("truncated.jpg"), "truncated.jpg"), "0xFFD9"));
  EXPECT_TRUE(contains(refusal(load("truncated.png"), "truncated.png"), "truncated PNG"));
  EXPECT_TRUE(contains(refusal(load("bad_crc.png"), "bad_crc.png"), "CRC"));
}

TEST(LoadImage, RefusesADecompressionBombFromItsHeaderAlone) {
  // 45 bytes declaring 10^10 pixels (30 GB as BGR): refused from the header alone, before any decoder
  // runs: the message gives the declared size, which only the header holds.
  const std::string msg = refusal([] { load_image(kData + "/bad/huge_declared.png", {}); }, "huge_declared.png");
  EXPECT_TRUE(contains(msg, "100000 x 100000 px")) << msg;
  EXPECT_TRUE(contains(msg, "limit of 10000 x 10000 px")) << msg;

  ImageLimits wide;  // within the side limits, over the pixel-count limit
  wide.max_width_px = 200000;
  wide.max_height_px = 200000;
  const std::string msg2 = refusal([&] { load_image(kData + "/bad/huge_declared.png", wide); }, "huge_declared.png");
  EXPECT_TRUE(contains(msg2, "limit of 40000000 pixels")) << msg2;
}

TEST(LoadImage, AppliesEachLimit) {
  const std::string fruits = kData + "/images/fruits.jpg";  // 512 x 480, 82 kB
  ImageLimits small_file;
  small_file.max_file_bytes = 1000;
  EXPECT_TRUE(contains(refusal([&] { load_image(fruits, small_file); }, "fruits.jpg"), "limit of 1000 bytes"));
  ImageLimits narrow;
  narrow.max_width_px = 511;
  EXPECT_TRUE(contains(refusal([&] { load_image(fruits, narrow); }, "fruits.jpg"), "512 x 480 px exceeds"));
  ImageLimits short_limit;
  short_limit.max_height_px = 479;
  refusal([&] { load_image(fruits, short_limit); }, "fruits.jpg");
  ImageLimits few;
  few.max_pixels = 512 * 480 - 1;
  EXPECT_TRUE(contains(refusal([&] { load_image(fruits, few); }, "fruits.jpg"), "pixels"));
  ImageLimits exact;
  exact.max_width_px = 512;
  exact.max_height_px = 480;
  exact.max_pixels = 512 * 480;
  exact.max_file_bytes = static_cast<std::int64_t>(fs::file_size(fruits));
  EXPECT_EQ(load_image(fruits, exact).size(), cv::Size(512, 480));
  ImageLimits zero;
  zero.max_pixels = 0;
  EXPECT_THROW(load_image(fruits, zero), hk::ArgumentError);
}

TEST(LoadImage, MessageStaysOnOneLineForAHostileFileName) {
  const std::string msg = refusal([] { load_image(kData + "/bad/evil\nname\x1B[2J.png", {}); }, "evil");
  EXPECT_TRUE(contains(msg, "evil\\x0Aname\\x1B[2J.png")) << msg;
}

TEST(LoadImage, ReturnsBgrOfTheDeclaredSizeForEveryTestImage) {
  for (const fs::path& p : test_images()) {
    SCOPED_TRACE(p.filename().string());
    const cv::Mat m = load_image(p.string(), {});
    const ImageHeader h = read_image_header(p.string());
    EXPECT_EQ(m.type(), CV_8UC3);
    EXPECT_EQ(m.cols, h.width_px);
    EXPECT_EQ(m.rows, h.height_px);
  }
}

TEST(LoadImage, GivesTheSamePixelsAsImreadForEveryOpaqueTestImage) {
  // The checks and the PNG chunk clean-up must not change what is decoded.
  for (const fs::path& p : test_images()) {
    SCOPED_TRACE(p.filename().string());
    if (cv::imread(p.string(), cv::IMREAD_UNCHANGED).channels() == 4) continue;  // composited
    const cv::Mat ours = load_image(p.string(), {});
    const cv::Mat theirs = cv::imread(p.string(), cv::IMREAD_COLOR);
    ASSERT_EQ(ours.size(), theirs.size());
    EXPECT_EQ(cv::norm(ours, theirs, cv::NORM_INF), 0.0);
  }
}

/// PNG bytes with `chunk` (type + data; length and CRC added) inserted after IHDR.
std::vector<std::uint8_t> png_with_chunk(std::vector<std::uint8_t> png, const std::string& type,
                                         const std::string& data, bool good_crc);

TEST(LoadImage, ChecksPngChunks) {
  TempDir tmp;
  cv::Mat img(16, 24, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::rectangle(img, cv::Rect(4, 4, 10, 6), cv::Scalar(255, 255, 255), cv::FILLED);
  std::vector<std::uint8_t> png;
  ASSERT_TRUE(cv::imencode(".png", img, png));

  // An ancillary chunk with a bad checksum is dropped, as libpng would.
  const cv::Mat m = load_image(tmp.write("text.png", png_with_chunk(png, "tEXt", "Comment\0hello", false)), {});
  EXPECT_EQ(cv::norm(m, img, cv::NORM_INF), 0.0);

  // Damage inside the image data is caught by the IDAT checksum.
  std::vector<std::uint8_t> damaged = png;
  const auto idat = std::search(damaged.begin(), damaged.end(), std::begin("IDAT"), std::begin("IDAT") + 4);
  ASSERT_NE(idat, damaged.end());
  idat[6] ^= 0x55;
  EXPECT_TRUE(contains(refusal([&] { load_image(tmp.write("damaged.png", damaged), {}); }, "damaged.png"), "CRC"));

  // No IEND: the file was cut after the image data.
  std::vector<std::uint8_t> cut(png.begin(), png.end() - 12);
  EXPECT_TRUE(contains(refusal([&] { load_image(tmp.write("cut.png", cut), {}); }, "cut.png"), "IEND"));
}

std::vector<std::uint8_t> png_with_chunk(std::vector<std::uint8_t> png, const std::string& type,
                                         const std::string& data, bool good_crc) {
  std::vector<std::uint8_t> chunk = be32(static_cast<std::uint32_t>(data.size()));
  chunk.insert(chunk.end(), type.begin(), type.end());
  chunk.insert(chunk.end(), data.begin(), data.end());
  // CRC-32 (PNG Annex D), computed bitwise: the test must not share the library's table.
  std::uint32_t c = 0xFFFFFFFFU;
  for (std::size_t i = 4; i < chunk.size(); ++i) {
    c ^= chunk[i];
    for (int k = 0; k < 8; ++k) c = (c & 1U) ? 0xEDB88320U ^ (c >> 1) : c >> 1;
  }
  const auto crc = be32((c ^ 0xFFFFFFFFU) ^ (good_crc ? 0U : 1U));
  chunk.insert(chunk.end(), crc.begin(), crc.end());
  png.insert(png.begin() + 33, chunk.begin(), chunk.end());  // after signature (8) + IHDR (25)
  return png;
}

TEST(LoadImage, CompositesTransparencyOverWhite) {
  // Transparent pixels often hold black colour values; shown as black they would hide a dark
  // drawing's outline. A viewer shows them as background.
  TempDir tmp;
  cv::Mat bgra(20, 30, CV_8UC4, cv::Scalar(0, 0, 0, 0));          // transparent black
  bgra(cv::Rect(10, 5, 10, 10)).setTo(cv::Scalar(0, 0, 0, 255));  // opaque black square
  bgra(cv::Rect(0, 0, 4, 4)).setTo(cv::Scalar(0, 0, 255, 128));   // half-transparent red
  std::vector<std::uint8_t> bytes;
  ASSERT_TRUE(cv::imencode(".png", bgra, bytes));
  const cv::Mat m = load_image(tmp.write("alpha.png", bytes), {});
  EXPECT_EQ(m.at<cv::Vec3b>(0, 29), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(m.at<cv::Vec3b>(10, 15), cv::Vec3b(0, 0, 0));
  const cv::Vec3b pink = m.at<cv::Vec3b>(1, 1);
  EXPECT_EQ(pink[2], 255);
  EXPECT_NEAR(pink[0], 127, 2);
}

TEST(ToGrey, ShrinksTheLongSideToTheLimitAndReportsTheScale) {
  double scale = 0;
  const cv::Mat wide(500, 1000, CV_8UC3, cv::Scalar(10, 20, 30));
  const cv::Mat g = to_grey(wide, 800, &scale);
  EXPECT_EQ(g.type(), CV_8UC1);
  EXPECT_EQ(g.size(), cv::Size(800, 400));
  EXPECT_DOUBLE_EQ(scale, 1.25);

  const cv::Mat tall(1001, 333, CV_8UC1, cv::Scalar(7));
  const cv::Mat t = to_grey(tall, 100, &scale);
  EXPECT_EQ(t.rows, 100);
  EXPECT_EQ(t.cols, 33);
  EXPECT_DOUBLE_EQ(scale, 10.01);
  EXPECT_EQ(t.at<std::uint8_t>(50, 10), 7);

  const cv::Mat small(30, 40, CV_8UC3, cv::Scalar(0, 0, 255));
  const cv::Mat s = to_grey(small, 800, &scale);
  EXPECT_EQ(s.size(), small.size());
  EXPECT_DOUBLE_EQ(scale, 1.0);
  EXPECT_NEAR(s.at<std::uint8_t>(0, 0), 76, 1);  // 0.299 * 255: luminance, not a channel pick
  EXPECT_NO_THROW(to_grey(small, 10, nullptr));
}

TEST(ToGrey, RejectsBadArguments) {
  EXPECT_THROW(to_grey(cv::Mat(), 800, nullptr), hk::ArgumentError);
  EXPECT_THROW(to_grey(cv::Mat(4, 4, CV_32FC3), 800, nullptr), hk::ArgumentError);
  EXPECT_THROW(to_grey(cv::Mat(4, 4, CV_8UC3), 0, nullptr), hk::ArgumentError);
}

}  // namespace
}  // namespace hk::vision
