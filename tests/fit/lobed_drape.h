#ifndef TEXTILE_TESTS_FIT_LOBED_DRAPE_H_
#define TEXTILE_TESTS_FIT_LOBED_DRAPE_H_

// A cheap stand-in for a draped specimen in the photo tests: a polar mesh whose vertical
// projection is the disk r ≤ R(θ) = mean + lobe·cos(nodes·θ + phase) + skew·cos(θ − 1),
// so its shadow has `nodes` folds and, with skew, an area centroid off the support's centre.
// Only the projection matters to the drapemeter; z droops with the radius for realism.

#include <cmath>
#include <numbers>

#include "textile/photo/render_shadow.h"
#include "textile/sim/mesh/mesh.h"

namespace textile::testing {

struct LobedDrape {
  double mean = 0.12, lobe = 0.014, skew = 0.0, phase = 0.3;  // [m], [m], [m], [rad]
  int nodes = 6;

  double Radius(double theta) const {
    return mean + lobe * std::cos(nodes * theta + phase) + skew * std::cos(theta - 1.0);
  }

  TriangleMesh Mesh(int rings = 24, int segments = 720) const {
    TriangleMesh m;
    m.vertices.resize(1 + rings * segments, 3);
    m.vertices.row(0) << 0, 0, 0;
    for (int k = 1; k <= rings; ++k)
      for (int s = 0; s < segments; ++s) {
        const double t = 2 * std::numbers::pi * s / segments, f = double(k) / rings;
        const double r = f * Radius(t);
        m.vertices.row(1 + (k - 1) * segments + s) << r * std::cos(t), r * std::sin(t),
            -std::max(0.0, r - 0.09);
      }
    m.triangles.resize(segments * (2 * rings - 1), 3);
    int n = 0;
    auto id = [segments](int k, int s) { return 1 + (k - 1) * segments + (s % segments); };
    for (int s = 0; s < segments; ++s) m.triangles.row(n++) << 0, id(1, s), id(1, s + 1);
    for (int k = 1; k < rings; ++k)
      for (int s = 0; s < segments; ++s) {
        m.triangles.row(n++) << id(k, s), id(k + 1, s), id(k + 1, s + 1);
        m.triangles.row(n++) << id(k, s), id(k + 1, s + 1), id(k, s + 1);
      }
    return m;
  }
};

// A 1.1 MP camera (408 x 306 mm at the centre: the lobed shadow, 268 mm across, fits at 10°
// of tilt) without the chessboard photo (it doubles the rendering), to keep the tests fast.
inline RenderShadowOptions SmallPhoto(bool board = false) {
  RenderShadowOptions o;
  o.width_px = 1200, o.height_px = 900, o.mm_per_px = 0.34;
  o.render_board = board;
  return o;
}

// The lobed drape's mesh, made once.
inline const TriangleMesh& Lobed() {
  static const TriangleMesh mesh = LobedDrape{}.Mesh();
  return mesh;
}

}  // namespace textile::testing

#endif  // TEXTILE_TESTS_FIT_LOBED_DRAPE_H_
