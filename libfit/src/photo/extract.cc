// The photo extractor: strip detection on a reduced image, rig recognition, sub-pixel
// silhouette boundaries at full resolution, and the profile in the frame of
// docs/spec/cantilever.md. The method and its choices are described in docs/methods/extraction.md.

#include "textile/photo/extract.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <queue>
#include <sstream>

#include "deadline.h"
#include "extract_internal.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

using extract_internal::Block;
using extract_internal::Median;
using extract_internal::PlatformFit;
using extract_internal::ResampleByArc;
using extract_internal::SampleGray;
using extract_internal::Section;
using extract_internal::SectionSet;
using extract_internal::SmoothPolyline;
using extract_internal::Strip;
using extract_internal::Sweep;
using extract_internal::Vec2;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDeg = M_PI / 180.0;

// The silhouette is where the contrast exceeds this fraction of the section's peak: low enough
// to keep an oblique face that is 10 % as bright as a lit edge (the real photos), and the
// boundary itself is then placed on the steepest point of the transition, not at this level.
constexpr double kSilhouetteFraction = 0.06;
// Sample spacing across the strip [px]; bilinear interpolation in between.
constexpr double kAcrossStep = 0.5;
// A strip is at least this many times longer than thick, and at least this fraction of the
// reduced image's diagonal long.
constexpr double kMinElongation = 5.0;
constexpr double kMinLengthFraction = 0.08;
// A second band of the strip's shade with at least this fraction of its length × contrast is
// a second strip (SecondStrip).
constexpr double kSecondStripScore = 0.3;
// What a photo whose strip's free tip is cut off by its border needs.
constexpr const char* kWholeStripInView = "; the whole strip, its tip included, must be in view";

// Image borders, as bits.
enum Border : int { kNoBorder = 0, kLeft = 1, kRight = 2, kTop = 4, kBottom = 8 };

// ---------------------------------------------------------------- reduced-image detection

// Geodesic distance inside `mask` from `seeds`, 8-connected (steps 1 and √2) [px], over `box`
// only (the mask's bounding box: nothing outside it is reachable). Returns a box-sized map, the
// distance of pixel (x, y) at (x - box.x, y - box.y); +inf outside the mask or unreachable.
// Box-sized maps keep the many sweeps of the detection cheap: a strip's box is a fraction of the
// image, and a full-sized map would cost more to allocate and fill than the search itself.
cv::Mat GeodesicDistance(const cv::Mat& mask, const cv::Rect& box,
                         const std::vector<cv::Point>& seeds) {
  const float inf = std::numeric_limits<float>::infinity();
  cv::Mat dist(box.size(), CV_32F, cv::Scalar(inf));
  using Item = std::pair<float, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  const cv::Mat m = mask(box);
  const int w = box.width, h = box.height;
  for (const cv::Point& s : seeds) {
    const cv::Point q = s - box.tl();
    if (!box.contains(s) || !m.at<uchar>(q)) continue;
    dist.at<float>(q) = 0.0f;
    queue.push({0.0f, q.y * w + q.x});
  }
  static const int dx[8] = {1, -1, 0, 0, 1, 1, -1, -1};
  static const int dy[8] = {0, 0, 1, -1, 1, -1, 1, -1};
  static const float step[8] = {
      1, 1, 1, 1, float(M_SQRT2), float(M_SQRT2), float(M_SQRT2), float(M_SQRT2)};
  while (!queue.empty()) {
    const auto [d, i] = queue.top();
    queue.pop();
    const int x = i % w, y = i / w;
    if (d > dist.at<float>(y, x)) continue;
    for (int k = 0; k < 8; ++k) {
      const int nx = x + dx[k], ny = y + dy[k];
      if (nx < 0 || ny < 0 || nx >= w || ny >= h || !m.at<uchar>(ny, nx)) continue;
      const float nd = d + step[k];
      if (nd < dist.at<float>(ny, nx)) {
        dist.at<float>(ny, nx) = nd;
        queue.push({nd, ny * w + nx});
      }
    }
  }
  return dist;
}

// The farthest reachable pixel of a box-sized distance map, in image coordinates.
cv::Point Farthest(const cv::Mat& dist, const cv::Rect& box, float* value) {
  cv::Point best(-1, -1);
  float top = -1.0f;
  for (int y = 0; y < dist.rows; ++y) {
    const float* row = dist.ptr<float>(y);
    for (int x = 0; x < dist.cols; ++x) {
      if (std::isfinite(row[x]) && row[x] > top) {
        top = row[x];
        best = {x + box.x, y + box.y};
      }
    }
  }
  *value = top;
  return best;
}

// The ends of a band-like mask and its geodesic length (Sweep).
Sweep DoubleSweep(const cv::Mat& mask) {
  Sweep s;
  s.box = cv::boundingRect(mask);
  if (s.box.empty()) return s;
  cv::Point any(-1, -1);
  for (int x = s.box.x; any.x < 0 && x < s.box.x + s.box.width; ++x) {
    if (mask.at<uchar>(s.box.y, x)) any = {x, s.box.y};
  }
  float v;
  s.a = Farthest(GeodesicDistance(mask, s.box, {any}), s.box, &v);
  s.dist_a = GeodesicDistance(mask, s.box, {s.a});
  s.b = Farthest(s.dist_a, s.box, &v);
  s.length = v;
  s.dist_b = GeodesicDistance(mask, s.box, {s.b});
  return s;
}

// Threshold of a top-/black-hat image: Otsu's, but never within the noise of the flat
// background (median + 6 robust σ).
double HatThreshold(const cv::Mat& hat) {
  std::vector<int> hist(256, 0);
  for (int y = 0; y < hat.rows; ++y) {
    const uchar* row = hat.ptr<uchar>(y);
    for (int x = 0; x < hat.cols; ++x) ++hist[row[x]];
  }
  const auto median_of = [](const std::vector<int>& h, long total) {
    long seen = 0;
    for (int v = 0; v < 256; ++v) {
      seen += h[v];
      if (2 * seen >= total) return v;
    }
    return 255;
  };
  const long total = static_cast<long>(hat.total());
  const int med = median_of(hist, total);
  std::vector<int> dev(256, 0);
  for (int v = 0; v < 256; ++v) dev[std::abs(v - med)] += hist[v];
  const double spread = std::max(0.5, 1.4826 * median_of(dev, total));
  cv::Mat unused;
  const double otsu = cv::threshold(hat, unused, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  return std::max({otsu, med + 6.0 * spread, med + 3.0});
}

void CollectStrips(const cv::Mat& hat, int polarity, std::vector<Strip>* out) {
  const double min_length = kMinLengthFraction * std::hypot(hat.cols, hat.rows);
  cv::Mat binary = hat > HatThreshold(hat);
  cv::Mat labels, stats;
  const int n = extract_internal::ConnectedComponents(binary, &labels, &stats);
  std::vector<double> mass(n, 0.0);
  for (int y = 0; y < hat.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const uchar* v = hat.ptr<uchar>(y);
    for (int x = 0; x < hat.cols; ++x) mass[l[x]] += v[x];
  }
  std::vector<int> order;
  for (int l = 1; l < n; ++l) {
    const double diag =
        std::hypot(stats.at<int>(l, cv::CC_STAT_WIDTH), stats.at<int>(l, cv::CC_STAT_HEIGHT));
    if (diag >= min_length) order.push_back(l);
  }
  std::sort(order.begin(), order.end(), [&](int p, int q) { return mass[p] > mass[q]; });
  if (order.size() > 8) order.resize(8);
  for (const int l : order) {
    Strip s;
    s.polarity = polarity;
    // The sweep runs on the component's own box; the image-sized mask is made only for a
    // candidate that is kept.
    const cv::Rect box(stats.at<int>(l, cv::CC_STAT_LEFT), stats.at<int>(l, cv::CC_STAT_TOP),
                       stats.at<int>(l, cv::CC_STAT_WIDTH), stats.at<int>(l, cv::CC_STAT_HEIGHT));
    const cv::Mat own = labels(box) == l;
    const Sweep sweep = DoubleSweep(own);
    s.length = sweep.length;
    s.thickness = stats.at<int>(l, cv::CC_STAT_AREA) / std::max(1.0, s.length);
    // Length times mean contrast: a long, clear band beats a broad faint area (a shadow's rim)
    // of the same total contrast.
    s.score = s.length * mass[l] / std::max(1, stats.at<int>(l, cv::CC_STAT_AREA));
    if (s.length >= min_length && s.length >= kMinElongation * s.thickness) {
      s.mask = cv::Mat::zeros(hat.size(), CV_8U);
      own.copyTo(s.mask(box));
      out->push_back(std::move(s));
    }
  }
}

// Direction in which a band leaves its end: from the centroid of the pixels 2-4 thicknesses
// back (by geodesic distance from the end) to the end. `dist` is box-sized (GeodesicDistance).
Vec2 EndDirection(const cv::Mat& mask, const cv::Mat& dist, const cv::Rect& box,
                  const cv::Point& end, double thickness) {
  Vec2 sum = Vec2::Zero();
  int count = 0;
  for (int y = box.y; y < box.y + box.height; ++y) {
    for (int x = box.x; x < box.x + box.width; ++x) {
      const float d = dist.at<float>(y - box.y, x - box.x);
      if (mask.at<uchar>(y, x) && d >= 2.0 * thickness && d <= 4.0 * thickness + 2.0) {
        sum += Vec2(x, y);
        ++count;
      }
    }
  }
  if (count == 0) return Vec2::Zero();
  const Vec2 d = Vec2(end.x, end.y) - sum / count;
  return d.norm() > 0 ? Vec2(d.normalized()) : Vec2::Zero();
}

// Bridges gaps in the strip (a dim spot, a shadowed stretch): other pieces of the thresholded
// hat that continue the band beyond one of its ends, within a cone of ±30° and a gap of at most
// six thicknesses (or 5 % of the image diagonal), are joined to it, repeatedly. `threshold`
// is the hat level that makes a pixel part of a piece.
void MergeContinuations(const cv::Mat& hat, double threshold, Strip* strip) {
  cv::Mat binary = hat > threshold;
  cv::Mat labels;
  cv::connectedComponents(binary, labels, 8, CV_32S);
  const double gap = std::max(6.0 * strip->thickness, 0.05 * std::hypot(hat.cols, hat.rows));
  for (int round = 0; round < 12; ++round) {
    const Sweep sweep = DoubleSweep(strip->mask);
    bool merged = false;
    for (int e = 0; e < 2 && !merged; ++e) {
      const cv::Point end = e == 0 ? sweep.a : sweep.b;
      const Vec2 dir = EndDirection(strip->mask, e == 0 ? sweep.dist_a : sweep.dist_b, sweep.box,
                                    end, strip->thickness);
      if (dir.norm() == 0.0) continue;
      const int r = static_cast<int>(std::ceil(gap));
      double best = 1e300;
      cv::Point best_p;
      for (int y = std::max(0, end.y - r); y <= std::min(hat.rows - 1, end.y + r); ++y) {
        for (int x = std::max(0, end.x - r); x <= std::min(hat.cols - 1, end.x + r); ++x) {
          if (!labels.at<int>(y, x) || strip->mask.at<uchar>(y, x)) continue;
          const Vec2 v(x - end.x, y - end.y);
          const double d = v.norm();
          if (d > gap || d < 1.0 || v.dot(dir) < d * std::cos(30.0 * kDeg)) continue;
          if (d < best) {
            best = d;
            best_p = {x, y};
          }
        }
      }
      if (best > gap) continue;
      strip->mask |= labels == labels.at<int>(best_p);
      cv::line(strip->mask, end, best_p, cv::Scalar(255),
               std::max(1, static_cast<int>(strip->thickness / 2)));
      merged = true;
    }
    if (!merged) break;
  }
  strip->length = DoubleSweep(strip->mask).length;
}

// The largest 8-connected component of a mask (empty if there is none).
cv::Mat LargestComponent(const cv::Mat& mask) {
  const cv::Rect box = cv::boundingRect(mask);
  if (box.empty()) return cv::Mat();
  cv::Mat labels, stats;
  const int n = extract_internal::ConnectedComponents(mask(box), &labels, &stats);
  int best = 0;
  for (int l = 1; l < n; ++l) {
    if (best == 0 || stats.at<int>(l, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) {
      best = l;
    }
  }
  if (best == 0) return cv::Mat();
  cv::Mat out = cv::Mat::zeros(mask.size(), CV_8U);
  out(box).setTo(255, labels == best);
  return out;
}

// A clamp of the strip's own shade that is thinner than the hat kernel merges with the strip:
// parts much thicker than the strip that reach in from the photo's border are split off and
// returned as blocks; the strip keeps its largest remaining piece.
std::vector<Block> SplitOffThickParts(Strip* strip) {
  // All of it runs on the mask's box with a margin (for the distances, the opening's kernel)
  // rather than on the whole image: the results are the same.
  const cv::Rect image(0, 0, strip->mask.cols, strip->mask.rows);
  const cv::Rect box = cv::boundingRect(strip->mask);
  if (box.empty()) return {};
  cv::Mat dt;
  cv::distanceTransform(strip->mask(cv::Rect(box.x - 1, box.y - 1, box.width + 2, box.height + 2) &
                                    image),
                        dt, cv::DIST_L2, 3);
  // The band's width from its ridge (local maxima of the distance to its outside), where a long
  // band outnumbers a compact block.
  std::vector<double> ridge;
  for (int y = 1; y + 1 < dt.rows; ++y) {
    for (int x = 1; x + 1 < dt.cols; ++x) {
      const float v = dt.at<float>(y, x);
      if (v <= 0.0f) continue;
      bool top = true;
      for (int k = 0; k < 9 && top; ++k) top = dt.at<float>(y + k / 3 - 1, x + k % 3 - 1) <= v;
      if (top) ridge.push_back(v);
    }
  }
  const double width = ridge.empty() ? strip->thickness : std::max(2.0, 2.0 * Median(ridge) - 1.0);
  const int d = std::max(5, static_cast<int>(3.0 * width)) | 1;
  const cv::Rect roi = cv::Rect(box.x - d, box.y - d, box.width + 2 * d, box.height + 2 * d) & image;
  cv::Mat thick;
  cv::morphologyEx(strip->mask(roi), thick, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, {d, d}));
  cv::Mat labels, stats;
  const int n = extract_internal::ConnectedComponents(thick, &labels, &stats);
  std::vector<Block> blocks;
  cv::Mat removed(strip->mask.size(), CV_8U, cv::Scalar(0));
  for (int l = 1; l < n; ++l) {
    const cv::Rect own(stats.at<int>(l, cv::CC_STAT_LEFT) + roi.x,
                       stats.at<int>(l, cv::CC_STAT_TOP) + roi.y,
                       stats.at<int>(l, cv::CC_STAT_WIDTH), stats.at<int>(l, cv::CC_STAT_HEIGHT));
    // Only fixtures reaching in from outside the photo count (a frayed tip's brush does not).
    if (own.x > 0 && own.y > 0 && own.br().x < image.width && own.br().y < image.height) continue;
    Block b;
    b.mask = cv::Mat::zeros(strip->mask.size(), CV_8U);
    b.mask(roi).setTo(255, labels == l);
    b.sign = strip->polarity;
    b.box = own;
    removed |= b.mask;
    blocks.push_back(std::move(b));
  }
  if (!blocks.empty()) {
    cv::dilate(removed, removed, cv::getStructuringElement(cv::MORPH_ELLIPSE, {5, 5}));
    const cv::Mat rest = LargestComponent(strip->mask & ~removed);
    if (!rest.empty()) strip->mask = rest;
    strip->thickness = width;
  }
  return blocks;
}

// Loose fibres are thinner than the strip: a small opening removes them from the detection
// mask (not from the measurement, which is made on the photo itself). Only a small one: the
// strip may be much thinner near its root than on average.
void RemoveLooseFibres(Strip* strip) {
  if (strip->thickness < 6.0) return;
  cv::Mat opened;
  cv::morphologyEx(strip->mask, opened, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, {3, 3}));
  const cv::Mat cleaned = LargestComponent(opened);
  if (!cleaned.empty() && DoubleSweep(cleaned).length > 0.7 * strip->length) strip->mask = cleaned;
}

