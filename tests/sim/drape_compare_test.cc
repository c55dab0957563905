#include "textile/sim/scenes/drape_compare.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <numbers>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegree = kPi / 180.0;
constexpr double kR = 0.15, kRs = 0.09;  // the standard test's radii [m]

// A drape-like outline without symmetry (six folds, a lean to one side), so that one rotation
// fits best: r(θ + phase) on `bins` uniform bins [m].
Eigen::VectorXd Outline(int bins, double phase = 0.0) {
  Eigen::VectorXd r(bins);
  for (int b = 0; b < bins; ++b) {
    const double t = (b + 0.5) * 2.0 * kPi / bins + phase;
    r(b) =
        0.125 + 0.012 * std::cos(6.0 * t) + 0.004 * std::cos(t + 0.3) + 0.002 * std::sin(2.0 * t);
  }
  return r;
}

DrapeNodes Nodes(int count) {
  DrapeNodes n;
  for (int k = 0; k < count; ++k) {
    n.angles.push_back(2.0 * kPi * k / count);
    n.radii.push_back(0.13);
    n.prominences.push_back(0.01);
  }
  return n;
}

DrapeSeedResult Seed(unsigned seed, const Eigen::VectorXd& radii, double dc, int nodes) {
  DrapeSeedResult s;
  s.seed = seed;
  s.converged = true;
  s.drape_coefficient = dc;
  s.shadow.radii = radii;
  s.shadow.angles.resize(radii.size());
  for (int b = 0; b < radii.size(); ++b) s.shadow.angles(b) = (b + 0.5) * 2.0 * kPi / radii.size();
  s.nodes = Nodes(nodes);
  return s;
}

// A converged result of the given seeds on a 64-gon pattern of radius R (its area the
// polygon's, as the meshed pattern's is).
DrapeResult Simulated(std::vector<DrapeSeedResult> seeds, double radius = kR) {
  DrapeResult r;
  r.converged = true;
  r.message = "converged";
  std::vector<double> dc, nodes;
  for (const DrapeSeedResult& s : seeds) {
    dc.push_back(s.drape_coefficient);
    nodes.push_back(static_cast<double>(s.nodes.angles.size()));
  }
  auto mean = [](const std::vector<double>& v) {
    double sum = 0.0;
    for (double x : v) sum += x;
    return sum / v.size();
  };
  auto sd = [&mean](const std::vector<double>& v) {
    if (v.size() < 2) return 0.0;
    const double m = mean(v);
    double ss = 0.0;
    for (double x : v) ss += (x - m) * (x - m);
    return std::sqrt(ss / (v.size() - 1));
  };
  r.drape_coefficient = mean(dc);
  r.drape_coefficient_sd = sd(dc);
  r.nodes = mean(nodes);
  r.nodes_sd = sd(nodes);
  r.per_seed = std::move(seeds);
  constexpr int kSides = 64;
  r.mesh.vertices.resize(kSides + 1, 3);
  r.mesh.vertices.row(0) << 0.0, 0.0, 0.0;
  for (int k = 0; k < kSides; ++k)
    r.mesh.vertices.row(k + 1) << radius * std::cos(2.0 * kPi * k / kSides),
        radius * std::sin(2.0 * kPi * k / kSides), 0.0;
  r.specimen_area = 0.5 * kSides * radius * radius * std::sin(2.0 * kPi / kSides);
  r.support_area = kPi * kRs * kRs;
  return r;
}

MeasuredDrape Measured(const Eigen::VectorXd& radii, double dc, int nodes, double radius = kR) {
  MeasuredDrape m;
  m.source = "shadow.jpg";
  m.input_kind = "photo";
  m.specimen_radius = radius;
  m.support_radius = kRs;
  m.drape_coefficient = dc;
  m.shadow.radii = radii;
  m.nodes = Nodes(nodes);
  return m;
}

double RmsOf(const Eigen::VectorXd& r) { return std::sqrt(r.squaredNorm() / r.size()); }

