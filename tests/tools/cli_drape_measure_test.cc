// `textile drape-measure` through the real executable: the round trip from `textile drape`'s
// draped mesh (issue #33, point 4) and the files and text it writes.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "run_cli.h"
#include "textile/sim/io/mesh_io.h"
#include "textile/sim/scenes/drape_measure.h"

namespace textile {
namespace {

using testing::ReadAll;
using testing::Scratch;
using testing::Textile;
namespace fs = std::filesystem;

constexpr double kPi = std::numbers::pi;

// The smallest angle between two directions [deg].
double AngleApart(double a_deg, double b_deg) {
  return std::abs(std::remainder(a_deg - b_deg, 360.0));
}

TEST(CliDrapeMeasure, RoundTripFromDrapeObjAndPly) {
  const auto dir = Scratch("CliDrapeMeasure.RoundTrip");
  const auto d = Textile(
      "drape --material samples/materials/pabst-fig8.json --resolution-mm 15 "
      "--rim-mm 0 -o " +
      (dir / "d.json").string() + " --obj " + (dir / "d.obj").string() + " --ply " +
      (dir / "d.ply").string());
  ASSERT_EQ(d.exit_code, 0) << d.err;
  const auto drape = nlohmann::json::parse(ReadAll(dir / "d.json"));
  const auto m = Textile("drape-measure " + (dir / "d.obj").string() + " -o " +
                         (dir / "m.json").string() + " --png " + (dir / "m.png").string());
  ASSERT_EQ(m.exit_code, 0) << m.err;
  EXPECT_TRUE(m.err.empty()) << m.err;
  const auto measured = nlohmann::json::parse(ReadAll(dir / "m.json"));
  const double dc_drape = drape["drape_coefficient"], dc = measured["drape_coefficient"];
  EXPECT_NEAR(dc, dc_drape, 0.002);
  // The same raster (the mesh is centred: the centre is its origin, as the drape's), so the
  // whole difference is the definition: A_specimen = π R² here, the meshed pattern's area there.
  EXPECT_EQ(measured["centre_from"], "origin");
  const double support = drape["scene"]["support_area_mm2"],
               pattern = drape["scene"]["specimen_area_mm2"];
  const double circle = kPi * 150.0 * 150.0;
  EXPECT_NEAR(dc, dc_drape * (pattern - support) / (circle - support), 1e-9);
  EXPECT_NEAR(measured["shadow_area_mm2"].get<double>(),
              drape["seeds"][0]["shadow_area_mm2"].get<double>(), 1e-6);
  // The same nodes.
  const auto& sim_nodes = drape["seeds"][0]["node_list"];
  const auto& nodes = measured["node_list"];
  ASSERT_EQ(nodes.size(), sim_nodes.size());
  ASSERT_GE(nodes.size(), 3u);
  for (size_t k = 0; k < nodes.size(); ++k)
    EXPECT_LT(AngleApart(nodes[k]["angle_deg"], sim_nodes[k]["angle_deg"]), 2.0) << k;

  // The PLY (ASCII, with the drape's extra vertex properties) measures the same.
  const auto p = Textile("drape-measure " + (dir / "d.ply").string() + " -o " +
                         (dir / "p.json").string() + " --json");
  ASSERT_EQ(p.exit_code, 0) << p.err;
  const auto from_ply = nlohmann::json::parse(p.out);
  EXPECT_EQ(from_ply["drape_coefficient"].get<double>(), dc);
  EXPECT_EQ(from_ply["nodes"], measured["nodes"]);
  EXPECT_EQ(from_ply["output"], (dir / "p.json").string());

  // The text names the figures and the files; the outline CSV and the PNG are written.
  EXPECT_NE(m.out.find("drape coefficient: "), std::string::npos) << m.out;
  EXPECT_NE(m.out.find("centre: (0, 0) mm, the mesh's origin"), std::string::npos) << m.out;
  EXPECT_NE(m.out.find("outline: " + (dir / "m.outline.csv").string()), std::string::npos);
  const std::string csv = ReadAll(dir / "m.outline.csv");
  EXPECT_EQ(csv.rfind("theta_deg,r_mm,x_mm,y_mm\n", 0), 0u);
  EXPECT_EQ(testing::CountLines(csv), 361);
  EXPECT_EQ(ReadAll(dir / "m.png").substr(1, 3), "PNG");
}

TEST(CliDrapeMeasure, ScanInMillimetresYUpAndMovedMeasuresTheSame) {
  const auto dir = Scratch("CliDrapeMeasure.Scan");
  const TriangleMesh drape = SyntheticDrapeMesh(
      0.15, 0.09, 30, 360, [](double t) { return 0.12 + 0.015 * std::cos(7.0 * t); });
  // The scan: millimetres, y up ((X, Y, H) → (X, H, −Y)), moved by (37, −12) mm, binary PLY.
  TriangleMesh scan = drape;
  for (int v = 0; v < scan.num_vertices(); ++v) {
    const double x = drape.vertices(v, 0), y = drape.vertices(v, 1), h = drape.vertices(v, 2);
    scan.vertices.row(v) << 1000.0 * x + 37.0, 1000.0 * h + 250.0, -(1000.0 * y - 12.0);
  }
  std::ofstream(dir / "drape.obj") << ObjText(drape);
  std::ofstream(dir / "scan.ply", std::ios::binary) << PlyBinaryBytes(scan);
  const auto a = Textile("drape-measure " + (dir / "drape.obj").string() + " -o " +
                         (dir / "a.json").string() + " --json");
  const auto b = Textile("drape-measure " + (dir / "scan.ply").string() + " --units mm --up y -o " +
                         (dir / "b.json").string() + " --json");
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const auto ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
  EXPECT_EQ(jb["centre_from"], "plateau");
  EXPECT_NEAR(jb["centre_mm"][0].get<double>(), 37.0, 1e-6);
  EXPECT_NEAR(jb["centre_mm"][1].get<double>(), -12.0, 1e-6);
  EXPECT_NEAR(ja["drape_coefficient"].get<double>(), jb["drape_coefficient"].get<double>(), 5e-4);
  ASSERT_EQ(ja["nodes"], 7);
  ASSERT_EQ(jb["nodes"], 7);
  for (size_t k = 0; k < 7; ++k)
    EXPECT_NEAR(ja["node_list"][k]["radius_mm"].get<double>(),
                jb["node_list"][k]["radius_mm"].get<double>(), 0.5)
        << k;
}

}  // namespace
}  // namespace textile
