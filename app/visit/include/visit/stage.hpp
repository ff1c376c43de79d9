#pragma once
/// @file stage.hpp
/// What the device and the screen show, and what is said of it: a scene is published to the servo step with
/// the curves the screen draws (Shown), the level the visitor chose, Describe and Where on it, and its text
/// read off the window thread (TextReader) and swapped in with the fade when it comes. Practice shapes are
/// built here; library pictures, stick pages and camera captures are built by their desks (library_desk.hpp,
/// stick_desk.hpp, camera_desk.hpp) and shown here. It answers the visitor's flow's StageEffects
/// (kiosk_effects.hpp).
///
/// Window thread only: it hands scenes to the servo thread through ServoStep::publish and reads its display
/// state, nothing else.

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "audio/system.hpp"
#include "config/settings.hpp"
#include "formats/picture_notes.hpp"
#include "hk/level_choice.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/picture_shelf.hpp"
#include "pictures/text_reader.hpp"
#include "runtime/servo_step.hpp"
#include "visit/answers.hpp"
#include "visit/kiosk_effects.hpp"
#include "visit/tour_desk.hpp"
#include "visit/voice.hpp"

namespace hk::app {

/// What is on the device and on the screen.
struct Shown {
  std::vector<Polyline> polylines;                     ///< level-0 source curves [m] (for Describe)
  std::vector<std::vector<std::vector<Vec2>>> levels;  ///< [curve][level] → points [m]
  /// With level_mode = "cut": [curve][tolerance step] → the cut's segments (tolerance_cut) and its joined
  /// polyline (joined_cut_points) [m], what the walls are at that cut step; empty otherwise.
  std::vector<std::vector<std::vector<SegmentRef>>> cut_segments;
  std::vector<std::vector<std::vector<Vec2>>> cuts;
  std::vector<bool> closed;  ///< [curve]
  cv::Mat picture;           ///< BGR, empty for tutorial shapes
  std::string image_path;    ///< the picture's file (a page: its document), "" for tutorial shapes
  /// The picture's own size at full detail [px] (ImageScene::file_width_px), what staff names' coordinates are
  /// in; 0 for tutorial shapes.
  int file_width_px = 0, file_height_px = 0;
  vision::PxToM px_to_m{1, 0, 0};       ///< picture pixels → workspace metres
  const Scene* scene = nullptr;         ///< the published scene (read-only here; for the overlay)
  std::vector<TextBlockM> text_blocks;  ///< a document page's text (Describe reads the one under the hand)
  std::string text_language;            ///< the language of `text_blocks` as the document says it, "" unknown
  std::vector<Aabb> faces_m;            ///< faces guessed in the picture [m] (ImageScene::faces_m)
  PictureNotes notes;                   ///< a library picture's title and description (its sidecar)
  /// What each of `polylines` looks like (form, colour, size, speck), one per polyline.
  std::vector<meaning::ShapeDescriptor> descriptors;
  std::vector<meaning::NamedRegion> regions;  ///< regions staff named on `picture`
  std::vector<int> shape_region;              ///< per polyline: the region naming it, −1 none
  /// The same as Describe and Where say them, in the language `names_language` (Stage::names() makes them
  /// anew in the language in use, so a visitor who changes language hears staff names in theirs).
  mutable PictureNames names;
  mutable std::string names_language;
};

/// Where what is shown came from (what a rebuild with new settings asks for again).
struct ShownSource {
  int picture = -1;   ///< library index, −1 for none
  int document = -1;  ///< stick document, −1 for none
  int page = 0;       ///< the document's page (from 1), 0 for a picture
};

/// SceneBundle ids of what is shown: practice shapes −1..−3 (−1 − TutorialShape), library pictures their
/// index, stick pages kFirstPageId + document · kPageIdStride + page, camera captures kFirstCaptureId,
/// kFirstCaptureId − 1, ...
inline constexpr int kFirstPageId = 1000;
inline constexpr int kPageIdStride = 100000;
inline constexpr int kFirstCaptureId = -100;

/// The SceneBundle id of page `page` (from 1) of stick document `document`.
inline int page_id(int document, int page) { return kFirstPageId + document * kPageIdStride + page; }

/// What is shown. Not thread-safe: the window thread.
class Stage final : public StageEffects {
 public:
  /// How long a reading may take before "Reading the text." is said [s].
  static constexpr double kTextWait_s = 1.0;

  /// Everything given outlives the stage. `settings`: the settings in use (levels, level mode, servo
  /// parameters of each published scene); `half_m`: half the workspace's extent [m].
  Stage(ServoStep& step, Voice& voice, const audio::AudioSystem& audio, TourDesk& tour, PictureShelf& shelf,
        const config::Settings& settings, Vec2 half_m);

