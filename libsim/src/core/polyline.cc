#include "textile/sim/core/polyline.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace textile {

double DistanceToPolyline(const std::vector<double>& x, const std::vector<double>& y, double px,
                          double py, bool extend_ends) {
  const size_t m = std::min(x.size(), y.size());
  double best = std::numeric_limits<double>::infinity(), dist = best;
  for (size_t k = 0; k + 1 < m; ++k) {
    const double ex = x[k + 1] - x[k], ey = y[k + 1] - y[k];
    const double len2 = ex * ex + ey * ey;
    if (!(len2 > 0.0)) continue;
    const double rx = px - x[k], ry = py - y[k];
    const double t = (rx * ex + ry * ey) / len2;
    const double tc = std::clamp(t, 0.0, 1.0);
    const double d2 = (rx - tc * ex) * (rx - tc * ex) + (ry - tc * ey) * (ry - tc * ey);
    if (d2 < best) {
      best = d2;
      const bool beyond = extend_ends && ((k == 0 && t < 0.0) || (k + 2 == m && t > 1.0));
      dist = beyond ? std::abs(rx * ey - ry * ex) / std::sqrt(len2) : std::sqrt(d2);
    }
  }
  return dist;
}

double MaxDistanceToPolyline(const std::vector<double>& x, const std::vector<double>& y,
                             const std::vector<double>& px, const std::vector<double>& py) {
  double worst = 0.0;
  for (size_t j = 0; j < std::min(px.size(), py.size()); ++j)
    worst = std::max(worst, DistanceToPolyline(x, y, px[j], py[j]));
  return worst;
}

}  // namespace textile
