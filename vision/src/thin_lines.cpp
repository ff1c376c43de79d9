// Thin-line merging (see thin_lines.hpp for the algorithm and its reasons).
//
// All points of all chains are flattened into one array ("global index" g) so that a pair may
// join any two chains, and every per-point flag is one vector indexed by g.

#include "vision/thin_lines.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "hk/error.hpp"

namespace hk::vision {
namespace {

constexpr double kCosParallel = 0.8660254037844386;  // tangents within 30 deg of (anti-)parallel
constexpr double kSinNormal = 0.5;                   // the gap within 30 deg of both normals
constexpr double kMinGapPx = 1.0;                    // closer points are the same edge (junction pixels repeat)
constexpr double kMinRunWidths = 2.0;                // a run of pairs must be this many widths long to be a line
constexpr double kMinPiecePx = 2.0;                  // left-over pieces up to this long are Canny crumbs
constexpr double kMinStepPx = 0.2;                   // centre-line points closer than this to the last are dropped
constexpr double kCosJoin = -0.2;                    // a join turns by at most ~100 deg (an L's 90 deg passes)
// A join must stay clear of every edge point by this much: a segment crossing an 8-connected
// pixel chain passes within sqrt(2) / 2 px of one of its pixel centres (+ the 0.25 px sampling),
// while the centre of a stroke lies half the stroke width (>= ~1.5 px after the blur) from them.
constexpr double kJoinClearPx = 0.9;
constexpr double kCosCorner = 0.94;  // a join turning by more than ~20 deg goes through its corner
constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

/// Uniform grid over a fixed point set for radius queries: counting sort of the points by cell,
/// so the structure is flat arrays and queries visit the cells the disc overlaps. The cell is
/// given (the query radius), grown (doubled) only if the points' bounding box would need more
/// than 4 cells per point, so memory stays O(points) whatever the coordinates.
class PointGrid {
 public:
  PointGrid(const std::vector<cv::Point2d>& pts, double cell) {
    if (pts.empty()) return;
    double x1 = pts[0].x;
    double y1 = pts[0].y;
    x0_ = x1;
    y0_ = y1;
    for (const cv::Point2d& p : pts) {
      x0_ = std::min(x0_, p.x);
      y0_ = std::min(y0_, p.y);
      x1 = std::max(x1, p.x);
      y1 = std::max(y1, p.y);
    }
    const double max_cells = 4.0 * static_cast<double>(pts.size()) + 4096.0;
    cell_ = cell;
    while ((std::floor((x1 - x0_) / cell_) + 1.0) * (std::floor((y1 - y0_) / cell_) + 1.0) > max_cells) cell_ *= 2.0;
    nx_ = static_cast<std::size_t>((x1 - x0_) / cell_) + 1;
    ny_ = static_cast<std::size_t>((y1 - y0_) / cell_) + 1;
    start_.assign(nx_ * ny_ + 1, 0);
    std::vector<std::size_t> key(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) {
      key[i] = cell_index(pts[i].y, y0_, ny_) * nx_ + cell_index(pts[i].x, x0_, nx_);
      ++start_[key[i] + 1];
    }
    for (std::size_t c = 0; c + 1 < start_.size(); ++c) start_[c + 1] += start_[c];
    std::vector<std::size_t> fill(start_.begin(), start_.end() - 1);
    order_.resize(pts.size());
    sorted_.resize(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) {
      sorted_[fill[key[i]]] = pts[i];
      order_[fill[key[i]]++] = i;
    }
  }

  /// Calls f(index, squared distance) for every point within r of p (cell order, then index).
  template <typename F>
  void for_each_within(const cv::Point2d& p, double r, F&& f) const {
    if (order_.empty()) return;
    const double r2 = r * r;
    const std::size_t cx0 = cell_index(p.x - r, x0_, nx_);
    const std::size_t cx1 = cell_index(p.x + r, x0_, nx_);
    const std::size_t cy0 = cell_index(p.y - r, y0_, ny_);
    const std::size_t cy1 = cell_index(p.y + r, y0_, ny_);
    for (std::size_t cy = cy0; cy <= cy1; ++cy) {
      for (std::size_t cx = cx0; cx <= cx1; ++cx) {
        const std::size_t c = cy * nx_ + cx;
        for (std::size_t k = start_[c]; k < start_[c + 1]; ++k) {
          const cv::Point2d d = sorted_[k] - p;
          const double d2 = d.dot(d);
          if (d2 <= r2) f(order_[k], d2);
        }
      }
    }
  }

