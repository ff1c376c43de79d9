#pragma once
/// @file groove.hpp
/// The grooves rendering mode (DESIGN.md "Contact": `[haptics] render = "grooves"`).
///
/// Each curve is an engraved line, the convention of haptic line graphs (Yu & Brewster 2002, "Comparing
/// two haptic interfaces for multimodal graph rendering", HAPTICS'02, and Yu, Ramloll & Brewster 2001,
/// "Haptic graphs for blind computer users": lines rendered as grooves the hand falls into and follows,
/// rather than ridges or walls). Within a capture radius R of the polyline at the level in use, the hand is
/// pulled towards the closest point q of that polyline; beyond R nothing is felt. Curves never block.
///
/// The profile is ours. At distance r = |q − handle| the pull has magnitude
///     F(r) = min(k·r, depth_n, k·(R − r))   for r < R,   0 for r ≥ R,
/// then clamped to max_force_n: a trapezoid that is zero on the curve and at the rim. Why this shape:
///   - zero at the centre and slope k there: a spring of the wall stiffness k holds the hand on the
///     line, so the groove's centre is a stable rest point with the stiffness the device is tuned for;
///   - zero at the rim: no force step when the hand enters or leaves (a step would be felt as a click
///     and, on a stiff device, excite the handle);
///   - slope never above k anywhere: along a lone curve the force field is Lipschitz with constant k, so
///     it is no stiffer than a wall and just as stable under the servo's sampling;
///   - the flat top, depth_n, is what the operator sets: how hard the groove holds, as felt. At most
///     k·R/2 is reachable (the two slopes meet at r = R/2); a larger depth_n gives the triangle.
/// A Gaussian or cosine well would be smooth too, but its steepest slope depends on depth and width
/// together; the trapezoid keeps the slope bound k independent of the depth the operator chooses.
///
/// Where the closest point jumps — on the medial axis of the polylines within R: between two parts of
/// curves closer than 2R (inside a hairpin, between two nearby curves) and, by a little, on the bisector
/// of each concave polyline vertex — the direction of the pull turns in one tick. There, and only there
/// (and at a change of level or gains, where the polyline or the law changes under the hand), the change
/// of the groove force per tick is limited to k·|handle motion since the last tick| + jump_step_n. Along a
/// lone straight or convex stretch the limit never binds (the field is k-Lipschitz), so the force the
/// hand feels there is exactly F(r) towards q. The limit catches up at jump_step_n per tick at least, so a
/// jump of J [N] is absorbed within ceil(J / jump_step_n) ticks (2·depth_n / jump_step_n at worst, 40 ticks at
/// the defaults); a hand that leaves the radius within those ticks of a jump feels the rest of it fade
/// outside the rim, the one case where the force is not zero with the state Free.

#include <cstdint>

#include "haptics/collision_query.hpp"
#include "haptics/contact.hpp"
#include "haptics/scene.hpp"

namespace hk {

/// Parameters of the groove field. Units in names. Values are assumed checked (config ranges): finite,
/// capture_radius_m > 0, the rest ≥ 0.
struct GrooveParams {
  double capture_radius_m = 0.003;  ///< R: the pull acts within this distance of the curve [m]
  double depth_n = 1.0;             ///< the strongest pull (the trapezoid's flat top), at most k·R/2 is reached [N]
  double stiffness_n_per_m = 800;   ///< k: slope of the profile at the centre and at the rim [N/m]
  double max_force_n = 4;           ///< clamp on the groove force [N]
  double jump_step_n = 0.05;  ///< force change per tick allowed beyond k·|Δhandle| where the closest point jumps [N]
  bool cut_walls = true;  ///< build the cut masks (grooves along cut steps; read by the constructor without CutWalls);
                          ///< see ContactParams::cut_walls
};

/// The groove profile: F(r) = min(k·r, depth_n, k·(R − r)) for 0 ≤ r < R, 0 for r ≥ R (and for r < 0 or
/// non-finite r), then clamped to max_force_n [N]. `r_m` in metres. Pure, real-time safe.
double groove_profile_n(const GrooveParams& p, double r_m) noexcept;

/// The groove solver for one scene: same step interface as ContactSolver, so SceneStep can step either.
/// One per servo thread; sized at construction.
///
/// Output of update() (ContactOutput):
///   proxy_m      the closest point q of the polylines at the level in use when within the capture
///                radius, else the handle [m];
///   force_n      F(r)·(q − h)/r, through the per-tick limiter (see the file comment) [N];
///   state        Edge (1) within the capture radius, Free (0) outside;
///   constraint   [0] the segment holding q (Edge only), [1] none;
///   level        the level in use (also when free);
///   events       kEventContactBegin on entering the radius, kEventContactEnd on leaving it,
///                kEventQueryBudget when the closest-point walk ran out of the tick's budget;
///   path_m       the proxy at the start and at the end of the tick (path_count 2);
///   query, queries, budget_used   as ContactSolver (one closest-point walk per tick).
/// When the walk runs out of budget the answer is unknown: the solver keeps last tick's closest point if
/// it is still within the radius (the groove is followed from where it was), else reports free space.
class GrooveSolver {
 public:
  /// `scene` must outlive the solver. Allocates (at setup only); with params.cut_walls it computes the scene's
  /// cut masks (make_cut_walls).
  GrooveSolver(const Scene& scene, const GrooveParams& params);
  /// The same, with the cut masks and bounds `cuts` (make_cut_walls of `scene`, shared with other solvers of
  /// it; null: none) in place of params.cut_walls. Throws hk::ArgumentError when they are another scene's.
  GrooveSolver(const Scene& scene, const GrooveParams& params, std::shared_ptr<const CutWalls> cuts);

  /// Starts at p [m] on `level`: free state, no force remembered (the next force is limited from zero).
  /// Real-time safe (allocates nothing).
  void reset(Vec2 p_m, int level) noexcept;

  /// One tick: the closest point within the capture radius at in.level, the groove force towards it,
  /// limited per tick. in.handle_velocity_m_per_s is not used. Every box test is charged to a copy of
  /// in.budget (see BoundarySection::closest_point). Real-time safe: no allocation, lock, throw or I/O.
  void update(const ContactInput& in, ContactOutput& out) noexcept;

  /// The boundary section (the grooves mode walks from the roots and leaves it at the roots; kept for
  /// the display, which shows the active solver's section).
  const BoundarySection& section() const { return section_; }
  /// The parameters in use.
  const GrooveParams& params() const { return params_; }
  /// New parameters from the next update on; the force moves to the new law through the per-tick limiter.
  /// Real-time safe.
  void set_params(const GrooveParams& p) { params_ = p; }
  /// The closest point after the last update (Edge), or the handle (Free) [m].
  Vec2 proxy() const { return proxy_; }
  /// Edge within the capture radius after the last update, else Free.
  ContactState state() const { return state_; }

 private:
  // The phases of update, in order (each documented where it is defined).
  void find_groove(Vec2 h, QueryBudget& budget, ContactOutput& out) noexcept;
  Vec2 groove_force(Vec2 h) noexcept;
  const Scene* scene_;
  GrooveParams params_;
  BoundarySection section_;
  Vec2 proxy_;  // closest point (Edge) or handle (Free) [m]
  ContactState state_ = ContactState::Free;
  SegmentRef seg_;  // segment holding proxy_ while Edge
  int level_ = 0;
  Vec2 last_force_;   // groove force of the last tick [N]
  Vec2 last_handle_;  // handle at the last tick [m]
};

}  // namespace hk
