// acpm-accuracy: the plain 200 mm strip on the virtual ACPM200, the shell model at increasing
// resolution against the exact elastica (docs/spec/cantilever.md: the shell's validation), for the
// paper's three fabrics plus a very soft and a very stiff one. Crossing-length error and
// side-profile RMS against run time (a Pareto curve), with the elastica's own time as the reference
// row. Three shell variants: the curvature-tensor bending with one push (first-order convergence),
// the same extrapolated from e and e/2 (the default), and the paper's hinges (biased short by
// their bending-twist coupling, docs/methods/statics.md).

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "bench/bench.h"
#include "common/chart_file.h"
#include "common/cli.h"
#include "textile/sim/scenes/acpm_shell.h"
#include "textile/sim/elastica/elastica.h"

namespace textile::bench {

Benchmark AcpmAccuracyBenchmark();

namespace {
const bool kRegistered = AddBenchmark(30, AcpmAccuracyBenchmark);

struct Fabric {
  std::string name;
  double gsm, b1, b2, c1;  // KES
};

// RMS distance [m] of the shell's side profile points from the elastica polyline at the same
// overhang.
double ProfileRms(const AcpmCrossings& shell, const ElasticaProfile& exact) {
  if (shell.profile_x.empty() || !exact.converged) return std::numeric_limits<double>::quiet_NaN();
  double sum = 0.0;
  for (size_t k = 0; k < shell.profile_x.size(); ++k) {
    const Eigen::Vector2d p(shell.profile_x[k], shell.profile_y[k]);
    double best = std::numeric_limits<double>::infinity();
    for (size_t j = 0; j + 1 < exact.x.size(); ++j) {
      const Eigen::Vector2d a(exact.x[j], exact.y[j]), b(exact.x[j + 1], exact.y[j + 1]);
      const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      best = std::min(best, (p - (a + t * (b - a))).norm());
    }
    sum += best * best;
  }
  return std::sqrt(sum / static_cast<double>(shell.profile_x.size()));
}

}  // namespace

Benchmark AcpmAccuracyBenchmark() {
  return {"acpm-accuracy",
          "Plain 200 mm strip on the virtual ACPM200: shell model vs the exact elastica over "
          "resolution (crossing error, profile RMS, run time)",
          [](const Context& ctx) {
            Result res;
            res.columns = {"material",          "model",          "resolution_mm", "seconds",
                           "crossing_error_rel", "profile_rms_mm", "overhang_mm",   "solves"};
            std::vector<Fabric> fabrics = {{"pabst-fig8", 200, 0.1, 0.0892, -0.0092},
                                           {"pabst-dress", 130, 0.0973, 0.0973, 0.0453},
                                           {"pabst-interlining", 250, 0.5168, 1.8856, 2.2683},
                                           {"very soft", 60, 0.005, 0.005, 0.0},
                                           {"very stiff", 400, 5.0, 5.0, 0.0}};
            if (ctx.quick) fabrics.resize(2);
            const std::vector<double> resolutions =
                ctx.quick ? std::vector<double>{4.0, 2.0} : std::vector<double>{8.0, 4.0, 2.0, 1.0, 0.5};
            std::ostringstream sum;
            chart::Panel pareto{.title = "Shell model vs elastica: error against run time",
                                .x_label = "seconds",
                                .y_label = "|crossing error| (relative)",
                                .log_x = true,
                                .log_y = true};
            for (const Fabric& f : fabrics) {
              Material m;
              m.name = f.name;
              m.areal_density = f.gsm * 1e-3;
              m.bending = BendingLaw::FromKes(f.b1, f.b2, f.c1);
              AcpmOptions options;
              options.num_rays = 1;
              const auto t0 = std::chrono::steady_clock::now();
              const BarrierCrossing exact = FindBarrierCrossing(m.EffectiveLaw(), m.areal_density);
              const double exact_seconds =
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
              if (!exact.converged) continue;
              res.rows.push_back({{"material", f.name},
                                  {"model", "elastica"},
                                  {"seconds", exact_seconds},
                                  {"crossing_error_rel", 0.0},
                                  {"overhang_mm", 1e3 * exact.overhang}});
              ElasticaOptions eo;
              eo.num_samples = 801;
              const ElasticaProfile exact_profile =
                  SolveHeavyElastica(m.EffectiveLaw(), m.areal_density, exact.overhang, eo);
              struct Variant {
                std::string label;
                BendingDiscretization bending;
                bool extrapolate;
              };
              const std::vector<Variant> variants = {
                  {"shell tensor extrapolated", BendingDiscretization::kTensor, true},
                  {"shell tensor", BendingDiscretization::kTensor, false},
                  {"shell hinge", BendingDiscretization::kHinge, false}};
              for (const Variant& v : variants) {
                chart::Series series{.label = f.name + ", " + v.label.substr(6),
                                     .style = chart::Series::Style::kLineAndMarkers};
                for (double mm : resolutions) {
                  // The hinge variant converges to a biased value: two resolutions show it.
                  if (v.bending == BendingDiscretization::kHinge && mm < 2.0) continue;
                  ShellAcpmSettings settings;
                  settings.element_length = mm * 1e-3;
                  settings.bending = v.bending;
                  settings.extrapolate = v.extrapolate;
                  const auto t1 = std::chrono::steady_clock::now();
                  const AcpmCrossings shell =
                      ShellAcpmCrossings(m, options, options.RayPositions(), settings);
                  const double seconds =
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
                  nlohmann::json row = {{"material", f.name},  {"model", v.label},
                                        {"resolution_mm", mm}, {"seconds", seconds},
                                        {"solves", shell.solves}};
                  if (shell.converged) {
                    const double err = shell.overhang.front() / exact.overhang - 1.0;
                    row["crossing_error_rel"] = err;
                    row["overhang_mm"] = 1e3 * shell.overhang.front();
                    // The profile at the shell's crossing vs the elastica at the exact one: the
                    // shapes at the moment the barrier is cut.
                    row["profile_rms_mm"] = 1e3 * ProfileRms(shell, exact_profile);
                    series.x.push_back(seconds);
                    series.y.push_back(std::max(1e-6, std::abs(err)));
                    sum << f.name << " " << v.label << " " << mm << " mm: crossing "
                        << cli::Num(1e3 * shell.overhang.front(), 5) << " mm vs "
                        << cli::Num(1e3 * exact.overhang, 5) << " mm (" << cli::Num(100 * err, 3)
                        << " %) in " << cli::Num(seconds, 3) << " s\n";
                  } else {
                    row["message"] = shell.message;
                    sum << f.name << " " << v.label << " " << mm << " mm: " << shell.message << "\n";
                  }
                  res.rows.push_back(row);
                  if (ctx.progress)
                    std::fprintf(stderr, "acpm-accuracy %s %s %g mm done\n", f.name.c_str(),
                                 v.label.c_str(), mm);
                }
                pareto.series.push_back(series);
              }
            }
            chart::WritePng({.title = "acpm-accuracy: shell model on a plain strip",
                             .panels = {pareto}},
                            ctx.out_dir + "/acpm-accuracy.png");
            res.summary = sum.str();
            if (ctx.print) std::printf("%s", res.summary.c_str());
            return res;
          }};
}

}  // namespace textile::bench
