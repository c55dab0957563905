#include "textile/sim/exchange/material_export.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdlib>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"
#include "textile/sim/elements/bending_element.h"
#include "textile/sim/elements/membrane.h"
#include "textile/sim/mesh/mesh.h"

namespace textile {
namespace {

const std::string kSamples = std::string(TEXTILE_SOURCE_DIR) + "/samples/";

// The paper's Fig. 8 law across the warp, the interlining's (stiffer) along it.
Material Anisotropic() {
  Material m = LawOnlyMaterial(BendingLaw::FromKes(0.5, 0.4, -0.02), 0.25);
  m.name = "anisotropic";
  m.bending_weft = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  m.beta = 1.5;
  return m;
}

// A material whose whole membrane was given: linear yarns, so the ARCSim form is exact at
// small strain.
Material MeasuredMembrane() {
  Material m = LawOnlyMaterial(BendingLaw::FromKes(0.1, 0.0892, -0.0092), 0.2);
  m.name = "measured membrane";
  m.orthotropic = OrthotropicMembrane{TensileCurve::Linear(3000.0), TensileCurve::Linear(1200.0), 50.0};
  m.defaulted = {"stretch.compression_ratio"};
  return m;
}

double Json(const std::string& text, const std::vector<int>& at) {
  nlohmann::json j = nlohmann::json::parse(text)["bending"];
  for (int i : at) j = j[i];
  return j.get<double>();
}

TEST(MaterialExport, FormatNamesAndTheirRefusal) {
  EXPECT_EQ(ParseExportFormat("arcsim"), ExportFormat::kArcsim);
  EXPECT_EQ(ParseExportFormat("u3m"), ExportFormat::kU3m);
  EXPECT_EQ(ParseExportFormat("csv"), ExportFormat::kCsv);
  try {
    ParseExportFormat("obj");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("arcsim, u3m or csv"), std::string::npos) << e.what();
  }
}

// ARCSim's bending force is ke θ: its table must hold M/κ, which is B(0) at rest.
TEST(MaterialExport, SecantStiffnessIsMomentOverCurvature) {
  const BendingLaw law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  EXPECT_DOUBLE_EQ(SecantStiffness(law, 0.0), law.b1());
  for (double k : {1.0, 20.0, 300.0}) EXPECT_DOUBLE_EQ(SecantStiffness(law, k) * k, law.Moment(k));
  // Softening: the secant lies between b2 and b1 and falls with κ.
  EXPECT_LT(SecantStiffness(law, 300.0), SecantStiffness(law, 20.0));
  EXPECT_GT(SecantStiffness(law, 300.0), law.b2());
}

// Row 0 serves hinges along the material u axis (the warp): bent across, along the weft.
TEST(MaterialExport, ArcsimRowsAreTheWeftTheBiasAndTheWarpWithBetaApplied) {
  const Material m = Anisotropic();
  const ExportedMaterial e = ExportMaterial(m, ExportFormat::kArcsim, {});
  const nlohmann::json j = nlohmann::json::parse(e.text);
  EXPECT_DOUBLE_EQ(j["density"].get<double>(), 0.25);
  ASSERT_EQ(j["bending"].size(), 3u);
  for (int c = 0; c < 5; ++c) {
    const double k = 2.0 * kArcsimBendingAlpha[c];
    const double warp = 4.0 * SecantStiffness(m.EffectiveLaw(), k);
    const double weft = 4.0 * SecantStiffness(m.EffectiveWeftLaw(), k);
    EXPECT_NEAR(Json(e.text, {0, c}), weft, 1e-12 * weft);
    EXPECT_NEAR(Json(e.text, {1, c}), 0.5 * (warp + weft), 1e-12 * warp);
    EXPECT_NEAR(Json(e.text, {2, c}), warp, 1e-12 * warp);
  }
  EXPECT_NEAR(Json(e.text, {2, 0}), 4.0 * 1.5 * units::KesStiffnessToSi(0.5), 1e-15);
  // The fork's keys: {b1, c1} with β; the bias their mean.
  EXPECT_NEAR(j["pcb_bending_warp"][0].get<double>(), 1.5 * units::KesStiffnessToSi(0.5), 1e-15);
  EXPECT_NEAR(j["pcb_bending_warp"][1].get<double>(), 1.5 * units::KesQuadraticToSi(-0.02), 1e-18);
  EXPECT_NEAR(j["pcb_bending_bias"][0].get<double>(),
              0.5 * (j["pcb_bending_warp"][0].get<double>() + j["pcb_bending_weft"][0].get<double>()),
              1e-18);
  // The membrane is the documented defaults: no stretching, and the note says so.
  EXPECT_FALSE(j.contains("stretching"));
  EXPECT_TRUE(HasNote(e.notes, "stretching_left_out"));
  ExportOptions strict;
  strict.strict = true;
  try {
    ExportMaterial(m, ExportFormat::kArcsim, strict);
    FAIL() << "--strict exported an unmeasured membrane";
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("stretch.warp, stretch.weft, stretch.shear"),
              std::string::npos)
        << err.what();
  }
}

