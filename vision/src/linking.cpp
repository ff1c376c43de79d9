// Edge linking by tracing the edge-pixel graph (algorithm and guarantees in linking.hpp).
//
// Why a graph walk and not cv::findContours: findContours follows the border of a region, so a
// one-pixel-wide open edge comes back as a there-and-back loop that visits every pixel twice;
// a haptic wall built from it would be two coincident walls with a hairpin at each end. Here
// every adjacency link between edge pixels is walked exactly once, so each pixel run between
// junctions and ends becomes exactly one polyline.
//
// Canny's output is not a clean one-pixel curve: staircases carry redundant corner pixels and
// sharp corners grow 1-2 pixel spurs and 2x2 clumps. Taken literally, each of those is a
// junction that cuts a boundary into pieces, and the short middle piece then falls under the
// length filter, leaving a gap a point proxy can slip through. Hence the thinning before
// tracing and the junction clean-up after it.
//
// Layout: the edge map is copied into a byte grid with a one-pixel empty border so neighbour
// lookups need no bounds checks, and the edge pixels are listed once in raster order; every
// later pass visits only that list (a few percent of the pixels), never the whole grid. The
// thinning and link rules depend only on the 8-neighbour mask of a pixel and are tabulated. Per
// pixel we keep the 8-bit mask of its graph links and the mask of links already walked.
// Directions are numbered clockwise on screen from east. Tracing yields segments (junction to
// junction/end, or junction-free cycles), stored concatenated in one array; joining segments
// through junctions yields the chains. Loops over pixels avoid data-dependent branches where
// the branch would be unpredictable (they cost more than the work on this data), and the
// buffers are kept between calls (see Linker).

#include "vision/linking.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <utility>

#include <opencv2/core/hal/intrin.hpp>

#include "hk/error.hpp"

namespace hk::vision {
namespace {

//                                 E  SE  S  SW   W  NW   N  NE
constexpr std::array<int, 8> kDx = {1, 1, 0, -1, -1, -1, 0, 1};
constexpr std::array<int, 8> kDy = {0, 1, 1, 1, 0, -1, -1, -1};

constexpr int opposite(int d) { return (d + 4) & 7; }
constexpr bool has(unsigned mask, int d) { return ((mask >> (d & 7)) & 1U) != 0; }

// Segments shorter than these are Canny artefacts at corners, not shape (a few pixels are a
// fraction of a millimetre on the device); they must not cut a boundary into pieces.
constexpr double kSpurPx = 3.0;      // a branch from a junction to a free end
constexpr double kShortPx = 3.0;     // one of several branches joining the same two junctions
constexpr double kTinyLoopPx = 5.0;  // a loop from a junction back to itself (a 2x2 block)

// Everything the linker decides about a pixel depends only on which of its 8 neighbours are
// edge pixels: an 8-bit mask, bit d = direction d. The rules are tabulated once.

/// Whether a pixel with neighbour mask n is the redundant corner of a staircase step: its only
/// 4-neighbours are two perpendicular ones a = p + u and b = p + v, the inner corner p - u - v is
/// empty and a side diagonal p + u - v or p - u + v is set (see Linker::thin_l_corners).
constexpr bool is_staircase_corner(unsigned n) {
  if (has(n, 0) + has(n, 2) + has(n, 4) + has(n, 6) != 2) return false;
  for (int d = 0; d < 8; d += 2) {  // u = direction d, v = direction d + 2 (perpendicular)
    if (!has(n, d) || !has(n, d + 2)) continue;
    const bool inner_empty = !has(n, d + 5);               // p - u - v
    const bool side_set = has(n, d + 7) || has(n, d + 3);  // p + u - v, p - u + v
    return inner_empty && side_set;
  }
  return false;
}

/// Graph links of a pixel with neighbour mask n: 4-neighbours always; a diagonal neighbour only
/// if neither pixel 4-adjacent to both is set (otherwise the path through that pixel already
/// connects them: an L-corner).
constexpr std::uint8_t links_of(unsigned n) {
  unsigned mask = 0;
  for (int d = 0; d < 8; ++d) {
    if (!has(n, d)) continue;
    if (d % 2 == 1 && (has(n, d + 7) || has(n, d + 1))) continue;  // flanking 4-directions set
    mask |= 1U << d;
  }
  return static_cast<std::uint8_t>(mask);
}

template <typename F>
constexpr std::array<std::uint8_t, 256> tabulate(F f) {
  std::array<std::uint8_t, 256> t{};
  for (unsigned n = 0; n < 256; ++n) t[n] = static_cast<std::uint8_t>(f(n));
  return t;
}

constexpr auto kStaircaseCorner = tabulate(is_staircase_corner);
constexpr auto kLinks = tabulate(links_of);
constexpr auto kPopcount = tabulate([](unsigned n) { return std::popcount(n); });

/// Length of a step between 8-adjacent pixel centres, [0] axial, [1] diagonal: as cv::norm of the
/// step gives it (segment lengths, compared with the thresholds above), and as std::hypot gives
/// it (chain lengths, which must equal chain_length_px's for the length filter). Looked up, not
/// branched on: the kind of the next step is unpredictable.
const std::array<double, 2> kStepNorm = {1.0, std::sqrt(2.0)};
const std::array<double, 2> kStepHypot = {std::hypot(1.0, 0.0), std::hypot(1.0, 1.0)};

/// Edge maps of more pixels than this do not keep the linker's buffers after the call.
constexpr std::size_t kKeepPixels = std::size_t{1} << 22;

/// One linker per thread (see link_edges): its buffers, the largest of which are as large as the
/// edge map (3 bytes per pixel), are kept between calls, because allocating them anew each call
/// costs more than the linking (large freed blocks go back to the OS and come back as page
/// faults).
class Linker {
 public:
  /// Links `edges` (CV_8UC1, non-empty); everything of a previous call is reset first.
  std::vector<Chain> link(const cv::Mat& edges, double min_length_px) {
    reset(edges);
    load(edges);
    thin_l_corners();
    build_adjacency();
    std::vector<Chain> chains = run(min_length_px);
    if (size_ > kKeepPixels) *this = Linker{};  // do not keep a huge image's buffers
    return chains;
  }

