// drape-sensitivity: what the DC's sensitivities cost on a drape of about 10k vertices, per
// material parameter (one factorisation of the exact Hessian and one adjoint back-substitution
// shared by all, two element gradients each; docs/methods/sensitivity.md) against the issue's
// target of 30 ms a parameter (Sensitive Couture Table 1: 145-640 ms), what each scene radius
// adds, and how far the linear ∂DC/∂ln b1 is from differences of whole drapes at b1 e^(±0.01)
// (full runs only).

#include <algorithm>
#include <cmath>
#include <sstream>

#include "bench/bench.h"
#include "textile/sim/core/error.h"
#include "textile/sim/law/material_parameters.h"
#include "textile/sim/scenes/drape.h"

namespace textile::bench {

Benchmark DrapeSensitivityBenchmark();

namespace {
const bool kRegistered = AddBenchmark(64, DrapeSensitivityBenchmark);

Material Fig8() {
  Material m = LawOnlyMaterial(BendingLaw::FromKes(0.1, 0.0892, -0.0092), 0.2);
  return m;
}

// One seed, no rim split (one equilibrium), element h [m], tolerance tight enough for
// differences of whole drapes.
DrapeOptions Scene(double h) {
  DrapeOptions o;
  o.element_size = h;
  o.coarse_to_fine = false;
  o.solver.tolerance = 1e-8;
  o.solver.max_seconds = 600.0;
  return o;
}

}  // namespace

Benchmark DrapeSensitivityBenchmark() {
  return {"drape-sensitivity",
          "Drape sensitivities: time per parameter on a ~10k-vertex drape, and dDC/dln b1 "
          "against differences of whole drapes",
          [](const Context& ctx) {
            Result res;
            res.columns = {"vertices", "parameters", "solve_s", "sensitivity_s",
                           "ms_per_parameter", "ms_per_radius", "dc", "d_dc_d_ln_b1",
                           "fd_d_dc_d_ln_b1", "relative_error"};
            // ~10k vertices at 2.9 mm over the 150 mm disk; quick: ~2.6k at 5.6 mm.
            const double h = ctx.quick ? 0.0056 : 0.0029;
            const Material m = Fig8();
            DrapeOptions o = Scene(h);
            const DrapeResult plain = SimulateDrape(m, o);
            o.sensitivity = true;  // every parameter, and the scene's radii
            const DrapeResult r = SimulateDrape(m, o);
            if (!r.converged) throw ComputeError("drape-sensitivity: " + r.message);
            const int parameters = static_cast<int>(r.sensitivities.size());
            const double equilibria = std::max(1, r.sensitivity_equilibria);
            // The scene's two radii, timed inside the same run.
            const double per_radius =
                1e3 * r.scene_sensitivity_seconds /
                std::max(1.0, static_cast<double>(r.scene_sensitivities.size()) * equilibria);
            double d_b1 = std::nan("");
            for (const ParameterInfluence& s : r.sensitivities)
              if (s.parameter == "b1") d_b1 = s.d_q_d_ln_p;
            double fd = std::nan("");
            if (!ctx.quick) {
              const double b1 = m.bending.b1();
              const DrapeResult up =
                  SimulateDrape(WithMaterialParameter(m, "b1", b1 * std::exp(0.01)), Scene(h));
              const DrapeResult down =
                  SimulateDrape(WithMaterialParameter(m, "b1", b1 * std::exp(-0.01)), Scene(h));
              if (up.converged && down.converged)
                fd = (up.drape_coefficient - down.drape_coefficient) / 0.02;
            }
            const double per = 1e3 * (r.sensitivity_seconds - r.scene_sensitivity_seconds) /
                               (std::max(1, parameters) * equilibria);
            nlohmann::json row = {{"vertices", r.mesh.num_vertices()},
                                  {"parameters", parameters},
                                  {"solve_s", plain.seconds},
                                  {"sensitivity_s", r.sensitivity_seconds},
                                  {"ms_per_parameter", per},
                                  {"ms_per_radius", per_radius},
                                  {"dc", r.drape_coefficient},
                                  {"d_dc_d_ln_b1", d_b1},
                                  {"fd_d_dc_d_ln_b1", std::isfinite(fd) ? nlohmann::json(fd)
                                                                        : nlohmann::json()},
                                  {"relative_error", std::isfinite(fd)
                                                         ? nlohmann::json(std::abs(d_b1 / fd - 1))
                                                         : nlohmann::json()}};
            res.rows.push_back(row);
            std::ostringstream s;
            s << r.mesh.num_vertices() << " vertices, " << parameters << " parameters: "
              << r.sensitivity_seconds << " s of sensitivities (" << per
              << " ms a parameter, target 30; each scene radius " << per_radius
              << " ms more) after a " << plain.seconds << " s drape; dDC/dln b1 " << d_b1;
            if (std::isfinite(fd)) s << " against " << fd << " from whole drapes (raster DCs)";
            s << "\n";
            res.summary = s.str();
            return res;
          }};
}

}  // namespace textile::bench