// ARCSim's hinge (physics.cpp: energy ke l² θ² / (8 (A₀ + A₁)), moment ke κ / 4, dde.cpp's
// α = κ / 2) built from the exported table against the engine's Pabst hinge on one hinge: the
// same energy for a linear law, the same moment dE/dθ at each sampled curvature for a
// nonlinear one.
TEST(MaterialExport, ArcsimHingeFromTheTableBendsAsTheEnginesHinge) {
  Eigen::MatrixXd v(4, 3);
  v << 0.0, 0.0, 0.0, 0.004, -0.003, 0.0, 0.004, 0.003, 0.0, 0.008, 0.0, 0.0;  // a rhombus
  TriangleMesh rest;
  rest.vertices = v;
  rest.triangles.resize(2, 3);
  rest.triangles << 0, 1, 2, 1, 3, 2;
  const auto hinges = BuildHinges(rest);
  ASSERT_EQ(hinges.size(), 1u);
  const double l = (v.row(hinges[0].v[3]) - v.row(hinges[0].v[2])).norm();
  for (const BendingLaw& law : {BendingLaw::FromKes(0.1, 0.1, 0.0), BendingLaw::FromKes(0.1, 0.0892, -0.0092)}) {
    Material m = LawOnlyMaterial(law, 0.2);
    const nlohmann::json table = nlohmann::json::parse(ExportMaterial(m, ExportFormat::kArcsim, {}).text)["bending"];
    const BendingElements b(rest, hinges, law, std::nullopt, {.model = BendingModel::kPabst});
    const double a = b.area_weight(0), h = a / l;  // A₀ + A₁ = l h̄
    for (int c = 1; c < 5; ++c) {
      const double kappa = 2.0 * kArcsimBendingAlpha[c], theta = kappa * h;
      const double ke = table[2][c].get<double>();
      // dE/dθ: ARCSim's ke l² θ / (4 a); the engine's M(κ) a / h̄ = M(κ) l.
      EXPECT_NEAR(ke * l * l * theta / (4.0 * a), law.Moment(kappa) * l, 1e-12 * law.Moment(kappa) * l);
      if (law.kappa0() != 0.0) continue;
      // Energy, on the mesh: fold the kite by θ about its hinge.
      Vertices x = rest.vertices;
      const Eigen::Vector3d p0 = v.row(hinges[0].v[2]), axis = (v.row(hinges[0].v[3]) - v.row(hinges[0].v[2])).normalized();
      const int tip = hinges[0].v[1];
      const Eigen::Vector3d r = x.row(tip).transpose() - p0;
      x.row(tip) = (p0 + Eigen::AngleAxisd(theta, axis) * r).transpose();
      const double ours = b.HingeEnergy(x, 0);
      EXPECT_NEAR(ke * l * l * theta * theta / (8.0 * a), ours, 1e-6 * ours) << c;
    }
  }
}

