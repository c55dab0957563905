// sensitivity-fabrics: which inputs move the DC of the paper's three fabrics (Pabst et al.:
// the Fig. 8 fabric, the Fig. 9 dress fabric, the interlining; samples/materials), each
// parameter's DC change over its stated or default uncertainty, default drape scene. The
// picture of docs/methods/sensitivity.md, "What the paper's fabrics say".

#include <cmath>
#include <cstdio>
#include <sstream>

#include "bench/bench.h"
#include "common/chart_file.h"
#include "common/cli.h"
#include "textile/sim/core/error.h"
#include "textile/sim/law/material_parameters.h"
#include "textile/sim/scenes/drape.h"

namespace textile::bench {

Benchmark SensitivityFabricsBenchmark();

namespace {
const bool kRegistered = AddBenchmark(67, SensitivityFabricsBenchmark);

struct Fabric {
  const char* name;
  const char* json;  // as samples/materials/pabst-*.json give them
};

const Fabric kFabrics[] = {
    {"Fig. 8 fabric",
     R"({"areal_density_gsm": 200, "bending": {"units": "kes", "b1": 0.1, "b2": 0.0892, "c1": -0.0092},
         "stretch": {"stiffness_N_per_m": 1000, "poisson": 0.3}})"},
    {"dress fabric",
     R"({"areal_density_gsm": 130, "bending": {"units": "kes", "b1": 0.0973, "b2": 0.0973, "c1": 0.0453},
         "stretch": {"stiffness_N_per_m": 1000, "poisson": 0.3}})"},
    {"interlining",
     R"({"areal_density_gsm": 250, "bending": {"units": "kes", "b1": 0.5168, "b2": 1.8856, "c1": 2.2683},
         "stretch": {"stiffness_N_per_m": 1000, "poisson": 0.3}})"},
};

// The parameters in the picture's order (x = 1, 2, ...).
const char* const kParameters[] = {"b1", "b2", "c1", "areal_density_gsm",
                                   "stretch.stiffness_N_per_m", "stretch.poisson",
                                   "stretch.compression_ratio"};

}  // namespace

Benchmark SensitivityFabricsBenchmark() {
  return {"sensitivity-fabrics",
          "The paper's three fabrics: each input's DC change over its uncertainty (default scene)",
          [](const Context& ctx) {
            Result res;
            res.columns = {"fabric", "drape_coefficient", "parameter", "defaulted",
                           "d_dc_d_ln_p", "dc_change"};
            chart::Panel panel{.title = "DC change over each input's uncertainty",
                               .x_label = "input (see the notes)",
                               .y_label = "|ΔDC|",
                               .log_y = true,
                               .y_range = chart::Range{2e-6, 0.3},  // the notes below the points
                               .legend_corner = chart::Corner::kTopLeft,
                               .notes_corner = chart::Corner::kBottomLeft};
            int index = 1;
            for (const char* p : kParameters)
              panel.notes.push_back(std::to_string(index++) + ": " + p);
            panel.notes.push_back("7 is a default nobody measured");
            std::ostringstream sum;
            for (const Fabric& f : kFabrics) {
              const Material m = ParseMaterialJson(f.json, f.name);
              DrapeOptions o;
              o.sensitivity = true;
              if (!ctx.quick) ChooseDrapeRim(m, true, DrapeExtrapolation::kDefault, &o);
              const DrapeResult r = SimulateDrape(m, o);
              if (!r.converged) throw ComputeError(std::string(f.name) + ": " + r.message);
              chart::Series s{.label = std::string(f.name) + " (DC " + cli::Num(r.drape_coefficient, 3) + ")",
                              .style = chart::Series::Style::kMarkers};
              sum << f.name << ": DC " << cli::Num(r.drape_coefficient, 4) << "; largest";
              for (size_t k = 0; k < 3 && k < r.sensitivities.size(); ++k)
                sum << (k ? ", " : " ") << r.sensitivities[k].parameter << " "
                    << cli::Num(r.sensitivities[k].change, 2);
              sum << "\n";
              for (size_t x = 0; x < std::size(kParameters); ++x)
                for (const ParameterInfluence& i : r.sensitivities)
                  if (i.parameter == kParameters[x]) {
                    s.x.push_back(static_cast<double>(x + 1));
                    s.y.push_back(std::max(i.change, 1e-6));
                  }
              for (const ParameterInfluence& i : r.sensitivities)
                res.rows.push_back({{"fabric", f.name},
                                    {"drape_coefficient", r.drape_coefficient},
                                    {"parameter", i.parameter},
                                    {"defaulted", i.defaulted},
                                    {"d_dc_d_ln_p", i.d_q_d_ln_p},
                                    {"dc_change", i.change}});
              panel.series.push_back(s);
              if (ctx.progress) std::fprintf(stderr, "sensitivity-fabrics %s done\n", f.name);
            }
            chart::WritePng({.title = "Which inputs move the drape coefficient", .panels = {panel}},
                            ctx.out_dir + "/sensitivity-fabrics.png");
            res.summary = sum.str();
            if (ctx.print) std::printf("%s", res.summary.c_str());
            return res;
          }};
}

}  // namespace textile::bench