// Distance from a reduced-image point to the nearest block pixel, searched within 40 px [px].
// Cleans the chosen band: cut at half its own contrast in `hat` (its top- or black-hat), gaps
// bridged, thick parts reaching in from the border split off (returned as blocks), fibres
// removed.
std::vector<Block> PrepareStrip(const cv::Mat& hat, Strip* strip) {
  // Faint structures touching the strip (the slanted edge of a platform leaves a thin trace
  // in the hats, a shadow's rim, a faint face) are cut off at half the strip's own contrast.
  double threshold = HatThreshold(hat);
  {
    std::vector<double> values;
    for (int y = 0; y < hat.rows; ++y) {
      for (int x = 0; x < hat.cols; ++x) {
        if (strip->mask.at<uchar>(y, x)) values.push_back(hat.at<uchar>(y, x));
      }
    }
    threshold = std::max(threshold, 0.5 * Median(values));
    const cv::Mat core = LargestComponent(strip->mask & (hat > threshold));
    if (!core.empty()) strip->mask = core;
  }
  MergeContinuations(hat, threshold, strip);

  std::vector<Block> own_blocks = SplitOffThickParts(strip);
  RemoveLooseFibres(strip);
  return own_blocks;
}

// Distance from a reduced-image point to the nearest pixel of a mask [reduced px] (1e300 if
// the mask is empty).
double DistanceToMask(const cv::Mat& mask, const cv::Point& p) {
  std::vector<cv::Point> on;
  cv::findNonZero(mask, on);
  double best = 1e300;
  for (const cv::Point& q : on) best = std::min(best, std::hypot(q.x - p.x, q.y - p.y));
  return best;
}

// A second strip beside the chosen, prepared one (`strips` sorted by score, the chosen strip
// first): the strongest other candidate of the same polarity with at least
// kSecondStripScore of its score and a thickness within a factor 2 that lies clear of it (no
// pixel within 3 thicknesses + 2 px: pieces of one strip split by a dim stretch are joined to
// it or touch it). Returns its index in `strips`.
std::optional<size_t> SecondStrip(const std::vector<Strip>& strips, const Strip& strip) {
  cv::Mat zone;  // made only if a candidate gets this far (none on the shipped photos)
  for (size_t k = 1; k < strips.size(); ++k) {
    const Strip& c = strips[k];
    if (c.polarity != strip.polarity || c.score < kSecondStripScore * strip.score) continue;
    if (c.thickness > 2.0 * strip.thickness || 2.0 * c.thickness < strip.thickness) continue;
    if (zone.empty()) {
      const int r = static_cast<int>(std::ceil(3.0 * strip.thickness + 2.0));
      cv::dilate(strip.mask, zone,
                 cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * r + 1, 2 * r + 1}));
    }
    if (cv::countNonZero(c.mask & zone) == 0) return k;
  }
  return std::nullopt;
}

double DistanceToBlocks(const std::vector<Block>& blocks, const cv::Point& p) {
  double best = 1e300;
  for (const Block& b : blocks) {
    for (int y = std::max(0, p.y - 40); y < std::min(b.mask.rows, p.y + 41); ++y) {
      for (int x = std::max(0, p.x - 40); x < std::min(b.mask.cols, p.x + 41); ++x) {
        if (b.mask.at<uchar>(y, x)) best = std::min(best, std::hypot(x - p.x, y - p.y));
      }
    }
  }
  return best;
}

// The refusal of a strip that hangs off both ends of a platform, `at` the platform's top [full
// px].
std::string DrapedMessage(const Vec2& at) {
  return "the strip hangs off both ends of the platform (the top at about " +
         std::to_string(std::lround(at.x())) + "," + std::to_string(std::lround(at.y())) +
         " px): not a cantilever from one edge; lay it so that only one end overhangs";
}

// Two bands that are the two overhangs of one strip lying over a whole platform, whose part on
// the platform is not seen (a dark strip on a dark platform): each band's higher end lies at one
// block (within 3 thicknesses + 5 px), and the bands hang down away from each other, more than
// that below their higher ends. Sets `at` to the middle of the higher ends [reduced px].
bool OverhangsOnBothSides(const cv::Mat& small, const Strip& a, const Strip& b, Vec2* at) {
  const double t = std::max(a.thickness, b.thickness);
  const double near = 3.0 * t + 5.0;
  const auto ends = [](const Strip& s) {
    const Sweep e = DoubleSweep(s.mask);
    return e.a.y <= e.b.y ? std::make_pair(e.a, e.b) : std::make_pair(e.b, e.a);
  };
  const auto [high_a, low_a] = ends(a);
  const auto [high_b, low_b] = ends(b);
  if (low_a.y - high_a.y < near || low_b.y - high_b.y < near) return false;
  // Away from each other: the band whose high end is on the left hangs further left.
  const bool a_left = high_a.x <= high_b.x;
  const cv::Point& left_low = a_left ? low_a : low_b;
  const cv::Point& left_high = a_left ? high_a : high_b;
  const cv::Point& right_low = a_left ? low_b : low_a;
  const cv::Point& right_high = a_left ? high_b : high_a;
  if (!(left_low.x < left_high.x && right_low.x > right_high.x)) return false;
  cv::Mat zone = a.mask | b.mask;
  const int r = static_cast<int>(std::ceil(2.0 * t + 1.0));
  cv::dilate(zone, zone, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * r + 1, 2 * r + 1}));
  for (const Block& block : extract_internal::FindBlocks(small, zone, t)) {
    if (DistanceToBlocks({block}, high_a) <= near && DistanceToBlocks({block}, high_b) <= near) {
      *at = Vec2(0.5 * (high_a.x + high_b.x), 0.5 * (high_a.y + high_b.y));
      return true;
    }
  }
  return false;
}

// Which image borders a set of mask pixels (those within `radius` of an end) touches. `dist` is
// box-sized (GeodesicDistance).
int BordersNear(const cv::Mat& mask, const cv::Mat& dist, const cv::Rect& box, double radius) {
  int borders = kNoBorder;
  for (int y = box.y; y < box.y + box.height; ++y) {
    for (int x = box.x; x < box.x + box.width; ++x) {
      if (!mask.at<uchar>(y, x) || !(dist.at<float>(y - box.y, x - box.x) <= radius)) continue;
      if (x == 0) borders |= kLeft;
      if (x == mask.cols - 1) borders |= kRight;
      if (y == 0) borders |= kTop;
      if (y == mask.rows - 1) borders |= kBottom;
    }
  }
  return borders;
}

// Centre line of a band: centroids of the level sets of the geodesic distance from the root,
// in 1 px bins (level sets of a band cut straight across it). Widths [px] per point.
std::vector<Vec2> LevelSetCentreline(const cv::Mat& mask, const std::vector<cv::Point>& seeds,
                                     std::vector<double>* widths) {
  const cv::Rect box = cv::boundingRect(mask);
  const cv::Mat d = GeodesicDistance(mask, box, seeds);
  std::vector<Vec2> sum;
  std::vector<int> count;
  for (int y = 0; y < d.rows; ++y) {
    const float* row = d.ptr<float>(y);
    for (int x = 0; x < d.cols; ++x) {
      if (!std::isfinite(row[x])) continue;
      const size_t k = static_cast<size_t>(row[x]);
      if (k >= sum.size()) {
        sum.resize(k + 1, Vec2::Zero());
        count.resize(k + 1, 0);
      }
      sum[k] += Vec2(x + box.x, y + box.y);
      ++count[k];
    }
  }
  std::vector<Vec2> line;
  widths->clear();
  for (size_t k = 0; k < sum.size(); ++k) {
    if (count[k] == 0) continue;
    line.push_back(sum[k] / count[k]);
    widths->push_back(count[k]);
  }
  return line;
}

// A hanging strip bends gently (radii of many thicknesses); a centre line that turns sharply
// has wandered into a brush of fibres or along a lit end face. Cuts the line (1 px spacing)
// where its direction over `base` px turns by more than 35° from the stretch before.
// Moreover the moment, hence the curvature, of a cantilever falls from the edge towards its free
// end: once the turn per `base` has passed its peak (the edge; before it the strip may lie flat
// on a platform), in the outer half of the line it may not grow again by more than 12° over the
// least turn seen since that peak; where it does, the line is cut. Sharp turns count only from
// `from_fraction` of the line on: a coarse line from the reduced image may kink where the strip
// passes a platform's corner, far from the tip's fibres.
void CutAtSharpTurn(std::vector<Vec2>* line, double base, bool check_growth,
                    double from_fraction = 0.0) {
  const int b = static_cast<int>(base);
  const int n = static_cast<int>(line->size());
  const int from = static_cast<int>(from_fraction * n);
  double peak = -1.0, least = 1e9;
  for (int i = b; i + b < n; ++i) {
    const Vec2 before = ((*line)[i] - (*line)[i - b]).normalized();
    const Vec2 after = ((*line)[i + b] - (*line)[i]).normalized();
    const double turn = std::acos(std::clamp(before.dot(after), -1.0, 1.0));
    if ((turn > 35.0 * kDeg && i >= from) ||
        (check_growth && i > n / 2 && turn > least + 12.0 * kDeg)) {
      line->resize(i + 1);
      return;
    }
    if (turn >= peak) {
      peak = turn;  // still rising towards the edge's curvature
      least = turn;
    } else {
      least = std::min(least, turn);
    }
  }
}

// ---------------------------------------------------------------- full-resolution sections