TEST(DrapeCompare, IdenticalDrapesPassWithZeroRms) {
  const DrapeComparison c = CompareDrapes(Simulated({Seed(1, Outline(360), 0.62, 6)}),
                                          Measured(Outline(360), 0.62, 6), DrapeCompareOptions{});
  EXPECT_TRUE(c.pass);
  EXPECT_EQ(c.Verdict(), "pass");
  EXPECT_EQ(c.FailureReason(), "");
  EXPECT_TRUE(c.dc_ok);
  EXPECT_TRUE(c.nodes_ok);
  EXPECT_FALSE(c.outline_judged);
  EXPECT_EQ(c.dc_difference, 0.0);
  EXPECT_EQ(c.measured_nodes, 6);
  EXPECT_LT(c.outline_rms, 1e-12);
  EXPECT_LT(c.outline_rms_unrotated, 1e-12);
  EXPECT_NEAR(c.best_rotation, 0.0, 1e-12);
  ASSERT_EQ(c.per_seed.size(), 1u);
  EXPECT_EQ(c.per_seed[0].nodes, 6);
  // One seed: the comparison says it has no spread to judge by, and nothing else.
  ASSERT_EQ(c.notes.size(), 1u);
  EXPECT_EQ(c.notes[0].code, "single_seed");
}

TEST(DrapeCompare, RotatedCopyIsFoundWithinAFractionOfABin) {
  for (const double degrees : {37.4, -100.25, 179.5, 0.3}) {
    // The measured outline is the simulated one turned clockwise by α: r_m(θ) = f(θ + α).
    const OutlineAlignment a = AlignOutlines(Outline(360), Outline(360, degrees * kDegree));
    // Linear interpolation between 1° bins: the fit is good to ~0.01° and the residual to the
    // interpolation's error, h²/8 × |r''| ≈ 0.015 mm at most for these folds.
    EXPECT_NEAR(a.rotation / kDegree, degrees, 0.02) << degrees;
    EXPECT_LT(a.rms, 0.02e-3) << degrees;
    EXPECT_NEAR(RmsOf(a.aligned - Outline(360)), a.rms, 1e-15) << degrees;
    if (std::abs(degrees) > 5.0) {
      EXPECT_GT(a.rms_unrotated, 5e-3) << degrees;
    }
  }
}

TEST(DrapeCompare, ScaledOutlineGivesItsKnownRms) {
  // r_m = s r: the best rotation is 0 (the autocorrelation peaks there) and the RMS
  // (s − 1) × RMS(r). Up to the interpolation's smoothing: a turn by a fraction of a bin averages
  // neighbours, shrinks the too-large outline a little and found 0.02° and 3e-8 m better here.
  const Eigen::VectorXd r = Outline(360);
  const DrapeComparison c = CompareDrapes(Simulated({Seed(1, r, 0.62, 6)}),
                                          Measured(1.04 * r, 0.62, 6), DrapeCompareOptions{});
  EXPECT_NEAR(c.outline_rms, 0.04 * RmsOf(r), 1e-7);
  EXPECT_NEAR(c.outline_rms_unrotated, 0.04 * RmsOf(r), 1e-12);
  EXPECT_NEAR(c.best_rotation / kDegree, 0.0, 0.05);
}

// drape.json's `comparison`: the struct's figures in mm and degrees, its verdict and notes as
// data; the measured file's name is the caller's to add.
TEST(DrapeCompare, JsonCarriesTheFiguresTheVerdictAndTheNotes) {
  const DrapeComparison c = CompareDrapes(Simulated({Seed(1, Outline(360), 0.60, 6)}),
                                          Measured(Outline(360), 0.65, 6), DrapeCompareOptions{});
  const nlohmann::json j = DrapeComparisonJson(c);
  EXPECT_EQ(j["verdict"], "fail");
  EXPECT_EQ(j["dc_ok"], false);
  EXPECT_DOUBLE_EQ(j["measured_dc"].get<double>(), c.measured_dc);
  EXPECT_DOUBLE_EQ(j["dc_difference"].get<double>(), c.dc_difference);
  EXPECT_DOUBLE_EQ(j["outline_rms_mm"].get<double>(), c.outline_rms * 1e3);
  EXPECT_TRUE(j["outline_tol_mm"].is_null());
  ASSERT_EQ(j["seeds"].size(), c.per_seed.size());
  ASSERT_EQ(j["notes"].size(), c.notes.size());
  EXPECT_EQ(j["notes"][0]["code"], "dc_differs");
  EXPECT_FALSE(j.contains("measured_file"));
}

