#ifndef TEXTILE_FIT_SRC_EXTRACT_INTERNAL_H_
#define TEXTILE_FIT_SRC_EXTRACT_INTERNAL_H_

// Pieces of the photo extractor shared by its source files (extract_*.cc); not public API.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

namespace textile::extract_internal {

using Vec2 = Eigen::Vector2d;

// Median of a non-empty sample (copied: the caller's order is kept).
double Median(std::vector<double> v);

// Gaussian smoothing of a sequence, with the window truncated symmetrically at the ends so that
// straight runs stay straight up to the last point. sigma in samples; <= 0, NaN or infinite
// returns the input.
std::vector<Vec2> SmoothPolyline(const std::vector<Vec2>& p, double sigma);

// Points every `step` along a polyline's arc length, from its first point to its last (which is
// always included).
std::vector<Vec2> ResampleByArc(const std::vector<Vec2>& p, double step);

// Bilinear sample of an 8-bit grey image at (x, y) [px]; false outside the pixel centres' hull.
bool SampleGray(const cv::Mat& gray, double x, double y, double* value);

// 8-connected components of a CV_8U mask: labels (CV_32S) and stats (n × 5 CV_32S, columns
// cv::CC_STAT_LEFT, TOP, WIDTH, HEIGHT, AREA) as cv::connectedComponentsWithStats gives them,
// without the centroids, which cost more than the labelling itself. Returns n, the number of
// labels including the background (0).
int ConnectedComponents(const cv::Mat& mask, cv::Mat* labels, cv::Mat* stats);

// A large region that differs from the background (clamp, platform, fixture), found on the
// reduced image.
struct Block {
  cv::Mat mask;  // CV_8U, reduced-image size, 255 inside
  int sign = 0;  // +1 lighter than the background, -1 darker
  cv::Rect box;  // bounding box on the reduced image
};

// Blocks of the reduced grey image: a smooth (quadratic) background is fitted robustly, and
// regions that differ from it by much more than the noise, are thicker than `min_thickness`
// [px] and cover at least 1 % of the image are returned. `ignore` (CV_8U) marks pixels to leave
// out of the background fit (the strip).
std::vector<Block> FindBlocks(const cv::Mat& small, const cv::Mat& ignore, double min_thickness);

// A platform that does not stand out from the background as a region (a strong light gradient
// or shadow makes its faces as light as the background somewhere), found by its front face
// instead: the straightest long edge of one sign that runs from just below the held, level part
// of the strip's line (`path`, full px) down to the bottom of the reduced image `small`, within
// ±12° of the vertical. `ignore` marks the strip. Returns the region behind that edge and below
// the strip as a block for FitPlatform, or nothing if no edge stands out from the noise.
std::optional<Block> FindBlockByFrontEdge(const cv::Mat& small, const cv::Mat& ignore,
                                          const std::vector<Vec2>& path, double scale,
                                          int direction, double min_thickness);

// A platform found at full resolution: its top face and front face as lines, and their corner.
struct PlatformFit {
  bool found = false;
  std::string why_not;   // when not found
  Vec2 corner{0, 0};     // top/front corner [px]
  Vec2 top_far{0, 0};    // far end of the measured top face [px]
  Vec2 front_low{0, 0};  // low end of the measured front face [px]
  double top_angle = 0;  // top face direction, counter-clockwise from the image rows [rad]
  // The strip lies on the block's top behind its corner (also when not found: a platform
  // that could not be measured).
  bool under_strip = false;
};

// Looks for a platform block under the root of the strip. `block` is on the reduced image
// (scale = reduced px per full px); `direction` is +1 if the overhang points right, -1 left;
// `path` is the strip's coarse centre line [full px], which must pass near the corner; `thickness`
// is the strip's silhouette width [full px].
PlatformFit FitPlatform(const cv::Mat& gray, const Block& block, double scale, int direction,
                        const std::vector<Vec2>& path, double thickness);

// Whether the reduced grey image `small` shows a chessboard (a calibration board given as a strip
// photo): at least 8 dark and 4 light squares of one size, in the Otsu threshold eroded by a
// pixel. Strip photos show none (a strip is one long component).
bool LooksLikeCalibrationBoard(const cv::Mat& small);

// Whether a strip is draped over a block rather than held at one end: its centre line `line`
// (from one end to the other) has both ends more than 3 `thickness` + 5 px below its highest
// point, and its top stretch lies on one of `blocks` (within 2 `thickness` + 4 px above its
// mask); all on the reduced image [px]. Sets `peak` to the highest point. Such a strip lies over
// a whole platform and off its far edge too: not a cantilever from one edge.
bool DrapedOverBlock(const std::vector<Vec2>& line, const std::vector<Block>& blocks,
                     double thickness, Vec2* peak);

}  // namespace textile::extract_internal

#endif  // TEXTILE_FIT_SRC_EXTRACT_INTERNAL_H_
