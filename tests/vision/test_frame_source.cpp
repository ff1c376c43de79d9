// Frame sources (vision/frame_source.hpp): the spec parser, the file source on one image and
// on a folder of frames written here, and the camera paths on a machine that may have no camera at all (the
// CI machine has none): listing never throws and prints nothing, a missing camera or a node that is not a
// camera is refused with one line.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "hk/error.hpp"
#include "temp_dir.hpp"
#include "test_paths.hpp"
#include "vision/frame_source.hpp"
#include "vision/intake.hpp"

namespace hk::vision {
namespace {

namespace fs = std::filesystem;

const std::string kImages = std::string(HK_TEST_DATA_DIR) + "/images";

using test::TempDir;  // a scratch folder for the test, removed at its end

/// PNG bytes of a 64 x 48 px frame: noise (so the file is a few kB) with its top-left pixel set to `mark`.
std::vector<std::uint8_t> png_frame(std::uint8_t mark) {
  cv::Mat img(48, 64, CV_8UC3);
  cv::RNG rng(mark);
  rng.fill(img, cv::RNG::UNIFORM, 0, 256);
  img.at<cv::Vec3b>(0, 0) = cv::Vec3b(mark, mark, mark);
  std::vector<std::uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(".png", img, bytes));
  return bytes;
}

std::vector<std::uint8_t> text_bytes(const std::string& s) { return std::vector<std::uint8_t>(s.begin(), s.end()); }

/// Runs f, which must throw CameraError; returns its message after checking it is one line and contains
/// every needle.
template <class F>
std::string camera_refusal(F&& f, const std::vector<std::string>& needles) {
  try {
    f();
  } catch (const CameraError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\r'), std::string::npos) << msg;
    for (const std::string& n : needles) EXPECT_NE(msg.find(n), std::string::npos) << "'" << n << "' not in: " << msg;
    return msg;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected CameraError, got: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected CameraError";
  return {};
}

std::unique_ptr<FrameSource> open_spec(const std::string& spec, const FrameSourceParams& params = {}) {
  return open_frame_source(parse_source_spec(spec), params);
}

// --- spec parsing -------------------------------------------------------------------------------------------

TEST(FrameSourceSpec, ParsesEveryKind) {
  SourceSpec s = parse_source_spec("file:frames/");
  EXPECT_EQ(s.kind, SourceSpec::Kind::File);
  EXPECT_EQ(s.path, "frames/");
  EXPECT_EQ(s.str(), "file:frames/");

  s = parse_source_spec("file:C:odd:name.png");  // only the first ':' separates the kind
  EXPECT_EQ(s.kind, SourceSpec::Kind::File);
  EXPECT_EQ(s.path, "C:odd:name.png");

  s = parse_source_spec("libcamera:0");
  EXPECT_EQ(s.kind, SourceSpec::Kind::Libcamera);
  EXPECT_EQ(s.index, 0);
  EXPECT_EQ(s.str(), "libcamera:0");
  EXPECT_EQ(parse_source_spec("libcamera:63").index, 63);
  EXPECT_EQ(parse_source_spec("libcamera:7").str(), "libcamera:7");

  s = parse_source_spec("v4l2:/dev/video0");
  EXPECT_EQ(s.kind, SourceSpec::Kind::V4l2);
  EXPECT_EQ(s.path, "/dev/video0");
  EXPECT_EQ(s.str(), "v4l2:/dev/video0");

  s = parse_source_spec("v4l2:3");  // a bare number is /dev/videoN
  EXPECT_EQ(s.kind, SourceSpec::Kind::V4l2);
  EXPECT_EQ(s.path, "/dev/video3");
  EXPECT_EQ(s.str(), "v4l2:/dev/video3");
}

TEST(FrameSourceSpec, RefusesBadSpecsInOneLineNamingThem) {
  camera_refusal([] { parse_source_spec("usb:1"); },
                 {"'usb:1'", "unknown kind", "file:PATH", "libcamera:N", "v4l2:DEV"});
  camera_refusal([] { parse_source_spec(""); }, {"''", "unknown kind"});
  camera_refusal([] { parse_source_spec("frames"); }, {"'frames'", "unknown kind"});
  camera_refusal([] { parse_source_spec("FILE:x.png"); }, {"'FILE:x.png'", "unknown kind"});
  camera_refusal([] { parse_source_spec("file:"); }, {"'file:'", "empty path"});
  camera_refusal([] { parse_source_spec("libcamera:"); }, {"'libcamera:'", "index"});
  camera_refusal([] { parse_source_spec("libcamera:64"); }, {"'libcamera:64'", "0 to 63"});
  camera_refusal([] { parse_source_spec("libcamera:-1"); }, {"'libcamera:-1'", "index"});
  camera_refusal([] { parse_source_spec("libcamera:+1"); }, {"'libcamera:+1'", "index"});
  camera_refusal([] { parse_source_spec("libcamera: 1"); }, {"'libcamera: 1'", "index"});
  camera_refusal([] { parse_source_spec("libcamera:1x"); }, {"'libcamera:1x'", "index"});
  camera_refusal([] { parse_source_spec("libcamera:99999999999999999999"); }, {"'libcamera:99999999999999999999'"});
  camera_refusal([] { parse_source_spec("v4l2:"); }, {"'v4l2:'", "empty device"});
  camera_refusal([] { parse_source_spec("v4l2:video0"); }, {"'v4l2:video0'", "starting with '/'"});
  // Control characters are escaped so the message stays on one line.
  camera_refusal([] { parse_source_spec("usb:\n\x1b[31m"); }, {"'usb:\\x0A\\x1B[31m'"});
  camera_refusal([] { parse_source_spec(std::string("file:a\0b", 8)); }, {"'file:a\\x00b'", "NUL"});
}

// --- the file source ----------------------------------------------------------------------------------------

TEST(FrameSourceFile, SingleImageIsServedAgainAndAgain) {
  const std::string path = kImages + "/coins.png";
  const cv::Mat expected = load_image(path, ImageLimits{});
  FrameSourceParams params;
  params.file_fps = 10.0;
  const auto source = open_spec("file:" + path, params);
  EXPECT_EQ(source->name(), "file '" + path + "' (1 image)");

  const double times[] = {0.0, 0.1, 0.2};
  for (std::uint64_t i = 0; i < 3; ++i) {
    Frame f;
    ASSERT_TRUE(source->next(f, 0.0)) << "a file source never times out";
    EXPECT_EQ(f.index, i);
    EXPECT_DOUBLE_EQ(f.t_s, times[i]);
    ASSERT_EQ(f.bgr.type(), CV_8UC3);
    ASSERT_EQ(f.bgr.size(), expected.size());
    EXPECT_EQ(cv::norm(f.bgr, expected, cv::NORM_INF), 0.0) << "frame " << i;
    f.bgr.setTo(cv::Scalar(1, 2, 3));  // a caller drawing on its frame does not change the next one
  }
}

TEST(FrameSourceFile, FolderServesFramesInNameOrderThenRepeatsTheLast) {
  TempDir dir;
  // Written out of order; a text file and a sub-folder are not frames.
  dir.write("frame_c.png", png_frame(30));
  dir.write("frame_a.png", png_frame(10));
  dir.write("notes.txt", text_bytes("not a frame\n"));
  dir.write("frame_b.png", png_frame(20));
  fs::create_directory(dir.path() + "/sub");

  FrameSourceParams params;
  params.file_fps = 4.0;
  const auto source = open_spec("file:" + dir.path(), params);
  EXPECT_EQ(source->name(), "file '" + dir.path() + "' (3 frames)");

  const std::uint8_t marks[] = {10, 20, 30, 30, 30};
  for (std::uint64_t i = 0; i < 5; ++i) {
    Frame f;
    ASSERT_TRUE(source->next(f, 0.0));
    EXPECT_EQ(f.index, i);
    EXPECT_DOUBLE_EQ(f.t_s, static_cast<double>(i) / 4.0);
    ASSERT_EQ(f.bgr.type(), CV_8UC3);
    ASSERT_EQ(f.bgr.size(), cv::Size(64, 48));
    EXPECT_EQ(f.bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(marks[i], marks[i], marks[i])) << "frame " << i;
  }
  // The frames are exactly what load_image gives for each file.
  const auto again = open_spec("file:" + dir.path(), params);
  for (const char* name : {"frame_a.png", "frame_b.png", "frame_c.png"}) {
    Frame f;
    ASSERT_TRUE(again->next(f, 0.0));
    EXPECT_EQ(cv::norm(f.bgr, load_image(dir.path() + "/" + name, ImageLimits{}), cv::NORM_INF), 0.0) << name;
  }
}

TEST(FrameSourceFile, FolderWithoutAnImageIsRefused) {
  TempDir dir;
  dir.write("notes.txt", text_bytes("hello\n"));
  dir.write("fake.png", text_bytes("a text file named .png\n"));
  camera_refusal([&] { open_spec("file:" + dir.path()); },
                 {"'file:" + dir.path() + "'", "no image in the folder", "2 files"});

  TempDir empty;
  camera_refusal([&] { open_spec("file:" + empty.path()); }, {"'file:" + empty.path() + "'", "no image"});
}

TEST(FrameSourceFile, TruncatedPngIsRefusedNamingIt) {
  TempDir dir;
  std::vector<std::uint8_t> cut = png_frame(20);
  ASSERT_GT(cut.size(), 200u);
  cut.resize(cut.size() / 2);  // header intact, data cut: listed as a frame, refused when decoded
  dir.write("a.png", png_frame(10));
  const std::string truncated = dir.write("b.png", cut);

  const auto source = open_spec("file:" + dir.path());
  Frame first;
  ASSERT_TRUE(source->next(first, 0.0));
  EXPECT_EQ(first.bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(10, 10, 10));
  Frame second;
  second.index = 99;
  camera_refusal([&] { source->next(second, 0.0); }, {"'file:" + dir.path() + "'", "'" + truncated + "'"});
  EXPECT_EQ(second.index, 99u) << "a refused frame leaves out untouched";

  // Given alone, it is refused at open.
  camera_refusal([&] { open_spec("file:" + truncated); }, {"'file:" + truncated + "'", "'" + truncated + "'"});
}

TEST(FrameSourceFile, MissingPathAndOtherNonImagesAreRefused) {
  TempDir dir;
  const std::string missing = dir.path() + "/no_such_frames";
  camera_refusal([&] { open_spec("file:" + missing); }, {"'file:" + missing + "'", "No such file or directory"});
  const std::string text = dir.write("notes.txt", text_bytes("hello\n"));
  camera_refusal([&] { open_spec("file:" + text); }, {"'file:" + text + "'", "notes.txt"});
  camera_refusal([&] { open_spec("file:/dev/null"); }, {"'file:/dev/null'", "not an image file or a folder"});
  const std::string odd = dir.path() + "/new\nline";
  camera_refusal([&] { open_spec("file:" + odd); }, {"new\\x0Aline"});
}

TEST(FrameSourceFile, FrameLargerThanTheLimitIsRefused) {
  const std::string path = kImages + "/coins.png";
  FrameSourceParams params;
  params.max_frame_bytes = 1000;
  camera_refusal([&] { open_spec("file:" + path, params); }, {"'file:" + path + "'", "coins.png"});
}

TEST(FrameSourceFile, ParametersOutOfRangeAreInvalidArguments) {
  const std::string spec = "file:" + kImages + "/coins.png";
  const auto with = [&](auto change) {
    FrameSourceParams p;
    change(p);
    return p;
  };
  EXPECT_THROW(open_spec(spec, with([](FrameSourceParams& p) { p.width_px = 63; })), hk::ArgumentError);
  EXPECT_THROW(open_spec(spec, with([](FrameSourceParams& p) { p.height_px = 8193; })), hk::ArgumentError);
  EXPECT_THROW(open_spec(spec, with([](FrameSourceParams& p) { p.file_fps = 0.0; })), hk::ArgumentError);
  EXPECT_THROW(open_spec(spec, with([](FrameSourceParams& p) { p.file_fps = 1001.0; })), hk::ArgumentError);
  EXPECT_THROW(open_spec(spec, with([](FrameSourceParams& p) { p.max_frame_bytes = 0; })), hk::ArgumentError);
  EXPECT_NO_THROW(open_spec(spec, with([](FrameSourceParams& p) { p.file_fps = 1000.0; })));
}

// --- cameras (this machine may have none) -------------------------------------------------------------------

/// Whoever runs the tests asked for libcamera's own log (then it is not silenced).
bool libcamera_log_requested() {
  return std::getenv("LIBCAMERA_LOG_LEVELS") != nullptr || std::getenv("LIBCAMERA_LOG_FILE") != nullptr;
}

bool listed(const std::vector<CameraInfo>& cameras, const std::string& spec) {
  for (const CameraInfo& c : cameras) {
    if (c.spec == spec) return true;
  }
  return false;
}

TEST(FrameSourceCamera, ListingNeverThrowsAndIsQuietWithoutCameras) {
  ::testing::internal::CaptureStderr();
  std::vector<CameraInfo> cameras;
  EXPECT_NO_THROW(cameras = list_cameras());
  const std::vector<CameraInfo> again = list_cameras();  // the one CameraManager is reused, not made twice
  const std::string printed = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(again.size(), cameras.size());
  if (cameras.empty() && !libcamera_log_requested()) {
    EXPECT_EQ(printed, "") << "no camera must be a quiet path";
  }

  for (const CameraInfo& c : cameras) {
    SCOPED_TRACE(c.spec);
    ASSERT_TRUE(c.backend == "libcamera" || c.backend == "v4l2") << c.backend;
    const SourceSpec spec = parse_source_spec(c.spec);
    EXPECT_EQ(spec.kind, c.backend == "libcamera" ? SourceSpec::Kind::Libcamera : SourceSpec::Kind::V4l2);
    EXPECT_EQ(spec.str(), c.spec);
    EXPECT_EQ(c.name.find('\n'), std::string::npos);
    try {
      const auto source = open_frame_source(spec, FrameSourceParams{});
      EXPECT_FALSE(source->name().empty());
    } catch (const CameraError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
}

TEST(FrameSourceCamera, MissingLibcameraCameraIsRefusedInOneLine) {
  const std::vector<CameraInfo> cameras = list_cameras();
  camera_refusal([] { open_spec("libcamera:63"); }, {"camera 'libcamera:63': no such camera"});
  if (listed(cameras, "libcamera:0")) GTEST_SKIP() << "this machine has a libcamera camera 0";
  ::testing::internal::CaptureStderr();
  camera_refusal([] { open_spec("libcamera:0"); }, {"camera 'libcamera:0': no such camera (libcamera found"});
  const std::string printed = ::testing::internal::GetCapturedStderr();
  if (!libcamera_log_requested()) {
    EXPECT_EQ(printed, "");
  }
}

TEST(FrameSourceCamera, MissingV4l2DeviceIsRefusedInOneLine) {
  camera_refusal([] { open_spec("v4l2:/dev/hk_no_such_video"); },
                 {"camera 'v4l2:/dev/hk_no_such_video': cannot open: No such file or directory"});
  if (fs::exists("/dev/video0")) GTEST_SKIP() << "this machine has /dev/video0";
  camera_refusal([] { open_spec("v4l2:/dev/video0"); },
                 {"camera 'v4l2:/dev/video0': cannot open: No such file or directory"});
  camera_refusal([] { open_spec("v4l2:0"); }, {"camera 'v4l2:/dev/video0': cannot open"});
}

TEST(FrameSourceCamera, V4l2NodeThatIsNotACameraIsRefused) {
  camera_refusal([] { open_spec("v4l2:/dev/null"); }, {"camera 'v4l2:/dev/null': not a V4L2 device"});
  TempDir dir;
  const std::string file = dir.write("video0", text_bytes("not a device\n"));
  camera_refusal([&] { open_spec("v4l2:" + file); }, {"camera 'v4l2:" + file + "': not a video device"});
  camera_refusal([&] { open_spec("v4l2:" + dir.path()); }, {"camera 'v4l2:" + dir.path() + "': cannot open"});
}

}  // namespace
}  // namespace hk::vision
