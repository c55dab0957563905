// Small geometric helpers of the photo extractor: medians, smoothing and resampling of
// polylines, bilinear sampling.

#include <algorithm>
#include <cmath>

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
  if (sigma <= 0.0 || p.size() < 3) return p;
  const int n = static_cast<int>(p.size());
  const int reach = static_cast<int>(std::ceil(3.0 * sigma));
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
