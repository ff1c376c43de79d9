#pragma once
// Reference edge linker for the vision tests: the first, straightforward implementation of the
// algorithm of link_edges (linking.hpp), kept unchanged as an oracle. It scans the whole padded
// grid in every pass, keeps each segment in its own vector and pairs junction ends through a
// full-size lookup grid - slow, but simple enough to read against the specification. The
// optimised link_edges must give exactly the same chains (test_reference.cpp).

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "vision/linking.hpp"

namespace hk::vision::test::reference {
namespace detail {

//                                 E  SE  S  SW   W  NW   N  NE
constexpr std::array<int, 8> kDx = {1, 1, 0, -1, -1, -1, 0, 1};
constexpr std::array<int, 8> kDy = {0, 1, 1, 1, 0, -1, -1, -1};

constexpr int opposite(int d) { return (d + 4) & 7; }

// Segments shorter than these are Canny artefacts at corners, not shape (a few pixels are a
// fraction of a millimetre on the device); they must not cut a boundary into pieces.
constexpr double kSpurPx = 3.0;      // a branch from a junction to a free end
constexpr double kShortPx = 3.0;     // one of several branches joining the same two junctions
constexpr double kTinyLoopPx = 5.0;  // a loop from a junction back to itself (a 2x2 block)

class Linker {
 public:
  explicit Linker(const cv::Mat& edges)
      : w_(edges.cols),
        h_(edges.rows),
        stride_(edges.cols + 2),
        set_(static_cast<std::size_t>(stride_) * (h_ + 2), 0),
        adj_(set_.size(), 0),
        used_(set_.size(), 0) {
    for (int d = 0; d < 8; ++d) off_[d] = kDy[d] * stride_ + kDx[d];
    for (int y = 0; y < h_; ++y) {
      const std::uint8_t* row = edges.ptr<std::uint8_t>(y);
      for (int x = 0; x < w_; ++x) set_[index(x, y)] = row[x] != 0 ? 1 : 0;
    }
    thin_l_corners();
    build_adjacency();
  }

  std::vector<Chain> run(double min_length_px) {
    trace_all();
    mark_minor_segments();
    link_segments_at_junctions();
    std::vector<Found> found = assemble();
    std::stable_sort(found.begin(), found.end(), [](const Found& a, const Found& b) { return a.first < b.first; });
    std::vector<Chain> chains;
    chains.reserve(found.size());
    for (Found& f : found) {
      if (chain_length_px(f.chain) >= min_length_px) chains.push_back(std::move(f.chain));
    }
    return chains;
  }

 private:
  /// A maximal run of links between pixels of degree != 2 (or a cycle of degree-2 pixels).
  struct Segment {
    std::vector<std::size_t> pix;  // ordered pixel indices; a loop from a junction back to
                                   // itself repeats the junction at the end
    bool cycle = false;            // a cycle without junctions (pix does not repeat)
    bool minor = false;            // a corner artefact, kept as its own chain (see kSpurPx)
    double length = 0.0;           // polyline length [px]
  };
  struct Found {
    std::size_t first;  // raster index of the first point, for the output order
    Chain chain;
  };

  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y + 1) * static_cast<std::size_t>(stride_) + static_cast<std::size_t>(x + 1);
  }
  cv::Point2d point(std::size_t i) const {
    const auto s = static_cast<std::size_t>(stride_);
    return {static_cast<double>(i % s) - 1.0, static_cast<double>(i / s) - 1.0};
  }
  std::size_t step(std::size_t p, int d) const {
    return static_cast<std::size_t>(static_cast<std::ptrdiff_t>(p) + off_[d]);
  }
  int degree(std::size_t p) const { return std::popcount(adj_[p]); }

  /// Removes, in raster order, the redundant corner pixel of each step of a staircase: a pixel
  /// whose only 4-neighbours are two perpendicular ones a = p + u and b = p + v, with the inner
  /// corner p - u - v empty and a side diagonal p + u - v or p + v - u set (the curve turns back
  /// to its heading right after the step; a true right-angle corner has neither and is kept).
  /// a and b stay 8-adjacent and every other neighbour of p is 4-adjacent to a or b, so
  /// connectivity is kept. Canny's 4-connected staircases thus become 8-connected diagonals,
  /// which are shorter (a 45-degree run of n steps is n*sqrt2 long, not 2n) and smoother to touch.
  void thin_l_corners() {
    for (int y = 0; y < h_; ++y) {
      for (int x = 0; x < w_; ++x) {
        const std::size_t p = index(x, y);
        if (!set_[p]) continue;
        if (set_[step(p, 0)] + set_[step(p, 2)] + set_[step(p, 4)] + set_[step(p, 6)] != 2) continue;
        for (int d = 0; d < 8; d += 2) {  // u = direction d, v = direction d + 2 (perpendicular)
          if (!set_[step(p, d)] || !set_[step(p, (d + 2) & 7)]) continue;
          const bool inner_empty = !set_[step(p, (d + 5) & 7)];                            // p - u - v
          const bool side_set = set_[step(p, (d + 7) & 7)] || set_[step(p, (d + 3) & 7)];  // p + u - v, p - u + v
          if (inner_empty && side_set) set_[p] = 0;
          break;
        }
      }
    }
  }

