#pragma once
/// @file contact.hpp
/// The god-object contact solver (seed paper §4; DESIGN.md "Contact"; Zilles & Salisbury 1995).
///
/// A proxy point follows the handle but never crosses a curve's polyline at the level in use. States:
///   0 Free   — proxy = handle;
///   1 Edge   — on one segment: the tangential part of the handle motion slides the proxy, the normal part
///              is force;
///   2 Vertex — held by two constraints (a concave corner, or two curves that meet): the proxy stays
///              while the force is positively spanned by the two edge normals and the stable-contact
///              rule holds (the pull along each incident edge points towards the vertex); otherwise it
///              leaves to the edge whose rule failed.
/// Convex corners are passed over, never held (no sticky corners, seed §4). Transitions are found within
/// the tick: the solver iterates (at most max_iterations moves) until the proxy rests. Every proxy move is
/// a swept query against the scene, so a move that would cross any polyline stops a skin short of it.
/// Curves are walls from both sides: the proxy keeps the side it came from.
/// Force on the handle = stiffness · (proxy − handle) − damping · (handle velocity along the contact
/// normal), clamped to max_force_n.
///
/// Friction (the friction cone of the god-object, Salisbury, Brock, Massie, Swarup &
/// Zilles 1995, "Haptic rendering: programming touch interaction with virtual objects", §"friction", and
/// CHAI3D's finger-proxy algorithm): in edge contact the handle's offset from the proxy has a normal part
/// d (the penetration) and a tangential part t. The proxy sticks while |t| ≤ μ_s·d (inside the static
/// cone); once outside, it slides and trails the handle at |t| = μ_d·d (on the dynamic cone), so the
/// tangential force is μ_d times the normal force: Coulomb's law. It sticks again when the handle comes
/// back inside the dynamic cone and has all but stopped along the edge (stick_speed_m_per_s). μ_s ≥ μ_d
/// gives the hysteresis between sticking and sliding. Both 0:
/// frictionless, the seed paper's model. Friction only ever holds the proxy back, so it takes energy out
/// (the work the hand does round a closed loop is ≥ 0).
///
/// Push-through (DESIGN.md "Contact"): a blind visitor cannot lift the handle over a wall,
/// so a wall gives way, as a membrane, to a deliberate press. While in contact, the spring force
/// stiffness·|proxy − handle| (unclamped: how hard the hand presses) is counted tick by tick (not while the
/// force ramps in: ContactInput::press_counts); once it has
/// been ≥ pop_force_n for pop_hold_s without a break, the next tick begins with a pop: the proxy jumps to
/// the handle, on the far side of the wall(s) it was held by (pushed off any polyline within the skin, so
/// it never rests on a wall), the state becomes Free, and the event kEventPopThrough is set. That is the
/// one tick on which the proxy crosses a curve. The force of the tick before the pop does not vanish in one
/// tick: it fades linearly to zero over pop_release_s (added to whatever the proxy's new contacts give, the
/// sum clamped to max_force_n). pop_force_n = 0 turns push-through off: walls never give way. A gentle
/// exploration (the visitor's usual 1–2 N) never reaches the default 3 N.

#include <cstdint>

#include "haptics/collision_query.hpp"
#include "haptics/scene.hpp"

