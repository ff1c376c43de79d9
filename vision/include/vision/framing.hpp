#pragma once
/// @file framing.hpp
/// Spoken framing for someone who cannot see the preview. Each camera frame is looked at
/// once (look_at_frame: the page found in it, how bright it is, how much it moved since the frame before);
/// FramingGuide turns the looks into advice, one piece at a time, and decides when to capture: once the page
/// has been whole, roughly centred, lit and still for `still_s`.
///
/// The advice, most urgent first (only the first that applies is given):
///   too dark → no page ("place the picture under the camera") → cut off (top, bottom, left, right: a corner of
///   the page on that edge of the frame or beyond it, PageDetection::touches_frame; a page lying whole in the
///   frame is not cut off, however near the edge) → off centre ("move it left / right / up / down") → moving
///   ("hold still") → still for still_s: capture.
/// Directions are the visitor's, with the camera looking down from the visitor's side of the table: the
/// frame's left is the visitor's left and the frame's top is away from the visitor ("up"). A page whose
/// centre lies right of the frame's centre must move left, and so on. Advice is said when it changes, and
/// the same advice again only after `repeat_s` (someone moving a page slowly is not talked at every frame).
/// When no page outline can be found but the frame is lit, still and not empty (a picture filling the whole
/// frame), it is captured whole after `whole_frame_after_s`.

#include <cstdint>
#include <optional>

#include <opencv2/core.hpp>

#include "vision/page.hpp"

namespace hk::vision {

/// What a frame showed (look_at_frame).
struct FrameLook {
  PageDetection page;      ///< the page found (page.found false: none)
  double mean_grey = 0.0;  ///< mean grey level of the frame [0, 255]
  double detail =
      0.0;  ///< standard deviation of the grey levels of the small frame [grey levels]: ~0 for an empty, even table
  /// Mean absolute grey-level change from the frame before, on small blurred copies [grey levels]; negative
  /// for the first frame (nothing to compare with).
  double motion = -1.0;
  /// Largest move of a page corner since the frame before, as a share of the frame's diagonal; negative when
  /// either frame had no page.
  double corner_motion = -1.0;
  double t_s = 0.0;   ///< the frame's time [s] (Frame::t_s)
  int width_px = 0;   ///< the frame's width [px]
  int height_px = 0;  ///< the frame's height [px]
};

/// Looks at one frame (CV_8UC3 BGR or CV_8UC1): find_page at `page`'s settings, brightness, detail, and motion
/// against `previous`. `previous` is the look at the frame before (nullptr for the first) and `small` carries a
/// small blurred grey copy from one call to the next (empty at the first call; replaced by this frame's).
/// @throws hk::ArgumentError as find_page.
FrameLook look_at_frame(const cv::Mat& frame, double t_s, const FrameLook* previous, cv::Mat& small,
                        const PageParams& page = {});

/// What the guide says (one message of the catalogue each).
enum class FramingAdvice : std::uint8_t {
  PlacePicture,  ///< "Place the picture under the camera."
  TooDark,       ///< "It is too dark."
  CutOffTop,     ///< "It is cut off at the top."
  CutOffBottom,  ///< "It is cut off at the bottom."
  CutOffLeft,    ///< "It is cut off on the left."
  CutOffRight,   ///< "It is cut off on the right."
  MoveLeft,      ///< "Move it left."
  MoveRight,     ///< "Move it right."
  MoveUp,        ///< "Move it up." (away from you)
  MoveDown,      ///< "Move it down." (towards you)
  HoldStill,     ///< "Hold still."
};

/// The advice's short name, as written in capture.json's guidance: "place", "too_dark", "cut_off_top",
/// "cut_off_bottom", "cut_off_left", "cut_off_right", "move_left", "move_right", "move_up", "move_down",
/// "hold_still".
const char* advice_name(FramingAdvice a);

/// Thresholds of the guide. Defaults measured on synthetic camera sequences (tests/vision/test_framing.cpp).
struct FramingParams {
  double still_s = 1.0;   ///< whole, centred and still this long → capture [s], (0, 60]
  double repeat_s = 3.0;  ///< the same advice is said again after this long at the earliest [s], >= 0
  double centre_tolerance =
      0.15;  ///< the page's centre may lie this share of the frame's width (height) off the frame's centre, (0, 0.5]
  double min_mean_grey = 45.0;       ///< a darker frame is "too dark" [grey levels], [0, 255]
  double max_motion = 4.0;           ///< FrameLook::motion above this is moving [grey levels], > 0
  double max_corner_motion = 0.006;  ///< FrameLook::corner_motion above this is moving [share of the diagonal], > 0
  double whole_frame_after_s =
      3.0;  ///< no page but lit, still and with detail this long → capture the whole frame [s], > 0
  double min_detail =
      30.0;  ///< FrameLook::detail below this is an empty table or a plain texture, not a picture [grey levels], >= 0
};

/// One step of the guide.
struct FramingStep {
  std::optional<FramingAdvice> say;  ///< advice to speak now; empty: nothing new to say
  bool capture = false;              ///< capture this frame now (its look's page, or the whole frame when no page)
};

/// The guide: a state machine over frame looks. Deterministic: the same looks give the same steps.
class FramingGuide {
 public:
  /// @throws hk::ArgumentError for a parameter outside its range.
  explicit FramingGuide(const FramingParams& p = {});
  /// The advice for one look (looks in time order). After a capture the guide starts again as new.
  FramingStep update(const FrameLook& look);
  /// Forget everything (a new capture).
  void reset();
  /// The advice a look calls for, before timing (nothing when the page is ready: whole, centred, lit, still).
  std::optional<FramingAdvice> advice_for(const FrameLook& look) const;

 private:
  FramingParams p_;
  std::optional<FramingAdvice> last_said_;
  double last_said_t_s_ = 0.0;
  bool ready_ = false;  // the looks since ready_since_s_ all called for nothing
  double ready_since_s_ = 0.0;
  bool whole_ = false;  // no page, but lit, still and with detail since whole_since_s_
  double whole_since_s_ = 0.0;
};

}  // namespace hk::vision
