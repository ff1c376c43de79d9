// Reduced decoding (load_image_reduced): a large JPEG is decoded at the largest 1/2^k that keeps the long
// side asked for, upright as its EXIF orientation says; a large PNG is read by rows and averaged by blocks,
// exactly the block means of OpenCV's full decode, for every kind of PNG; interlaced PNGs, PNGs with eXIf
// and other formats are decoded in full; and every intake refusal comes before any pixel is decoded,
// whatever size is asked for.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <png.h>
#include <zlib.h>
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

using test::TempDir;  // a scratch folder for the test, removed at its end

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
  const std::vector<std::uint8_t> tiff = {'I',
                                          'I',
                                          42,
                                          0,
                                          8,
                                          0,
                                          0,
                                          0,  // header, IFD at offset 8
                                          1,
                                          0,  // one entry
                                          0x12,
                                          0x01,
                                          3,
                                          0,
                                          1,
                                          0,
                                          0,
                                          0,  // tag 0x0112 Orientation, SHORT, count 1
                                          static_cast<std::uint8_t>(orientation),
                                          0,
                                          0,
                                          0,
                                          0,
                                          0,
                                          0,
                                          0};  // no next IFD
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

TEST(DecodeReductionFor, ChoosesTheLargestReductionThatKeepsTheSide) {
  EXPECT_EQ(decode_reduction_for(6000, 4000, 800), 4);   // 1500 x 1000 (1/8 would give 750)
  EXPECT_EQ(decode_reduction_for(6000, 4000, 1200), 4);  // 1500 >= 1200
  EXPECT_EQ(decode_reduction_for(6000, 4000, 1600), 2);  // 3000 x 2000 (1/4 would give 1500)
  EXPECT_EQ(decode_reduction_for(4000, 6000, 1600), 2);  // the long side, whichever it is
  EXPECT_EQ(decode_reduction_for(1000, 800, 800), 1);    // 1/2 would give 500
  EXPECT_EQ(decode_reduction_for(6000, 4000, 0), 1);     // 0: full decode
  EXPECT_EQ(decode_reduction_for(6000, 4000, 750), 8);   // never beyond 1/8
  EXPECT_EQ(decode_reduction_for(6001, 10, 751), 8);     // libjpeg rounds up: ceil(6001 / 8) = 751
  EXPECT_EQ(decode_reduction_for(6000, 10, 751), 4);
  EXPECT_EQ(decode_reduction_for(799, 600, 800), 1);  // already smaller than asked
}

TEST(LoadImageReduced, DecodesA24MegapixelJpegAtTheChosenReduction) {
  const TempDir dir;
  const std::vector<std::uint8_t> bytes = encode(".jpg", photo({6000, 4000}), {cv::IMWRITE_JPEG_QUALITY, 92});
  const std::string path = dir.write("phone.jpg", bytes);
  const cv::Mat full = load_image(path, {});
  struct Case {
    int keep, scale, w, h;
  };
  for (const Case c :
       {Case{800, 4, 1500, 1000}, Case{1200, 4, 1500, 1000}, Case{1600, 2, 3000, 2000}, Case{0, 1, 6000, 4000}}) {
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

/// What a PNG holds, for write_png: libpng's colour type, bit depth and interlace method, the rows as PNG
/// stores them (big-endian 16-bit samples), and a palette and tRNS when given.
struct PngSpec {
  int width = 0, height = 0;
  int colour_type = PNG_COLOR_TYPE_RGB;
  int bit_depth = 8;
  int interlace = PNG_INTERLACE_NONE;
  std::vector<std::vector<png_byte>> rows;
  std::vector<png_color> palette;
  std::vector<png_byte> trns_alpha;         ///< palette entries' alpha
  std::optional<png_color_16> trns_colour;  ///< the one transparent grey or RGB value
};

/// An empty PngSpec of that size and kind (rows, palette and tRNS to add).
PngSpec png_spec(cv::Size size, int colour_type, int bit_depth, int interlace = PNG_INTERLACE_NONE) {
  PngSpec s;
  s.width = size.width;
  s.height = size.height;
  s.colour_type = colour_type;
  s.bit_depth = bit_depth;
  s.interlace = interlace;
  return s;
}

void append_bytes(png_structp png, png_bytep data, png_size_t n) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + n);
}