 private:
  void reset(const cv::Mat& edges) {
    w_ = edges.cols;
    h_ = edges.rows;
    stride_ = static_cast<std::ptrdiff_t>(w_) + 2;
    inv_stride_ = 1.0 / static_cast<double>(stride_);
    size_ = static_cast<std::size_t>(stride_) * static_cast<std::size_t>(h_ + 2);
    for (int d = 0; d < 8; ++d) off_[d] = kDy[d] * stride_ + kDx[d];
    if (capacity_ < size_) {  // grids: every cell read is written first, so no clearing
      set_ = std::make_unique_for_overwrite<std::uint8_t[]>(size_);
      node_ = std::make_unique_for_overwrite<Node[]>(size_);
      capacity_ = size_;
    }
    pix_.clear();
    ends_.clear();
    seg_pix_.clear();
    segs_.clear();
    link_.clear();
    out_pix_.clear();
    found_.clear();
  }

  /// Steps 3 to 5 of the algorithm (linking.hpp) on the adjacency built by link().
  std::vector<Chain> run(double min_length_px) {
    trace_all();
    mark_minor_segments();
    link_segments_at_junctions();
    assemble();
    // Output order: raster index of the first point, ties in discovery order.
    std::stable_sort(found_.begin(), found_.end(), [](const Found& a, const Found& b) { return a.first < b.first; });
    std::vector<Chain> chains;
    chains.reserve(found_.size());
    for (const Found& f : found_) {
      const std::size_t* pix = out_pix_.data() + f.begin;
      if (path_length(pix, f.count, f.closed) < min_length_px) continue;
      Chain c;
      c.closed = f.closed;
      c.points_px.resize(f.count);
      for (std::size_t k = 0; k < f.count; ++k) c.points_px[k] = point(pix[k]);
      chains.push_back(std::move(c));
    }
    return chains;
  }

  /// Graph state of one pixel of the padded grid (valid only at edge pixels left by thinning).
  struct Node {
    std::uint8_t links;  // links to neighbours, bit d = direction d
    std::uint8_t used;   // links already walked
  };
  /// A maximal run of links between pixels of degree != 2 (or a cycle of degree-2 pixels):
  /// seg_pix_[begin, end) in order. A loop from a junction back to itself repeats the junction
  /// at the end; a cycle without junctions does not.
  struct Segment {
    std::size_t begin = 0;
    std::size_t end = 0;
    std::size_t front_end = 0;  // index in ends_ of the first pixel (segments from pass 1)
    bool cycle = false;         // a cycle without junctions
    bool minor = false;         // a corner artefact, kept as its own chain (see kSpurPx)
    double length = 0.0;        // polyline length [px] (of an open walk; cycles: unused)
    std::size_t size() const { return end - begin; }
  };
  /// One output chain: out_pix_[begin, begin + count), raster index of its first point.
  struct Found {
    std::size_t first;
    std::size_t begin;
    std::size_t count;
    bool closed;
  };