  /// True when some point lies within r of p.
  bool any_within(const cv::Point2d& p, double r) const {
    bool found = false;
    for_each_within(p, r, [&](std::size_t, double) { found = true; });
    return found;
  }

 private:
  std::size_t cell_index(double v, double v0, std::size_t n) const {
    const double c = std::floor((v - v0) / cell_);
    if (!(c > 0.0)) return 0;
    if (c >= static_cast<double>(n - 1)) return n - 1;
    return static_cast<std::size_t>(c);
  }

  double x0_ = 0, y0_ = 0, cell_ = 1;
  std::size_t nx_ = 0, ny_ = 0;
  std::vector<std::size_t> start_;   // points of cell c: order_[start_[c] .. start_[c + 1])
  std::vector<std::size_t> order_;   // point indices by cell
  std::vector<cv::Point2d> sorted_;  // the points in that order (the query loop reads them in sequence)
};

/// A centre line under construction.
struct Piece {
  std::vector<cv::Point2d> pts;
  std::vector<double> vals;
  bool closed = false;
  bool live = true;
};

/// A run of paired points along one chain (step 3).
struct Run {
  std::size_t chain = 0;
  std::vector<std::size_t> members;   // global indices, in walk order
  std::vector<std::size_t> walk_pos;  // position of each member in the chain's walk (monotone)
  bool closed = false;                // the run goes round its whole (closed) chain
  bool kept = false;
};

double polyline_length(const std::vector<cv::Point2d>& pts, bool closed) {
  double l = 0.0;
  for (std::size_t i = 1; i < pts.size(); ++i) l += cv::norm(pts[i] - pts[i - 1]);
  if (closed && pts.size() > 1) l += cv::norm(pts.front() - pts.back());
  return l;
}

/// [1 2 1] / 4 along the piece (cyclic when closed, end points kept when open): removes the
/// zig-zag of midpoints whose partners alternate between two neighbouring pixels.
void smooth(Piece& c) {
  const std::size_t n = c.pts.size();
  if (n < 3) return;
  const std::vector<cv::Point2d> p = c.pts;
  for (std::size_t i = 0; i < n; ++i) {
    if (!c.closed && (i == 0 || i + 1 == n)) continue;
    const cv::Point2d& a = p[(i + n - 1) % n];
    const cv::Point2d& b = p[(i + 1) % n];
    c.pts[i] = 0.25 * a + 0.5 * p[i] + 0.25 * b;
  }
}

/// Drops points closer than kMinStepPx to the previous kept point (and, closed, to the first).
void drop_close_points(Piece& c) {
  std::vector<cv::Point2d> pts;
  std::vector<double> vals;
  for (std::size_t i = 0; i < c.pts.size(); ++i) {
    if (!pts.empty() && cv::norm(c.pts[i] - pts.back()) < kMinStepPx) continue;
    pts.push_back(c.pts[i]);
    vals.push_back(c.vals[i]);
  }
  if (c.closed && pts.size() > 1 && cv::norm(pts.back() - pts.front()) < kMinStepPx) {
    pts.pop_back();
    vals.pop_back();
  }
  if (c.closed && pts.size() < 3) c.closed = false;
  c.pts = std::move(pts);
  c.vals = std::move(vals);
}

std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// Every point of every chain in one array (global index g): position, tangent over ±h points, chain, index
/// in its chain, arc length from the chain's start; per chain its offset, length and closedness.
struct Flat {
  std::size_t K = 0, N = 0;
  std::vector<std::size_t> off;  // points of chain k: g in [off[k], off[k + 1])
  std::vector<cv::Point2d> pos, tan;
  std::vector<std::size_t> chain_of, idx;
  std::vector<double> arc, length;
  std::vector<char> closed;
};

/// Checks the input (throws hk::ArgumentError) and flattens it (step 1).
Flat flatten(const std::vector<Chain>& chains, double w, const PointValues* values_in) {
  if (!std::isfinite(w) || w < 0.0) {
    throw hk::ArgumentError("merge_thin_lines: max_width_px must be finite and >= 0, got " + number(w));
  }
  if (values_in != nullptr) {
    bool ok = values_in->size() == chains.size();
    for (std::size_t k = 0; ok && k < chains.size(); ++k) ok = (*values_in)[k].size() == chains[k].points_px.size();
    if (!ok) throw hk::ArgumentError("merge_thin_lines: values_in must have one value per chain point");
  }
  Flat f;
  f.K = chains.size();
  f.off.assign(f.K + 1, 0);
  for (std::size_t k = 0; k < f.K; ++k) {
    for (const cv::Point2d& p : chains[k].points_px) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
        throw hk::ArgumentError("merge_thin_lines: chain " + std::to_string(k) + " has a non-finite point");
      }
    }
    f.off[k + 1] = f.off[k] + chains[k].points_px.size();
  }
  f.N = f.off[f.K];
  if (w == 0.0 || f.N == 0) return f;
  f.pos.resize(f.N);
  f.tan.resize(f.N);
  f.chain_of.resize(f.N);
  f.idx.resize(f.N);
  f.arc.resize(f.N);
  f.length.resize(f.K);
  f.closed.resize(f.K);
  const long h = std::clamp(std::lround(w / 2.0), 2L, 4L);
  for (std::size_t k = 0; k < f.K; ++k) {
    const auto& p = chains[k].points_px;
    const std::size_t n = p.size();
    f.closed[k] = chains[k].closed && n >= 3;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t g = f.off[k] + i;
      f.pos[g] = p[i];
      f.chain_of[g] = k;
      f.idx[g] = i;
      f.arc[g] = i == 0 ? 0.0 : f.arc[g - 1] + cv::norm(p[i] - p[i - 1]);
      long a = static_cast<long>(i) - h;
      long b = static_cast<long>(i) + h;
      const long nl = static_cast<long>(n);
      if (f.closed[k]) {
        a = ((a % nl) + nl) % nl;
        b %= nl;
      } else {
        a = std::max(a, 0L);
        b = std::min(b, nl - 1);
      }
      const cv::Point2d t = p[static_cast<std::size_t>(b)] - p[static_cast<std::size_t>(a)];
      const double tn = cv::norm(t);
      f.tan[g] = tn > 1e-12 ? t / tn : cv::Point2d(0, 0);  // a zero tangent pairs with nothing
    }
    f.length[k] = n == 0 ? 0.0 : f.arc[f.off[k] + n - 1] + (f.closed[k] ? cv::norm(p.back() - p.front()) : 0.0);
  }
  return f;
}

