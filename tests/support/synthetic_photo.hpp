#pragma once
/// @file synthetic_photo.hpp
/// Synthetic camera photos of a picture held under the kiosk's camera, shared by
/// tests/vision/test_page.cpp and bench/rectify.cpp: a picture warped by a known homography onto a generated,
/// textured backdrop (a wooden table top or a cloth of coloured blobs), then lit unevenly, blurred and made
/// noisy as a cheap camera would. Deterministic from the seed (cv::RNG). Header-only; OpenCV core and imgproc.
///
/// Geometry: frame pixels with x right, y down and the origin at the centre of the top-left pixel (as
/// vision/page.hpp), so a picture of W x H pixels spans [-0.5, W - 0.5] x [-0.5, H - 0.5] in its own pixels and
/// its corners are mapped by the homography onto SyntheticPhoto::corners_px. The picture's edge is drawn with
/// area-like anti-aliasing: its 50 % coverage lies exactly on the true outline.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "textures.hpp"

namespace hk::test {

/// What the picture lies on.
enum class Backdrop {
  wood,   ///< a brown wooden table top (hk::test::wood_texture, tinted): mid grey with dark growth rings
  blobs,  ///< a cloth of soft random blobs in random colours (grey 30 to 225) on a mid background
};

/// How the picture is held and photographed. Ranges are those the tests cover.
struct PhotoConditions {
  double rotation_deg = 0.0;   ///< the picture turned in the frame, counter-clockwise on screen, [-30, 30] degrees
  double perspective = 0.0;    ///< keystone: the two corners of one (seeded) side moved inward along that side by
                               ///< this share of its length, the other two by up to a third of it, [0, 0.15]
  double blur_sigma_px = 0.0;  ///< Gaussian blur of the whole frame (focus), [0, 1.5] px
  double noise_sigma = 0.0;    ///< Gaussian sensor noise per channel, [0, 6] grey levels
  bool uneven_light = false;   ///< a multiplicative light gradient from 0.6 to 1.1 across the frame (seeded direction)
  Backdrop backdrop = Backdrop::wood;
  double fill = 0.72;  ///< the picture's bounding box spans at most this share of the frame's width and height
  cv::Point2d offset_px{0,
                        0};  ///< the picture's centre relative to the frame's centre [px]; may move it out of the frame
  std::uint64_t seed = 1;    ///< seeds the backdrop, the keystone side, the light's direction and the noise
};

/// A synthetic photo and its truth.
struct SyntheticPhoto {
  cv::Mat frame;                          ///< CV_8UC3 (BGR)
  std::array<cv::Point2d, 4> corners_px;  ///< the picture's own top-left, top-right, bottom-right, bottom-left corners
                                          ///< in frame pixels (may lie outside the frame when offset_px moves it out)
  cv::Matx33d homography;                 ///< picture pixels -> frame pixels
};

/// A generated backdrop, w x h, CV_8UC3, deterministic from `seed`.
inline cv::Mat backdrop_texture(Backdrop kind, int w, int h, std::uint64_t seed) {
  if (kind == Backdrop::wood) {
    const cv::Mat grey = wood_texture(w, h, seed);
    cv::Mat f;
    grey.convertTo(f, CV_32F);
    std::vector<cv::Mat> ch{f * 0.62, f * 0.80, f * 1.0};  // B, G, R: brown
    cv::Mat bgr, out;
    cv::merge(ch, bgr);
    bgr.convertTo(out, CV_8UC3);
    return out;
  }
  cv::RNG rng(seed);
  cv::Mat img(h, w, CV_8UC3, cv::Scalar(110, 120, 125));
  const double d = std::hypot(w, h);
  const int count = 60 + static_cast<int>(d / 20.0);
  for (int i = 0; i < count; ++i) {
    const cv::Point centre(rng.uniform(-w / 10, w + w / 10), rng.uniform(-h / 10, h + h / 10));
    const cv::Size axes(static_cast<int>(d * rng.uniform(0.02, 0.09)), static_cast<int>(d * rng.uniform(0.02, 0.09)));
    const cv::Scalar colour(rng.uniform(30, 226), rng.uniform(30, 226), rng.uniform(30, 226));
    cv::ellipse(img, centre, axes, rng.uniform(0.0, 180.0), 0, 360, colour, cv::FILLED, cv::LINE_AA);
  }
  cv::GaussianBlur(img, img, cv::Size(0, 0), 1.0 + d / 800.0);  // soft, out-of-focus-ish blob edges
  cv::Mat weave(h, w, CV_32FC3);
  rng.fill(weave, cv::RNG::NORMAL, 0.0, 6.0);  // the cloth's weave
  cv::Mat f, out;
  img.convertTo(f, CV_32FC3);
  f += weave;
  f.convertTo(out, CV_8UC3);
  return out;
}

/// A page of a document (the "page" of the tests), w x h, CV_8UC3: off-white paper, a title, four lines of
/// word-like text in large print (cv::putText) and a figure (a disc, a square and a triangle, drawn in black), with
/// margins of about 7 % so the paper's edge is plain. Deterministic from `seed`.
inline cv::Mat text_page(int w = 420, int h = 594, std::uint64_t seed = 7) {
  cv::RNG rng(seed);
  cv::Mat page(h, w, CV_8UC3, cv::Scalar(236, 242, 244));
  const int margin = static_cast<int>(0.07 * w);
  const double s = w / 420.0;
  const cv::Scalar ink(30, 30, 30);
  const int thick = std::max(1, static_cast<int>(std::lround(5 * s)));
  cv::putText(page, "Shapes", {margin, margin + static_cast<int>(48 * s)}, cv::FONT_HERSHEY_DUPLEX, 2.0 * s, ink,
              thick + 1, cv::LINE_AA);
  int y = margin + static_cast<int>(115 * s);
  const int line_step = static_cast<int>(50 * s);
  for (int line = 0; line < 4; ++line, y += line_step) {
    std::string text;
    while (text.size() < 12) {
      const int len = rng.uniform(2, 6);
      for (int k = 0; k < len; ++k) text += static_cast<char>('a' + rng.uniform(0, 26));
      text += ' ';
    }
    cv::putText(page, text, {margin, y}, cv::FONT_HERSHEY_SIMPLEX, 1.25 * s, ink, thick, cv::LINE_AA);
  }
  const int fy = y;
  const int fh = h - margin - fy;
  if (fh > 20) {
    const int r = std::min(fh, w / 4) / 2;
    cv::circle(page, {margin + r + 4, fy + fh / 2}, r, ink, cv::FILLED, cv::LINE_AA);
    cv::rectangle(page, cv::Rect(w / 2 - r, fy + fh / 2 - r, 2 * r, 2 * r), ink, std::max(2, static_cast<int>(6 * s)),
                  cv::LINE_AA);
    const std::vector<cv::Point> tri{
        {w - margin - 2 * r, fy + fh / 2 + r}, {w - margin, fy + fh / 2 + r}, {w - margin - r, fy + fh / 2 - r}};
    cv::fillConvexPoly(page, tri, ink, cv::LINE_AA);
  }
  return page;
}

/// The picture's corners in the frame for `c` (before any fitting to the frame): keystone, rotation, and a
/// placement at the frame's centre + offset with the picture's bounding box at most `fill` of the frame.
inline std::array<cv::Point2d, 4> photo_corners(cv::Size picture, cv::Size frame, const PhotoConditions& c) {
  cv::RNG rng(c.seed * 7919 + 17);
  const double w = picture.width, h = picture.height;
  std::array<cv::Point2d, 4> q{cv::Point2d(-w / 2, -h / 2), cv::Point2d(w / 2, -h / 2), cv::Point2d(w / 2, h / 2),
                               cv::Point2d(-w / 2, h / 2)};
  // Keystone: side k (k -> k+1) is the far one; its corners move inward along it by `perspective` of its length.
  const int far = rng.uniform(0, 4);
  std::array<cv::Point2d, 4> moved = q;
  for (int k = 0; k < 4; ++k) {
    const cv::Point2d next = q[static_cast<std::size_t>((k + 1) % 4)], prev = q[static_cast<std::size_t>((k + 3) % 4)];
    const cv::Point2d to_next = next - q[static_cast<std::size_t>(k)], to_prev = prev - q[static_cast<std::size_t>(k)];
    const bool on_far_as_start = k == far, on_far_as_end = (k + 3) % 4 == far;
    const double a = on_far_as_start ? c.perspective : rng.uniform(0.0, c.perspective / 3.0);
    const double b = on_far_as_end ? c.perspective : rng.uniform(0.0, c.perspective / 3.0);
    moved[static_cast<std::size_t>(k)] += a * to_next + b * to_prev;
  }
  const double th = -c.rotation_deg * std::numbers::pi / 180.0;  // counter-clockwise on screen (y down)
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (auto& p : moved) {
    p = {std::cos(th) * p.x - std::sin(th) * p.y, std::sin(th) * p.x + std::cos(th) * p.y};
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  }
  const double s = std::min(c.fill * frame.width / (x1 - x0), c.fill * frame.height / (y1 - y0));
  const cv::Point2d centre((frame.width - 1) / 2.0 + c.offset_px.x, (frame.height - 1) / 2.0 + c.offset_px.y);
  for (auto& p : moved) p = centre + s * (p - cv::Point2d((x0 + x1) / 2, (y0 + y1) / 2));
  return moved;
}

/// `c` with offset_px chosen so that the picture lies against the frame's edge `edge` (0 top, 1 right, 2 bottom,
/// 3 left): its corner nearest that edge `gap_px` inside it, measured from the frame's outer boundary (half a pixel
/// beyond the outermost pixel centres), or that far outside it for a negative gap; centred along the edge.
inline PhotoConditions near_edge(cv::Size picture, cv::Size frame, PhotoConditions c, int edge, double gap_px) {
  c.offset_px = {0, 0};
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const cv::Point2d& p : photo_corners(picture, frame, c)) {
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  }
  const double left = -0.5 + gap_px, right = frame.width - 0.5 - gap_px, top = -0.5 + gap_px,
               bottom = frame.height - 0.5 - gap_px;
  switch (edge) {
    case 0:
      c.offset_px = {0, top - y0};
      break;
    case 1:
      c.offset_px = {right - x1, 0};
      break;
    case 2:
      c.offset_px = {0, bottom - y1};
      break;
    default:
      c.offset_px = {left - x0, 0};
      break;
  }
  return c;
}

