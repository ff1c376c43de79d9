// Closing small gaps in outlines: close_gaps, in three phases (candidates, greedy joins,
// walks), see gaps.hpp.
#include "vision/gaps.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <tuple>

#include "hk/error.hpp"

namespace hk::vision {
namespace {

/// Ends are numbered 2·chain (its first point) and 2·chain + 1 (its last point).
int chain_of(int end) { return end / 2; }
bool is_start(int end) { return end % 2 == 0; }

const cv::Point2d& end_point(const std::vector<Chain>& chains, int end) {
  const Chain& c = chains[static_cast<std::size_t>(chain_of(end))];
  return is_start(end) ? c.points_px.front() : c.points_px.back();
}

double end_value(const PointValues& values, int end) {
  const std::vector<double>& v = values[static_cast<std::size_t>(chain_of(end))];
  return is_start(end) ? v.front() : v.back();
}

void check_input(const std::vector<Chain>& chains, const GapParams& p, const PointValues& values) {
  if (!std::isfinite(p.max_gap_px) || p.max_gap_px < 0.0)
    throw hk::ArgumentError("close_gaps: max_gap_px must be finite and >= 0, got " + std::to_string(p.max_gap_px));
  if (!(p.max_turn_deg > 0.0 && p.max_turn_deg <= 90.0))
    throw hk::ArgumentError("close_gaps: max_turn_deg must be in (0, 90], got " + std::to_string(p.max_turn_deg));
  if (!(p.direction_span_px > 0.0) || !std::isfinite(p.direction_span_px))
    throw hk::ArgumentError("close_gaps: direction_span_px must be finite and > 0");
  if (!(p.min_piece_px >= 0.0) || !std::isfinite(p.min_piece_px))
    throw hk::ArgumentError("close_gaps: min_piece_px must be finite and >= 0");
  for (const Chain& c : chains)
    if (c.points_px.empty()) throw hk::ArgumentError("close_gaps: a chain has no point");
  if (values.empty()) return;
  if (values.size() != chains.size()) throw hk::ArgumentError("close_gaps: values must have one entry per chain");
  for (std::size_t k = 0; k < chains.size(); ++k)
    if (values[k].size() != chains[k].points_px.size())
      throw hk::ArgumentError("close_gaps: values must have one value per chain point");
}

/// A possible join: its gap [px], how far it turns from the ends' directions (the larger of the two) and
/// its two ends.
struct Candidate {
  double gap_px;
  double turn;
  int a;
  int b;
};

/// Phase 1: every pair of open ends within the gap whose join continues both ends' directions.
std::vector<Candidate> find_candidates(const std::vector<Chain>& chains, const GapParams& p) {
  std::vector<int> ends;
  std::vector<cv::Point2d> dirs;
  std::vector<double> lengths(chains.size(), 0.0);
  for (std::size_t k = 0; k < chains.size(); ++k) {
    const Chain& c = chains[k];
    if (c.closed || c.points_px.size() < 2) continue;
    lengths[k] = chain_length_px(c);  // open: no closing segment
    if (lengths[k] < p.min_piece_px) continue;
    for (const bool start : {true, false}) {
      ends.push_back(2 * static_cast<int>(k) + (start ? 0 : 1));
      dirs.push_back(end_direction(c, start, p.direction_span_px));
    }
  }
  const double min_cos = std::cos(p.max_turn_deg * std::numbers::pi / 180.0);
  std::vector<Candidate> out;
  for (std::size_t i = 0; i < ends.size(); ++i)
    for (std::size_t j = i + 1; j < ends.size(); ++j) {
      const int a = ends[i], b = ends[j];
      const cv::Point2d d = end_point(chains, b) - end_point(chains, a);
      const double gap = cv::norm(d);
      if (gap > p.max_gap_px + 1e-9) continue;  // "up to", rounding aside
      if (chain_of(a) == chain_of(b) && lengths[static_cast<std::size_t>(chain_of(a))] <= 3.0 * gap) continue;
      // How well the join carries on from each end: cosines of the turns at a and at b.
      double ca, cb;
      if (gap < 1e-9) {
        ca = cb = -dirs[i].dot(dirs[j]);  // the same point: the two directions must carry on into each other
      } else {
        const cv::Point2d u = d / gap;
        ca = dirs[i].dot(u);
        cb = -dirs[j].dot(u);
      }
      const double need = gap < 1.5 ? 1e-9 : min_cos;        // adjacent pixels: only not turning back
      if (ca < need - 1e-12 || cb < need - 1e-12) continue;  // "at most max_turn_deg", rounding aside
      out.push_back({gap, 1.0 - std::min(ca, cb), a, b});
    }
  return out;
}

/// Phase 2: shortest gap first (then the straighter join), each end at most once. partner[end] = the end it
/// joins, or -1.
std::vector<int> choose_joins(std::vector<Candidate> cands, std::size_t chain_count, GapStats& stats) {
  std::stable_sort(cands.begin(), cands.end(), [](const Candidate& x, const Candidate& y) {
    return std::tie(x.gap_px, x.turn) < std::tie(y.gap_px, y.turn);
  });
  std::vector<int> partner(2 * chain_count, -1);
  for (const Candidate& c : cands) {
    if (partner[static_cast<std::size_t>(c.a)] >= 0 || partner[static_cast<std::size_t>(c.b)] >= 0) continue;
    partner[static_cast<std::size_t>(c.a)] = c.b;
    partner[static_cast<std::size_t>(c.b)] = c.a;
    ++stats.joins;
  }
  return partner;
}

/// Appends chain k's points (and values) to `out`, forwards or backwards.
void append_chain(const std::vector<Chain>& chains, const PointValues& values, std::size_t k, bool forward, Chain& out,
                  std::vector<double>* vout) {
  const auto& pts = chains[k].points_px;
  const std::size_t n = pts.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t s = forward ? i : n - 1 - i;
    out.points_px.push_back(pts[s]);
    if (vout) vout->push_back(values[k][s]);
  }
}

/// Appends the points strictly between ends `from` and `to` on the straight join, about 1 px apart.
void fill_gap(const std::vector<Chain>& chains, const PointValues& values, int from, int to, Chain& out,
              std::vector<double>* vout) {
  const cv::Point2d a = end_point(chains, from), b = end_point(chains, to);
  const int steps = static_cast<int>(std::ceil(cv::norm(b - a) - 1e-9));
  for (int k = 1; k < steps; ++k) {
    const double t = static_cast<double>(k) / steps;
    out.points_px.push_back(a + t * (b - a));
    if (vout) vout->push_back((1.0 - t) * end_value(values, from) + t * end_value(values, to));
  }
}

/// Phase 3: walks each group of joined chains from its head (an end with no partner, or chain k itself when
/// the group is a ring) into one chain.
void walk_group(const std::vector<Chain>& chains, const PointValues& values, const std::vector<int>& partner,
                std::size_t k, std::vector<char>& used, Chain& out, std::vector<double>* vout, GapStats& stats) {
  // The head: back from chain k's first end until an end with no partner, or round to chain k (a ring).
  int head = 2 * static_cast<int>(k);
  bool ring = false;
  for (int e = head;;) {
    const int q = partner[static_cast<std::size_t>(e)];
    if (q < 0) {
      head = e;
      break;
    }
    if (chain_of(q) == static_cast<int>(k)) {
      ring = true;
      head = 2 * static_cast<int>(k);
      break;
    }
    e = q ^ 1;
  }
  for (int enter = head;;) {
    const auto c = static_cast<std::size_t>(chain_of(enter));
    used[c] = 1;
    append_chain(chains, values, c, is_start(enter), out, vout);
    const int leave = enter ^ 1;
    const int q = partner[static_cast<std::size_t>(leave)];
    if (q < 0) break;
    fill_gap(chains, values, leave, q, out, vout);
    if (used[static_cast<std::size_t>(chain_of(q))]) break;  // back at the head of a ring: its closing join filled
    enter = q;
  }
  out.closed = ring;
  if (ring) ++stats.chains_closed;
}

}  // namespace

