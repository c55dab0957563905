// elastica: run time of one heavy-elastica solve against its accuracy (the forward model every
// fit and the ACPM elastica model call), for the paper's fabrics at L = 100 mm.

#include <cmath>
#include <cstdio>
#include <sstream>

#include "bench/bench.h"
#include "common/chart_file.h"
#include "textile/sim/elastica/elastica.h"
#include "textile/sim/core/units.h"

namespace textile::bench {

Benchmark ElasticaBenchmark();

namespace {
const bool kRegistered = AddBenchmark(45, ElasticaBenchmark);
}  // namespace

Benchmark ElasticaBenchmark() {
  return {"elastica", "One heavy-elastica solve: run time against accuracy (tolerance sweep)",
          [](const Context& ctx) {
            Result res;
            res.columns = {"material", "rel_tol", "sensitivities", "samples", "seconds",
                           "tip_error_rel", "integrations"};
            struct F {
              const char* name;
              double b1, b2, c1, gsm;
            };
            const F fabrics[] = {{"pabst-fig8", 0.1, 0.0892, -0.0092, 200},
                                 {"pabst-dress", 0.0973, 0.0973, 0.0453, 130},
                                 {"pabst-interlining", 0.5168, 1.8856, 2.2683, 250}};
            const std::vector<double> tols = ctx.quick ? std::vector<double>{1e-6, 1e-10}
                                                       : std::vector<double>{1e-4, 1e-6, 1e-8, 1e-10, 1e-12};
            const int repeats = ctx.quick ? 20 : 200;
            const double L = 0.1;
            for (const F& f : fabrics) {
              const BendingLaw law = BendingLaw::FromKes(f.b1, f.b2, f.c1);
              const double rho = units::GsmToSi(f.gsm);
              ElasticaOptions ref_o;
              ref_o.rel_tol = 1e-13;
              const ElasticaProfile ref = SolveHeavyElastica(law, rho, L, ref_o);
              for (bool sens : {false, true}) {
                for (int samples : {2, 201}) {
                for (double tol : tols) {
                  if (samples == 2 && sens) continue;  // the fit always samples the curve
                  ElasticaOptions o;
                  o.rel_tol = tol;
                  o.num_samples = samples;
                  o.sensitivities = sens;
                  ElasticaProfile p;
                  const double sec = MedianSeconds([&] { p = SolveHeavyElastica(law, rho, L, o); }, repeats);
                  const double err = std::hypot(p.tip_x - ref.tip_x, p.tip_y - ref.tip_y) / L;
                  res.rows.push_back({{"material", f.name}, {"rel_tol", tol}, {"sensitivities", sens},
                                      {"samples", o.num_samples}, {"seconds", sec},
                                      {"tip_error_rel", err}, {"integrations", p.shooting_iterations}});
                }
                }
              }
            }
            std::ostringstream sum;
            char line[200];
            std::snprintf(line, sizeof line, "%-18s %8s %5s %7s %10s %14s\n", "material", "rel_tol",
                          "sens", "samples", "ms", "tip_err_rel");
            sum << line;
            for (const auto& r : res.rows) {
              std::snprintf(line, sizeof line, "%-18s %8.0e %5s %7d %10.4f %14.2e\n",
                            r["material"].get<std::string>().c_str(), r["rel_tol"].get<double>(),
                            r["sensitivities"].get<bool>() ? "yes" : "no", r["samples"].get<int>(),
                            r["seconds"].get<double>() * 1e3, r["tip_error_rel"].get<double>());
              sum << line;
            }
            res.summary = sum.str();
            namespace chart = textile::chart;
            chart::Panel p{.title = "Heavy elastica, L = 100 mm: error vs run time",
                           .x_label = "run time [ms]", .y_label = "tip error / L [-]",
                           .log_x = true, .log_y = true};
            int k = 0;
            for (const F& f : fabrics) {
              for (int variant = 0; variant < 3; ++variant) {
                const bool sens = variant == 2;
                const int samples = variant == 0 ? 2 : 201;
                chart::Series s{.label = std::string(f.name) + (variant == 0 ? ", tip only"
                                                                : sens ? ", 201 samples + sensitivities"
                                                                       : ", 201 samples"),
                                .style = chart::Series::Style::kLineAndMarkers,
                                .color = chart::PaletteColor(k / 3), .dashed = variant == 0};
                for (const auto& r : res.rows) {
                  if (r["material"] != f.name || r["sensitivities"] != sens || r["samples"] != samples) continue;
                  s.x.push_back(r["seconds"].get<double>() * 1e3);
                  s.y.push_back(std::max(r["tip_error_rel"].get<double>(), 1e-16));
                }
                p.series.push_back(s);
                ++k;
              }
            }
            chart::WritePng({.title = "elastica benchmark", .panels = {p}}, ctx.out_dir + "/elastica.png");
            return res;
          }};
}

}  // namespace textile::bench
