// drape-measure-photo (issue 33's targets): a seeded population of rendered top-view shadow
// photos (render_shadow.h) of draped meshes (the Fig. 8 fabric's simulated drape and lobed
// synthetic shadows with 4-9 nodes and an off-centre first harmonic), tilted 0-10° off
// vertical, both styles, a light gradient and vignetting, noise and JPEG, at 20 MP; measured
// with the true rig by MeasureDrapePhoto. Reports |DC error| against the mesh's own DC, node
// count mismatches, the found centre's error, gross failures and the time per photo (wall
// clock with OpenCV's threads, and the CPU time of one thread with OpenCV single-threaded).


#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <numbers>
#include <opencv2/core.hpp>
#include <random>
#include <sstream>

#include "bench/bench.h"
#include "textile/photo/drape_photo.h"
#include "textile/photo/render_shadow.h"
#include "textile/sim/law/material.h"
#include "textile/sim/scenes/drape.h"

namespace textile::bench {
namespace {

// A polar mesh whose projection is r ≤ mean + lobe cos(n θ + φ) + skew cos(θ − ψ) [m].
TriangleMesh LobedMesh(int nodes, double lobe, double skew, double phase, double skew_angle) {
  const int rings = 24, segments = 720;
  TriangleMesh m;
  m.vertices.resize(1 + rings * segments, 3);
  m.vertices.row(0) << 0, 0, 0;
  for (int k = 1; k <= rings; ++k)
    for (int s = 0; s < segments; ++s) {
      const double t = 2 * std::numbers::pi * s / segments;
      const double r =
          double(k) / rings *
          (0.12 + lobe * std::cos(nodes * t + phase) + skew * std::cos(t - skew_angle));
      m.vertices.row(1 + (k - 1) * segments + s) << r * std::cos(t), r * std::sin(t), 0.0;
    }
  m.triangles.resize(segments * (2 * rings - 1), 3);
  int n = 0;
  auto id = [](int k, int s) { return 1 + (k - 1) * segments + (s % segments); };
  for (int s = 0; s < segments; ++s) m.triangles.row(n++) << 0, id(1, s), id(1, s + 1);
  for (int k = 1; k < rings; ++k)
    for (int s = 0; s < segments; ++s) {
      m.triangles.row(n++) << id(k, s), id(k + 1, s), id(k + 1, s + 1);
      m.triangles.row(n++) << id(k, s), id(k + 1, s + 1), id(k, s + 1);
    }
  return m;
}

Benchmark DrapeMeasurePhotoBenchmark();
const bool kRegistered = AddBenchmark(65, DrapeMeasurePhotoBenchmark);

Benchmark DrapeMeasurePhotoBenchmark() {
  return {
      "drape-measure-photo",
      "rendered 20 MP shadow photos (tilt 0-10°, both styles, light, noise, JPEG): DC error, "
      "nodes, centre, time per photo",
      [](const Context& ctx) {
        Result res;
        res.columns = {"case",     "mesh",     "style",       "tilt_deg",   "k1",
                       "gradient", "noise",    "jpeg",        "megapixels", "truth_dc",
                       "dc",       "dc_error", "truth_nodes", "nodes",      "centre_error_mm",
                       "seconds",  "cpu_ms",   "success",     "description"};
        const int cases = ctx.quick ? 4 : 24;
        const int width = ctx.quick ? 1600 : 5472, height = ctx.quick ? 1200 : 3648;
        // About 520 x 350 mm in view: the largest shadow (292 mm across) fits at 10° of tilt.
        const double mm_per_px = ctx.quick ? 0.3 : 0.095;
        // The simulated drape: the Fig. 8 fabric, one seed, a coarse mesh (its shadow is what
        // matters here, not its accuracy as a drape).
        Material fig8;  // samples/materials/pabst-fig8.json
        fig8.name = "Pabst Fig. 8";
        fig8.areal_density = 0.2;
        fig8.bending = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
        DrapeOptions d;
        d.element_size = 0.015;
        const DrapeResult sim = SimulateDrape(fig8, d);
        std::mt19937_64 rng(20261202);
        std::uniform_real_distribution<double> U(0.0, 1.0);
        std::vector<double> errors, centre_errors, seconds, cpu;
        int node_mismatches = 0, failures = 0, render_failures = 0;
        for (int c = 1; c <= cases; ++c) {
          RenderShadowOptions o;
          o.width_px = width, o.height_px = height, o.mm_per_px = mm_per_px;
          o.style = c % 2 ? ShadowStyle::kShadow : ShadowStyle::kTop;
          o.tilt_deg = 10.0 * (c - 1) / std::max(1, cases - 1);
          o.tilt_azimuth_deg = 360.0 * U(rng), o.roll_deg = 20.0 * U(rng) - 10.0;
          o.k1 = c % 3 == 0 ? -0.08 * U(rng) : 0.0;
          o.gradient = 0.4 * U(rng), o.gradient_azimuth_deg = 360.0 * U(rng);
          o.vignetting = 0.25 * U(rng);
          o.noise = 1.0 + 4.0 * U(rng);
          o.jpeg_quality = c % 4 == 0 ? 0 : 80 + static_cast<int>(15 * U(rng));
          o.blur_px = (0.8 + 1.5 * U(rng)) * (ctx.quick ? 1.0 : 2.0);
          o.texture = o.style == ShadowStyle::kTop ? 0.12 * U(rng) : 0.0;
          if (o.style == ShadowStyle::kTop && U(rng) < 0.5)
            o.paper = 0.18, o.specimen_reflectance = 0.7;  // a light specimen on a dark ground
          o.supersample = 2;
          o.render_board = false;
          o.seed = 1000u + c;
          const bool use_sim = c % 3 == 1 && sim.converged;
          std::string mesh_name = "fig8-drape";
          TriangleMesh lobed;
          if (!use_sim) {
            const int nodes = 4 + static_cast<int>(6 * U(rng));
            lobed = LobedMesh(nodes, 0.008 + 0.012 * U(rng), 0.006 * U(rng), 6.3 * U(rng),
                              6.3 * U(rng));
            mesh_name = "lobed-" + std::to_string(nodes);
          }
          const Vertices& x = use_sim ? sim.per_seed[0].positions : lobed.vertices;
          const Triangles& t = use_sim ? sim.mesh.triangles : lobed.triangles;
          nlohmann::json row = {{"case", c},
                                {"mesh", mesh_name},
                                {"style", ToString(o.style)},
                                {"tilt_deg", o.tilt_deg},
                                {"k1", o.k1},
                                {"gradient", o.gradient},
                                {"noise", o.noise},
                                {"jpeg", o.jpeg_quality},
                                {"megapixels", width * height / 1e6}};
          RenderedShadow r;
          try {
            r = RenderShadowPhoto(x, t, o);
          } catch (const std::exception& e) {
            row["success"] = false;
            row["description"] = std::string("render failed: ") + e.what();
            res.rows.push_back(row);
            ++render_failures;
            continue;
          }
          row["description"] = r.description;
          row["truth_dc"] = r.truth.drape_coefficient;
          row["truth_nodes"] = r.truth.nodes.angles.size();
          MeasuredDrape m;
          try {
            std::vector<double> wall;
            for (int k = 0; k < (ctx.quick ? 1 : 3); ++k) {
              const auto t0 = std::chrono::steady_clock::now();
              m = MeasureDrapePhoto(r.photo, r.rig, DrapePhotoOptions{}, "rendered");
              wall.push_back(
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            }
            const int threads = cv::getNumThreads();
            cv::setNumThreads(1);
            const double c0 = ThreadCpuSeconds();
            MeasureDrapePhoto(r.photo, r.rig, DrapePhotoOptions{}, "rendered");
            const double cpu_s = ThreadCpuSeconds() - c0;
            cv::setNumThreads(threads);
            row["seconds"] = Median(wall);
            row["cpu_ms"] = cpu_s * 1e3;
            seconds.push_back(Median(wall));
            cpu.push_back(cpu_s * 1e3);
          } catch (const std::exception& e) {
            row["success"] = false;
            row["description"] = r.description + "; failed: " + e.what();
            res.rows.push_back(row);
            ++failures;
            continue;
          }
          row["success"] = true;
          row["dc"] = m.drape_coefficient;
          row["dc_error"] = m.drape_coefficient - r.truth.drape_coefficient;
          row["nodes"] = m.nodes.angles.size();
          row["centre_error_mm"] = m.centre.norm() * 1e3;  // the true rig's frame is the drape's
          errors.push_back(std::abs(m.drape_coefficient - r.truth.drape_coefficient));
          centre_errors.push_back(m.centre.norm() * 1e3);
          if (m.nodes.angles.size() != r.truth.nodes.angles.size()) ++node_mismatches;
          if (ctx.progress)
            std::cerr << "drape-measure-photo: case " << c << " " << mesh_name << " "
                      << ToString(o.style) << " tilt " << o.tilt_deg << ": DC error "
                      << row["dc_error"].get<double>() << ", " << row["seconds"].get<double>()
                      << " s\n";
          res.rows.push_back(row);
        }
        const auto worst = [](const std::vector<double>& v) {
          return v.empty() ? NAN : *std::max_element(v.begin(), v.end());
        };
        std::ostringstream sum;
        char line[512];
        std::snprintf(line, sizeof line,
                      "%d photos of %.1f MP: |DC error| median %.5f, worst %.5f (target 0.005); "
                      "node count mismatches %d; gross failures %d (renders that failed: %d)\n"
                      "found centre's error: median %.2f mm, worst %.2f mm\n"
                      "time per photo: median %.3f s wall (worst %.3f), %.0f ms CPU on one thread "
                      "(target 0.3 s)\n",
                      cases, width * height / 1e6, Median(errors), worst(errors), node_mismatches,
                      failures, render_failures, Median(centre_errors), worst(centre_errors),
                      Median(seconds), worst(seconds), Median(cpu));
        res.summary = line;
        if (ctx.print) std::cout << res.summary;
        return res;
      }};
}

}  // namespace
}  // namespace textile::bench
