// God-object contact solver (seed paper §4). See contact.hpp for the model.
#include "haptics/contact.hpp"

#include <algorithm>
#include <cmath>

namespace hk {
namespace {

struct SegGeom {
  Vec2 a, b, u, n;  // end points, unit direction, unit left normal
  double len = 0.0;
};

inline SegGeom geom(const Scene& sc, SegmentRef s) {
  SegGeom g;
  sc.segment(s, &g.a, &g.b);
  const Vec2 d = g.b - g.a;
  g.len = length(d);
  g.u = normalized_or(d, Vec2{1.0, 0.0});
  g.n = left_perp(g.u);
  return g;
}

// The neighbour of segment s across its start (dir < 0) or end (dir > 0) vertex, if the curve has one.
inline bool neighbour(const Scene& sc, SegmentRef s, int dir, SegmentRef* out) {
  const CurveInfo& ci = sc.curve(static_cast<std::size_t>(s.curve));
  const std::int32_t n = static_cast<std::int32_t>(ci.segment_count[s.level]);
  std::int32_t k = s.segment + (dir > 0 ? 1 : -1);
  if (k < 0 || k >= n) {
    if (!ci.closed) return false;
    k = (k + n) % n;
  }
  if (k == s.segment) return false;
  *out = SegmentRef{s.curve, s.level, k};
  return true;
}

}  // namespace

ContactSolver::ContactSolver(const Scene& scene, const ContactParams& params)
    : scene_(&scene), params_(params), section_(scene) {}

double ContactSolver::side_of(SegmentRef s, Vec2 p) const {
  const SegGeom g = geom(*scene_, s);
  return dot(g.n, p - g.a) >= 0.0 ? 1.0 : -1.0;
}

void ContactSolver::reset(Vec2 p_m, int level) {
  proxy_ = p_m;
  state_ = ContactState::Free;
  level_ = level;
  section_.reset();
  // A proxy started on a wall would have no side: push it off along the wall's normal.
  Vec2 q;
  SegmentRef s;
  if (section_.closest_point(p_m, level, 2.0 * params_.skin_m, &q, &s)) {
    const SegGeom g = geom(*scene_, s);
    const double side = dot(g.n, p_m - g.a) >= 0.0 ? 1.0 : -1.0;
    proxy_ = q + (2.0 * params_.skin_m * side) * g.n;
  }
}

ContactSolver::Move ContactSolver::move_to(Vec2 target, int level, const SegmentRef* excluded, int excluded_count,
                            const QueryBudget& budget, ContactOutput& out, Constraint* hit_out) {
  QueryStats st;
  const SweepHit hit = section_.first_hit(proxy_, target, level, excluded, excluded_count, budget, &st);
  out.query.box_tests += st.box_tests;
  out.query.segment_tests += st.segment_tests;
  out.query.splits += st.splits;
  out.query.merges += st.merges;
  out.query.section_size = st.section_size;
  out.query.coarsest_answer_level = std::max(out.query.coarsest_answer_level, st.coarsest_answer_level);
  out.query.budget_exhausted = out.query.budget_exhausted || st.budget_exhausted;
  ++out.queries;
  if (hit.blocked) {
    // Unresolved in time: go only as far as the sweep is proven clear, less the skin. Never guess.
    const double len = distance(proxy_, target);
    const double t = len > 0.0 ? std::max(0.0, hit.t - params_.skin_m / len) : 0.0;
    proxy_ = proxy_ + t * (target - proxy_);
    if (out.path_count < ContactOutput::kMaxPath) out.path_m[out.path_count++] = proxy_;
    out.events |= kEventQueryBudget;
    return Move::Blocked;
  }
  if (!hit.hit) {
    proxy_ = target;
    if (out.path_count < ContactOutput::kMaxPath) out.path_m[out.path_count++] = proxy_;
    return Move::Clear;
  }
  // Stop where the proxy is a skin away from the wall's line, along the path already proven clear.
  const SegGeom g = geom(*scene_, hit.segment);
  double side = dot(g.n, proxy_ - g.a);
  side = side > 0.0 ? 1.0 : (side < 0.0 ? -1.0 : (dot(g.n, target - g.a) > 0.0 ? -1.0 : 1.0));
  const double dist0 = side * dot(g.n, proxy_ - g.a);
  const double closing = -side * dot(g.n, target - proxy_);
  double t = 0.0;
  if (closing > 0.0) t = std::clamp((dist0 - params_.skin_m) / closing, 0.0, hit.t);
  proxy_ = proxy_ + t * (target - proxy_);
  if (out.path_count < ContactOutput::kMaxPath) out.path_m[out.path_count++] = proxy_;
  hit_out->seg = hit.segment;
  hit_out->side = side;
  return Move::Hit;
}

void ContactSolver::update(const ContactInput& in, ContactOutput& out) {
  const Scene& sc = *scene_;
  const ContactState before = state_;
  out.events = kEventNone;
  out.corner_turn_rad = 0.0;
  out.query = QueryStats{};
  out.queries = 0;
  out.path_count = 0;
  out.path_m[out.path_count++] = proxy_;
  if (in.level != level_) {  // constraints refer to the old level's segments: start free (proxy kept)
    state_ = ContactState::Free;
    level_ = in.level;
  }
  const Vec2 h = in.handle_m;
  const double skin = params_.skin_m;
  bool rest = false;
  int iter = 0;
  for (; iter < params_.max_iterations && !rest; ++iter) {
    switch (state_) {
      case ContactState::Free: {
        Constraint hit;
        const Move m = move_to(h, level_, nullptr, 0, in.budget, out, &hit);
        if (m == Move::Hit) {
          state_ = ContactState::Edge;
          c_[0] = hit;
        } else {
          rest = true;
        }
        break;
      }
      case ContactState::Edge: {
        const SegmentRef seg = c_[0].seg;
        const double side = c_[0].side;
        const SegGeom g = geom(sc, seg);
        if (side * dot(g.n, h - g.a) >= 0.0) {  // handle back on the proxy's side: contact released
          state_ = ContactState::Free;
          break;
        }
        const double tau = dot(g.u, h - g.a);
        const int clamped = tau < 0.0 ? -1 : (tau > g.len ? 1 : 0);
        const double tau_c = std::clamp(tau, 0.0, g.len);
        Constraint hit;
        const Move m = move_to(g.a + tau_c * g.u + (side * skin) * g.n, level_, &seg, 1, in.budget, out, &hit);
        if (m == Move::Blocked) {
          rest = true;
          break;
        }
        if (m == Move::Hit) {
          state_ = ContactState::Vertex;  // a second wall while sliding
          c_[1] = hit;
          out.events |= kEventVertexBegin;
          const SegGeom gh = geom(sc, hit.seg);  // the angle between the two walls' lines, in [0, π/2]
          out.corner_turn_rad = std::max(out.corner_turn_rad, std::atan2(std::fabs(cross(g.u, gh.u)), std::fabs(dot(g.u, gh.u))));
          break;
        }
        if (clamped == 0) {
          rest = true;
          break;
        }
        // The slide reached a vertex V of the segment.
        SegmentRef nb;
        if (!neighbour(sc, seg, clamped, &nb)) {  // the open end of a curve: go round it
          state_ = ContactState::Free;
          break;
        }
        const SegGeom gn = geom(sc, nb);
        const Vec2 v = clamped > 0 ? g.b : g.a;
        const Vec2 u_in = clamped > 0 ? g.u : gn.u;
        const Vec2 u_out = clamped > 0 ? gn.u : g.u;
        const double turn = side * cross(u_in, u_out);
        const bool pen_nb = side * dot(gn.n, h - gn.a) < 0.0;
        const double turn_rad = std::atan2(std::fabs(turn), dot(u_in, u_out));  // how sharply the curve turns at V
        if (turn > 0.0) {  // concave on the proxy's side: the two walls hold it
          if (pen_nb) {
            state_ = ContactState::Vertex;
            c_[1] = Constraint{nb, side};
            out.events |= kEventVertexBegin;
            out.corner_turn_rad = std::max(out.corner_turn_rad, turn_rad);
          } else {
            rest = true;
          }
          break;
        }
        // Convex (or straight): step round the corner to the bisector of the two normals, then go on
        // along the next edge if the handle is behind it, or leave it.
        if (turn < 0.0) {
          out.events |= kEventConvexCorner;
          out.corner_turn_rad = std::max(out.corner_turn_rad, turn_rad);
        }
        const Vec2 bis = normalized_or(g.n + gn.n, clamped > 0 ? g.u : -g.u);
        const Move mc = move_to(v + (side * skin) * bis, level_, nullptr, 0, in.budget, out, &hit);
        if (mc == Move::Blocked) {
          rest = true;
          break;
        }
        if (mc == Move::Hit) {
          state_ = ContactState::Edge;
          c_[0] = hit;
          break;
        }
        if (pen_nb) {
          c_[0] = Constraint{nb, side};
        } else {
          state_ = ContactState::Free;
        }
        break;
      }
      case ContactState::Vertex: {
        const SegGeom ga = geom(sc, c_[0].seg);
        const SegGeom gb = geom(sc, c_[1].seg);
        const double sa = c_[0].side, sb = c_[1].side;
        const bool pen_a = sa * dot(ga.n, h - ga.a) < 0.0;
        const bool pen_b = sb * dot(gb.n, h - gb.a) < 0.0;
        if (!pen_a && !pen_b) {
          state_ = ContactState::Free;
        } else if (!pen_a) {
          state_ = ContactState::Edge;
          c_[0] = c_[1];
        } else if (!pen_b) {
          state_ = ContactState::Edge;
        } else {
          // Stable-contact rule (seed §4): sliding along an edge must not lead away from the other wall.
          const Vec2 pull = h - proxy_;
          const double along_a = dot(ga.u, pull), along_b = dot(gb.u, pull);
          const bool a_leaves_b = sb * dot(gb.n, along_a * ga.u) > 0.0;
          const bool b_leaves_a = sa * dot(ga.n, along_b * gb.u) > 0.0;
          if (a_leaves_b && (!b_leaves_a || std::abs(along_a) >= std::abs(along_b))) {
            state_ = ContactState::Edge;
          } else if (b_leaves_a) {
            state_ = ContactState::Edge;
            c_[0] = c_[1];
          } else {
            rest = true;
          }
        }
        break;
      }
    }
  }
  if (!rest) out.events |= kEventIterationLimit;

  // Force: spring from handle to proxy, damping along the contact normal, one clamp.
  Vec2 f = params_.stiffness_n_per_m * (proxy_ - h);
  if (state_ != ContactState::Free && params_.damping_n_s_per_m > 0.0) {
    const SegGeom g = geom(sc, c_[0].seg);
    f -= (params_.damping_n_s_per_m * dot(in.handle_velocity_m_per_s, g.n)) * g.n;
  }
  const double mag = length(f);
  if (mag > params_.max_force_n) f = (params_.max_force_n / mag) * f;
  if (!is_finite(f)) f = Vec2{0.0, 0.0};

  out.proxy_m = proxy_;
  out.force_n = f;
  out.state = state_;
  out.level = -1;
  out.constraint[0] = SegmentRef{};
  out.constraint[1] = SegmentRef{};
  if (state_ != ContactState::Free) {
    out.constraint[0] = c_[0].seg;
    out.level = c_[0].seg.level;
    if (state_ == ContactState::Vertex) out.constraint[1] = c_[1].seg;
  }
  if (before == ContactState::Free && state_ != ContactState::Free) out.events |= kEventContactBegin;
  if (before != ContactState::Free && state_ == ContactState::Free) out.events |= kEventContactEnd;
}

}  // namespace hk
