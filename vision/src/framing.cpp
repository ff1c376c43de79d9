// Spoken framing: frame looks and the guide's state machine (see framing.hpp).

#include "vision/framing.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"

namespace hk::vision {
namespace {

constexpr int kSmallWidthPx = 160;    // motion and detail are measured on a copy this wide
constexpr double kTimeSlackS = 1e-6;  // frame times are sums of floating-point steps: 10 x 0.1 s counts as 1 s

cv::Mat grey_of(const cv::Mat& frame) {
  if (frame.type() == CV_8UC1) return frame;
  cv::Mat grey;
  cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

cv::Mat small_blurred(const cv::Mat& grey) {
  const double f = static_cast<double>(kSmallWidthPx) / grey.cols;
  const cv::Size size(kSmallWidthPx, std::max(1, static_cast<int>(std::lround(grey.rows * f))));
  cv::Mat small;
  cv::resize(grey, small, size, 0, 0, cv::INTER_AREA);
  cv::GaussianBlur(small, small, cv::Size(3, 3), 0.0);
  return small;
}

double largest_corner_move(const PageDetection& a, const PageDetection& b, double diagonal_px) {
  double worst = 0.0;
  for (std::size_t k = 0; k < 4; ++k) worst = std::max(worst, cv::norm(a.corners_px[k] - b.corners_px[k]));
  return worst / diagonal_px;
}

void check(bool ok, const char* what) {
  if (!ok) throw hk::ArgumentError(std::string("framing: ") + what);
}

}  // namespace

FrameLook look_at_frame(const cv::Mat& frame, double t_s, const FrameLook* previous, cv::Mat& small,
                        const PageParams& page) {
  if (frame.empty() || (frame.type() != CV_8UC3 && frame.type() != CV_8UC1)) {
    throw hk::ArgumentError("look_at_frame: the frame must be a non-empty CV_8UC3 or CV_8UC1 image");
  }
  FrameLook look;
  look.t_s = t_s;
  look.width_px = frame.cols;
  look.height_px = frame.rows;
  look.page = find_page(frame, page);
  const cv::Mat grey = grey_of(frame);
  look.mean_grey = cv::mean(grey)[0];
  cv::Mat now = small_blurred(grey);
  cv::Scalar mean, stddev;
  cv::meanStdDev(now, mean, stddev);
  look.detail = stddev[0];
  if (previous != nullptr && !small.empty() && small.size() == now.size()) {
    cv::Mat diff;
    cv::absdiff(now, small, diff);
    look.motion = cv::mean(diff)[0];
    if (previous->page.found && look.page.found) {
      look.corner_motion = largest_corner_move(previous->page, look.page, std::hypot(frame.cols, frame.rows));
    }
  }
  small = std::move(now);
  return look;
}

const char* advice_name(FramingAdvice a) {
  switch (a) {
    case FramingAdvice::PlacePicture:
      return "place";
    case FramingAdvice::TooDark:
      return "too_dark";
    case FramingAdvice::CutOffTop:
      return "cut_off_top";
    case FramingAdvice::CutOffBottom:
      return "cut_off_bottom";
    case FramingAdvice::CutOffLeft:
      return "cut_off_left";
    case FramingAdvice::CutOffRight:
      return "cut_off_right";
    case FramingAdvice::MoveLeft:
      return "move_left";
    case FramingAdvice::MoveRight:
      return "move_right";
    case FramingAdvice::MoveUp:
      return "move_up";
    case FramingAdvice::MoveDown:
      return "move_down";
    case FramingAdvice::HoldStill:
      return "hold_still";
  }
  return "?";
}

FramingGuide::FramingGuide(const FramingParams& p) : p_(p) {
  check(std::isfinite(p.still_s) && p.still_s > 0.0 && p.still_s <= 60.0, "still_s must be in (0, 60] s");
  check(std::isfinite(p.repeat_s) && p.repeat_s >= 0.0, "repeat_s must be >= 0 s");
  check(std::isfinite(p.centre_tolerance) && p.centre_tolerance > 0.0 && p.centre_tolerance <= 0.5,
        "centre_tolerance must be in (0, 0.5]");
  check(std::isfinite(p.min_mean_grey) && p.min_mean_grey >= 0.0 && p.min_mean_grey <= 255.0,
        "min_mean_grey must be in [0, 255]");
  check(std::isfinite(p.max_motion) && p.max_motion > 0.0, "max_motion must be > 0");
  check(std::isfinite(p.max_corner_motion) && p.max_corner_motion > 0.0, "max_corner_motion must be > 0");
  check(std::isfinite(p.whole_frame_after_s) && p.whole_frame_after_s > 0.0, "whole_frame_after_s must be > 0 s");
  check(std::isfinite(p.min_detail) && p.min_detail >= 0.0, "min_detail must be >= 0");
}

void FramingGuide::reset() {
  last_said_.reset();
  last_said_t_s_ = 0.0;
  ready_ = false;
  whole_ = false;
}

std::optional<FramingAdvice> FramingGuide::advice_for(const FrameLook& look) const {
  if (look.mean_grey < p_.min_mean_grey) return FramingAdvice::TooDark;
  const PageDetection& page = look.page;
  if (!page.found) return FramingAdvice::PlacePicture;
  // Cut off: a corner of the page on the frame's edge or beyond it (top, bottom, left, right of the frame); a page
  // lying whole in the frame, however near its edge, is not.
  if (page.touches_frame[0]) return FramingAdvice::CutOffTop;
  if (page.touches_frame[2]) return FramingAdvice::CutOffBottom;
  if (page.touches_frame[3]) return FramingAdvice::CutOffLeft;
  if (page.touches_frame[1]) return FramingAdvice::CutOffRight;
  // Off centre: the mean of the corners against the frame's centre, as shares of the frame's width and height.
  cv::Point2d centre(0, 0);
  for (const cv::Point2d& c : page.corners_px) centre += c * 0.25;
  const double dx = centre.x / look.width_px - 0.5, dy = centre.y / look.height_px - 0.5;
  if (std::abs(dx) > p_.centre_tolerance || std::abs(dy) > p_.centre_tolerance) {
    if (std::abs(dx) >= std::abs(dy)) {  // the larger offset first
      return dx > 0 ? FramingAdvice::MoveLeft : FramingAdvice::MoveRight;
    }
    return dy > 0 ? FramingAdvice::MoveUp : FramingAdvice::MoveDown;
  }
  if (look.motion > p_.max_motion || look.corner_motion > p_.max_corner_motion) return FramingAdvice::HoldStill;
  return std::nullopt;
}

FramingStep FramingGuide::update(const FrameLook& look) {
  FramingStep step;
  std::optional<FramingAdvice> advice = advice_for(look);
  // Still: compared with the frame before (the first frame is not known to be still), and the page's corners
  // too when both frames had one.
  const bool compared = look.motion >= 0.0 && (!look.page.found || look.corner_motion >= 0.0);
  const bool still = compared && look.motion <= p_.max_motion && look.corner_motion <= p_.max_corner_motion;

  // A page ready (nothing to advise) and still: capture once it has been so for still_s.
  if (!advice && still) {
    if (!ready_) ready_since_s_ = look.t_s;
    ready_ = true;
  } else {
    ready_ = false;
  }
  // No page, but a lit, still frame with detail: a picture filling the frame, captured whole.
  const bool whole = advice == FramingAdvice::PlacePicture && still && look.detail >= p_.min_detail;
  if (whole) {
    if (!whole_) whole_since_s_ = look.t_s;
    whole_ = true;
    if (last_said_ == FramingAdvice::PlacePicture) advice.reset();  // said once: not repeated while it waits
  } else {
    whole_ = false;
  }
  if ((ready_ && look.t_s - ready_since_s_ >= p_.still_s - kTimeSlackS) ||
      (whole_ && look.t_s - whole_since_s_ >= p_.whole_frame_after_s - kTimeSlackS)) {
    step.capture = true;
    reset();
    return step;
  }
  if (advice && (advice != last_said_ || look.t_s - last_said_t_s_ >= p_.repeat_s - kTimeSlackS)) {
    step.say = advice;
    last_said_ = advice;
    last_said_t_s_ = look.t_s;
  }
  return step;
}

}  // namespace hk::vision