  /// Puts practice shape `shape` on the device (a library picture still being built is not wanted any more).
  void show_tutorial(TutorialShape shape) override;
  /// The shown picture's notes in the language in use (notes_in).
  PictureNotes shown_notes() const override;
  /// What the picture or page holds (describe.hpp), led by "Reading the text." while its text is read.
  std::string describe() override;
  /// "What is here": on a document page, the block of text under the hand (its number and first words);
  /// else the shape the proxy touches or the hand is nearest (describe.hpp shape_at_hand: its number, size,
  /// kind, what lies in it and what it lies in), and where the hand is (place_words).
  std::string where() override;
  /// The blocks of text of the page shown, and the one under the proxy (as Describe reads it).
  PageText page_text() override;
  /// From the level in use (chosen by hand speed in auto mode), one step of the same kind (LevelChoice::stepped:
  /// a level, or along the tolerance or cut steps): the visitor's choice then holds until reset_level.
  bool change_level(int delta) override;
  bool auto_level() const override { return auto_level_; }

  /// Shows the scene of `is` (its scene is taken) as `id`, from `source`, with `notes`, with the fade; starts
  /// reading its text when that is pending (`reading_said`: "Reading the text." was said already, by the
  /// page's announcement).
  void show(ImageScene& is, int id, ShownSource source, PictureNotes notes, bool reading_said = false);
  /// The operator's level and mode again (a new picture, page or visitor), asked of the servo step at once;
  /// `at_once` false: from the next scene published (settings applied, the scene rebuilt).
  void reset_level(bool at_once = true);
  /// Staff names put on what is shown, at once (the operator's Names tab saved them): `regions` drawn on
  /// Shown::picture and `shape_region` one per curve (−1 none), as apply_names makes them. Where, Describe and the
  /// tour say them from now on; the scene on the device is not touched (names never reach the servo thread).
  /// Ignored when `shape_region` is not one per curve shown.
  void set_names(std::vector<meaning::NamedRegion> regions, std::vector<int> shape_region);
  /// A new visitor: far and near explained again, the operator's level, the tour's touches forgotten.
  void new_visitor();
  /// Window thread, every frame (`now_s` the frame clock [s]): the text of the page shown, read since it was
  /// shown (a page or picture built with its text pending is felt at once). Says "Reading the text." once
  /// when the reading has taken more than kTextWait_s and nothing else is being said. When the text comes,
  /// the scene with the words masked and its blocks is swapped in with the fade, and, once nothing else is
  /// being said, "The text is ready. It has 3 blocks of text and one figure."; or "No text was found." (only
  /// after "Reading the text."); or "The text could not be read." (a worker that crashed, hung or ran out of
  /// memory).
  void poll_text(double now_s);
  /// Whether the text of the page shown is being read, or its news not yet said (scripted runs wait for it).
  bool text_busy() const { return text_.pending() || !text_news_.empty(); }
  /// The longest side pictures whose text is read are shrunk to [px] (KioskRuntime::set_screen_picture_side_px).
  void set_screen_picture_side_px(int px) { screen_side_px_ = px; }

  const Shown& shown() const { return shown_; }
  /// SceneBundle id of what is shown (see kFirstPageId).
  int shown_id() const { return shown_id_; }
  /// Where what is shown came from.
  const ShownSource& source() const { return source_; }
  /// The library picture shown is now number `index` of a new listing (−1: no longer in it). Its scene, and the
  /// SceneBundle id the device holds it under, stay as they are.
  void renumber_picture(int index) { source_.picture = index; }
  /// Scenes put on the device so far: what tests count to see that a superseded page never was.
  std::uint64_t scenes_published() const { return scenes_published_; }
  /// Level in use (the servo thread's, which follows the hand's speed in auto mode).
  int level() const { return step_.display().level; }
  /// What is shown, as the guided tour sees it.
  TourPicture tour_picture() const;

 private:
  bool showing_tutorial() const { return shown_id_ <= -1 && shown_id_ >= -3; }
  ShownView view() const;                            // what the answers read of what is shown
  std::string shape_words(std::size_t curve) const;  // what curve `curve` is, for Where and the tour
  std::string describe_shown();                      // describe() without the reading's news
  void text_arrived(TextRead& read);                 // swaps in the page with its text and words what came
  void publish(Shown sh, std::unique_ptr<Scene> scene, int id, std::vector<Aabb> text_boxes = {});
  const PictureNames& names() const;  // shown_.names in the language in use

  ServoStep& step_;
  Voice& voice_;
  const audio::AudioSystem& audio_;
  TourDesk& tour_;
  PictureShelf& shelf_;
  const config::Settings& s_;
  Vec2 half_;
  Shown shown_;
  mutable PictureNotes said_notes_;  // shown_.notes in the language in use, what view() hands out
  int shown_id_ = -100;
  ShownSource source_;
  std::uint64_t scenes_published_ = 0;
  LevelChoice level_;                             // the visitor's or the operator's fixed choice (auto_level_ false)
  bool auto_level_ = true;                        // levels from hand speed
  bool far_near_said_ = false;                    // Where on a practice shape has said what far and near mean
  int screen_side_px_ = kScreenPictureMaxSidePx;  // set_screen_picture_side_px
  // The text of the page shown.
  TextReader text_;
  double text_since_s_ = -1.0;     // poll_text's clock when the reading was first seen, −1 before
  bool text_said_ = false;         // "Reading the text." was said for it
  bool text_heard_early_ = false;  // page_text handed out its blocks before it was whole: no "text ready" news
  std::string text_news_;          // what came of it, said once nothing else is being said
  int text_news_id_ = 0;           // the scene it is about
};

}  // namespace hk::app