TEST(MaterialExport, PcbBendingIsTheQuadraticBranchOrTheBestQuadraticOfASpline) {
  const BendingLaw law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  const QuadraticBending q = PcbBending(law);
  for (double k : {0.5, 10.0, 0.99 * law.kappa0()})
    EXPECT_NEAR(q.k1 * k + q.k2 * k * k, law.Moment(k), 1e-13 * law.Moment(k));
  EXPECT_EQ(q.kappa_fit, law.kappa0());
  const QuadraticBending linear = PcbBending(BendingLaw::FromKes(0.1, 0.1, -0.01));  // κ0 = 0
  EXPECT_DOUBLE_EQ(linear.k1, units::KesStiffnessToSi(0.1));
  EXPECT_EQ(linear.k2, 0.0);
  EXPECT_TRUE(std::isinf(linear.kappa_fit));
  // A spline: the error reported is the largest on a finer sampling, within a hair.
  const BendingLaw spline = BendingLaw::FromSpline({0.0, 10.0, 40.0, 100.0}, {0.0, 1e-4, 3e-4, 6e-4});
  const QuadraticBending s = PcbBending(spline);
  double worst = 0.0;
  for (int i = 1; i <= 1000; ++i) {
    const double k = spline.kappa0() * i / 1000.0;
    worst = std::max(worst, std::abs(s.k1 * k + s.k2 * k * k - spline.Moment(k)) / spline.Moment(k));
  }
  EXPECT_GT(worst, 0.0);
  EXPECT_NEAR(s.max_relative_error, worst, 0.02 * worst + 1e-6);
  EXPECT_LT(s.max_relative_error, 0.2);
}

// ARCSim's energy ½ (k0 G00² + 2 k1 G00 G11 + k2 G11² + k3 G01²), the file's rows doubled
// on load, against the engine's own membrane energy at a small strain.
double ArcsimStretchEnergy(const nlohmann::json& row, const Eigen::Matrix2d& f2) {
  const Eigen::Matrix2d g = 0.5 * (f2.transpose() * f2 - Eigen::Matrix2d::Identity());
  const double k0 = 2 * row[0].get<double>(), k1 = 2 * row[1].get<double>();
  const double k2 = 2 * row[2].get<double>(), k3 = 2 * row[3].get<double>();
  return 0.5 * (k0 * g(0, 0) * g(0, 0) + 2 * k1 * g(0, 0) * g(1, 1) + k2 * g(1, 1) * g(1, 1) +
                k3 * g(0, 1) * g(0, 1));
}

TEST(MaterialExport, ArcsimStretchingHasTheEnginesSmallStrainEnergy) {
  // A unit right triangle in the pattern plane, stretched 1e-4 / 2e-4 and sheared 3e-4.
  Eigen::Matrix3d rest;
  rest << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  double area = 0.0;
  const Eigen::Matrix2d dm_inv = RestInverse(rest, 0, &area);
  Eigen::Matrix2d f2;
  f2 << 1.0001, 3e-4, 0.0, 1.0002;
  Eigen::Matrix3d x = rest;
  for (int v = 1; v < 3; ++v) x.row(v).head<2>() = (f2 * rest.row(v).head<2>().transpose()).transpose();

  const Material ortho = MeasuredMembrane();
  const nlohmann::json o = nlohmann::json::parse(ExportMaterial(ortho, ExportFormat::kArcsim, {}).text);
  ASSERT_TRUE(o.contains("stretching")) << o.dump();
  ASSERT_EQ(o["stretching"].size(), 6u);
  const double ours = OrthotropicMembraneEnergy(*ortho.orthotropic, ortho.Compression(), dm_inv, area, x);
  EXPECT_NEAR(ArcsimStretchEnergy(o["stretching"][0], f2) * area, ours, 2e-3 * ours);

  Material iso = LawOnlyMaterial(BendingLaw::FromKes(0.1, 0.0892, -0.0092), 0.2);
  iso.name = "isotropic";
  iso.orthotropic.reset();
  iso.stretch_stiffness = 2000.0;
  iso.poisson = 0.3;
  iso.defaulted.clear();
  const nlohmann::json i = nlohmann::json::parse(ExportMaterial(iso, ExportFormat::kArcsim, {}).text);
  const double stvk = MembraneEnergy(MembraneModel::kStVK, MembraneLame::FromStretch(2000.0, 0.3),
                                     dm_inv, area, x);
  EXPECT_NEAR(ArcsimStretchEnergy(i["stretching"][5], f2) * area, stvk, 1e-9 * stvk);
}