TEST(DrapeCompare, DcOffByMoreThanTheToleranceFailsWithTheNote) {
  const DrapeComparison c = CompareDrapes(Simulated({Seed(1, Outline(360), 0.60, 6)}),
                                          Measured(Outline(360), 0.65, 6), DrapeCompareOptions{});
  EXPECT_FALSE(c.dc_ok);
  EXPECT_TRUE(c.nodes_ok);
  EXPECT_FALSE(c.pass);
  EXPECT_EQ(c.Verdict(), "fail");
  EXPECT_NEAR(c.dc_difference, -0.05, 1e-15);
  ASSERT_TRUE(HasNote(c.notes, "dc_differs"));
  EXPECT_EQ(c.notes[0].text,
            "the simulation drapes more than measured: DC 0.6 simulated against 0.65 measured, "
            "0.05 apart, beyond 0.03");
  // The failure's reason is the failed parts' notes only (not single_seed).
  EXPECT_EQ(c.FailureReason(), c.notes[0].text);
  // A larger DC is a stiffer drape; a wider tolerance passes it.
  const DrapeComparison stiff = CompareDrapes(Simulated({Seed(1, Outline(360), 0.71, 6)}),
                                              Measured(Outline(360), 0.62, 6), {});
  EXPECT_NE(stiff.notes[0].text.find("drapes less than measured: DC 0.71 simulated against 0.62"),
            std::string::npos)
      << stiff.notes[0].text;
  DrapeCompareOptions wide;
  wide.dc_tolerance = 0.1;
  EXPECT_TRUE(CompareDrapes(Simulated({Seed(1, Outline(360), 0.60, 6)}),
                            Measured(Outline(360), 0.65, 6), wide)
                  .pass);
}

TEST(DrapeCompare, NodeCountsBeyondTheToleranceFail) {
  const DrapeComparison c = CompareDrapes(Simulated({Seed(1, Outline(360), 0.62, 8)}),
                                          Measured(Outline(360), 0.62, 6), {});
  EXPECT_TRUE(c.dc_ok);
  EXPECT_FALSE(c.nodes_ok);
  EXPECT_FALSE(c.pass);
  ASSERT_TRUE(HasNote(c.notes, "nodes_differ"));
  EXPECT_EQ(c.notes[0].text,
            "the simulation forms more folds than measured: 8 nodes against 6, "
            "beyond ± 1");
  // One node apart is within the default ±1; the mean over seeds is what is judged.
  EXPECT_TRUE(CompareDrapes(Simulated({Seed(1, Outline(360), 0.62, 7)}),
                            Measured(Outline(360), 0.62, 6), {})
                  .nodes_ok);
  const DrapeComparison seeds =
      CompareDrapes(Simulated({Seed(1, Outline(360), 0.62, 7), Seed(2, Outline(360), 0.62, 8)}),
                    Measured(Outline(360), 0.62, 6), {});
  EXPECT_NEAR(seeds.simulated_nodes, 7.5, 1e-15);
  EXPECT_FALSE(seeds.nodes_ok);
  EXPECT_NE(seeds.notes[0].text.find("7.5 ± 0.71 nodes against 6"), std::string::npos)
      << seeds.notes[0].text;
}

TEST(DrapeCompare, OutlineIsJudgedOnlyWithATolerance) {
  const Eigen::VectorXd r = Outline(360);
  DrapeCompareOptions o;
  EXPECT_TRUE(CompareDrapes(Simulated({Seed(1, r, 0.62, 6)}), Measured(1.1 * r, 0.62, 6), o).pass);
  o.outline_tolerance = 0.005;  // 5 mm; the scaled outline is 12.5 mm off
  const DrapeComparison c =
      CompareDrapes(Simulated({Seed(1, r, 0.62, 6)}), Measured(1.1 * r, 0.62, 6), o);
  EXPECT_TRUE(c.outline_judged);
  EXPECT_FALSE(c.outline_ok);
  EXPECT_FALSE(c.pass);
  ASSERT_TRUE(HasNote(c.notes, "outline_differs"));
  EXPECT_NE(c.notes[0].text.find("beyond 5 mm"), std::string::npos) << c.notes[0].text;
  o.outline_tolerance = 0.02;
  EXPECT_TRUE(CompareDrapes(Simulated({Seed(1, r, 0.62, 6)}), Measured(1.1 * r, 0.62, 6), o).pass);
}

