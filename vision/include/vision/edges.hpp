#pragma once
/// @file edges.hpp
/// Edge detection: the first half of the seed paper's "edge detection and linking" (§5, Canny).
///
/// Kiosk images are unknown in advance (photos, scanned pages, black-on-white silhouettes), so the
/// Canny thresholds are chosen from each image's own gradient statistics unless the operator
/// fixes them.

#include <opencv2/core.hpp>

namespace hk::vision {

/// Parameters of detect_edges. Pixel quantities are at the resolution of the grey image given.
struct EdgeParams {
  double blur_sigma_px = 1.5;  ///< Gaussian pre-blur standard deviation [px]; 0 = no blur
  double canny_low = 0;        ///< hysteresis low threshold, Sobel-3x3 L2 units; 0 = 0.4 * high
  double canny_high = 0;       ///< hysteresis high threshold, Sobel-3x3 L2 units; 0 = from image
};

/// Edge pixels and the thresholds that produced them.
struct EdgeMap {
  cv::Mat edges;  ///< CV_8UC1, same size as the grey input, 255 = edge pixel, 0 = not
  double low;     ///< low hysteresis threshold used (Sobel-3x3 L2 gradient magnitude units)
  double high;    ///< high hysteresis threshold used (same units)
};

/// Canny edge detection (J. Canny, "A Computational Approach to Edge Detection", IEEE PAMI 8(6),
/// 1986) with automatic thresholds.
///
/// Steps: cv::GaussianBlur (sigma = blur_sigma_px, replicated border); 3x3 Sobel derivatives
/// (replicated border); Canny's non-maximum suppression and hysteresis on those derivatives
/// with the L2 gradient norm sqrt(gx^2 + gy^2). The magnitude of a blurred step of height D grey
/// levels is about 8 * D / (sigma * sqrt(2 pi)) in these units. The Sobel and Canny steps are
/// our own vectorised code, but the edge map is bit for bit that of cv::Sobel(..., CV_16S, ...,
/// BORDER_REPLICATE) followed by cv::Canny(dx, dy, edges, low, high, L2gradient = true) (all
/// integer arithmetic; like cv::Sobel, a submatrix input sees its parent's pixels beyond its
/// edges).
///
/// Automatic high threshold (when canny_high == 0), after the rule of MATLAB's
/// edge(I, 'canny') (a fixed fraction of pixels are non-edges, "ThresholdRatio" low = 0.4 high;
/// MathWorks documentation), adapted so that it works on the mostly flat images a kiosk sees
/// (documents, silhouettes, logos) as well as on photos:
///   high = max(min(P90, 0.5 * Gmax), 5 * s_noise, kMinAutoHigh),   low = 0.4 * high,
/// where P90 is the 90th percentile of the non-zero gradient magnitudes only (flat areas do not
/// count), Gmax the largest magnitude (on images with few clean edges P90 is the strongest edge
/// itself, and an edge half as strong is still a sure edge), and s_noise the Rayleigh scale of
/// the magnitude of pure noise: sigma_noise (Immerkaer, "Fast Noise Variance Estimation", CVIU
/// 64(2), 1996) times the noise gain of blur + Sobel, so that noise alone exceeds high with
/// probability exp(-12.5) ~ 4e-6 per pixel. kMinAutoHigh (= 20, a blurred step of about 10 grey
/// levels at sigma 1.5) keeps faint shading and JPEG blocking of nearly uniform images out.
/// Given thresholds are used as they are (low = 0.4 * high when only high is given).
///
/// Cost: O(pixels), no sorting. Like cv::Canny, the passes run in row stripes on OpenCV's
/// threads (cv::setNumThreads(1) makes them serial); the result does not depend on the number of
/// threads. Each calling thread keeps its scratch images (about 6 bytes per pixel) between
/// calls, for images of up to 2^22 pixels; concurrent calls from different threads are safe.
///
/// @param grey CV_8UC1 image, non-empty.
/// @throws hk::ArgumentError if grey is empty or not CV_8UC1, or a parameter is negative or
///         not finite.
EdgeMap detect_edges(const cv::Mat& grey, const EdgeParams& p);

/// Floor of the automatically chosen high threshold (Sobel-3x3 L2 units); see detect_edges.
inline constexpr double kMinAutoHigh = 20.0;

}  // namespace hk::vision
