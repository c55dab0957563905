// Small geometric helpers of the photo extractor: medians, smoothing and resampling of
// polylines, bilinear sampling.

#include <algorithm>
#include <climits>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "extract_internal.h"

namespace textile::extract_internal {

double Median(std::vector<double> v) {
  const size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + h, v.end());
  const double hi = v[h];
  if (v.size() % 2 == 1) return hi;
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + h));
}

std::vector<Vec2> SmoothPolyline(const std::vector<Vec2>& p, double sigma) {
  // A NaN or infinite sigma would make the window's reach undefined (ceil(3 NaN) cast to int):
  // nothing sensible to smooth with, so the input is returned as it is.
  if (!(sigma > 0.0) || !std::isfinite(sigma) || p.size() < 3) return p;
  const int n = static_cast<int>(p.size());
  // No wider than the sequence (the window is truncated there anyway): a huge sigma must not
  // overflow the int either.
  const int reach = static_cast<int>(std::min<double>(std::ceil(3.0 * sigma), n));
  std::vector<double> w(reach + 1);
  for (int k = 0; k <= reach; ++k) w[k] = std::exp(-0.5 * k * k / (sigma * sigma));
  std::vector<Vec2> out(n);
  for (int i = 0; i < n; ++i) {
    // Symmetric window: a lopsided one would pull the ends towards the inside of a bend.
    const int r = std::min({reach, i, n - 1 - i});
    Vec2 sum = w[0] * p[i];
    double wsum = w[0];
    for (int k = 1; k <= r; ++k) {
      sum += w[k] * (p[i - k] + p[i + k]);
      wsum += 2.0 * w[k];
    }
    out[i] = sum / wsum;
  }
  return out;
}

std::vector<Vec2> ResampleByArc(const std::vector<Vec2>& p, double step) {
  std::vector<Vec2> out;
  if (p.empty()) return out;
  out.push_back(p.front());
  double carried = 0.0;  // arc length since the last output point
  for (size_t i = 1; i < p.size(); ++i) {
    const Vec2 d = p[i] - p[i - 1];
    const double len = d.norm();
    if (len <= 0.0) continue;
    double at = step - carried;  // position of the next output point on this segment
    while (at <= len) {
      out.push_back(p[i - 1] + d * (at / len));
      at += step;
    }
    carried = len - (at - step);
  }
  if ((out.back() - p.back()).norm() > 1e-6 * step) {
    if (carried < 0.25 * step && out.size() > 1) out.pop_back();  // no tiny last interval
    out.push_back(p.back());
  }
  return out;
}

int ConnectedComponents(const cv::Mat& mask, cv::Mat* labels, cv::Mat* stats) {
  const int n = cv::connectedComponents(mask, *labels, 8, CV_32S);
  std::vector<int> x0(n, INT_MAX), y0(n, INT_MAX), x1(n, -1), y1(n, -1), area(n, 0);
  // By runs of one label along a row: the box and area once a run, not once a pixel.
  const int cols = labels->cols;
  for (int y = 0; y < labels->rows; ++y) {
    const int* row = labels->ptr<int>(y);
    for (int x = 0; x < cols;) {
      const int l = row[x];
      int end = x + 1;
      while (end < cols && row[end] == l) ++end;
      x0[l] = std::min(x0[l], x);
      x1[l] = std::max(x1[l], end - 1);
      y0[l] = std::min(y0[l], y);
      y1[l] = std::max(y1[l], y);
      area[l] += end - x;
      x = end;
    }
  }
  stats->create(n, 5, CV_32S);
  for (int l = 0; l < n; ++l) {
    int* s = stats->ptr<int>(l);
    const bool any = area[l] > 0;
    s[cv::CC_STAT_LEFT] = any ? x0[l] : 0;
    s[cv::CC_STAT_TOP] = any ? y0[l] : 0;
    s[cv::CC_STAT_WIDTH] = any ? x1[l] - x0[l] + 1 : 0;
    s[cv::CC_STAT_HEIGHT] = any ? y1[l] - y0[l] + 1 : 0;
    s[cv::CC_STAT_AREA] = area[l];
  }
  return n;
}

bool SampleGray(const cv::Mat& gray, double x, double y, double* value) {
  if (!(x >= 0.0 && y >= 0.0 && x <= gray.cols - 1 && y <= gray.rows - 1)) return false;
  const int x0 = std::min(static_cast<int>(x), gray.cols - 2);
  const int y0 = std::min(static_cast<int>(y), gray.rows - 2);
  const double fx = x - x0, fy = y - y0;
  const uchar* r0 = gray.ptr<uchar>(y0);
  const uchar* r1 = gray.ptr<uchar>(y0 + 1);
  *value =
      (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
  return true;
}

}  // namespace textile::extract_internal
