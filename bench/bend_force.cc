// bend-force: run time of one bending-force evaluation, and of force + Jacobian, for the four
// bending models on Pabst et al.'s Table 3 scene (0.5 m × 0.5 m, 3600 triangles, fixed at one
// border and hanging down), 1 thread and all threads. Ratios to Bridson are measured in the same
// run, in alternating batches.
// One thread: CPU time of the calling thread per call (robust on a loaded machine); all threads:
// wall time (the CPU time of the workers is not the caller's). The Jacobian both ways: the
// fixed-pattern path (SetHessian, full and upper half) and the triplet path plus setFromTriplets.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <sstream>
#include <thread>

#include "bench/bench.h"
#include "common/chart_file.h"
#include "textile/sim/elements/bending_element.h"

namespace textile::bench {
namespace {

// A plausible hanging shape: clamped along x = 0, the slope grows like a heavy cantilever's
// (φ ∝ (s/L)², 70° at the free end, laid out isometrically), plus a 3 mm wave across y that
// grows towards the free end so that every hinge bends a little differently.
Vertices HangingSheet(const TriangleMesh& flat, double length) {
  Vertices x = flat.vertices;
  constexpr int kSteps = 2000;
  const double tip_angle = 70.0 * std::numbers::pi / 180.0;
  for (int i = 0; i < x.rows(); ++i) {
    const double s = flat.vertices(i, 0), y = flat.vertices(i, 1);
    double px = 0.0, pz = 0.0;  // midpoint-rule arc length integration of (cos φ, -sin φ)
    const double ds = s / kSteps;
    for (int k = 0; k < kSteps; ++k) {
      const double phi = tip_angle * std::pow((k + 0.5) * ds / length, 2);
      px += std::cos(phi) * ds;
      pz -= std::sin(phi) * ds;
    }
    const double wave =
        0.003 * (s / length) * (s / length) * std::sin(2.0 * std::numbers::pi * y / 0.25);
    x.row(i) << px, y, pz + wave;
  }
  return x;
}

// Seconds per call of f: 1 thread, this thread's CPU time, median over batches of 10 calls
// (the clock's resolution and scheduler noise average out in a batch); more threads, wall time.
double SecondsPerCall(const std::function<void()>& f, int repeats, int threads) {
  if (threads > 1) return MedianSeconds(f, repeats);
  constexpr int kBatch = 10;
  std::vector<double> per_call;
  for (int b = 0; b < std::max(3, repeats / kBatch); ++b) {
    const double start = ThreadCpuSeconds();
    for (int k = 0; k < kBatch; ++k) f();
    per_call.push_back((ThreadCpuSeconds() - start) / kBatch);
  }
  return Median(per_call);
}

}  // namespace

Benchmark BendForceBenchmark();

namespace {
const bool kRegistered = AddBenchmark(10, BendForceBenchmark);
}  // namespace

Benchmark BendForceBenchmark() {
  return {
      "bend-force",
      "Bending force and force + Jacobian on Pabst's Table 3 sheet (3600 triangles), four models",
      [](const Context& ctx) {
        Result res;
        res.columns = {"model",
                       "threads",
                       "clock",
                       "triangles",
                       "hinges",
                       "force_ms",
                       "force_jacobian_ms",
                       "force_jacobian_upper_ms",
                       "force_jacobian_psd_ms",
                       "force_jacobian_triplets_ms",
                       "assemble_ms",
                       "force_vs_bridson"};
        const TriangleMesh mesh = CrissCrossGridMesh(0.5, 0.5, 30, 30);  // 4·30·30 = 3600
        const std::vector<Hinge> hinges = BuildHinges(mesh);
        const Vertices x = HangingSheet(mesh, 0.5);
        const BendingLaw law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);  // Fig. 8 fabric
        const int all = std::max(1u, std::thread::hardware_concurrency());
        std::vector<int> thread_counts = {1};
        if (all > 1) thread_counts.push_back(all);
        const int repeats = ctx.quick ? 30 : 400;
        const BendingModel models[] = {BendingModel::kVolino, BendingModel::kBridson,
                                       BendingModel::kIsometric, BendingModel::kPabst};
        for (BendingModel model : models) {
          for (int threads : thread_counts) {
            const BendingElements b(mesh, hinges, law, std::nullopt,
                                    {.model = model, .threads = threads});
            const auto seconds = [&](const std::function<void()>& f, int n) {
              return SecondsPerCall(f, n, threads);
            };
            Vertices grad = Vertices::Zero(mesh.num_vertices(), 3);
            std::vector<Eigen::Triplet<double>> triplets;
            triplets.reserve(144 * hinges.size());
            const auto force = [&] {
              grad.setZero();
              b.AddGradient(x, grad);
            };
            force();  // warm up caches and the scratch buffer
            const double force_s = seconds(force, repeats);
            // New: the values of a fixed-pattern matrix, full and upper half.
            Eigen::SparseMatrix<double> full = b.HessianPattern(false);
            Eigen::SparseMatrix<double> upper = b.HessianPattern(true);
            const BendingHessianSlots full_slots = b.HessianSlots(full, false);
            const BendingHessianSlots upper_slots = b.HessianSlots(upper, true);
            const auto fixed = [&](HessianProjection projection, const BendingHessianSlots& slots,
                                   Eigen::SparseMatrix<double>* m) {
              force();
              b.SetHessian(x, projection, slots, m);
            };
            fixed(HessianProjection::kNone, full_slots, &full);
            const double fj_s =
                seconds([&] { fixed(HessianProjection::kNone, full_slots, &full); }, repeats);
            const double upper_s =
                seconds([&] { fixed(HessianProjection::kNone, upper_slots, &upper); }, repeats);
            const double psd_s =
                seconds([&] { fixed(HessianProjection::kEigen, full_slots, &full); },
                        std::max(10, repeats / 20));
            // Old: triplets, then what a Newton step pays on top: the sparse matrix from them.
            const auto triplet_path = [&] {
              force();
              triplets.clear();
              b.AddHessianTriplets(x, &triplets, false);
            };
            triplet_path();
            const int few = std::max(10, repeats / 20);
            const double triplets_s = seconds(triplet_path, few);
            Eigen::SparseMatrix<double> hessian(3 * mesh.num_vertices(), 3 * mesh.num_vertices());
            const double assemble_s = seconds(
                [&] { hessian.setFromTriplets(triplets.begin(), triplets.end()); }, few);
            res.rows.push_back({{"model", BendingModelName(model)},
                                {"threads", threads},
                                {"clock", threads > 1 ? "wall" : "thread_cpu"},
                                {"triangles", mesh.num_triangles()},
                                {"hinges", static_cast<int>(hinges.size())},
                                {"force_ms", force_s * 1e3},
                                {"force_jacobian_ms", fj_s * 1e3},
                                {"force_jacobian_upper_ms", upper_s * 1e3},
                                {"force_jacobian_psd_ms", psd_s * 1e3},
                                {"force_jacobian_triplets_ms", triplets_s * 1e3},
                                {"assemble_ms", assemble_s * 1e3}});
          }
        }
        // Ratios to Bridson at the same thread count, paired: batches of the model and of
        // Bridson alternate, and the median of the batch ratios is taken, so that a change of
        // the machine's load between the rows above does not enter the ratio.
        for (int threads : thread_counts) {
          const BendingElements bridson(mesh, hinges, law, std::nullopt,
                                        {.model = BendingModel::kBridson, .threads = threads});
          for (auto& r : res.rows) {
            if (r["threads"] != threads) continue;
            const BendingElements b(mesh, hinges, law, std::nullopt,
                                    {.model = ParseBendingModel(r["model"].get<std::string>()),
                                     .threads = threads});
            Vertices grad = Vertices::Zero(mesh.num_vertices(), 3);
            const auto force = [&](const BendingElements& e) {
              return [&grad, &x, e = &e] {
                grad.setZero();
                e->AddGradient(x, grad);
              };
            };
            std::vector<double> ratios;
            for (int k = 0; k < std::max(3, repeats / 10); ++k) {
              const double t_model = SecondsPerCall(force(b), 10, threads);
              ratios.push_back(t_model / SecondsPerCall(force(bridson), 10, threads));
            }
            r["force_vs_bridson"] = Median(ratios);
          }
        }

        std::ostringstream sum;
        char line[220];
        std::snprintf(line, sizeof line, "%-10s %7s %10s %10s %10s %10s %11s %10s %10s\n",
                      "model", "threads", "force_ms", "force+J", "force+J_up", "force+Jpsd",
                      "triplets+J", "assemble", "vs_bridson");
        sum << line;
        for (const auto& r : res.rows) {
          std::snprintf(line, sizeof line,
                        "%-10s %7d %10.4f %10.4f %10.4f %10.3f %11.3f %10.3f %10.2f\n",
                        r["model"].get<std::string>().c_str(), r["threads"].get<int>(),
                        r["force_ms"].get<double>(), r["force_jacobian_ms"].get<double>(),
                        r["force_jacobian_upper_ms"].get<double>(),
                        r["force_jacobian_psd_ms"].get<double>(),
                        r["force_jacobian_triplets_ms"].get<double>(),
                        r["assemble_ms"].get<double>(), r["force_vs_bridson"].get<double>());
          sum << line;
        }
        sum << "1 thread: CPU ms of the calling thread per call; more threads: wall ms. force+J: "
               "force + SetHessian (fixed pattern, full; _up: upper half); triplets+J: force + "
               "AddHessianTriplets, plus setFromTriplets (assemble) to get a matrix; vs_bridson: "
               "median ratio of alternating batches\n";
        const auto find = [&](const char* model, int threads) -> const nlohmann::json& {
          for (const auto& r : res.rows)
            if (r["model"] == model && r["threads"] == threads) return r;
          return res.rows.front();
        };
        const auto& p1 = find("pabst", 1);
        std::snprintf(line, sizeof line,
                      "targets (1 thread): pabst force %.4f ms (<= 0.1: %s), pabst/bridson %.2f "
                      "(<= 1.2: %s), "
                      "force + Jacobian %.3f ms (<= 0.5: %s; upper half %.3f ms); paper: 6.3 / "
                      "51.1 / 65.0 ms\n",
                      p1["force_ms"].get<double>(),
                      p1["force_ms"].get<double>() <= 0.1 ? "met" : "MISSED",
                      p1["force_vs_bridson"].get<double>(),
                      p1["force_vs_bridson"].get<double>() <= 1.2 ? "met" : "MISSED",
                      p1["force_jacobian_ms"].get<double>(),
                      p1["force_jacobian_ms"].get<double>() <= 0.5 ? "met" : "MISSED",
                      p1["force_jacobian_upper_ms"].get<double>());
        sum << line;
        res.summary = sum.str();

        namespace chart = textile::chart;
        chart::Panel p{
            .title = "Bending on 3600 triangles (" + std::to_string(hinges.size()) + " hinges)",
            .x_label = "model (1 Volino, 2 Bridson, 3 isometric, 4 Pabst)",
            .y_label = "time per evaluation [ms]",
            .log_y = true};
        int k = 0;
        for (int threads : thread_counts) {
          for (const char* what : {"force_ms", "force_jacobian_ms"}) {
            chart::Series s{
                .label =
                    std::string(what == std::string("force_ms") ? "force" : "force + Jacobian") +
                    ", " + std::to_string(threads) + " thread" + (threads > 1 ? "s" : ""),
                .style = chart::Series::Style::kLineAndMarkers,
                .color = chart::PaletteColor(k++),
                .dashed = threads > 1};
            int i = 1;
            for (BendingModel model : models) {
              s.x.push_back(i++);
              s.y.push_back(find(BendingModelName(model).c_str(), threads)[what].get<double>());
            }
            p.series.push_back(s);
          }
        }
        p.notes = {"paper (2008 CPU): Volino 6.3, Bridson 51.1, Pabst 65.0 ms (force)"};
        chart::WritePng({.title = "bend-force benchmark", .panels = {p}},
                        ctx.out_dir + "/bend-force.png");
        return res;
      }};
}

}  // namespace textile::bench
