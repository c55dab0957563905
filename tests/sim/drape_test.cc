#include "textile/sim/scenes/drape.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "ring_area.h"
#include "textile/sim/elements/contact.h"
#include "textile/sim/core/error.h"
#include "textile/sim/mesh/pattern_mesh.h"

namespace textile {
namespace {

constexpr double kPi = std::numbers::pi;

// The paper's Fig. 8 fabric, 200 g/m² (samples/materials/pabst-fig8.json).
Material Fig8() {
  Material m;
  m.areal_density = 0.2;
  m.bending = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  return m;
}

// The same fabric on the spec's StVK membrane, as stiff in compression as in tension (c = 1): the
// tests of the rim extrapolation and of the resting mount's friction were measured on it, and
// their figures (a split DC that rises by more than 0.005, nothing sliding within 10 mm of the
// rim) are that membrane's. Soft in compression (the default) the skirt hangs nearly plumb in
// its folds and a 5 mm rim drapes like a 2.5 mm one (docs/methods/drapemeter.md, "Compression").
Material Fig8StiffInCompression() {
  Material m = Fig8();
  m.compression_ratio = 1.0;
  return m;
}

// Coarse scenes keep the tests fast; the figures they check are orderings and bounds that hold
// at any resolution (docs/methods/drapemeter.md has the converged numbers).
DrapeOptions Coarse() {
  DrapeOptions o;
  o.element_size = 0.015;
  o.coarse_to_fine = false;
  o.raster_cell = 0.001;
  return o;
}

// The plain coarse drape, shared by the tests that compare against it (computed once).
const DrapeResult& PlainDrape() {
  static const DrapeResult r = SimulateDrape(Fig8(), Coarse());
  return r;
}

double AngleDistance(double a, double b) {
  const double d = std::fmod(std::abs(a - b), 2.0 * kPi);
  return std::min(d, 2.0 * kPi - d);
}

TEST(DrapeShadow, FlatDiskGivesItsOwnAreaAndRadiusSoDcIsOne) {
  PatternMeshOptions mo;
  mo.element_size = 0.01;
  const TriangleMesh disk = MeshDisk(0.15, {}, mo).mesh;
  const double area = TriangleAreas(disk).sum();
  const double cell = 0.00025;
  const DrapeShadow s = MeasureShadow(disk.vertices, disk.triangles, cell, 360);
  // Cell-centre sampling: each boundary cell is in or out, the errors cancel along the rim;
  // the bound is half a cell times the perimeter.
  EXPECT_NEAR(s.area, area, 0.5 * cell * 2.0 * kPi * 0.15);
  const double support = kPi * 0.09 * 0.09;
  EXPECT_NEAR(DrapeCoefficient(s.area, area, support), 1.0,
              0.5 * cell * 2.0 * kPi * 0.15 / (area - support));
  // Outline: the polygon's rim, between its inscribed radius (sag h²/8R) and R, less a cell.
  EXPECT_LE(s.radii.maxCoeff(), 0.15 + 1e-12);
  EXPECT_GT(s.radii.minCoeff(), 0.15 - 0.01 * 0.01 / (8 * 0.15) - 1.5 * cell);
  // A flat disk has no folds.
  EXPECT_TRUE(FindNodes(s.radii, 5, 0.003, 0.15).angles.empty());
}

TEST(DrapeShadow, HolesAreFilledAndTiltDoesNotMatterButProjectionDoes) {
  PatternMeshOptions mo;
  mo.element_size = 0.01;
  const TriangleMesh disk = MeshDisk(0.15, {}, mo).mesh;
  // An annulus: drop every triangle whose centroid lies within 60 mm of the centre.
  TriangleMesh ring;
  ring.vertices = disk.vertices;
  std::vector<int> keep;
  for (int f = 0; f < disk.num_triangles(); ++f) {
    Eigen::RowVector3d c = Eigen::RowVector3d::Zero();
    for (int k = 0; k < 3; ++k) c += disk.vertices.row(disk.triangles(f, k)) / 3.0;
    if (c.head<2>().norm() > 0.06) keep.push_back(f);
  }
  ring.triangles = disk.triangles(keep, Eigen::all);
  const double cell = 0.0005;
  const DrapeShadow full = MeasureShadow(disk.vertices, disk.triangles, cell, 180);
  const DrapeShadow holed = MeasureShadow(ring.vertices, ring.triangles, cell, 180);
  EXPECT_DOUBLE_EQ(holed.area, full.area);
  // Squashing the disk in y by 2 (a vertical projection of a disk tilted by 60°) halves its shadow.
  Vertices tilted = disk.vertices;
  tilted.col(2) = tilted.col(1) * std::sqrt(3.0) / 2.0;
  tilted.col(1) *= 0.5;
  const DrapeShadow half = MeasureShadow(tilted, disk.triangles, cell, 180);
  EXPECT_NEAR(half.area, 0.5 * full.area, 0.5 * cell * 2.0 * kPi * 0.15);
}

// The support's disk casts its own shadow: fabric that left part of it bare (a resting specimen
// slid off the edge) cannot give a shadow smaller than the support, nor a negative DC.
TEST(DrapeShadow, TheSupportShadesItselfSoTheDcIsNeverNegative) {
  PatternMeshOptions mo;
  mo.element_size = 0.01;
  TriangleMesh patch = MeshDisk(0.05, {}, mo).mesh;
  patch.vertices.col(0).array() += 0.08;  // a 50 mm patch from r = 30 to 130 mm
  const double cell = 0.0005, support = 0.09;
  const double patch_area = TriangleAreas(patch).sum(), support_area = kPi * support * support;
  const DrapeShadow bare = MeasureShadow(patch.vertices, patch.triangles, cell, 360);
  EXPECT_NEAR(bare.area, patch_area, 0.5 * cell * 2.0 * kPi * 0.05);
  const DrapeShadow s = MeasureShadow(patch.vertices, patch.triangles, cell, 360, support);
  // The union of the two disks: the support plus the patch's part beyond it.
  EXPECT_GT(s.area, support_area);
  EXPECT_LT(s.area, support_area + patch_area);
  EXPECT_GE(DrapeCoefficient(s.area, kPi * 0.15 * 0.15, support_area), 0.0);
  EXPECT_GE(s.radii.minCoeff(), support - 1.5 * cell);
  // The support's part the patch leaves bare: the support less the lens where the two overlap.
  EXPECT_NEAR(s.bare_support_area, s.area - bare.area, 4.0 * cell * 2.0 * kPi * 0.09);
  EXPECT_GT(s.bare_support_area, 0.5 * support_area);
  EXPECT_DOUBLE_EQ(bare.bare_support_area, 0.0);
  EXPECT_NEAR(s.radii.maxCoeff(), 0.13, 1.5 * cell);
  EXPECT_THROW(MeasureShadow(patch.vertices, patch.triangles, cell, 360, -0.01), InputError);
}

TEST(DrapeNodes, AnOutlineWithKLobesHasKNodesAtTheLobes) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 2e-4);  // 0.2 mm: raster-level jitter
  for (int k = 3; k <= 12; ++k) {
    const int bins = 360;
    const double phase = 0.3 * k;
    Eigen::VectorXd r(bins);
    for (int b = 0; b < bins; ++b) {
      const double t = (b + 0.5) * 2.0 * kPi / bins;
      r(b) = 0.12 + 0.012 * std::cos(k * t + phase) + noise(rng);
    }
    const DrapeNodes nodes = FindNodes(r, 5, 0.003, 0.15);
    ASSERT_EQ(static_cast<int>(nodes.angles.size()), k) << "k = " << k;
    for (size_t i = 0; i < nodes.angles.size(); ++i) {
      // Peaks at k t + phase = 2π n; a bin is 1°.
      const double n = std::round((k * nodes.angles[i] + phase) / (2.0 * kPi));
      EXPECT_LT(AngleDistance(nodes.angles[i], (2.0 * kPi * n - phase) / k), 3.0 * kPi / 180.0);
      EXPECT_NEAR(nodes.radii[i], 0.132, 1.5e-3);
      EXPECT_NEAR(nodes.prominences[i], 0.024, 2e-3);
    }
  }
  // A circle with noise, and a low bump below the absolute threshold, have no nodes.
  Eigen::VectorXd flat(360);
  for (int b = 0; b < 360; ++b) flat(b) = 0.12 + noise(rng);
  EXPECT_TRUE(FindNodes(flat, 5, 0.003, 0.15).angles.empty());
  EXPECT_TRUE(FindNodes(Eigen::VectorXd::Constant(360, 0.1), 5, 0.003, 0.15).angles.empty());
  // Two lobes of different size: the relative rule keeps both when they stand out.
  Eigen::VectorXd two(360);
  for (int b = 0; b < 360; ++b) {
    const double t = (b + 0.5) * 2.0 * kPi / 360;
    two(b) = 0.1 + 0.02 * std::exp(-std::pow((t - 1.0) / 0.2, 2)) +
             0.01 * std::exp(-std::pow((t - 4.0) / 0.2, 2));
  }
  const DrapeNodes n2 = FindNodes(two, 5, 0.003, 0.15);
  ASSERT_EQ(n2.angles.size(), 2u);
  EXPECT_NEAR(n2.prominences[0], 0.02, 1e-3);
  EXPECT_NEAR(n2.prominences[1], 0.01, 1e-3);
}

