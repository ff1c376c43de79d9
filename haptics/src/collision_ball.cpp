// The free-space ball of first_hit (seed paper §3, box distances schedule box updates): its test, its walls
// gathered by a full query and answering the sweeps inside it, and its placement after a full query.
#include "collision_query_internal.hpp"

namespace hk {

// The ball's walls (gather_ball_walls) answer a sweep of their level id inside their ball: the first hit among
// them, excluded ones left out, the same answer a full query gives (every wall within the ball is among them;
// ties as test_segment). False, with nothing written, for a sweep they cannot answer. Charges no box test. The
// first sweep inside the ball copies the walls (copy_ball_walls).
bool BoundarySection::Ops::answer_from_ball_walls(BoundarySection& self, Vec2 a, Vec2 b, int level,
                                                  const SegmentRef* excluded, int excluded_count, SweepHit* out,
                                                  QueryStats* stats) noexcept {
  BallWalls& w = self.ball_walls_;
  if (level != w.level) return false;
  const double r_sq = w.radius_sq;
  const Vec2 da = a - w.center_m, db = b - w.center_m;
  if (!(dot(da, da) < r_sq && dot(db, db) < r_sq)) return false;
  if (!w.copied) copy_ball_walls(self);
  // The walls whose rectangle meets the sweep's (the rectangles apart: no common point), as a bit mask, two
  // walls per step (a slot past count meets nothing that counts: the mask drops it).
  const Aabb sweep = rect_of(a, b);
  unsigned meets = 0;
  for (int k = 0; k < w.count; k += 2) {
#if defined(__SSE2__)
    const __m128d lx = _mm_load_pd(w.lo_x + k), ly = _mm_load_pd(w.lo_y + k), hx = _mm_load_pd(w.hi_x + k),
                  hy = _mm_load_pd(w.hi_y + k);
    const __m128d m =
        _mm_and_pd(_mm_and_pd(_mm_cmple_pd(lx, _mm_set1_pd(sweep.hi.x)), _mm_cmple_pd(_mm_set1_pd(sweep.lo.x), hx)),
                   _mm_and_pd(_mm_cmple_pd(ly, _mm_set1_pd(sweep.hi.y)), _mm_cmple_pd(_mm_set1_pd(sweep.lo.y), hy)));
    meets |= static_cast<unsigned>(_mm_movemask_pd(m)) << k;
#else
    for (int i = k; i < k + 2; ++i) {
      meets |= (w.lo_x[i] <= sweep.hi.x && sweep.lo.x <= w.hi_x[i] && w.lo_y[i] <= sweep.hi.y && sweep.lo.y <= w.hi_y[i]
                    ? 1u
                    : 0u)
               << i;
    }
#endif
  }
  meets &= (1u << w.count) - 1u;
  SweepHit best;
  best.t = std::numeric_limits<double>::infinity();
  std::int32_t tested = 0;
  int coarsest = 0;
  for (; meets != 0; meets &= meets - 1) {
    const int k = __builtin_ctz(meets);
    if (is_excluded(w.ref[k], excluded, excluded_count)) continue;
    ++tested;
    coarsest = std::max(coarsest, w.ref[k].level);
    double t = 0.0;
    if (intersect_sweep_segment_inline(a, b, w.p0_m[k], w.p1_m[k], &t) && closer(t, w.ref[k], best.t, best.segment)) {
      best.hit = true;
      best.t = t;
      best.segment = w.ref[k];
    }
  }
  if (best.hit) {
    best.point_m = lerp(a, b, best.t);
  } else {
    best.t = 1.0;
    best.point_m = b;
  }
  if (stats) {
    *stats = QueryStats{};
    stats->segment_tests = tested;
    stats->coarsest_answer_level = coarsest;
    stats->ball_walls = true;
    stats->section_size = static_cast<std::int32_t>(self.section_.size());
  }
  *out = best;
  return true;
}

// Phase 3: the ball's walls, a second free-space ball around the same centre (the end of the sweep) that
// reaches past the nearest boxes: the section entries nearest to it, in order of their rectangles' distance,
// while each is a segment box within kDirectLevels of its walls and all their walls fit in kMaxBallWalls, have
// those walls noted, as runs copied out when first needed (seed §3: coherence; the walls under a box are its
// only walls of the level); the ball's radius is the distance to the nearest entry left out (its box's distance,
// and no more than the next one's rectangle's, which bounds every farther box from below). Every wall of the
// level within that radius is then among those noted, so a later sweep inside the ball is answered exactly by
// them alone (answer_from_ball_walls): near a wall, or sliding along one in contact, where the plain ball is as small
// as the gap to it. Kept only when it reaches farther than the plain ball. Runs before the splits and merges, which
// change the entries in place: it reads them as phase 1 scanned them.
void BoundarySection::Ops::gather_ball_walls(BoundarySection& self, const Query& q) noexcept {
  BallWalls& w = self.ball_walls_;
  w.radius_sq = 0.0;
  w.count = 0;
  w.runs = 0;
  w.copied = false;
  const std::size_t n = q.scanned;
  std::uint32_t unused = 0;
  if (q.nearest_rect >= n || segments_under(self, self.section_[q.nearest_rect], q.level, &unused) == 0)
    return;  // no walls to copy
  // Note the walls of the nearest entries, in order of their rectangles' distance (each taken out of rect_d_sq_ as it
  // is reached, so the next is the nearest left), while they fit (copied when first needed: copy_ball_walls).
  float* d_sq = self.rect_d_sq_.data();
  constexpr double kAllWallsRadius_m = 1.0;  // every entry's walls noted: any radius holds; the workspace is smaller
  double r_sq = kAllWallsRadius_m * kAllWallsRadius_m;
  for (std::size_t e = q.nearest_rect; e < n;) {
    std::uint32_t first = 0;
    const std::uint32_t count =
        w.runs == kBallWallEntries ? 0 : segments_under(self, self.section_[e], q.level, &first);
    d_sq[e] = std::numeric_limits<float>::infinity();
    if (count == 0 || w.count + static_cast<int>(count) > kMaxBallWalls) {
      // The radius: the first entry left out, by its box; every other one is no nearer than the next rectangle.
      r_sq = box_distance_sq(entry_box_at(self, e), q.b);
      const std::size_t next = nearest_rect_left(self, n);
      if (next < n) r_sq = std::min(r_sq, static_cast<double>(d_sq[next]));
      break;
    }
    w.run_first[w.runs] = first;
    w.run_count[w.runs] = count;
    ++w.runs;
    w.count += static_cast<int>(count);
    e = nearest_rect_left(self, n);
  }
  if (w.count == 0 || r_sq <= q.nearest_sq) {
    w.count = 0;
    w.runs = 0;
    return;
  }
  w.center_m = q.b;
  w.radius_sq = r_sq;
  w.level = q.level;
}

// The entry of the nearest rectangle left in rect_d_sq_ (the first of equals; entries taken out are +inf), or n when
// none is left: four entries per SSE instruction, no branch on the data (the scan's groups of four, its padding +inf).
std::size_t BoundarySection::Ops::nearest_rect_left(const BoundarySection& self, std::size_t n) noexcept {
  const float* d_sq = self.rect_d_sq_.data();
  std::size_t nearest = n;
#if defined(__SSE2__)
  NearestOfFours nearest_rect(n);
  for (std::size_t i = 0; i < n; i += kScanLanes) nearest_rect.take(_mm_loadu_ps(d_sq + i));
  nearest = nearest_rect.nearest();
#else
  float best = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    if (d_sq[i] < best) {
      best = d_sq[i];
      nearest = i;
    }
  }
#endif
  return nearest;
}

