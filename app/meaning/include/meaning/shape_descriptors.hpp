#pragma once
/// @file shape_descriptors.hpp
/// What the kiosk can see of each shape by itself: its form (shape_form.hpp), its colour (colour_name.hpp),
/// its size, and whether it is a speck too small to count. Built with the scene, off the window thread, and
/// kept with it in the scene cache; said as guesses.

#include <opencv2/core.hpp>

#include <vector>

#include "haptics/multires.hpp"
#include "haptics/scene.hpp"
#include "meaning/colour_name.hpp"
#include "meaning/shape_form.hpp"
#include "vision/mapping.hpp"

namespace hk::meaning {

/// What one shape looks like.
struct ShapeDescriptor {
  FormGuess form;           ///< its form, from the coarse wavelet level
  bool has_colour = false;  ///< colour is known (a picture to read it from)
  ColourName colour;  ///< inside a closed shape; along a line drawing's lines (ink); none for a photograph's open edge
  double size_cm = 0.0;   ///< the longer side of its bounding box in the workspace [cm]
  double length_m = 0.0;  ///< its level-0 length [m]
  /// Shorter than the tour's least shape (TourParams::min_shape_length_m, 6 mm): not counted, described or
  /// toured as a shape.
  bool speck = false;
};

/// What the picture's pixels say of the shapes: the BGR `picture` (8-bit, 3 channels; empty: no colours),
/// `px_to_m` mapping its pixels to the workspace, and whether it is a line drawing (its outlines are ink on
/// paper, so a closed outline's colour is the ink's, not the paper's inside it).
struct PictureColours {
  cv::Mat picture;
  vision::PxToM px_to_m{1, 0, 0};
  bool line_drawing = false;
};

/// One descriptor per polyline: `polylines[i]` [m] built into `scene` as the curve whose source_index is i
/// (a polyline the scene skipped: its form from its own points). The form is read at the coarsest level of
/// the curve with at least 32 points whose largest deviation (CurveInfo::max_error_m) is at most 3 % of the curve's
/// bounding-box diagonal, the colour as the median in CIELAB inside a closed shape (its outline filled, less the
/// closed shapes inside it, 2 px in from both: a thick stroke drawn as a square is the colour of its stroke, a wing
/// the colour around its spots) or along a line drawing's line; an open edge of a photograph has none (its pixels
/// blend two colours). Cost: O(points) a shape, O(shapes²) to find the shapes inside, plus O(pixels) of each closed
/// shape's box.
std::vector<ShapeDescriptor> describe_shapes(const std::vector<Polyline>& polylines, const Scene& scene,
                                             const PictureColours& colours);

/// The same without a scene: the form from each polyline's own points (tutorial shapes, tests).
std::vector<ShapeDescriptor> describe_shapes(const std::vector<Polyline>& polylines, const PictureColours& colours);

}  // namespace hk::meaning
