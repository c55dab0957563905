#ifndef TEXTILE_SIM_SCENES_DRAPE_SENSITIVITY_H_
#define TEXTILE_SIM_SCENES_DRAPE_SENSITIVITY_H_

// What moves the drape coefficient (docs/methods/sensitivity.md): the DC's derivative with
// respect to each material parameter, through the equilibrium's sensitivity
// (solve/sensitivity.h, Sensitive Couture section 4) and the shadow's outline:
//
//   DC = (A - A_s) / (A_0 - A_s),   A = ½ Σ_b r_b² Δθ,
//   dA = Σ_b r_b dr_b Δθ,           dr_b = ((1 - s) dp + s dq)·n / (u_b·n),
//
// r_b the outermost crossing of the projected mesh's edges (p, q, crossed at p + s (q - p),
// normal n) with the ray u_b at the bin's angle. The polar area is the raster's within its
// cells (a drape's shadow is star-shaped about the centre), and unlike a raster's it has a
// derivative. SimulateDrape fills DrapeResult::sensitivities when DrapeOptions::sensitivity is
// set.

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "textile/sim/mesh/mesh.h"

namespace textile {

// The shadow's outline: per bin b (angle (b + ½) 2π / #bins) the outermost crossing radius of
// a projected edge [m] (at least the support's radius), the edge's vertex ids and where along
// it the ray crosses (s; edge -1 where the support's rim is the outline).
struct ShadowOutline {
  std::vector<double> radii;
  std::vector<std::array<int, 2>> edge;
  std::vector<double> along;
  double area = 0.0;  // ½ Σ r_b² Δθ [m²]
};
// Throws InputError for fewer than 8 bins, a non-finite state or bad triangles.
ShadowOutline TraceShadowOutline(const Vertices& x, const Triangles& triangles, int bins,
                                 double support_radius);
// ∂A/∂x (#V×3 [m]): the outline's area is linear, to first order, in the displacements of its
// edges' vertices (nothing vertical, nothing where the support's rim is the outline).
Vertices OutlineAreaGradient(const ShadowOutline& outline, const Vertices& x);
// dA for vertex displacements dx (#V×3 [m]) [m²], to first order: ∂A/∂x · dx (InputError for
// another size).
double OutlineAreaDerivative(const ShadowOutline& outline, const Vertices& x, const Vertices& dx);

}  // namespace textile

#endif  // TEXTILE_SIM_SCENES_DRAPE_SENSITIVITY_H_