TEST(DrapeMeasurement, BadInputIsRefused) {
  EXPECT_THROW(DrapeCoefficient(0.05, 0.02, 0.03), InputError);
  EXPECT_THROW(DrapeCoefficient(0.05, 0.07, 0.0), InputError);
  EXPECT_THROW(DrapeCoefficient(std::nan(""), 0.07, 0.02), InputError);
  Vertices x(3, 3);
  x << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  Triangles t(1, 3);
  t << 0, 1, 2;
  EXPECT_THROW(MeasureShadow(x, t, 0.0, 360), InputError);
  EXPECT_THROW(MeasureShadow(x, t, 0.01, 4), InputError);
  Triangles bad(1, 3);
  bad << 0, 1, 3;
  EXPECT_THROW(MeasureShadow(x, bad, 0.01, 360), InputError);
  EXPECT_THROW(FindNodes(Eigen::VectorXd::Constant(360, 0.1), 4, 0.003, 0.1), InputError);
}

TEST(Drape, SpecimenNotLargerThanTheSupportIsRefused) {
  DrapeOptions o = Coarse();
  o.specimen_radius = 0.09;
  try {
    SimulateDrape(Fig8(), o);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("must be larger than the support"), std::string::npos)
        << e.what();
  }
  o = Coarse();
  o.seeds = 0;
  EXPECT_THROW(SimulateDrape(Fig8(), o), InputError);
  o = Coarse();
  o.perturbation = 0.0;
  EXPECT_THROW(SimulateDrape(Fig8(), o), InputError);
  EXPECT_THROW(ParseDrapeSeams("diagonal"), InputError);
  EXPECT_THROW(ParseDrapeMount("glued"), InputError);
  EXPECT_EQ(ParseDrapeSeams(DrapeSeamsName(DrapeSeams::kWeftWarp)), DrapeSeams::kWeftWarp);
}

