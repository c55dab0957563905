// `textile drape` through the real executable (coarse meshes: the figures are checked for
// consistency and bounds, docs/methods/drapemeter.md has the converged numbers).

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "run_cli.h"
#include "textile/sim/scenes/drape_measure.h"

namespace textile {
namespace {

using testing::ExpectRefused;
using testing::ReadAll;
using testing::Scratch;
using testing::Textile;
namespace fs = std::filesystem;

const std::string kFig8 = "--material samples/materials/pabst-fig8.json";
const std::string kCoarseMesh = " --resolution-mm 15 --no-coarse-to-fine";
// Without the default rim band (--rim-mm auto), for speed: the tests check orderings and the
// files, not the converged DC.
const std::string kCoarse = kCoarseMesh + " --rim-mm 0";

TEST(CliDrape, PlainDrapeWritesResultOutlinePngAndObj) {
  const auto dir = Scratch("CliDrape.Plain");
  const auto r = Textile("drape " + kFig8 + kCoarse + " --seeds 2 -o " + (dir / "drape.json").string() +
                         " --png " + (dir / "shadow.png").string() + " --obj " + (dir / "mesh.obj").string() +
                         " --json --progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("drape: seed 2"), std::string::npos) << r.err;  // progress on stderr
  const auto out = nlohmann::json::parse(r.out);
  const auto j = nlohmann::json::parse(ReadAll(dir / "drape.json"));
  EXPECT_EQ(out["drape_coefficient"], j["drape_coefficient"]);
  EXPECT_TRUE(j["converged"].get<bool>());
  const double dc = j["drape_coefficient"].get<double>();
  EXPECT_GT(dc, 0.0);
  EXPECT_LT(dc, 1.0);
  ASSERT_EQ(j["seeds"].size(), 2u);
  // Mean and sample sd of the two seeds' figures.
  const double a = j["seeds"][0]["drape_coefficient"], b = j["seeds"][1]["drape_coefficient"];
  EXPECT_NEAR(dc, 0.5 * (a + b), 1e-12);
  EXPECT_NEAR(j["drape_coefficient_sd"].get<double>(), std::abs(a - b) / std::sqrt(2.0), 1e-12);
  EXPECT_TRUE(j["nodes"].is_number());
  EXPECT_TRUE(j["nodes_sd"].is_number());
  // Every figure's mean and sample sd over the seeds (the outline radii too).
  for (const std::string figure : {"min_radius", "max_radius", "mean_radius"}) {
    const double ra = j["seeds"][0][figure + "_mm"], rb = j["seeds"][1][figure + "_mm"];
    EXPECT_NEAR(j[figure + "_mm"].get<double>(), 0.5 * (ra + rb), 1e-9) << figure;
    EXPECT_NEAR(j[figure + "_sd_mm"].get<double>(), std::abs(ra - rb) / std::sqrt(2.0), 1e-9) << figure;
  }
  EXPECT_EQ(j["scene"]["mount"], "clamped");
  EXPECT_EQ(j["scene"]["start_modes"], nlohmann::json::parse("[3, 8]"));
  // The solver report: a factorisation per Newton step at least, the exact-Hessian steps among
  // them, a residual under the tolerance.
  for (const auto& seed : j["seeds"]) {
    const auto& solver = seed["solver"];
    EXPECT_TRUE(solver["converged"].get<bool>());
    EXPECT_GE(solver["factorizations"].get<int>(), solver["iterations"].get<int>());
    EXPECT_GE(solver["exact_hessian_steps"].get<int>(), 0);
    EXPECT_LE(solver["exact_hessian_steps"].get<int>(), solver["iterations"].get<int>());
    EXPECT_LT(solver["residual"].get<double>(), 1e-4);
    EXPECT_EQ(solver["friction_slips"].get<int>(), 0);  // clamped: no support, no friction
  }
  // Outline CSV next to the result: a header and one row per 1° bin, radii between the
  // support and the specimen.
  const std::string csv = ReadAll(dir / "drape.outline.csv");
  EXPECT_EQ(csv.rfind("theta_deg,r_mm,x_mm,y_mm\n", 0), 0u);
  EXPECT_EQ(testing::CountLines(csv), 361);
  EXPECT_GT(j["min_radius_mm"].get<double>(), 90.0);
  EXPECT_LT(j["max_radius_mm"].get<double>(), 151.0);
  EXPECT_GT(fs::file_size(dir / "shadow.png"), 5000u);
  const std::string obj = ReadAll(dir / "mesh.obj");
  EXPECT_NE(obj.find("\nf "), std::string::npos);
}

TEST(CliDrape, SeamFromPresetOrFileRaisesDc) {
  const auto dir = Scratch("CliDrape.Seam");
  const auto plain = Textile("drape " + kFig8 + kCoarse + " -o " + (dir / "plain.json").string() + " --json");
  const auto preset = Textile("drape " + kFig8 + kCoarse + " --seams weft --seam-type C-plain -o " +
                              (dir / "preset.json").string() + " --json");
  const auto file = Textile("drape " + kFig8 + kCoarse +
                            " --seams weft --seam-file samples/seams/C-plain.json --sensitivity -o " +
                            (dir / "file.json").string() + " --json");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  ASSERT_EQ(preset.exit_code, 0) << preset.err;
  ASSERT_EQ(file.exit_code, 0) << file.err;
  const auto p = nlohmann::json::parse(plain.out), s = nlohmann::json::parse(preset.out),
             f = nlohmann::json::parse(file.out);
  EXPECT_GT(s["drape_coefficient"].get<double>(), p["drape_coefficient"].get<double>());
  // The sample file holds the same Table 2 seam: the same drape.
  EXPECT_NEAR(f["drape_coefficient"].get<double>(), s["drape_coefficient"].get<double>(), 1e-9);
  EXPECT_EQ(s["scene"]["seams"], "weft");
  EXPECT_EQ(s["scene"]["seam_profile"]["type"], "C-plain");
  // --sensitivity with seams: the seam's coefficients as the file has them, then B_f as a
  // whole; a stiffer seam holds the drape up.
  const auto& seam = f["seam_sensitivities"];
  ASSERT_EQ(seam.size(), 4u) << f.dump();
  EXPECT_EQ(seam[2]["parameter"], "seam.a0");
  EXPECT_DOUBLE_EQ(seam[2]["value"].get<double>(), 9.07);
  EXPECT_EQ(seam[3]["parameter"], "seam.scale");
  EXPECT_GT(seam[3]["d_dc_d_ln_p"].get<double>(), 0.0);
  EXPECT_FALSE(s.contains("seam_sensitivities"));
}

// A PLY's header properties of its vertex element and its vertex rows (ASCII, as PlyText writes).
struct Ply {
  std::vector<std::string> properties;
  std::vector<std::vector<double>> vertices;
};
Ply ReadPly(const std::string& text) {
  Ply ply;
  std::istringstream in(text);
  std::string line;
  int count = 0;
  bool in_vertex = false;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream words(line);
    std::string a, b, c;
    words >> a >> b >> c;
    if (a == "element") {
      in_vertex = b == "vertex";
      if (in_vertex) count = std::stoi(c);
    } else if (a == "property" && in_vertex) {
      ply.properties.push_back(c);
    }
  }
  for (int v = 0; v < count && std::getline(in, line); ++v) {
    std::istringstream words(line);
    std::vector<double> row;
    for (double x; words >> x;) row.push_back(x);
    ply.vertices.push_back(row);
  }
  return ply;
}

TEST(CliDrape, PlyCarriesEachVertexsPatternPositionAndSeamDistance) {
  // Weft seam: the diameter along the pattern's y axis, so a vertex's distance to it is |rest x|.
  // Clamped vertices (r <= 90 mm) lie where they were cut; the overhang hangs below.
  const auto dir = Scratch("CliDrape.Ply");
  const auto r = Textile("drape " + kFig8 + kCoarse + " --seams weft -o " + (dir / "seam.json").string() +
                         " --ply " + (dir / "seam.ply").string() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["ply"], (dir / "seam.ply").string());
  const Ply ply = ReadPly(ReadAll(dir / "seam.ply"));
  ASSERT_EQ(ply.properties, (std::vector<std::string>{"x", "y", "z", "rest_x", "rest_y", "seam_distance"}));
  ASSERT_EQ(static_cast<int>(ply.vertices.size()), j["scene"]["vertices"].get<int>());
  int clamped = 0, hanging = 0;
  for (const auto& v : ply.vertices) {
    ASSERT_EQ(v.size(), 6u);
    EXPECT_NEAR(v[5], std::abs(v[3]), 1e-12);
    if (std::hypot(v[3], v[4]) < 0.089) {
      ++clamped;
      EXPECT_NEAR(v[0], v[3], 1e-12);
      EXPECT_NEAR(v[1], v[4], 1e-12);
      EXPECT_NEAR(v[2], 0.0, 1e-12);
    } else if (std::hypot(v[3], v[4]) > 0.149) {
      hanging += v[2] < -0.01;
    }
  }
  EXPECT_GT(clamped, 50);
  EXPECT_GT(hanging, 20);
  // Weft and warp seams turned by 30°, on the split rim (the result's mesh is the split one): the
  // distance is to the nearer of the two diameters. Text output, one seed: no radius sd line.
  const auto cross = Textile("drape " + kFig8 + kCoarseMesh + " --rim-mm 6 --seams weft+warp --frame-deg 30 -o " +
                             (dir / "cross.json").string() + " --ply " + (dir / "cross.ply").string());
  ASSERT_EQ(cross.exit_code, 0) << cross.err;
  EXPECT_NE(cross.out.find("mesh (PLY): " + (dir / "cross.ply").string()), std::string::npos) << cross.out;
  EXPECT_EQ(cross.out.find("outline radius"), std::string::npos) << cross.out;
  const auto jc = nlohmann::json::parse(ReadAll(dir / "cross.json"));
  ASSERT_TRUE(jc["scene"]["extrapolate"].get<bool>());
  const Ply cp = ReadPly(ReadAll(dir / "cross.ply"));
  ASSERT_EQ(static_cast<int>(cp.vertices.size()), jc["scene"]["vertices"].get<int>());
  EXPECT_GT(jc["scene"]["vertices"].get<int>(), jc["scene"]["base_vertices"].get<int>());
  const double t = 30.0 * M_PI / 180.0;
  for (const auto& v : cp.vertices) {
    ASSERT_EQ(v.size(), 6u);
    const double to_warp = std::abs(-v[3] * std::sin(t) + v[4] * std::cos(t));  // the x axis turned
    const double to_weft = std::abs(v[3] * std::cos(t) + v[4] * std::sin(t));   // the y axis turned
    EXPECT_NEAR(v[5], std::min(to_warp, to_weft), 1e-9);
  }
  // Without seams there is no seam distance; two seeds print the radii's sd.
  const auto plain = Textile("drape " + kFig8 + kCoarse + " --seeds 2 -o " + (dir / "plain.json").string() +
                             " --ply " + (dir / "plain.ply").string());
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_NE(plain.out.find("\noutline radius [mm]: min "), std::string::npos) << plain.out;
  EXPECT_EQ(ReadPly(ReadAll(dir / "plain.ply")).properties,
            (std::vector<std::string>{"x", "y", "z", "rest_x", "rest_y"}));
}

// The vertex count a drape reports before it solves ("drape: mesh: N vertices" on stderr; 0 if
// absent), so capped runs, which write nothing, still show the mesh.
int MeshVertices(const std::string& err) {
  const auto at = err.find("drape: mesh: ");
  return at == std::string::npos ? 0 : std::stoi(err.substr(at + 13));
}

// The last "error: ..." line of stderr, checked to be one line ("" and a failure if none).
std::string LastError(const std::string& err) {
  const auto at = err.rfind("error: ");
  if (at == std::string::npos) {
    ADD_FAILURE() << "no error line in: " << err;
    return {};
  }
  std::string last = err.substr(at);
  EXPECT_EQ(testing::CountLines(last), 1) << err;
  return last;
}

// Degrees from the angle a [deg] to the nearest multiple of 90° (the weft and warp seams' ends).
double DegreesToSeamLines(double a) {
  const double r = std::fmod(std::fmod(a, 90.0) + 90.0, 90.0);
  return std::min(r, 90.0 - r);
}

TEST(CliDrape, LengthwiseStiffSeamsPutTheNodesOnTheSeamLines) {
  // Default settings (the fold pattern needs the rim band). The paper's scalar seam (rib 1)
  // puts the four nodes of weft + warp seams on the diagonals (measured 45°, 134°, 224°, 316°);
  // a seam band 16 times stiffer against bending its own line puts them on the seam lines
  // (measured 92°, 176°, 266°, 358° for seeds 1-4). docs/methods/seams.md, "Lengthwise stiffness".
  const auto dir = Scratch("CliDrape.Rib");
  const auto paper = Textile("drape " + kFig8 + " --seams weft+warp -o " + (dir / "paper.json").string() +
                             " --json");
  const auto rib = Textile("drape " + kFig8 + " --seams weft+warp --seam-rib 16 --seeds 2 -o " +
                           (dir / "rib.json").string() + " --json");
  ASSERT_EQ(paper.exit_code, 0) << paper.err;
  ASSERT_EQ(rib.exit_code, 0) << rib.err;
  const auto p = nlohmann::json::parse(paper.out), r = nlohmann::json::parse(rib.out);
  EXPECT_EQ(p["scene"]["seam_profile"]["rib_factor"], 1.0);
  EXPECT_EQ(r["scene"]["seam_profile"]["rib_factor"], 16.0);
  ASSERT_EQ(p["seeds"][0]["node_list"].size(), 4u);
  for (const auto& node : p["seeds"][0]["node_list"])
    EXPECT_GT(DegreesToSeamLines(node["angle_deg"].get<double>()), 30.0) << node.dump();
  ASSERT_EQ(r["seeds"].size(), 2u);
  for (const auto& seed : r["seeds"]) {
    ASSERT_EQ(seed["node_list"].size(), 4u) << seed["node_list"].dump();
    for (const auto& node : seed["node_list"])
      EXPECT_LT(DegreesToSeamLines(node["angle_deg"].get<double>()), 8.0) << node.dump();
  }
  // The rib stiffens: DC rises (measured 0.863 → 0.897).
  EXPECT_GT(r["drape_coefficient"].get<double>(), p["drape_coefficient"].get<double>());
}

TEST(CliDrape, RimBandIsMeshedReportedAndRecorded) {
  const auto dir = Scratch("CliDrape.Rim");
  const auto r = Textile("drape " + kFig8 + kCoarseMesh +
                         " --rim-mm 5 --rim-band-mm 20 --no-extrapolate -o " + (dir / "rim.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("(h = 15 mm, 5 mm to 20 mm past the rim)"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(ReadAll(dir / "rim.json"));
  EXPECT_EQ(j["scene"]["rim_mm"].get<double>(), 5.0);
  EXPECT_EQ(j["scene"]["rim_band_mm"].get<double>(), 20.0);
  EXPECT_NEAR(j["scene"]["rim_turn_down_mm"].get<double>(), 8.622, 1e-3);
  // 5 mm against ℓ = 8.6 mm: still a note, with a smaller shortfall (0.1 × 5 / 8.6), and now
  // pointing to a smaller rim element rather than to the band this run already has.
  EXPECT_NE(r.out.find("note: DC may be low by up to about 0.06"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("a smaller --rim-mm meshes it finer"), std::string::npos) << r.out;
  // The plain 15 mm disk has 442 vertices; the band triples that (1445 measured).
  EXPECT_GT(j["scene"]["vertices"].get<int>(), 1000);
  EXPECT_TRUE(j["converged"].get<bool>());
}

// --seam-refine-mm: the mesh refined near the seam lines only (Pabst 4.3), recorded in the scene;
// the DC moves little (docs/methods/drapemeter.md, "Seam refinement": at most 0.003 on the default mesh).
TEST(CliDrape, SeamRefinementMeshesTheSeamBandFinerAndKeepsTheDrape) {
  const auto dir = Scratch("CliDrape.SeamRefine");
  const std::string weft = "drape " + kFig8 + kCoarse + " --seams weft -o ";
  const auto plain = Textile(weft + (dir / "plain.json").string());
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const auto refined = Textile(weft + (dir / "refined.json").string() + " --seam-refine-mm 20");
  ASSERT_EQ(refined.exit_code, 0) << refined.err;
  EXPECT_NE(refined.out.find(" mm, refined within 20 mm of the seams)"), std::string::npos)
      << refined.out;
  EXPECT_EQ(plain.out.find("refined within"), std::string::npos) << plain.out;
  const auto p = nlohmann::json::parse(ReadAll(dir / "plain.json"));
  const auto r = nlohmann::json::parse(ReadAll(dir / "refined.json"));
  EXPECT_EQ(p["scene"]["seam_refine_mm"].get<double>(), 0.0);
  EXPECT_EQ(r["scene"]["seam_refine_mm"].get<double>(), 20.0);
  // C-plain's ⌈S⌉ is 10 at the seam and 8 or more out to 20 mm: edges of about h/3 in a 40 mm
  // band across the 300 mm specimen, about a sixth of its area at eight or more times the
  // density (432 → 992 vertices measured).
  const int v0 = p["scene"]["vertices"].get<int>(), v1 = r["scene"]["vertices"].get<int>();
  EXPECT_GT(v1, 1.5 * v0) << v0 << " " << v1;
  EXPECT_LT(v1, 4 * v0) << v0 << " " << v1;
  EXPECT_TRUE(r["converged"].get<bool>());
  EXPECT_NEAR(r["drape_coefficient"].get<double>(), p["drape_coefficient"].get<double>(), 0.02);
  // Without seams there is nothing to refine near.
  const auto none = Textile("drape " + kFig8 + kCoarse + " --seam-refine-mm 20 -o " +
                            (dir / "none.json").string());
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_NE(none.err.find("--seam-refine-mm: needs --seams weft, weft+warp or shifted"),
            std::string::npos)
      << none.err;
  EXPECT_FALSE(fs::exists(dir / "none.json"));
}

// The default: the rim band (auto: ℓ/2 = 4.31 mm) split, a second solve, the DC extrapolated;
// both DCs and both solver reports in the JSON, no shortfall note.
TEST(CliDrape, ExtrapolateReportsBothDrapesAndTheExtrapolatedDc) {
  const auto dir = Scratch("CliDrape.Extrapolate");
  const auto r = Textile("drape " + kFig8 + kCoarseMesh + " -o " + (dir / "x.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("(h = 15 mm, 4.31 mm to 20 mm past the rim; "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("before the rim's split)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(": between the split rim's "), std::string::npos) << r.out;
  // The sample gives no compression ratio: its default is the one note.
  EXPECT_EQ(r.out.find("DC may be"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("stretch.compression_ratio not given"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(ReadAll(dir / "x.json"));
  EXPECT_TRUE(j["scene"]["extrapolate"].get<bool>());
  EXPECT_GT(j["scene"]["vertices"].get<int>(), 2 * j["scene"]["base_vertices"].get<int>());
  const auto& seed = j["seeds"][0];
  const double base = seed["base_drape_coefficient"].get<double>();
  const double split = seed["split_drape_coefficient"].get<double>();
  EXPECT_GT(split, base);
  EXPECT_NEAR(seed["extrapolation_bound"].get<double>(), 0.5 * (split - base), 1e-12);
  EXPECT_NEAR(seed["drape_coefficient"].get<double>(), 1.5 * split - 0.5 * base, 1e-12);
  EXPECT_NEAR(j["drape_coefficient"].get<double>(), 1.5 * split - 0.5 * base, 1e-12);
  EXPECT_TRUE(seed["split_solver"]["converged"].get<bool>());
  EXPECT_GT(seed["split_solver"]["iterations"].get<int>(), 0);
  ASSERT_TRUE(j["note"].is_string()) << j.dump();
  EXPECT_EQ(j["note"].get<std::string>().rfind("stretch.compression_ratio not given", 0), 0u)
      << j["note"];
  EXPECT_EQ(j["note"].get<std::string>().find("DC may be"), std::string::npos) << j["note"];
  EXPECT_NEAR(j["scene"]["rim_mm"].get<double>(), 8.622 / 2.0, 1e-3);
}

// `--rim-mm auto` is ℓ/2 when extrapolating (the default) and ℓ/3 with --no-extrapolate; the
// mesh is reported before the solve (capped runs: nothing is written).
TEST(CliDrape, AutoRimIsHalfTheTurnDownWhenExtrapolatingElseAThird) {
  const auto dir = Scratch("CliDrape.AutoRim");
  const auto capped = kFig8 + kCoarseMesh + " --max-seconds 0.001 --progress -o " + (dir / "r.json").string();
  const auto extrapolating = Textile("drape " + capped);
  const auto single = Textile("drape " + capped + " --no-extrapolate");
  const auto both = Textile("drape " + capped + " --extrapolate --no-extrapolate");
  EXPECT_EQ(extrapolating.exit_code, 3) << extrapolating.err;
  EXPECT_EQ(single.exit_code, 3) << single.err;
  EXPECT_EQ(both.exit_code, 2) << both.err;
  EXPECT_NE(extrapolating.err.find("; split at the rim: "), std::string::npos) << extrapolating.err;
  EXPECT_EQ(single.err.find("split at the rim"), std::string::npos) << single.err;
  // ℓ/3 along the rim has about (3/2)² the rim's vertices of ℓ/2.
  EXPECT_GT(MeshVertices(single.err), MeshVertices(extrapolating.err) * 5 / 4) << single.err << extrapolating.err;
  // A band narrower than ℓ/2 cannot be split: one solve with ℓ/3, as with --no-extrapolate.
  const auto narrow = Textile("drape " + capped + " --rim-band-mm 3");
  const auto narrow_single = Textile("drape " + capped + " --rim-band-mm 3 --no-extrapolate");
  EXPECT_EQ(narrow.exit_code, 3) << narrow.err;
  EXPECT_EQ(narrow.err.find("split at the rim"), std::string::npos) << narrow.err;
  EXPECT_EQ(MeshVertices(narrow.err), MeshVertices(narrow_single.err)) << narrow.err << narrow_single.err;
  EXPECT_FALSE(fs::exists(dir / "r.json"));
}

TEST(CliDrape, CoarseRimGetsANoteAndAutoMeshesItFiner) {
  const auto dir = Scratch("CliDrape.RimNote");
  const auto plain = Textile("drape " + kFig8 + kCoarse + " -o " + (dir / "plain.json").string());
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const std::string note =
      "note: DC may be low by up to about 0.2: the rim's elements (15 mm) are coarse against this "
      "fabric's turn-down length there (8.6 mm)";
  EXPECT_NE(plain.out.find(note), std::string::npos) << plain.out;
  // Without a band it points to auto (with one, to a smaller --rim-mm: the test above).
  EXPECT_NE(plain.out.find("--rim-mm auto meshes it finer"), std::string::npos) << plain.out;
  const auto j = nlohmann::json::parse(ReadAll(dir / "plain.json"));
  EXPECT_EQ(j["note"].get<std::string>().rfind(note.substr(6), 0), 0u) << j["note"];
  // No --rim-mm: the default, auto, ℓ/3 = 2.9 mm along the rim, several times the plain 15 mm
  // disk's 442 vertices (a capped run: the mesh is reported before the solve).
  const auto autorim = Textile("drape " + kFig8 + kCoarseMesh + " --max-seconds 0.001 --progress -o " +
                               (dir / "auto.json").string());
  EXPECT_EQ(autorim.exit_code, 3) << autorim.err;
  EXPECT_GT(MeshVertices(autorim.err), 4 * 442) << autorim.err;
  EXPECT_FALSE(fs::exists(dir / "auto.json"));
}

TEST(CliDrape, NonConvergenceIsExit3WithOneLineAndNoFiles) {
  const auto dir = Scratch("CliDrape.NoConv");
  const auto r = Textile("drape " + kFig8 + kCoarse + " --max-seconds 0.001 -o " + (dir / "r.json").string() +
                         " --png " + (dir / "r.png").string() + " --obj " + (dir / "r.obj").string() + " --ply " +
                         (dir / "r.ply").string());
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(LastError(r.err).find("not converged"), std::string::npos) << r.err;
  EXPECT_EQ(testing::CountLines(r.err), 1) << r.err;  // no progress lines without --progress
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_TRUE(fs::is_empty(dir)) << "a failed run left a file";
  // The same when a cascade's coarse level stops short ahead of the (default) rim split.
  const auto c = Textile("drape " + kFig8 + " --coarse-to-fine --max-seconds 0.01 --progress -o " +
                         (dir / "c.json").string());
  EXPECT_EQ(c.exit_code, 3) << c.err;
  EXPECT_NE(c.err.find("split at the rim"), std::string::npos) << c.err;
  EXPECT_NE(LastError(c.err).find("not converged (seed 1: coarse level: time cap"), std::string::npos)
      << c.err;
  EXPECT_FALSE(fs::exists(dir / "c.json"));
}

// The resting mount settles with the samples' friction (contact.h, friction_potential); a run
// cut short is not converged (exit 3) and writes nothing; `--rim-mm auto` gives it a rim band
// (more vertices than --rim-mm 0), not the extrapolation (no split reported).
// A heavy, stretchy fabric resting on the disk passes through it on a coarse mesh (contact
// holds the nodes only) and leaves part of its top bare: the support's own shadow keeps the DC
// at or above 0 (it was -0.05), and the run warns not to trust it.
TEST(CliDrape, AFabricThroughTheSupportGetsAWarningAndNoNegativeDc) {
  const auto dir = Scratch("CliDrape.Through");
  const auto r = Textile("drape --material tests/bad_inputs/files/material-heavy-stretchy.json" + kCoarse +
                         " --mount resting -o " + (dir / "r.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(ReadAll(dir / "r.json"));
  EXPECT_GE(j["drape_coefficient"].get<double>(), -1e-3);
  EXPECT_GE(j["min_radius_mm"].get<double>(), 90.0 - 1.0);
  ASSERT_TRUE(j["note"].is_string()) << j.dump();
  EXPECT_NE(j["note"].get<std::string>().find("of the support's top bare"), std::string::npos) << j["note"];
  EXPECT_NE(r.out.find("before trusting this DC"), std::string::npos) << r.out;
  // The sample fabric on the same mount and mesh covers the disk's top: no such warning.
  const auto plain = Textile("drape " + kFig8 + kCoarse + " --mount resting -o " + (dir / "p.json").string());
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(plain.out.find("of the support's top bare"), std::string::npos) << plain.out;
}

// The resting contact's penalty lets the skirt sink into the disk's side under the rim's load:
// past 0.3 mm the run says how deep and what that cost on the default mesh; a stiffer contact
// (--contact-sink-mm) sinks it less, and says nothing (docs/methods/drapemeter.md, "Contact stiffness").
// Measured on this mesh, seed 1: 0.57 mm at the default 0.01 (DC 0.517), 0.11 mm at 0.001 (0.544).
TEST(CliDrape, ASkirtSunkIntoTheSupportGetsANoteAndAStifferContactSinksItLess) {
  const auto dir = Scratch("CliDrape.Sink");
  // 0.001 cycles at 15 mm (docs); soft in compression (the default) it cycles here too: the
  // figures are those of the membrane as stiff in compression as in tension.
  const std::string mesh = " --resolution-mm 12 --rim-mm 0 --compression-ratio 1";
  const auto soft =
      Textile("drape " + kFig8 + mesh + " --mount resting -o " + (dir / "s.json").string());
  ASSERT_EQ(soft.exit_code, 0) << soft.err;
  EXPECT_NE(soft.out.find("note: the skirt sank up to 0."), std::string::npos) << soft.out;
  EXPECT_NE(soft.out.find("(--contact-sink-mm 0.01)"), std::string::npos) << soft.out;
  const auto s = nlohmann::json::parse(ReadAll(dir / "s.json"));
  EXPECT_EQ(s["scene"]["contact_sink_mm"].get<double>(), 0.01);
  const double soft_depth = s["seeds"][0]["max_penetration_mm"].get<double>();
  EXPECT_GT(soft_depth, 0.2);
  const auto stiff =
      Textile("drape " + kFig8 + mesh + " --mount resting --contact-sink-mm 0.001 -o " +
              (dir / "t.json").string());
  ASSERT_EQ(stiff.exit_code, 0) << stiff.err;
  EXPECT_EQ(stiff.out.find("the skirt sank"), std::string::npos) << stiff.out;
  const auto t = nlohmann::json::parse(ReadAll(dir / "t.json"));
  EXPECT_LT(t["seeds"][0]["max_penetration_mm"].get<double>(), 0.5 * soft_depth);
  // Clamped: no support, no such figure.
  const auto clamped = Textile("drape " + kFig8 + kCoarse + " -o " + (dir / "c.json").string());
  ASSERT_EQ(clamped.exit_code, 0) << clamped.err;
  const auto c = nlohmann::json::parse(ReadAll(dir / "c.json"));
  EXPECT_TRUE(c["scene"]["contact_sink_mm"].is_null());
  EXPECT_FALSE(c["seeds"][0].contains("max_penetration_mm"));
}

// --compression-ratio overrides the material's stretch.compression_ratio: the report names
// it and the result's material carries it. The sample gives none, so it drapes on the default
// 0.01 (soft in compression, said on the first line); at 1, as stiff in compression as in
// tension, the skirt stands out further (docs/methods/drapemeter.md, "Compression").
TEST(CliDrape, CompressionRatioOverridesTheMaterialsAndIsReported) {
  const auto dir = Scratch("CliDrape.Compression");
  const auto plain = Textile("drape " + kFig8 + kCoarse + " -o " + (dir / "p.json").string());
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_NE(plain.out.find("; membrane soft in compression (ratio 0.01)"), std::string::npos)
      << plain.out;
  const auto p = nlohmann::json::parse(ReadAll(dir / "p.json"));
  EXPECT_FALSE(p["material"]["stretch"].contains("compression_ratio"));
  EXPECT_EQ(p["scene"]["compression_ratio"].get<double>(), 0.01);
  EXPECT_EQ(p["scene"]["compression_ratio_from"], "material");
  const auto stiff = Textile("drape " + kFig8 + kCoarse + " --compression-ratio 1 -o " +
                             (dir / "s.json").string());
  ASSERT_EQ(stiff.exit_code, 0) << stiff.err;
  EXPECT_EQ(stiff.out.find("soft in compression"), std::string::npos) << stiff.out;
  const auto s = nlohmann::json::parse(ReadAll(dir / "s.json"));
  EXPECT_EQ(s["material"]["stretch"]["compression_ratio"].get<double>(), 1.0);
  EXPECT_EQ(s["scene"]["compression_ratio"].get<double>(), 1.0);
  EXPECT_EQ(s["scene"]["compression_ratio_from"], "--compression-ratio");
  EXPECT_GT(s["drape_coefficient"].get<double>(), p["drape_coefficient"].get<double>() + 0.08);
}

// --cache keeps a drape with its sensitivities; --what-if then predicts a nearby material's DC
// from it without a drape (no outline), and solves, caching it, when the edit is too far.
TEST(CliDrape, WhatIfPredictsFromTheCacheAndSolvesWhenTooFar) {
  const auto dir = Scratch("CliDrape.WhatIf");
  const std::string cache = " --cache " + (dir / "cache").string();
  const auto base = Textile("drape " + kFig8 + kCoarse + cache + " -o " + (dir / "b.json").string());
  ASSERT_EQ(base.exit_code, 0) << base.err;
  const auto b = nlohmann::json::parse(ReadAll(dir / "b.json"));
  EXPECT_FALSE(b["sensitivities"].empty());  // implied by --cache
  const auto near = Textile("drape " + kFig8 + kCoarse + cache + " --what-if b1=0.102 -o " +
                            (dir / "n.json").string());
  ASSERT_EQ(near.exit_code, 0) << near.err;
  EXPECT_NE(near.out.find("what-if b1=0.102: DC"), std::string::npos) << near.out;
  const auto n = nlohmann::json::parse(ReadAll(dir / "n.json"));
  EXPECT_TRUE(n["what_if"]["predicted"].get<bool>());
  EXPECT_EQ(n["what_if"]["entries_used"], 1);
  const double db1 = 0.002 / 0.1;  // b1's relative change
  double d_ln_b1 = 0.0;
  for (const auto& row : b["sensitivities"])
    if (row["parameter"] == "b1") d_ln_b1 = row["d_dc_d_ln_p"].get<double>();
  EXPECT_NEAR(n["drape_coefficient"].get<double>(),
              b["drape_coefficient"].get<double>() + d_ln_b1 * db1, 1e-6);
  EXPECT_FALSE(fs::exists(dir / "n.outline.csv"));
  // 30 % away: beyond the reach, so solved and cached.
  const auto far = Textile("drape " + kFig8 + kCoarse + cache + " --what-if b1=0.13 -o " +
                           (dir / "f.json").string());
  ASSERT_EQ(far.exit_code, 0) << far.err;
  EXPECT_NE(far.out.find("what-if b1=0.13: solved, the nearest of 1 cached drapes"), std::string::npos)
      << far.out;
  const auto f = nlohmann::json::parse(ReadAll(dir / "f.json"));
  EXPECT_FALSE(f["what_if"]["predicted"].get<bool>());
  EXPECT_NE(f["what_if"]["reason"].get<std::string>().find("beyond the reach"), std::string::npos);
  EXPECT_GT(f["drape_coefficient"].get<double>(), b["drape_coefficient"].get<double>());
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir / "cache")) entries += e.path().extension() == ".json";
  EXPECT_EQ(entries, 2);
}

// --sensitivity adds the DC's σ (null without a fit covariance, with the reason) and the
// influence table, largest change first, to drape.json and the text; the unmeasured membrane
// default (compression ratio) leads for the Fig. 8 file.
TEST(CliDrape, SensitivityReportsTheInfluenceTableAndSigma) {
  const auto dir = Scratch("CliDrape.Sensitivity");
  const auto r = Textile("drape " + kFig8 + kCoarse + " --sensitivity -o " +
                         (dir / "s.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("DC sigma: none"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("influence (dDC/dln p"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(ReadAll(dir / "s.json"));
  EXPECT_TRUE(j["drape_coefficient_sigma"].is_null());
  EXPECT_NE(j["drape_coefficient_sigma_note"].get<std::string>().find("no fit covariance"),
            std::string::npos);
  const auto& table = j["sensitivities"];
  ASSERT_EQ(table.size(), 8u);  // b1 b2 c1 beta density, stiffness poisson compression_ratio
  EXPECT_EQ(table[0]["parameter"], "stretch.compression_ratio");
  EXPECT_TRUE(table[0]["defaulted"].get<bool>());
  for (size_t k = 1; k < table.size(); ++k)
    EXPECT_GE(table[k - 1]["dc_change"].get<double>(), table[k]["dc_change"].get<double>());
  for (const auto& row : table) {
    if (row["parameter"] == "b1") {
      EXPECT_GT(row["d_dc_d_ln_p"].get<double>(), 0.0);
    }
  }
  // The scene's radii, apart from the σ, in mm.
  const auto& scene = j["scene_sensitivities"];
  ASSERT_EQ(scene.size(), 2u);
  EXPECT_EQ(scene[0]["parameter"], "specimen_radius");
  EXPECT_EQ(scene[0]["unit"], "mm");
  EXPECT_LT(scene[0]["d_dc_d_ln_p"].get<double>(), 0.0);
  EXPECT_EQ(scene[1]["parameter"], "support_radius");
  EXPECT_NE(r.out.find("scene (not in the sigma):"), std::string::npos) << r.out;
  EXPECT_TRUE(j["seam_sensitivities"].is_null());  // no seams
  // Without the flag the result has none of it.
  const auto plain = Textile("drape " + kFig8 + kCoarse + " -o " + (dir / "p.json").string());
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_FALSE(nlohmann::json::parse(ReadAll(dir / "p.json")).contains("sensitivities"));
}

// --start-modes widens the start perturbation's band of harmonics; the result records it, and a
// different start on the same fabric is a different first seed's drape (docs/methods/drapemeter.md,
// "Nodes").
TEST(CliDrape, StartModesAreTheStartsHarmonicsAndAreRecorded) {
  const auto dir = Scratch("CliDrape.StartModes");
  const auto r = Textile("drape " + kFig8 + kCoarse + " --start-modes 2-12 -o " +
                         (dir / "w.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(ReadAll(dir / "w.json"));
  EXPECT_EQ(j["scene"]["start_modes"], nlohmann::json::parse("[2, 12]"));
  EXPECT_GT(j["drape_coefficient"].get<double>(), 0.0);
  EXPECT_LT(j["drape_coefficient"].get<double>(), 1.0);
}

TEST(CliDrape, RestingMountSettlesAndACutShortRunFailsCleanly) {
  const auto dir = Scratch("CliDrape.Resting");
  const auto r = Textile("drape " + kFig8 + kCoarse + " --mount resting --progress -o " +
                         (dir / "r.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("experimental"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("experimental"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(ReadAll(dir / "r.json"));
  EXPECT_EQ(j["scene"]["mount"], "resting");
  EXPECT_TRUE(j["converged"].get<bool>());
  EXPECT_GT(j["drape_coefficient"].get<double>(), 0.0);
  EXPECT_LT(j["drape_coefficient"].get<double>(), 1.0);
  EXPECT_GT(j["seeds"][0]["solver"]["contacts"].get<int>(), 0) << j["seeds"][0]["solver"].dump();
  const auto cut = Textile("drape " + kFig8 + kCoarse + " --mount resting --max-seconds 0.001 --progress -o " +
                           (dir / "cut.json").string());
  EXPECT_EQ(cut.exit_code, 3) << cut.err;
  EXPECT_NE(LastError(cut.err).find("not converged"), std::string::npos) << cut.err;
  EXPECT_FALSE(fs::exists(dir / "cut.json"));
  const auto vertices = [](const std::string& err) {
    const size_t at = err.find("drape: mesh: ");
    return at == std::string::npos ? -1 : std::stoi(err.substr(at + 13));
  };
  const auto banded = Textile("drape " + kFig8 + kCoarseMesh + " --mount resting --max-seconds 0.001 --progress -o " +
                              (dir / "band.json").string());
  EXPECT_EQ(banded.exit_code, 3) << banded.err;
  EXPECT_GT(vertices(banded.err), vertices(cut.err)) << banded.err << cut.err;
  EXPECT_EQ(banded.err.find("split at the rim"), std::string::npos) << banded.err;
}

// Gmsh is loaded when a mesh is needed, not at start-up (libsim/src/mesh/gmsh_api.h): without it a
// drape fails with one clear line and no files, and a command that meshes nothing still runs.
TEST(CliDrape, WithoutGmshIsExit3WithOneLineAndNoFiles) {
  const auto dir = Scratch("CliDrape.NoGmsh");
  const std::string missing = "TEXTILE_GMSH=/nonexistent/libgmsh.so.4.8";
  const auto r = Textile("drape " + kFig8 + kCoarse + " -o " + (dir / "r.json").string(), missing);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_EQ(testing::CountLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("cannot load Gmsh (tried /nonexistent/libgmsh.so.4.8)"), std::string::npos)
      << r.err;
  EXPECT_TRUE(fs::is_empty(dir));
  const auto law = Textile("law " + kFig8, missing);
  EXPECT_EQ(law.exit_code, 0) << law.err;
}

TEST(CliDrape, RefusesBadInput) {
  const auto dir = Scratch("CliDrape.Bad");
  const std::string o = " -o " + (dir / "r.json").string();
  ExpectRefused(Textile("drape " + kFig8 + " --specimen-mm 90" + o), "--specimen-mm", "specimen = support");
  ExpectRefused(Textile("drape " + kFig8 + " --specimen-mm 80" + o), "larger than the support", "small specimen");
  ExpectRefused(Textile("drape " + kFig8 + " --seams diagonal" + o), "--seams", "bad seams");
  ExpectRefused(Textile("drape " + kFig8 + " --mount glued" + o), "--mount", "bad mount");
  ExpectRefused(Textile("drape " + kFig8 + " --seams weft --seam-type Z-plain" + o), "--seam-type", "bad type");
  ExpectRefused(Textile("drape " + kFig8 + " --seam-type C-plain" + o), "--seams", "type without seams");
  ExpectRefused(Textile("drape " + kFig8 + " --seams weft --seam-file nope.json" + o), "nope.json", "missing file");
  ExpectRefused(Textile("drape " + kFig8 + " --seeds 0" + o), "--seeds", "no seeds");
  ExpectRefused(Textile("drape " + kFig8 + " --resolution-mm 0" + o), "--resolution-mm", "zero size");
  ExpectRefused(Textile("drape --material nope.json" + o), "nope.json", "missing material");
  ExpectRefused(Textile("drape " + kFig8 + " -o /nonexistent/dir/r.json"), "/nonexistent/dir", "bad output");
  EXPECT_FALSE(fs::exists(dir / "r.json"));
}


// A MEASURED.json made from a drape's own JSON (drape.json, its first seed) and outline CSV:
// the outline turned clockwise by `turn_bins` 1° bins, the DC moved by `dc_shift`.
std::string MeasuredFrom(const nlohmann::json& drape, const std::string& outline_csv, int turn_bins,
                         double dc_shift, double specimen_mm = 150.0) {
  std::vector<double> r_mm;
  std::istringstream in(outline_csv);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    const auto comma = line.find(',');
    r_mm.push_back(std::stod(line.substr(comma + 1)));
  }
  const int bins = static_cast<int>(r_mm.size());
  MeasuredDrape m;
  m.source = "made by the test";
  m.input_kind = "mesh";
  m.specimen_radius = specimen_mm * 1e-3;
  m.support_radius = 0.09;
  m.drape_coefficient = drape["drape_coefficient"].get<double>() + dc_shift;
  m.shadow.angles.resize(bins);
  m.shadow.radii.resize(bins);
  for (int b = 0; b < bins; ++b) {
    m.shadow.angles(b) = (b + 0.5) * 2.0 * M_PI / bins;
    m.shadow.radii(b) = 1e-3 * r_mm[(b + turn_bins) % bins];  // r_m(θ) = r_s(θ + turn)
  }
  for (const auto& node : drape["seeds"][0]["node_list"]) {
    m.nodes.angles.push_back(node["angle_deg"].get<double>() * M_PI / 180.0);
    m.nodes.radii.push_back(node["radius_mm"].get<double>() * 1e-3);
    m.nodes.prominences.push_back(node["prominence_mm"].get<double>() * 1e-3);
  }
  m.min_radius = m.shadow.radii.minCoeff();
  m.max_radius = m.shadow.radii.maxCoeff();
  m.mean_radius = m.shadow.radii.mean();
  return MeasuredDrapeJson(m);
}

void WriteFile(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

TEST(CliDrape, CompareWithAMeasuredDrapeReportsAVerdict) {
  // The measured drape is this very simulation's, turned by 40° and 0.01 stiffer: the best
  // rotation undoes the turn exactly (whole bins), the outline RMS is the CSV's round-off, the
  // DCs are 0.01 apart, the nodes equal: pass. (Coarse and one seed: the same drape each run.)
  const auto dir = Scratch("CliDrape.Compare");
  const auto base = Textile("drape " + kFig8 + kCoarse + " -o " + (dir / "self.json").string());
  ASSERT_EQ(base.exit_code, 0) << base.err;
  const auto self = nlohmann::json::parse(ReadAll(dir / "self.json"));
  const std::string csv = ReadAll(dir / "self.outline.csv");
  WriteFile(dir / "measured.json", MeasuredFrom(self, csv, 40, 0.01));
  const auto r = Textile("drape " + kFig8 + kCoarse + " --compare " + (dir / "measured.json").string() +
                         " -o " + (dir / "drape.json").string() + " --png " + (dir / "drape.png").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(ReadAll(dir / "drape.json"));
  ASSERT_TRUE(j.contains("comparison")) << j.dump(2);
  const auto& c = j["comparison"];
  EXPECT_EQ(c["measured_file"], (dir / "measured.json").string());
  EXPECT_EQ(c["measured_source"], "made by the test");
  EXPECT_EQ(c["simulated_dc"], self["drape_coefficient"]);
  EXPECT_NEAR(c["measured_dc"].get<double>(), self["drape_coefficient"].get<double>() + 0.01, 1e-12);
  EXPECT_NEAR(c["dc_difference"].get<double>(), -0.01, 1e-9);
  EXPECT_EQ(c["dc_tol"].get<double>(), 0.03);
  EXPECT_TRUE(c["dc_ok"].get<bool>());
  EXPECT_EQ(c["measured_nodes"].get<int>(), self["seeds"][0]["nodes"].get<int>());
  EXPECT_TRUE(c["nodes_ok"].get<bool>());
  EXPECT_NEAR(c["best_rotation_deg"].get<double>(), 40.0, 1e-6);
  EXPECT_LT(c["outline_rms_mm"].get<double>(), 1e-6);
  EXPECT_GT(c["outline_rms_unrotated_mm"].get<double>(), 1.0);
  EXPECT_TRUE(c["outline_tol_mm"].is_null());
  EXPECT_TRUE(c["outline_ok"].is_null());
  // The same shadows over π R² (a 15 mm mesh's polygon: ~0.002 lower).
  EXPECT_LT(c["simulated_dc_pi_r2"].get<double>(), c["simulated_dc"].get<double>());
  EXPECT_GT(c["simulated_dc_pi_r2"].get<double>(), c["simulated_dc"].get<double>() - 0.004);
  EXPECT_EQ(c["verdict"], "pass");
  ASSERT_EQ(c["seeds"].size(), 1u);
  EXPECT_EQ(c["notes"][0]["code"], "single_seed");
  EXPECT_NE(r.out.find("compared with: " + (dir / "measured.json").string() + " (measured from made by the test)\n"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  verdict: pass\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("after turning the measured one by 40°"), std::string::npos) << r.out;
  EXPECT_GT(fs::file_size(dir / "drape.png"), 5000u);

  // 0.05 stiffer, and the outline judged: a failed verdict is a result (exit 0) with its notes...
  WriteFile(dir / "stiff.json", MeasuredFrom(self, csv, 0, 0.05));
  const auto fail = Textile("drape " + kFig8 + kCoarse + " --compare " + (dir / "stiff.json").string() +
                            " --outline-tol-mm 2 --dc-tol 0.04 -o " + (dir / "fail.json").string() + " --json");
  ASSERT_EQ(fail.exit_code, 0) << fail.err;
  const auto f = nlohmann::json::parse(fail.out)["comparison"];
  EXPECT_EQ(f["verdict"], "fail");
  EXPECT_FALSE(f["dc_ok"].get<bool>());
  EXPECT_EQ(f["dc_tol"].get<double>(), 0.04);
  EXPECT_TRUE(f["outline_ok"].get<bool>());
  EXPECT_EQ(f["outline_tol_mm"].get<double>(), 2.0);
  EXPECT_EQ(f["notes"][0]["code"], "dc_differs");
  EXPECT_NE(f["notes"][0]["text"].get<std::string>().find("the simulation drapes more than measured"),
            std::string::npos) << f.dump(2);
  // ... and with --strict an error: exit 3, one line, nothing written.
  const auto strict = Textile("drape " + kFig8 + kCoarse + " --compare " + (dir / "stiff.json").string() +
                              " --strict -o " + (dir / "strict.json").string());
  EXPECT_EQ(strict.exit_code, 3) << strict.err;
  EXPECT_NE(LastError(strict.err).find("failed (--strict): the simulation drapes more than measured"),
            std::string::npos) << strict.err;
  EXPECT_EQ(strict.err.find("one seed"), std::string::npos) << strict.err;  // the failures only
  EXPECT_FALSE(fs::exists(dir / "strict.json"));
  EXPECT_FALSE(fs::exists(dir / "strict.outline.csv"));
}

TEST(CliDrape, CompareRefusesAnotherTestBeforeSimulating) {
  // A measured drape of a 140 mm specimen: refused with both radii, before the mesh is made.
  const auto dir = Scratch("CliDrape.CompareRadius");
  std::string csv = "theta_deg,r_mm,x_mm,y_mm\n";
  for (int b = 0; b < 360; ++b) csv += std::to_string(b + 0.5) + ",140,0,0\n";
  const auto drape = nlohmann::json::parse(R"({"drape_coefficient": 0.6, "seeds": [{"node_list": []}]})");
  WriteFile(dir / "other.json", MeasuredFrom(drape, csv, 0, 0.0, 160.0));
  const auto r = Textile("drape " + kFig8 + kCoarse + " --compare " + (dir / "other.json").string() +
                         " -o " + (dir / "d.json").string() + " --progress");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(LastError(r.err).find(": measured with a 160 mm specimen on a 90 mm support; the "
                                  "simulation's is 150 mm on 90 mm"),
            std::string::npos) << r.err;
  EXPECT_EQ(MeshVertices(r.err), 0) << r.err;  // no work done
  EXPECT_FALSE(fs::exists(dir / "d.json"));
}

}  // namespace
}  // namespace textile
