// Checks that refuse photos which do not show one usable cantilever (docs/methods/extraction.md, exit
// 3): a calibration board given as a strip photo, a strip hanging off both ends of a platform.

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "extract_internal.h"

namespace textile::extract_internal {
namespace {

// A board has many squares; the smallest boards in use (4×3 inner corners) have 10 of each
// shade, of which the light ones at the board's rim merge with its white margin.
constexpr int kMinBoardDark = 8;
constexpr int kMinBoardLight = 4;

// Squares of one shade (dark or light) on the reduced image: components that differ from the
// local mean (a box of a fifth of the image, wider than a square: light falling off across the
// board does not matter) by more than 10 grey levels (noise is 2-3), eroded by a pixel so that
// squares touching at their corners come apart, at least 8 × 8 px, filling at least 40 % of
// their box (a square seen at 45° fills half), at most 3:1 (perspective), clear of the photo's
// border, and of the median area of such components to a factor 2. Of those, the ones whose
// nearest such neighbour lies one to two sides away (the next square of that shade is a
// diagonal away on a board, √2 sides) are counted: specks of noise or texture are not tiled.
int CountBoardSquares(const cv::Mat& small, bool dark) {
  const int box = std::max(15, std::max(small.cols, small.rows) / 5) | 1;
  cv::Mat mean;
  cv::blur(small, mean, cv::Size(box, box), cv::Point(-1, -1), cv::BORDER_REPLICATE);
  cv::Mat binary = dark ? (small + 10 < mean) : (small > mean + 10);
  cv::erode(binary, binary, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(binary, labels, stats, centroids, 4, CV_32S);
  std::vector<double> areas;
  std::vector<Vec2> centres;
  for (int l = 1; l < n; ++l) {
    const int x = stats.at<int>(l, cv::CC_STAT_LEFT), y = stats.at<int>(l, cv::CC_STAT_TOP);
    const int w = stats.at<int>(l, cv::CC_STAT_WIDTH), h = stats.at<int>(l, cv::CC_STAT_HEIGHT);
    const int area = stats.at<int>(l, cv::CC_STAT_AREA);
    if (area < 64 || x == 0 || y == 0 || x + w == small.cols || y + h == small.rows) continue;
    if (area < 0.4 * w * h || std::max(w, h) > 3 * std::min(w, h)) continue;
    areas.push_back(area);
    centres.emplace_back(centroids.at<double>(l, 0), centroids.at<double>(l, 1));
  }
  if (areas.empty()) return 0;
  const double m = Median(areas);
  std::vector<Vec2> similar;
  for (size_t i = 0; i < areas.size(); ++i) {
    if (areas[i] >= 0.5 * m && areas[i] <= 2 * m) similar.push_back(centres[i]);
  }
  // The side of a square before the erosion [px].
  const double side = std::sqrt(m) + 2.0;
  int tiled = 0;
  for (size_t i = 0; i < similar.size(); ++i) {
    double nearest = 1e300;
    for (size_t j = 0; j < similar.size(); ++j) {
      if (j != i) nearest = std::min(nearest, (similar[i] - similar[j]).norm());
    }
    tiled += nearest >= side && nearest <= 2.0 * side;
  }
  return tiled;
}

}  // namespace

bool LooksLikeCalibrationBoard(const cv::Mat& small) {
  return CountBoardSquares(small, /*dark=*/true) >= kMinBoardDark &&
         CountBoardSquares(small, /*dark=*/false) >= kMinBoardLight;
}

bool DrapedOverBlock(const std::vector<Vec2>& line, const std::vector<Block>& blocks,
                     double thickness, Vec2* peak) {
  if (line.size() < 5) return false;
  const auto top = std::min_element(line.begin(), line.end(),
                                    [](const Vec2& p, const Vec2& q) { return p.y() < q.y(); });
  const double depth = 3.0 * thickness + 5.0;
  if (line.front().y() - top->y() < depth || line.back().y() - top->y() < depth) return false;
  // Some point of the line's top stretch lies on a block: the block's mask just below it.
  const int reach = static_cast<int>(std::ceil(2.0 * thickness + 4.0));
  for (const Vec2& p : line) {
    if (p.y() > top->y() + thickness) continue;
    const int x = static_cast<int>(std::lround(p.x()));
    const int y0 = static_cast<int>(std::lround(p.y()));
    for (const Block& b : blocks) {
      if (x < 0 || x >= b.mask.cols) continue;
      for (int y = std::max(0, y0); y <= std::min(b.mask.rows - 1, y0 + reach); ++y) {
        if (b.mask.at<uchar>(y, x)) {
          *peak = *top;
          return true;
        }
      }
    }
  }
  return false;
}

}  // namespace textile::extract_internal
