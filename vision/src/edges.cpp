// Canny edge detection with thresholds chosen from the image (see edges.hpp for the rule).
//
// The 3x3 Sobel derivatives are computed once, in one pass that also histograms their L2
// magnitudes for the automatic threshold, and the non-maximum suppression and hysteresis then
// run on exactly those derivatives, so the threshold statistics are taken from exactly the
// gradient that is thresholded (same kernel, border and L2 norm).
//
// Everything after the blur is our own code, but it computes exactly what
// cv::Sobel(..., BORDER_REPLICATE) and cv::Canny(dx, dy, ..., L2gradient = true) compute (all
// integer arithmetic; tests/vision/test_reference.cpp checks the edge maps against OpenCV's),
// only faster: one pass per stage, vectorised, the suppression without per-pixel branches, no
// sorting, in row stripes on OpenCV's threads (as cv::Canny), and with the image-sized buffers
// kept between calls (Scratch).

#include "vision/edges.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <utility>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"

namespace hk::vision {
namespace {

constexpr double kHighPercentile = 0.90;  // of the non-zero gradient magnitudes
constexpr double kLowRatio = 0.4;         // low = kLowRatio * high (MATLAB's ThresholdRatio)
constexpr double kNoiseSigmas = 5.0;      // high >= this many Rayleigh scales of pure noise
constexpr double kMaxFraction = 0.5;      // high <= this fraction of the strongest gradient

/// Statistics of the non-zero L2 gradient magnitudes, from a histogram of 1-unit bins.
struct GradientStats {
  double percentile = 0.0;  // kHighPercentile quantile (see below)
  double max = 0.0;         // largest magnitude (lower edge of its bin)
};

// |Sobel 3x3| <= 4 * 255 per axis on 8-bit input, so the L2 magnitude is < 1443.
constexpr std::size_t kHistBins = 1448;

/// Histogram of floor(sqrt(gx^2 + gy^2)) over the pixels, 1-unit bins, filled row by row.
/// A zero gradient lands in bin 0, which does not count (a non-zero one has magnitude >= 1).
class MagnitudeHistogram {
 public:
  /// Adds one row of n pixels given their squared magnitudes, 8 at a time. Pixel x goes to
  /// partial histogram x % 4, so that runs of equal bins do not wait on each other's increments.
  void add(const std::int32_t* m2, int n) {
    int x = 0;
#if CV_SIMD128
    const cv::v_int32x4 zero = cv::v_setzero_s32();
    const cv::v_uint16x8 last = cv::v_setall_u16(static_cast<std::uint16_t>(kHistBins - 1));
    for (; x + 8 <= n; x += 8) {
      const cv::v_int32x4 a = cv::v_load(m2 + x);
      const cv::v_int32x4 b = cv::v_load(m2 + x + 4);
      if (!cv::v_check_any((a | b) != zero)) continue;  // flat: all in bin 0
      // Exact: m2 < 2^22 is exact in float, and for non-square m2 the distance of sqrt(m2)
      // below the next integer (> 1 / (2 * 1443)) exceeds half a float ulp there (2^-14), so
      // truncating the correctly rounded float square root gives floor(sqrt(m2)), as the
      // double one does. Bins < 1448 fit in 16 bits.
      const cv::v_uint16x8 bins = cv::v_min(
          cv::v_pack_u(cv::v_trunc(cv::v_sqrt(cv::v_cvt_f32(a))), cv::v_trunc(cv::v_sqrt(cv::v_cvt_f32(b)))), last);
      ++part_[0][cv::v_extract_n<0>(bins)];
      ++part_[1][cv::v_extract_n<1>(bins)];
      ++part_[2][cv::v_extract_n<2>(bins)];
      ++part_[3][cv::v_extract_n<3>(bins)];
      ++part_[0][cv::v_extract_n<4>(bins)];
      ++part_[1][cv::v_extract_n<5>(bins)];
      ++part_[2][cv::v_extract_n<6>(bins)];
      ++part_[3][cv::v_extract_n<7>(bins)];
    }
#endif
    for (; x < n; ++x) {
      if (m2[x] == 0) continue;
      const auto bin = static_cast<std::size_t>(std::sqrt(static_cast<double>(m2[x])));
      ++part_[static_cast<std::size_t>(x & 3)][std::min(bin, kHistBins - 1)];
    }
    // Each partial histogram receives at most a quarter of the pixels (rounded up) of the rows
    // since the last flush: flush long before a 32-bit count could overflow.
    pending_ += n / 4 + 1;
    if (pending_ > (std::int64_t{1} << 30)) flush();
  }