// The ball's walls noted by gather_ball_walls, copied out: each run's consecutive segments (one level of one
// curve), their end points, rectangles and references, in run order. Reads the scene only here, so a full query
// whose walls ball no later sweep enters leaves their points where they are (on a large scene, seldom cached).
void BoundarySection::Ops::copy_ball_walls(BoundarySection& self) noexcept {
  BallWalls& w = self.ball_walls_;
  const Scene& sc = *self.scene_;
  int k = 0;
  for (int r = 0; r < w.runs; ++r) {
    const NodeInfo in = sc.info(w.run_first[r]);
    for (std::uint32_t i = 0; i < w.run_count[r]; ++i, ++k) {
      sc.segment_points(w.run_first[r] + i, &w.p0_m[k], &w.p1_m[k]);
      const Aabb rect = rect_of(w.p0_m[k], w.p1_m[k]);
      w.lo_x[k] = rect.lo.x;
      w.lo_y[k] = rect.lo.y;
      w.hi_x[k] = rect.hi.x;
      w.hi_y[k] = rect.hi.y;
      w.ref[k] = SegmentRef{static_cast<std::int32_t>(in.curve), in.level, static_cast<std::int32_t>(in.index + i)};
    }
  }
  w.copied = true;
}

// Phase 6: the next free-space ball: the distance from the end of the sweep to the nearest box phase 1
// scanned, even when the section changed since: a split box holds every wall its children hold and merged
// children every wall their parent holds, so the boxes scanned still cover every wall and no wall comes
// nearer than that. (Measuring the changed section again finds the children's boxes, which may be
// farther, but cost more than the slightly larger ball saved: PERFORMANCE.md, round two.) The section needs
// no compaction: splits and merges changed it in place, no node twice (a split puts in children of a node that
// was in, so they were not; a merge a parent it checked was not), a frontier still
// (CollisionQuery.BoundarySectionStaysSmallOnALongWalk checks it).
void BoundarySection::Ops::place_free_ball(BoundarySection& self, const Query& q) noexcept {
  self.ball_center_m_ = q.b;
  self.ball_radius_sq_ = q.nearest_sq;
  self.ball_levels_[0] = q.level;  // the boxes scanned covered the walls of both ids the section served
  self.ball_levels_[1] = self.other_level_;
}

}  // namespace hk