TEST(Drape, RimBandOptionsAreCheckedByName) {
  const auto why = [](const DrapeOptions& o) {
    std::string w;
    EXPECT_FALSE(o.Check(&w));
    return w;
  };
  DrapeOptions o = Coarse();
  o.rim_element_size = 0.02;  // coarser than the 15 mm mesh
  EXPECT_EQ(why(o).substr(0, 17), "rim_element_size:");
  o.rim_element_size = -0.001;
  EXPECT_EQ(why(o).substr(0, 17), "rim_element_size:");
  o.rim_element_size = std::nan("");
  EXPECT_EQ(why(o).substr(0, 17), "rim_element_size:");
  o.rim_element_size = 5e-5;
  EXPECT_EQ(why(o), "rim_element_size: below 0.1 mm is not a drape mesh");
  o = Coarse();
  o.rim_element_size = 0.005;
  o.rim_band = -0.01;
  EXPECT_EQ(why(o), "rim_band: must be in [0, the overhang]");
  o.rim_band = 0.07;  // the overhang is 60 mm
  EXPECT_EQ(why(o), "rim_band: must be in [0, the overhang]");
  EXPECT_THROW(SimulateDrape(Fig8(), o), InputError);
}

TEST(Drape, RimExtrapolationBoundIsHalfTheBracketEitherWay) {
  // docs/methods/drapemeter.md, "Extrapolated DC": the middle of [DC_split, 2 DC_split - DC_base] and
  // half its width; a split DC below the base's is a reversed bracket, said as such, and its
  // bound is still >= 0 (it was printed as "DC ± -0.0038").
  const RimExtrapolation up = ExtrapolateRim(0.80, 0.84);
  EXPECT_NEAR(up.drape_coefficient, 0.86, 1e-15);
  EXPECT_NEAR(up.bound, 0.02, 1e-15);
  EXPECT_FALSE(up.reversed);
  const RimExtrapolation down = ExtrapolateRim(0.84, 0.80);
  EXPECT_NEAR(down.drape_coefficient, 0.78, 1e-15);
  EXPECT_NEAR(down.bound, 0.02, 1e-15);
  EXPECT_TRUE(down.reversed);
  const RimExtrapolation same = ExtrapolateRim(0.8, 0.8);
  EXPECT_EQ(same.bound, 0.0);
  EXPECT_FALSE(same.reversed);
}

TEST(Drape, SupportAndShiftTheMesherCannotTakeAreRefusedByName) {
  const auto why = [](const DrapeOptions& o) {
    std::string w;
    EXPECT_FALSE(o.Check(&w));
    return w;
  };
  DrapeOptions o = Coarse();  // 15 mm elements
  o.support_radius = 0.0037;  // under a quarter of an element: its chords merge in the mesher
  EXPECT_EQ(why(o), "support_radius: must be at least a quarter of element_size");
  o.support_radius = 0.00375;
  std::string w;
  EXPECT_TRUE(o.Check(&w)) << w;
  o = Coarse();
  o.seams = DrapeSeams::kShifted;
  o.seam_shift = -0.13501;  // closer than one element to the rim (|shift| <= 135 mm)
  EXPECT_EQ(why(o).substr(0, 11), "seam_shift:");
  o.seam_shift = 0.135;
  EXPECT_DOUBLE_EQ(MaxSeamShift(o), 0.135);
  EXPECT_TRUE(o.Check(&w)) << w;
  o.seams = DrapeSeams::kWeft;  // the shift of a seam that is not shifted is not checked
  o.seam_shift = 0.149;
  EXPECT_TRUE(o.Check(&w)) << w;
}

TEST(Drape, AutoRimIsCappedForALimpFabricOnly) {
  // A limp fabric's turn-down length asks for the 0.5 mm floor: 67k vertices in the band and
  // minutes of solving. Auto keeps the band under about kAutoRimMaxVertices vertices and says
  // it capped; the Fig. 8 fabric's ℓ/2 (4.31 mm) is far from the cap.
  const DrapeOptions o;  // 90 mm support, 20 mm band
  Material limp;
  limp.areal_density = 0.3;
  limp.bending = BendingLaw::FromKes(0.0005, 0.0005, 0.0);
  bool capped = false;
  const double e = AutoRimElementSize(limp, o, true, &capped);
  EXPECT_TRUE(capped);
  const double area = std::numbers::pi * (0.11 * 0.11 - 0.09 * 0.09);
  EXPECT_NEAR(2.0 / std::sqrt(3.0) * area / (e * e), kAutoRimMaxVertices,
              1e-6 * kAutoRimMaxVertices);
  EXPECT_GT(e, 0.0005);
  const double fig8 = AutoRimElementSize(Fig8(), o, true, &capped);
  EXPECT_FALSE(capped);
  EXPECT_NEAR(fig8, 0.5 * RimTurnDownLength(Fig8(), o), 1e-15);
}