  /// Adds the counts of another histogram (of other pixels).
  void merge(MagnitudeHistogram& other) {
    other.flush();
    flush();
    for (std::size_t b = 0; b < kHistBins; ++b) hist_[b] += other.hist_[b];
  }

  /// The quantile is returned as the lower edge of its bin minus 0.5, so that the pixels at the
  /// quantile count as strong (Canny keeps m > high): on clean synthetic or binary images every
  /// ridge pixel of a straight edge has exactly the same magnitude, the quantile itself.
  GradientStats stats() {
    flush();
    hist_[0] = 0;  // zero gradients (flat areas) do not count
    GradientStats st;
    std::int64_t nonzero = 0;
    for (std::size_t b = 0; b < kHistBins; ++b) {
      nonzero += hist_[b];
      if (hist_[b] > 0) st.max = static_cast<double>(b);
    }
    if (nonzero == 0) return st;
    const auto target = static_cast<std::int64_t>(std::ceil(kHighPercentile * static_cast<double>(nonzero)));
    std::int64_t cumulative = 0;
    for (std::size_t b = 0; b < kHistBins; ++b) {
      cumulative += hist_[b];
      if (cumulative >= target) {
        st.percentile = static_cast<double>(b) - 0.5;
        break;
      }
    }
    return st;
  }

 private:
  void flush() {
    for (auto& h : part_) {
      for (std::size_t b = 0; b < kHistBins; ++b) hist_[b] += h[b];
      h.fill(0);
    }
    pending_ = 0;
  }

