// Phase 1 of first_hit: the clip of the sweep against the boundary section, its rectangles scanned four per
// SSE instruction, and the full query's marks.
#include "collision_query_internal.hpp"

namespace hk {

// Phase 1: clip the sweep against every box of the boundary section, grown by the merge margin, so one
// clip answers both "hit?" (then an exact clip makes it a candidate) and "still near?" (else it may merge).
// On the way, the distance from the end of the sweep to the nearest box: the next free-space ball. The
// rectangles settle most entries: scan_section_rects bounds them all (four per SSE instruction), and only
// the entries whose rectangle meets the sweep, or is nearer than the nearest box found, have their box
// rebuilt. An entry not hit is idle (no kHitMark): merge_idle_siblings may merge it.
void BoundarySection::Ops::clip_section(BoundarySection& self, Query& q) noexcept {
  self.candidates_.clear();
  const std::size_t n_section = self.section_.size();
  q.scanned = n_section;
  q.charge_section_boxes(static_cast<std::int32_t>(n_section));
  const std::size_t nearest_rect = scan_section_rects(self, q);
  q.nearest_rect = nearest_rect;
  if (nearest_rect == n_section) return;  // an empty section (an empty scene)
  // The free-space ball: the nearest box. A rectangle holds its box, so a box is nearer than the nearest found
  // so far only when its rectangle is; starting from the box of the nearest rectangle leaves few others to
  // rebuild. The minimum is the same whatever the order.
  q.nearest_sq = box_distance_sq(entry_box_at(self, nearest_rect), q.b);
  mark_near_rects(self, q.nearest_sq, nearest_rect);
  const std::size_t words = (n_section + 63) / 64;
  for (std::size_t w = 0; w < words; ++w) {
    for (std::uint64_t m = self.rect_overlap_bits_[w] | self.rect_near_bits_[w]; m != 0; m &= m - 1) {
      const std::size_t i = 64 * w + static_cast<std::size_t>(__builtin_ctzll(m));
      if (i >= n_section) break;  // past the end: the last group's far entries (never marked)
      const std::uint32_t node = self.section_[i];
      const std::uint64_t bit = std::uint64_t{1} << (i % 64);
      const ErrorBox box = entry_box_at(self, i);
      if (self.rect_near_bits_[w] & bit) q.nearest_sq = std::min(q.nearest_sq, box_distance_sq(box, q.b));
      double te = 0.0, tx = 0.0;
      if ((self.rect_overlap_bits_[w] & bit) &&
          clip_segment_box_inline(box, q.a, q.b, self.merge_margin_m_, &te, &tx)) {
        mark(self, node, kHitMark);
        ++q.hit;
        if (clip_segment_box_inline(box, q.a, q.b, 0.0, &te, &tx))
          self.candidates_.push_back({te, node, static_cast<std::uint32_t>(i)});
      }
    }
  }
}

// The rectangle pass of clip_section: for every section entry, a lower bound on the squared distance from the
// sweep's end to its rectangle (rect_d_sq_) and whether the rectangle, grown by the merge margin, may meet the
// sweep's (bit i % 64 of rect_overlap_bits_[i / 64]), four entries per SSE instruction. The rectangles are floats
// widened outward (SectionRects::set), so both answers are conservative: every entry whose exact rectangle meets
// the sweep's grown by the margin has its bit (the comparisons are against the sweep's bounds widened outward as
// well, with no arithmetic on the rectangles), and each distance is at most the exact one (a slack of 2^-20 of
// the largest coordinate, four times what rounding the point and the subtractions can add, is taken off each
// axis's distance; with it the squares' rounding cannot lift the sum above the exact distance either). The exact
// boxes decide after it (clip_section). Entries in groups of four: the arrays hold four past the most there can
// be, and the four past the section are made infinitely far (SectionRects::set_far_group), so the last group's extra
// lanes measure +inf and meet nothing. Returns the entry of the nearest rectangle by these bounds (the first of
// equals; section_.size() when it is empty).
std::size_t BoundarySection::Ops::scan_section_rects(BoundarySection& self, const Query& q) noexcept {
  const std::size_t n = self.section_.size();
  const float* lo_x = self.section_rect_.lo_x.data();
  const float* lo_y = self.section_rect_.lo_y.data();
  const float* hi_x = self.section_rect_.hi_x.data();
  const float* hi_y = self.section_rect_.hi_y.data();
  float* d_sq = self.rect_d_sq_.data();
  QuadBitWriter overlap{self.rect_overlap_bits_.data()};
  // The sweep's rectangle grown by the margin, widened outward as the entries' are: an entry may meet it when
  // lo ≤ s_hi and s_lo ≤ hi.
  const double m = self.merge_margin_m_;
  const float s_lo_x = float_below(q.sweep.lo.x - m), s_lo_y = float_below(q.sweep.lo.y - m);
  const float s_hi_x = float_above(q.sweep.hi.x + m), s_hi_y = float_above(q.sweep.hi.y + m);
  const float px = static_cast<float>(q.b.x), py = static_cast<float>(q.b.y);
  const double largest = std::max({self.scale_m_, std::abs(q.b.x), std::abs(q.b.y)});
  const float slack = float_above(1e-12 + largest * 0x1p-20);
  self.section_rect_.set_far_group(n);  // the last group's entries past the section
  std::size_t nearest = n;
  std::size_t i = 0;
#if defined(__SSE2__)
  const __m128 vpx = _mm_set1_ps(px), vpy = _mm_set1_ps(py), zero = _mm_setzero_ps(), vslack = _mm_set1_ps(slack);
  const __m128 v_slo_x = _mm_set1_ps(s_lo_x), v_slo_y = _mm_set1_ps(s_lo_y), v_shi_x = _mm_set1_ps(s_hi_x),
               v_shi_y = _mm_set1_ps(s_hi_y);
  static_assert(kMaxSectionEntries < (1u << 24), "entries are exact as floats (NearestOfFours)");
  NearestOfFours nearest_rect(n);
  for (; i < n; i += kScanLanes) {
    const __m128 lx = _mm_loadu_ps(lo_x + i), ly = _mm_loadu_ps(lo_y + i), hx = _mm_loadu_ps(hi_x + i),
                 hy = _mm_loadu_ps(hi_y + i);
    const __m128 dx = _mm_max_ps(_mm_sub_ps(_mm_max_ps(_mm_sub_ps(lx, vpx), _mm_sub_ps(vpx, hx)), vslack), zero);
    const __m128 dy = _mm_max_ps(_mm_sub_ps(_mm_max_ps(_mm_sub_ps(ly, vpy), _mm_sub_ps(vpy, hy)), vslack), zero);
    const __m128 d = _mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy));
    _mm_storeu_ps(d_sq + i, d);
    nearest_rect.take(d);
    const __m128 meets = _mm_and_ps(_mm_and_ps(_mm_cmple_ps(lx, v_shi_x), _mm_cmple_ps(v_slo_x, hx)),
                                    _mm_and_ps(_mm_cmple_ps(ly, v_shi_y), _mm_cmple_ps(v_slo_y, hy)));
    overlap.put(i, static_cast<unsigned>(_mm_movemask_ps(meets)));
  }
  nearest = nearest_rect.nearest();
