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

// Shadow photos (tests/data/drape-photos, rendered by render-shadow from a lobed drape of truth
// DC 0.44390 with 6 nodes): a vertical camera with --mm-per-px, and a camera tilted 8° with its
// rig; both within 0.001 of the truth (the issue asks 0.005), the overlay written, the MEASURED
// file readable by `drape --compare`.
TEST(CliDrapeMeasure, ShadowPhotosWithAScaleAndWithARig) {
  const auto dir = Scratch("CliDrapeMeasure.Photos");
  const std::string photos = "tests/data/drape-photos/";
  struct Case {
    std::string args, name;
  };
  for (const Case& c : {Case{photos + "shadow-lobed.png --mm-per-px 0.66", "plain"},
                        Case{photos + "shadow-lobed-tilted.jpg --rig " + photos +
                                 "shadow-lobed-tilted.rig.json",
                             "tilted"}}) {
    SCOPED_TRACE(c.name);
    const fs::path out = dir / (c.name + ".json"), png = dir / (c.name + ".png");
    const auto r = Textile("drape-measure " + c.args + " -o " + out.string() + " --png " +
                           png.string() + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(ReadAll(out));
    EXPECT_EQ(j["input"], "photo");
    EXPECT_NEAR(j["drape_coefficient"].get<double>(), 0.44390, 0.001);
    EXPECT_EQ(j["nodes"].get<int>(), 6);
    EXPECT_EQ(j["centre_from"], "shadow");
    EXPECT_GT(fs::file_size(png), 1000u);
    EXPECT_TRUE(fs::exists(dir / (c.name + ".outline.csv")));
    const MeasuredDrape back = ParseMeasuredDrapeJson(ReadAll(out), out.string());
    EXPECT_NEAR(back.drape_coefficient, j["drape_coefficient"].get<double>(), 1e-12);
    EXPECT_EQ(back.nodes.angles.size(), 6u);
  }
}

// The lab's whole chain on a rendered Cusick photo: a drape's mesh is photographed from 8° off
// vertical with its chessboard (render-shadow), the board calibrated, the photo measured through
// the rig: within 0.005 of the drape's own DC (the point 4; its pi R² value, the
// shadows being the same), the same nodes; then `drape --compare` of the same fabric passes.
TEST(CliDrapeMeasure, RenderedShadowPhotoThroughItsCalibratedRigMeasuresTheDrape) {
  const auto dir = Scratch("CliDrapeMeasure.Chain");
  const auto p = [&dir](const char* name) { return (dir / name).string(); };
  const std::string scene = "--material samples/materials/pabst-fig8.json --resolution-mm 15 "
                            "--rim-mm 0";
  ASSERT_EQ(Textile("drape " + scene + " -o " + p("d.json") + " --obj " + p("d.obj")).exit_code, 0);
  const auto shot = Textile("render-shadow " + p("d.obj") + " -o " + p("s.jpg") + " --board " +
                            p("b.png") + " --truth " + p("t.json") +
                            " --tilt-deg 8 --gradient 0.3 --noise 3 --jpeg 90");
  ASSERT_EQ(shot.exit_code, 0) << shot.err;
  const auto truth = nlohmann::json::parse(ReadAll(dir / "t.json"));
  const double square = truth["board"]["square_mm"].get<double>();
  const auto cal = Textile("calibrate " + p("b.png") + " --board 9x6 --square-mm " +
                           std::to_string(square) + " -o " + p("rig.json"));
  ASSERT_EQ(cal.exit_code, 0) << cal.err;
  const auto m = Textile("drape-measure " + p("s.jpg") + " --rig " + p("rig.json") + " -o " +
                         p("m.json"));
  ASSERT_EQ(m.exit_code, 0) << m.err;
  const auto measured = nlohmann::json::parse(ReadAll(dir / "m.json"));
  const auto drape = nlohmann::json::parse(ReadAll(dir / "d.json"));
  // The drape's DC over pi R² instead of its meshed pattern's area: the same shadow.
  const double own = drape["seeds"][0]["drape_coefficient"].get<double>();
  const double pattern = drape["scene"]["specimen_area_mm2"].get<double>();
  const double support = drape["scene"]["support_area_mm2"].get<double>();
  const double own_pi_r2 = own * (pattern - support) / (kPi * 150.0 * 150.0 - support);
  EXPECT_NEAR(measured["drape_coefficient"].get<double>(), own_pi_r2, 0.005);
  EXPECT_NEAR(measured["drape_coefficient"].get<double>(),
              truth["drape_coefficient"].get<double>(), 0.005);
  EXPECT_EQ(measured["nodes"], drape["seeds"][0]["nodes"]);
  const auto c = Textile("drape " + scene + " --compare " + p("m.json") + " -o " + p("c.json"));
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_EQ(nlohmann::json::parse(ReadAll(dir / "c.json"))["comparison"]["verdict"], "pass");
}

}  // namespace
}  // namespace textile