/// `spec` written by libpng (which interlaces it when asked).
std::vector<std::uint8_t> write_png(const PngSpec& spec) {
  std::vector<std::uint8_t> out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_set_write_fn(png, &out, append_bytes, nullptr);
  png_set_IHDR(png, info, spec.width, spec.height, spec.bit_depth, spec.colour_type, spec.interlace,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (!spec.palette.empty()) png_set_PLTE(png, info, spec.palette.data(), static_cast<int>(spec.palette.size()));
  if (!spec.trns_alpha.empty())
    png_set_tRNS(png, info, spec.trns_alpha.data(), static_cast<int>(spec.trns_alpha.size()), nullptr);
  if (spec.trns_colour) png_set_tRNS(png, info, nullptr, 0, &*spec.trns_colour);
  png_write_info(png, info);
  std::vector<png_bytep> rows;
  for (const auto& r : spec.rows) rows.push_back(const_cast<png_bytep>(r.data()));
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

/// A w x h test pattern: fruits.jpg's grey level at each pixel, so every block average differs.
cv::Mat grey_photo(cv::Size size) {
  cv::Mat g;
  cv::cvtColor(photo(size), g, cv::COLOR_BGR2GRAY);
  return g;
}

/// The PNGs OpenCV cannot write: a 16-colour palette with transparent entries, 2-bit grey, grey and RGB with
/// one transparent value (tRNS), each w x h.
std::vector<std::pair<std::string, PngSpec>> libpng_variants(cv::Size size) {
  const cv::Mat g = grey_photo(size);
  const cv::Mat c = photo(size);
  std::vector<std::pair<std::string, PngSpec>> out;
  PngSpec pal = png_spec(size, PNG_COLOR_TYPE_PALETTE, 8);
  for (int i = 0; i < 16; ++i)
    pal.palette.push_back(
        {static_cast<png_byte>(i * 17), static_cast<png_byte>(255 - i * 17), static_cast<png_byte>(i * 5)});
  for (int i = 0; i < 16; ++i) pal.trns_alpha.push_back(static_cast<png_byte>(i * 16));
  PngSpec two_bit = png_spec(size, PNG_COLOR_TYPE_GRAY, 2);
  PngSpec grey_trns = png_spec(size, PNG_COLOR_TYPE_GRAY, 8);
  grey_trns.trns_colour = png_color_16{0, 0, 0, 0, 128};
  PngSpec rgb_trns = png_spec(size, PNG_COLOR_TYPE_RGB, 8);
  for (int y = 0; y < size.height; ++y) {
    std::vector<png_byte> p(size.width), t((size.width + 3) / 4), gr(size.width), rgb(size.width * 3);
    for (int x = 0; x < size.width; ++x) {
      const int v = g.at<std::uint8_t>(y, x);
      p[x] = static_cast<png_byte>(v / 16);
      t[x / 4] = static_cast<png_byte>(t[x / 4] | ((v / 64) << (6 - 2 * (x % 4))));
      gr[x] = static_cast<png_byte>(v / 2 * 2);  // even, so that the transparent 128 is common
      const cv::Vec3b bgr = c.at<cv::Vec3b>(y, x);
      rgb[3 * x] = static_cast<png_byte>(bgr[2] & 0xF0);
      rgb[3 * x + 1] = static_cast<png_byte>(bgr[1] & 0xF0);
      rgb[3 * x + 2] = static_cast<png_byte>(bgr[0] & 0xF0);
    }
    pal.rows.push_back(p);
    two_bit.rows.push_back(t);
    grey_trns.rows.push_back(gr);
    rgb_trns.rows.push_back(rgb);
  }
  rgb_trns.trns_colour = png_color_16{0, rgb_trns.rows[0][0], rgb_trns.rows[0][1], rgb_trns.rows[0][2], 0};
  out.emplace_back("palette with tRNS", pal);
  out.emplace_back("grey 2-bit", two_bit);
  out.emplace_back("grey with tRNS", grey_trns);
  out.emplace_back("RGB with tRNS", rgb_trns);
  return out;
}

/// What load_image promises for a PNG, derived from OpenCV alone: cv::imdecode's colour pixels or, when it
/// decodes four channels, those composited over white (out = a * c + (1 - a) * 255, a in [0, 1]).
cv::Mat reference_decode(const std::vector<std::uint8_t>& png) {
  const cv::Mat colour = cv::imdecode(png, cv::IMREAD_COLOR);
  const cv::Mat all = cv::imdecode(png, cv::IMREAD_UNCHANGED);
  if (all.channels() != 4) return colour;
  cv::Mat f;
  all.convertTo(f, CV_32F, all.depth() == CV_16U ? 1.0 / 65535.0 : 1.0 / 255.0);
  cv::Mat out(all.size(), CV_8UC3);
  for (int y = 0; y < f.rows; ++y) {
    for (int x = 0; x < f.cols; ++x) {
      const cv::Vec4f p = f.at<cv::Vec4f>(y, x);
      for (int k = 0; k < 3; ++k)
        out.at<cv::Vec3b>(y, x)[k] = cv::saturate_cast<std::uint8_t>(255.0f * (p[3] * p[k] + 1.0f - p[3]));
    }
  }
  return out;
}

/// `full` averaged over scale x scale blocks, the right and bottom edges first extended by repeating the last
/// column and row to whole blocks.
cv::Mat block_means(const cv::Mat& full, int scale) {
  const int w = (full.cols + scale - 1) / scale, h = (full.rows + scale - 1) / scale;
  cv::Mat padded, out;
  cv::copyMakeBorder(full, padded, 0, h * scale - full.rows, 0, w * scale - full.cols, cv::BORDER_REPLICATE);
  cv::resize(padded, out, {w, h}, 0, 0, cv::INTER_AREA);
  return out;
}

TEST(LoadImageReduced, DecodesAPngToTheBlockMeansOfItsFullDecode) {
  const cv::Size size(1203, 803);  // neither side a multiple of 2, 4 or 8
  const cv::Mat c = photo(size);
  cv::Mat alpha(size, CV_8UC1);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      alpha.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>((x * 255) / (size.width - 1));
  cv::Mat bgra, c16, bgra16, g16;
  cv::merge(std::vector<cv::Mat>{c, alpha}, bgra);  // alpha from 0 at the left to 1 at the right
  c.convertTo(c16, CV_16UC3, 257.0);
  c16 += cv::Scalar::all(3);  // low bytes that differ from the high ones
  bgra.convertTo(bgra16, CV_16UC4, 257.0);
  grey_photo(size).convertTo(g16, CV_16UC1, 257.0);
  std::vector<std::pair<std::string, std::vector<std::uint8_t>>> pngs = {
      {"RGB 8-bit", encode(".png", c)},
      {"RGBA 8-bit", encode(".png", bgra)},
      {"RGB 16-bit", encode(".png", c16)},
      {"RGBA 16-bit", encode(".png", bgra16)},
      {"grey 8-bit", encode(".png", grey_photo(size))},
      {"grey 16-bit", encode(".png", g16)}};
  for (const auto& [name, spec] : libpng_variants(size)) pngs.emplace_back(name, write_png(spec));
  for (const auto& [name, png] : pngs) {
    SCOPED_TRACE(name);
    const cv::Mat full = reference_decode(png);
    ASSERT_EQ(full.size(), size);
    EXPECT_EQ(cv::norm(decode_image(png, name, {}), full, cv::NORM_INF), 0.0);  // the full decode is OpenCV's
    for (const int keep : {600, 300, 150}) {
      const DecodedImage d = decode_image_reduced(png, name, {}, keep);
      EXPECT_EQ(d.scale, decode_reduction_for(size.width, size.height, keep)) << keep;
      EXPECT_EQ(d.format, "png");
      EXPECT_EQ(d.file_width_px, size.width);
      EXPECT_EQ(d.file_height_px, size.height);
      EXPECT_EQ(d.bgr.size(), cv::Size((size.width + d.scale - 1) / d.scale, (size.height + d.scale - 1) / d.scale));
      EXPECT_EQ(cv::norm(d.bgr, block_means(full, d.scale), cv::NORM_INF), 0.0) << "keep " << keep;
    }
  }
}

TEST(LoadImageReduced, DecodesAnInterlacedPngOrOneWithAnExifChunkInFull) {
  const cv::Size size(1203, 803);
  PngSpec spec = png_spec(size, PNG_COLOR_TYPE_GRAY, 8, PNG_INTERLACE_ADAM7);
  const cv::Mat g = grey_photo(size);
  for (int y = 0; y < size.height; ++y)
    spec.rows.emplace_back(g.ptr<std::uint8_t>(y), g.ptr<std::uint8_t>(y) + size.width);
  const std::vector<std::uint8_t> interlaced = write_png(spec);
  // An eXIf chunk (orientation 1: as stored) after the IHDR: 8 + 25 bytes in.
  std::vector<std::uint8_t> exif = encode(".png", photo(size));
  const std::vector<std::uint8_t> body = {'e',  'X', 'I', 'f', 'I', 'I', 42, 0, 8, 0, 0, 0, 1, 0, 0x12,
                                          0x01, 3,   0,   1,   0,   0,   0,  1, 0, 0, 0, 0, 0, 0, 0};
  std::vector<std::uint8_t> chunk = {0, 0, 0, static_cast<std::uint8_t>(body.size() - 4)};
  chunk.insert(chunk.end(), body.begin(), body.end());
  const auto crc = static_cast<std::uint32_t>(crc32(0, body.data(), static_cast<uInt>(body.size())));
  for (const int shift : {24, 16, 8, 0}) chunk.push_back(static_cast<std::uint8_t>(crc >> shift));
  exif.insert(exif.begin() + 33, chunk.begin(), chunk.end());
  for (const auto& [name, png] : {std::pair{"interlaced", interlaced}, std::pair{"eXIf", exif}}) {
    SCOPED_TRACE(name);
    const DecodedImage d = decode_image_reduced(png, name, {}, 150);
    EXPECT_EQ(d.scale, 1);
    EXPECT_EQ(d.bgr.size(), size);
    EXPECT_EQ(cv::norm(d.bgr, cv::imdecode(png, cv::IMREAD_COLOR), cv::NORM_INF), 0.0);
  }
}

TEST(LoadImageReduced, RefusesAPngWhoseImageDataIsDamagedWithLibpngsReason) {
  // Both files' chunks are whole and their CRCs right (tests/data/bad/IMAGES.md): only inflating and
  // unfiltering the image data finds what is wrong.
  const std::string bad = kData + "/bad/";
  for (const auto& [name, reason] : {std::pair{"damaged_idat.png", "bad adaptive filter value"},
                                     std::pair{"short_idat.png", "Not enough image data"}}) {
    SCOPED_TRACE(name);
    const std::string full = refusal([&] { load_image(bad + name, {}); });
    EXPECT_EQ(full,
              "image '" + bad + name + "': the png data could not be decoded (corrupt or unsupported): " + reason);
    for (const int keep : {50, 100, 200}) EXPECT_EQ(refusal([&] { load_image_reduced(bad + name, {}, keep); }), full);
  }
}

TEST(LoadImageReduced, AppliesTheExifOrientationToAReducedDecode) {
  const TempDir dir;
  cv::Mat landscape = photo({1600, 800});
  cv::rectangle(landscape, cv::Rect(0, 0, 200, 200), cv::Scalar(0, 0, 255),
                cv::FILLED);  // red corner: top left as stored
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
  for (const std::string name : {"not_an_image.png", "empty.png", "no_such_file.png", "truncated.jpg", "truncated.png",
                                 "bad_crc.png", "huge_declared.png"}) {
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