TEST(Drape, HugeFrameAnglesAreATurnLikeAnyOther) {
  // 1e17 degrees in radians has no fraction of a turn in its last bits: the support circle's
  // points, frame + i step, collapsed onto each other ("seam 0 segment 0 has zero length").
  // The frame is used modulo 2π, so the drape is that of the reduced angle, exactly.
  DrapeOptions o = Coarse();
  o.frame_angle = 1e17 * std::numbers::pi / 180.0;
  const DrapeResult huge = SimulateDrape(Fig8(), o);
  o.frame_angle = std::remainder(o.frame_angle, 2.0 * std::numbers::pi);
  const DrapeResult reduced = SimulateDrape(Fig8(), o);
  ASSERT_TRUE(huge.converged) << huge.message;
  EXPECT_EQ(huge.drape_coefficient, reduced.drape_coefficient);
  EXPECT_EQ(huge.mesh.num_vertices(), reduced.mesh.num_vertices());
}

TEST(Drape, RimTurnDownLengthIsTheClampedStripsBoundaryLayer) {
  // ℓ = sqrt(B / (ρ g (R − R_s))) with B the smaller stiffness, here b2 = 0.0892 gf·cm:
  // sqrt(8.7475e-6 N·m / (0.2 kg/m² · 9.80665 m/s² · 0.06 m)) = 8.62 mm.
  const DrapeOptions o;
  EXPECT_NEAR(RimTurnDownLength(Fig8(), o), 8.622e-3, 1e-6);
  Material heavy = Fig8();
  heavy.areal_density = 0.8;  // four times the weight: half the length
  EXPECT_NEAR(RimTurnDownLength(heavy, o) / RimTurnDownLength(Fig8(), o), 0.5, 1e-12);
  Material weft = Fig8();
  weft.bending_weft = BendingLaw::FromKes(0.0223, 0.0223, 0.0);  // a quarter of b2 across
  EXPECT_NEAR(RimTurnDownLength(weft, o) / RimTurnDownLength(Fig8(), o), 0.5, 1e-3);
  Material bias = Fig8();
  bias.bending_bias = BendingLaw::FromKes(0.0223, 0.0223, 0.0);  // the softest is the bias
  EXPECT_NEAR(RimTurnDownLength(bias, o) / RimTurnDownLength(Fig8(), o), 0.5, 1e-3);
  Material none = Fig8();
  none.areal_density = 0.0;
  EXPECT_THROW(RimTurnDownLength(none, o), InputError);
  // `--rim-mm auto`: ℓ/2 to be split (extrapolating), ℓ/3 for one solve; clamped to
  // [0.5 mm, element size].
  EXPECT_NEAR(AutoRimElementSize(Fig8(), o, true), 8.622e-3 / 2.0, 1e-6);
  EXPECT_NEAR(AutoRimElementSize(Fig8(), o, false), 8.622e-3 / 3.0, 1e-6);
  DrapeOptions fine = o;
  fine.element_size = 0.003;
  EXPECT_EQ(AutoRimElementSize(Fig8(), fine, true), 0.003);
  Material light = Fig8();
  light.bending = BendingLaw::FromKes(1e-5, 1e-5, 0.0);  // ℓ ≈ 0.09 mm
  // On the default band the cap on its vertices decides for so limp a fabric
  // (AutoRimIsCappedForALimpFabricOnly); on a 1 mm band (0.26 mm at the cap) the floor does.
  DrapeOptions narrow = o;
  narrow.rim_band = 0.001;
  EXPECT_EQ(AutoRimElementSize(light, narrow, false), 0.0005);
  EXPECT_THROW(AutoRimElementSize(none, o, true), InputError);
}

// The overhang turns down at the rim over a few millimetres; a mesh too coarse there lets it
// fold along one row of edges and the drape comes out low (docs/methods/drapemeter.md, "Resolution").
TEST(Drape, RimBandRefinesTheRimAndRaisesTheDrape) {
  DrapeOptions o = Coarse();
  o.rim_element_size = 0.005;
  o.rim_band = 0.02;
  const DrapeResult rim = SimulateDrape(Fig8(), o);
  const DrapeResult& plain = PlainDrape();
  ASSERT_TRUE(rim.converged && plain.converged) << rim.message << " / " << plain.message;
  // Triangles just outside the rim: about (15/5)² = 9 times smaller; near the centre unchanged.
  const auto mean_area = MeanTriangleAreaInRing;
  EXPECT_GT(mean_area(plain.mesh, 0.092, 0.108) / mean_area(rim.mesh, 0.092, 0.108), 5.0);
  EXPECT_NEAR(mean_area(rim.mesh, 0.0, 0.05) / mean_area(plain.mesh, 0.0, 0.05), 1.0, 0.25);
  // Measured on seed 1: 0.509 without the band, 0.576 with it (seed 2: 0.567).
  EXPECT_GT(rim.drape_coefficient, plain.drape_coefficient + 0.03);
  EXPECT_LT(rim.drape_coefficient, 1.0);
  EXPECT_NEAR(rim.mass, 0.2 * rim.specimen_area, 1e-12);
}