/// Step 2: each point's partner, the nearest facing point across a gap of at most w (kNone: none).
std::vector<std::size_t> find_partners(const Flat& f, const PointGrid& grid, double w) {
  std::vector<std::size_t> partner(f.N, kNone);
  for (std::size_t g = 0; g < f.N; ++g) {
    std::size_t best = kNone;
    double best_d2 = std::numeric_limits<double>::infinity();
    grid.for_each_within(f.pos[g], w, [&](std::size_t q, double d2) {
      if (q == g || d2 < kMinGapPx * kMinGapPx) return;
      if (d2 > best_d2 || (d2 == best_d2 && q > best)) return;  // cannot beat the best
      // Most candidates are p's neighbours along its own edge: the gap-along-the-tangent test,
      // squared (no root), rejects them first.
      const cv::Point2d r = f.pos[q] - f.pos[g];
      const double along_g = r.dot(f.tan[g]);
      if (along_g * along_g > kSinNormal * kSinNormal * d2) return;
      if (std::abs(f.tan[g].dot(f.tan[q])) < kCosParallel) return;
      const double along_q = r.dot(f.tan[q]);
      if (along_q * along_q > kSinNormal * kSinNormal * d2) return;
      if (f.chain_of[q] == f.chain_of[g]) {
        const double d = std::sqrt(d2);
        double sep = std::abs(f.arc[q] - f.arc[g]);
        if (f.closed[f.chain_of[g]]) sep = std::min(sep, f.length[f.chain_of[g]] - sep);
        if (sep < std::max(1.5 * d, d + 2.0)) return;  // its own neighbourhood, not a facing side
      }
      best = q;
      best_d2 = d2;
    });
    partner[g] = best;
  }
  return partner;
}

/// Signed index step from i to j on chain k, the short way round a closed chain.
long index_step(const Flat& f, std::size_t k, std::size_t i, std::size_t j) {
  long d = static_cast<long>(j) - static_cast<long>(i);
  if (f.closed[k]) {
    const long n = static_cast<long>(f.off[k + 1] - f.off[k]);
    d = ((d % n) + n) % n;
    if (d > n / 2) d -= n;
  }
  return d;
}

