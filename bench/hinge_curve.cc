// hinge-curve: Pabst et al. Fig. 10, the bending force in normal direction of one bending
// element against its opening angle, for the four models and two fabrics of the paper.
// Not a timing: the curves show what each model's force does at large bends.

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>

#include "bench/bench.h"
#include "common/chart_file.h"
#include "textile/sim/elements/bending_element.h"

namespace textile::bench {

Benchmark HingeCurveBenchmark();

namespace {
const bool kRegistered = AddBenchmark(15, HingeCurveBenchmark);
}  // namespace

Benchmark HingeCurveBenchmark() {
  return {
      "hinge-curve",
      "Pabst Fig. 10: normal force of one hinge vs opening angle, four models, two fabrics",
      [](const Context& ctx) {
        Result res;
        res.columns = {"fabric",      "model",           "opening_deg",        "bend_deg",
                       "kappa_per_m", "normal_force_mn", "tangential_force_mn"};
        // One symmetric hinge: edge 1 cm along y, wings 1 cm from it, flat at rest.
        constexpr double kEdge = 0.01, kHeight = 0.01;
        TriangleMesh rest;
        rest.vertices.resize(4, 3);
        rest.vertices << -kHeight, 0.5 * kEdge, 0, kHeight, 0.5 * kEdge, 0, 0, 0, 0, 0, kEdge, 0;
        rest.triangles.resize(2, 3);
        rest.triangles << 0, 2, 3, 1, 3, 2;
        const std::vector<Hinge> hinges = BuildHinges(rest);
        const Hinge& h = hinges.at(0);
        struct Fabric {
          const char* name;
          BendingLaw law;
        };
        const Fabric fabrics[] = {
            {"fig8 {0.1, 0.0892, -0.0092}", BendingLaw::FromKes(0.1, 0.0892, -0.0092)},
            {"interlining {0.5168, 1.8856, 2.2683}", BendingLaw::FromKes(0.5168, 1.8856, 2.2683)}};
        const BendingModel models[] = {BendingModel::kVolino, BendingModel::kBridson,
                                       BendingModel::kIsometric, BendingModel::kPabst};
        const int step = ctx.quick ? 10 : 2;
        for (const Fabric& f : fabrics) {
          for (BendingModel model : models) {
            const BendingElements b(rest, hinges, f.law, std::nullopt, {.model = model});
            for (int opening = 180; opening >= 2; opening -= step) {
              // Each wing turns up by half the bend angle θ = 180° - opening.
              const double bend = (180.0 - opening) * std::numbers::pi / 180.0;
              Vertices x = rest.vertices;
              x.row(h.v[0]) << -kHeight * std::cos(bend / 2), 0.5 * kEdge,
                  kHeight * std::sin(bend / 2);
              x.row(h.v[1]) << kHeight * std::cos(bend / 2), 0.5 * kEdge,
                  kHeight * std::sin(bend / 2);
              Vertices grad = Vertices::Zero(4, 3);
              b.AddGradient(x, grad);
              const Eigen::Vector3d force = -grad.row(h.v[0]).transpose();
              const Eigen::Vector3d x0 = x.row(h.v[0]), x2 = x.row(h.v[2]), x3 = x.row(h.v[3]);
              const Eigen::Vector3d normal = (x3 - x2).cross(x0 - x2).normalized();
              const double fn = force.dot(normal);
              const double ft = (force - fn * normal).norm();
              res.rows.push_back({{"fabric", f.name},
                                  {"model", BendingModelName(model)},
                                  {"opening_deg", opening},
                                  {"bend_deg", 180 - opening},
                                  {"kappa_per_m", b.HingeCurvature(x, 0)},
                                  {"normal_force_mn", -fn * 1e3},
                                  {"tangential_force_mn", ft * 1e3}});
            }
          }
        }

        std::ostringstream sum;
        char line[200];
        std::snprintf(line, sizeof line,
                      "normal force on a wing [mN], edge 1 cm, wing heights 1 cm\n%-38s %-10s",
                      "fabric", "model");
        sum << line;
        const int shown[] = {170, 150, 120, 90, 60, 30, 10};
        for (int a : shown) {
          std::snprintf(line, sizeof line, " %7d°", a);
          sum << line;
        }
        sum << "   peak at\n";
        for (const Fabric& f : fabrics) {
          for (BendingModel model : models) {
            std::snprintf(line, sizeof line, "%-38s %-10s", f.name,
                          BendingModelName(model).c_str());
            sum << line;
            double peak = -1, peak_at = 0;
            for (const auto& r : res.rows) {
              if (r["fabric"] != f.name || r["model"] != BendingModelName(model)) continue;
              if (r["normal_force_mn"].get<double>() > peak) {
                peak = r["normal_force_mn"].get<double>();
                peak_at = r["opening_deg"].get<int>();
              }
              for (int a : shown) {
                if (r["opening_deg"].get<int>() == a) {
                  std::snprintf(line, sizeof line, " %8.3f", r["normal_force_mn"].get<double>());
                  sum << line;
                }
              }
            }
            std::snprintf(line, sizeof line, "   %3.0f°\n", peak_at);
            sum << line;
          }
        }
        sum << "(opening angle: 180° flat, 0° folded shut; the isometric curve lies on Volino's)\n";
        res.summary = sum.str();

        namespace chart = textile::chart;
        std::vector<chart::Panel> panels;
        for (const Fabric& f : fabrics) {
          chart::Panel p{.title = f.name,
                         .x_label = "opening angle [deg] (180 = flat)",
                         .y_label = "normal force on a wing [mN]"};
          int k = 0;
          for (BendingModel model : models) {
            chart::Series s{.label = BendingModelName(model),
                            .color = chart::PaletteColor(k++),
                            .dashed = model == BendingModel::kIsometric};
            for (const auto& r : res.rows) {
              if (r["fabric"] != f.name || r["model"] != BendingModelName(model)) continue;
              s.x.push_back(r["opening_deg"].get<int>());
              s.y.push_back(r["normal_force_mn"].get<double>());
            }
            p.series.push_back(s);
          }
          p.notes = {"one hinge: edge 1 cm, wings 1 cm", "Bridson/Volino/IBM stiffness from b1"};
          panels.push_back(p);
        }
        chart::WritePng({.title = "Pabst et al. Fig. 10: bending force in normal direction",
                         .width_px = 1400,
                         .columns = 2,
                         .panels = panels},
                        ctx.out_dir + "/hinge-curve.png");
        return res;
      }};
}

}  // namespace textile::bench