// Rim extrapolation: the rim band split in four, the drape carried over and solved again,
// DC = 2 DC_split − DC_base. The split mesh's drape is higher (first-order convergence from
// below) and like a direct solve with its rim size.
TEST(Drape, RimExtrapolationSplitsTheRimAndExtrapolates) {
  DrapeOptions o = Coarse();
  o.rim_element_size = 0.005;
  const DrapeResult base = SimulateDrape(Fig8StiffInCompression(), o);
  o.rim_extrapolation = true;
  const DrapeResult r = SimulateDrape(Fig8StiffInCompression(), o);
  ASSERT_TRUE(base.converged && r.converged) << base.message << " / " << r.message;
  const DrapeSeedResult& s = r.per_seed.at(0);
  EXPECT_TRUE(s.split_summary.converged);
  EXPECT_EQ(r.base_vertices, base.mesh.num_vertices());
  EXPECT_GT(r.mesh.num_vertices(), 2 * r.base_vertices);
  EXPECT_EQ(s.positions.rows(), r.mesh.num_vertices());
  // Triangles just outside the rim are split in four; near the centre they are not.
  const auto mean_area = MeanTriangleAreaInRing;
  EXPECT_NEAR(mean_area(base.mesh, 0.092, 0.108) / mean_area(r.mesh, 0.092, 0.108), 4.0, 0.5);
  EXPECT_NEAR(mean_area(r.mesh, 0.0, 0.05) / mean_area(base.mesh, 0.0, 0.05), 1.0, 1e-12);
  // Same pattern, same mass.
  EXPECT_NEAR(r.specimen_area, base.specimen_area, 1e-15);
  EXPECT_NEAR(r.mass, base.mass, 1e-15);
  // The base solve is the plain run's.
  EXPECT_EQ(s.base_drape_coefficient, base.drape_coefficient);
  EXPECT_GT(s.split_drape_coefficient, s.base_drape_coefficient + 0.005);
  // Between the split DC and the first-order extrapolation 2 DC_split − DC_base, in the middle.
  EXPECT_DOUBLE_EQ(s.extrapolation_bound,
                   0.5 * (s.split_drape_coefficient - s.base_drape_coefficient));
  EXPECT_DOUBLE_EQ(s.drape_coefficient, s.split_drape_coefficient + s.extrapolation_bound);
  EXPECT_EQ(r.drape_coefficient, s.drape_coefficient);
  // The split rim is a 2.5 mm rim: a mesh made with 2.5 mm there drapes alike (measured, seed
  // 1: base 0.5755, split 0.6057, extrapolated 0.6206, direct 2.5 mm 0.5963), and the
  // extrapolation goes past both.
  DrapeOptions fine = Coarse();
  fine.rim_element_size = 0.0025;
  const DrapeResult direct = SimulateDrape(Fig8StiffInCompression(), fine);
  ASSERT_TRUE(direct.converged) << direct.message;
  EXPECT_NEAR(s.split_drape_coefficient, direct.drape_coefficient, 0.015);
  EXPECT_GT(direct.drape_coefficient, s.base_drape_coefficient + 0.01);
  EXPECT_GT(s.drape_coefficient, direct.drape_coefficient + 0.01);
  // Split first, then solve: the same base drape, and the split solve cut short, is a run
  // without a DC that says which solve failed; the positions still fit the split mesh.
  DrapeOptions capped = o;
  capped.solver.max_iterations = s.summary.iterations;  // enough for the base (67), not the split
  const DrapeResult short_split = SimulateDrape(Fig8StiffInCompression(), capped);
  EXPECT_FALSE(short_split.converged);
  EXPECT_EQ(short_split.message.rfind("seed 1: rim split: ", 0), 0u) << short_split.message;
  const DrapeSeedResult& f = short_split.per_seed.at(0);
  EXPECT_TRUE(f.summary.converged);
  EXPECT_FALSE(f.split_summary.converged);
  EXPECT_TRUE(std::isnan(f.drape_coefficient) && std::isnan(short_split.drape_coefficient));
  EXPECT_EQ(f.shadow.mask.size(), 0u);
  EXPECT_EQ(f.positions.rows(), short_split.mesh.num_vertices());
  // Without a rim band there is nothing to split.
  DrapeOptions none = Coarse();
  none.rim_extrapolation = true;
  std::string why;
  EXPECT_FALSE(none.Check(&why));
  EXPECT_EQ(why, "rim_extrapolation: needs a rim band (rim_element_size > 0)");
  EXPECT_THROW(SimulateDrape(Fig8StiffInCompression(), none), InputError);
  // A band narrower than one rim element would split little beyond the clamp (the DC would
  // not converge towards anything).
  none.rim_element_size = 0.005;
  none.rim_band = 0.004;
  EXPECT_FALSE(none.Check(&why));
  EXPECT_EQ(why, "rim_extrapolation: needs a rim band at least one rim element wide");
  // The resting mount may extrapolate: its friction anchors go over to the split mesh
  // (Drape.RestingSpecimenCarriesItsFrictionOverToTheSplitRim). Not coarse to fine: that fine
  // level starts its friction afresh (at 15 mm the cloth slid off, DC 0.33 against 0.56).
  none.rim_band = 0.02;
  none.mount = DrapeMount::kResting;
  EXPECT_TRUE(none.Check(&why)) << why;
  none.coarse_to_fine = true;
  EXPECT_FALSE(none.Check(&why));
  EXPECT_EQ(why.rfind("coarse_to_fine: clamped mount only", 0), 0u) << why;
}