/// Whether the partners of consecutive run points g0 and g1 (walk `steps` apart) follow each other: on one
/// chain and moving on slowly; a leap is another stroke.
bool partners_follow(const Flat& f, const std::vector<std::size_t>& partner, std::size_t g0, std::size_t g1,
                     std::size_t steps) {
  const std::size_t q0 = partner[g0];
  const std::size_t q1 = partner[g1];
  if (f.chain_of[q0] != f.chain_of[q1]) return false;
  return std::labs(index_step(f, f.chain_of[q0], f.idx[q0], f.idx[q1])) <= 2 * static_cast<long>(steps) + 3;
}

/// The runs found so far, and for each point the run it is in and the run its partner is in (kNone: none).
struct RunWalk {
  std::vector<Run> runs;
  std::vector<std::size_t> run_of, partner_of_run;
};

/// Where the walk of chain k (n points) starts: a closed chain's at an unpaired point, so that no run is cut
/// at index 0; an open chain's at 0.
std::size_t walk_start(const Flat& f, const std::vector<std::size_t>& partner, std::size_t k, std::size_t n) {
  if (!f.closed[k]) return 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (partner[f.off[k] + i] == kNone) return i;
  }
  return 0;
}

/// Walks chain k (n points) from `start`, extending the current run with each paired point while at most
/// max_skip points were skipped, the partners follow and the walk did not fold, else starting a new run.
void walk_chain(const Flat& f, const std::vector<std::size_t>& partner, std::size_t k, std::size_t n, std::size_t start,
                std::size_t max_skip, RunWalk& rw) {
  std::vector<Run>& runs = rw.runs;
  std::size_t cur = kNone;
  for (std::size_t t = 0; t < n; ++t) {
    const std::size_t g = f.off[k] + (start + t) % n;
    if (partner[g] == kNone) continue;
    bool extend = false;
    if (cur != kNone) {
      const Run& r = runs[cur];
      const std::size_t steps = t - r.walk_pos.back();
      // The fold test: g's partner already in this run, or g the partner of one of its points,
      // means the walk went round a stroke's end and came back along its other side.
      extend = steps - 1 <= max_skip && partners_follow(f, partner, r.members.back(), g, steps) &&
               rw.run_of[partner[g]] != cur && rw.partner_of_run[g] != cur;
    }
    if (!extend) {
      cur = runs.size();
      runs.push_back(Run{});
      runs[cur].chain = k;
    }
    runs[cur].members.push_back(g);
    runs[cur].walk_pos.push_back(t);
    rw.run_of[g] = cur;
    rw.partner_of_run[partner[g]] = cur;
  }
}

/// Closed chain k (n points), whose runs start at first_run: the last run may go on across the walk's start
/// into the first (then the first's points move to the last), or be the first itself going round the whole
/// chain (then it is marked closed); not when the two runs are a fold of one stroke.
void join_across_start(const Flat& f, const std::vector<std::size_t>& partner, std::size_t n, std::size_t first_run,
                       std::size_t max_skip, RunWalk& rw) {
  std::vector<Run>& runs = rw.runs;
  Run& first = runs[first_run];
  Run& last = runs.back();
  const std::size_t steps = first.walk_pos.front() + n - last.walk_pos.back();
  if (steps - 1 > max_skip || !partners_follow(f, partner, last.members.back(), first.members.front(), steps)) return;
  if (&first == &last) {
    first.closed = true;
    return;
  }
  const std::size_t last_id = runs.size() - 1;
  bool fold = false;
  for (const std::size_t g : first.members) fold = fold || rw.run_of[partner[g]] == last_id;
  for (const std::size_t g : last.members) fold = fold || rw.run_of[partner[g]] == first_run;
  if (fold) return;
  for (std::size_t j = 0; j < first.members.size(); ++j) {
    last.members.push_back(first.members[j]);
    last.walk_pos.push_back(first.walk_pos[j] + n);
    rw.run_of[first.members[j]] = last_id;
  }
  first.members.clear();
  first.walk_pos.clear();
}

