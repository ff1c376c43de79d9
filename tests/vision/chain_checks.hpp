#pragma once
// Property checks on linked chains shared by the vision test files: the invariants link_edges
// promises (linking.hpp), written once so every test asserts the same thing.

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "vision/linking.hpp"

namespace hk::vision::test {

inline bool is_integer(double v) { return v == std::floor(v); }

/// Chains straight from link_edges on an edge map of `size`: integer points inside the image on
/// edge pixels, consecutive points (and the closure of a closed chain) 8-adjacent and distinct,
/// no pixel twice in a chain.
inline void expect_pixel_chains_valid(const std::vector<Chain>& chains, const cv::Mat& edges) {
  for (std::size_t k = 0; k < chains.size(); ++k) {
    const auto& pts = chains[k].points_px;
    SCOPED_TRACE("chain " + std::to_string(k) + " of " + std::to_string(chains.size()));
    ASSERT_FALSE(pts.empty());
    std::set<std::pair<int, int>> seen;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const cv::Point2d p = pts[i];
      ASSERT_TRUE(is_integer(p.x) && is_integer(p.y)) << p;
      ASSERT_TRUE(p.x >= 0 && p.y >= 0 && p.x < edges.cols && p.y < edges.rows) << p;
      ASSERT_NE(edges.at<std::uint8_t>(static_cast<int>(p.y), static_cast<int>(p.x)), 0) << p;
      ASSERT_TRUE(seen.insert({static_cast<int>(p.x), static_cast<int>(p.y)}).second) << "pixel twice: " << p;
      if (i > 0) {
        const cv::Point2d d = p - pts[i - 1];
        ASSERT_TRUE(std::abs(d.x) <= 1 && std::abs(d.y) <= 1) << "not 8-adjacent: " << pts[i - 1] << " " << p;
      }
    }
    if (chains[k].closed) {
      ASSERT_GE(pts.size(), 3u);
      const cv::Point2d d = pts.front() - pts.back();
      ASSERT_TRUE(std::abs(d.x) <= 1 && std::abs(d.y) <= 1) << "closure not 8-adjacent";
    }
  }
}

/// Every edge pixel is in some chain, or is a staircase corner the linker thinned away (it had
/// at least two 4-neighbours) lying next to a chain point; a pixel in several chains (a junction)
/// is an end point of all of them but at most one; thinning kept the 8-connected components.
/// Call with chains linked with min_length_px = 0.
inline void expect_edges_covered_once(const std::vector<Chain>& chains, const cv::Mat& edges) {
  std::map<std::pair<int, int>, int> count;
  std::map<std::pair<int, int>, int> as_end;
  for (const Chain& c : chains) {
    for (std::size_t i = 0; i < c.points_px.size(); ++i) {
      const std::pair<int, int> key{static_cast<int>(c.points_px[i].x), static_cast<int>(c.points_px[i].y)};
      ++count[key];
      if (i == 0 || i + 1 == c.points_px.size()) ++as_end[key];
    }
  }
  const auto on = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < edges.cols && y < edges.rows && edges.at<std::uint8_t>(y, x) != 0;
  };
  for (int y = 0; y < edges.rows; ++y) {
    for (int x = 0; x < edges.cols; ++x) {
      if (!on(x, y)) continue;
      const auto it = count.find({x, y});
      if (it == count.end()) {
        const int four = on(x + 1, y) + on(x - 1, y) + on(x, y + 1) + on(x, y - 1);
        EXPECT_GE(four, 2) << "edge pixel (" << x << ", " << y << ") in no chain and not a corner";
        bool next_to_chain = false;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) next_to_chain = next_to_chain || count.count({x + dx, y + dy}) > 0;
        }
        EXPECT_TRUE(next_to_chain) << "thinned pixel (" << x << ", " << y << ") not next to any chain";
        continue;
      }
      if (it->second > 1) {
        const int ends = as_end[std::make_pair(x, y)];
        EXPECT_GE(ends, it->second - 1) << "pixel (" << x << ", " << y << ") inside more than one chain";
      }
    }
  }
  cv::Mat linked = cv::Mat::zeros(edges.size(), CV_8UC1);
  for (const auto& [key, n] : count) linked.at<std::uint8_t>(key.second, key.first) = 255;
  cv::Mat labels;
  const cv::Mat binary = edges != 0;
  EXPECT_EQ(cv::connectedComponents(linked, labels, 8), cv::connectedComponents(binary, labels, 8))
      << "linking changed the number of 8-connected components";
}

/// Chains in any pixel frame of a w x h image (e.g. scaled back from a processed image): finite,
/// inside [0, w-1] x [0, h-1], no two consecutive points equal, no point twice in a chain (unless
/// `repeats_allowed`: traced outlines pass a one-pixel-wide part of a region twice).
inline void expect_chains_sane(const std::vector<Chain>& chains, int w, int h, bool repeats_allowed = false) {
  for (std::size_t k = 0; k < chains.size(); ++k) {
    const auto& pts = chains[k].points_px;
    SCOPED_TRACE("chain " + std::to_string(k));
    ASSERT_FALSE(pts.empty());
    std::set<std::pair<double, double>> seen;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const cv::Point2d p = pts[i];
      ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y));
      ASSERT_TRUE(p.x >= 0 && p.y >= 0 && p.x <= w - 1 && p.y <= h - 1) << p;
      if (i > 0) {
        ASSERT_NE(p, pts[i - 1]) << "duplicate consecutive point";
      }
      ASSERT_TRUE(seen.insert({p.x, p.y}).second || repeats_allowed) << "point twice: " << p;
    }
  }
}

}  // namespace hk::vision::test