// Sub-sample edge position: the first local maximum of the inward derivative of the contrast
// c, from `start` (just outside the silhouette) towards `core`, that is at least `min_slope`
// per sample; parabola through the maximum. Falls back to `fallback` when there is none.
double RefineEdge(const std::vector<double>& c, int start, int core, double min_slope,
                  double fallback) {
  const int step = core > start ? 1 : -1;
  const auto slope = [&](int j) { return step * (c[j + 1] - c[j - 1]) / 2.0; };
  const int last = static_cast<int>(c.size()) - 2;
  for (int j = start; j != core; j += step) {
    if (j < 2 || j > last - 1) continue;
    const double here = slope(j), before = slope(j - step), after = slope(j + step);
    if (here >= min_slope && here >= before && here > after) {
      const double den = before - 2.0 * here + after;
      const double delta = den < 0.0 ? 0.5 * (before - after) / den : 0.0;
      return j + step * std::clamp(delta, -0.5, 0.5);
    }
  }
  return fallback;
}

// Stations along `line`: tangents over ±3 points (root -> tip) and normals on the top side.
void PlaceStations(const std::vector<Vec2>& line, int direction, SectionSet* set) {
  const int m = static_cast<int>(line.size());
  set->p = line;
  set->t.resize(m);
  set->n.resize(m);
  set->s.resize(m);
  for (int i = 0; i < m; ++i) {
    Vec2 d = line[std::min(i + 3, m - 1)] - line[std::max(i - 3, 0)];
    if (d.norm() < 1e-9) d = Vec2(direction, 0.0);
    set->t[i] = d.normalized();
    set->n[i] = direction * Vec2(set->t[i].y(), -set->t[i].x());
  }
}

// Grey levels across the strip at every station, 2 half + 1 samples kAcrossStep apart centred
// on it: *raw (#M × cols, CV_32F) and *inside (CV_8U, 1 where the sample lies in the photo;
// outside ones take the nearest border's value).
void SampleAcross(const cv::Mat& gray, const SectionSet& set, int half, cv::Mat* raw,
                  cv::Mat* inside) {
  const int m = static_cast<int>(set.p.size());
  const int cols = 2 * half + 1;
  raw->create(m, cols, CV_32F);
  inside->create(m, cols, CV_8U);
  const double x_max = gray.cols - 1.0, y_max = gray.rows - 1.0;
  for (int i = 0; i < m; ++i) {
    float* out = raw->ptr<float>(i);
    uchar* in_row = inside->ptr<uchar>(i);
    const Vec2 q0 = set.p[i] - half * kAcrossStep * set.n[i], dq = kAcrossStep * set.n[i];
    const Vec2 q1 = q0 + (cols - 1) * dq;
    // A section wholly inside the photo (the usual case) is sampled without per-sample checks.
    const bool all_in = std::min(q0.x(), q1.x()) >= 0.0 && std::max(q0.x(), q1.x()) <= x_max &&
                        std::min(q0.y(), q1.y()) >= 0.0 && std::max(q0.y(), q1.y()) <= y_max;
    for (int j = 0; j < cols; ++j) {
      const double x = q0.x() + j * dq.x(), y = q0.y() + j * dq.y();
      double v;
      if (all_in) {
        const int x0 = std::min(static_cast<int>(x), gray.cols - 2);
        const int y0 = std::min(static_cast<int>(y), gray.rows - 2);
        const double fx = x - x0, fy = y - y0;
        const uchar* r0 = gray.ptr<uchar>(y0);
        const uchar* r1 = r0 + gray.step[0];
        v = (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) +
            fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
        in_row[j] = 1;
      } else {
        const bool in = SampleGray(gray, x, y, &v);
        if (!in) SampleGray(gray, std::clamp(x, 0.0, x_max), std::clamp(y, 0.0, y_max), &v);
        in_row[j] = in;
      }
      out[j] = static_cast<float>(v);
    }
  }
}

// Background on each side of every section: the median of its outer `margin` samples of the
// smoothed profiles `u`. Returns the background noise σ (robust, from every fourth section).
double BackgroundLevels(const cv::Mat& u, int margin, std::vector<double>* bg_lo,
                        std::vector<double>* bg_up) {
  const int m = u.rows, cols = u.cols;
  std::vector<double> deviations;
  bg_lo->resize(m);
  bg_up->resize(m);
  for (int i = 0; i < m; ++i) {
    const float* row = u.ptr<float>(i);
    std::vector<double> lo(row, row + margin), up(row + cols - margin, row + cols);
    (*bg_lo)[i] = Median(lo);
    (*bg_up)[i] = Median(up);
    if (i % 4 == 0) {
      for (double v : lo) deviations.push_back(std::abs(v - (*bg_lo)[i]));
      for (double v : up) deviations.push_back(std::abs(v - (*bg_up)[i]));
    }
  }
  return std::max(0.2, 1.4826 * Median(deviations));
}

// How one section's samples are read: the window's geometry and the background.
struct SectionWindow {
  int half = 0, margin = 0, core_reach = 0;  // [samples]
  double bg_lo = 0.0, bg_up = 0.0;           // background on each side [grey levels]
  double noise = 0.0;                        // [grey levels]
  int polarity = 0;
};

// One section from its smoothed samples `row` (cols = 2 half + 1) and which of them lie in the
// photo: the contrast against the background interpolated between both sides (*c, scratch of
// cols), its core, solid run and the two boundaries.
void MeasureSection(const float* row, const uchar* inside, const SectionWindow& w,
                    std::vector<double>* contrast, Section* sec) {
  std::vector<double>& c = *contrast;
  const int half = w.half, cols = 2 * half + 1, margin = w.margin;
  const double jl = (margin - 1) / 2.0, ju = cols - 1 - (margin - 1) / 2.0;
  for (int j = 0; j < cols; ++j) {
    const double bg = w.bg_lo + (w.bg_up - w.bg_lo) * (j - jl) / (ju - jl);
    c[j] = w.polarity * (row[j] - bg);
  }
  sec->bg = 0.5 * (w.bg_lo + w.bg_up);
  if (!inside[half]) return;
  int core = half;
  for (int j = half - w.core_reach; j <= half + w.core_reach; ++j) {
    if (j > 0 && j < cols - 1 && c[j] > c[core]) core = j;
  }
  sec->peak = c[core];
  if (sec->peak < 4.0 * w.noise) return;
  sec->present = true;
  {
    int lo = core, hi = core;
    while (lo > 0 && c[lo - 1] > 0.5 * sec->peak) --lo;
    while (hi < cols - 1 && c[hi + 1] > 0.5 * sec->peak) ++hi;
    sec->solid = (hi - lo + 1) * kAcrossStep;
    sec->solid_mid = (0.5 * (lo + hi) - half) * kAcrossStep;
  }
  const double threshold = std::max(kSilhouetteFraction * sec->peak, 4.0 * w.noise);
  int a = core, b = core;
  while (a > 0 && c[a - 1] > threshold) --a;
  while (b < cols - 1 && c[b + 1] > threshold) ++b;
  // The silhouette must end inside the window with background on both sides.
  if (a <= margin || b >= cols - 1 - margin) return;
  if (std::abs(w.bg_up - w.bg_lo) > 0.5 * sec->peak) return;
  bool all_inside = true;
  for (int j = std::max(0, a - 4); j <= std::min(cols - 1, b + 4); ++j)
    all_inside &= inside[j] != 0;
  if (!all_inside) return;
  const double cross_lo = (a - 1) + (threshold - c[a - 1]) / (c[a] - c[a - 1]);
  const double cross_up = (b + 1) - (threshold - c[b + 1]) / (c[b] - c[b + 1]);
  const double min_slope = threshold * kAcrossStep / 4.0;
  const double e_lo = RefineEdge(c, a - 1, core, min_slope, cross_lo);
  const double e_up = RefineEdge(c, b + 1, core, min_slope, cross_up);
  sec->n_lo = (e_lo - half) * kAcrossStep;
  sec->n_up = (e_up - half) * kAcrossStep;
  sec->valid = sec->lo_ok = sec->up_ok = sec->n_up > sec->n_lo;
}

// Cross-sections at every point of `line` [px of `gray`], half_width either side [px]; the
// core (the contrast's peak) is looked for within core_half_width of the line [px].
SectionSet AnalyseSections(const cv::Mat& gray, const std::vector<Vec2>& line, int direction,
                           int polarity, double half_width, double core_half_width) {
  SectionSet set;
  PlaceStations(line, direction, &set);
  SectionWindow w;
  w.half = static_cast<int>(std::lround(half_width / kAcrossStep));
  const int cols = 2 * w.half + 1;
  cv::Mat raw, inside;
  SampleAcross(gray, set, w.half, &raw, &inside);
  // Noise is smoothed across (σ = 1 px) and along (σ = 1.5 stations) the strip; both are far
  // below the scale of the strip's shape.
  cv::Mat u;
  cv::GaussianBlur(raw, u, cv::Size(0, 0), 1.0 / kAcrossStep, 1.5, cv::BORDER_REPLICATE);
  w.margin = std::max(4, static_cast<int>(std::lround(0.12 * cols)));
  std::vector<double> bg_lo, bg_up;
  set.noise = BackgroundLevels(u, w.margin, &bg_lo, &bg_up);
  w.noise = set.noise;
  w.polarity = polarity;
  w.core_reach = std::max(2, static_cast<int>(std::lround(core_half_width / kAcrossStep)));
  std::vector<double> c(cols);
  for (int i = 0; i < static_cast<int>(line.size()); ++i) {
    w.bg_lo = bg_lo[i];
    w.bg_up = bg_up[i];
    MeasureSection(u.ptr<float>(i), inside.ptr<uchar>(i), w, &c, &set.s[i]);
  }
  return set;
}

// Running quantile q (0.5: median) of values[i] over valid stations within ±reach. The window
// is kept sorted as it slides (one insertion and one removal per station), which gives exactly
// the quantile of each window for far less than selecting it anew every time.
std::vector<double> RunningQuantile(const std::vector<double>& values, const std::vector<char>& ok,
                                    int reach, double q = 0.5) {
  const int m = static_cast<int>(values.size());
  std::vector<double> out(m, kNaN);
  std::vector<double> window;  // sorted
  const auto add = [&](int k) {
    if (ok[k] && !std::isnan(values[k]))
      window.insert(std::upper_bound(window.begin(), window.end(), values[k]), values[k]);
  };
  const auto remove = [&](int k) {
    if (ok[k] && !std::isnan(values[k]))
      window.erase(std::lower_bound(window.begin(), window.end(), values[k]));
  };
  for (int k = 0; k <= std::min(m - 1, reach); ++k) add(k);
  for (int i = 0; i < m; ++i) {
    if (i > 0) {
      if (i - reach - 1 >= 0) remove(i - reach - 1);
      if (i + reach < m) add(i + reach);
    }
    const size_t n = window.size();
    if (n == 0) continue;
    if (q == 0.5) {
      // As Median(): the middle value, or the mean of the two middle values.
      out[i] = n % 2 == 1 ? window[n / 2] : 0.5 * (window[n / 2 - 1] + window[n / 2]);
    } else {
      out[i] = window[static_cast<size_t>(std::lround(q * (n - 1)))];
    }
  }
  return out;
}

// Drops sections whose contrast is weak, and boundaries that jump away from their neighbours'
// (a loose fibre lying against the strip, a speck), then records the typical contrast and width.
// Each boundary is judged on its own, so a frayed lower edge does not cost the upper one.
void RejectOutliers(SectionSet* set) {
  const int m = static_cast<int>(set->s.size());
  std::vector<double> peaks;
  for (const auto& s : set->s)
    if (s.present) peaks.push_back(s.peak);
  if (peaks.empty()) return;
  const double ref = Median(peaks);
  int before = 0;
  for (auto& s : set->s) {
    if (s.peak < 0.3 * ref) s.present = s.valid = s.lo_ok = s.up_ok = false;
    before += s.valid;
  }
  std::vector<double> lo(m), up(m), width(m);
  std::vector<char> ok(m);
  std::vector<double> widths;
  for (int i = 0; i < m; ++i) {
    lo[i] = set->s[i].n_lo;
    up[i] = set->s[i].n_up;
    width[i] = set->s[i].width();
    ok[i] = set->s[i].valid;
    if (ok[i]) widths.push_back(width[i]);
  }
  if (widths.empty()) return;
  // Silhouettes widen or narrow slowly: half the width or twice it, within a few widths, is a
  // fibre or a speck, not the strip.
  const double w_med = Median(widths);
  const std::vector<double> width_med =
      RunningQuantile(width, ok, std::max(20, static_cast<int>(2.0 * w_med)));
  for (int i = 0; i < m; ++i) {
    Section& s = set->s[i];
    if (s.valid && (width[i] < 0.5 * width_med[i] || width[i] > 2.0 * width_med[i])) {
      s.valid = s.lo_ok = s.up_ok = false;
    }
  }
  // Boundaries follow a smooth curve along the guide: twice, a running reference over ±1.5
  // widths, and points farther from it than 3 robust σ (at least 1 px, at most 15 % of the
  // width or 2 px) are dropped. Fibres only ever push a boundary outwards, so the reference is
  // a quantile on the inner side (30 %) rather than the median: it stays on the edge even
  // where fibres are the local majority.
  const int reach = std::max(15, static_cast<int>(1.5 * w_med));
  for (int side = 0; side < 2; ++side) {
    const std::vector<double>& v = side == 0 ? lo : up;
    for (int iter = 0; iter < 2; ++iter) {
      for (int i = 0; i < m; ++i) ok[i] = side == 0 ? set->s[i].lo_ok : set->s[i].up_ok;
      const std::vector<double> med = RunningQuantile(v, ok, reach, side == 0 ? 0.7 : 0.3);
      std::vector<double> dev;
      for (int i = 0; i < m; ++i)
        if (ok[i]) dev.push_back(std::abs(v[i] - med[i]));
      if (dev.empty()) break;
      const double tol = std::clamp(3.0 * 1.4826 * Median(dev), 1.0, std::max(2.0, 0.15 * w_med));
      for (int i = 0; i < m; ++i) {
        if (ok[i] && std::abs(v[i] - med[i]) > tol)
          (side == 0 ? set->s[i].lo_ok : set->s[i].up_ok) = false;
      }
    }
  }
  int after = 0;
  peaks.clear();
  widths.clear();
  for (auto& s : set->s) {
    s.valid = s.lo_ok && s.up_ok;
    after += s.valid;
    if (!s.valid) continue;
    peaks.push_back(s.peak);
    widths.push_back(s.width());
  }
  set->rejected = before - after;
  if (!peaks.empty()) {
    set->contrast = Median(peaks);
    set->width = Median(widths);
  }
}