/// Marks `kept` the runs (of 2 points or more) whose length along their chain is at least kMinRunWidths × w;
/// shorter ones are corners and crossings.
void mark_kept_runs(const Flat& f, std::vector<Run>& runs, double w) {
  for (Run& r : runs) {
    if (r.members.size() < 2) continue;
    double len = 0.0;
    if (r.closed) {
      len = f.length[r.chain];
    } else {
      for (std::size_t j = 1; j < r.members.size(); ++j) {
        const double a0 = f.arc[r.members[j - 1]];
        const double a1 = f.arc[r.members[j]];
        len += a1 >= a0 ? a1 - a0 : a1 + f.length[r.chain] - a0;  // across the start of a closed chain
      }
    }
    r.kept = len >= kMinRunWidths * w;
  }
}

/// Step 3: runs of paired points along each chain; `kept` marks those long enough to be lines (short runs
/// are corners and crossings).
std::vector<Run> find_runs(const Flat& f, const std::vector<std::size_t>& partner, double w) {
  const std::size_t max_skip = std::max<std::size_t>(2, static_cast<std::size_t>(std::ceil(w / 2.0)));
  RunWalk rw{{}, std::vector<std::size_t>(f.N, kNone), std::vector<std::size_t>(f.N, kNone)};
  for (std::size_t k = 0; k < f.K; ++k) {
    const std::size_t n = f.off[k + 1] - f.off[k];
    if (n == 0) continue;
    const std::size_t first_run = rw.runs.size();
    walk_chain(f, partner, k, n, walk_start(f, partner, k, n), max_skip, rw);
    if (f.closed[k] && rw.runs.size() != first_run) join_across_start(f, partner, n, first_run, max_skip, rw);
  }
  mark_kept_runs(f, rw.runs, w);
  return std::move(rw.runs);
}

/// The value of chain k's point i, 0 without values.
double value_at(const PointValues* values_in, std::size_t k, std::size_t i) {
  return values_in != nullptr ? (*values_in)[k][i] : 0.0;
}

/// Marks what run r stands for as covered: its points, their partners, the unpaired points skipped between
/// run points and the partner-side points between consecutive partners.
void cover_run(const Flat& f, const std::vector<std::size_t>& partner, const Run& r, std::vector<char>& covered) {
  const std::size_t m = r.members.size();
  for (std::size_t j = 0; j < m; ++j) {
    covered[r.members[j]] = 1;
    covered[partner[r.members[j]]] = 1;
  }
  const std::size_t n_own = f.off[r.chain + 1] - f.off[r.chain];
  for (std::size_t j = 1; j <= m; ++j) {
    if (j == m && !r.closed) break;
    const std::size_t g0 = r.members[j - 1];
    const std::size_t g1 = r.members[j % m];
    const std::size_t steps = j < m ? r.walk_pos[j] - r.walk_pos[j - 1] : r.walk_pos[0] + n_own - r.walk_pos[m - 1];
    for (std::size_t s = 1; s < steps; ++s) covered[f.off[r.chain] + (f.idx[g0] + s) % n_own] = 1;
    const std::size_t q0 = partner[g0];
    const std::size_t c = f.chain_of[q0];
    const long d = index_step(f, c, f.idx[q0], f.idx[partner[g1]]);
    const long n_c = static_cast<long>(f.off[c + 1] - f.off[c]);
    for (long s = 1; s < std::labs(d); ++s) {
      const long i = static_cast<long>(f.idx[q0]) + (d > 0 ? s : -s);
      covered[f.off[c] + static_cast<std::size_t>(((i % n_c) + n_c) % n_c)] = 1;
    }
  }
}

/// Step 4: centre lines from the kept runs' fresh points (midpoints of each point and its partner, values
/// averaged), smoothed; what each run stands for is marked in `covered`.
std::vector<Piece> build_centre_lines(const Flat& f, const std::vector<std::size_t>& partner,
                                      const std::vector<Run>& runs, const PointValues* values_in,
                                      std::vector<char>& covered) {
  std::vector<Piece> centre;
  for (const Run& r : runs) {
    if (!r.kept) continue;
    const std::size_t m = r.members.size();
    std::vector<char> fresh(m);
    bool all_fresh = true;
    for (std::size_t j = 0; j < m; ++j) {
      fresh[j] = !covered[r.members[j]] && !covered[partner[r.members[j]]];
      all_fresh = all_fresh && fresh[j];
    }
    const auto midpoint = [&](std::size_t j, Piece& c) {
      const std::size_t g = r.members[j];
      const std::size_t q = partner[g];
      c.pts.push_back(0.5 * (f.pos[g] + f.pos[q]));
      c.vals.push_back(0.5 *
                       (value_at(values_in, f.chain_of[g], f.idx[g]) + value_at(values_in, f.chain_of[q], f.idx[q])));
    };
    if (r.closed && all_fresh) {
      Piece c;
      c.closed = true;
      for (std::size_t j = 0; j < m; ++j) midpoint(j, c);
      centre.push_back(std::move(c));
    } else {
      std::size_t s = 0;
      if (r.closed) {
        while (fresh[s]) ++s;  // start at a covered point, so no piece is cut at the run's start
      }
      Piece c;
      for (std::size_t t = 0; t <= m; ++t) {
        const std::size_t j = (s + t) % m;
        if (t < m && fresh[j]) {
          midpoint(j, c);
          continue;
        }
        if (c.pts.size() >= 2) centre.push_back(std::move(c));
        c = Piece{};
      }
    }
    cover_run(f, partner, r, covered);
  }
  for (Piece& c : centre) {
    smooth(c);
    drop_close_points(c);
  }
  return centre;
}

