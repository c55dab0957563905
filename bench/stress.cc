// stress: the static solver at the extremes (docs/spec/benchmarks.md): bending/stretch ratio over
// six decades, 20-2000 g/m², b1 = b2, κ0 near 0, 50 to 100k triangles, bad meshes. Every run has a
// time and iteration cap; the outcome is "converged", "failed-cleanly" (not converged with a
// reason, or a typed InputError/ComputeError) or "other" (anything else: a non-finite result,
// an unexpected exception). Only "other" is a bug.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <sstream>

#include "bench/bench.h"
#include "common/chart_file.h"
#include "common/cli.h"
#include "textile/sim/core/error.h"
#include "textile/sim/solve/static_solver.h"

namespace textile::bench {

Benchmark StressBenchmark();

namespace {
const bool kRegistered = AddBenchmark(70, StressBenchmark);
using cli::Num;

struct Case {
  std::string name;
  double gsm = 200.0;
  BendingLaw law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  double bending_scale = 1.0;
  int nx = 16, ny = 10;     // criss-cross cells of a 0.5 m × 0.3 m sheet held along x = 0
  double jitter = 0.0;      // vertex jitter, fraction of the cell size (bad meshes)
};

struct Outcome {
  std::string outcome, message;
  double seconds = 0.0;
  int iterations = 0;
  int triangles = 0;
};

Outcome Run(const Case& c, double max_seconds) {
  const auto start = std::chrono::steady_clock::now();
  Outcome out;
  try {
    TriangleMesh mesh = CrissCrossGridMesh(0.5, 0.3, c.nx, c.ny);
    if (c.jitter > 0.0) {
      std::mt19937 rng(11);
      std::uniform_real_distribution<double> u(-1.0, 1.0);
      const double cell = 0.5 / c.nx;
      for (int v = 0; v < mesh.num_vertices(); ++v)
        if (mesh.vertices(v, 0) > 1e-12) mesh.vertices.row(v).head<2>() += c.jitter * cell * Eigen::RowVector2d(u(rng), u(rng));
    }
    out.triangles = mesh.num_triangles();
    Material m;
    m.areal_density = c.gsm * 1e-3;
    m.bending = c.law;
    ClothOptions options;
    options.bending_scale = c.bending_scale;
    ClothProblem problem(mesh, m, {}, options);
    std::vector<int> held;
    for (int v = 0; v < mesh.num_vertices(); ++v)
      if (mesh.vertices(v, 0) < 1e-12) held.push_back(v);
    Vertices at(static_cast<long>(held.size()), 3);
    for (size_t k = 0; k < held.size(); ++k) at.row(static_cast<long>(k)) = mesh.vertices.row(held[k]);
    problem.FixVertices(held, at);
    Vertices x = mesh.vertices;
    SolveOptions solve;
    solve.max_seconds = max_seconds;
    solve.max_iterations = 500;
    const SolveSummary s = SolveStatic(&problem, &x, solve);
    out.iterations = s.iterations;
    out.message = s.message;
    if (s.converged && std::isfinite(s.energy) && x.allFinite()) {
      out.outcome = "converged";
    } else if (!s.converged && !s.message.empty()) {
      out.outcome = "failed-cleanly";
    } else {
      out.outcome = "other";
    }
  } catch (const InputError& e) {
    out.outcome = "failed-cleanly";
    out.message = std::string("input: ") + e.what();
  } catch (const ComputeError& e) {
    out.outcome = "failed-cleanly";
    out.message = std::string("compute: ") + e.what();
  } catch (const std::exception& e) {
    out.outcome = "other";
    out.message = e.what();
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace

Benchmark StressBenchmark() {
  return {"stress",
          "Static solver at the extremes: stiffness ratios, densities, degenerate laws, 50 to 100k "
          "triangles, bad meshes; converged or failed cleanly, never NaN, never a hang",
          [](const Context& ctx) {
            Result res;
            res.columns = {"case", "outcome", "seconds", "iterations", "triangles", "message"};
            std::vector<Case> cases;
            for (double scale : {1e-3, 1e-1, 1e1, 1e3})
              cases.push_back({.name = "bending/stretch x" + Num(scale), .bending_scale = scale});
            for (double gsm : {20.0, 2000.0})
              cases.push_back({.name = Num(gsm) + " g/m2", .gsm = gsm});
            cases.push_back({.name = "b1 = b2 (linear law)", .law = BendingLaw::FromKes(0.1, 0.1, 0.0)});
            cases.push_back({.name = "kappa0 near 0", .law = BendingLaw::FromKes(0.1, 0.0892, -1e-7)});
            cases.push_back({.name = "50 triangles", .nx = 4, .ny = 3});
            cases.push_back({.name = "10k triangles", .nx = 71, .ny = 36});
            if (!ctx.quick) cases.push_back({.name = "100k triangles", .nx = 224, .ny = 112});
            cases.push_back({.name = "jittered mesh 0.3 cell", .jitter = 0.3});
            cases.push_back({.name = "tangled mesh 0.8 cell", .jitter = 0.8});
            const double cap = ctx.quick ? 20.0 : 120.0;
            std::ostringstream sum;
            int other = 0;
            for (const Case& c : cases) {
              const Outcome o = Run(c, cap);
              if (o.outcome == "other") ++other;
              res.rows.push_back({{"case", c.name},
                                  {"outcome", o.outcome},
                                  {"seconds", o.seconds},
                                  {"iterations", o.iterations},
                                  {"triangles", o.triangles},
                                  {"message", o.message}});
              sum << c.name << ": " << o.outcome << " in " << Num(o.seconds, 3) << " s ("
                  << o.iterations << " it, " << o.triangles << " triangles)"
                  << (o.outcome == "converged" ? "" : ": " + o.message) << "\n";
              if (ctx.progress)
                std::fprintf(stderr, "stress %s: %s\n", c.name.c_str(), o.outcome.c_str());
            }
            sum << (other == 0 ? "no run ended in an unclean state\n"
                               : std::to_string(other) + " run(s) ended in an unclean state\n");
            res.summary = sum.str();
            chart::Panel panel{.title = "Run time per case (index as listed in the CSV)",
                               .x_label = "case",
                               .y_label = "seconds",
                               .log_y = true};
            for (const std::string outcome : {"converged", "failed-cleanly", "other"}) {
              chart::Series s{.label = outcome, .style = chart::Series::Style::kMarkers};
              for (size_t i = 0; i < res.rows.size(); ++i) {
                if (res.rows[i]["outcome"] != outcome) continue;
                s.x.push_back(static_cast<double>(i));
                s.y.push_back(std::max(1e-4, res.rows[i]["seconds"].get<double>()));
              }
              if (!s.x.empty()) panel.series.push_back(s);
            }
            chart::WritePng({.title = "stress: the static solver at the extremes", .panels = {panel}},
                            ctx.out_dir + "/stress.png");
            if (ctx.print) std::printf("%s", res.summary.c_str());
            return res;
          }};
}

}  // namespace textile::bench