namespace hk {

/// Contact state of the proxy (seed §4 state machine). Values are those written to trace.csv.
enum class ContactState : std::uint8_t { Free = 0, Edge = 1, Vertex = 2 };

/// Haptic events of one tick, for sound and display (bit flags).
enum HapticEvent : std::uint32_t {
  kEventNone = 0,
  kEventContactBegin = 1u << 0,    ///< free → contact
  kEventContactEnd = 1u << 1,      ///< contact → free
  kEventVertexBegin = 1u << 2,     ///< entered vertex contact (concave corner)
  kEventConvexCorner = 1u << 3,    ///< slid over a convex corner onto the next edge
  kEventIterationLimit = 1u << 4,  ///< the tick's move budget ran out before the proxy came to rest
  kEventQueryBudget =
      1u
      << 5,  ///< a collision query ran out of its box-test budget: the proxy stopped where the sweep was proven clear
  kEventPopThrough =
      1u << 6,  ///< the proxy passed through a wall on purpose this tick (pressed ≥ pop_force_n for pop_hold_s)
};

/// Solver parameters. Units in names.
struct ContactParams {
  double stiffness_n_per_m = 800.0;
  double damping_n_s_per_m = 0.0;
  double max_force_n = 4.0;
  double skin_m = 1e-6;           ///< the proxy rests this far on its side of a wall, so rounding never puts it across
  int max_iterations = 8;         ///< proxy moves per tick before giving up for this tick (it stays valid)
  double static_friction = 0.0;   ///< μ_s: the proxy sticks while |tangential offset| ≤ μ_s · penetration
  double dynamic_friction = 0.0;  ///< μ_d ≤ μ_s: a sliding proxy trails the handle by μ_d · penetration
  /// A sliding proxy sticks again only when the handle moves along the edge slower than this [m/s]
  /// (Karnopp 1985, "Computer simulation of stick-slip friction in mechanical dynamic systems": a band of
  /// relative speed counted as zero), so a hand that keeps moving feels steady μ_d, not stick-slip.
  double stick_speed_m_per_s = 0.002;
  /// Push-through (see above): a press with spring force ≥ this for pop_hold_s lets the proxy through [N];
  /// 0 = off (walls never give way).
  double pop_force_n = 0.0;
  double pop_hold_s = 0.3;      ///< how long the press must last [s]
  double pop_release_s = 0.02;  ///< the force of the tick before a pop fades to zero over this [s]
  double period_s =
      0.001;  ///< the servo period the solver is stepped at [s] (counts pop_hold_s and pop_release_s in ticks)
  /// Build the cut masks for walls at cut steps (BoundarySection's `cut_walls`; read at construction);
  /// without them a cut step renders as its tolerance step. SceneStep does not read it: it computes the masks
  /// once for LevelSteps::Cuts and hands them to both its solvers (the constructor that takes CutWalls).
  bool cut_walls = true;
};

/// Input of one solver step.
struct ContactInput {
  Vec2 handle_m;                 ///< handle position [m]
  Vec2 handle_velocity_m_per_s;  ///< for rendered damping [m/s]
  int level = 0;  ///< level id whose polylines are walls (a level, a tolerance step or a cut step: hk/constants.hpp)
  /// The tick's box-test budget (QueryBudget): its limit, and what was already spent this tick before the
  /// step (e.g. by level_change_is_safe). Every query of the step draws on it.
  QueryBudget budget;
  /// False while the force is still ramping in (start-up, a device back, a new picture): a hand sinks into
  /// a wall the ramp holds weakly, and that must not count as a deliberate press (push-through).
  bool press_counts = true;
};

/// Output of one solver step.
struct ContactOutput {
  Vec2 proxy_m;  ///< proxy (god-object) position after the step [m]
  Vec2 force_n;  ///< force on the handle, clamped [N]
  ContactState state = ContactState::Free;
  SegmentRef constraint[2];  ///< active constraints (edge: [0]; vertex: [0] and [1])
  std::int32_t level = -1;   ///< level of the polyline that constrained the proxy (its curve's level, −1 when free)
  std::uint32_t events = kEventNone;  ///< HapticEvent flags
  /// Sharpest turn of the corners met this tick (convex corners passed, the corner of a vertex contact
  /// entered) [rad], 0 when none: the direction change of the polyline there, in [0, π]. Lets sound and
  /// display mark only the corners a hand would call corners, not every vertex of a smooth curve.
  double corner_turn_rad = 0.0;
  bool sticking = false;  ///< edge contact held by static friction this tick
  std::int32_t transition_level =
      -1;  ///< ≥ 0: the previous level id, still a wall after a level change (see level_change_is_safe)
  /// How long the hand has pressed with ≥ pop_force_n without a break, by the end of this tick [s]; 0 when
  /// push-through is off, the proxy is free or the press is lighter. The wall gives way once it reaches pop_hold_s.
  double press_s = 0.0;
  QueryStats query;  ///< summed over this step's queries
  std::int32_t queries = 0;
  /// Box tests charged to the tick's budget by the end of the step: ContactInput::budget.box_tests_used
  /// plus this step's (query.box_tests). At most budget.max_box_tests + query.section_box_tests.
  std::int32_t budget_used = 0;
  /// The proxy's path within the tick: path_m[0] is where it started, then the end of every move
  /// (a wrap round a convex corner is several moves; the straight chord between ticks may cut it).
  static constexpr int kMaxPath = 40;
  Vec2 path_m[kMaxPath];
  std::int32_t path_count = 0;
};

/// The god-object solver for one scene. One per servo thread; sized at construction.
class ContactSolver {
 public:
  /// `scene` must outlive the solver. Allocates (at setup only); with params.cut_walls it computes the scene's
  /// cut masks (make_cut_walls).
  ContactSolver(const Scene& scene, const ContactParams& params);
  /// The same, with the cut masks and bounds `cuts` (make_cut_walls of `scene`, shared with other solvers of
  /// it; null: none) in place of params.cut_walls. Throws hk::ArgumentError when they are another scene's.
  ContactSolver(const Scene& scene, const ContactParams& params, std::shared_ptr<const CutWalls> cuts);