TEST(MaterialExport, BiasLawIsTheFortyFiveDegreeBlend) {
  const Material m = Anisotropic();
  const BlendedLaw blend(m.EffectiveLaw(), m.EffectiveWeftLaw(), 0.25 * std::numbers::pi);
  const BendingLaw bias = BiasLaw(m);
  for (double k : {0.013, 0.7, 5.0, 33.0, 120.0, 999.0})
    EXPECT_NEAR(bias.Moment(k), blend.Moment(k), 1e-4 * blend.Moment(k)) << k;
}

std::vector<std::vector<std::string>> CsvRows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream l(line);
    while (std::getline(l, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    rows.push_back(cells);
  }
  return rows;
}

// The fitted sample: its CSV carries the fit's σ, and its bending length is the fit report's.
TEST(MaterialExport, AMeasuredBiasLawIsWhatEveryFormatWritesForTheBias) {
  Material m = Anisotropic();
  m.bending_bias = BendingLaw::FromKes(0.2, 0.15, -0.01);
  const BendingLaw bias = *m.EffectiveBiasLaw();  // β = 1.5 applied

  const nlohmann::json arcsim = nlohmann::json::parse(ExportMaterial(m, ExportFormat::kArcsim, {}).text);
  for (size_t j = 1; j < kArcsimBendingAlpha.size(); ++j) {
    const double kappa = kArcsimCurvaturePerAlpha * kArcsimBendingAlpha[j];
    EXPECT_NEAR(arcsim["bending"][1][j].get<double>(), 4.0 * bias.Moment(kappa) / kappa,
                1e-12 * bias.b1());
  }
  const QuadraticBending q = PcbBending(bias);
  EXPECT_DOUBLE_EQ(arcsim["pcb_bending_bias"][0].get<double>(), q.k1);
  EXPECT_DOUBLE_EQ(arcsim["pcb_bending_bias"][1].get<double>(), q.k2);

  const ExportedMaterial csv = ExportMaterial(m, ExportFormat::kCsv, {});
  std::istringstream rows(csv.text);
  std::string header, warp, weft, bias_row;
  std::getline(rows, header);
  std::getline(rows, warp);
  std::getline(rows, weft);
  std::getline(rows, bias_row);
  EXPECT_EQ(bias_row.rfind("bias,45,pabst,0.3,0.225,-0.015,", 0), 0u) << bias_row;
  for (const Note& n : csv.notes) EXPECT_NE(n.code, "bias_blend") << "the bias is measured";

  ExportOptions o;
  o.thickness_mm = 0.5;
  const nlohmann::json u3m = nlohmann::json::parse(ExportMaterial(m, ExportFormat::kU3m, o).text);
  EXPECT_NEAR(u3m["custom"]["textile"]["bending_bias"]["b1"].get<double>(), 0.3, 1e-12);
}