  /// Pixel centre of padded-grid index i. The division by the stride is done by multiplying
  /// with its reciprocal and correcting the at most one unit of rounding (a 64-bit division
  /// per point would cost more than all the rest of the output).
  cv::Point2d point(std::size_t i) const {
    const auto s = static_cast<std::size_t>(stride_);
    auto row = static_cast<std::size_t>(static_cast<double>(i) * inv_stride_);
    auto col = static_cast<std::ptrdiff_t>(i - row * s);
    if (col < 0) {
      --row;
      col += stride_;
    } else if (col >= stride_) {
      ++row;
      col -= stride_;
    }
    return {static_cast<double>(col) - 1.0, static_cast<double>(row) - 1.0};
  }
  std::size_t step(std::size_t p, int d) const {
    return static_cast<std::size_t>(static_cast<std::ptrdiff_t>(p) + off_[d]);
  }
  int degree(std::size_t p) const { return kPopcount[node_[p].links]; }
  bool is_junction(std::size_t p) const { return degree(p) >= 3; }

  /// Mask of the set 8-neighbours of p, bit d = direction d.
  unsigned neighbours(std::size_t p) const {
    const std::uint8_t* c = set_.get() + p;
    const std::ptrdiff_t s = stride_;
    return static_cast<unsigned>(c[1] | (c[s + 1] << 1) | (c[s] << 2) | (c[s - 1] << 3) | (c[-1] << 4) |
                                 (c[-s - 1] << 5) | (c[-s] << 6) | (c[-s + 1] << 7));
  }

  /// Copies the edge map into set_ (1 = edge pixel) with an empty one-pixel border and lists the
  /// edge pixels in raster order; every later pass visits only those.
  void load(const cv::Mat& edges) {
    pix_.resize(static_cast<std::size_t>(cv::countNonZero(edges)));
    std::size_t* out = pix_.data();
    // Appends row + x0 + i for each set bit i of `bits`: one loop per 64 pixels, so that
    // (unpredictable) loop exits are rare.
    const auto list = [&out](std::uint64_t bits, std::size_t first) {
      for (; bits != 0; bits &= bits - 1) *out++ = first + static_cast<std::size_t>(std::countr_zero(bits));
    };
    std::uint8_t* g = set_.get();
    std::fill_n(g, stride_, 0);
    std::fill_n(g + static_cast<std::size_t>(h_ + 1) * static_cast<std::size_t>(stride_), stride_, 0);
    for (int y = 0; y < h_; ++y) {
      const std::uint8_t* src = edges.ptr<std::uint8_t>(y);
      const std::size_t row = static_cast<std::size_t>(y + 1) * static_cast<std::size_t>(stride_) + 1;
      std::uint8_t* dst = g + row;
      dst[-1] = 0;
      dst[w_] = 0;
      std::uint64_t bits = 0;  // pixels x0 .. x0 + 63
      int x0 = 0;
      int x = 0;
#if CV_SIMD128
      const cv::v_uint8x16 zero = cv::v_setzero_u8();
      const cv::v_uint8x16 one = cv::v_setall_u8(1);
      for (; x + 16 <= w_; x += 16) {
        const cv::v_uint8x16 on = cv::v_load(src + x) != zero;
        cv::v_store(dst + x, on & one);
        bits |= static_cast<std::uint64_t>(cv::v_signmask(on)) << (x - x0);
        if (x + 16 - x0 == 64) {
          list(bits, row + static_cast<std::size_t>(x0));
          bits = 0;
          x0 = x + 16;
        }
      }
#endif
      for (; x < w_; ++x) {
        dst[x] = src[x] != 0 ? 1 : 0;
        bits |= static_cast<std::uint64_t>(dst[x]) << (x - x0);
        if (x + 1 - x0 == 64) {
          list(bits, row + static_cast<std::size_t>(x0));
          bits = 0;
          x0 = x + 1;
        }
      }
      list(bits, row + static_cast<std::size_t>(x0));
    }
  }