  /// Puts the proxy at p in free space and forgets the contact state. If p is within the skin of a
  /// polyline at `level`, it is pushed off along the wall's normal (closest_point within two skins, its
  /// box tests charged to a budget of `max_box_tests`, 0 = no limit; past the budget the proxy stays at
  /// p). Real-time safe: allocates nothing, and with a budget its work is bounded like a tick's queries.
  void reset(Vec2 p_m, int level, std::int32_t max_box_tests = 0) noexcept;

  /// One tick: move the proxy towards the handle under the constraints, then compute the force.
  /// Real-time safe: no allocation, lock, throw or I/O.
  void update(const ContactInput& in, ContactOutput& out) noexcept;

  /// Whether the level in use may change to `new_level` now without the proxy ending up on the other side
  /// of the new level's polyline than it is of the old one. For each curve the proxy
  /// touches, and every curve within the search radius (below) at either level (at most kMaxSideCurves in
  /// all; more, and the change waits), the proxy's side of the curve is found at both levels
  /// (closest point and pseudo-normal, see side_of_curve); a curve on which the sides differ has the proxy
  /// between its two polylines, and the change must wait (the caller tries again next tick; as the hand
  /// moves on, the two levels' polylines cross each other and the sides agree again). Points between two
  /// levels lie within E = (largest wall offset of the old level + of the new) of both polylines, the offset
  /// being the boxes' error bound: their half-width combined with their reach past their segments' ends, which
  /// is the larger at a sharp corner, where a coarse level's apex lies inside the original's. So only curves
  /// within 2E are searched, and every one of them, not only the nearest at each level: a second curve as
  /// near, where two edges cross, could have the proxy between its levels; and E takes the reach as well as the
  /// half-width, since with the half-width alone a coarse apex could lie behind the proxy unseen. When the change is
  /// made (the next update() with the new level), the old level stays a wall, with the proxy's constraints on it, until
  /// the proxy rests on none of its segments: the proxy, on the same side of both polylines, then reaches the new one
  /// without crossing either. No second change is made while the old level is still a wall. Allocates nothing (at most
  /// six closest-point walks). With a `budget`, the walks' box tests are charged to it and never take it past its
  /// limit: when it runs out before the answer is known, the answer is false (the change waits). Levels, tolerance
  /// steps and cut steps mix freely (level ids, hk/constants.hpp): each curve is compared at its own polyline for each
  /// id (a cut step's: its joined cut, where E takes twice the cut's error bound, as a joined piece may lie anywhere in
  /// its box), and a curve with the same polyline under both has nothing between them. At a cut step a segment's ends
  /// depend on its neighbours in the cut, so a constraint keeps the level id it was met at (its geometry), and the wall
  /// the proxy slides on is left out only of the queries where it has that same geometry.
  bool level_change_is_safe(int new_level, QueryBudget* budget = nullptr) noexcept;
  /// The most curves level_change_is_safe compares sides on in one check (where more lie within its radius,
  /// as at a knot of many edges, the change waits).
  static constexpr int kMaxSideCurves = 8;

  Vec2 proxy() const { return proxy_; }
  ContactState state() const { return state_; }
  const ContactParams& params() const { return params_; }
  void set_params(const ContactParams& p) { params_ = p; }
  const BoundarySection& section() const { return section_; }