TEST(DrapeCompare, SeedsAreComparedOneByOne) {
  // Two seeds with their folds in other places: each gets its own rotation; the RMS is their
  // mean; a DC sd over half the tolerance is a note, not a wider tolerance.
  const DrapeComparison c =
      CompareDrapes(Simulated({Seed(1, Outline(360, 10 * kDegree), 0.60, 6),
                               Seed(2, Outline(360, -50 * kDegree), 0.64, 6)}),
                    Measured(Outline(360), 0.62, 6), {});
  ASSERT_EQ(c.per_seed.size(), 2u);
  EXPECT_NEAR(c.per_seed[0].outline.rotation / kDegree, -10.0, 0.02);
  EXPECT_NEAR(c.per_seed[1].outline.rotation / kDegree, 50.0, 0.02);
  EXPECT_EQ(c.best_rotation, c.per_seed[0].outline.rotation);
  EXPECT_NEAR(c.outline_rms, 0.5 * (c.per_seed[0].outline.rms + c.per_seed[1].outline.rms), 1e-15);
  EXPECT_NEAR(c.simulated_dc_sd, 0.04 / std::sqrt(2.0), 1e-12);
  EXPECT_TRUE(c.dc_ok);
  EXPECT_TRUE(HasNote(c.notes, "seed_spread"));
  EXPECT_FALSE(HasNote(c.notes, "single_seed"));
}

TEST(DrapeCompare, OtherBinCountsAreResampled) {
  // 720 measured bins against 360 simulated, and 90 against 360: the rotation is still found.
  // The RMS left is the linear interpolation's error, h²/8 × |r''| at most: 0.004 mm at 0.5°,
  // 0.26 mm at 4° for these folds.
  for (const auto& [bins, rms] : {std::pair{720, 0.01e-3}, std::pair{90, 0.2e-3}}) {
    const OutlineAlignment a = AlignOutlines(Outline(360), Outline(bins, 25 * kDegree));
    EXPECT_NEAR(a.rotation / kDegree, 25.0, 0.05) << bins;
    EXPECT_LT(a.rms, rms) << bins;
    EXPECT_EQ(a.aligned.size(), 360);
  }
  // Resampling to the same count is the identity; a constant stays constant.
  EXPECT_EQ(ResampleOutline(Outline(360), 360), Outline(360));
  const Eigen::VectorXd flat = ResampleOutline(Eigen::VectorXd::Constant(17, 0.1), 360);
  EXPECT_NEAR(flat.minCoeff(), 0.1, 1e-15);
  EXPECT_NEAR(flat.maxCoeff(), 0.1, 1e-15);
  // Fine outlines take the stepped search and its local refinement.
  const OutlineAlignment fine = AlignOutlines(Outline(3600), Outline(3600, -63.33 * kDegree));
  EXPECT_NEAR(fine.rotation / kDegree, -63.33, 0.005);
  EXPECT_THROW(AlignOutlines(Outline(4), Outline(360)), InputError);
}

TEST(DrapeCompare, ADrapeWhoseDcMayBeLowSaysSo) {
  DrapeResult r = Simulated({Seed(1, Outline(360), 0.55, 6)});
  r.notes.push_back({"rim_shortfall", "DC may be low by up to about 0.1"});
  const DrapeComparison c = CompareDrapes(r, Measured(Outline(360), 0.62, 6), {});
  EXPECT_FALSE(c.dc_ok);
  EXPECT_TRUE(HasNote(c.notes, "simulated_dc_low"));
  EXPECT_FALSE(HasNote(CompareDrapes(Simulated({Seed(1, Outline(360), 0.55, 6)}),
                                     Measured(Outline(360), 0.62, 6), {})
                           .notes,
                       "simulated_dc_low"));
}