  /// Removes, in raster order, the redundant corner pixel of each step of a staircase: a pixel
  /// whose only 4-neighbours are two perpendicular ones a = p + u and b = p + v, with the inner
  /// corner p - u - v empty and a side diagonal p + u - v or p + v - u set (the curve turns back
  /// to its heading right after the step; a true right-angle corner has neither and is kept).
  /// a and b stay 8-adjacent and every other neighbour of p is 4-adjacent to a or b, so
  /// connectivity is kept. Canny's 4-connected staircases thus become 8-connected diagonals,
  /// which are shorter (a 45-degree run of n steps is n*sqrt2 long, not 2n) and smoother to touch.
  /// Each decision sees the removals made before it in raster order.
  void thin_l_corners() {
    std::size_t kept = 0;
    for (const std::size_t p : pix_) {  // without a branch per pixel
      const std::uint8_t keep = kStaircaseCorner[neighbours(p)] ^ 1U;
      set_[p] = keep;
      pix_[kept] = p;
      kept += keep;
    }
    pix_.resize(kept);
  }

  /// Links of every edge pixel; lists the pixels of degree != 2 (the starts of tracing).
  void build_adjacency() {
    ends_.resize(pix_.size());
    std::size_t n = 0;
    for (const std::size_t p : pix_) {  // without a branch per pixel
      const std::uint8_t links = kLinks[neighbours(p)];
      node_[p] = Node{links, 0};
      ends_[n] = p;
      n += kPopcount[links] != 2 ? 1U : 0U;
    }
    ends_.resize(n);
  }

  /// Walks from `start` along link d through degree-2 pixels until a pixel of another degree or
  /// `start` itself is reached (then `start` is appended again); appends the segment. Marks the
  /// links walked as used: at the two ends the link by which the walk leaves or arrives, at a
  /// degree-2 pixel both (it is passed through; its links are used both or neither, since a
  /// walk never stops at one and never starts at one that was passed).
  Segment& trace(std::size_t start, int d) {
    Segment s;
    s.begin = seg_pix_.size();
    seg_pix_.push_back(start);
    node_[start].used = static_cast<std::uint8_t>(node_[start].used | (1U << d));
    std::size_t cur = start;
    for (;;) {
      s.length += kStepNorm[static_cast<std::size_t>(d & 1)];  // odd directions are diagonal
      cur = step(cur, d);
      seg_pix_.push_back(cur);
      Node& n = node_[cur];
      const unsigned back = 1U << opposite(d);  // the link just walked, seen from cur
      if (cur == start || kPopcount[n.links] != 2) {
        n.used = static_cast<std::uint8_t>(n.used | back);
        break;
      }
      n.used = n.links;
      d = std::countr_zero(n.links & ~back);  // the other link
    }
    s.end = seg_pix_.size();
    segs_.push_back(s);
    return segs_.back();
  }

  void trace_all() {
    seg_pix_.reserve(pix_.size() + pix_.size() / 4 + 16);
    // Pass 1: branches from ends, junctions and isolated pixels (degree != 2).
    for (std::size_t k = 0; k < ends_.size(); ++k) {
      const std::size_t p = ends_[k];
      if (node_[p].links == 0) {
        Segment s;
        s.begin = seg_pix_.size();
        seg_pix_.push_back(p);
        s.end = seg_pix_.size();
        s.front_end = k;
        segs_.push_back(s);
        continue;
      }
      for (unsigned free = node_[p].links & ~node_[p].used; free != 0; free = node_[p].links & ~node_[p].used) {
        trace(p, std::countr_zero(free)).front_end = k;
      }
    }
    // Pass 2: what is left are cycles of degree-2 pixels; start each at its raster-first pixel.
    for (const std::size_t p : pix_) {
      const unsigned free = node_[p].links & ~node_[p].used;
      if (free == 0) continue;
      Segment& s = trace(p, std::countr_zero(free));
      seg_pix_.pop_back();  // the walk ended back at p
      --s.end;
      s.cycle = true;
    }
  }

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
      if (s.cycle || s.size() < 2) continue;
      const std::size_t a = seg_pix_[s.begin];
      const std::size_t b = seg_pix_[s.end - 1];
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
    struct Junction {
      int count = 0;                      // segment ends here
      std::array<std::int64_t, 2> end{};  // the first two of them
    };
    std::vector<Junction> at(ends_.size());  // by index in ends_ (junctions are among them)
    // Segments not from pass 1 (cycles) have no junction ends, minor ones are skipped.
    for (std::size_t i = 0; i < segs_.size(); ++i) {
      const Segment& s = segs_[i];
      if (s.cycle || s.minor || s.size() < 2) continue;
      for (std::size_t e = 0; e < 2; ++e) {
        const std::size_t p = e == 0 ? seg_pix_[s.begin] : seg_pix_[s.end - 1];
        if (!is_junction(p)) continue;
        Junction& j = at[e == 0 || p == seg_pix_[s.begin] ? s.front_end : index_in_ends(p)];
        if (j.count < 2) j.end[static_cast<std::size_t>(j.count)] = static_cast<std::int64_t>(2 * i + e);
        ++j.count;
      }
    }
    for (const Junction& j : at) {
      if (j.count != 2) continue;
      link_[static_cast<std::size_t>(j.end[0])] = j.end[1];
      link_[static_cast<std::size_t>(j.end[1])] = j.end[0];
    }
  }

