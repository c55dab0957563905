#ifndef TEXTILE_SIM_CORE_POLYLINE_H_
#define TEXTILE_SIM_CORE_POLYLINE_H_

// Distances between a point and a curve given as a polyline, for comparing profiles (measured
// with simulated, one model with another).
//
//   const double d = textile::DistanceToPolyline(curve_x, curve_y, px, py);

#include <vector>

namespace textile {

// Distance from (px, py) to the polyline (x_k, y_k), in the units of the input. Zero-length
// segments are skipped. With extend_ends, a point beyond an end of the curve (its nearest
// point is that end, past the end segment's direction) gets its distance from that segment's
// line instead: the normal distance to the curve continued straight. The polyline needs at
// least one segment of non-zero length; otherwise the result is infinite.
double DistanceToPolyline(const std::vector<double>& x, const std::vector<double>& y, double px,
                          double py, bool extend_ends = false);

// The largest distance of the points (px_j, py_j) from the polyline (x_k, y_k), as above
// without extended ends; 0 for no points.
double MaxDistanceToPolyline(const std::vector<double>& x, const std::vector<double>& y,
                             const std::vector<double>& px, const std::vector<double>& py);

}  // namespace textile

#endif  // TEXTILE_SIM_CORE_POLYLINE_H_