  std::array<std::array<std::uint32_t, kHistBins>, 4> part_{};
  std::array<std::int64_t, kHistBins> hist_{};
  std::int64_t pending_ = 0;
};

/// dx^2 + dy^2 of one row of n pixels into m[0 .. n-1].
void squared_magnitudes(const std::int16_t* gx, const std::int16_t* gy, int n, std::int32_t* m) {
  int x = 0;
#if CV_SIMD128
  for (; x + 8 <= n; x += 8) {
    cv::v_int16x8 ab0;
    cv::v_int16x8 ab1;
    cv::v_zip(cv::v_load(gx + x), cv::v_load(gy + x), ab0, ab1);
    cv::v_store(m + x, cv::v_dotprod(ab0, ab0));
    cv::v_store(m + x + 4, cv::v_dotprod(ab1, ab1));
  }
#endif
  for (; x < n; ++x) m[x] = gx[x] * gx[x] + gy[x] * gy[x];
}

/// Row stripes for cv::parallel_for_: the rows are split into stripe_count(rows, cols) stripes,
/// as many as OpenCV has threads (cv::Canny splits its work the same way; cv::setNumThreads(1)
/// makes everything serial) but each of at least kMinStripePixels pixels and kMinStripeRows
/// rows (below that, starting a thread costs more than it saves). Every stage computes per-row
/// results or integer sums, so the output does not depend on the split.
constexpr std::int64_t kMinStripePixels = std::int64_t{1} << 17;
constexpr int kMinStripeRows = 16;

int stripe_count(int rows, int cols) {
  const std::int64_t by_size =
      std::min<std::int64_t>(static_cast<std::int64_t>(rows) * cols / kMinStripePixels, rows / kMinStripeRows);
  return static_cast<int>(std::max<std::int64_t>(1, std::min<std::int64_t>(cv::getNumThreads(), by_size)));
}

/// Calls f(stripe, first_row, end_row) for each of n stripes of `rows` rows, in parallel.
template <typename F>
void for_each_stripe(int n, int rows, const F& f) {
  const auto bounds = [n, rows](int s) { return static_cast<int>(static_cast<std::int64_t>(rows) * s / n); };
  if (n == 1) {
    f(0, 0, rows);
    return;
  }
  cv::parallel_for_(
      cv::Range(0, n),
      [&](const cv::Range& r) {
        for (int s = r.start; s < r.end; ++s) f(s, bounds(s), bounds(s + 1));
      },
      n);
}

/// 3x3 Sobel derivatives of a CV_8UC1 image with replicated border, exactly
/// cv::Sobel(src, dx, CV_16S, 1, 0, 3, 1, 0, BORDER_REPLICATE) and likewise dy (0, 1):
/// dx = [-1 0 1; -2 0 2; -1 0 1] * I, dy = its transpose (x right, y down). When `hist` is given,
/// the magnitudes are added to it on the way (one pass over the image instead of three).
/// Like cv::Sobel, a submatrix's border pixels see the parent image's pixels next to them.
void sobel_3x3(const cv::Mat& src, cv::Mat& dx, cv::Mat& dy, MagnitudeHistogram* hist) {
  const int w = src.cols;
  const int h = src.rows;
  if (src.isSubmatrix()) {
    // OpenCV's filters read the parent image's pixels beyond the edges of a submatrix (border
    // extrapolation starts only at the parent's edges); keep that.
    cv::Sobel(src, dx, CV_16S, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
    cv::Sobel(src, dy, CV_16S, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
    std::vector<std::int32_t> m2(static_cast<std::size_t>(w));
    for (int y = 0; hist != nullptr && y < h; ++y) {
      squared_magnitudes(dx.ptr<std::int16_t>(y), dy.ptr<std::int16_t>(y), w, m2.data());
      hist->add(m2.data(), w);
    }
    return;
  }
  dx.create(h, w, CV_16SC1);
  dy.create(h, w, CV_16SC1);
  const int n = stripe_count(h, w);
  // A histogram of its own per stripe, merged at the end; with one stripe (images of fewer than 2 * 2^17
  // pixels, or one thread) the pixels go straight into `hist` (each histogram is 35 KB to clear, flush
  // and merge).
  std::vector<MagnitudeHistogram> part(hist != nullptr && n > 1 ? static_cast<std::size_t>(n) : 0);
  for_each_stripe(n, h, [&](int stripe, int y0, int y1) {
    std::vector<std::int32_t> m2(hist != nullptr ? static_cast<std::size_t>(w) : 0);
    for (int y = y0; y < y1; ++y) {
      const std::uint8_t* r0 = src.ptr<std::uint8_t>(std::max(y - 1, 0));
      const std::uint8_t* r1 = src.ptr<std::uint8_t>(y);
      const std::uint8_t* r2 = src.ptr<std::uint8_t>(std::min(y + 1, h - 1));
      std::int16_t* gx = dx.ptr<std::int16_t>(y);
      std::int16_t* gy = dy.ptr<std::int16_t>(y);
      const auto scalar = [&](int x) {
        const int l = std::max(x - 1, 0);
        const int r = std::min(x + 1, w - 1);
        gx[x] = static_cast<std::int16_t>((r0[r] - r0[l]) + 2 * (r1[r] - r1[l]) + (r2[r] - r2[l]));
        gy[x] = static_cast<std::int16_t>((r2[l] + 2 * r2[x] + r2[r]) - (r0[l] + 2 * r0[x] + r0[r]));
      };
      scalar(0);
      int x = 1;
#if CV_SIMD128
      const auto at = [](const std::uint8_t* q) { return cv::v_reinterpret_as_s16(cv::v_load_expand(q)); };
      for (; x + 9 <= w; x += 8) {  // reads columns x - 1 .. x + 8 <= w - 1
        const cv::v_int16x8 a0 = at(r0 + x - 1);
        const cv::v_int16x8 b0 = at(r0 + x);
        const cv::v_int16x8 c0 = at(r0 + x + 1);
        const cv::v_int16x8 a1 = at(r1 + x - 1);
        const cv::v_int16x8 c1 = at(r1 + x + 1);
        const cv::v_int16x8 a2 = at(r2 + x - 1);
        const cv::v_int16x8 b2 = at(r2 + x);
        const cv::v_int16x8 c2 = at(r2 + x + 1);
        const cv::v_int16x8 d1 = c1 - a1;
        cv::v_store(gx + x, (c0 - a0) + (d1 + d1) + (c2 - a2));
        cv::v_store(gy + x, (a2 + b2 + b2 + c2) - (a0 + b0 + b0 + c0));
      }
#endif
      for (; x < w; ++x) scalar(x);
      if (hist != nullptr) {
        squared_magnitudes(gx, gy, w, m2.data());
        (n > 1 ? part[static_cast<std::size_t>(stripe)] : *hist).add(m2.data(), w);
      }
    }
  });
  for (MagnitudeHistogram& h_part : part) hist->merge(h_part);
}

/// Second difference along a row, L(x) = I(x-1) - 2 I(x) + I(x+1), for the n inner pixels
/// x = 1 .. n (into l[0 .. n-1]).
void row_second_difference(const std::uint8_t* r, int n, std::int16_t* l) {
  int x = 0;
#if CV_SIMD128
  for (; x + 8 <= n; x += 8) {
    const cv::v_int16x8 a = cv::v_reinterpret_as_s16(cv::v_load_expand(r + x));
    const cv::v_int16x8 b = cv::v_reinterpret_as_s16(cv::v_load_expand(r + x + 1));
    const cv::v_int16x8 c = cv::v_reinterpret_as_s16(cv::v_load_expand(r + x + 2));
    cv::v_store(l + x, (a + c) - (b + b));
  }
#endif
  for (; x < n; ++x) l[x] = static_cast<std::int16_t>(r[x] - 2 * r[x + 1] + r[x + 2]);
}

/// Sum over the inner pixels (1 <= x < cols - 1, 1 <= y < rows - 1) of |I * K| for the
/// Immerkaer kernel K = [1 -2 1; -2 4 -2; 1 -2 1], in exact integer arithmetic: the response is
/// L(y - 1) - 2 L(y) + L(y + 1) with the row second differences L (each row's computed once),
/// and |response| <= 16 * 255 fits in 16 bits.
std::int64_t immerkaer_abs_sum(const cv::Mat& grey) {
  const int n = grey.cols - 2;  // inner pixels per row
  const int inner_rows = grey.rows - 2;
  const int stripes = stripe_count(inner_rows, n);
  std::vector<std::int64_t> sums(static_cast<std::size_t>(stripes), 0);
  for_each_stripe(stripes, inner_rows, [&](int stripe, int first, int end) {
    // Responses of rows y = first + 1 .. end (inner rows are 1 .. rows - 2).
    std::vector<std::int16_t> ring(3 * static_cast<std::size_t>(n));
    std::int16_t* l0 = ring.data();
    std::int16_t* l1 = l0 + n;
    std::int16_t* l2 = l1 + n;
    row_second_difference(grey.ptr<std::uint8_t>(first), n, l0);
    row_second_difference(grey.ptr<std::uint8_t>(first + 1), n, l1);
    std::int64_t total = 0;
    for (int y = first + 1; y <= end; ++y) {
      row_second_difference(grey.ptr<std::uint8_t>(y + 1), n, l2);
      int x = 0;
#if CV_SIMD128
      const cv::v_int16x8 ones = cv::v_setall_s16(1);
      while (x + 8 <= n) {
        // Per chunk each int32 lane adds at most 2 * 4080 per step: 2^15 steps cannot overflow.
        cv::v_int32x4 acc = cv::v_setzero_s32();
        const int chunk_end = std::min(n, x + 8 * (1 << 15));
        for (; x + 8 <= chunk_end; x += 8) {
          const cv::v_int16x8 mid = cv::v_load(l1 + x);
          const cv::v_uint16x8 abs_r = cv::v_absdiff(cv::v_load(l0 + x) + cv::v_load(l2 + x), mid + mid);
          acc += cv::v_dotprod(cv::v_reinterpret_as_s16(abs_r), ones);
        }
        total += cv::v_reduce_sum(acc);
      }
#endif
      for (; x < n; ++x) total += std::abs(l0[x] - 2 * l1[x] + l2[x]);
      std::int16_t* const oldest = l0;
      l0 = l1;
      l1 = l2;
      l2 = oldest;
    }
    sums[static_cast<std::size_t>(stripe)] = total;
  });
  std::int64_t total = 0;
  for (const std::int64_t v : sums) total += v;
  return total;
}

/// Standard deviation of additive white noise in a grey image, by J. Immerkaer, "Fast Noise
/// Variance Estimation", Computer Vision and Image Understanding 64(2), 1996: the image is
/// filtered with the difference of two Laplacians [1 -2 1; -2 4 -2; 1 -2 1], which cancels
/// image structure up to second order, and sigma = sqrt(pi/2) * mean|response| / 6 over the
/// pixels whose 3x3 neighbourhood lies inside the image.
/// Texture and edges add to the estimate, so it over-estimates on busy images (harmless here:
/// it is only a floor).
double noise_sigma(const cv::Mat& grey) {
  if (grey.rows < 3 || grey.cols < 3) return 0.0;
  const double inner_area = static_cast<double>(grey.cols - 2) * static_cast<double>(grey.rows - 2);
  return std::sqrt(CV_PI / 2.0) * static_cast<double>(immerkaer_abs_sum(grey)) / (6.0 * inner_area);
}

/// Standard deviation of one Sobel component after the pre-blur, per unit of white noise: the
/// L2 norm of the impulse response of GaussianBlur(sigma) followed by Sobel-x.
double gradient_noise_gain_uncached(double blur_sigma_px) {
  const int half = static_cast<int>(std::ceil(4.0 * blur_sigma_px)) + 2;
  cv::Mat impulse = cv::Mat::zeros(2 * half + 1, 2 * half + 1, CV_32F);
  impulse.at<float>(half, half) = 1.0f;
  if (blur_sigma_px > 0.0) cv::GaussianBlur(impulse, impulse, cv::Size(0, 0), blur_sigma_px);
  cv::Mat gx;
  cv::Sobel(impulse, gx, CV_32F, 1, 0, 3);
  return cv::norm(gx, cv::NORM_L2);
}

/// gradient_noise_gain_uncached, remembered for the last sigma of each thread (callers use one
/// sigma for every image; the impulse response costs as much as a small image).
double gradient_noise_gain(double blur_sigma_px) {
  thread_local double cached_sigma = -1.0;
  thread_local double cached_gain = 0.0;
  if (blur_sigma_px != cached_sigma) {
    cached_gain = gradient_noise_gain_uncached(blur_sigma_px);
    cached_sigma = blur_sigma_px;
  }
  return cached_gain;
}

/// Buffers of detect_edges as large as the image, kept per thread between calls (cv::Mat::create
/// reuses them while the image size stays the same): allocating them anew each call costs more
/// than the computation, because large freed blocks go back to the OS and come back as page
/// faults. Not kept after images of more than kKeepPixels pixels.
struct Scratch {
  cv::Mat blurred;                                 // CV_8UC1
  cv::Mat dx;                                      // CV_16SC1
  cv::Mat dy;                                      // CV_16SC1
  cv::Mat map;                                     // CV_8UC1, (rows + 2) x (cols + 2), see canny_l2
  std::vector<std::vector<std::uint8_t*>> strong;  // strong pixels, per stripe
};
constexpr std::int64_t kKeepPixels = std::int64_t{1} << 22;

// ---- Canny non-maximum suppression and hysteresis -------------------------------------------
//
// The same computation as cv::Canny(dx, dy, edges, low, high, L2gradient = true) of OpenCV 4.x
// (modules/imgproc/src/canny.cpp), bit for bit, with the suppression vectorised and without
// branches per pixel: on photos most pixels pass the low threshold, and OpenCV's per-pixel
// direction branches are then mispredicted about every other pixel. Definition (OpenCV's):
//  * m = dx^2 + dy^2 (int), 0 outside the image; thresholds t -> floor(min(t, 32767)^2).
//  * direction from |dy| * 2^15 against |dx| * TG22 (TG22 = round(tan(22.5 deg) * 2^15)) and
//    against |dx| * (TG22 + 2^16) (tan 67.5 deg): horizontal gradient -> m > left, m >= right;
//    vertical -> m > above, m >= below; otherwise the diagonal of sign(dx * dy) (s = -1 when
//    dx ^ dy < 0) -> m > above[x - s], m > below[x + s].
//  * a pixel is a candidate when m > low and it is such a maximum, strong when also m > high;
//    the edges are the candidates 8-connected through candidates to a strong one.

constexpr int kTg22 = 13573;  // cv::Canny's TG22: round(0.41421356 * 2^15)

/// Map values, as in cv::Canny.
constexpr std::uint8_t kWeak = 0;    // candidate, edge if connected to a strong one
constexpr std::uint8_t kNone = 1;    // not an edge
constexpr std::uint8_t kStrong = 2;  // edge

#if CV_SIMD128
/// The vectorised part of suppress_row: one row's inputs (as suppress_row's) and the thresholds as
/// vectors, suppressing 16 pixels per block. Its functions are forced inline, so a block compiles to the
/// straight-line code of one loop body.
struct SimdRowSuppressor {
  const std::int32_t* mp;
  const std::int32_t* mc;
  const std::int32_t* mn;
  const std::int16_t* gx;
  const std::int16_t* gy;
  cv::v_int32x4 vlow;
  cv::v_int32x4 vhigh;
  cv::v_int32x4 one = cv::v_setall_s32(1);
  cv::v_int16x8 zero16 = cv::v_setzero_s16();
  cv::v_int32x4 zero32 = cv::v_setzero_s32();
  // pmaddwd of (2|dy|, |dx|) pairs with (2^14, -TG22): |dy| * 2^15 - |dx| * TG22.
  cv::v_int16x8 coef{16384, -kTg22, 16384, -kTg22, 16384, -kTg22, 16384, -kTg22};

  SimdRowSuppressor(const std::int32_t* mp_, const std::int32_t* mc_, const std::int32_t* mn_, const std::int16_t* gx_,
                    const std::int16_t* gy_, int low, int high)
      : mp(mp_), mc(mc_), mn(mn_), gx(gx_), gy(gy_), vlow(cv::v_setall_s32(low)), vhigh(cv::v_setall_s32(high)) {}

  /// Suppression of the 4 pixels at xq: dev = |dy| 2^15 - |dx| TG22, x16 = |dx| 2^16, neg =
  /// (dx ^ dy < 0); gives the map value and the strong mask (-1 / 0 per lane).
  [[gnu::always_inline]] void quad(int xq, const cv::v_int32x4& m, const cv::v_int32x4& dev, const cv::v_int32x4& x16,
                                   const cv::v_int32x4& neg, cv::v_int32x4& value, cv::v_int32x4& strong) const {
    const cv::v_int32x4 horizontal = dev < zero32;  // y < tg22x
    const cv::v_int32x4 vertical = dev > x16;       // y > tg22x + (x << 16)
    const cv::v_int32x4 up_l = cv::v_load(mp + xq - 1);
    const cv::v_int32x4 up_r = cv::v_load(mp + xq + 1);
    const cv::v_int32x4 dn_l = cv::v_load(mn + xq - 1);
    const cv::v_int32x4 dn_r = cv::v_load(mn + xq + 1);
    const cv::v_int32x4 pass_h = (m > cv::v_load(mc + xq - 1)) & ~(cv::v_load(mc + xq + 1) > m);  // m > l, m >= r
    const cv::v_int32x4 pass_v = (m > cv::v_load(mp + xq)) & ~(cv::v_load(mn + xq) > m);
    const cv::v_int32x4 pass_d = cv::v_select(neg, (m > up_r) & (m > dn_l), (m > up_l) & (m > dn_r));
    const cv::v_int32x4 pass = cv::v_select(horizontal, pass_h, cv::v_select(vertical, pass_v, pass_d));
    const cv::v_int32x4 cand = pass & (m > vlow);
    strong = cand & (m > vhigh);
    value = one + cand - (strong + strong);  // masks are -1: kNone, kWeak, kStrong
  }

  /// The direction terms of the 8 pixels at xh (magnitudes ma, mb), and their suppression.
  [[gnu::always_inline]] void half(int xh, const cv::v_int32x4& ma, const cv::v_int32x4& mb, cv::v_int32x4& value_a,
                                   cv::v_int32x4& value_b, cv::v_int32x4& strong_a, cv::v_int32x4& strong_b) const {
    const cv::v_int16x8 sx = cv::v_load(gx + xh);
    const cv::v_int16x8 sy = cv::v_load(gy + xh);
    const cv::v_int16x8 ax = cv::v_reinterpret_as_s16(cv::v_abs(sx));
    const cv::v_int16x8 ay = cv::v_reinterpret_as_s16(cv::v_abs(sy));
    cv::v_int16x8 z0;
    cv::v_int16x8 z1;
    cv::v_zip(ay + ay, ax, z0, z1);
    cv::v_uint32x4 ax0;
    cv::v_uint32x4 ax1;
    cv::v_expand(cv::v_reinterpret_as_u16(ax), ax0, ax1);
    cv::v_int32x4 neg0;  // dx ^ dy < 0: the diagonal is the anti-diagonal (s = -1)
    cv::v_int32x4 neg1;
    cv::v_expand((sx ^ sy) < zero16, neg0, neg1);
    quad(xh, ma, cv::v_dotprod(z0, coef), cv::v_reinterpret_as_s32(ax0 << 16), neg0, value_a, strong_a);
    quad(xh + 4, mb, cv::v_dotprod(z1, coef), cv::v_reinterpret_as_s32(ax1 << 16), neg1, value_b, strong_b);
  }

  /// The 16 pixels at x: their map values stored, the strong ones pushed; a block with no magnitude over
  /// the low threshold is all kNone at once.
  [[gnu::always_inline]] void block(int x, std::uint8_t* map, std::vector<std::uint8_t*>& stack) const {
    const cv::v_int32x4 m0 = cv::v_load(mc + x);
    const cv::v_int32x4 m1 = cv::v_load(mc + x + 4);
    const cv::v_int32x4 m2 = cv::v_load(mc + x + 8);
    const cv::v_int32x4 m3 = cv::v_load(mc + x + 12);
    if (!cv::v_check_any((m0 > vlow) | (m1 > vlow) | (m2 > vlow) | (m3 > vlow))) {
      cv::v_store(map + x, cv::v_setall_u8(kNone));
      return;
    }
    cv::v_int32x4 value[4];
    cv::v_int32x4 strong[4];
    half(x, m0, m1, value[0], value[1], strong[0], strong[1]);
    half(x + 8, m2, m3, value[2], value[3], strong[2], strong[3]);
    cv::v_store(map + x, cv::v_pack_u(cv::v_pack(value[0], value[1]), cv::v_pack(value[2], value[3])));
    int bits = cv::v_signmask(cv::v_pack(cv::v_pack(strong[0], strong[1]), cv::v_pack(strong[2], strong[3])));
    for (; bits != 0; bits &= bits - 1) stack.push_back(map + x + std::countr_zero(static_cast<unsigned>(bits)));
  }
};
#endif

/// The scalar suppression of pixels x0 .. n-1 of a row (the ones the vectorised blocks leave, or all of
/// them without SIMD), with the same inputs and result as suppress_row.
[[gnu::always_inline]] inline void suppress_row_scalar(const std::int32_t* mp, const std::int32_t* mc,
                                                       const std::int32_t* mn, const std::int16_t* gx,
                                                       const std::int16_t* gy, int x0, int n, int low, int high,
                                                       std::uint8_t* map, std::vector<std::uint8_t*>& stack) {
  for (int x = x0; x < n; ++x) {
    const int m = mc[x];
    bool cand = false;
    if (m > low) {
      const int xs = gx[x];
      const int ys = gy[x];
      const int ax = std::abs(xs);
      const int ay = std::abs(ys) << 15;
      const int tg22x = ax * kTg22;
      if (ay < tg22x) {
        cand = m > mc[x - 1] && m >= mc[x + 1];
      } else if (ay > tg22x + (ax << 16)) {
        cand = m > mp[x] && m >= mn[x];
      } else {
        const int s = (xs ^ ys) < 0 ? -1 : 1;
        cand = m > mp[x - s] && m > mn[x + s];
      }
    }
    if (!cand) {
      map[x] = kNone;
    } else if (m > high) {
      map[x] = kStrong;
      stack.push_back(map + x);
    } else {
      map[x] = kWeak;
    }
  }
}

/// One row of suppression: fills map[0 .. n-1] with kWeak / kNone / kStrong and pushes the strong
/// pixels. mp, mc, mn: magnitudes of the previous, current and next row, each readable at -1 and n
/// (zeros there). 16 pixels at a time with SIMD, the rest one by one.
void suppress_row(const std::int32_t* mp, const std::int32_t* mc, const std::int32_t* mn, const std::int16_t* gx,
                  const std::int16_t* gy, int n, int low, int high, std::uint8_t* map,
                  std::vector<std::uint8_t*>& stack) {
  int x = 0;
#if CV_SIMD128
  const SimdRowSuppressor simd(mp, mc, mn, gx, gy, low, high);
  for (; x + 16 <= n; x += 16) simd.block(x, map, stack);
#endif
  suppress_row_scalar(mp, mc, mn, gx, gy, x, n, low, high, map, stack);
}

/// cv::Canny(dx, dy, edges, low_thresh, high_thresh, true) for CV_16SC1 derivatives and
/// 0 <= low_thresh <= high_thresh: CV_8UC1, 255 = edge.
cv::Mat canny_l2(const cv::Mat& dx, const cv::Mat& dy, double low_thresh, double high_thresh, Scratch& scratch) {
  const int w = dx.cols;
  const int h = dx.rows;
  low_thresh = std::min(32767.0, low_thresh);
  high_thresh = std::min(32767.0, high_thresh);
  const int low = cvFloor(low_thresh * low_thresh);
  const int high = cvFloor(high_thresh * high_thresh);

  // Map with a one-pixel kNone border, so hysteresis needs no bounds checks.
  const std::ptrdiff_t step = w + 2;
  scratch.map.create(h + 2, w + 2, CV_8UC1);
  std::uint8_t* map = scratch.map.ptr<std::uint8_t>();
  std::fill_n(map, step, kNone);
  std::fill_n(map + (h + 1) * step, step, kNone);

  // Suppression in row stripes, each with its own three magnitude rows (previous, current,
  // next; a zero on each side) and its own strong pixels.
  const int n = stripe_count(h, w);
  std::vector<std::vector<std::uint8_t*>>& strong = scratch.strong;
  strong.resize(static_cast<std::size_t>(n));
  for_each_stripe(n, h, [&](int stripe, int y0, int y1) {
    std::vector<std::int32_t> ring(3 * static_cast<std::size_t>(step), 0);
    std::int32_t* mp = ring.data() + 1;
    std::int32_t* mc = mp + step;
    std::int32_t* mn = mc + step;
    if (y0 > 0) squared_magnitudes(dx.ptr<std::int16_t>(y0 - 1), dy.ptr<std::int16_t>(y0 - 1), w, mp);
    squared_magnitudes(dx.ptr<std::int16_t>(y0), dy.ptr<std::int16_t>(y0), w, mc);
    std::vector<std::uint8_t*>& stack = strong[static_cast<std::size_t>(stripe)];
    stack.clear();
    for (int y = y0; y < y1; ++y) {
      if (y + 1 < h) {
        squared_magnitudes(dx.ptr<std::int16_t>(y + 1), dy.ptr<std::int16_t>(y + 1), w, mn);
      } else {
        std::fill_n(mn, w, 0);
      }
      std::uint8_t* row = map + (y + 1) * step;
      row[0] = row[w + 1] = kNone;
      suppress_row(mp, mc, mn, dx.ptr<std::int16_t>(y), dy.ptr<std::int16_t>(y), w, low, high, row + 1, stack);
      std::int32_t* const oldest = mp;
      mp = mc;
      mc = mn;
      mn = oldest;
    }
  });
  std::vector<std::uint8_t*>& stack = strong[0];
  for (std::size_t k = 1; k < strong.size(); ++k) stack.insert(stack.end(), strong[k].begin(), strong[k].end());

  // Hysteresis: grow the strong pixels through 8-connected candidates.
  const std::array<std::ptrdiff_t, 8> around = {-step - 1, -step, -step + 1, -1, 1, step - 1, step, step + 1};
  while (!stack.empty()) {
    std::uint8_t* const p = stack.back();
    stack.pop_back();
    for (const std::ptrdiff_t o : around) {
      if (p[o] == kWeak) {
        p[o] = kStrong;
        stack.push_back(p + o);
      }
    }
  }

  cv::Mat edges(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* src = map + (y + 1) * step + 1;
    std::uint8_t* dst = edges.ptr<std::uint8_t>(y);
    int x = 0;
#if CV_SIMD128
    const cv::v_uint8x16 strong = cv::v_setall_u8(kStrong);
    for (; x + 16 <= w; x += 16) cv::v_store(dst + x, cv::v_load(src + x) == strong);
#endif
    for (; x < w; ++x) dst[x] = src[x] == kStrong ? 255 : 0;
  }
  return edges;
}

}  // namespace

EdgeMap detect_edges(const cv::Mat& grey, const EdgeParams& p) {
  if (grey.empty() || grey.type() != CV_8UC1) {
    throw hk::ArgumentError("detect_edges: expected a non-empty CV_8UC1 image");
  }
  for (const double v : {p.blur_sigma_px, p.canny_low, p.canny_high}) {
    if (!std::isfinite(v) || v < 0.0) {
      throw hk::ArgumentError("detect_edges: parameters must be finite and >= 0");
    }
  }
  thread_local Scratch scratch;
  cv::Mat blurred = grey;
  if (p.blur_sigma_px > 0.0) {
    // Into our own buffer: blurring into `blurred` would blur the caller's image in place.
    cv::GaussianBlur(grey, scratch.blurred, cv::Size(0, 0), p.blur_sigma_px, p.blur_sigma_px, cv::BORDER_REPLICATE);
    blurred = scratch.blurred;
  }
  cv::Mat& dx = scratch.dx;
  cv::Mat& dy = scratch.dy;
  EdgeMap out;
  if (p.canny_high > 0.0) {
    sobel_3x3(blurred, dx, dy, nullptr);
    out.high = p.canny_high;
  } else {
    MagnitudeHistogram hist;
    sobel_3x3(blurred, dx, dy, &hist);
    // Pure noise gives a Rayleigh-distributed magnitude with scale sigma_noise * gain, which
    // exceeds kNoiseSigmas scales with probability exp(-kNoiseSigmas^2 / 2) = 4e-6.
    const double noise_floor = kNoiseSigmas * noise_sigma(grey) * gradient_noise_gain(p.blur_sigma_px);
    // On images with few, clean edges (logos, silhouettes) the quantile sits at the strongest
    // edge; an edge half as strong as the strongest one is still a sure edge.
    const GradientStats st = hist.stats();
    out.high = std::max({std::min(st.percentile, kMaxFraction * st.max), noise_floor, kMinAutoHigh});
  }
  out.low = p.canny_low > 0.0 ? p.canny_low : kLowRatio * out.high;
  if (out.low > out.high) std::swap(out.low, out.high);  // as cv::Canny does; report what it used
  out.edges = canny_l2(dx, dy, out.low, out.high, scratch);
  if (static_cast<std::int64_t>(grey.rows) * grey.cols > kKeepPixels) scratch = Scratch{};
  return out;
}

}  // namespace hk::vision