// The resting mount (ContactOptions::friction_potential: Coulomb friction as a potential from
// where each node landed, lagged normal forces): with the samples' μ = 0.3 the specimen settles
// on the disk, and less friction lets more of it slide out over the rim. Measured on this mesh,
// seed 1: DC 0.532 (μ = 0.3, 118 steps, outline from 104.5 mm), 0.383 (μ = 0.1, from 95.8 mm),
// 0.560 (μ = 3); clamped 0.509. Slip
// between converged stretches (lagged_slip) settled here only with μ = 3 (DC 0.491, 621 steps)
// and per-step stick/slip switching never (docs/methods/drapemeter.md, "Limits").
TEST(Drape, RestingSpecimenSettlesWithTheSamplesFrictionAndLessFrictionLetsItSlideOut) {
  DrapeOptions o = Coarse();
  o.mount = DrapeMount::kResting;
  const DrapeResult r = SimulateDrape(Fig8StiffInCompression(), o);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_GT(r.drape_coefficient, 0.0);
  EXPECT_LT(r.drape_coefficient, 1.0);
  // Nothing slid over the rim: the outline stays outside the support, as the clamped one does.
  EXPECT_GT(r.min_radius, o.support_radius + 0.01);
  EXPECT_NEAR(r.mass, 0.2 * r.specimen_area, 1e-9);
  ASSERT_EQ(r.per_seed.size(), 1u);
  EXPECT_GT(r.per_seed[0].summary.contacts, 0);
  Material slippery = Fig8StiffInCompression();
  slippery.friction = 0.1;
  const DrapeResult s = SimulateDrape(slippery, o);
  ASSERT_TRUE(s.converged) << s.message;
  EXPECT_LT(s.drape_coefficient, r.drape_coefficient - 0.05);
  EXPECT_LT(s.min_radius, r.min_radius);
}

// The resting mount's contact stiffness (DrapeOptions::contact_sink): the rim carries the hanging
// overhang, many times a node's own weight, so the penalty lets the skirt sink into the disk's
// side (1 mm on the CLI's default mesh, the DC about 0.03 low; docs/methods/drapemeter.md, "Contact
// stiffness"), and a stiffer one less. max_penetration reports the deepest node. Measured on
// this mesh, seed 1: the deepest node 0.49 mm at 1e-5 m (DC 0.532), 0.18 mm at 3e-6 m (0.579).
TEST(Drape, AStifferRestingContactSinksTheSkirtLess) {
  DrapeOptions o = Coarse();
  o.mount = DrapeMount::kResting;
  ASSERT_EQ(o.contact_sink, 1e-5);
  const Support disk =
      Support::Disk(Eigen::Vector3d::Zero(), o.support_radius, o.support_thickness, o.rim_rounding);
  const auto deepest = [&](const DrapeResult& r) {
    double depth = 0.0;
    const Vertices& x = r.per_seed.at(0).positions;
    for (int i = 0; i < x.rows(); ++i)
      depth = std::max(depth, -disk.SignedDistance(x.row(i).transpose(), nullptr));
    return depth;
  };
  const DrapeResult soft = SimulateDrape(Fig8(), o);
  ASSERT_TRUE(soft.converged) << soft.message;
  o.contact_sink = 3e-6;
  const DrapeResult stiff = SimulateDrape(Fig8(), o);
  ASSERT_TRUE(stiff.converged) << stiff.message;
  EXPECT_EQ(soft.per_seed[0].max_penetration, deepest(soft));
  EXPECT_EQ(stiff.per_seed[0].max_penetration, deepest(stiff));
  EXPECT_GT(deepest(soft), 0.2e-3);
  EXPECT_LT(deepest(stiff), 0.6 * deepest(soft));
  EXPECT_EQ(PlainDrape().per_seed.at(0).max_penetration, 0.0);  // clamped: no support
  o.contact_sink = 0.0;
  std::string why;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_EQ(why, "contact_sink: must be in [1e-9, 3e-5] m");
}

// A resting specimen's rim split goes on with the base drape's friction (its anchors where the
// nodes landed, ClothProblem::CarryAnchorsFrom) and extrapolates as a clamped one does.
TEST(Drape, RestingSpecimenCarriesItsFrictionOverToTheSplitRim) {
  DrapeOptions o = Coarse();
  o.mount = DrapeMount::kResting;
  o.rim_element_size = 0.006;
  o.rim_extrapolation = true;
  const DrapeResult r = SimulateDrape(Fig8StiffInCompression(), o);
  ASSERT_TRUE(r.converged) << r.message;
  ASSERT_EQ(r.per_seed.size(), 1u);
  const DrapeSeedResult& s = r.per_seed[0];
  EXPECT_TRUE(s.split_summary.converged);
  EXPECT_GT(s.split_summary.contacts, s.summary.contacts);  // the split mesh has more nodes there
  EXPECT_NEAR(
      r.drape_coefficient,
      s.split_drape_coefficient + 0.5 * (s.split_drape_coefficient - s.base_drape_coefficient),
      1e-12);
  EXPECT_GT(r.drape_coefficient, 0.0);
  EXPECT_LT(r.drape_coefficient, 1.0);
  EXPECT_GT(r.min_radius, o.support_radius + 0.01);  // nothing slid over the rim
  EXPECT_NEAR(r.mass, 0.2 * r.specimen_area, 1e-9);
}