 private:
  struct Constraint {
    SegmentRef seg;
    double side = 1.0;  // +1: proxy on the segment's left, −1: right
    int level = 0;  // the level id it is a wall of (a cut step's segments are drawn joined: their ends depend on it)
  };
  enum class Move : std::uint8_t { Clear, Hit, Blocked };
  // Moves the proxy towards `target`, stopping a skin short of the first wall (Hit, wall in hit_out),
  // or short of the first box the query could not resolve in its budget (Blocked). The `excluded`
  // constraint (the wall the proxy slides on, or null) is left out of each query whose walls include it
  // with the same geometry (excluded_at).
  Move move_to(Vec2 target, int level, const Constraint* excluded, QueryBudget& budget, ContactOutput& out,
               Constraint* hit_out) noexcept;
  // Whether constraint c is a wall of level id `level` with the same end points as its own (its own level;
  // at a cut step the same segment may be joined to other neighbours, so it is another wall there).
  bool excluded_at(const Constraint& c, int level) const noexcept;
  // What one update() works on: the handle, the tick's budget, the output. Passed to the state steps.
  struct Step {
    const ContactInput& in;
    ContactOutput& out;
    QueryBudget budget;
  };
  // The phases of update(), in order: begin_step, pop_through (when a press has lasted pop_hold_s), then per
  // iteration the step of the current state (each returns true when the proxy is at rest for this tick),
  // then contact_force, release_force and finish_step (which also counts the press for the next tick).
  void begin_step(const ContactInput& in, ContactOutput& out) noexcept;
  // Push-through, its own transition Edge/Vertex → Free: true when the press counted so far is due.
  bool pop_due() const noexcept;
  void pop_through(Step& s) noexcept;
  // The contact force plus what remains of the force before a pop (fading over pop_release_s), clamped.
  Vec2 release_force(Vec2 contact_force_n) noexcept;
  void count_press(const ContactInput& in, ContactOutput& out) noexcept;
  // Pushes the proxy off any polyline of the level in use within the skin, to the side it is on.
  void push_off_walls(QueryBudget* budget) noexcept;
  bool step_free(Step& s) noexcept;
  bool step_edge(Step& s) noexcept;
  bool step_vertex(Step& s) noexcept;
  // Edge state: the slide along c_[0] reached its vertex at the end `clamped` (−1 start, +1 end).
  bool at_edge_vertex(Step& s, int clamped) noexcept;
  Vec2 contact_force(const ContactInput& in) const noexcept;
  void finish_step(ContactState before, Vec2 force_n, ContactOutput& out) noexcept;
  // The wall geometry of segment s at level id `level` (BoundarySection::wall_points), and of a constraint.
  struct SegGeom {
    Vec2 a, b, u, n;  // end points, unit direction, unit left normal
    double len = 0.0;
  };
  SegGeom geom(SegmentRef s, int level) const noexcept;
  SegGeom geom(const Constraint& c) const noexcept { return geom(c.seg, c.level); }

  const Scene* scene_;
  ContactParams params_;
  BoundarySection section_;
  Vec2 proxy_;
  ContactState state_ = ContactState::Free;
  Constraint c_[2];
  int level_ = 0;
  bool sticking_ = false;      // edge contact inside the static friction cone
  int transition_level_ = -1;  // the previous level, still a wall just after a change; −1 = none
  long press_ticks_ = 0;       // consecutive ticks in contact pressed with ≥ pop_force_n
  Vec2 release_from_n_;        // the force of the tick before the last pop [N]
  long release_left_ = 0;      // ticks of its fade still to go
  Vec2 last_force_n_;          // the force of the last tick [N]
  // Per level id: how far its walls can lie from the original curve [m]: for a level or tolerance step, the
  // largest error bound of any curve's boxes (Scene::max_error_bound_m: the half-width combined with how far a
  // box reaches past its segment's ends; at a sharp corner the original runs on past a coarse segment's end,
  // so the half-width alone was too small and a change of level could put the proxy behind the new level's
  // apex); for a cut step, twice its cut's error bound (a joined piece may lie anywhere in its box).
  double max_wall_offset_m_[kLevelIds] = {};
  // Side of p relative to curve `curve`'s polyline at `level`: +1 left, −1 right, 0 when the polyline is not
  // within radius_m, 2 when p lies on it, 3 when `budget` ran out first. Where the nearest point is an open end,
  // the side of the end segment's line: beyond the end, the wedge between two levels' end segments then has
  // different sides, as it lies between the polylines; so does the opposite wedge, where a change waits
  // although nothing is crossed (safe, and only while the proxy stays there).
  int side_of_curve(Vec2 p, int curve, int level, double radius_m, QueryBudget* budget) noexcept;
};

}  // namespace hk
