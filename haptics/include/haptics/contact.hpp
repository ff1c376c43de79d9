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

#include <cstdint>

#include "haptics/collision_query.hpp"
#include "haptics/scene.hpp"

namespace hk {

/// Contact state of the proxy (seed §4 state machine). Values are those written to trace.csv.
enum class ContactState : std::uint8_t { Free = 0, Edge = 1, Vertex = 2 };

/// Haptic events of one tick, for sound and display (bit flags).
enum HapticEvent : std::uint32_t {
  kEventNone = 0,
  kEventContactBegin = 1u << 0,   ///< free → contact
  kEventContactEnd = 1u << 1,     ///< contact → free
  kEventVertexBegin = 1u << 2,    ///< entered vertex contact (concave corner)
  kEventConvexCorner = 1u << 3,   ///< slid over a convex corner onto the next edge
  kEventIterationLimit = 1u << 4, ///< the tick's move budget ran out before the proxy came to rest
  kEventQueryBudget = 1u << 5,    ///< a collision query ran out of time: the proxy stopped where the sweep was proven clear
};

/// Solver parameters. Units in names.
struct ContactParams {
  double stiffness_n_per_m = 800.0;
  double damping_n_s_per_m = 0.0;
  double max_force_n = 4.0;
  double skin_m = 1e-6;       ///< the proxy rests this far on its side of a wall, so rounding never puts it across
  int max_iterations = 8;     ///< proxy moves per tick before giving up for this tick (it stays valid)
};

/// Input of one solver step.
struct ContactInput {
  Vec2 handle_m;                     ///< handle position [m]
  Vec2 handle_velocity_m_per_s;      ///< for rendered damping [m/s]
  int level = 0;                     ///< level whose polylines are walls
  QueryBudget budget;                ///< anytime limits of the collision queries
};

/// Output of one solver step.
struct ContactOutput {
  Vec2 proxy_m;                      ///< proxy (god-object) position after the step [m]
  Vec2 force_n;                      ///< force on the handle, clamped [N]
  ContactState state = ContactState::Free;
  SegmentRef constraint[2];          ///< active constraints (edge: [0]; vertex: [0] and [1])
  std::int32_t level = -1;           ///< level whose polyline constrained the proxy (−1 when free)
  std::uint32_t events = kEventNone; ///< HapticEvent flags
  /// Sharpest turn of the corners met this tick (convex corners passed, the corner of a vertex contact
  /// entered) [rad], 0 when none: the direction change of the polyline there, in [0, π]. Lets sound and
  /// display mark only the corners a hand would call corners, not every vertex of a smooth curve.
  double corner_turn_rad = 0.0;
  QueryStats query;                  ///< summed over this step's queries
  std::int32_t queries = 0;
  /// The proxy's path within the tick: path_m[0] is where it started, then the end of every move
  /// (a wrap round a convex corner is several moves; the straight chord between ticks may cut it).
  static constexpr int kMaxPath = 40;
  Vec2 path_m[kMaxPath];
  std::int32_t path_count = 0;
};

/// The god-object solver for one scene. One per servo thread; sized at construction.
class ContactSolver {
 public:
  /// `scene` must outlive the solver. Allocates (at setup only).
  ContactSolver(const Scene& scene, const ContactParams& params);

  /// Puts the proxy at p in free space and forgets the contact state. If p is within the skin of a
  /// polyline at `level`, it is pushed off along the wall's normal. Not for the servo path (may walk
  /// the tree from the roots), but allocates nothing.
  void reset(Vec2 p_m, int level);

  /// One tick: move the proxy towards the handle under the constraints, then compute the force.
  /// Real-time safe: no allocation, lock, throw or I/O.
  void update(const ContactInput& in, ContactOutput& out);

  Vec2 proxy() const { return proxy_; }
  ContactState state() const { return state_; }
  const ContactParams& params() const { return params_; }
  void set_params(const ContactParams& p) { params_ = p; }
  const BoundarySection& section() const { return section_; }

 private:
  struct Constraint {
    SegmentRef seg;
    double side = 1.0;  // +1: proxy on the segment's left, −1: right
  };
  enum class Move : std::uint8_t { Clear, Hit, Blocked };
  // Moves the proxy towards `target`, stopping a skin short of the first wall (Hit, wall in hit_out),
  // or short of the first box the query could not resolve in its budget (Blocked).
  Move move_to(Vec2 target, int level, const SegmentRef* excluded, int excluded_count, const QueryBudget& budget,
               ContactOutput& out, Constraint* hit_out);
  double side_of(SegmentRef s, Vec2 p) const;

  const Scene* scene_;
  ContactParams params_;
  BoundarySection section_;
  Vec2 proxy_;
  ContactState state_ = ContactState::Free;
  Constraint c_[2];
  int level_ = 0;
};

}  // namespace hk