/// Renders `picture` (CV_8UC1 or CV_8UC3) into a `frame`-sized photo under conditions `c`. The picture is first
/// shrunk (INTER_AREA) to about its size in the frame so the perspective warp (bilinear) does not alias; the
/// frame is then backdrop·(1 − coverage) + picture·coverage (cv::blendLinear), times the light, blurred, plus
/// noise. `backdrop`, when given (frame-sized CV_8UC3, e.g. a cached backdrop_texture), is used instead of
/// generating one from c.backdrop and c.seed.
inline SyntheticPhoto synthetic_photo(const cv::Mat& picture, cv::Size frame, const PhotoConditions& c,
                                      const cv::Mat* backdrop = nullptr) {
  CV_Assert(!picture.empty() && (picture.type() == CV_8UC1 || picture.type() == CV_8UC3));
  CV_Assert(backdrop == nullptr || (backdrop->size() == frame && backdrop->type() == CV_8UC3));
  cv::Mat pic;
  if (picture.channels() == 1)
    cv::cvtColor(picture, pic, cv::COLOR_GRAY2BGR);
  else
    pic = picture;
  SyntheticPhoto out;
  out.corners_px = photo_corners(pic.size(), frame, c);
  const double W = pic.cols, H = pic.rows;
  const cv::Point2f src[4] = {{-0.5f, -0.5f},
                              {static_cast<float>(W - 0.5), -0.5f},
                              {static_cast<float>(W - 0.5), static_cast<float>(H - 0.5)},
                              {-0.5f, static_cast<float>(H - 0.5)}};
  cv::Point2f dst[4];
  for (int k = 0; k < 4; ++k)
    dst[k] = cv::Point2f(static_cast<float>(out.corners_px[static_cast<std::size_t>(k)].x),
                         static_cast<float>(out.corners_px[static_cast<std::size_t>(k)].y));
  out.homography = cv::Matx33d(cv::getPerspectiveTransform(src, dst));

  // Shrink first when the picture is smaller in the frame than in its file.
  const double area = std::abs(cv::contourArea(std::vector<cv::Point2f>(dst, dst + 4)));
  const double lin = std::sqrt(area / (W * H));
  cv::Mat render = pic;
  cv::Matx33d render_h = out.homography;
  if (lin < 0.9) {
    const cv::Size rs(std::max(2, static_cast<int>(std::lround(W * lin))),
                      std::max(2, static_cast<int>(std::lround(H * lin))));
    cv::resize(pic, render, rs, 0, 0, cv::INTER_AREA);
    const double sx = W / rs.width, sy = H / rs.height;  // resized px -> picture px: x = (x' + 0.5) sx - 0.5
    const cv::Matx33d to_pic(sx, 0, 0.5 * sx - 0.5, 0, sy, 0.5 * sy - 0.5, 0, 0, 1);
    render_h = out.homography * to_pic;
  }
  cv::Mat colour, coverage, uncovered, img;
  cv::warpPerspective(render, colour, cv::Mat(render_h), frame, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  // Bilinear coverage of a ones image with a zero border: 0.5 exactly on the picture's outline (x = -0.5).
  cv::warpPerspective(cv::Mat(render.size(), CV_32F, cv::Scalar(1.0)), coverage, cv::Mat(render_h), frame,
                      cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0.0));
  cv::subtract(cv::Scalar(1.0), coverage, uncovered);
  cv::blendLinear(colour, backdrop ? *backdrop : backdrop_texture(c.backdrop, frame.width, frame.height, c.seed),
                  coverage, uncovered, img);

  cv::RNG rng(c.seed * 104729 + 3);
  cv::Mat f;
  img.convertTo(f, CV_32FC3);
  if (c.uneven_light) {
    const double a = rng.uniform(0.0, 2 * std::numbers::pi);
    const double dx = std::cos(a), dy = std::sin(a);
    const double lo = std::min(0.0, dx * frame.width) + std::min(0.0, dy * frame.height);
    const double hi = std::max(0.0, dx * frame.width) + std::max(0.0, dy * frame.height);
    for (int y = 0; y < frame.height; ++y) {
      cv::Vec3f* row = f.ptr<cv::Vec3f>(y);
      for (int x = 0; x < frame.width; ++x)
        row[x] *= static_cast<float>(0.6 + 0.5 * ((dx * x + dy * y) - lo) / (hi - lo));
    }
  }
  if (c.blur_sigma_px > 0) cv::GaussianBlur(f, f, cv::Size(0, 0), c.blur_sigma_px);
  if (c.noise_sigma > 0) {
    cv::Mat noise(frame, CV_32FC3);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, c.noise_sigma);
    f += noise;
  }
  f.convertTo(out.frame, CV_8UC3);
  return out;
}

}  // namespace hk::test
