#include "runtime/coverage.hpp"

#include <cmath>

namespace hk::app {
namespace {

long long cell_key(long long ix, long long iy) { return (ix << 32) ^ (iy & 0xffffffffLL); }

}  // namespace

CoverageMeter::CoverageMeter(double radius_m)
    : radius_m_(radius_m > 0.0 && std::isfinite(radius_m) ? radius_m : 0.001) {}

void CoverageMeter::add(Vec2 proxy_m, int curve_a, int curve_b) {
  for (int c : {curve_a, curve_b}) {
    if (c < 0) continue;
    if (static_cast<std::size_t>(c) >= touched_.size()) touched_.resize(static_cast<std::size_t>(c) + 1, false);
    touched_[static_cast<std::size_t>(c)] = true;
  }
  if (!is_finite(proxy_m)) return;
  // Keep a position only after the proxy moved an eighth of the radius: a resting proxy adds nothing.
  if (distance(proxy_m, last_kept_) < radius_m_ / 8) return;
  last_kept_ = proxy_m;
  const long long ix = static_cast<long long>(std::floor(proxy_m.x / radius_m_));
  const long long iy = static_cast<long long>(std::floor(proxy_m.y / radius_m_));
  cells_[cell_key(ix, iy)].push_back(proxy_m);
}

bool CoverageMeter::reached(Vec2 p) const {
  const long long ix = static_cast<long long>(std::floor(p.x / radius_m_));
  const long long iy = static_cast<long long>(std::floor(p.y / radius_m_));
  const double r2 = radius_m_ * radius_m_;
  for (long long dx = -1; dx <= 1; ++dx)
    for (long long dy = -1; dy <= 1; ++dy) {
      const auto it = cells_.find(cell_key(ix + dx, iy + dy));
      if (it == cells_.end()) continue;
      for (const Vec2& q : it->second)
        if (length_sq(q - p) <= r2) return true;
    }
  return false;
}

Coverage CoverageMeter::measure(const Scene& scene) const {
  Coverage cov;
  cov.curves = scene.curve_count();
  double total = 0.0, near = 0.0;
  const double step = radius_m_ / 4;
  for (std::size_t c = 0; c < scene.curve_count(); ++c) {
    const CurveInfo& ci = scene.curve(c);
    const Vec2* p = scene.points(c, 0);
    const std::uint32_t n = ci.point_count[0];
    const std::uint32_t segments = ci.closed ? n : (n > 0 ? n - 1 : 0);
    for (std::uint32_t i = 0; i < segments; ++i) {
      const Vec2 a = p[i], b = p[(i + 1) % n];
      const double len = distance(a, b);
      if (!(len > 0.0)) continue;
      // Each piece of length ≤ step counts by its midpoint.
      const int pieces = static_cast<int>(std::ceil(len / step));
      for (int k = 0; k < pieces; ++k) {
        const double piece = (k + 1 < pieces) ? step : len - step * (pieces - 1);
        total += piece;
        if (reached(lerp(a, b, (k * step + 0.5 * piece) / len))) near += piece;
      }
    }
    if (c < touched_.size() && touched_[c]) ++cov.curves_touched;
  }
  cov.length_fraction = total > 0.0 ? near / total : 0.0;
  return cov;
}

}  // namespace hk::app