/// A centre line's end, for joining.
struct End {
  std::size_t piece;
  bool back;
  cv::Point2d at;
  cv::Point2d out;  // unit direction leaving the piece through this end
};

/// The open centre lines' ends, each with the direction it leaves by (over up to w, or half the line).
std::vector<End> open_ends(const std::vector<Piece>& centre, double w) {
  std::vector<End> ends;
  for (std::size_t c = 0; c < centre.size(); ++c) {
    const Piece& pc = centre[c];
    if (!pc.live || pc.closed || pc.pts.size() < 2) continue;
    const double reach = std::min(w, 0.5 * polyline_length(pc.pts, false));
    for (const bool back : {false, true}) {
      const std::size_t n = pc.pts.size();
      const auto at = [&](std::size_t i) { return back ? pc.pts[n - 1 - i] : pc.pts[i]; };
      std::size_t i = 1;
      double walked = cv::norm(at(1) - at(0));
      while (walked < reach && i + 1 < n) {
        walked += cv::norm(at(i + 1) - at(i));
        ++i;
      }
      const cv::Point2d d = at(0) - at(i);
      const double dn = cv::norm(d);
      ends.push_back({c, back, at(0), dn > 0 ? d / dn : cv::Point2d(0, 0)});
    }
  }
  return ends;
}

/// The path of a join: through the point where the two ends' rays meet when the stroke turns (an L's centre
/// line has its corner there; the chord would cut it), else the chord. Empty when neither stays clear of
/// every edge point (`grid`: all input points).
std::vector<cv::Point2d> join_path(const End& ea, const End& eb, const PointGrid& grid, double join_r) {
  std::vector<std::vector<cv::Point2d>> tries;
  const double det = ea.out.x * (-eb.out.y) - ea.out.y * (-eb.out.x);  // ea + t out_a = eb + u out_b
  if (ea.out.dot(-eb.out) < kCosCorner && std::abs(det) > 1e-9) {
    const cv::Point2d r = eb.at - ea.at;
    const double t = (r.x * (-eb.out.y) - r.y * (-eb.out.x)) / det;
    const double u = (ea.out.x * r.y - ea.out.y * r.x) / det;
    if (t > 0.0 && u > 0.0 && t <= join_r && u <= join_r) tries.push_back({ea.at, ea.at + t * ea.out, eb.at});
  }
  tries.push_back({ea.at, eb.at});
  for (const auto& path : tries) {
    bool clear = true;
    for (std::size_t k = 1; clear && k < path.size(); ++k) {
      const int parts = static_cast<int>(std::ceil(cv::norm(path[k] - path[k - 1]) / 0.25));
      for (int i = 0; clear && i <= parts; ++i) {
        const cv::Point2d p =
            path[k - 1] + (path[k] - path[k - 1]) * (parts > 0 ? static_cast<double>(i) / parts : 0.0);
        clear = !grid.any_within(p, kJoinClearPx);
      }
    }
    if (clear) return path;
  }
  return {};
}