  /// 4-neighbours always link; a diagonal neighbour links only if neither pixel 4-adjacent to
  /// both is set (otherwise the path through that pixel already connects them: an L-corner).
  void build_adjacency() {
    for (int y = 0; y < h_; ++y) {
      for (int x = 0; x < w_; ++x) {
        const std::size_t p = index(x, y);
        if (!set_[p]) continue;
        std::uint8_t mask = 0;
        for (int d = 0; d < 8; ++d) {
          if (!set_[step(p, d)]) continue;
          if (d % 2 == 1) {  // diagonal: its two flanking 4-directions are d - 1 and d + 1
            if (set_[step(p, (d + 7) & 7)] || set_[step(p, (d + 1) & 7)]) continue;
          }
          mask = static_cast<std::uint8_t>(mask | (1U << d));
        }
        adj_[p] = mask;
      }
    }
  }

  void mark(std::size_t p, int d) {
    used_[p] = static_cast<std::uint8_t>(used_[p] | (1U << d));
    const std::size_t q = step(p, d);
    used_[q] = static_cast<std::uint8_t>(used_[q] | (1U << opposite(d)));
  }

  /// Walks from `start` along link d through degree-2 pixels until a pixel of another degree or
  /// `start` itself is reached (then `start` is appended again).
  Segment trace(std::size_t start, int d) {
    Segment s;
    s.pix.push_back(start);
    std::size_t cur = start;
    for (;;) {
      mark(cur, d);
      cur = step(cur, d);
      s.pix.push_back(cur);
      if (cur == start || degree(cur) != 2) break;
      const std::uint8_t free = adj_[cur] & ~used_[cur];
      if (free == 0) break;  // unreachable for degree 2: only the incoming link is used
      d = std::countr_zero(free);
    }
    s.length = polyline_length(s.pix, false);
    return s;
  }

  double polyline_length(const std::vector<std::size_t>& pix, bool closed) const {
    double len = 0.0;
    for (std::size_t i = 1; i < pix.size(); ++i) len += cv::norm(point(pix[i]) - point(pix[i - 1]));
    if (closed && pix.size() > 1) len += cv::norm(point(pix.front()) - point(pix.back()));
    return len;
  }

  void trace_all() {
    // Pass 1: branches from ends, junctions and isolated pixels (degree != 2).
    for (int y = 0; y < h_; ++y) {
      for (int x = 0; x < w_; ++x) {
        const std::size_t p = index(x, y);
        if (!set_[p] || degree(p) == 2) continue;
        if (adj_[p] == 0) {
          Segment s;
          s.pix.push_back(p);
          segs_.push_back(std::move(s));
          continue;
        }
        for (std::uint8_t free = adj_[p] & ~used_[p]; free != 0; free = adj_[p] & ~used_[p]) {
          segs_.push_back(trace(p, std::countr_zero(free)));
        }
      }
    }
    // Pass 2: what is left are cycles of degree-2 pixels; start each at its raster-first pixel.
    for (int y = 0; y < h_; ++y) {
      for (int x = 0; x < w_; ++x) {
        const std::size_t p = index(x, y);
        const std::uint8_t free = adj_[p] & ~used_[p];
        if (!set_[p] || free == 0) continue;
        Segment s = trace(p, std::countr_zero(free));
        s.pix.pop_back();  // the walk ended back at p
        s.cycle = true;
        s.length = polyline_length(s.pix, true);
        segs_.push_back(std::move(s));
      }
    }
  }

  bool is_junction(std::size_t p) const { return degree(p) >= 3; }

  /// Spurs, redundant short parallel branches and tiny loops at junctions (after Kovesi's
  /// cleanedgelist.m, which removes short spurs and merges the edges they separated).
  void mark_minor_segments() {
    struct Short {
      std::size_t a, b;  // junction pair, a < b
      std::size_t seg;
    };
    std::vector<Short> parallels;
    for (std::size_t i = 0; i < segs_.size(); ++i) {
      Segment& s = segs_[i];
      if (s.cycle || s.pix.size() < 2) continue;
      const std::size_t a = s.pix.front();
      const std::size_t b = s.pix.back();
      const bool ja = is_junction(a);
      const bool jb = is_junction(b);
      if (a == b) {
        s.minor = s.length <= kTinyLoopPx;
      } else if (ja != jb) {
        s.minor = s.length <= kSpurPx && degree(ja ? b : a) == 1;
      } else if (ja && jb && s.length <= kShortPx) {
        parallels.push_back({std::min(a, b), std::max(a, b), i});
      }
    }
    // Of several short branches between the same two junctions keep the shortest (then the
    // first found): they are alternative routes through one clump of pixels.
    std::sort(parallels.begin(), parallels.end(), [this](const Short& x, const Short& y) {
      if (x.a != y.a) return x.a < y.a;
      if (x.b != y.b) return x.b < y.b;
      if (segs_[x.seg].length != segs_[y.seg].length) return segs_[x.seg].length < segs_[y.seg].length;
      return x.seg < y.seg;
    });
    for (std::size_t k = 1; k < parallels.size(); ++k) {
      if (parallels[k].a == parallels[k - 1].a && parallels[k].b == parallels[k - 1].b) {
        segs_[parallels[k].seg].minor = true;
      }
    }
  }

