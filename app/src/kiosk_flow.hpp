#pragma once
/// @file kiosk_flow.hpp
/// What a visitor walks through (issue 5, item 5), as a state machine apart from windows and devices so
/// it can be driven by scripted input in tests:
///   Attract   — waiting; the first key press or handle motion speaks the welcome and starts the tutorial;
///   Tutorial  — a square, a circle, a triangle (Next moves on); after the triangle, the first picture;
///   Picture   — Next / Previous picture, Describe, Finer / Coarser level, Volume, Help, Tutorial again.
/// Every key press is answered in speech at once (the speech cuts off what was being said). With no key
/// and no handle motion for `timeout_s`, the kiosk warns `warning_s` ahead, then says goodbye, restores the
/// operator's defaults and returns to Attract. Any key or motion extends the time.

#include <string>

#include "audio/messages.hpp"

namespace hk::app {

/// Keys a blind visitor can find (mapped to physical keys in the config by the window layer).
enum class KioskKey { Help, Next, Previous, Describe, Finer, Coarser, VolumeUp, VolumeDown, Tutorial, Other };

/// States of the flow.
enum class KioskState { Attract, Tutorial, Picture };

/// Tutorial shapes, in order.
enum class TutorialShape { Square = 0, Circle = 1, Triangle = 2 };

/// What the flow asks of the rest of the kiosk. The window layer implements it with the AudioSystem, the
/// servo core and the picture library; tests record the calls.
class KioskEffects {
 public:
  virtual ~KioskEffects() = default;
  /// Speak `text` now, cutting off what is being said.
  virtual void say(const std::string& text) = 0;
  /// Put a tutorial shape on the device.
  virtual void show_tutorial(TutorialShape shape) = 0;
  /// Put picture `index` (0-based) on the device. Returns its number of shapes.
  virtual int show_picture(int index) = 0;
  /// Pictures in the library (≥ 1).
  virtual int picture_count() const = 0;
  /// A spoken description of what is shown (describe.hpp).
  virtual std::string describe() = 0;
  /// Level one finer (delta −1) or coarser (+1). Returns false at the limit (nothing changes).
  virtual bool change_level(int delta) = 0;
  /// Volume one step up (+1) or down (−1). Returns false at the limit.
  virtual bool change_volume(int delta) = 0;
  /// A new visitor: the operator's default settings (volume, level), speech stopped.
  virtual void new_session() = 0;
};

/// Timing of the flow. Units in names.
struct KioskFlowParams {
  double timeout_s = 120.0;  ///< no key and no motion for this long ends the session
  double warning_s = 20.0;   ///< the spoken warning comes this long before the end (at most timeout_s / 2)
};

/// The state machine. Not thread-safe: call from the window thread.
class KioskFlow {
 public:
  KioskFlow(KioskEffects& effects, const audio::MessageCatalog& messages, const KioskFlowParams& params = {});

  /// A key press at time `now_s` [s] (any monotonic clock).
  void key(KioskKey k, double now_s);
  /// The handle moved noticeably (the caller decides, e.g. > 5 mm since the last call) at `now_s`.
  void handle_moved(double now_s);
  /// Time passes (call every frame): warnings and the time-out.
  void tick(double now_s);

  KioskState state() const { return state_; }
  TutorialShape tutorial_shape() const { return shape_; }
  int picture() const { return picture_; }
  bool warned() const { return warned_; }

 private:
  void wake(double now_s);
  void start_tutorial();
  void show(int index, const std::string& before = {});
  void say(audio::MessageId id, std::initializer_list<audio::MessageArg> args = {});

  KioskEffects& fx_;
  const audio::MessageCatalog& msg_;
  KioskFlowParams p_;
  KioskState state_ = KioskState::Attract;
  TutorialShape shape_ = TutorialShape::Square;
  int picture_ = 0;
  double last_activity_s_ = 0;
  bool warned_ = false;
};

}  // namespace hk::app