/// Each end's best partner end for a join (kNone: none): within join_r, the smallest turn, the joining
/// segment not doubling back and its path clear of the edges.
std::vector<std::size_t> best_joins(const std::vector<End>& ends, const std::vector<Piece>& centre,
                                    const PointGrid& grid, double join_r) {
  std::vector<cv::Point2d> end_pts;
  for (const End& e : ends) end_pts.push_back(e.at);
  const PointGrid end_grid(end_pts, join_r);
  std::vector<std::size_t> best(ends.size(), kNone);
  for (std::size_t a = 0; a < ends.size(); ++a) {
    double best_score = -std::numeric_limits<double>::infinity();
    end_grid.for_each_within(ends[a].at, join_r, [&](std::size_t b, double d2) {
      if (b == a) return;
      const End& ea = ends[a];
      const End& eb = ends[b];
      if (ea.piece == eb.piece && polyline_length(centre[ea.piece].pts, false) < 3.0 * join_r) return;
      const double score = ea.out.dot(-eb.out);
      if (score < kCosJoin) return;
      if (d2 > 0.25) {  // the joining segment must not double back either
        const cv::Point2d s = (eb.at - ea.at) / std::sqrt(d2);
        if (s.dot(ea.out) < kCosJoin || s.dot(-eb.out) < kCosJoin) return;
      }
      if (!(score > best_score || (score == best_score && b < best[a]))) return;
      // ... nor cross an edge: a continuation runs inside the stroke (through a corner or a
      // crossing); a path leaving it would bridge two strokes across the background.
      if (join_path(ea, eb, grid, join_r).empty()) return;
      best_score = score;
      best[a] = b;
    });
  }
  return best;
}

/// Joins the pieces of ends a and b (mutual best) along `path`: A ends at the join, B starts there; one piece
/// joined to itself closes.
void join_pieces(std::vector<Piece>& centre, const End& ea, const End& eb, const std::vector<cv::Point2d>& path) {
  Piece& A = centre[ea.piece];
  if (!ea.back) {  // A must end at the join ...
    std::reverse(A.pts.begin(), A.pts.end());
    std::reverse(A.vals.begin(), A.vals.end());
  }
  const double v_end = A.vals.back();
  if (ea.piece == eb.piece) {
    if (path.size() == 3) {
      A.pts.push_back(path[1]);
      A.vals.push_back(0.5 * (v_end + A.vals.front()));
    }
    A.closed = true;
    drop_close_points(A);
    return;
  }
  Piece& B = centre[eb.piece];
  if (eb.back) {  // ... and B start there
    std::reverse(B.pts.begin(), B.pts.end());
    std::reverse(B.vals.begin(), B.vals.end());
  }
  if (path.size() == 3) {
    A.pts.push_back(path[1]);
    A.vals.push_back(0.5 * (v_end + B.vals.front()));
  }
  A.pts.insert(A.pts.end(), B.pts.begin(), B.pts.end());
  A.vals.insert(A.vals.end(), B.vals.begin(), B.vals.end());
  B = Piece{};
  B.live = false;
  drop_close_points(A);
}

/// Step 5: joins centre-line ends that continue each other (mutual best, smallest turn), round after round
/// until no join is left; returns the live lines.
std::vector<Piece> join_centre_lines(std::vector<Piece> centre, const PointGrid& grid, double w) {
  const double join_r = 2.0 * w + 2.0;
  for (bool joined = true; joined;) {
    joined = false;
    const std::vector<End> ends = open_ends(centre, w);
    if (ends.size() < 2) break;
    const std::vector<std::size_t> best = best_joins(ends, centre, grid, join_r);
    std::vector<char> touched(centre.size(), 0);
    for (std::size_t a = 0; a < ends.size(); ++a) {
      const std::size_t b = best[a];
      if (b == kNone || b < a || best[b] != a) continue;
      if (touched[ends[a].piece] || touched[ends[b].piece]) continue;  // this round's other join moved its ends
      touched[ends[a].piece] = touched[ends[b].piece] = 1;
      joined = true;
      join_pieces(centre, ends[a], ends[b], join_path(ends[a], ends[b], grid, join_r));
    }
  }
  std::vector<Piece> lines;
  for (Piece& c : centre) {
    if (c.live && c.pts.size() >= 2) lines.push_back(std::move(c));
  }
  return lines;
}

