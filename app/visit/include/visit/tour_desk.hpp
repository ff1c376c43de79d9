#pragma once
/// @file tour_desk.hpp
/// The guided tour's window-thread half (runtime/guided_tour.hpp plans it, the servo step follows it): the
/// Guide key's question ("I will guide your hand to a shape. Hold the handle lightly."), the tour planned
/// from where the handle is once that has been heard and handed to the servo thread, the cursor while it
/// runs (a cursor that moves more than 3 mm takes over; the model hand goes limp, so the tour leads the
/// handle), and what is said when it ends: the shape it traced and what remains. It also keeps which shapes
/// the handle touched in this visit of the picture shown (VisitTouches), from which the next tour is chosen.
///
/// Window thread only: it reads the servo's display state and hands tours over through ServoStep's
/// publish_tour and cancel_tour, nothing else.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "audio/system.hpp"
#include "config/settings.hpp"
#include "haptics/scene.hpp"
#include "runtime/device_host.hpp"
#include "runtime/guided_tour.hpp"
#include "runtime/servo_step.hpp"
#include "visit/kiosk_effects.hpp"
#include "visit/voice.hpp"

namespace hk::app {

/// The picture shown, as the tour sees it.
struct TourPicture {
  const Scene* scene = nullptr;  ///< null: nothing shown
  int id = 0;                    ///< its SceneBundle id
  std::size_t described = 0;     ///< shapes `words` can name (the level-0 curves shown)
  /// What shape `curve` is, in words ("a small closed shape, on the left"), for the line said at a tour's end.
  std::function<std::string(std::size_t curve)> words;
  /// The name curve `curve` takes, as said ("the left wing"), "" for none; null: the picture has no names.
  std::function<std::string(std::size_t curve)> name;
  /// A named part the Guide key leads to: its name as said and the curve a tour traces for it.
  struct Part {
    std::string name;
    std::size_t curve = 0;
  };
  /// The parts staff named, in the order Guide offers them (the largest first), each name once; empty: Guide
  /// leads to the nearest shape not yet touched.
  std::vector<Part> parts;
};

/// The guided tour between the Guide key and the line said at its end; it answers the visitor's flow's
/// TourEffects (kiosk_effects.hpp). Not thread-safe: the window thread.
class TourDesk final : public TourEffects {
 public:
  /// Extra time after the tour's question before its force may start [s] (the sound device's latency).
  static constexpr double kAskMargin_s = 0.3;

  /// Everything given outlives the desk. `settings`: the settings in use (tour_params_from; the servo rate
  /// that times the question); `half_m`: half the workspace's extent [m]; `cursor_m`: where the model hand
  /// starts [m].
  TourDesk(ServoStep& step, DeviceHost& devices, Voice& voice, const audio::AudioSystem& audio,
           const config::Settings& settings, Vec2 half_m, Vec2 cursor_m);
  /// Where the desk learns what is shown (Stage::tour_picture), asked at each Guide key and poll. Until it is
  /// set, nothing is shown.
  void set_picture(std::function<TourPicture()> picture) { picture_ = std::move(picture); }

