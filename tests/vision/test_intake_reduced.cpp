// Reduced decoding (load_image_reduced): a large JPEG is decoded at the largest 1/2^k that keeps the long
// side asked for, upright as its EXIF orientation says; other formats are decoded in full; and every intake
// refusal comes before any pixel is decoded, whatever size is asked for.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vision/intake.hpp"
#include "hk/error.hpp"

namespace hk::vision {
namespace {

namespace fs = std::filesystem;

const std::string kData = HK_TEST_DATA_DIR;

/// A scratch directory, removed with its contents at the end of the test.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("hk_reduced_" + std::string(info->name()) + "_" +
                                        std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    fs::create_directories(dir_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& name, const std::vector<std::uint8_t>& bytes) const {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    return p.string();
  }

 private:
  fs::path dir_;
};

/// fruits.jpg scaled to `size` (INTER_CUBIC): a photograph with detail at every scale.
cv::Mat photo(cv::Size size) {
  cv::Mat out;
  cv::resize(cv::imread(kData + "/images/fruits.jpg", cv::IMREAD_COLOR), out, size, 0, 0, cv::INTER_CUBIC);
  return out;
}

std::vector<std::uint8_t> encode(const std::string& ext, const cv::Mat& m, std::vector<int> params = {}) {
  std::vector<std::uint8_t> out;
  EXPECT_TRUE(cv::imencode(ext, m, out, params));
  return out;
}

/// `jpeg` with an EXIF APP1 segment (little-endian TIFF, one IFD entry: Orientation = `orientation`) right
/// after its SOI marker.
std::vector<std::uint8_t> with_exif_orientation(const std::vector<std::uint8_t>& jpeg, std::uint16_t orientation) {
  const std::vector<std::uint8_t> tiff = {'I', 'I', 42, 0, 8, 0, 0, 0,  // header, IFD at offset 8
                                          1, 0,                         // one entry
                                          0x12, 0x01, 3, 0, 1, 0, 0, 0,  // tag 0x0112 Orientation, SHORT, count 1
                                          static_cast<std::uint8_t>(orientation), 0, 0, 0,
                                          0, 0, 0, 0};  // no next IFD
  std::vector<std::uint8_t> app1 = {'E', 'x', 'i', 'f', 0, 0};
  app1.insert(app1.end(), tiff.begin(), tiff.end());
  const std::size_t len = app1.size() + 2;
  std::vector<std::uint8_t> out(jpeg.begin(), jpeg.begin() + 2);  // SOI
  out.insert(out.end(), {0xFF, 0xE1, static_cast<std::uint8_t>(len >> 8), static_cast<std::uint8_t>(len & 0xFF)});
  out.insert(out.end(), app1.begin(), app1.end());
  out.insert(out.end(), jpeg.begin() + 2, jpeg.end());
  return out;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// The InputError message of f, which must throw one.
template <class F>
std::string refusal(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InputError";
  return {};
}

TEST(JpegReductionFor, ChoosesTheLargestReductionThatKeepsTheSide) {
  EXPECT_EQ(jpeg_reduction_for(6000, 4000, 800), 4);   // 1500 x 1000 (1/8 would give 750)
  EXPECT_EQ(jpeg_reduction_for(6000, 4000, 1200), 4);  // 1500 >= 1200
  EXPECT_EQ(jpeg_reduction_for(6000, 4000, 1600), 2);  // 3000 x 2000 (1/4 would give 1500)
  EXPECT_EQ(jpeg_reduction_for(4000, 6000, 1600), 2);  // the long side, whichever it is
  EXPECT_EQ(jpeg_reduction_for(1000, 800, 800), 1);    // 1/2 would give 500
  EXPECT_EQ(jpeg_reduction_for(6000, 4000, 0), 1);     // 0: full decode
  EXPECT_EQ(jpeg_reduction_for(6000, 4000, 750), 8);   // never beyond 1/8
  EXPECT_EQ(jpeg_reduction_for(6001, 10, 751), 8);     // libjpeg rounds up: ceil(6001 / 8) = 751
  EXPECT_EQ(jpeg_reduction_for(6000, 10, 751), 4);
  EXPECT_EQ(jpeg_reduction_for(799, 600, 800), 1);     // already smaller than asked
}

TEST(LoadImageReduced, DecodesA24MegapixelJpegAtTheChosenReduction) {
  const TempDir dir;
  const std::vector<std::uint8_t> bytes = encode(".jpg", photo({6000, 4000}), {cv::IMWRITE_JPEG_QUALITY, 92});
  const std::string path = dir.write("phone.jpg", bytes);
  const cv::Mat full = load_image(path, {});
  struct Case {
    int keep, scale, w, h;
  };
  for (const Case c : {Case{800, 4, 1500, 1000}, Case{1200, 4, 1500, 1000}, Case{1600, 2, 3000, 2000}, Case{0, 1, 6000, 4000}}) {
    SCOPED_TRACE("keep " + std::to_string(c.keep));
    const DecodedImage d = load_image_reduced(path, {}, c.keep);
    EXPECT_EQ(d.scale, c.scale);
    EXPECT_EQ(d.bgr.type(), CV_8UC3);
    EXPECT_EQ(d.bgr.size(), cv::Size(c.w, c.h));
    EXPECT_EQ(d.file_width_px, 6000);
    EXPECT_EQ(d.file_height_px, 4000);
    EXPECT_EQ(d.format, "jpeg");
    // The same picture: the full decode averaged over the same blocks differs by little.
    cv::Mat shrunk;
    cv::resize(full, shrunk, d.bgr.size(), 0, 0, cv::INTER_AREA);
    EXPECT_LT(cv::norm(shrunk, d.bgr, cv::NORM_L1) / static_cast<double>(d.bgr.total() * 3), 2.0);
    // And decode_image_reduced on the bytes gives the same pixels.
    const DecodedImage from_bytes = decode_image_reduced(bytes, "phone.jpg", {}, c.keep);
    EXPECT_EQ(cv::norm(from_bytes.bgr, d.bgr, cv::NORM_INF), 0.0);
  }
  EXPECT_EQ(cv::norm(load_image_reduced(path, {}, 0).bgr, full, cv::NORM_INF), 0.0);  // keep 0 is load_image
}

TEST(LoadImageReduced, NeverReducesAPng) {
  const TempDir dir;
  const std::string path = dir.write("big.png", encode(".png", photo({2400, 1600})));
  const DecodedImage d = load_image_reduced(path, {}, 200);
  EXPECT_EQ(d.scale, 1);
  EXPECT_EQ(d.format, "png");
  EXPECT_EQ(d.bgr.size(), cv::Size(2400, 1600));
  EXPECT_EQ(cv::norm(d.bgr, load_image(path, {}), cv::NORM_INF), 0.0);
}

TEST(LoadImageReduced, AppliesTheExifOrientationToAReducedDecode) {
  const TempDir dir;
  cv::Mat landscape = photo({1600, 800});
  cv::rectangle(landscape, cv::Rect(0, 0, 200, 200), cv::Scalar(0, 0, 255), cv::FILLED);  // red corner: top left as stored
  const std::vector<std::uint8_t> plain = encode(".jpg", landscape, {cv::IMWRITE_JPEG_QUALITY, 95});
  const std::string path = dir.write("rotated.jpg", with_exif_orientation(plain, 6));  // 6: turn 90° clockwise to show
  const cv::Mat full = load_image(path, {});
  ASSERT_EQ(full.size(), cv::Size(800, 1600));  // the full decode is upright
  const DecodedImage d = load_image_reduced(path, {}, 400);
  EXPECT_EQ(d.scale, 4);
  EXPECT_EQ(d.bgr.size(), cv::Size(200, 400));
  EXPECT_EQ(d.file_width_px, 800);
  EXPECT_EQ(d.file_height_px, 1600);
  cv::Mat shrunk;
  cv::resize(full, shrunk, d.bgr.size(), 0, 0, cv::INTER_AREA);
  EXPECT_LT(cv::norm(shrunk, d.bgr, cv::NORM_L1) / static_cast<double>(d.bgr.total() * 3), 2.0);
  // Turned clockwise, the stored top-left corner is at the top right.
  const cv::Vec3b top_right = d.bgr.at<cv::Vec3b>(10, d.bgr.cols - 10);
  EXPECT_GT(top_right[2], 200);
  EXPECT_LT(top_right[0], 60);
}

TEST(LoadImageReduced, RefusesEveryBadFileAsLoadImageDoes) {
  const std::string bad = kData + "/bad/";
  for (const std::string name : {"not_an_image.png", "empty.png", "no_such_file.png", "truncated.jpg", "truncated.png", "bad_crc.png",
                                  "huge_declared.png"}) {
    SCOPED_TRACE(name);
    const std::string full = refusal([&] { load_image(bad + name, {}); });
    for (const int keep : {1, 100, 800, 100000}) {
      EXPECT_EQ(refusal([&] { load_image_reduced(bad + name, {}, keep); }), full);
    }
  }
  // A large JPEG cut short is refused for its missing end marker before the reduced decode would run.
  const TempDir dir;
  std::vector<std::uint8_t> cut = encode(".jpg", photo({3000, 2000}));
  cut.resize(cut.size() / 2);
  const std::string msg = refusal([&] { decode_image_reduced(cut, "cut.jpg", {}, 300); });
  EXPECT_TRUE(contains(msg, "0xFFD9")) << msg;
  EXPECT_TRUE(contains(msg, "cut.jpg")) << msg;
  // The limits apply to the file as declared, not to the reduced size.
  ImageLimits narrow;
  narrow.max_width_px = 2999;
  const std::string path = dir.write("wide.jpg", encode(".jpg", photo({3000, 2000})));
  const std::string limit_msg = refusal([&] { load_image_reduced(path, narrow, 300); });
  EXPECT_TRUE(contains(limit_msg, "3000 x 2000 px exceeds")) << limit_msg;
  ImageLimits zero;
  zero.max_pixels = 0;
  EXPECT_THROW(load_image_reduced(path, zero, 300), hk::ArgumentError);
  EXPECT_THROW(decode_image_reduced(cut, "cut.jpg", zero, 300), hk::ArgumentError);
}

}  // namespace
}  // namespace hk::vision