  /// At a junction where exactly two (non-minor) segment ends remain, the two segments are one
  /// curve: link those ends. End 2i is the front of segment i, end 2i + 1 its back.
  void link_segments_at_junctions() {
    link_.assign(2 * segs_.size(), -1);
    std::vector<std::int32_t> slot(set_.size(), -1);  // junction pixel -> index into ends
    std::vector<std::array<std::int64_t, 3>> ends;    // {count, first end, second end}
    for (std::size_t i = 0; i < segs_.size(); ++i) {
      const Segment& s = segs_[i];
      if (s.cycle || s.minor || s.pix.size() < 2) continue;
      for (int e = 0; e < 2; ++e) {
        const std::size_t p = e == 0 ? s.pix.front() : s.pix.back();
        if (!is_junction(p)) continue;
        if (slot[p] < 0) {
          slot[p] = static_cast<std::int32_t>(ends.size());
          ends.push_back({0, -1, -1});
        }
        auto& j = ends[static_cast<std::size_t>(slot[p])];
        if (j[0] < 2) j[static_cast<std::size_t>(1 + j[0])] = static_cast<std::int64_t>(2 * i + e);
        ++j[0];
      }
    }
    for (const auto& j : ends) {
      if (j[0] != 2) continue;
      link_[static_cast<std::size_t>(j[1])] = j[2];
      link_[static_cast<std::size_t>(j[2])] = j[1];
    }
  }

  /// Follows linked segments from segment `seg` (forward = from its front) and returns the
  /// joined chain; a chain that comes back to its first pixel is closed.
  Found walk(std::size_t seg, bool forward, std::vector<char>& visited) const {
    std::vector<std::size_t> pix;
    for (;;) {
      visited[seg] = 1;
      const auto& sp = segs_[seg].pix;
      if (forward) {
        pix.insert(pix.end(), sp.begin() + (pix.empty() ? 0 : 1), sp.end());
      } else {
        pix.insert(pix.end(), sp.rbegin() + (pix.empty() ? 0 : 1), sp.rend());
      }
      const std::int64_t next = link_[2 * seg + (forward ? 1 : 0)];
      if (next < 0 || visited[static_cast<std::size_t>(next / 2)]) break;
      seg = static_cast<std::size_t>(next / 2);
      forward = next % 2 == 0;  // entering at the front: walk it forward
    }
    return make_found(std::move(pix), false);
  }

  Found make_found(std::vector<std::size_t> pix, bool closed) const {
    if (pix.size() > 1 && pix.front() == pix.back()) {
      pix.pop_back();
      closed = true;
    }
    Found f{pix.front(), Chain{}};
    f.chain.closed = closed;
    f.chain.points_px.reserve(pix.size());
    for (const std::size_t p : pix) f.chain.points_px.push_back(point(p));
    return f;
  }

  std::vector<Found> assemble() const {
    std::vector<Found> found;
    std::vector<char> visited(segs_.size(), 0);
    for (std::size_t i = 0; i < segs_.size(); ++i) {
      const Segment& s = segs_[i];
      if (s.cycle || s.minor) {
        visited[i] = 1;
        found.push_back(make_found(s.pix, s.cycle));
      }
    }
    // Paths: start at a segment end that is not linked (a free end, or a junction where the
    // curve does not simply continue).
    for (std::size_t i = 0; i < segs_.size(); ++i) {
      if (visited[i]) continue;
      if (link_[2 * i] < 0) {
        found.push_back(walk(i, true, visited));
      } else if (link_[2 * i + 1] < 0) {
        found.push_back(walk(i, false, visited));
      }
    }
    // What is left are rings of linked segments.
    for (std::size_t i = 0; i < segs_.size(); ++i) {
      if (!visited[i]) found.push_back(walk(i, true, visited));
    }
    return found;
  }

  int w_;
  int h_;
  int stride_;
  std::array<std::ptrdiff_t, 8> off_{};
  std::vector<std::uint8_t> set_;   // 1 = edge pixel (padded grid)
  std::vector<std::uint8_t> adj_;   // links of each pixel, bit d = direction d
  std::vector<std::uint8_t> used_;  // links already walked
  std::vector<Segment> segs_;       // in discovery order
  std::vector<std::int64_t> link_;  // per segment end: the end it continues into, or -1
};

}  // namespace detail

/// link_edges as first written (same contract; CV_8UC1 input, min_length_px >= 0).
inline std::vector<Chain> link_edges(const cv::Mat& edges, double min_length_px) {
  if (edges.empty()) return {};
  return detail::Linker(edges).run(min_length_px);
}

}  // namespace hk::vision::test::reference