// The drape's Newton doubles full steps that lower the energy (expand_steps, on for drapes)
// and takes the exact Hessian near the end (exact_below): each on its own must save steps and
// leave the drape as it is. On the membrane where they matter most, a lab's orthotropic one
// soft in shear and compression (here its defaults: a file with the law alone); measured on this
// mesh, seed 1: 330 steps with both, 504 without the doubling. (On the isotropic sample
// membrane the doubling saves none here: 98 and 98.)
TEST(Drape, SolverShortcutsReachTheSameDrapeInFewerSteps) {
  DrapeOptions o = Coarse();
  o.rim_element_size = 0.005;
  ASSERT_TRUE(o.solver.expand_steps);
  ASSERT_EQ(o.solver.exact_below, kDrapeExactBelow);
  const Material lab = LawOnlyMaterial(Fig8().bending, Fig8().areal_density);
  ASSERT_TRUE(lab.orthotropic.has_value());
  const DrapeResult both = SimulateDrape(lab, o);
  DrapeOptions no_doubling = o;
  no_doubling.solver.expand_steps = false;
  DrapeOptions no_exact = o;
  no_exact.solver.exact_below = 0.0;
  const SolveSummary& b = both.per_seed.at(0).summary;
  ASSERT_TRUE(both.converged) << both.message;
  EXPECT_GT(b.exact_steps, 0);
  for (const DrapeOptions& other : {no_doubling, no_exact}) {
    const DrapeResult r = SimulateDrape(lab, other);
    const SolveSummary& s = r.per_seed.at(0).summary;
    SCOPED_TRACE(std::string(other.solver.expand_steps ? "no exact Hessian" : "no doubling") +
                 ": " + s.BriefReport());
    ASSERT_TRUE(r.converged) << r.message;
    EXPECT_NEAR(both.drape_coefficient, r.drape_coefficient, 1e-3);
    EXPECT_NEAR(b.energy, s.energy, 1e-6 * std::abs(s.energy));
    EXPECT_EQ(both.nodes, r.nodes);
    EXPECT_LT(b.iterations, s.iterations);
    if (other.solver.exact_below == 0.0) {
      EXPECT_EQ(s.exact_steps, 0);
    }
  }
}

TEST(Drape, NonConvergedRunReportsNoDrapeCoefficient) {
  DrapeOptions o = Coarse();
  o.solver.max_iterations = 2;
  const DrapeResult r = SimulateDrape(Fig8(), o);
  EXPECT_FALSE(r.converged);
  EXPECT_NE(r.message.find("iteration cap"), std::string::npos) << r.message;
  EXPECT_TRUE(std::isnan(r.drape_coefficient));
  EXPECT_TRUE(std::isnan(r.per_seed.at(0).drape_coefficient));
  for (double figure : {r.drape_coefficient_sd, r.nodes, r.nodes_sd, r.min_radius, r.max_radius,
                        r.mean_radius, r.min_radius_sd, r.max_radius_sd, r.mean_radius_sd})
    EXPECT_TRUE(std::isnan(figure)) << figure;
}

TEST(Drape, PlainSpecimenDrapesWithFoldsAndConservesMass) {
  const DrapeResult& r = PlainDrape();
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_GT(r.drape_coefficient, 0.0);
  EXPECT_LT(r.drape_coefficient, 1.0);
  EXPECT_GE(r.nodes, 3.0);
  // Mass: ρ × the meshed area, exactly (lumped masses partition each triangle's).
  EXPECT_NEAR(r.mass, 0.2 * r.specimen_area, 1e-12);
  const DrapeSeedResult& s = r.per_seed.at(0);
  // The clamped disk stays flat and the overhang hangs: nothing above z = 0, the rim below it.
  EXPECT_LE(s.positions.col(2).maxCoeff(), 1e-9);
  EXPECT_LT(s.positions.col(2).minCoeff(), -0.02);
  // The outline lies between the support and the flat specimen.
  EXPECT_GT(s.min_radius, 0.09);
  EXPECT_LT(s.max_radius, 0.15 + 1e-3);
}

TEST(Drape, RotatingThePerturbationAndSeamsOverTheMeshKeepsDc) {
  DrapeOptions o = Coarse();
  const DrapeResult& a = PlainDrape();
  o.frame_angle = 37.0 * kPi / 180.0;
  const DrapeResult b = SimulateDrape(Fig8(), o);
  ASSERT_TRUE(a.converged && b.converged) << a.message << " / " << b.message;
  // The same start turned by 37° over an unstructured mesh: the drape must be the same up to
  // discretisation: measured 0.509 and 0.502 on this 15 mm mesh, 8 nodes each.
  EXPECT_NEAR(a.drape_coefficient, b.drape_coefficient, 0.03);
  EXPECT_NEAR(a.nodes, b.nodes, 1.0);
}

TEST(Drape, StifferFabricDrapesLess) {
  Material stiff = Fig8();
  stiff.beta = 3.0;  // M_β = β M: three times the bending stiffness
  const DrapeResult& soft = PlainDrape();
  const DrapeResult hard = SimulateDrape(stiff, Coarse());
  ASSERT_TRUE(soft.converged && hard.converged) << soft.message << " / " << hard.message;
  // Measured 0.51 → 0.76 (bending length × 3^(1/3)).
  EXPECT_GT(hard.drape_coefficient, soft.drape_coefficient + 0.1);
}

// A measured bias law takes part: one equal to the warp and weft law drapes as the plain fabric
// (the hinges' blend gives that law back), one a quarter as stiff lets the skirt fall further.
// Measured on this 15 mm mesh: 0.372 with the same law (identical), 0.306 with the soft bias.
TEST(Drape, AMeasuredBiasLawIsBlendedIntoTheHinges) {
  Material same = Fig8();
  same.bending_bias = same.bending;
  const DrapeResult r = SimulateDrape(same, Coarse());
  ASSERT_TRUE(r.converged && PlainDrape().converged) << r.message;
  EXPECT_NEAR(r.drape_coefficient, PlainDrape().drape_coefficient, 1e-6);
  Material soft = Fig8();
  soft.bending_bias = soft.bending.Scaled(0.25);
  const DrapeResult s = SimulateDrape(soft, Coarse());
  ASSERT_TRUE(s.converged) << s.message;
  EXPECT_LT(s.drape_coefficient, PlainDrape().drape_coefficient - 0.01);
}

