#ifndef TEXTILE_TESTS_SIM_RING_AREA_H_
#define TEXTILE_TESTS_SIM_RING_AREA_H_

// A test helper shared by the mesher's and the drapemeter's tests.

#include <Eigen/Core>
#include <limits>

#include "textile/sim/mesh/mesh.h"

namespace textile {

// Mean area [m²] of the triangles whose centroid lies at r_lo < |(x, y)| < r_hi [m] from the
// origin; NaN when there is none.
inline double MeanTriangleAreaInRing(const TriangleMesh& m, double r_lo, double r_hi) {
  const Eigen::VectorXd areas = TriangleAreas(m);
  double sum = 0.0;
  int n = 0;
  for (int f = 0; f < m.num_triangles(); ++f) {
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (int k = 0; k < 3; ++k) c += m.vertices.row(m.triangles(f, k)).head<2>().transpose() / 3;
    if (c.norm() > r_lo && c.norm() < r_hi) sum += areas(f), ++n;
  }
  return n > 0 ? sum / n : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace textile

#endif  // TEXTILE_TESTS_SIM_RING_AREA_H_