  /// Index in ends_ (raster order) of one of its pixels: a binary search whose steps compile to
  /// conditional moves (a full-size pixel -> index grid would cost more in page faults on the
  /// first call than this costs on the few junction ends).
  std::size_t index_in_ends(std::size_t p) const {
    const std::size_t* base = ends_.data();
    std::size_t len = ends_.size();
    while (len > 1) {
      const std::size_t half = len / 2;
      base = base[half - 1] < p ? base + half : base;
      len -= half;
    }
    return static_cast<std::size_t>(base - ends_.data());
  }

  /// Appends the pixels of segment `seg` (reversed when !forward; without its first pixel when
  /// `skip_first`) to the chain being built at the end of out_pix_.
  void append(std::size_t seg, bool forward, bool skip_first) {
    const Segment& s = segs_[seg];
    const std::size_t skip = skip_first ? 1 : 0;
    if (forward) {
      out_pix_.insert(out_pix_.end(), seg_pix_.begin() + static_cast<std::ptrdiff_t>(s.begin + skip),
                      seg_pix_.begin() + static_cast<std::ptrdiff_t>(s.end));
    } else {
      for (std::size_t k = s.end - skip; k > s.begin; --k) out_pix_.push_back(seg_pix_[k - 1]);
    }
  }

  /// Records out_pix_[begin, end) as a chain; a chain whose last pixel repeats its first is
  /// closed (the repeat dropped).
  void finish(std::size_t begin, bool closed) {
    if (out_pix_.size() - begin > 1 && out_pix_[begin] == out_pix_.back()) {
      out_pix_.pop_back();
      closed = true;
    }
    found_.push_back({out_pix_[begin], begin, out_pix_.size() - begin, closed});
  }

  /// Follows linked segments from segment `seg` (forward = from its front) and records the
  /// joined chain; a chain that comes back to its first pixel is closed.
  void walk(std::size_t seg, bool forward, std::vector<char>& visited) {
    const std::size_t begin = out_pix_.size();
    for (;;) {
      visited[seg] = 1;
      append(seg, forward, out_pix_.size() > begin);
      const std::int64_t next = link_[2 * seg + (forward ? 1 : 0)];
      if (next < 0 || visited[static_cast<std::size_t>(next / 2)]) break;
      seg = static_cast<std::size_t>(next / 2);
      forward = next % 2 == 0;  // entering at the front: walk it forward
    }
    finish(begin, false);
  }

  void assemble() {
    out_pix_.reserve(seg_pix_.size());
    std::vector<char> visited(segs_.size(), 0);
    for (std::size_t i = 0; i < segs_.size(); ++i) {
      const Segment& s = segs_[i];
      if (s.cycle || s.minor) {
        visited[i] = 1;
        const std::size_t begin = out_pix_.size();
        append(i, true, false);
        finish(begin, s.cycle);
      }
    }
    // Paths: start at a segment end that is not linked (a free end, or a junction where the
    // curve does not simply continue).
    for (std::size_t i = 0; i < segs_.size(); ++i) {
      if (visited[i]) continue;
      if (link_[2 * i] < 0) {
        walk(i, true, visited);
      } else if (link_[2 * i + 1] < 0) {
        walk(i, false, visited);
      }
    }
    // What is left are rings of linked segments.
    for (std::size_t i = 0; i < segs_.size(); ++i) {
      if (!visited[i]) walk(i, true, visited);
    }
  }

