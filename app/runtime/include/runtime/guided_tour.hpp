#pragma once
/// @file guided_tour.hpp
/// The guided tour: the Guide key leads the handle to the nearest shape not yet touched
/// in this visit, traces its outline once and lets go. This file is the planning half, GL-free and off the
/// servo thread: which shapes were touched (VisitTouches), which shape comes next and the timed path of
/// the handle's target (plan_tour). The servo half (ServoStep::publish_tour, haptics/tour_guide.hpp's
/// TourGuide) follows the path with a force-limited spring.
///
/// The path, as a flat list of timed targets (TourPath::points, built here, read by the servo thread):
///   1. transit: from the handle to a start point offset_m (1.5 mm) off the shape on the handle's side, in a
///      straight line with a minimum-jerk time law (Flash & Hogan 1985, "The coordination of arm
///      movements", J. Neurosci. 5(7)): it starts and ends at rest and its peak speed is 1.875 times its
///      mean; the mean is tour_speed, so it never goes faster than 2 × tour_speed. Walls are suspended
///      (the visitor is led through the air, over walls in the way).
///   2. onto the track: 0.5 mm from the start point to the outline's track, at tour_speed; walls are on
///      from here (only the toured shape's: ServoStep lets go of contacts with other shapes).
///   3. outline: the target runs along the shape's outline track_offset_m (1 mm) off the curve on the
///      handle's side, at tour_speed, and a force, press_force_n (0.6 N), pushes the handle onto the wall:
///      along the wall's inward normal while the handle touches the shape (ServoStep takes it from the
///      contact), else along the path's normal. Against the 300 N/m spring and the 800 N/m wall this rests
///      the handle ~0.3 mm into the wall, so the visitor feels the wall and hears its slide cues while
///      being led round it. The press grows in over the first press_ramp_m of the outline and fades over
///      its last. A closed shape is traced all the way round back to the start; an open one from its end
///      nearer the handle to the far end.
///   4. release: back to offset_m on the handle's side, at tour_speed; then the servo lets go (the guide
///      force fades out over fade_s).
/// The press keeps the handle on the wall, so in the outline it follows the wall into every narrow pocket,
/// slot or hook of the rendered polyline, which the track, offset from the curve at the planning level, passes
/// outside; from inside a hook the spring pulls into the wall. The TourGuide then follows the wall instead (see
/// TourParams::trap_s): the handle is led out of the pocket along it, and the spring takes over again near the
/// waiting target; without it, tours on 9 of the 22 test pictures stop as if held.
/// (An outline 1.5 mm off the wall on the handle's side with no press would lead the handle round in the
/// air, never touching the shape. A target 1.5 mm past the wall fails: with the walls' friction (μ_s 0.4) the handle
/// sticks on the wall wherever the pull points mostly into it — round every convex corner — while the target runs on. A
/// target outside pulls the handle round convex corners; the press, a force along the wall's normal where the handle
/// is, keeps it on the wall without pulling it into a corner.)
///
/// "Sensible order": always the nearest untouched shape from where the handle is (distance to its
/// polyline), so repeated Guide presses walk the picture without long jumps. Specks are not toured: a
/// curve whose level-0 length is below min_shape_length_m (6 mm, about a fingertip's width) is neither
/// chosen nor counted as remaining.

#include <cstdint>
#include <optional>
#include <vector>

#include "config/settings.hpp"
#include "haptics/scene.hpp"
#include "haptics/tour_guide.hpp"
#include "hk/vec2.hpp"

namespace hk::app {

/// The shapes touched in this visit of this picture (the kiosk keeps what was touched per visit). Fed with the servo
/// display state's contact curve and with completed tours. Forgotten with a new picture (reset) and a new visitor.
class VisitTouches {
 public:
  /// Forgets everything; from now on touches of picture `scene_id` with `curve_count` curves are kept.
  void reset(int scene_id, int curve_count);
  /// Curve `curve` of picture `scene_id` was touched. Ignored for another picture or a curve out of range.
  void touch(int scene_id, int curve);
  /// Whether curve `curve` was touched (false out of range).
  bool touched(int curve) const;
  /// Curves touched.
  int count() const { return count_; }
  /// The picture the touches are of (−1 before the first reset).
  int scene_id() const { return scene_id_; }

 private:
  int scene_id_ = -1;
  int count_ = 0;
  std::vector<unsigned char> touched_;
};

/// Length of curve c's level-0 polyline [m] (closed: round the loop).
double curve_length_m(const Scene& scene, std::size_t c);
/// Whether curve c is a shape worth a tour (level-0 length ≥ p.min_shape_length_m).
bool is_tour_shape(const Scene& scene, std::size_t c, const TourParams& p);
/// Shapes (is_tour_shape) of the scene not yet touched.
int shapes_remaining(const Scene& scene, const VisitTouches& touched, const TourParams& p);
/// Distance from p to curve c's polyline at `level` (clamped to the curve's levels) [m].
double distance_to_curve_m(const Scene& scene, std::size_t c, int level, Vec2 p);
/// The level tours of curve c are planned on: the coarsest whose max_error_m is below p.plan_error_m (0 if none).
int tour_plan_level(const Scene& scene, std::size_t c, const TourParams& p);

/// Plans the tour to the nearest shape not yet touched from `handle_m` [m] (distance to its polyline at
/// tour_plan_level), as described in the file comment. `scene_id` is stored in the path (the servo drops a
/// path for another picture). Returns nullopt when every shape is touched (or there is none). Allocates:
/// not for the servo thread. Never throws for a valid scene (std::bad_alloc aside).
std::optional<TourPath> plan_tour(const Scene& scene, int scene_id, Vec2 handle_m, const VisitTouches& touched,
                                  const TourParams& p);

/// Plans the tour to curve `curve` (a named part the visitor picked) from `handle_m` [m], as plan_tour does for
/// the shape it chooses, touched or not. Returns nullopt for a curve out of range or with fewer than 2 points at
/// tour_plan_level. Allocates: not for the servo thread.
std::optional<TourPath> plan_tour_to(const Scene& scene, int scene_id, Vec2 handle_m, std::size_t curve,
                                     const TourParams& p);

}  // namespace hk::app