TEST(MaterialExport, CsvHasOneRowADirectionWithTheLabsNumbers) {
  const Material fitted = ReadMaterial(kSamples + "expected/pabst-fig8.fitted.json");
  const ExportedMaterial e = ExportMaterial(fitted, ExportFormat::kCsv, {});
  const auto rows = CsvRows(e.text);
  ASSERT_EQ(rows.size(), 4u) << e.text;
  ASSERT_EQ(rows[0].size(), 15u);
  EXPECT_EQ(rows[0][9], "bending_length_mm");
  for (int r = 1; r <= 3; ++r) {
    ASSERT_EQ(rows[r].size(), 15u) << e.text;
    EXPECT_NEAR(std::stod(rows[r][9]), fitted.fit["bending_length_mm"].get<double>(), 1e-3);
    EXPECT_NEAR(std::stod(rows[r][6]), fitted.fit["b1_sd"].get<double>(), 1e-9);
    EXPECT_EQ(rows[r][13], "");  // membrane not measured
  }
  EXPECT_EQ(rows[1][0], "warp");
  EXPECT_EQ(rows[3][0], "bias");
  EXPECT_TRUE(HasNote(e.notes, "membrane_not_measured"));

  // Two laws: the bias is the blend (no b2, c1, no σ); the moduli are the membrane's.
  Material two = Anisotropic();
  two.orthotropic = MeasuredMembrane().orthotropic;
  two.defaulted = {};
  const auto r2 = CsvRows(ExportMaterial(two, ExportFormat::kCsv, {}).text);
  EXPECT_EQ(r2[3][2], "blend");
  EXPECT_EQ(r2[3][4], "");
  EXPECT_EQ(r2[1][6], "");
  EXPECT_NEAR(std::stod(r2[1][3]), 0.75, 1e-9);  // β b1
  EXPECT_GT(std::stod(r2[1][9]), std::stod(r2[3][9]));  // the warp is the stiffer
  EXPECT_GT(std::stod(r2[3][9]), std::stod(r2[2][9]));
  EXPECT_NEAR(std::stod(r2[1][13]), 3000.0, 1e-6);
  EXPECT_NEAR(std::stod(r2[3][13]), 4.0 / (1 / 3000.0 + 1 / 1200.0 + 1 / 50.0), 1e-4);
  EXPECT_NEAR(std::stod(r2[2][14]), 50.0, 1e-9);
}

// A composite prepreg (3000 g/m², 5000 gf·cm) never reaches the 41.5° barrier in 300 mm:
// empty cells and one note, not a number.
TEST(MaterialExport, CsvOfAStripThatNeverReachesTheBarrierHasEmptyCellsAndANote) {
  Material m = LawOnlyMaterial(BendingLaw::FromKes(5000.0, 3000.0, -100.0), 3.0);
  const ExportedMaterial e = ExportMaterial(m, ExportFormat::kCsv, {});
  const auto rows = CsvRows(e.text);
  ASSERT_EQ(rows.size(), 4u);
  for (int r = 1; r <= 3; ++r) {
    EXPECT_EQ(rows[r][9], "");
    EXPECT_EQ(rows[r][10], "");
    EXPECT_EQ(rows[r][12], "3000");
  }
  int notes = 0;
  for (const Note& n : e.notes) notes += n.code == "no_bending_length";
  EXPECT_EQ(notes, 1);
  EXPECT_EQ(e.text.find("nan"), std::string::npos);
}