/// Step 6: the chains' points no run covered (untouched chains whole, the rest cut into pieces trimmed where
/// they run into a centre line, crumbs dropped), then the centre lines; values alongside.
std::vector<Chain> assemble(const std::vector<Chain>& chains, const Flat& f, const std::vector<char>& covered,
                            std::vector<Piece> lines, double w, const PointValues* values_in, PointValues& vals_out,
                            ThinLineStats& st) {
  std::vector<cv::Point2d> samples;  // centre lines sampled at <= 0.5 px
  for (const Piece& c : lines) {
    const std::size_t n = c.pts.size();
    for (std::size_t i = 0; i < n; ++i) {
      samples.push_back(c.pts[i]);
      if (i + 1 == n && !c.closed) break;
      const cv::Point2d a = c.pts[i];
      const cv::Point2d b = c.pts[(i + 1) % n];
      const int parts = static_cast<int>(std::ceil(cv::norm(b - a) / 0.5));
      for (int s = 1; s < parts; ++s) samples.push_back(a + (b - a) * (static_cast<double>(s) / parts));
    }
  }
  const PointGrid near_lines(samples, w);
  std::vector<Chain> out;
  for (std::size_t k = 0; k < f.K; ++k) {
    const std::size_t n = chains[k].points_px.size();
    bool touched = false;
    for (std::size_t i = 0; i < n && !touched; ++i) touched = covered[f.off[k] + i] != 0;
    if (!touched) {
      out.push_back(chains[k]);
      vals_out.push_back(values_in != nullptr ? (*values_in)[k] : std::vector<double>(n, 0.0));
      continue;
    }
    std::size_t s = 0;
    if (f.closed[k]) {
      while (!covered[f.off[k] + s]) ++s;  // start at a covered point: pieces are never cut at 0
    }
    std::vector<std::size_t> piece;
    for (std::size_t t = 0; t <= n; ++t) {
      const std::size_t i = (s + t) % n;
      if (t < n && !covered[f.off[k] + i]) {
        piece.push_back(i);
        continue;
      }
      std::size_t a = 0;
      std::size_t b = piece.size();
      while (a < b && near_lines.any_within(f.pos[f.off[k] + piece[a]], w)) ++a;
      while (b > a && near_lines.any_within(f.pos[f.off[k] + piece[b - 1]], w)) --b;
      Chain c;
      std::vector<double> v;
      for (std::size_t j = a; j < b; ++j) {
        c.points_px.push_back(f.pos[f.off[k] + piece[j]]);
        v.push_back(value_at(values_in, k, piece[j]));
      }
      if (c.points_px.size() >= 2 && polyline_length(c.points_px, false) > kMinPiecePx) {
        out.push_back(std::move(c));
        vals_out.push_back(std::move(v));
      }
      piece.clear();
    }
  }
  for (Piece& c : lines) {
    Chain ch;
    ch.points_px = std::move(c.pts);
    ch.closed = c.closed;
    out.push_back(std::move(ch));
    vals_out.push_back(std::move(c.vals));
    ++st.pairs_merged;
  }
  return out;
}

/// merge_thin_lines, phase by phase (thin_lines.hpp's steps).
std::vector<Chain> merge(const std::vector<Chain>& chains, double w, ThinLineStats* stats, const PointValues* values_in,
                         PointValues* values_out) {
  const Flat f = flatten(chains, w, values_in);
  ThinLineStats st;
  st.points_in = f.N;
  if (w == 0.0 || f.N == 0) {
    st.points_out = f.N;
    if (stats != nullptr) *stats = st;
    if (values_out != nullptr) *values_out = values_in != nullptr ? *values_in : PointValues(f.K);
    return chains;
  }
  const PointGrid grid(f.pos, w);  // all input points: partners (step 2) and the joins' clearance (step 5)
  const std::vector<std::size_t> partner = find_partners(f, grid, w);
  const std::vector<Run> runs = find_runs(f, partner, w);
  std::vector<char> covered(f.N, 0);
  std::vector<Piece> lines = join_centre_lines(build_centre_lines(f, partner, runs, values_in, covered), grid, w);
  PointValues vals_out;
  std::vector<Chain> out = assemble(chains, f, covered, std::move(lines), w, values_in, vals_out, st);
  for (const Chain& c : out) st.points_out += c.points_px.size();
  if (stats != nullptr) *stats = st;
  if (values_out != nullptr) *values_out = std::move(vals_out);
  return out;
}

}  // namespace

std::vector<Chain> merge_thin_lines(const std::vector<Chain>& chains, double max_width_px, ThinLineStats* stats) {
  return merge(chains, max_width_px, stats, nullptr, nullptr);
}

std::vector<Chain> merge_thin_lines(const std::vector<Chain>& chains, double max_width_px, ThinLineStats* stats,
                                    const PointValues& values_in, PointValues* values_out) {
  return merge(chains, max_width_px, stats, &values_in, values_out);
}

}  // namespace hk::vision