// The longest stretch of sections showing the strip, with gaps of at most max_gap stations.
std::pair<int, int> LongestRun(const SectionSet& set, int max_gap) {
  std::pair<int, int> best(-1, -2);
  int first = -1, last = -1;
  for (int i = 0; i < static_cast<int>(set.s.size()); ++i) {
    if (!set.s[i].present) continue;
    if (first < 0 || i - last > max_gap + 1) first = i;
    last = i;
    if (last - first > best.second - best.first) best = {first, last};
  }
  return best;
}

// The strip's measured stretch: the longest run, without unmeasured sections at its ends and
// without a frayed end, where the strip's solid body gives way to fibres (a brush of bright
// fibres is as contrasted as the strip but has no solid core). *end_width is the typical width
// just before the end [px]; *measured_from (if given) the run's first station before the
// unusable stations of `line` at its start were skipped. {-1, -2} if nothing usable.
std::pair<int, int> TrimmedRun(const SectionSet& set, TraceLine line, double* end_width,
                               int* measured_from = nullptr) {
  auto [first, last] = LongestRun(set, std::max(15, static_cast<int>(1.5 * set.width)));
  if (last - first < 10) return {-1, -2};
  {
    std::vector<double> solid;
    for (int i = first; i <= last; ++i)
      if (set.s[i].present) solid.push_back(set.s[i].solid);
    const double ref = Median(solid);
    const int k = std::max(5, static_cast<int>(0.5 * set.width));
    while (last > first + 10) {
      std::vector<double> tail;
      for (int i = std::max(first, last - k); i <= last; ++i)
        if (set.s[i].present) tail.push_back(set.s[i].solid);
      if (!tail.empty() && Median(tail) >= 0.5 * ref && set.s[last].solid >= 0.5 * ref) break;
      --last;
    }
  }
  std::vector<double> widths;
  const int want = std::max(10, static_cast<int>(2 * set.width));
  for (int i = last; i >= first && static_cast<int>(widths.size()) < want; --i) {
    if (set.s[i].valid) widths.push_back(set.s[i].width());
  }
  if (widths.empty()) return {-1, -2};
  *end_width = Median(widths);
  if (measured_from) *measured_from = first;
  while (first < last - 10 && !set.s[first].Usable(line)) ++first;
  return {first, last};
}

// Per-station offsets along the normal for stations first..last: valid values, gaps filled by
// linear interpolation, ends by the nearest valid value.
std::vector<double> FilledOffsets(const SectionSet& set, int first, int last, TraceLine which) {
  std::vector<double> out(last - first + 1, kNaN);
  for (int i = first; i <= last; ++i) {
    const Section& s = set.s[i];
    if (!s.Usable(which)) continue;
    out[i - first] = which == TraceLine::kUpper   ? s.n_up
                     : which == TraceLine::kLower ? s.n_lo
                                                  : 0.5 * (s.n_lo + s.n_up);
  }
  int prev = -1;
  for (int k = 0; k < static_cast<int>(out.size()); ++k) {
    if (std::isnan(out[k])) continue;
    for (int g = prev + 1; prev >= 0 && g < k; ++g) {
      out[g] = out[prev] + (out[k] - out[prev]) * (g - prev) / double(k - prev);
    }
    prev = k;
  }
  if (prev < 0) return out;
  for (int k = prev + 1; k < static_cast<int>(out.size()); ++k) out[k] = out[prev];
  for (int k = 0; std::isnan(out[k]); ++k) {
    int next = k;
    while (std::isnan(out[next])) ++next;
    out[k] = out[next];
  }
  return out;
}

// Extends a polyline at its start and end along its end tangents (measured over `base` px).
std::vector<Vec2> Extend(const std::vector<Vec2>& line, double at_start, double at_end,
                         double base) {
  if (line.size() < 2) return line;
  const auto tangent = [&](bool start) {
    double run = 0.0;
    size_t k = 1;
    if (start) {
      while (k + 1 < line.size() && run < base) run += (line[k] - line[k - 1]).norm(), ++k;
      return Vec2((line[0] - line[k - 1]).normalized());
    }
    const size_t n = line.size();
    while (k + 1 < n && run < base) run += (line[n - k] - line[n - k - 1]).norm(), ++k;
    return Vec2((line[n - 1] - line[n - k]).normalized());
  };
  std::vector<Vec2> out;
  const Vec2 ts = tangent(true), te = tangent(false);
  for (int k = static_cast<int>(std::floor(at_start)); k >= 1; --k)
    out.push_back(line.front() + k * ts);
  out.insert(out.end(), line.begin(), line.end());
  for (int k = 1; k <= static_cast<int>(std::floor(at_end)); ++k)
    out.push_back(line.back() + k * te);
  return out;
}

// The guide for the next tracking pass, from a set of sections (in that set's pixels): the
// strip's solid core through a running median and a wide Gaussian, resampled every pixel.
// *w_max is the 95 % quantile of the silhouette widths [px]. False if too little was measured.
bool NextGuide(const SectionSet& set, std::vector<Vec2>* guide, double* w_max) {
  double w_end;
  const std::pair<int, int> run = TrimmedRun(set, TraceLine::kMid, &w_end);
  std::vector<double> w;
  for (const auto& s : set.s) {
    if (s.valid) w.push_back(s.width());
  }
  if (run.second - run.first < 10 || w.empty()) return false;
  // The guide must be smooth more than exact: it follows the strip's solid core (a silhouette
  // whose faint part comes and goes, an oblique face, would make the mid-line jump), through a
  // running median and a wide Gaussian; the next pass measures the boundaries again anyway.
  std::vector<double> core(run.second - run.first + 1);
  std::vector<char> has(core.size());
  for (int i = run.first; i <= run.second; ++i) {
    core[i - run.first] = set.s[i].solid_mid;
    has[i - run.first] = set.s[i].present;
  }
  core = RunningQuantile(core, has, std::max(10, static_cast<int>(set.width)));
  guide->clear();
  for (int i = run.first; i <= run.second; ++i) {
    const double n = core[i - run.first];
    guide->push_back(set.p[i] + (std::isnan(n) ? 0.0 : n) * set.n[i]);
  }
  *guide = ResampleByArc(SmoothPolyline(*guide, std::max(3.0, 0.5 * set.width)), 1.0);
  // A lit end face or a brush of fibres can still bend the end of the guide away.
  CutAtSharpTurn(guide, std::max(20.0, set.width), /*check_growth=*/true);
  std::sort(w.begin(), w.end());
  *w_max = w[static_cast<size_t>(0.95 * (w.size() - 1))];
  return true;
}

// Full-resolution pixel <-> pixel of an image reduced by the integer factor f (box average of
// f x f pixels, cv::INTER_AREA).
Vec2 ReducedFromFull(const Vec2& p, int f) { return (p.array() + 0.5) / f - 0.5; }
Vec2 FullFromReduced(const Vec2& p, int f) { return (p.array() + 0.5) * f - 0.5; }

// `line` (a guide extended straight back by its first points before `start`) with that back
// extension replaced by the coarse line from `start` back to `reach` px beyond the point
// nearest `target`, if that lies behind `start` along the coarse line; else `line`.
std::vector<Vec2> ReachBackAlong(const std::vector<Vec2>& coarse, const std::vector<Vec2>& line,
                                 const Vec2& start, const Vec2& target, double reach) {
  const auto nearest = [&](const Vec2& q) {
    size_t best = 0;
    for (size_t k = 1; k < coarse.size(); ++k)
      if ((coarse[k] - q).squaredNorm() < (coarse[best] - q).squaredNorm()) best = k;
    return best;
  };
  const size_t from = nearest(start), to = nearest(target);
  if (to + 2 > from) return line;
  size_t k0 = 0;  // the guide's start in `line`
  while (k0 + 1 < line.size() && (line[k0] - start).squaredNorm() > 1e-12) ++k0;
  // The coarse line is resampled every pixel of arc: reach px are as many points.
  const size_t first = to - std::min(to, static_cast<size_t>(reach));
  std::vector<Vec2> out(coarse.begin() + first, coarse.begin() + from);
  out.insert(out.end(), line.begin() + k0, line.end());
  return ResampleByArc(SmoothPolyline(out, 2.0), 1.0);
}

// Cross-sections along the strip at full resolution: a first pass on the coarse line (width
// about t_full px), then passes on the measured line (whose normals cross the strip squarely),
// extended along the strip for as long as it continues, so that tracking goes on past where the
// reduced image lost the strip. root_ext: how far to look back beyond the held end [px].
// The first pass, whose window is wide, may run on `mid`, the photo reduced by the integer
// factor `f` (f = 1: none): it only places the guide, which the later passes measure again at
// full resolution, and it costs f² less there. *ok is false if the first pass found too little
// to follow. With a root_target (--edge-px: where the strip leaves its support) behind the
// measured stretch's start, each later pass reaches back along the coarse line to root_ext
// beyond it instead of straight on: the first, wide pass may start its measured stretch far
// down a sharp bend (where the platform's corner merges with the strip in its wide window),
// and a straight extension leaves a bend within a few widths.
SectionSet TrackStrip(const cv::Mat& gray, const cv::Mat& mid, int f,
                      const std::vector<Vec2>& coarse, int direction, int polarity, double t_full,
                      double root_ext, const std::optional<Vec2>& root_target, bool* ok) {
  *ok = true;
  // The reduced image may show only the strip's brightest part (a lit edge): the first window is
  // wide enough for an oblique face several times wider, and the core is looked for widely.
  const double half_1 =
      std::max({3.0 * t_full + 15.0, 0.06 * std::max(gray.cols, gray.rows), 20.0});
  std::vector<Vec2> line =
      Extend(coarse, root_ext, 2.0 * t_full + 20.0, std::max(10.0, 2.0 * t_full));
  SectionSet set;
  int set_f = 1;  // full-resolution pixels per pixel of `set`
  if (f > 1) {
    for (Vec2& p : line) p = ReducedFromFull(p, f);
    line = ResampleByArc(line, 1.0);
    set = AnalyseSections(mid, line, direction, polarity, half_1 / f, 0.6 * half_1 / f);
    set_f = f;
  } else {
    set = AnalyseSections(gray, line, direction, polarity, half_1, 0.6 * half_1);
  }
  RejectOutliers(&set);
  for (int pass = 0; pass < 12; ++pass) {
    std::vector<Vec2> guide;
    double w_max;
    if (!NextGuide(set, &guide, &w_max)) {
      *ok = set_f == 1;
      break;
    }
    const double width = set.width * set_f;
    w_max *= set_f;
    if (set_f > 1) {
      for (Vec2& p : guide) p = FullFromReduced(p, set_f);
      guide = ResampleByArc(guide, 1.0);
    }
    const double half_2 = 0.5 * w_max + std::max(12.0, 0.75 * width);
    const double ahead = std::max(60.0, 4.0 * width);
    line = Extend(guide, root_ext, ahead, std::max(10.0, 2.0 * width));
    if (root_target) line = ReachBackAlong(coarse, line, guide.front(), *root_target, root_ext);
    set = AnalyseSections(gray, line, direction, polarity, half_2, 0.5 * w_max + 3.0);
    set_f = 1;
    RejectOutliers(&set);
    // Done unless the strip still shows at the far end of the extension, or it was followed
    // well into the extension: the extension is straight, and a strip that curves leaves it
    // before its far end although it goes on (the next guide follows it further). A strip
    // that ends is measured to where the previous guide ended, and no further.
    double unused;
    const std::pair<int, int> now = TrimmedRun(set, TraceLine::kMid, &unused);
    const int far_end = static_cast<int>(set.s.size()) - 1 - static_cast<int>(0.5 * ahead);
    if (now.second < now.first) break;
    const Vec2 tangent =
        (guide.back() - guide[guide.size() > 10 ? guide.size() - 11 : 0]).normalized();
    const bool grew = (set.p[now.second] - guide.back()).dot(tangent) > std::max(5.0, width);
    if (pass > 0 && now.second < far_end && !grew) break;
  }
  return set;
}