cv::Point2d end_direction(const Chain& c, bool at_start, double span_px) {
  const auto& pts = c.points_px;
  const std::size_t n = pts.size();
  if (n < 2) return {0.0, 0.0};
  const cv::Point2d tip = at_start ? pts.front() : pts.back();
  cv::Point2d back = tip;
  double walked = 0.0;
  for (std::size_t i = 1; i < n && walked < span_px; ++i) {
    const cv::Point2d q = at_start ? pts[i] : pts[n - 1 - i];
    walked += cv::norm(q - back);
    back = q;
  }
  const cv::Point2d d = tip - back;
  const double len = cv::norm(d);
  return len > 0.0 ? d / len : cv::Point2d(0.0, 0.0);
}

std::vector<Chain> close_gaps(const std::vector<Chain>& chains, const GapParams& p, GapStats* stats,
                              const PointValues& values, PointValues* values_out) {
  check_input(chains, p, values);
  GapStats st;
  const std::vector<int> partner = choose_joins(find_candidates(chains, p), chains.size(), st);
  const bool with_values = !values.empty() && values_out != nullptr;
  std::vector<Chain> out;
  PointValues vout;
  std::vector<char> used(chains.size(), 0);
  for (std::size_t k = 0; k < chains.size(); ++k) {
    if (used[k]) continue;
    Chain joined;
    std::vector<double> v;
    if (partner[2 * k] < 0 && partner[2 * k + 1] < 0) {
      joined = chains[k];
      if (with_values) v = values[k];
      used[k] = 1;
    } else {
      walk_group(chains, values, partner, k, used, joined, with_values ? &v : nullptr, st);
    }
    out.push_back(std::move(joined));
    if (with_values) vout.push_back(std::move(v));
  }
  if (with_values) *values_out = std::move(vout);
  if (stats) *stats = st;
  return out;
}

}  // namespace hk::vision
