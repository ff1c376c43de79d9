// Pixel <-> workspace mapping (see mapping.hpp for why it is one uniform scale).

#include "vision/mapping.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hk/error.hpp"

namespace hk::vision {

double PxToM::x_m(double u) const { return offset_x_m + scale_m_per_px * u; }
double PxToM::y_m(double v) const { return offset_y_m - scale_m_per_px * v; }
double PxToM::u_px(double x) const { return (x - offset_x_m) / scale_m_per_px; }
double PxToM::v_px(double y) const { return (offset_y_m - y) / scale_m_per_px; }

PxToM fit_to_workspace(int width_px, int height_px, double width_m, double height_m) {
  if (width_px <= 0 || height_px <= 0) {
    throw hk::ArgumentError("fit_to_workspace: image size must be positive");
  }
  if (!(std::isfinite(width_m) && std::isfinite(height_m) && width_m > 0.0 && height_m > 0.0)) {
    throw hk::ArgumentError("fit_to_workspace: workspace size must be positive and finite");
  }
  const double scale = std::min(width_m / width_px, height_m / height_px);
  // Centre pixel ((w - 1) / 2, (h - 1) / 2) -> (0, 0).
  return PxToM{scale, -scale * (width_px - 1) / 2.0, scale * (height_px - 1) / 2.0};
}

}  // namespace hk::vision