  /// The model hand's target [m] (the mouse or a script stands in for the visitor's hand). After a tour the
  /// hand keeps the place the tour led the handle to: later cursors are offset by it (until new_visitor).
  /// While a tour runs, a cursor more than 3 mm from where it was at the hand-over stops it.
  void set_cursor(Vec2 m);
  /// Any key: stops a tour under way or announced, quietly (the Guide key that did so then says so).
  void key_pressed() override;
  /// The Guide key on the picture shown. A picture with parts staff named (TourPicture::parts): until each has
  /// been offered in this visit of the picture, names the next ("I will guide your hand to the left wing. …",
  /// tour_ask_part), so each press, one that stops a tour too, offers the next; the tour to it (plan_tour_to)
  /// starts once the question has been heard, and its end says the part as offered ("That was the left wing.").
  /// Then, as on any picture: when it has a shape not yet touched
  /// (plan_tour), asks first; the tour is planned and handed to the servo thread by poll() once the question
  /// has been heard (its length in servo ticks, kAskMargin_s more). Nothing left: the named parts again, in
  /// turn, else says so (tour_all_touched, or tour_nothing without shapes). A press that stopped a tour to an
  /// untouched shape says tour_stopped instead.
  void guide() override;
  /// Window thread, every frame: keeps what the handle touches in this visit's touches, and with [kiosk]
  /// say_names_on_touch "on" says the name of a named shape the handle touches, once in the visit of the
  /// picture (touch_name: "The left wing."; not while a tour runs or anything else is being said: then at a
  /// later touch); hands an announced tour over when it is due; and when the tour handed over has ended, says
  /// what it traced and what remains ("Tour stopped. …" when the hand held it back or the device was lost;
  /// nothing when a key, the mouse, a new picture or visitor stopped it) and gives the handle back to the
  /// cursor where it is.
  void poll();
  /// A new picture (`id`, `curves` shapes) is published: touches start again; a tour under way stops
  /// without a word, an announced one does not start.
  void picture_changed(int id, int curves);
  /// A new visitor, on the picture `id` with `curves` shapes: as picture_changed, and the hand's offset from
  /// earlier tours is forgotten.
  void new_visitor(int id, int curves);

  /// Whether a tour announced or handed to the servo thread has not yet been reported ended.
  bool running() const { return running_ != 0 || asked_; }
  /// A tour is announced and not yet handed to the servo thread.
  bool announced() const { return asked_; }
  /// The shapes touched in this visit of the picture shown.
  const VisitTouches& touches() const { return touches_; }

 private:
  TourPicture picture() const { return picture_ ? picture_() : TourPicture{}; }
  void hand_over(const TourPicture& picture);  // plans the announced tour from the handle and publishes it
  void report_end(const TourPicture& picture, const ServoDisplayState& d);  // what it traced and what remains
  void stop_quietly();                                                      // ends what runs or is announced
  // Announces a tour, due once heard: to named part `part_name` (its curve `part_curve`) or, −1 and "", to the
  // nearest shape not yet touched.
  void ask(const std::string& question, int scene_id, int part_curve, std::string part_name);
  void offer_part(const TourPicture& picture);                   // the next named part, in turn
  void say_touched_name(const TourPicture& picture, int curve);  // the first touch of a named shape

  std::function<TourPicture()> picture_;  // set_picture
  ServoStep& step_;
  DeviceHost& devices_;
  Voice& voice_;
  const audio::AudioSystem& audio_;
  const config::Settings& s_;
  Vec2 half_;
  VisitTouches touches_;
  int seq_ = 0;                    // TourPath::id of the last tour handed over
  int running_ = 0;                // its id until poll sees it ended, else 0
  int scene_ = 0;                  // the picture it was planned for
  bool quiet_ = false;             // ended by a key, the mouse, a new picture or visitor: nothing to say at its end
  bool guide_stops_ = false;       // this key press stopped a running or announced tour
  bool asked_ = false;             // announced, not yet handed to the servo thread
  std::int64_t due_tick_ = 0;      // the servo tick from which the announced tour may start
  int part_curve_ = -1;            // the announced tour's named part (its curve), −1 for the nearest untouched shape
  std::string part_name_;          // that part's name as offered, "" for none
  std::size_t parts_offered_ = 0;  // named parts offered in this visit of the picture (TourPicture::parts)
  std::vector<std::string> names_said_;  // names said at a touch in this visit of the picture
  Vec2 cursor_in_;                       // the last cursor given to set_cursor [m]
  Vec2 cursor_offset_;                   // added to it: where tours left the hand [m]
  Vec2 cursor_ref_;                      // cursor_in_ when the tour was handed over [m]
};

}  // namespace hk::app
