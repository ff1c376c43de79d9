// The file frame source ("file:PATH", vision/frame_source.hpp): one image served again and again, or a folder
// of frames served in name order, then its last frame again. Frames are decoded one at a time through
// load_image (the same checks as every other outside image); only the current frame is kept in memory.

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "frame_sources.hpp"
#include "input_error.hpp"
#include "vision/frame_source.hpp"
#include "vision/intake.hpp"

namespace hk::vision::detail {
namespace {

namespace fs = std::filesystem;

class FileFrameSource final : public FrameSource {
 public:
  FileFrameSource(SourceSpec spec, const FrameSourceParams& params, std::vector<std::string> files, bool folder)
      : spec_(std::move(spec)), fps_(params.file_fps), files_(std::move(files)), folder_(folder) {
    limits_.max_file_bytes = params.max_frame_bytes;
  }

  /// A single image is decoded at open, so that a bad file is refused by open_frame_source.
  void preload(cv::Mat bgr) {
    current_ = std::move(bgr);
    current_file_ = 0;
  }

  std::string name() const override {
    const std::string path = "file '" + hk::one_line(spec_.path) + "'";
    if (!folder_) return path + " (1 image)";
    return path + " (" + std::to_string(files_.size()) + (files_.size() == 1 ? " frame)" : " frames)");
  }

  bool next(Frame& out, double /*timeout_s: a file never keeps anyone waiting*/) override {
    const std::size_t file = static_cast<std::size_t>(std::min<std::uint64_t>(next_index_, files_.size() - 1));
    if (file != current_file_) {
      cv::Mat bgr;
      try {
        bgr = load_image(files_[file], limits_);
      } catch (const InputError& e) {
        throw_camera_error(spec_, e.what());
      }
      current_ = std::move(bgr);
      current_file_ = file;
    }
    out.bgr = current_.clone();  // the caller may draw on its frame; the repeated one stays clean
    out.t_s = static_cast<double>(next_index_) / fps_;
    out.index = next_index_;
    ++next_index_;
    return true;
  }

 private:
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);

  SourceSpec spec_;
  double fps_;
  ImageLimits limits_;
  std::vector<std::string> files_;  ///< the frames, in the order served; never empty
  bool folder_;
  cv::Mat current_;  ///< the decoded frame of files_[current_file_]
  std::size_t current_file_ = kNone;
  std::uint64_t next_index_ = 0;
};

/// The folder's regular files (symbolic links followed) whose header is an image, sorted by file name.
std::vector<std::string> list_frames(const SourceSpec& spec) {
  std::error_code ec;
  std::vector<fs::path> names;
  fs::directory_iterator it(spec.path, ec);
  if (ec) throw_camera_error(spec, "cannot list the folder: " + ec.message());
  for (; it != fs::directory_iterator(); it.increment(ec)) {
    std::error_code type_ec;
    if (it->is_regular_file(type_ec)) names.push_back(it->path().filename());
  }
  if (ec) throw_camera_error(spec, "cannot list the folder: " + ec.message());
  std::sort(names.begin(), names.end(), [](const fs::path& a, const fs::path& b) { return a.native() < b.native(); });

  std::vector<std::string> frames;
  for (const fs::path& n : names) {
    const std::string path = (fs::path(spec.path) / n).string();
    try {
      (void)read_image_header(path);
    } catch (const InputError&) {
      continue;  // not an image (a text file, a thumbnail database): skipped
    }
    frames.push_back(path);
  }
  if (frames.empty()) {
    throw_camera_error(spec, "no image in the folder (" + std::to_string(names.size()) +
                                 (names.size() == 1 ? " file, " : " files, ") + "none with an image header)");
  }
  return frames;
}

}  // namespace

std::unique_ptr<FrameSource> open_file_source(const SourceSpec& spec, const FrameSourceParams& params) {
  struct stat st {};
  if (::stat(spec.path.c_str(), &st) != 0) throw_camera_error(spec, "cannot open: " + errno_text(errno));
  if (S_ISDIR(st.st_mode)) {
    return std::make_unique<FileFrameSource>(spec, params, list_frames(spec), true);
  }
  if (!S_ISREG(st.st_mode)) throw_camera_error(spec, "not an image file or a folder");
  auto source = std::make_unique<FileFrameSource>(spec, params, std::vector<std::string>{spec.path}, false);
  ImageLimits limits;
  limits.max_file_bytes = params.max_frame_bytes;
  try {
    source->preload(load_image(spec.path, limits));
  } catch (const InputError& e) {
    throw_camera_error(spec, e.what());
  }
  return source;
}

}  // namespace hk::vision::detail
