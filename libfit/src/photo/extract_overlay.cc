// The extraction overlay: what was found, drawn over the photo so that a person can judge it.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "textile/photo/extract.h"

namespace textile {
namespace {

// Colours (BGR) chosen to stay visible on black, white and grey backgrounds.
const cv::Scalar kTraceColor(60, 220, 60);     // green
const cv::Scalar kUpperColor(0, 200, 255);     // amber
const cv::Scalar kLowerColor(255, 160, 0);     // azure
const cv::Scalar kPlatformColor(255, 255, 0);  // cyan
const cv::Scalar kBlockColor(0, 140, 255);     // orange
const cv::Scalar kOriginColor(40, 40, 255);    // red
const cv::Scalar kUpColor(255, 80, 255);       // magenta
const cv::Scalar kTipColor(255, 0, 255);       // magenta
constexpr int kShift = 4;                      // sub-pixel bits for drawing

cv::Point Fixed(const Eigen::Vector2d& p, double k) {
  // Pixel centres: full-resolution (x + 0.5) maps to overlay (x + 0.5)·k.
  return cv::Point(static_cast<int>(std::lround(((p.x() + 0.5) * k - 0.5) * (1 << kShift))),
                   static_cast<int>(std::lround(((p.y() + 0.5) * k - 0.5) * (1 << kShift))));
}

void Polyline(cv::Mat& img, const std::vector<Eigen::Vector2d>& pts, double k,
              const cv::Scalar& color, int thickness) {
  if (pts.size() < 2) return;
  std::vector<cv::Point> q;
  for (const auto& p : pts) q.push_back(Fixed(p, k));
  cv::polylines(img, q, false, color, thickness, cv::LINE_AA, kShift);
}

std::string Fixed1(double v, int precision) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(precision);
  s << v;
  return s.str();
}

}  // namespace

cv::Mat DrawExtractionOverlay(const cv::Mat& gray, const ExtractionSummary& r, int max_side_px) {
  const double k = std::min(1.0, max_side_px / double(std::max(gray.cols, gray.rows)));
  cv::Mat small, img;
  if (k < 1.0) {
    cv::resize(gray, small, cv::Size(), k, k, cv::INTER_AREA);
  } else {
    small = gray;
  }
  cv::cvtColor(small, img, cv::COLOR_GRAY2BGR);
  const int side = std::max(img.cols, img.rows);
  const int line = std::max(1, side / 900);

  for (const auto& contour : r.blocks_px) {
    std::vector<Eigen::Vector2d> pts;
    for (const auto& q : contour) pts.emplace_back(q.x, q.y);
    if (!pts.empty()) pts.push_back(pts.front());
    Polyline(img, pts, k, kBlockColor, line);
  }
  if (r.platform_px.size() == 3) Polyline(img, r.platform_px, k, kPlatformColor, line + 1);
  // Boundaries as fine dots, so that the photo stays visible between them.
  const int dot = std::max(1 << kShift, (1 << kShift) * line / 2);
  for (size_t i = 0; i < r.upper_px.size(); i += 3) {
    cv::circle(img, Fixed(r.upper_px[i], k), dot, kUpperColor, -1, cv::LINE_AA, kShift);
  }
  for (size_t i = 0; i < r.lower_px.size(); i += 3) {
    cv::circle(img, Fixed(r.lower_px[i], k), dot, kLowerColor, -1, cv::LINE_AA, kShift);
  }
  Polyline(img, r.trace_px, k, kTraceColor, line);

  // Origin and axes: x towards the overhang, y up, both as seen.
  const double level = r.level_deg * M_PI / 180.0;
  const int dir = r.direction == "left" ? -1 : 1;
  const Eigen::Vector2d x_axis = dir * Eigen::Vector2d(std::cos(level), -std::sin(level));
  const Eigen::Vector2d y_axis(-std::sin(level), -std::cos(level));
  const double arm = 0.06 * side / k;
  const cv::Point o = Fixed(r.origin_px, k);
  cv::arrowedLine(img, o, Fixed(r.origin_px + arm * x_axis, k), kOriginColor, line + 1, cv::LINE_AA,
                  kShift, 0.15);
  cv::arrowedLine(img, o, Fixed(r.origin_px + arm * y_axis, k), kUpColor, line + 1, cv::LINE_AA,
                  kShift, 0.15);
  cv::circle(img, o, (1 << kShift) * (4 * line + 2), kOriginColor, line + 1, cv::LINE_AA, kShift);
  if (r.success) {
    cv::circle(img, Fixed(r.tip_px, k), (1 << kShift) * (4 * line + 2), kTipColor, line + 1,
               cv::LINE_AA, kShift);
  }

  // Caption.
  std::vector<std::string> lines;
  const std::string name = std::filesystem::path(r.source).filename().string();
  lines.push_back(name + ": " +
                  (r.success ? r.rig_type + " rig, " + r.rig_detail : "FAILED: " + r.message));
  if (r.success) {
    lines.push_back("strip " + r.polarity + ", overhang " + r.direction + ", trace " + r.trace +
                    ", L = " + Fixed1(r.length_mm, 1) + " mm, tip (" + Fixed1(r.tip_mm.x(), 1) +
                    ", " + Fixed1(r.tip_mm.y(), 1) + ") mm, " + Fixed1(r.mm_per_px, 4) + " mm/px");
    lines.push_back(
        "green: traced line; amber/azure: upper/lower edge; red: origin, x; magenta: up, tip; " +
        std::string(r.platform_px.empty() ? "" : "cyan: platform; ") + "orange: blocks");
  }
  for (const Note& w : r.warnings) lines.push_back("warning: " + w.text);
  const double font = std::max(0.4, side / 2200.0);
  const int thick = std::max(1, static_cast<int>(font * 1.5));
  int baseline = 0;
  const int height = cv::getTextSize("Ag", cv::FONT_HERSHEY_SIMPLEX, font, thick, &baseline).height;
  int y = height + 8;
  for (const auto& text : lines) {
    cv::putText(img, text, {8, y}, cv::FONT_HERSHEY_SIMPLEX, font, cv::Scalar(0, 0, 0), thick + 2,
                cv::LINE_AA);
    cv::putText(img, text, {8, y}, cv::FONT_HERSHEY_SIMPLEX, font, cv::Scalar(255, 255, 255), thick,
                cv::LINE_AA);
    y += height + baseline + 6;
  }
  return img;
}

}  // namespace textile
