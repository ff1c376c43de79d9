#pragma once
/// @file texture.hpp
/// Texture out: an edge in texture (grain, gravel, fur, print) is surrounded by edges like
/// itself; an object's outline stands alone. Surround inhibition after Grigorescu, Petkov & Westenberg,
/// "Contour detection based on nonclassical receptive field inhibition", IEEE TIP 12(7), 2003: the gradient
/// magnitude around each pixel, in an annulus that leaves the pixel itself out, is taken off its own
/// magnitude; an edge that keeps enough of it stands out.

#include <vector>

#include <opencv2/core.hpp>

#include "vision/linking.hpp"

namespace hk::vision {

/// Outer σ / inner σ of the surround annulus (Grigorescu et al. use 4).
inline constexpr double kSurroundRatio = 4.0;
/// A chain stands out when at least this share of its points keeps Canny's low threshold after inhibition.
inline constexpr double kStandOutShare = 0.4;

/// `src` (CV_32F) averaged over the annulus
///   w(r) ∝ exp(−r²/2σo²) − exp(−r²/2σi²),  σi = sigma, σo = kSurroundRatio·sigma,
/// normalised to sum 1: zero at the pixel itself, non-negative everywhere (σo > σi), largest a little over σi
/// away and fading like the outer Gaussian — the role of Grigorescu et al.'s DoG⁺ annulus (eq. 6), as a
/// difference of two separable Gaussians: (G_o∗src − (σi/σo)²·G_i∗src) / (1 − (σi/σo)²). Replicated border.
/// @throws hk::ArgumentError if src is not a non-empty CV_32FC1 image or sigma is not finite and > 0.
cv::Mat surround_mean(const cv::Mat& src, double sigma);

/// The surround of the gradient at every point of every chain (out[k][i] at chains[k].points_px[i], integer
/// pixels of `grey`): the gradient magnitude m (3x3 Sobel L2 of `grey` blurred at blur_sigma_px, replicated
/// border: the units of Extraction::point_strength and Canny's thresholds) averaged over the annulus of
/// surround_mean at σ = max(blur_sigma_px, 1) — Grigorescu et al.'s isotropic inhibition term (§II-B). The
/// annulus is smooth, so the average is taken at half resolution (area-averaged, σ halved) and enlarged back
/// bilinearly. Their anisotropic variants (weighting the surround by the angle between the gradients) were
/// measured and not kept: they spare noise (docs/PERFORMANCE.md, "Texture out before edges").
/// `grey` is not modified.
/// @param grey  CV_8UC1, not empty.
/// @throws hk::ArgumentError for an empty or non-CV_8UC1 image or a negative or non-finite sigma.
PointValues chain_surround(const cv::Mat& grey, double blur_sigma_px, const std::vector<Chain>& chains);

/// Texture test of one chain, after Grigorescu et al.'s inhibition (the inhibited strength of a point is
/// strength − alpha · surround): true = an outline that stands out from its surround (kept) when at least
/// kStandOutShare of its points keep an inhibited strength of at least `low` (Canny's low threshold: they
/// would still be edge pixels); false = texture. An edge in noise or grain is about as strong as its
/// surround and fails; an object's outline against a plainer background keeps most of its strength. Linked
/// chains are tested whole, so an outline is kept or dropped whole, never cut into pieces (inhibiting pixels
/// before linking, as Grigorescu et al. do, broke the coins' outlines: docs/PERFORMANCE.md).
/// strength and surround: per point (a missing surround value counts as 0); alpha >= 0 (0 keeps every chain
/// whose points reach low); an empty chain is kept.
bool stands_out(const std::vector<double>& strength, const std::vector<double>& surround, double alpha, double low);

}  // namespace hk::vision