TEST(DrapeCompare, PiR2DcIsTheSameShadowOverTheCutSpecimen) {
  const DrapeResult r = Simulated({Seed(1, Outline(360), 0.62, 6)});
  const DrapeComparison c = CompareDrapes(r, Measured(Outline(360), 0.62, 6), {});
  const double pi_r2 = kPi * kR * kR;
  EXPECT_NEAR(c.simulated_dc_pi_r2,
              0.62 * (r.specimen_area - r.support_area) / (pi_r2 - r.support_area), 1e-15);
  // A 64-gon loses 0.16 % of the disk (0.26 % of the overhang): ~0.0016 of this DC.
  EXPECT_LT(c.simulated_dc_pi_r2, c.simulated_dc);
  EXPECT_GT(c.simulated_dc_pi_r2, c.simulated_dc - 0.002);
}

TEST(DrapeCompare, ADrapeMeasuredFromItsOwnShadowDiffersOnlyByTheDcDefinition) {
  // A coarse plain drape (15 mm, no rim band: ~0.2 s) measured from its own shadow raster as a
  // drape-measure input would be: the same outline (0 mm at 0°), the same nodes, and a DC that
  // is the simulated one over π R² (simulated_dc_pi_r2) exactly.
  Material fabric;
  fabric.areal_density = 0.2;
  fabric.bending = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  DrapeOptions o;
  o.element_size = 0.015;
  o.raster_cell = 0.001;
  const DrapeResult r = SimulateDrape(fabric, o);
  ASSERT_TRUE(r.converged) << r.message;
  const MeasuredDrape m =
      MeasureDrapeShadow(r.per_seed[0].shadow, MeasureOptionsOf(o), "own shadow");
  const DrapeComparison c = CompareDrapes(r, m, {});
  EXPECT_NEAR(c.measured_dc, c.simulated_dc_pi_r2, 1e-12);
  // A 15 mm mesh's polygon: the definitions differ by 0.0026 × DC (0.0013 here).
  EXPECT_GT(c.dc_difference, 0.0005);
  EXPECT_LT(c.dc_difference, 0.003);
  EXPECT_EQ(c.measured_nodes, static_cast<int>(r.per_seed[0].nodes.angles.size()));
  EXPECT_LT(c.outline_rms, 1e-12);
  EXPECT_NEAR(c.best_rotation, 0.0, 1e-12);
  EXPECT_TRUE(c.pass);
}

TEST(DrapeCompare, AnotherSpecimenOrSupportIsRefused) {
  const DrapeResult r = Simulated({Seed(1, Outline(360), 0.62, 6)});
  try {
    CompareDrapes(r, Measured(Outline(360), 0.62, 6, 0.14), {});
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "measured with a 140 mm specimen on a 90 mm support; the simulation's is 150 mm "
                 "on 90 mm: another test (give the simulation the same --specimen-mm and "
                 "--support-mm)");
  }
  DrapeOptions o;
  EXPECT_NO_THROW(CheckDrapesComparable(Measured(Outline(360), 0.62, 6), o));
  o.support_radius = 0.1;
  EXPECT_THROW(CheckDrapesComparable(Measured(Outline(360), 0.62, 6), o), InputError);
}

TEST(DrapeCompare, RefusesUnconvergedResultsAndBadOptions) {
  DrapeResult r = Simulated({Seed(1, Outline(360), 0.62, 6)});
  r.converged = false;
  r.message = "seed 1: 3000 iterations";
  EXPECT_THROW(CompareDrapes(r, Measured(Outline(360), 0.62, 6), {}), ComputeError);
  std::string why;
  DrapeCompareOptions o;
  EXPECT_TRUE(o.Check(&why));
  for (const double bad : {0.0, -0.1, 1.5, std::nan("")}) {
    o.dc_tolerance = bad;
    EXPECT_FALSE(o.Check(&why)) << bad;
    EXPECT_EQ(why, "dc_tolerance: must be in (0, 1]");
  }
  o = {};
  o.node_tolerance = -1.0;
  EXPECT_FALSE(o.Check(&why));
  o = {};
  o.outline_tolerance = std::nan("");
  EXPECT_FALSE(o.Check(&why));
  EXPECT_THROW(CompareDrapes(Simulated({Seed(1, Outline(360), 0.62, 6)}),
                             Measured(Outline(360), 0.62, 6), o),
               InputError);
}

}  // namespace
}  // namespace textile
