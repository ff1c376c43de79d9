// Guesses at faces with OpenCV's cascades, checked against the mirror image (faces.hpp).
#include "meaning/faces.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

namespace hk::meaning {
namespace {

constexpr std::size_t kMaxFaces = 8;

/// The two cascades, loaded once per thread (a CascadeClassifier is not to be shared between threads).
struct Cascades {
  cv::CascadeClassifier frontal, profile;
  bool ok = false;
};

Cascades& cascades(const std::string& dir) {
  thread_local Cascades c;
  thread_local std::string loaded_from;
  thread_local bool tried = false;
  if (tried && loaded_from == dir) return c;
  tried = true;
  loaded_from = dir;
  c.ok =
      c.frontal.load(dir + "/haarcascade_frontalface_alt2.xml") && c.profile.load(dir + "/haarcascade_profileface.xml");
  static std::atomic<bool> warned{false};
  if (!c.ok && !warned.exchange(true))
    spdlog::warn("faces: the cascades in '{}' cannot be loaded (Debian package opencv-data); no faces are guessed",
                 dir);
  return c;
}

double iou(const cv::Rect& a, const cv::Rect& b) {
  const double inter = (a & b).area();
  return inter <= 0 ? 0.0 : inter / (a.area() + b.area() - inter);
}

/// Whether `cascade` finds, in the mirror image of `grey`'s neighbourhood of `box` (the box grown by half its width on
/// every side), a face of about its size (0.7 to 1.4 times) agreeing with it (kMirrorAgreement once mirrored back).
bool found_in_mirror(cv::CascadeClassifier& cascade, const cv::Mat& grey, const cv::Rect& box) {
  const int grow = box.width / 2;
  const cv::Rect around = cv::Rect(box.x - grow, box.y - grow, box.width + 2 * grow, box.height + 2 * grow) &
                          cv::Rect(0, 0, grey.cols, grey.rows);
  cv::Mat mirrored;
  cv::flip(grey(around), mirrored, 1);
  std::vector<cv::Rect> found;
  const int lo = std::max(kMinFacePx * 3 / 4, box.width * 7 / 10), hi = box.width * 14 / 10;
  // Two neighbours, not three: the neighbourhood's smaller pyramid samples fewer windows over the face.
  cascade.detectMultiScale(mirrored, found, 1.05, 2, 0, cv::Size(lo, lo), cv::Size(hi, hi));
  for (cv::Rect f : found) {
    f.x = around.x + around.width - f.x - f.width;  // back to the picture's side
    f.y += around.y;
    if (iou(f, box) >= kMirrorAgreement) return true;
  }
  return false;
}

/// Boxes `cascade` finds in `grey` that it finds again in the mirror image.
std::vector<cv::Rect> found_both_ways(cv::CascadeClassifier& cascade, const cv::Mat& grey) {
  std::vector<cv::Rect> direct;
  cascade.detectMultiScale(grey, direct, 1.05, 3, 0, cv::Size(kMinFacePx, kMinFacePx));
  std::vector<cv::Rect> agreed;
  for (const cv::Rect& d : direct)
    if (found_in_mirror(cascade, grey, d)) agreed.push_back(d);
  return agreed;
}

}  // namespace

std::vector<cv::Rect> find_faces(const cv::Mat& picture, const std::string& cascade_dir) {
  if (picture.empty()) return {};
  Cascades& c = cascades(cascade_dir);
  if (!c.ok) return {};
  cv::Mat grey;
  if (picture.channels() == 1)
    grey = picture;
  else
    cv::cvtColor(picture, grey, picture.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  const double scale = static_cast<double>(kFaceSearchSidePx) / std::max(grey.cols, grey.rows);
  cv::Mat small;
  cv::resize(grey, small, {}, scale, scale, scale < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR);
  cv::equalizeHist(small, small);
  std::vector<cv::Rect> faces = found_both_ways(c.frontal, small);
  for (const cv::Rect& p : found_both_ways(c.profile, small))
    if (std::none_of(faces.begin(), faces.end(), [&](const cv::Rect& f) { return iou(f, p) >= kMirrorAgreement; }))
      faces.push_back(p);
  std::sort(faces.begin(), faces.end(), [](const cv::Rect& a, const cv::Rect& b) { return a.area() > b.area(); });
  if (faces.size() > kMaxFaces) faces.resize(kMaxFaces);
  const cv::Rect whole(0, 0, picture.cols, picture.rows);
  for (cv::Rect& f : faces)
    f = cv::Rect(cv::Point(static_cast<int>(f.x / scale), static_cast<int>(f.y / scale)),
                 cv::Point(static_cast<int>((f.x + f.width) / scale), static_cast<int>((f.y + f.height) / scale))) &
        whole;
  return faces;
}

}  // namespace hk::meaning