// The default membrane is soft in compression (kDefaultCompressionRatio, 0.01): the skirt takes
// up its excess circumference by buckling. One as stiff in compression as in tension (c = 1, the
// spec's StVK) compresses where the soft one folds, so its skirt stands out further
// (docs/methods/drapemeter.md, "Compression"). Measured on this 15 mm mesh: 0.372 → 0.509.
TEST(Drape, AMembraneAsStiffInCompressionAsInTensionDrapesHigher) {
  ASSERT_EQ(Fig8().compression_ratio, kDefaultCompressionRatio);
  Material stiff = Fig8();
  stiff.compression_ratio = 1.0;
  const DrapeResult r = SimulateDrape(stiff, Coarse());
  ASSERT_TRUE(r.converged && PlainDrape().converged) << r.message;
  EXPECT_GT(PlainDrape().drape_coefficient, 0.0);
  EXPECT_GT(r.drape_coefficient, PlainDrape().drape_coefficient + 0.08);
  EXPECT_GE(PlainDrape().nodes, 5.0);
}

// A material file without a membrane drapes on the documented defaults, and the result says so
// (one membrane_default note per defaulted field); a file that gives the membrane has no such note.
TEST(Drape, DefaultedMembraneIsNotedInTheResult) {
  const std::string bending =
      R"("areal_density_gsm": 200, "bending": {"units": "kes", "b1": 0.1, "b2": 0.0892, "c1": -0.0092})";
  const Material defaulted = ParseMaterialJson("{" + bending + "}", "defaulted.json");
  const DrapeResult r = SimulateDrape(defaulted, Coarse());
  ASSERT_TRUE(r.converged) << r.message;
  const auto count = std::count_if(r.notes.begin(), r.notes.end(),
                                   [](const Note& n) { return n.code == "membrane_default"; });
  EXPECT_EQ(count, static_cast<long>(defaulted.defaulted.size()));
  EXPECT_GE(count, 3);  // warp, weft and shear at least
  EXPECT_FALSE(HasNote(PlainDrape().notes, "membrane_default"));
  const Material given = ParseMaterialJson(
      "{" + bending + R"(, "stretch": {"stiffness_N_per_m": 1000, "poisson": 0.3, "compression_ratio": 1}})", "given.json");
  EXPECT_TRUE(MaterialDefaultNotes(given).empty());
}

TEST(Drape, SeamRaisesDcAndCarriesItsMass) {
  DrapeOptions o = Coarse();
  const DrapeResult& plain = PlainDrape();
  o.seams = DrapeSeams::kWeft;
  o.seam_profile = SeamPreset("C-plain");
  const DrapeResult seam = SimulateDrape(Fig8(), o);
  ASSERT_TRUE(plain.converged && seam.converged) << plain.message << " / " << seam.message;
  // Measured 0.51 → 0.80: S(d) of C-plain is 4..9 over the whole specimen.
  EXPECT_GT(seam.drape_coefficient, plain.drape_coefficient + 0.1);
  // The seam band: 3 extra layers, 10 mm wide, along a 300 mm diameter (its caps are outside).
  const double band = 3 * 0.2 * 0.01 * 0.3;
  EXPECT_NEAR(seam.mass - 0.2 * seam.specimen_area, band, 0.01 * band);
  // The weft seam is an edge path from rim to rim along the pattern's y axis (the weft).
  ASSERT_EQ(seam.seam_paths.size(), 1u);
  const auto& path = seam.seam_paths[0];
  ASSERT_GE(path.size(), 3u);
  for (int v : path) EXPECT_NEAR(seam.mesh.vertices(v, 0), 0.0, 1e-9);
  EXPECT_NEAR(std::abs(seam.mesh.vertices(path.front(), 1)), 0.15, 1e-9);
  EXPECT_NEAR(std::abs(seam.mesh.vertices(path.back(), 1)), 0.15, 1e-9);
}

TEST(Drape, WeftAndWarpSeamsPinTheFoldPattern) {
  // Two crossing C-plain seams fix the folds whatever the start: both seeds find the same drape,
  // with its four nodes on the diagonals between the seams (measured: 44°, 134°, 225°, 314°).
  DrapeOptions o = Coarse();
  o.seams = DrapeSeams::kWeftWarp;
  o.seeds = 2;
  const DrapeResult r = SimulateDrape(Fig8(), o);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_NEAR(r.per_seed[0].drape_coefficient, r.per_seed[1].drape_coefficient, 1e-3);
  for (const DrapeSeedResult& s : r.per_seed) {
    ASSERT_EQ(s.nodes.angles.size(), 4u) << "seed " << s.seed;
    for (double a : s.nodes.angles) {
      const double to_diagonal = std::abs(std::fmod(a, 0.5 * kPi) - 0.25 * kPi);
      EXPECT_LT(to_diagonal, 5.0 * kPi / 180.0) << "node at " << a * 180.0 / kPi << "°";
    }
  }
}

}  // namespace
}  // namespace textile
