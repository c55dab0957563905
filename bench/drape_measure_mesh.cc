// drape-measure-mesh: reading and measuring a draped mesh of about 500k triangles (a fine
// 3D scan's size) per file format, against the target of 0.5 s (issue #33).

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "bench/bench.h"
#include "common/atomic_file.h"
#include "textile/sim/io/mesh_io.h"
#include "textile/sim/plot/measured_drape_picture.h"
#include "textile/sim/scenes/drape_measure.h"

namespace textile::bench {

Benchmark DrapeMeasureMeshBenchmark();

namespace {

const bool kRegistered = AddBenchmark(62, DrapeMeasureMeshBenchmark);

constexpr double kTargetSeconds = 0.5;

// A six-node drape as a scan would give it: a fine polar mesh of the 150 mm specimen on the
// 90 mm support, its rim at r(θ) = 120 + 15 cos 6θ mm.
TriangleMesh ScanLikeDrape(bool quick) {
  const int rings = quick ? 100 : 250, sectors = quick ? 500 : 1000;  // 99.5k / 499k triangles
  return SyntheticDrapeMesh(0.15, 0.09, rings, sectors,
                            [](double t) { return 0.12 + 0.015 * std::cos(6.0 * t); });
}

double Seconds(std::chrono::steady_clock::time_point from) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - from).count();
}

}  // namespace

Benchmark DrapeMeasureMeshBenchmark() {
  return {"drape-measure-mesh",
          "drape-measure of a ~500k-triangle draped mesh: read + measure per format (target 0.5 s)",
          [](const Context& ctx) {
            Result res;
            res.columns = {"format",  "triangles",         "file_mb", "read_s",   "measure_s",
                           "total_s", "drape_coefficient", "nodes",   "target_s", "met"};
            const TriangleMesh mesh = ScanLikeDrape(ctx.quick);
            EnsureDirectory(ctx.out_dir);
            const std::string dir = ctx.out_dir + "/drape-measure-mesh-files";
            EnsureDirectory(dir);
            struct Format {
              const char* name;
              std::string file;
              std::string bytes;
            };
            Format formats[] = {{"obj", dir + "/drape.obj", ObjText(mesh)},
                                {"ply-ascii", dir + "/drape-ascii.ply", PlyText(mesh)},
                                {"ply-binary", dir + "/drape-binary.ply", PlyBinaryBytes(mesh)}};
            const int repeats = ctx.quick ? 1 : 5;
            MeasuredDrape last;
            for (Format& f : formats) {
              WriteFileAtomically(f.file, f.bytes);
              std::vector<double> read, measure, total;
              for (int k = 0; k < repeats; ++k) {
                const auto t0 = std::chrono::steady_clock::now();
                const TriangleMesh back = ReadDrapedMesh(f.file);
                const double r = Seconds(t0);
                const auto t1 = std::chrono::steady_clock::now();
                last = MeasureDrapeMesh(back, {}, f.file);
                measure.push_back(Seconds(t1));
                read.push_back(r);
                total.push_back(Seconds(t0));
              }
              const double t = Median(total);
              res.rows.push_back({{"format", f.name},
                                  {"triangles", mesh.num_triangles()},
                                  {"file_mb", static_cast<double>(f.bytes.size()) / 1e6},
                                  {"read_s", Median(read)},
                                  {"measure_s", Median(measure)},
                                  {"total_s", t},
                                  {"drape_coefficient", last.drape_coefficient},
                                  {"nodes", last.nodes.angles.size()},
                                  {"target_s", kTargetSeconds},
                                  {"met", t <= kTargetSeconds}});
              if (ctx.progress) std::fprintf(stderr, "drape-measure-mesh: %s %.3f s\n", f.name, t);
              std::filesystem::remove(f.file);
            }
            std::filesystem::remove(dir);
            std::ostringstream sum;
            char line[200];
            std::snprintf(line, sizeof line, "%-11s %9s %8s %8s %9s %8s %7s %5s %4s\n", "format",
                          "triangles", "file_MB", "read_s", "measure_s", "total_s", "DC", "nodes",
                          "met");
            sum << line;
            for (const auto& r : res.rows) {
              std::snprintf(line, sizeof line, "%-11s %9d %8.1f %8.3f %9.3f %8.3f %7.4f %5d %4s\n",
                            r["format"].get<std::string>().c_str(), r["triangles"].get<int>(),
                            r["file_mb"].get<double>(), r["read_s"].get<double>(),
                            r["measure_s"].get<double>(), r["total_s"].get<double>(),
                            r["drape_coefficient"].get<double>(), r["nodes"].get<int>(),
                            r["met"].get<bool>() ? "yes" : "no");
              sum << line;
            }
            res.summary = sum.str();
            WriteMeasuredDrapePng(last, ctx.out_dir + "/drape-measure-mesh.png");
            return res;
          }};
}

}  // namespace textile::bench