  /// Polyline length of pixels pix[0 .. n), plus the closing step when closed, summed in the
  /// order chain_length_px sums (so the length filter agrees with it exactly).
  double path_length(const std::size_t* pix, std::size_t n, bool closed) const {
    // In the padded grid (stride >= w + 2) the index difference of two pixels is 1 or stride
    // exactly for an axial step and stride +- 1 exactly for a diagonal one. No branch per step.
    const auto s = static_cast<std::size_t>(stride_);
    unsigned not_adjacent = 0;
    const auto step_length = [s, &not_adjacent](std::size_t a, std::size_t b) {
      const std::size_t d = a > b ? a - b : b - a;
      const unsigned axial = static_cast<unsigned>(d == 1) + static_cast<unsigned>(d == s);
      const unsigned diagonal = static_cast<unsigned>(d == s - 1) + static_cast<unsigned>(d == s + 1);
      not_adjacent |= (axial | diagonal) ^ 1U;
      return kStepHypot[diagonal];
    };
    double len = 0.0;
    for (std::size_t k = 1; k < n; ++k) len += step_length(pix[k - 1], pix[k]);
    if (closed && n > 1) len += step_length(pix[n - 1], pix[0]);
    if (not_adjacent != 0) [[unlikely]] {  // does not occur; exact fallback
      const auto dist = [this](std::size_t a, std::size_t b) {
        const cv::Point2d pa = point(a);
        const cv::Point2d pb = point(b);
        return std::hypot(pb.x - pa.x, pb.y - pa.y);
      };
      len = 0.0;
      for (std::size_t k = 1; k < n; ++k) len += dist(pix[k - 1], pix[k]);
      if (closed && n > 1) len += dist(pix[n - 1], pix[0]);
    }
    return len;
  }

  int w_ = 0;
  int h_ = 0;
  std::ptrdiff_t stride_ = 2;
  double inv_stride_ = 0.5;
  std::size_t size_ = 0;      // cells of the padded grid, (w + 2) * (h + 2)
  std::size_t capacity_ = 0;  // cells allocated in the grids
  std::array<std::ptrdiff_t, 8> off_{};
  std::unique_ptr<std::uint8_t[]> set_;  // 1 = edge pixel (padded grid; border 0)
  std::unique_ptr<Node[]> node_;         // graph state, written for the pixels in pix_
  std::vector<std::size_t> pix_;         // edge pixels (left by thinning), raster order
  std::vector<std::size_t> ends_;        // those of degree != 2, raster order
  std::vector<std::size_t> seg_pix_;     // pixels of all segments, concatenated
  std::vector<Segment> segs_;            // in discovery order
  std::vector<std::int64_t> link_;       // per segment end: the end it continues into, or -1
  std::vector<std::size_t> out_pix_;     // pixels of all chains, concatenated
  std::vector<Found> found_;             // chains in discovery order
};

}  // namespace

double chain_length_px(const Chain& chain) {
  const auto& p = chain.points_px;
  double len = 0.0;
  // sqrt of the squared length, not std::hypot: pixel steps are far from overflow, and hypot costs several times as
  // much.
  const auto step = [](cv::Point2d a, cv::Point2d b) {
    return std::sqrt((b.x - a.x) * (b.x - a.x) + (b.y - a.y) * (b.y - a.y));
  };
  for (std::size_t i = 1; i < p.size(); ++i) len += step(p[i - 1], p[i]);
  if (chain.closed && p.size() > 1) len += step(p.back(), p.front());
  return len;
}

std::vector<Chain> link_edges(const cv::Mat& edges, double min_length_px) {
  if (std::isnan(min_length_px) || min_length_px < 0.0) {
    throw hk::ArgumentError("link_edges: min_length_px must be >= 0");
  }
  if (edges.empty()) return {};
  if (edges.type() != CV_8UC1) throw hk::ArgumentError("link_edges: expected a CV_8UC1 edge map");
  thread_local Linker linker;
  return linker.link(edges, min_length_px);
}

}  // namespace hk::vision