#else
  float nearest_sq = std::numeric_limits<float>::infinity();
  for (; i < n; i += kScanLanes) {
    unsigned four_bits = 0;
    for (std::size_t k = i; k < i + kScanLanes; ++k) {
      const float dx = std::max(std::max(lo_x[k] - px, px - hi_x[k]) - slack, 0.0f);
      const float dy = std::max(std::max(lo_y[k] - py, py - hi_y[k]) - slack, 0.0f);
      d_sq[k] = dx * dx + dy * dy;
      if (d_sq[k] < nearest_sq) {
        nearest_sq = d_sq[k];
        nearest = k;
      }
      if (lo_x[k] <= s_hi_x && s_lo_x <= hi_x[k] && lo_y[k] <= s_hi_y && s_lo_y <= hi_y[k]) four_bits |= 1u << (k - i);
    }
    overlap.put(i, four_bits);
  }
#endif
  overlap.finish(i);
  return nearest;
}

// The entries whose rectangle may be nearer to the sweep's end than bound_sq [m²] (their distance bound is
// below it, rounded up to a float), but for `skip` (whose box was measured already): bit i % 64 of
// rect_near_bits_[i / 64]. In groups of four, as scan_section_rects.
void BoundarySection::Ops::mark_near_rects(BoundarySection& self, double bound_sq, std::size_t skip) noexcept {
  const std::size_t n = self.section_.size();
  const float* d_sq = self.rect_d_sq_.data();
  const float bound = float_above(bound_sq);
  QuadBitWriter near{self.rect_near_bits_.data()};
  std::size_t i = 0;
  for (; i < n; i += kScanLanes) {
#if defined(__SSE2__)
    near.put(i, static_cast<unsigned>(_mm_movemask_ps(_mm_cmplt_ps(_mm_loadu_ps(d_sq + i), _mm_set1_ps(bound)))));
#else
    unsigned four_bits = 0;
    for (std::size_t k = 0; k < kScanLanes; ++k) four_bits |= (d_sq[i + k] < bound ? 1u : 0u) << k;
    near.put(i, four_bits);
#endif
  }
  near.finish(i);
  self.rect_near_bits_[skip / 64] &= ~(std::uint64_t{1} << (skip % 64));
}

}  // namespace hk
