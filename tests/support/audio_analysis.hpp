#pragma once
// Signal analysis for the audio tests, written independently of the synthesiser: onsets from the
// energy of the first difference (a high-pass that favours attacks), a plain DFT for spectra.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

namespace hk::test {

/// Energy of the first difference x[n] − x[n−1] in windows of `win` samples every `hop` samples.
inline std::vector<double> hf_energy(const std::vector<float>& x, std::size_t hop = 24, std::size_t win = 48) {
  std::vector<double> e;
  for (std::size_t start = 0; start + win <= x.size(); start += hop) {
    double s = 0;
    for (std::size_t n = std::max<std::size_t>(start, 1); n < start + win; ++n) {
      const double d = static_cast<double>(x[n]) - x[n - 1];
      s += d * d;
    }
    e.push_back(s);
  }
  return e;
}

/// Onset times [samples]: a 0.5 ms window (hop 0.25 ms) whose high-frequency energy is above `floor`
/// and `rise` times the largest of the windows 0.75–1.5 ms before it. The time reported is the END of the
/// window, so an onset is never reported before the sound that caused it. After an onset, 1 ms is skipped.
/// The short windows resolve clicks 2 ms apart (contact chatter), about the ear's own limit.
inline std::vector<std::size_t> onsets(const std::vector<float>& x, double floor = 1e-4, double rise = 4.0,
                                       int rate = 48000) {
  const std::size_t hop = static_cast<std::size_t>(rate / 4000), win = 2 * hop;
  const std::vector<double> e = hf_energy(x, hop, win);
  const std::size_t back_lo = 3, back_hi = 6, skip = 4;  // in hops: 0.75 ms, 1.5 ms, 1 ms
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < e.size(); ++i) {
    double before = 0;
    for (std::size_t k = back_lo; k <= back_hi; ++k) before = std::max(before, i >= k ? e[i - k] : 0.0);
    if (e[i] >= floor && e[i] >= rise * before) {
      out.push_back(i * hop + win);
      i += skip;
    }
  }
  return out;
}

/// RMS of x[from, to).
inline double rms(const std::vector<float>& x, std::size_t from, std::size_t to) {
  to = std::min(to, x.size());
  if (from >= to) return 0;
  double s = 0;
  for (std::size_t i = from; i < to; ++i) s += static_cast<double>(x[i]) * x[i];
  return std::sqrt(s / static_cast<double>(to - from));
}

/// Peak |x| in [from, to).
inline double peak(const std::vector<float>& x, std::size_t from, std::size_t to) {
  double p = 0;
  for (std::size_t i = from; i < std::min(to, x.size()); ++i) p = std::max(p, std::fabs(static_cast<double>(x[i])));
  return p;
}

/// Magnitude spectrum of x[from, from+n) with a Hann window, bins every rate/n Hz up to rate/2 (direct DFT).
inline std::vector<double> spectrum(const std::vector<float>& x, std::size_t from, std::size_t n) {
  std::vector<double> mag(n / 2 + 1, 0.0);
  for (std::size_t k = 0; k <= n / 2; ++k) {
    double re = 0, im = 0;
    for (std::size_t i = 0; i < n && from + i < x.size(); ++i) {
      const double w = 0.5 - 0.5 * std::cos(2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n - 1));
      const double ph = -2 * std::numbers::pi * static_cast<double>(k * i % n) / static_cast<double>(n);
      re += w * x[from + i] * std::cos(ph);
      im += w * x[from + i] * std::sin(ph);
    }
    mag[k] = std::sqrt(re * re + im * im);
  }
  return mag;
}

/// Spectral centroid [Hz] of x[from, from+n).
inline double spectral_centroid(const std::vector<float>& x, std::size_t from, std::size_t n, int rate = 48000) {
  const std::vector<double> m = spectrum(x, from, n);
  double num = 0, den = 0;
  for (std::size_t k = 0; k < m.size(); ++k) {
    num += m[k] * static_cast<double>(k) * rate / static_cast<double>(n);
    den += m[k];
  }
  return den > 0 ? num / den : 0;
}

/// Frequency of the largest spectral peak [Hz] of x[from, from+n), refined by parabolic interpolation
/// of the log magnitudes of the peak bin and its neighbours.
inline double dominant_frequency(const std::vector<float>& x, std::size_t from, std::size_t n, int rate = 48000) {
  const std::vector<double> m = spectrum(x, from, n);
  std::size_t k = 1;
  for (std::size_t i = 1; i + 1 < m.size(); ++i) {
    if (m[i] > m[k]) k = i;
  }
  const double a = std::log(m[k - 1] + 1e-30), b = std::log(m[k] + 1e-30), c = std::log(m[k + 1] + 1e-30);
  const double delta = 0.5 * (a - c) / (a - 2 * b + c);
  return (static_cast<double>(k) + delta) * rate / static_cast<double>(n);
}

/// Time [samples] from `from` until the 1 ms RMS envelope last exceeds `fraction` of its maximum in [from, to).
inline std::size_t decay_length(const std::vector<float>& x, std::size_t from, std::size_t to, double fraction = 0.1) {
  const std::size_t w = 48;
  double mx = 0;
  for (std::size_t i = from; i + w <= to; i += w) mx = std::max(mx, rms(x, i, i + w));
  std::size_t last = from;
  for (std::size_t i = from; i + w <= to; i += w) {
    if (rms(x, i, i + w) >= fraction * mx) last = i + w;
  }
  return last - from;
}

}  // namespace hk::test