enum class TipStatus { kFound, kLeftImage, kNoEnd };

// Axial position of the tip beyond a station [px along the tangent from `centre`; may be
// negative]: where the solid width of the strip falls to half of its value just before. The
// solid width of a cross-section is its longest run of samples above half the strip's peak
// contrast: a loose fibre adds a run of a pixel or two, the band a run of its whole width, so
// a frayed end is not followed. *status says whether the image or the search range ended first.
double FindTip(const cv::Mat& gray, const Vec2& centre, const Vec2& tangent, const Vec2& normal,
               double width, double bg, double peak, int polarity, TipStatus* status) {
  *status = TipStatus::kFound;
  const double w = std::max(width, 3.0);
  std::vector<double> t_at, a_at;
  for (double t = -2.0 * w; t <= 3.0 * w + 20.0; t += 0.5) {
    int count = 0, run = 0, longest = 0;
    for (double u = -0.75 * w; u <= 0.75 * w + 1e-9; u += 0.5) {
      const Vec2 q = centre + t * tangent + u * normal;
      double v;
      if (!SampleGray(gray, q.x(), q.y(), &v)) {
        run = 0;
        continue;
      }
      ++count;
      run = polarity * (v - bg) > 0.5 * peak ? run + 1 : 0;
      longest = std::max(longest, run);
    }
    if (count == 0) {
      if (t > -0.5 * w) {
        *status = TipStatus::kLeftImage;
        break;
      }
      continue;
    }
    t_at.push_back(t);
    a_at.push_back(0.5 * longest);
  }
  std::vector<double> before;
  for (size_t k = 0; k < t_at.size(); ++k)
    if (t_at[k] <= -0.5 * w) before.push_back(a_at[k]);
  if (before.empty()) return 0.0;
  // Smooth lightly along the axis so that single noisy samples do not end the strip.
  std::vector<Vec2> pts;
  for (double v : a_at) pts.emplace_back(v, 0.0);
  pts = SmoothPolyline(pts, 2.0);
  const double half = 0.5 * Median(before);
  for (size_t k = 1; k < t_at.size(); ++k) {
    if (t_at[k] < -0.5 * w) continue;
    if (pts[k].x() < half) {
      // The width may have fallen below half already before -w/2 (the end lies a little
      // behind `centre`): the crossing is the last one before k, not an extrapolation from
      // the two samples at k.
      size_t j = k;
      while (j > 0 && pts[j - 1].x() < half) --j;
      *status = TipStatus::kFound;  // the strip ends before the image does
      if (j == 0) return t_at[0];
      const double a0 = pts[j - 1].x(), a1 = pts[j].x();
      const double f = std::clamp((a0 - half) / (a0 - a1), 0.0, 1.0);
      return t_at[j - 1] + f * (t_at[j] - t_at[j - 1]);
    }
  }
  if (*status == TipStatus::kFound) *status = TipStatus::kNoEnd;
  return 0.0;
}

// --edge-px may lie at most this many strip widths plus kEdgeFarPx from the traced line (or
// its straight continuation back from its start): a platform's corner lies half a width under
// the mid-line, a width under the upper edge.
constexpr double kEdgeFarWidths = 3.0;
constexpr double kEdgeFarPx = 10.0;

std::string Fmt(double v, int precision = 3) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(precision);
  s << v;
  return s.str();
}

const char* BorderName(int b) {
  return b & kLeft ? "left" : b & kRight ? "right" : b & kTop ? "top" : "bottom";
}

}  // namespace

bool ExtractOptions::Check(std::string* why) const {
  // Finer than 0.01 mm only interpolates (a pixel is 0.05-0.2 mm on a cantilever photo) and
  // makes files of millions of rows; coarser than 10 mm leaves too few points on most strips.
  if (!(std::isfinite(step_mm) && step_mm >= kMinStepMm && step_mm <= kMaxStepMm)) {
    *why = "step_mm must lie in [" + Fmt(kMinStepMm, 2) + ", " + Fmt(kMaxStepMm, 0) + "] mm";
    return false;
  }
  if (level_deg && !(std::isfinite(*level_deg) && std::abs(*level_deg) <= 45.0)) {
    *why = "level_deg must lie in [-45, 45] degrees";
    return false;
  }
  if (edge_px && !(std::isfinite(edge_px->x()) && std::isfinite(edge_px->y()))) {
    *why = "edge_px must be two finite numbers";
    return false;
  }
  if (tip_px && !(std::isfinite(tip_px->x()) && std::isfinite(tip_px->y()))) {
    *why = "tip_px must be two finite numbers";
    return false;
  }
  if (detect_side_px < 200 || detect_side_px > 8000) {
    *why = "detect_side_px must lie in [200, 8000]";
    return false;
  }
  if (!(std::isfinite(max_seconds) && max_seconds >= 0.0)) {
    *why = "max_seconds must be a finite number >= 0 [s]";
    return false;
  }
  return true;
}

std::string ExtractionSummary::BriefReport() const {
  std::ostringstream s;
  if (!success) {
    s << source << ": failed: " << message;
    return s.str();
  }
  s << source << ": " << rig_type << " rig (" << rig_detail << "), strip " << polarity
    << " on its background, overhang to the " << direction << ", trace " << trace << "\n";
  s << "  " << profile.size() << " points, L = " << Fmt(length_mm, 2) << " mm, tip (x, y) = ("
    << Fmt(tip_mm.x(), 2) << ", " << Fmt(tip_mm.y(), 2) << ") mm, " << Fmt(mm_per_px, 5)
    << " mm/px, silhouette " << Fmt(width_px, 1) << " px wide";
  const ExtractionConfidence& c = confidence;
  if (!c.held_end.empty()) {
    s << "\n  confidence: held end " << c.held_end << ", tip " << c.tip << ", "
      << Fmt(100.0 * c.sections_measured, 0) << " % of sections measured";
    if (c.shape && c.shape->converged)
      s << ", heavy cantilever within " << Fmt(units::MToMm(c.shape->rms), 3) << " mm rms"
        << (c.shape->plausible ? "" : " (FAILS the 1 mm check)");
    else if (c.shape)
      s << ", no heavy cantilever fits (FAILS the physics check)";
  }
  for (const Note& w : warnings) s << "\n  warning: " << w.text;
  return s.str();
}

std::vector<std::string> ExtractionSummary::WarningTexts() const {
  std::vector<std::string> texts;
  for (const Note& w : warnings) texts.push_back(w.text);
  return texts;
}

