// `textile acpm` through the real executable.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "run_cli.h"
#include "textile/sim/law/bending_law.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

using testing::ExpectRefused;
using testing::ReadAll;
using testing::Scratch;
using testing::Textile;
namespace fs = std::filesystem;

const std::string kFig8 = "--material samples/materials/pabst-fig8.json";

TEST(CliAcpm, PlainSamplePrintsTheRayTableAndWritesJsonAndPng) {
  const auto dir = Scratch("CliAcpm.Plain");
  const auto r = Textile("acpm " + kFig8 + " -o " + (dir / "r.json").string() + " --png " +
                         (dir / "front.png").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("model: elastica (auto: nothing varies across the width"), std::string::npos)
      << r.out;
  // docs/spec/cantilever.md: Fig. 8 at 200 g/m² crosses at 33.5864 mm; ray 17 at z = 195 mm.
  EXPECT_NE(r.out.find(" 17   195.00        -    33.5864"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(ReadAll(dir / "r.json"));
  EXPECT_EQ(j["model"], "elastica");
  ASSERT_EQ(j["rays"].size(), 17u);
  for (const auto& ray : j["rays"]) {
    EXPECT_NEAR(ray["overhang_mm"].get<double>(), 33.5864, 1e-4);
    EXPECT_NEAR(ray["bending_length_mm"].get<double>(), 16.7932, 1e-4);
    EXPECT_NEAR(ray["rigidity_uNm"].get<double>(), 9.28863, 1e-5);
    EXPECT_TRUE(ray["d_mm"].is_null());
    EXPECT_EQ(ray["factor"].get<double>(), 1.0);
  }
  EXPECT_NEAR(j["device_time_s"].get<double>(), 33.5864 / 2.0, 1e-4);
  EXPECT_EQ(j["side_profile"]["x_mm"].size(), 201u);
  EXPECT_GT(fs::file_size(dir / "front.png"), 10000u);
}

// A material whose law is the Fig. 8 law sampled as a spline (41 knots, 0 .. 4 /cm) crosses
// where the law does: 33.5864 mm (the 41-knot spline moves L* by 1e-6 relative,
// cantilever_outputs_test.cc), the rays' table unchanged to its printed digits.
// --sensitivity: the crossing length's σ (null without a fit covariance) and influence table in
// acpm.json (mm) and the text; the dress fabric's linear law moves with b2 alone, L/3 per ln.
TEST(CliAcpm, SensitivityReportsTheLengthsInfluenceTable) {
  const auto dir = Scratch("CliAcpm.Sensitivity");
  const auto r = Textile("acpm --material samples/materials/pabst-dress.json --sensitivity -o " +
                         (dir / "r.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("L sigma: none"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(ReadAll(dir / "r.json"));
  EXPECT_TRUE(j["crossing_length_sigma_mm"].is_null());
  const auto& table = j["sensitivities"];
  ASSERT_EQ(table.size(), 3u);
  const double length = j["plain"]["overhang_mm"].get<double>();
  for (const auto& row : table) {
    if (row["parameter"] == "b2") {
      EXPECT_NEAR(row["d_length_mm_d_ln_p"].get<double>(), length / 3.0, 1e-4 * length);
      EXPECT_NEAR(row["length_change_mm"].get<double>(), 0.1 * length / 3.0, 1e-4 * length);
    }
  }
  EXPECT_EQ(j["scene_sensitivities"].size(), 1u);  // the barrier's angle
  EXPECT_TRUE(j["seam_sensitivities"].is_null());  // no seam
  const auto plain = Textile("acpm " + kFig8 + " -o " + (dir / "p.json").string());
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_FALSE(nlohmann::json::parse(ReadAll(dir / "p.json")).contains("sensitivities"));
  // A seam across: its position and coefficients too, apart from the σ, in the text and the
  // JSON; a stiffer seam holds the strip out further.
  const auto seam = Textile(
      "acpm " + kFig8 + " --seam C-plain --seam-dir across --seam-at 20 --sensitivity -o " +
      (dir / "s.json").string());
  ASSERT_EQ(seam.exit_code, 0) << seam.err;
  EXPECT_NE(seam.out.find("scene (not in the sigma):\n  barrier_angle = 41.5 deg: "),
            std::string::npos) << seam.out;
  EXPECT_NE(seam.out.find("seam (not in the sigma):"), std::string::npos) << seam.out;
  const auto s = nlohmann::json::parse(ReadAll(dir / "s.json"));
  ASSERT_EQ(s["scene_sensitivities"].size(), 2u);
  EXPECT_EQ(s["scene_sensitivities"][1]["parameter"], "seam_position");
  EXPECT_EQ(s["scene_sensitivities"][1]["unit"], "mm");
  ASSERT_EQ(s["seam_sensitivities"].size(), 4u);
  EXPECT_GT(s["seam_sensitivities"][3]["d_length_mm_d_ln_p"].get<double>(), 0.0);
}

// --monte-carlo N: the sampled σ beside the linear one in acpm.json and the text, the same draws
// for the same seed; it implies --sensitivity.
TEST(CliAcpm, MonteCarloPutsTheSampledSigmaBesideTheLinearOne) {
  const auto dir = Scratch("CliAcpm.MonteCarlo");
  const std::string run = "acpm --material tests/data/sensitivity/fig8-fitted.json --rays 1 "
                          "--monte-carlo 50 -o ";
  const auto r = Textile(run + (dir / "a.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("L Monte Carlo: sigma"), std::string::npos) << r.out;
  const auto a = nlohmann::json::parse(ReadAll(dir / "a.json"));
  ASSERT_TRUE(a.contains("monte_carlo")) << a.dump();
  const auto& mc = a["monte_carlo"];
  EXPECT_EQ(mc["samples"], 50);
  EXPECT_EQ(mc["unit"], "mm");
  EXPECT_NEAR(mc["linear_sigma"].get<double>(), a["crossing_length_sigma_mm"].get<double>(), 1e-12);
  EXPECT_GT(mc["sigma"].get<double>(), 0.0);
  EXPECT_FALSE(a["sensitivities"].empty());
  const auto again = Textile(run + (dir / "b.json").string());
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(nlohmann::json::parse(ReadAll(dir / "b.json"))["monte_carlo"]["sigma"], mc["sigma"]);
}

TEST(CliAcpm, SplineMaterialCrossesWhereItsPabstLawDoes) {
  const auto dir = Scratch("CliAcpm.Spline");
  const BendingLaw fig8 = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  nlohmann::json kappa = nlohmann::json::array(), moment = nlohmann::json::array();
  for (int i = 0; i <= 40; ++i) {
    kappa.push_back(0.1 * i);
    moment.push_back(units::SiMomentToKes(fig8.Moment(units::KesCurvatureToSi(0.1 * i))));
  }
  const nlohmann::json material = {
      {"name", "Fig. 8 as a spline"},
      {"areal_density_gsm", 200},
      {"bending", {{"law", "spline"}, {"units", "kes"}, {"kappa", kappa}, {"moment", moment}}}};
  std::ofstream(dir / "spline.json") << material.dump(2);
  const auto r = Textile("acpm --material " + (dir / "spline.json").string() + " -o " +
                         (dir / "r.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(" 17   195.00        -    33.5864"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(ReadAll(dir / "r.json"));
  EXPECT_EQ(j["material"]["law_kes"]["law"], "spline");
  EXPECT_EQ(j["material"]["law_kes"]["kappa"].size(), 41u);
  EXPECT_NEAR(j["plain"]["overhang_mm"].get<double>(), 33.5864, 33.5864 * 2e-6);
}

// Away from 41.5° the bending length is not L/2: the plain figures use the barrier's angle as
// the rays do (they printed L/2 whatever the angle: 7.56 mm against the rays' 17.0 at 5°).
TEST(CliAcpm, PlainFiguresFollowTheBarrierAngle) {
  const auto dir = Scratch("CliAcpm.Barrier");
  for (const char* angle : {"41.5", "5"}) {
    const auto r = Textile("acpm " + kFig8 + " --barrier-deg " + angle + " --rays 1 --json -o " +
                           (dir / "r.json").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    const double c = j["plain"]["bending_length_mm"].get<double>();
    const double ray_c = j["rays"][0]["bending_length_mm"].get<double>();
    EXPECT_NEAR(c, ray_c, 1e-9 * ray_c) << angle;
    EXPECT_NEAR(j["rays"][0]["factor"].get<double>(), 1.0, 1e-12) << angle;
    const double overhang = j["plain"]["overhang_mm"].get<double>();
    if (std::string(angle) == "5") {
      EXPECT_GT(c, overhang) << c;  // a 5° tilt is reached early: c is over twice L/2
    } else {
      EXPECT_NEAR(c, overhang / 2.0, 1e-3 * overhang);
    }
  }
}

TEST(CliAcpm, SeamAcrossIsAnsweredByTheElastica) {
  const auto dir = Scratch("CliAcpm.Across");
  const auto r = Textile("acpm " + kFig8 + " --seam C-plain --seam-dir across --seam-at 10 --json -o " +
                         (dir / "r.json").string() + " --png " + (dir / "p.png").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["model"], "elastica");
  EXPECT_EQ(j["seam"]["direction"], "across");
  EXPECT_EQ(j["seam"]["profile"]["type"], "C-plain");
  EXPECT_DOUBLE_EQ(j["rays"][0]["d_mm"].get<double>(), 10.0);
  EXPECT_GT(j["rays"][0]["factor"].get<double>(), 1.5);
  EXPECT_TRUE(fs::exists(dir / "p.png"));
}

TEST(CliAcpm, FittedSeamFileIsAccepted) {
  const auto dir = Scratch("CliAcpm.SeamFile");
  const auto r = Textile("acpm " + kFig8 + " --seam samples/seams/B-twill.json --seam-dir across --seam-at 50 -o " +
                         (dir / "r.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("seam: B-twill (3 layers) across"), std::string::npos) << r.out;
}

TEST(CliAcpm, ObjIsTheSampleAtTheCrossing) {
  // The elastica's profile swept across the 200 mm width: x from the edge to the front, y over
  // the width, z down to the tip (Fig. 8: L = 33.59 mm).
  const auto dir = Scratch("CliAcpm.Obj");
  const auto r = Textile("acpm " + kFig8 + " -o " + (dir / "r.json").string() + " --obj " +
                         (dir / "sample.obj").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("sample.obj"), std::string::npos) << r.out;
  std::ifstream obj(dir / "sample.obj");
  double min_z = 0.0, max_x = 0.0, max_y = 0.0;
  int vertices = 0, faces = 0;
  for (std::string line; std::getline(obj, line);) {
    if (line.rfind("v ", 0) == 0) {
      double x, y, z;
      ASSERT_EQ(std::sscanf(line.c_str(), "v %lf %lf %lf", &x, &y, &z), 3) << line;
      max_x = std::max(max_x, x);
      max_y = std::max(max_y, y);
      min_z = std::min(min_z, z);
      ++vertices;
    } else if (line.rfind("f ", 0) == 0) {
      ++faces;
    }
  }
  EXPECT_EQ(vertices, 201 * 11);
  EXPECT_EQ(faces, 2 * 200 * 10);
  EXPECT_NEAR(max_y, 0.2, 1e-12);
  EXPECT_GT(max_x, 0.01);
  EXPECT_LT(max_x, 0.0336);
  // The front is on the 41.5° barrier line through the edge: tip depth = tan(41.5°) x_tip.
  EXPECT_LT(min_z, -0.02);
}

TEST(CliAcpm, SeamAlongRunsOnTheShellModel) {
  const auto dir = Scratch("CliAcpm.Shell");
  const auto r = Textile("acpm " + kFig8 + " --seam C-plain --rays 3 --json -o " + (dir / "r.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["model"], "shell");
  ASSERT_EQ(j["rays"].size(), 3u);
  EXPECT_GT(j["rays"][1]["factor"].get<double>(), 1.5);
  EXPECT_TRUE(fs::exists(dir / "r.json"));
}

// The shell model bends a sheet with a membrane, so a run on it names the membrane's defaulted
// fields (the KES sample gives all but the in-plane compression), printed and in the result;
// the elastica has no membrane and says nothing of it.
TEST(CliAcpm, TheShellNamesTheMembranesDefaultsAndTheElasticaDoesNot) {
  const auto dir = Scratch("CliAcpm.MembraneDefaults");
  const auto shell = Textile("acpm --material samples/materials/pabst-fig8-kes.json --model shell -o " +
                             (dir / "s.json").string());
  ASSERT_EQ(shell.exit_code, 0) << shell.err;
  EXPECT_NE(shell.out.find("note: stretch.compression_ratio not given: 0.01"), std::string::npos)
      << shell.out;
  const auto s = nlohmann::json::parse(ReadAll(dir / "s.json"));
  ASSERT_TRUE(s.contains("membrane_defaults")) << s.dump();
  ASSERT_EQ(s["membrane_defaults"].size(), 1u);
  EXPECT_EQ(s["membrane_defaults"][0]["code"], "membrane_default");
  const auto elastica = Textile("acpm " + kFig8 + " -o " + (dir / "e.json").string());
  ASSERT_EQ(elastica.exit_code, 0) << elastica.err;
  EXPECT_EQ(elastica.out.find("not given"), std::string::npos) << elastica.out;
  EXPECT_FALSE(nlohmann::json::parse(ReadAll(dir / "e.json")).contains("membrane_defaults"));
}

TEST(CliAcpm, RefusesBadInput) {
  const auto dir = Scratch("CliAcpm.Bad");
  const std::string out = " -o " + (dir / "r.json").string();
  std::ofstream(dir / "stiff.json")
      << R"({"name": "board", "areal_density_gsm": 100, "bending": {"units": "kes", "b1": 50, "b2": 50, "c1": 0}})";
  ExpectRefused(Textile("acpm " + kFig8 + " --width-mm 250" + out), "wider than the ACPM200", "wide");
  ExpectRefused(Textile("acpm " + kFig8 + " --seam A-plain --seam-at 250" + out),
                "lies outside the 200 mm wide sample", "seam outside");
  ExpectRefused(Textile("acpm " + kFig8 + " --seam A-plain --seam-at -5" + out), "negative",
                "negative offset");
  ExpectRefused(Textile("acpm " + kFig8 + " --seam A-plain --seam-dir across --seam-at 400" + out),
                "outside the 300 mm long sample", "across outside");
  ExpectRefused(Textile("acpm " + kFig8 + " --seam A-plain --seam-dir across" + out), "required",
                "across without distance");
  ExpectRefused(Textile("acpm " + kFig8 + " --seam Z-plain" + out), "Z-plain", "unknown seam");
  ExpectRefused(Textile("acpm " + kFig8 + " --seam-at 10" + out), "--seam-at", "no seam");
  ExpectRefused(Textile("acpm " + kFig8 + " --model elastica --seam A-plain" + out),
                "cannot represent", "elastica along");
  ExpectRefused(Textile("acpm --material " + (dir / "stiff.json").string() + out),
                "does not reach the barrier within 300 mm", "too stiff");
  ExpectRefused(Textile("acpm --material nope.json" + out), "nope.json", "missing material");
  EXPECT_FALSE(fs::exists(dir / "r.json"));
}

TEST(CliAcpm, ResultFeedsFitSeam) {
  // Across seam: every ray has the same d, so fit-seam refuses it (no quadratic in d).
  const auto dir = Scratch("CliAcpm.FitSeam");
  ASSERT_EQ(Textile("acpm " + kFig8 + " --seam C-plain --seam-dir across --seam-at 10 -o " +
                    (dir / "r.json").string())
                .exit_code,
            0);
  ExpectRefused(Textile("fit-seam " + (dir / "r.json").string() + " -o " + (dir / "s.json").string()),
                "distinct distance", "across seam rays");
}

}  // namespace
}  // namespace textile
