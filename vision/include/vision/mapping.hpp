#pragma once
/// @file mapping.hpp
/// Pixel <-> workspace mapping (DESIGN.md "Frames and units").
///
/// The hand must feel the picture undistorted, so the map is one uniform scale plus an offset
/// (never separate x and y scales), and the v axis (down in the image) is flipped into y (away
/// from the user, up on screen).

namespace hk::vision {

/// Affine map from image pixels to workspace metres:
///   x_m = offset_x_m + scale_m_per_px * u,   y_m = offset_y_m - scale_m_per_px * v.
/// Pixels: u right, v down, origin at the centre of the top-left pixel [px].
/// Workspace: origin at the centre of the usable rectangle, x right, y away from the user [m].
struct PxToM {
  double scale_m_per_px;  ///< metres per pixel, > 0 [m/px]
  double offset_x_m;      ///< x of pixel u = 0 [m]
  double offset_y_m;      ///< y of pixel v = 0 [m]

  /// Workspace x [m] of pixel column u [px].
  double x_m(double u) const;
  /// Workspace y [m] of pixel row v [px].
  double y_m(double v) const;
  /// Pixel column u [px] of workspace x [m] (inverse of x_m).
  double u_px(double x_m) const;
  /// Pixel row v [px] of workspace y [m] (inverse of y_m).
  double v_px(double y_m) const;
};

/// The largest uniform map that fits the whole image into a width_m x height_m rectangle centred
/// on the workspace origin, keeping the aspect ratio.
///
/// scale = min(width_m / width_px, height_m / height_px), so the outer edges of the image's
/// pixels (u from -0.5 to width_px - 0.5) span at most width_m, and likewise in height. The image
/// centre ((width_px - 1) / 2, (height_px - 1) / 2) maps to (0, 0).
///
/// @param width_px, height_px image size [px], > 0.
/// @param width_m, height_m   usable rectangle of the device [m], > 0 and finite
///                            (default workspace 0.14 m x 0.09 m, DESIGN.md).
/// @throws hk::ArgumentError on a non-positive or non-finite size.
PxToM fit_to_workspace(int width_px, int height_px, double width_m, double height_m);

}  // namespace hk::vision