TEST(MaterialExport, U3mIsPhysicsOnlyWithTheLawInItsCustomSection) {
  const Material fitted = ReadMaterial(kSamples + "expected/pabst-fig8.fitted.json");
  ExportOptions o;
  o.timestamp = "2026-12-07T08:00:00Z";
  o.thickness_mm = 0.42;
  const ExportedMaterial e = ExportMaterial(fitted, ExportFormat::kU3m, o);
  const nlohmann::json j = nlohmann::json::parse(e.text);
  EXPECT_EQ(j["schema"], "1.1");
  const nlohmann::json& mat = j["material"];
  // What U3M 1.1 requires of a material, with no visuals.
  for (const char* key : {"name", "id", "created", "modified", "front", "back", "side", "physics",
                          "metadata", "description"})
    EXPECT_TRUE(mat.contains(key)) << key;
  EXPECT_EQ(mat.size(), 10u);
  EXPECT_TRUE(mat["front"].is_null() && mat["back"].is_null() && mat["side"].is_null());
  EXPECT_TRUE(std::regex_match(mat["id"].get<std::string>(),
                               std::regex("[0-9a-f]{8}-[0-9a-f]{4}-4[0-9a-f]{3}-[89ab][0-9a-f]{3}-[0-9a-f]{12}")));
  EXPECT_EQ(mat["created"], "2026-12-07T08:00:00Z");
  const nlohmann::json& p = mat["physics"];
  EXPECT_DOUBLE_EQ(p["weight"].get<double>(), 200.0);
  EXPECT_DOUBLE_EQ(p["thickness"].get<double>(), 0.42);
  EXPECT_EQ(p["devices"]["fab"], "null");
  EXPECT_EQ(p.size(), 6u);
  const nlohmann::json& t = j["custom"]["textile"];
  EXPECT_EQ(t["bending"], LawToJson(fitted.EffectiveLaw()));
  EXPECT_EQ(t["bending"]["units"], "kes");
  EXPECT_DOUBLE_EQ(t["bending_sigma"]["b2"].get<double>(), fitted.fit["b2_sd"].get<double>());
  EXPECT_EQ(t["material"]["fit"], fitted.fit);
  EXPECT_FALSE(HasNote(e.notes, "thickness_unknown"));
  // Deterministic: the same bytes again; another material, another id.
  EXPECT_EQ(ExportMaterial(fitted, ExportFormat::kU3m, o).text, e.text);
  const nlohmann::json other =
      nlohmann::json::parse(ExportMaterial(Anisotropic(), ExportFormat::kU3m, o).text);
  EXPECT_NE(other["material"]["id"], mat["id"]);
  EXPECT_TRUE(other["custom"]["textile"]["bending_sigma"].is_null());
  // The id follows every exported field but the times and the producer.
  ExportOptions thicker = o;
  thicker.thickness_mm = 0.5;
  EXPECT_NE(nlohmann::json::parse(ExportMaterial(fitted, ExportFormat::kU3m, thicker).text)["material"]["id"],
            mat["id"]);
  ExportOptions later = o;
  later.timestamp = "2027-01-01T00:00:00Z";
  later.producer = "textile 9.9.9";
  EXPECT_EQ(nlohmann::json::parse(ExportMaterial(fitted, ExportFormat::kU3m, later).text)["material"]["id"],
            mat["id"]);
  // Only U3M carries a thickness.
  EXPECT_THROW(ExportMaterial(fitted, ExportFormat::kCsv, o), InputError);
}

TEST(MaterialExport, U3mRefusesAMaterialWithoutANameOrAThicknessOutOfRange) {
  Material m = Anisotropic();
  m.name.clear();
  EXPECT_THROW(ExportMaterial(m, ExportFormat::kU3m, {}), InputError);
  m.name = "named";
  for (double t : {0.0, -1.0, 1e3, std::nan("")}) {
    ExportOptions o;
    o.thickness_mm = t;
    EXPECT_THROW(ExportMaterial(m, ExportFormat::kU3m, o), InputError) << t;
  }
}

TEST(MaterialExport, TimestampFollowsSourceDateEpoch) {
  ASSERT_EQ(setenv("SOURCE_DATE_EPOCH", "86400", 1), 0);
  EXPECT_EQ(ExportTimestamp(), "1970-01-02T00:00:00Z");
  ASSERT_EQ(setenv("SOURCE_DATE_EPOCH", "253402300799", 1), 0);
  EXPECT_EQ(ExportTimestamp(), "9999-12-31T23:59:59Z");
  for (const char* bad : {"soon", "253402300800", "99999999999999999999", "-1"}) {
    ASSERT_EQ(setenv("SOURCE_DATE_EPOCH", bad, 1), 0);
    EXPECT_THROW(ExportTimestamp(), InputError) << bad;
  }
  ASSERT_EQ(unsetenv("SOURCE_DATE_EPOCH"), 0);
  EXPECT_TRUE(std::regex_match(ExportTimestamp(),
                               std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)")));
  EXPECT_NE(ContentUuid4("a"), ContentUuid4("b"));
}

}  // namespace
}  // namespace textile