namespace extract_internal {

void CheckExtractInputs(const cv::Mat& gray, const Rig& rig, const ExtractOptions& options,
                        const std::string& source) {
  if (gray.empty() || gray.type() != CV_8UC1) {
    throw InputError(source + ": expected an 8-bit grey image");
  }
  std::string why;
  if (!options.Check(&why)) throw InputError(source + ": " + why);
  const int W = gray.cols, H = gray.rows;
  if (options.edge_px && !(options.edge_px->x() >= -0.5 && options.edge_px->x() <= W - 0.5 &&
                           options.edge_px->y() >= -0.5 && options.edge_px->y() <= H - 0.5)) {
    throw InputError("--edge-px " + Fmt(options.edge_px->x(), 1) + "," +
                     Fmt(options.edge_px->y(), 1) + " lies outside " + source + " (" +
                     std::to_string(W) + "x" + std::to_string(H) + " px)");
  }
  if (options.tip_px && !(options.tip_px->x() >= -0.5 && options.tip_px->x() <= W - 0.5 &&
                          options.tip_px->y() >= -0.5 && options.tip_px->y() <= H - 0.5)) {
    throw InputError("--tip-px " + Fmt(options.tip_px->x(), 1) + "," +
                     Fmt(options.tip_px->y(), 1) + " lies outside " + source + " (" +
                     std::to_string(W) + "x" + std::to_string(H) + " px)");
  }
  rig.CheckForImage(W, H, source);
}

void ReduceImages(ExtractState* s) {
  const int W = s->gray.cols, H = s->gray.rows;
  s->scale = std::min(1.0, s->options.detect_side_px / double(std::max(W, H)));
  // Large photos get an intermediate level too, reduced by an integer factor to about 2000 px
  // (a box average, the fast case of cv::INTER_AREA; the photo's last f - 1 rows and columns
  // are left out): the first, wide tracking pass runs on it, and the detection image is
  // reduced from it rather than from the photo.
  s->mid_factor = std::max(1, std::max(W, H) / 2000);
  const int f = s->mid_factor;
  if (f > 1) {
    const int mw = W / f, mh = H / f;
    cv::resize(s->gray(cv::Rect(0, 0, mw * f, mh * f)), s->mid, cv::Size(mw, mh), 0, 0,
               cv::INTER_AREA);
  }
  if (s->scale < 1.0 && f > 1) {
    const cv::Size size(static_cast<int>(std::lround(W * s->scale)),
                        static_cast<int>(std::lround(H * s->scale)));
    cv::resize(s->mid, s->small, size, 0, 0, cv::INTER_AREA);
  } else if (s->scale < 1.0) {
    cv::resize(s->gray, s->small, cv::Size(), s->scale, s->scale, cv::INTER_AREA);
  } else {
    s->small = s->gray;
  }
}

namespace {

// A reduced-image point in full-resolution pixels.
Vec2 FullFromSmall(const ExtractState& s, const Vec2& p) {
  return Vec2((p.x() + 0.5) / s.scale - 0.5, (p.y() + 0.5) / s.scale - 0.5);
}

// "(x,y)-(x,y) px": the two ends of a reduced-image band, at full resolution.
std::string EndsText(const ExtractState& s, const cv::Mat& mask) {
  const Sweep e = DoubleSweep(mask);
  const Vec2 a = FullFromSmall(s, Vec2(e.a.x, e.a.y)), b = FullFromSmall(s, Vec2(e.b.x, e.b.y));
  return "(" + Fmt(a.x(), 0) + "," + Fmt(a.y(), 0) + ")-(" + Fmt(b.x(), 0) + "," + Fmt(b.y(), 0) +
         ") px";
}

// A second strip, as long and clear as the chosen one, apart from it: the photo shows two
// cantilevers and nothing says which one to measure, unless --edge-px does (then the strip
// nearer to it is taken).
StageFailure ResolveSecondStrip(ExtractState* s, const std::vector<Strip>& strips) {
  const std::optional<size_t> k = SecondStrip(strips, s->strip);
  if (!k) return std::nullopt;
  const Strip& other = strips[*k];
  if (Vec2 at; OverhangsOnBothSides(s->small, s->strip, other, &at)) {
    return DrapedMessage(FullFromSmall(*s, at));
  }
  const ExtractOptions& options = s->options;
  if (!options.edge_px) {
    return "two strips in the photo, one from " + EndsText(*s, s->strip.mask) +
           ", the other from " + EndsText(*s, other.mask) +
           "; photograph one at a time, or give --edge-px X,Y at the held end of the one to "
           "measure";
  }
  const double scale = s->scale;
  const cv::Point e(static_cast<int>(std::lround((options.edge_px->x() + 0.5) * scale - 0.5)),
                    static_cast<int>(std::lround((options.edge_px->y() + 0.5) * scale - 0.5)));
  if (DistanceToMask(other.mask, e) < DistanceToMask(s->strip.mask, e)) {
    s->strip = other;
    s->own_blocks = PrepareStrip(s->strip.polarity > 0 ? s->light : s->dark, &s->strip);
  }
  return std::nullopt;
}

}  // namespace

StageFailure FindStrip(ExtractState* s) {
  // Background flattening: hats with a kernel far wider than any strip but smaller than the
  // light's gradients and broad shadows; a light and a dark strip show in one of the two.
  const cv::Mat& small = s->small;
  const int kernel = std::max(15, static_cast<int>(std::max(small.cols, small.rows) / 10)) | 1;
  const cv::Mat se = cv::getStructuringElement(cv::MORPH_RECT, {kernel, kernel});
  cv::morphologyEx(small, s->light, cv::MORPH_TOPHAT, se);
  cv::morphologyEx(small, s->dark, cv::MORPH_BLACKHAT, se);
  std::vector<Strip> strips;
  CollectStrips(s->light, +1, &strips);
  CollectStrips(s->dark, -1, &strips);
  if (strips.empty()) return "no strip found: nothing long and thin contrasts with the background";
  std::sort(strips.begin(), strips.end(),
            [](const Strip& a, const Strip& b) { return a.score > b.score; });
  s->strip = strips.front();
  for (size_t k = 1; k < strips.size(); ++k) {
    if (strips[k].polarity != s->strip.polarity && strips[k].score > 0.5 * s->strip.score) {
      s->summary.warnings.push_back({"other_polarity_band_ignored",
                                     "a " + std::string(s->strip.polarity > 0 ? "dark" : "light") +
                                         " band almost as prominent as the strip was ignored"});
      break;
    }
  }
  s->own_blocks = PrepareStrip(s->strip.polarity > 0 ? s->light : s->dark, &s->strip);
  return ResolveSecondStrip(s, strips);
}

void FindStripBlocks(ExtractState* s) {
  s->summary.polarity = s->strip.polarity > 0 ? "light" : "dark";
  s->sweep = DoubleSweep(s->strip.mask);
  s->t_small = std::max(1.0, cv::countNonZero(s->strip.mask) / std::max(1.0, s->sweep.length));
  const int side = 2 * static_cast<int>(s->t_small) + 3;
  cv::dilate(s->strip.mask, s->strip_zone,
             cv::getStructuringElement(cv::MORPH_ELLIPSE, {side, side}));
  for (const Block& b : s->own_blocks) s->strip_zone |= b.mask;
  s->blocks = FindBlocks(s->small, s->strip_zone, s->t_small);
  for (Block& b : s->own_blocks) s->blocks.push_back(std::move(b));
  s->own_blocks.clear();
}

StageFailure FindHeldEnd(ExtractState* s) {
  // The held end leaves the left or right border, or a block; a free end that touches any
  // border is a tip cut off by the image.
  const Sweep& sweep = s->sweep;
  s->end_radius = std::max(2.0, 1.5 * s->t_small);
  const int at_a = BordersNear(s->strip.mask, sweep.dist_a, sweep.box, s->end_radius);
  const int at_b = BordersNear(s->strip.mask, sweep.dist_b, sweep.box, s->end_radius);
  const int sides = kLeft | kRight;
  if (s->options.edge_px) {
    // The held end is the one at a side border if only one is (a free tip there would be cut
    // off), else the one nearer the edge given. Not simply the nearer one: a short strip
    // lying far along a platform from the border has its tip nearer the platform's corner
    // (pabst-fig8_L040mm.jpg was refused as a tip cut off by the border).
    const Vec2 e = *s->options.edge_px;
    if (static_cast<bool>(at_a & sides) != static_cast<bool>(at_b & sides)) {
      s->root_is_a = (at_a & sides) != 0;
    } else {
      s->root_is_a = (FullFromSmall(*s, Vec2(sweep.a.x, sweep.a.y)) - e).norm() <=
                     (FullFromSmall(*s, Vec2(sweep.b.x, sweep.b.y)) - e).norm();
    }
    s->root_how = "edge";
  } else if ((at_a & sides) && !(at_b & sides)) {
    s->root_is_a = true;
    s->root_how = "border";
  } else if ((at_b & sides) && !(at_a & sides)) {
    s->root_is_a = false;
    s->root_how = "border";
  } else if ((at_a & sides) && (at_b & sides)) {
    return "the free tip is cut off by the image border (the strip crosses the whole photo)" +
           std::string(kWholeStripInView);
  } else if (at_a != kNoBorder || at_b != kNoBorder) {
    s->root_is_a = at_a == kNoBorder;  // the end at the top/bottom border is the cut tip
    s->root_how = "block";
  } else {
    const double da = DistanceToBlocks(s->blocks, sweep.a);
    const double db = DistanceToBlocks(s->blocks, sweep.b);
    if (std::min(da, db) <= 3.0 * s->t_small + 5.0) {
      s->root_is_a = da <= db;
      s->root_how = "block";
    } else {
      // Nothing holds either end in view: the held end of a hanging strip is the higher one.
      s->root_is_a = sweep.a.y <= sweep.b.y;
      s->root_how = "guess";
      s->summary.warnings.push_back(
          {"held_end_guessed",
           "no clamp, platform or border holds the strip; took its higher end as the held end"});
    }
  }
  s->root_borders = s->root_is_a ? at_a : at_b;
  const int tip_borders = s->root_is_a ? at_b : at_a;
  if (tip_borders != kNoBorder) {
    return std::string("the free tip is cut off by the image border (") + BorderName(tip_borders) +
           ")" + kWholeStripInView;
  }
  return std::nullopt;
}

StageFailure TraceCoarseLine(ExtractState* s) {
  const cv::Mat& small = s->small;
  const bool at_side = s->root_how == "border" && (s->root_borders & (kLeft | kRight));
  std::vector<cv::Point> seeds;
  if (at_side) {
    const int x_border = (s->root_borders & kLeft) ? 0 : small.cols - 1;
    for (int y = 0; y < small.rows; ++y) {
      if (s->strip.mask.at<uchar>(y, x_border) &&
          (s->root_is_a ? s->sweep.DistA(x_border, y) : s->sweep.DistB(x_border, y)) <=
              s->end_radius + 2.0 * s->t_small) {
        seeds.emplace_back(x_border, y);
      }
    }
  }
  if (seeds.empty()) seeds.push_back(s->root_is_a ? s->sweep.a : s->sweep.b);
  std::vector<double> widths_small;
  std::vector<Vec2> coarse = LevelSetCentreline(s->strip.mask, seeds, &widths_small);
  if (coarse.size() < 5) return "no strip found: the detected band is too short";
  if (Vec2 peak; DrapedOverBlock(coarse, s->blocks, s->t_small, &peak)) {
    return DrapedMessage(FullFromSmall(*s, peak));
  }
  for (Vec2& p : coarse) p = FullFromSmall(*s, p);
  coarse = SmoothPolyline(coarse, std::max(2.0, 0.5 * s->t_small));
  coarse = ResampleByArc(coarse, 1.0);
  s->t_full = s->t_small / s->scale;
  CutAtSharpTurn(&coarse, std::max(10.0, 2.0 * s->t_full), /*check_growth=*/false,
                 /*from_fraction=*/0.6);
  if (at_side) {
    s->direction = (s->root_borders & kLeft) ? +1 : -1;
  } else {
    s->direction = coarse.back().x() >= coarse.front().x() ? +1 : -1;
  }
  s->coarse = std::move(coarse);
  s->summary.direction = s->direction > 0 ? "right" : "left";
  return std::nullopt;
}

namespace {

// The platform under the held end: the block nearest to the held end of the coarse line (a
// strip lying on a platform that contrasts with it starts on the platform, else at its
// corner), or one found by its front face. Sets *why to why none was found.
PlatformFit FindPlatform(ExtractState* s, std::string* why) {
  const cv::Mat& small = s->small;
  const Vec2& front = s->coarse.front();
  const cv::Point held(std::clamp(static_cast<int>(std::lround((front.x() + 0.5) * s->scale - 0.5)),
                                  0, small.cols - 1),
                       std::clamp(static_cast<int>(std::lround((front.y() + 0.5) * s->scale - 0.5)),
                                  0, small.rows - 1));
  double best_d = 1e300;
  int best_k = -1;
  for (size_t k = 0; k < s->blocks.size(); ++k) {
    const double d = DistanceToBlocks({s->blocks[k]}, held);
    if (d < best_d) {
      best_d = d;
      best_k = static_cast<int>(k);
    }
  }
  PlatformFit platform;
  if (best_k >= 0 && best_d <= 3.0 * s->t_small + 5.0) {
    platform =
        FitPlatform(s->gray, s->blocks[best_k], s->scale, s->direction, s->coarse, s->t_full);
    if (!platform.found) *why = platform.why_not;
  } else if (s->root_how == "border" || s->root_how == "guess") {
    // No region stands out under the held end, and the strip comes in from the border (a
    // clamp out of view?) or from nowhere: a platform whose faces the light makes as light
    // as the background in places, or whose top merges with the strip, still shows its
    // front face as a long straight edge.
    if (auto block = FindBlockByFrontEdge(small, s->strip_zone, s->coarse, s->scale, s->direction,
                                          s->t_small)) {
      platform = FitPlatform(s->gray, *block, s->scale, s->direction, s->coarse, s->t_full);
      if (!platform.found) *why = platform.why_not;
      s->blocks.push_back(std::move(*block));
      if (platform.found && s->root_how == "guess") {
        std::erase_if(s->summary.warnings,
                      [](const Note& w) { return w.code == "held_end_guessed"; });
      }
    }
  }
  return platform;
}

// The blocks' outlines at full resolution, for the overlay.
void RecordBlockOutlines(ExtractState* s) {
  for (const Block& b : s->blocks) {
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(b.mask.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
    for (auto& contour : contours) {
      for (cv::Point& q : contour) {
        const Vec2 f = FullFromSmall(*s, Vec2(q.x, q.y));
        q = cv::Point(static_cast<int>(std::lround(f.x())), static_cast<int>(std::lround(f.y())));
      }
      s->summary.blocks_px.push_back(std::move(contour));
    }
  }
}

}  // namespace

StageFailure FindRig(ExtractState* s) {
  if (s->options.rig != RigKind::kClamp) {
    std::string why = "no block under the strip's held end";
    s->platform = FindPlatform(s, &why);
    if (s->options.rig == RigKind::kPlatform && !s->platform.found) {
      return "platform not found: " + why;
    }
    // The strip lies on a block that could not be measured as a platform. Taken for a clamp
    // instead, the origin would be put where the strip leaves the image border (extrapolated)
    // or where its held end lies on the block, either far behind the platform's edge, and the
    // profile would be wrong with no sign of it: refuse.
    if (!s->platform.found && s->platform.under_strip &&
        (s->root_how == "border" || s->root_how == "block")) {
      return "the strip lies on a block that looks like a platform, but " + why +
             "; give the platform's edge with --edge-px X,Y (and --level-deg if the camera is "
             "rolled), or --rig-type clamp if the block is a clamp";
    }
  }
  RecordBlockOutlines(s);
  return std::nullopt;
}

namespace {

std::string TraceName(TraceLine line) {
  return line == TraceLine::kUpper ? "upper" : line == TraceLine::kLower ? "lower" : "mid";
}

// The traced line must be measured along enough of the strip: its gaps are bridged by
// interpolation, but a line measured nowhere (the upper edge of a very thick strip) has
// nothing to bridge, and one measured on a few sections would follow the guide, not the
// strip. A quarter of the stations at least; on the real photos a third of the sections
// lose their upper edge to fibres, which leaves two thirds.
StageFailure CheckTraceMeasured(const ExtractState& s) {
  const auto usable = [&](TraceLine line) {
    int n = 0;
    for (int i = s.measured_from; i <= s.last; ++i) n += s.set.s[i].Usable(line);
    return n;
  };
  const int stations = s.last - s.measured_from + 1;
  const auto enough = [&](int n) { return n >= 10 && 4 * n >= stations; };
  const TraceLine trace = s.options.trace;
  const int have = usable(trace);
  if (enough(have)) return std::nullopt;
  const auto what = [&](TraceLine line) {
    return line == TraceLine::kMid ? std::string("mid-line (both edges)")
                                   : TraceName(line) + " edge";
  };
  std::string m = "the strip's " + what(trace) + " is measured on only " + std::to_string(have) +
                  " of its " + std::to_string(stations) +
                  " cross-sections (a quarter needed: a very thick strip, a faint or frayed "
                  "edge?)";
  std::string others;
  for (TraceLine line : {TraceLine::kLower, TraceLine::kUpper, TraceLine::kMid}) {
    if (line == trace) continue;
    const int n = usable(line);
    if (enough(n)) {
      others += (others.empty() ? "" : ", ") + ("--trace " + TraceName(line)) + " (" +
                std::to_string(n) + ")";
    }
  }
  if (!others.empty()) m += "; measured enough: " + others;
  return m;
}

}  // namespace

StageFailure MeasureSections(ExtractState* s) {
  const double t_full = s->t_full;
  const double root_ext = s->root_how == "border" ? 3.0 * t_full + 10.0 : 2.0 * t_full + 10.0;
  // The first pass runs on the intermediate level if the strip is at least 4 px thick there.
  const int first_f = s->mid_factor > 1 && t_full >= 4.0 * s->mid_factor ? s->mid_factor : 1;
  bool tracked;
  s->set = TrackStrip(s->gray, s->mid, first_f, s->coarse, s->direction, s->strip.polarity, t_full,
                      root_ext, s->options.edge_px, &tracked);
  if (!tracked) {
    s->set = TrackStrip(s->gray, s->mid, 1, s->coarse, s->direction, s->strip.polarity, t_full,
                        root_ext, s->options.edge_px, &tracked);
  }
  const std::pair<int, int> run =
      TrimmedRun(s->set, s->options.trace, &s->w_end, &s->measured_from);
  s->first = run.first;
  s->last = run.second;
  if (run.second - run.first < 10) return "no strip found: its edges could not be measured";
  if (StageFailure why = CheckTraceMeasured(*s)) return why;
  s->summary.contrast = s->set.contrast;
  s->summary.noise = s->set.noise;
  s->summary.width_px = s->set.width;
  return std::nullopt;
}

void TraceMeasuredLine(ExtractState* s) {
  // Sections within ¾ of a width of the end straddle the end face: the line stops before them
  // (FindTipEnd continues it).
  const SectionSet& set = s->set;
  const int first = s->first, last = s->last;
  const int cut = std::min(static_cast<int>(0.75 * s->w_end), (last - first) / 4);
  s->end_i = last - cut;
  // The traced offsets: a running median over half a core width removes what the outlier test
  // let through (a fibre crossing a few sections), a Gaussian of half the profile's sample
  // spacing (at least 2 px) the remaining noise before resampling.
  std::vector<double> offsets = FilledOffsets(set, first, s->end_i, s->options.trace);
  {
    std::vector<double> cores;
    for (int i = first; i <= s->end_i; ++i)
      if (set.s[i].present) cores.push_back(set.s[i].solid);
    const int reach = std::max(2, static_cast<int>(0.5 * Median(cores)));
    offsets = RunningQuantile(offsets, std::vector<char>(offsets.size(), 1), reach);
  }
  std::vector<Vec2>& trace = s->trace;
  trace.clear();
  for (int i = first; i <= s->end_i; ++i) trace.push_back(set.p[i] + offsets[i - first] * set.n[i]);
  const double step_px = s->options.step_mm / s->rig.MmPerPxAt(trace.front());
  trace = SmoothPolyline(trace, std::clamp(0.5 * step_px, 2.0, 10.0));
  for (int i = first; i <= last; ++i) {
    if (set.s[i].up_ok) s->summary.upper_px.push_back(set.p[i] + set.s[i].n_up * set.n[i]);
    if (set.s[i].lo_ok) s->summary.lower_px.push_back(set.p[i] + set.s[i].n_lo * set.n[i]);
  }
}

StageFailure FindTipEnd(ExtractState* s) {
  // The line is continued straight from the stretch before the end face, to where the
  // contrast along the strip's middle falls to half (a frayed end was already trimmed to where
  // sections collapse to fibre width).
  const SectionSet& set = s->set;
  std::vector<Vec2>& trace = s->trace;
  const int end_i = s->end_i;
  const std::vector<double> mids = FilledOffsets(set, s->first, end_i, TraceLine::kMid);
  const int k = std::min<int>(static_cast<int>(trace.size()) - 1,
                              std::max(10, static_cast<int>(2.0 * s->w_end)));
  const Vec2 tangent = (trace.back() - trace[trace.size() - 1 - k]).normalized();
  if (s->options.tip_px) return TakeGivenTip(s, tangent);
  const Vec2 normal = s->direction * Vec2(tangent.y(), -tangent.x());
  const Vec2 centre = set.p[end_i] + mids.back() * set.n[end_i];
  TipStatus status;
  std::vector<double> peaks;
  for (int i = end_i; i >= s->first && peaks.size() < 20; --i)
    if (set.s[i].valid) peaks.push_back(set.s[i].peak);
  const double peak = peaks.empty() ? set.contrast : Median(peaks);
  const double t_tip = FindTip(s->gray, centre, tangent, normal, s->w_end, set.s[end_i].bg, peak,
                               s->strip.polarity, &status);
  if (status == TipStatus::kNoEnd) {
    s->summary.warnings.push_back(
        {"tip_end_unclear",
         "the tip's end is unclear (the strip's contrast does not fall off); took the last "
         "measured section"});
  }
  const Vec2 end = trace.back();
  while (trace.size() > 2 && (trace.back() - end).dot(tangent) > t_tip) trace.pop_back();
  const Vec2 tip = end + t_tip * tangent;
  trace.push_back(tip);
  s->summary.tip_px = tip;
  const int W = s->gray.cols, H = s->gray.rows;
  const double clearance =
      std::min({tip.x() + 0.5, W - 0.5 - tip.x(), tip.y() + 0.5, H - 0.5 - tip.y()});
  if (status == TipStatus::kLeftImage || clearance < 0.5 * s->w_end + 2.0) {
    s->summary.trace_px = trace;
    return "the free tip is cut off by the image border (or lies within " +
           Fmt(0.5 * s->w_end + 2.0, 0) + " px of it)" + kWholeStripInView;
  }
  return std::nullopt;
}

namespace {

// Distance from e to a polyline [px]; *arc: the arc length from its start to the nearest
// point [px].
double DistanceToPolyline(const Vec2& e, const std::vector<Vec2>& line, double* arc) {
  double best = (e - line.front()).norm(), run = 0.0;
  *arc = 0.0;
  for (size_t k = 1; k < line.size(); ++k) {
    const Vec2 d = line[k] - line[k - 1];
    const double f =
        std::clamp((e - line[k - 1]).dot(d) / std::max(d.squaredNorm(), 1e-12), 0.0, 1.0);
    const double miss = (e - line[k - 1] - f * d).norm();
    if (miss < best) best = miss, *arc = run + f * d.norm();
    run += d.norm();
  }
  return best;
}

// The largest distance of `line`'s points up to arc length `along` from the chord over them
// [px].
double SagittaUpTo(const std::vector<Vec2>& line, double along) {
  double sagitta = 0.0, run = 0.0;
  size_t end = 1;
  while (end + 1 < line.size() && run < along) run += (line[end] - line[end - 1]).norm(), ++end;
  const Vec2& a = line.front();
  const Vec2 chord = line[end - 1] - a;
  const double n = chord.norm();
  for (size_t k = 0; k < end && n > 0.0; ++k) {
    const Vec2 d = line[k] - a;
    sagitta = std::max(sagitta, std::abs(d.x() * chord.y() - d.y() * chord.x()) / n);
  }
  return sagitta;
}

}  // namespace

StageFailure TakeGivenTip(ExtractState* s, const Vec2& tangent) {
  std::vector<Vec2>& trace = s->trace;
  const Vec2 tip = *s->options.tip_px;
  const Vec2 end = trace.back();
  const double ahead = (tip - end).dot(tangent);
  double arc = 0.0;
  const double miss = ahead > 0.0 ? std::abs((tip - end).dot(Vec2(tangent.y(), -tangent.x())))
                                  : DistanceToPolyline(tip, trace, &arc);
  const double allowed = 2.0 * std::max(s->w_end, 2.0);
  if (miss > allowed)
    throw InputError("--tip-px " + Fmt(tip.x(), 1) + "," + Fmt(tip.y(), 1) + " lies " +
                     Fmt(miss, 0) + " px off the strip's traced line (at most " +
                     Fmt(allowed, 0) + " px; the line ends at " + Fmt(end.x(), 0) + "," +
                     Fmt(end.y(), 0) + " px: see the overlay)");
  if (ahead <= 0.0) {
    // Cut the line at the point: drop what lies beyond its arc length.
    std::vector<double> run(trace.size(), 0.0);
    for (size_t i = 1; i < trace.size(); ++i) run[i] = run[i - 1] + (trace[i] - trace[i - 1]).norm();
    while (trace.size() > 2 && run[trace.size() - 1] >= arc) trace.pop_back();
  }
  trace.push_back(tip);
  s->summary.tip_px = tip;
  return std::nullopt;
}

void CheckEdgeGiven(const ExtractState& s, std::vector<Note>* warnings) {
  if (!s.options.edge_px) return;
  // The edge is where the strip leaves its support: on the traced line (a clamp) or a
  // thickness under it (a platform's corner), on the coarse centre line (which also runs
  // over the part lying on a platform, back to where the strip was first seen), or on the
  // traced line's straight continuation back from where the sections start. Farther than a
  // few strip widths from all of these it is a mistake (reduced-image pixels, x and y
  // swapped, another photo's edge) that would move the whole profile: refused.
  const Vec2 e = *s.options.edge_px;
  const std::vector<Vec2>& trace = s.trace;
  double along = 0.0, unused = 0.0;
  double miss =
      std::min(DistanceToPolyline(e, trace, &along), DistanceToPolyline(e, s.coarse, &unused));
  const Vec2 back = (trace.front() - trace[std::min<size_t>(10, trace.size() - 1)]).normalized();
  const double behind = (e - trace.front()).dot(back);
  if (behind > 0.0) miss = std::min(miss, (e - trace.front() - behind * back).norm());
  const double limit = kEdgeFarWidths * s.set.width + kEdgeFarPx;
  if (!(miss <= limit)) {
    throw InputError("--edge-px " + Fmt(e.x(), 1) + "," + Fmt(e.y(), 1) + " lies " + Fmt(miss, 0) +
                     " px from the strip in " + s.summary.source + " (more than " +
                     Fmt(kEdgeFarWidths, 0) + " strip widths + " + Fmt(kEdgeFarPx, 0) +
                     " px = " + Fmt(limit, 0) + " px; its held end is at " +
                     Fmt(trace.front().x(), 0) + "," + Fmt(trace.front().y(), 0) +
                     "): the edge is where the strip leaves the platform or clamp, in "
                     "full-resolution pixels (x right, y down)");
  }
  // An edge well along the measured strip cuts off what lies before it: right if the strip
  // lies on a platform found in the photo up to there (straight: the shipped interlining
  // photos show 62 mm of it on the platform), wrong if that part already bends (an edge 100 mm
  // along a 251 mm strip hanging from a clamp gave L = 151 mm with no word). Bending: the part's
  // sagitta from its chord over a strip width and 2 % of the part (at least 2 px): 3.9 px over
  // 410 px on the interlining's platform, 42 px over 900 px on that clamp photo.
  const double sagitta = along > limit ? SagittaUpTo(trace, along) : 0.0;
  if (along > limit &&
      (!s.platform.found || sagitta > std::max({2.0, s.set.width, 0.02 * along}))) {
    warnings->push_back(
        {"edge_px_along_strip",
         "--edge-px lies " + Fmt(along * s.rig.MmPerPxAt(e), 1) + " mm (" + Fmt(along, 0) +
             " px) along the strip from its held end at " + Fmt(trace.front().x(), 0) + "," +
             Fmt(trace.front().y(), 0) +
             ": the profile leaves that part out; the edge is where the strip leaves the "
             "platform or clamp"});
  }
}

namespace {

// A clamp rig whose strip leaves the image border: the origin is where the traced line's first
// stretch, extended, meets that border.
StageFailure PlaceOriginAtBorder(ExtractState* s) {
  ExtractionSummary& r = s->summary;
  const char* side = s->direction > 0 ? "left" : "right";
  r.rig_detail = std::string("strip leaves the ") + side + " image border";
  // Say so when a block at that border is in view: most likely the clamp itself.
  for (const Block& b : s->blocks) {
    if (s->direction > 0 ? b.box.x == 0 : b.box.br().x == s->small.cols) {
      r.rig_detail += std::string("; a ") + (b.sign < 0 ? "dark" : "light") +
                      " block at that border (the clamp?)";
      break;
    }
  }
  const std::vector<Vec2>& trace = s->trace;
  const int k = std::min<int>(static_cast<int>(trace.size()) - 1,
                              std::max(10, static_cast<int>(s->set.width)));
  const Vec2 d = (trace[k] - trace[0]).normalized();
  const double x_border = s->direction > 0 ? -0.5 : s->gray.cols - 0.5;
  if (std::abs(d.x()) < 0.2) return "the strip leaves the image border too steeply to find where";
  const double gap = (x_border - trace[0].x()) / d.x();
  if (-gap > std::max(3.0 * s->set.width, 20.0)) {
    r.warnings.push_back(
        {"border_gap_extrapolated", "the strip's edges are measured only from " + Fmt(-gap, 0) +
                                        " px after the image border (extrapolated)"});
  }
  r.origin_px = trace[0] + gap * d;
  return std::nullopt;
}

}  // namespace

StageFailure PlaceOrigin(ExtractState* s) {
  ExtractionSummary& r = s->summary;
  const ExtractOptions& options = s->options;
  s->level = options.level_deg ? *options.level_deg * kDeg : 0.0;
  if (s->platform.found) {
    const PlatformFit& platform = s->platform;
    r.rig_type = "platform";
    r.rig_detail = "edge at the platform's top/front corner";
    if (!options.level_deg) s->level = platform.top_angle;
    r.platform_px = {platform.top_far, platform.corner, platform.front_low};
    r.origin_px = platform.corner;
  } else {
    r.rig_type = "clamp";
    if (s->root_how == "border") {
      if (StageFailure why = PlaceOriginAtBorder(s)) return why;
    } else if (s->root_how == "block") {
      r.rig_detail = "strip leaves a clamp inside the photo";
      r.origin_px = s->trace.front();
    } else {
      r.rig_detail = "held end guessed";
      r.origin_px = s->trace.front();
    }
  }
  if (options.edge_px) {
    r.origin_px = *options.edge_px;
    r.rig_detail = "origin given by --edge-px; " + r.rig_detail;
  }
  r.level_deg = s->level / kDeg;
  return std::nullopt;
}

namespace {

// The traced line in the profile frame [mm]: origin at r.origin_px, x along the horizontal
// towards the overhang, y up, both through the rig's plane.
std::vector<Vec2> TraceInMillimetres(ExtractState* s) {
  ExtractionSummary& r = s->summary;
  const Rig& rig = s->rig;
  const double level = s->level;
  const Vec2 x_img = s->direction * Vec2(std::cos(level), -std::sin(level));
  const Vec2 up_img(-std::sin(level), -std::cos(level));
  const Vec2 o = rig.PlaneFromImage(r.origin_px);
  const Vec2 hx = (rig.PlaneFromImage(r.origin_px + 20.0 * x_img) - o).normalized();
  Vec2 hy(-hx.y(), hx.x());
  if (hy.dot(rig.PlaneFromImage(r.origin_px + 20.0 * up_img) - o) < 0.0) hy = -hy;
  r.mm_per_px = rig.MmPerPxAt(r.origin_px);
  std::vector<Vec2> mm;
  for (const Vec2& p : s->trace) {
    const Vec2 q = rig.PlaneFromImage(p) - o;
    mm.emplace_back(q.dot(hx), q.dot(hy));
  }
  if (r.rig_type == "clamp" && s->root_how == "border" && !s->options.edge_px) {
    mm.insert(mm.begin(), Vec2(0.0, 0.0));
    s->trace.insert(s->trace.begin(), r.origin_px);
  }
  return mm;
}

}  // namespace

StageFailure MapToMillimetres(ExtractState* s) {
  const std::vector<Vec2> mm = TraceInMillimetres(s);
  // The profile starts where the traced line crosses x = 0 (the vertical through the origin).
  size_t start = 0;
  Vec2 first_mm;
  std::vector<Vec2> bridge;  // points between first_mm and the traced line
  if (mm.front().x() >= 0.0) {
    const Vec2 d = (mm[std::min<size_t>(5, mm.size() - 1)] - mm[0]).normalized();
    if (s->platform.found && !s->options.edge_px && d.x() > 1e-3) {
      // A strip resting on a platform leaves its edge level (θ(0) = 0, docs/spec/cantilever.md):
      // the gap to the first measured point is bridged by the parabola that is level at x = 0 and
      // meets that point with its slope. A straight line along that slope would put the start too
      // high by half the drop across the gap.
      const double x1 = mm[0].x(), m1 = d.y() / d.x();
      const double c = m1 / (2.0 * std::max(x1, 1e-9));
      const double y0 = mm[0].y() - c * x1 * x1;
      first_mm = Vec2(0.0, y0);
      const int pieces = static_cast<int>(std::ceil(x1 / (0.25 * s->options.step_mm)));
      for (int k = 1; k < pieces; ++k) {
        const double x = x1 * k / pieces;
        bridge.emplace_back(x, y0 + c * x * x);
      }
    } else {
      first_mm = mm[0] - (mm[0].x() / std::max(d.x(), 1e-3)) * d;
    }
    if (mm[0].x() > std::max(3.0 * s->set.width * s->summary.mm_per_px, 1.0)) {
      s->summary.warnings.push_back(
          {"trace_starts_beyond_edge", "the traced line starts " + Fmt(mm[0].x(), 2) +
                                           " mm beyond the edge; extrapolated to it"});
    }
  } else {
    while (start + 1 < mm.size() && mm[start + 1].x() < 0.0) ++start;
    if (start + 1 >= mm.size()) return "the strip does not reach past the edge (x > 0)";
    const double f = -mm[start].x() / (mm[start + 1].x() - mm[start].x());
    first_mm = mm[start] + f * (mm[start + 1] - mm[start]);
    ++start;
  }
  s->curve = {first_mm};
  s->curve.insert(s->curve.end(), bridge.begin(), bridge.end());
  s->curve.insert(s->curve.end(), mm.begin() + start, mm.end());
  s->start = start;
  return std::nullopt;
}

void AssembleProfile(ExtractState* s) {
  const ExtractOptions& options = s->options;
  const std::string& source = s->summary.source;
  const std::vector<Vec2>& curve = s->curve;
  // Arc length along the traced line (not along the chords between samples): k·step, and the
  // whole length at the tip.
  double length = 0.0;
  for (size_t k = 1; k < curve.size(); ++k) length += (curve[k] - curve[k - 1]).norm();
  // The spacing is the user's choice: fine enough (under an absurd rig scale) to make millions
  // of rows, or too coarse for this strip (below), it is bad input, named as the flag.
  const double points = std::floor(length / options.step_mm) + 1.0;
  if (!(points <= kMaxExtractedPoints)) {
    throw InputError("--step-mm " + Fmt(options.step_mm, 2) + ": the " + Fmt(length, 0) +
                     " mm strip in " + source + " would get " + Fmt(points, 0) +
                     " points, more than " + std::to_string(kMaxExtractedPoints) +
                     " (is the rig's scale right?)");
  }
  const std::vector<Vec2> resampled = ResampleByArc(curve, options.step_mm);
  if (resampled.size() < static_cast<size_t>(kMinProfilePoints) &&
      length >= (kMinProfilePoints - 1) * kDefaultStepMm) {
    // At the default spacing the strip would have enough points.
    const double enough = std::floor(100.0 * length / (kMinProfilePoints - 1)) / 100.0;
    throw InputError("--step-mm " + Fmt(options.step_mm, 2) + ": the " + Fmt(length, 1) +
                     " mm strip in " + source + " gets only " + std::to_string(resampled.size()) +
                     " points at that spacing (" + std::to_string(kMinProfilePoints) +
                     " needed: --step-mm " + Fmt(std::max(kMinStepMm, enough), 2) + " or less)");
  }
  ExtractionSummary& r = s->summary;
  Profile& p = r.profile;
  p.source = source;
  for (size_t k = 0; k < resampled.size(); ++k) {
    const double arc = k + 1 == resampled.size() ? length : k * options.step_mm;
    p.s.push_back(arc * 1e-3);
    p.x.push_back(resampled[k].x() * 1e-3);
    p.y.push_back(resampled[k].y() * 1e-3);
  }
  r.length_mm = length;
  r.tip_mm = resampled.back();
  // The overlay shows the part that became the profile.
  std::vector<Vec2>& trace = s->trace;
  trace.erase(trace.begin(), trace.begin() + std::min(s->start, trace.size()));
  r.trace_px = trace;
}

void DiagnoseSilhouette(ExtractState* s) {
  ExtractionSummary& r = s->summary;
  const SectionSet& set = s->set;
  const int first = s->first, last = s->last;
  // Widening of the silhouette towards the tip: the sign of an oblique view.
  std::vector<double> near_root, near_tip;
  const int n = last - first + 1;
  for (int i = first; i <= last; ++i) {
    if (!set.s[i].valid) continue;
    if (i - first < n / 5) near_root.push_back(set.s[i].width());
    if (last - i < n / 5) near_tip.push_back(set.s[i].width());
  }
  if (!near_root.empty() && !near_tip.empty()) r.widening = Median(near_tip) / Median(near_root);
  // An oblique view shows a face that is much fainter than the near edge: the silhouette is
  // then much wider than its solid core, and often widens towards the tip.
  std::vector<double> solid;
  for (int i = first; i <= last; ++i)
    if (set.s[i].present) solid.push_back(set.s[i].solid);
  r.core_width_px = solid.empty() ? 0.0 : Median(solid);
  const bool faint_face = r.width_px > 1.6 * r.core_width_px;
  if (s->options.trace == TraceLine::kMid && (r.widening > 1.5 || faint_face)) {
    r.warnings.push_back(
        {"oblique_view",
         "the silhouette " +
             (r.widening > 1.5
                  ? "widens " + Fmt(r.widening, 1) + "x towards the tip"
                  : "is " + Fmt(r.width_px / r.core_width_px, 1) + "x wider than its solid core") +
             " (an oblique view?): its mid-line is biased; --trace upper or "
             "lower follows the near edge"});
  }
  if (r.contrast < 10.0 * r.noise) {
    r.warnings.push_back({"low_contrast", "low contrast: strip " + Fmt(r.contrast, 1) +
                                              " vs noise " + Fmt(r.noise, 1) + " grey levels"});
  }
  for (int i = first; i <= last; ++i) r.rejected_sections += !set.s[i].Usable(s->options.trace);
  if (r.rejected_sections > n / 5) {
    r.warnings.push_back({"sections_rejected", std::to_string(r.rejected_sections) + " of " +
                                                   std::to_string(n) +
                                                   " cross-sections had no usable " + r.trace +
                                                   " line (fibres, specks, faint edges)"});
  }
}

StageFailure CheckResult(const ExtractState& s) {
  const ExtractionSummary& r = s.summary;
  if (r.profile.size() < static_cast<size_t>(kMinProfilePoints)) {
    return "the profile has only " + std::to_string(r.profile.size()) + " points (strip " +
           Fmt(r.length_mm, 2) + " mm long at " + Fmt(s.options.step_mm, 2) + " mm steps)";
  }
  try {
    CheckProfile(r.profile);
  } catch (const InputError& e) {
    std::string m = e.what();
    const auto colon = m.find(": ");
    return "the extracted profile is not a hanging strip: " +
           (colon == std::string::npos ? m : m.substr(colon + 2));
  }
  return std::nullopt;
}

}  // namespace extract_internal

namespace {

using extract_internal::ExtractState;
using extract_internal::StageFailure;

// The summary of a run that stopped. A photo that fails once the detection image exists is
// first checked for being a calibration board, so that the error names the mix-up rather than
// the stage it broke (the check costs nothing on photos that extract, and cannot refuse one).
ExtractionSummary Failed(ExtractState&& s, const std::string& message) {
  ExtractionSummary& r = s.summary;
  r.success = false;
  r.message = !s.small.empty() && extract_internal::LooksLikeCalibrationBoard(s.small)
                  ? "this looks like a calibration board (a chessboard), not a strip: give "
                    "board photos to textile calibrate, which writes the rig file for --rig"
                  : message;
  r.seconds = s.deadline.Elapsed();
  return std::move(r);
}

// The time cap (ExtractOptions::max_seconds), read between stages; each stage is a bounded
// pass over the photo, so the cap bounds a run to the cap plus one stage. True (and the
// summary says so, with no profile) once it is reached.
bool PastCap(ExtractState* s, const char* stage) {
  const std::optional<std::string> why = s->deadline.Reached(stage);
  if (!why) return false;
  ExtractionSummary& r = s->summary;
  r.profile = Profile{};
  r.success = false;
  r.message = *why + "; no profile";
  r.seconds = s->deadline.Elapsed();
  return true;
}

}  // namespace

ExtractionSummary ExtractProfile(const cv::Mat& gray, const Rig& rig, const ExtractOptions& options,
                                 const std::string& source) {
  using namespace extract_internal;
  ExtractState s(gray, rig, options, source);  // starts the time cap's clock
  CheckExtractInputs(gray, rig, options, source);
  s.summary.trace = TraceName(options.trace);
  if (PastCap(&s, "before the strip was looked for")) return std::move(s.summary);
  ReduceImages(&s);
  if (StageFailure why = FindStrip(&s)) return Failed(std::move(s), *why);
  FindStripBlocks(&s);
  if (StageFailure why = FindHeldEnd(&s)) return Failed(std::move(s), *why);
  if (StageFailure why = TraceCoarseLine(&s)) return Failed(std::move(s), *why);
  if (PastCap(&s, "after the strip's centre line was found")) return std::move(s.summary);
  if (StageFailure why = FindRig(&s)) return Failed(std::move(s), *why);
  if (StageFailure why = MeasureSections(&s)) return Failed(std::move(s), *why);
  if (PastCap(&s, "after the cross-sections were measured")) return std::move(s.summary);
  TraceMeasuredLine(&s);
  if (StageFailure why = FindTipEnd(&s)) return Failed(std::move(s), *why);
  CheckEdgeGiven(s, &s.summary.warnings);
  if (StageFailure why = PlaceOrigin(&s)) return Failed(std::move(s), *why);
  if (StageFailure why = MapToMillimetres(&s)) return Failed(std::move(s), *why);
  AssembleProfile(&s);
  DiagnoseSilhouette(&s);
  if (StageFailure why = CheckResult(s)) return Failed(std::move(s), *why);
  if (PastCap(&s, "with the profile done")) return std::move(s.summary);
  s.summary.confidence = AssessConfidence(s);
  if (StageFailure why = RefuseGuesses(s.summary.confidence, options, &s.summary.warnings))
    return Failed(std::move(s), *why);
  s.summary.success = true;
  s.summary.seconds = s.deadline.Elapsed();
  return std::move(s.summary);
}

}  // namespace textile
