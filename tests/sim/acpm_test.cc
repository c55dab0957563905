// The virtual ACPM200 (acpm.h) and the elastica's strip variation (elastica.h) that answers a
// seam across the push direction.

#include "textile/sim/scenes/acpm.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "textile/sim/elastica/elastica.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"
#include "textile/sim/law/material.h"

namespace textile {
namespace {

Material Fabric(double b1, double b2, double c1, double gsm) {
  Material m;
  m.name = "test";
  m.areal_density = units::GsmToSi(gsm);
  m.bending = BendingLaw::FromKes(b1, b2, c1);
  return m;
}
Material Fig8() { return Fabric(0.1, 0.0892, -0.0092, 200); }

template <typename Fn>
std::string ErrorOf(Fn fn) {
  try {
    fn();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

// ---- The strip variation of the elastica ----

// The reference solutions have rel_tol 1e-10 (docs/methods/cantilever-facts.md: positions to ~1e-12 L);
// two different integrations of the same strip agree to 1e-9 L.
constexpr double kSameStrip = 1e-9;

TEST(ElasticaVariation, ConstantMultiplierIsTheScaledLaw) {
  // S(u) = k everywhere is M_S = k M: the law scaled by k (β of section 3.4 does the same).
  const BendingLaw law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  for (double length : {0.03, 0.1, 0.5}) {  // 0.5 m hangs near vertically: the log form
    for (double k : {0.5, 3.0}) {
      ElasticaOptions o;
      o.variation.stiffness_multiplier = [k](double) { return k; };
      const ElasticaProfile a = SolveHeavyElastica(law, 0.2, length, o);
      const ElasticaProfile b = SolveHeavyElastica(law.Scaled(k), 0.2, length);
      ASSERT_TRUE(a.converged && b.converged) << a.message << b.message;
      for (size_t j = 0; j < a.x.size(); ++j) {
        EXPECT_NEAR(a.x[j], b.x[j], kSameStrip * length) << length << " " << k << " " << j;
        EXPECT_NEAR(a.y[j], b.y[j], kSameStrip * length) << length << " " << k << " " << j;
      }
      EXPECT_NEAR(a.log_tip_gap, b.log_tip_gap, 1e-8 * std::abs(b.log_tip_gap));
    }
  }
}

TEST(ElasticaVariation, UniformWeightFactorIsADenserStrip) {
  // W(u) = q u is the strip of density q ρ.
  const BendingLaw law = BendingLaw::FromKes(0.5168, 1.8856, 2.2683);
  ElasticaOptions o;
  o.variation.weight_from_tip = [](double u) { return 2.5 * u; };
  const ElasticaProfile a = SolveHeavyElastica(law, 0.25, 0.1, o);
  const ElasticaProfile b = SolveHeavyElastica(law, 0.625, 0.1);
  ASSERT_TRUE(a.converged && b.converged);
  for (size_t j = 0; j < a.x.size(); ++j) {
    EXPECT_NEAR(a.x[j], b.x[j], kSameStrip * 0.1);
    EXPECT_NEAR(a.y[j], b.y[j], kSameStrip * 0.1);
  }
}

TEST(ElasticaVariation, StiffRegionMatchesTwoPieceComposition) {
  // A strip whose first 40 mm from the tip is 4× stiffer. Changing tolerance and dropping the
  // breakpoint must not move the answer beyond the tolerance: the step that crosses the jump
  // is cut by the error control alone then (an independent check of the breakpoint logic).
  const BendingLaw law = BendingLaw::FromKes(0.0973, 0.0973, 0.0453);
  auto solve = [&](bool breakpoint, double tol) {
    ElasticaOptions o;
    o.rel_tol = tol;
    o.variation.stiffness_multiplier = [](double u) { return u < 0.04 ? 4.0 : 1.0; };
    if (breakpoint) o.variation.breakpoints = {0.04};
    return SolveHeavyElastica(law, 0.13, 0.06, o);
  };
  const ElasticaProfile ref = solve(true, 1e-12), with = solve(true, 1e-10),
                        without = solve(false, 1e-10);
  ASSERT_TRUE(ref.converged && with.converged && without.converged);
  EXPECT_NEAR(with.tip_y, ref.tip_y, 1e-9 * 0.06);
  EXPECT_NEAR(without.tip_y, ref.tip_y, 1e-7 * 0.06);
  // Stiffer near the tip: 60 mm is 3 bending lengths, short enough that stiffness anywhere
  // lifts the tip: it deflects less than the plain strip and more than the 4× stiffer one.
  const ElasticaProfile plain = SolveHeavyElastica(law, 0.13, 0.06);
  const ElasticaProfile stiff = SolveHeavyElastica(law.Scaled(4.0), 0.13, 0.06);
  EXPECT_GT(ref.tip_y, plain.tip_y);
  EXPECT_LT(ref.tip_y, stiff.tip_y);
  // The curvature jumps by 4× across the seam point (same moment on both sides).
  ElasticaOptions o;
  o.variation.stiffness_multiplier = [](double u) { return u < 0.04 ? 4.0 : 1.0; };
  o.variation.breakpoints = {0.04};
  o.arc_lengths = {0.02 - 1e-9, 0.02 + 1e-9};  // s = L - u
  const ElasticaProfile k = SolveHeavyElastica(law, 0.13, 0.06, o);
  ASSERT_TRUE(k.converged);
  EXPECT_NEAR(k.kappa[0] / k.kappa[1], 4.0, 1e-6);
}

TEST(ElasticaVariation, SensitivitiesMatchFiniteDifferences) {
  // The variational equations carry S through (S M(κ) = m: ∂κ/∂p|m has no S): check against
  // central differences, relative step 1e-5 (O(h²) ≈ 1e-9 of the largest, as in elastica_test).
  const BendingLaw law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  ElasticaOptions o;
  o.num_samples = 11;
  o.variation.stiffness_multiplier = [](double u) { return 1.0 + 2.0 * std::exp(-u / 0.01); };
  o.variation.weight_from_tip = [](double u) { return u + 2.0 * std::min(u, 0.005); };
  o.variation.breakpoints = {0.005};
  ElasticaOptions os = o;
  os.sensitivities = true;
  const ElasticaProfile p = SolveHeavyElastica(law, 0.2, 0.06, os);
  ASSERT_TRUE(p.converged) << p.message;
  const double params[3] = {law.b1(), law.b2(), law.c1()};
  double largest = 0.0;
  for (int k = 0; k < 3; ++k) largest = std::max(largest, p.dy_dp.col(k).cwiseAbs().maxCoeff() * std::abs(params[k]));
  for (int k = 0; k < 3; ++k) {
    double plus[3] = {params[0], params[1], params[2]}, minus[3] = {params[0], params[1], params[2]};
    const double h = 1e-5 * std::abs(params[k]);
    plus[k] += h;
    minus[k] -= h;
    const ElasticaProfile a =
        SolveHeavyElastica(BendingLaw::FromSi(plus[0], plus[1], plus[2]), 0.2, 0.06, o);
    const ElasticaProfile b =
        SolveHeavyElastica(BendingLaw::FromSi(minus[0], minus[1], minus[2]), 0.2, 0.06, o);
    for (int j = 0; j < 11; ++j) {
      const double fd = (a.y[j] - b.y[j]) / (2 * h);
      EXPECT_NEAR(p.dy_dp(j, k) * std::abs(params[k]), fd * std::abs(params[k]), 1e-6 * largest)
          << "param " << k << " sample " << j;
    }
  }
}

// ---- The scene ----

TEST(Acpm, PlainSampleIsTheElasticaCrossingOnEveryRay) {
  // docs/spec/cantilever.md's reference crossings (independent exact elastica), 1e-6 relative.
  struct Case {
    Material m;
    double crossing_mm;
  };
  for (const Case& c : {Case{Fig8(), 33.5864}, Case{Fabric(0.0973, 0.0973, 0.0453, 130), 39.1287},
                        Case{Fabric(0.5168, 1.8856, 2.2683, 250), 70.4996}}) {
    const AcpmResult r = RunAcpm(c.m);
    EXPECT_EQ(r.model, AcpmModelKind::kElastica);
    EXPECT_NE(r.model_reason.find("plain sample"), std::string::npos) << r.model_reason;
    ASSERT_EQ(r.rays.size(), 17u);
    EXPECT_DOUBLE_EQ(r.rays.front().z, 0.005);
    EXPECT_NEAR(r.rays.back().z, 0.195, 1e-15);
    EXPECT_NEAR(r.rays[8].z, 0.1, 1e-15);
    for (const AcpmRay& ray : r.rays) {
      EXPECT_NEAR(units::MToMm(ray.overhang), c.crossing_mm, 1e-4);  // printed to 1e-4 mm
      EXPECT_DOUBLE_EQ(ray.bending_length, ray.overhang / 2.0);
      EXPECT_DOUBLE_EQ(ray.factor, 1.0);
      EXPECT_TRUE(std::isnan(ray.d));
      // 12 cm/min = 2 mm/s.
      EXPECT_NEAR(ray.device_time, units::MToMm(ray.overhang) / 2.0, 1e-12);
    }
    // The side profile ends at the crossing: its tip lies on the 41.5° line.
    ASSERT_FALSE(r.profile_x.empty());
    EXPECT_NEAR(std::atan2(-r.profile_y.back(), r.profile_x.back()), kStandardBarrierAngle, 1e-8);
  }
}

TEST(Acpm, FarAcrossSeamChangesNothing) {
  // A seam 300 mm behind the front: d ≥ 266 mm on the overhang, beyond d_max + fade = 120 mm,
  // and its band is on the platform. Same strip as plain: factor 1 to the solver's accuracy.
  AcpmOptions o;
  o.seam.direction = AcpmSeamDirection::kAcross;
  o.seam.profile = SeamPreset("C-plain");
  o.seam.position = 0.3;
  const AcpmResult r = RunAcpm(Fig8(), o);
  EXPECT_EQ(r.model, AcpmModelKind::kElastica);
  EXPECT_NE(r.model_reason.find("across"), std::string::npos);
  EXPECT_NEAR(r.rays[0].factor, 1.0, 1e-8);
  EXPECT_NEAR(units::MToMm(r.rays[0].d), 300.0, 1e-12);
}

TEST(Acpm, AcrossSeamStiffensAndItsBandWeighs) {
  const Material m = Fig8();
  AcpmOptions o;
  o.seam.direction = AcpmSeamDirection::kAcross;
  o.seam.profile = SeamPreset("C-plain");
  o.seam.position = 0.01;
  const AcpmResult seamed = RunAcpm(m, o);
  // Stiffer near the front: it reaches the barrier later, but the whole strip is never more
  // than S(0) = 9.07 times as stiff.
  EXPECT_GT(seamed.rays[0].factor, 1.5);
  EXPECT_LT(seamed.rays[0].factor, 9.07);
  for (const AcpmRay& ray : seamed.rays) EXPECT_DOUBLE_EQ(ray.overhang, seamed.rays[0].overhang);
  // Mass alone: a seam with no stiffening (B_f = 1) but 4 layers in its band bends the strip
  // more, so it crosses earlier: factor < 1.
  AcpmOptions heavy = o;
  heavy.seam.profile.type = "fitted";
  heavy.seam.profile.coefficients_mm = {0.0, 0.0, 1.0};
  const AcpmResult h = RunAcpm(m, heavy);
  EXPECT_LT(h.rays[0].factor, 1.0);
  heavy.seam.profile.layers = 1;  // no extra mass either: the plain strip
  EXPECT_NEAR(RunAcpm(m, heavy).rays[0].factor, 1.0, 1e-8);
  // The side profile: its curvature jumps by S(0⁺)/S at the seam... here simply: the tip is on
  // the barrier line.
  EXPECT_NEAR(std::atan2(-seamed.profile_y.back(), seamed.profile_x.back()),
              kStandardBarrierAngle, 1e-8);
}

TEST(Acpm, LinearLawAcrossSeamMatchesScaledLawWhenSIsConstantOverTheOverhang) {
  // A "seam" whose factor is 3 on all of [0, 300] mm, no extra mass: the whole overhang is 3×
  // stiffer, so for a linear law G scales by 3 exactly (c³ ∝ B) up to the L/2 rule, which is
  // the same relative bias for both: factor = 3 to solver accuracy.
  AcpmOptions o;
  o.seam.direction = AcpmSeamDirection::kAcross;
  o.seam.profile.type = "fitted";
  o.seam.profile.layers = 1;
  o.seam.profile.coefficients_mm = {0.0, 0.0, 3.0};
  o.seam.profile.influence_mm = 400;
  o.seam.position = 0.0;
  const AcpmResult r = RunAcpm(Fabric(0.0973, 0.0973, 0.0453, 130), o);
  EXPECT_NEAR(r.rays[0].factor, 3.0, 1e-8);
}

TEST(Acpm, SeamAlongIsAnsweredByTheShellModel) {
  // auto picks the shell for a seam along the push; the elastica cannot answer it.
  AcpmOptions o;
  o.num_rays = 3;
  o.seam.direction = AcpmSeamDirection::kAlong;
  o.seam.profile = SeamPreset("B-plain");
  const AcpmResult r = RunAcpm(Fig8(), o);
  EXPECT_EQ(r.model, AcpmModelKind::kShell);
  ASSERT_EQ(r.rays.size(), 3u);
  // The seam's ray (the centre) is stiffer than the plain fabric; the factor is taken against
  // the shell's own plain crossing at the same resolution (docs/methods/statics.md).
  EXPECT_GT(r.rays[1].factor, 1.5);
  EXPECT_NEAR(r.rays[0].factor, r.rays[2].factor, 1e-2 * r.rays[0].factor);
  o.model = AcpmModelKind::kElastica;
  EXPECT_THROW(RunAcpm(Fig8(), o), InputError);
}

TEST(Acpm, ShellModelPlugsIn) {
  // A stand-in shell model: each ray's crossing = the plain one times S(d)^(1/3) (uncoupled
  // strips, linear law). RunAcpm must hand it the rays and the seam, and report its answer.
  const Material m = Fabric(0.0973, 0.0973, 0.0453, 130);
  const double plain = RunAcpm(m).rays[0].overhang;
  AcpmOptions o;
  o.seam.direction = AcpmSeamDirection::kAlong;
  o.seam.profile = SeamPreset("A-plain");
  o.seam.position = 0.05;
  int calls = 0;
  o.shell_model = [&](const Material&, const AcpmOptions& scene, const std::vector<double>& z) {
    ++calls;
    AcpmCrossings c;
    c.converged = true;
    for (double zi : z)
      c.overhang.push_back(plain * std::cbrt(scene.seam.profile.Multiplier(units::MToMm(std::abs(zi - 0.05)))));
    c.solves = 42;
    return c;
  };
  const AcpmResult r = RunAcpm(m, o);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(r.model, AcpmModelKind::kShell);
  EXPECT_NE(r.model_reason.find("along"), std::string::npos);
  ASSERT_EQ(r.rays.size(), 17u);
  for (const AcpmRay& ray : r.rays) {
    EXPECT_NEAR(ray.d, std::abs(ray.z - 0.05), 1e-15);
    EXPECT_NEAR(ray.factor, o.seam.profile.Multiplier(units::MToMm(ray.d)), 1e-9);
  }
  EXPECT_EQ(r.solves, 43);  // + the elastica's plain reference
  const nlohmann::json j = AcpmResultToJson(r, m, o);
  EXPECT_EQ(j["model"], "shell");
  EXPECT_EQ(j["rays"].size(), 17u);
  EXPECT_NEAR(j["rays"][0]["d_mm"].get<double>(), 45.0, 1e-9);
  EXPECT_EQ(j["seam"]["profile"]["type"], "A-plain");
}

TEST(Acpm, RefusesBadScenes) {
  struct Case {
    std::function<void(AcpmOptions&)> set;
    const char* fragment;
  };
  const std::vector<Case> cases = {
      {[](AcpmOptions& o) { o.width = 0.25; }, "250 mm is wider than the ACPM200 takes"},
      {[](AcpmOptions& o) { o.width = -0.1; }, "width"},
      {[](AcpmOptions& o) { o.length = 0.0; }, "length"},
      {[](AcpmOptions& o) { o.ray_margin = -0.001; }, "ray margin"},
      {[](AcpmOptions& o) {
         o.seam = {AcpmSeamDirection::kAlong, SeamPreset("A-plain"), 0.25};
       },
       "seam at z = 250 mm lies outside the 200 mm wide sample"},
      {[](AcpmOptions& o) {
         o.seam = {AcpmSeamDirection::kAlong, SeamPreset("A-plain"), -0.01};
       },
       "negative"},
      {[](AcpmOptions& o) {
         o.seam = {AcpmSeamDirection::kAcross, SeamPreset("A-plain"), -0.01};
       },
       "negative"},
      {[](AcpmOptions& o) {
         o.seam = {AcpmSeamDirection::kAcross, SeamPreset("A-plain"), 0.31};
       },
       "outside the 300 mm long sample"},
      {[](AcpmOptions& o) {
         o.seam.direction = AcpmSeamDirection::kAcross;
         o.seam.profile = SeamPreset("A-plain");
       },
       "required"},
  };
  for (const Case& c : cases) {
    AcpmOptions o;
    c.set(o);
    std::string why;
    EXPECT_FALSE(o.Check(&why)) << c.fragment;
    EXPECT_NE(why.find(c.fragment), std::string::npos) << why;
    EXPECT_THROW(RunAcpm(Fig8(), o), InputError) << c.fragment;
  }
}

TEST(Acpm, TooStiffToReachTheBarrierIsBadInput) {
  // b = 50 gf·cm at 100 g/m²: bending length (B/ρg)^(1/3) = 171 mm, crossing ≈ 342 mm.
  const std::string e = ErrorOf([] { RunAcpm(Fabric(50, 50, 0, 100)); });
  EXPECT_NE(e.find("does not reach the barrier within 300 mm"), std::string::npos) << e;
  EXPECT_THROW(RunAcpm(Fabric(50, 50, 0, 100)), InputError);
  // A longer sample holds it.
  AcpmOptions longer;
  longer.length = 0.5;
  EXPECT_NEAR(units::MToMm(RunAcpm(Fabric(50, 50, 0, 100), longer).rays[0].overhang), 342.1, 1.0);
}

TEST(Acpm, NarrowSampleAndOneRay) {
  AcpmOptions o;
  o.width = 0.05;
  o.num_rays = 1;
  const AcpmResult r = RunAcpm(Fig8(), o);
  ASSERT_EQ(r.rays.size(), 1u);
  EXPECT_DOUBLE_EQ(r.rays[0].z, 0.025);
}

// The crossing length's sensitivities. A linear law's elastica scales as L ∝ (b2 / ρ)^(1/3):
// dL/dln b2 = L/3 = -dL/dln ρ exactly, and β is b2's twin. A nonlinear law's β still mirrors ρ
// (M_β = β M against the weight). A seam along (the shell) is refused before any work.
TEST(Acpm, SensitivitiesOfTheCrossingLengthFollowTheElasticasScaling) {
  AcpmOptions o;
  o.num_rays = 3;
  o.sensitivity = true;
  const Material dress = Fabric(0.0973, 0.0973, 0.0453, 130);
  const AcpmResult r = RunAcpm(dress, o);
  const double length = r.rays[0].overhang;
  const auto row = [&](const AcpmResult& res, const std::string& name) {
    for (const ParameterInfluence& s : res.sensitivities)
      if (s.parameter == name) return s;
    ADD_FAILURE() << name << " missing";
    return ParameterInfluence{};
  };
  ASSERT_EQ(r.sensitivities.size(), 3u);  // b2, beta, areal_density_gsm: b1, c1 move nothing
  EXPECT_NEAR(row(r, "b2").d_q_d_ln_p, length / 3.0, 1e-6 * length);
  EXPECT_NEAR(row(r, "areal_density_gsm").d_q_d_ln_p, -length / 3.0, 1e-6 * length);
  EXPECT_NEAR(row(r, "beta").d_q_d_ln_p, length / 3.0, 1e-6 * length);
  EXPECT_FALSE(std::isfinite(r.crossing_length_sigma));
  const AcpmResult f = RunAcpm(Fig8(), o);
  EXPECT_NEAR(row(f, "beta").d_q_d_ln_p, -row(f, "areal_density_gsm").d_q_d_ln_p,
              1e-5 * f.rays[0].overhang);
  EXPECT_GT(row(f, "b1").d_q_d_ln_p, 0.0);
  // A covariance gives σ = √(gᵀ C g).
  Material fitted = Fig8();
  fitted.fit["covariance_kes"] = {{1e-4, 0.0, 0.0}, {0.0, 1e-4, 0.0}, {0.0, 0.0, 1e-6}};
  const AcpmResult s = RunAcpm(fitted, o);
  double expected = 0.0;
  for (const char* name : {"b1", "b2", "c1"}) {
    const ParameterInfluence i = row(s, name);
    expected += i.change * i.change;  // independent: each term its sd times its slope
  }
  EXPECT_NEAR(s.crossing_length_sigma, std::sqrt(expected), 1e-9 * std::sqrt(expected));
  o.sensitivity_parameters = {"stretch.stiffness_N_per_m"};
  EXPECT_THROW(RunAcpm(Fig8(), o), InputError);  // the elastica takes no membrane
}

// The shell's sensitivities are central differences of whole shell runs at p ± 1 %: on a plain
// strip they are the exact elastica's within 1 %, and the shell takes the membrane too.
TEST(Acpm, ShellSensitivitiesMatchTheElasticasOnAPlainStrip) {
  AcpmOptions o;
  o.num_rays = 1;
  o.sensitivity = true;
  o.sensitivity_parameters = {"b1", "areal_density_gsm"};
  const AcpmResult exact = RunAcpm(Fig8(), o);
  o.model = AcpmModelKind::kShell;
  const AcpmResult shell = RunAcpm(Fig8(), o);
  ASSERT_EQ(shell.model, AcpmModelKind::kShell);
  ASSERT_EQ(shell.sensitivities.size(), 2u);
  for (const ParameterInfluence& e : exact.sensitivities)
    for (const ParameterInfluence& s : shell.sensitivities)
      if (s.parameter == e.parameter) {
        EXPECT_NEAR(s.d_q_d_ln_p, e.d_q_d_ln_p, 0.01 * std::abs(e.d_q_d_ln_p)) << s.parameter;
      }
  o.sensitivity_parameters = {"stretch.stiffness_N_per_m"};
  EXPECT_TRUE(std::isfinite(RunAcpm(Fig8(), o).sensitivities.at(0).d_q_d_ln_p));
}

constexpr double kOneDegree = std::numbers::pi / 180.0;  // [rad]

// The mean crossing length of a run of `o` (no sensitivities).
double MeanLength(const Material& m, AcpmOptions o) {
  o.sensitivity = false;
  const AcpmResult r = RunAcpm(m, o);
  double sum = 0.0;
  for (const AcpmRay& ray : r.rays) sum += ray.overhang;
  return sum / static_cast<double>(r.rays.size());
}

// The scene's and the seam's rows of the elastica (a seam across) against central differences
// of whole runs at steps 17-50 times the rows' own: the barrier ±0.2°, the seam ±0.5 mm, B_f
// scaled by e^(±0.005); within 1 %. A list of parameters, or Monte Carlo alone, leaves them out.
TEST(Acpm, SceneAndSeamRowsMatchDifferencesOfWholeRuns) {
  AcpmOptions o;
  o.num_rays = 1;
  o.seam.direction = AcpmSeamDirection::kAcross;
  o.seam.profile = SeamPreset("C-plain");
  o.seam.position = 0.02;
  o.sensitivity = true;
  const Material m = Fig8();
  const AcpmResult r = RunAcpm(m, o);
  ASSERT_EQ(r.scene_sensitivities.size(), 2u);
  ASSERT_EQ(r.seam_sensitivities.size(), 4u);
  EXPECT_EQ(r.scene_sensitivities[0].parameter, "barrier_angle");
  EXPECT_NEAR(r.scene_sensitivities[0].value, 41.5, 1e-9);
  EXPECT_EQ(r.scene_sensitivities[1].parameter, "seam_position");
  EXPECT_NEAR(r.scene_sensitivities[1].value, 20.0, 1e-9);
  const auto fd = [&](const std::function<void(AcpmOptions*, double)>& set, double h) {
    AcpmOptions up = o, down = o;
    set(&up, h);
    set(&down, -h);
    return (MeanLength(m, up) - MeanLength(m, down)) / (2.0 * h);
  };
  const double angle =
      fd([](AcpmOptions* s, double t) { s->barrier_angle += t; }, 0.2 * kOneDegree);
  const double at = fd([](AcpmOptions* s, double t) { s->seam.position += t; }, 5e-4);
  const double scale = fd(
      [](AcpmOptions* s, double t) {
        s->seam.profile.type = "fitted";
        for (double& a : s->seam.profile.coefficients_mm) a *= std::exp(t);
      },
      0.005);
  EXPECT_GT(angle, 0.0);  // a steeper barrier wants a longer overhang
  EXPECT_NEAR(r.scene_sensitivities[0].d_q_d_p, angle, 0.01 * std::abs(angle));
  EXPECT_NEAR(r.scene_sensitivities[1].d_q_d_p, at, 0.01 * std::abs(at));
  EXPECT_NEAR(r.seam_sensitivities[3].d_q_d_ln_p, scale, 0.01 * std::abs(scale));
  EXPECT_NEAR(r.scene_sensitivities[0].change, std::abs(angle) * 0.5 * kOneDegree,
              0.01 * std::abs(angle) * 0.5 * kOneDegree);
  const nlohmann::json j = AcpmResultToJson(r, m, o);
  EXPECT_EQ(j["seam_sensitivities"].size(), 4u);
  EXPECT_EQ(j["scene_sensitivities"][1]["parameter"], "seam_position");
  o.sensitivity_parameters = {"b1"};
  EXPECT_TRUE(RunAcpm(m, o).scene_sensitivities.empty());
  o.sensitivity_parameters.clear();
  o.sensitivity = false;
  o.monte_carlo_samples = 4;
  Material fitted = m;
  fitted.fit["covariance_kes"] = {{1e-8, 0.0, 0.0}, {0.0, 1e-8, 0.0}, {0.0, 0.0, 1e-9}};
  const AcpmResult mc = RunAcpm(fitted, o);
  EXPECT_FALSE(mc.sensitivities.empty());
  EXPECT_TRUE(mc.scene_sensitivities.empty());
  EXPECT_TRUE(mc.seam_sensitivities.empty());
}

// Through a stand-in shell: each ray's crossing L(z) = L0 (1 + 0.1 sin θ) (1 + 10 |z − z_s| / m)
// B_f(0)^(1/3), refusing (not converged) a scene that fails Check; the rows are its derivatives,
// differences of runs at ±1 %. A seam along has no position row (the real shell's mesh follows
// the seam), and a note says so; a seam across at the back edge takes a one-sided difference.
TEST(Acpm, SceneRowsThroughTheShellModel) {
  AcpmOptions o;
  o.num_rays = 3;
  o.seam.direction = AcpmSeamDirection::kAlong;
  o.seam.profile = SeamPreset("B-plain");
  o.seam.position = 0.2;
  o.sensitivity = true;
  constexpr double kL0 = 0.05;
  o.shell_model = [](const Material&, const AcpmOptions& scene, const std::vector<double>& z) {
    AcpmCrossings c;
    c.converged = scene.Check(&c.message);
    for (double zi : z)
      c.overhang.push_back(kL0 * (1.0 + 0.1 * std::sin(scene.barrier_angle)) *
                           (1.0 + 10.0 * std::abs(zi - scene.seam.position)) *
                           std::cbrt(scene.seam.profile.StiffnessFactor(0.0)));
    return c;
  };
  const AcpmResult r = RunAcpm(Fig8(), o);
  ASSERT_EQ(r.model, AcpmModelKind::kShell);
  ASSERT_EQ(r.scene_sensitivities.size(), 1u);  // the barrier only
  EXPECT_NE(r.notes.find("position of a seam along"), std::string::npos) << r.notes;
  const std::vector<double> z = o.RayPositions();
  double mean_factor = 0.0;  // the mean over the rays of (1 + 10 |z − z_s|)
  for (double zi : z) mean_factor += (1.0 + 10.0 * std::abs(zi - 0.2)) / 3.0;
  const double a0 = o.seam.profile.coefficients_mm[2], theta = o.barrier_angle;
  const double common = kL0 * std::cbrt(a0);
  EXPECT_NEAR(r.scene_sensitivities[0].d_q_d_p, common * 0.1 * std::cos(theta) * mean_factor,
              1e-3 * common);
  // Only a0 moves B_f(0): dL/dln a0 = L/3; a2 and a1 nothing.
  const double length = common * (1.0 + 0.1 * std::sin(theta)) * mean_factor;
  EXPECT_NEAR(r.seam_sensitivities[2].d_q_d_ln_p, length / 3.0, 1e-3 * length);
  EXPECT_NEAR(r.seam_sensitivities[0].d_q_d_p, 0.0, 1e-9);
  EXPECT_NEAR(r.seam_sensitivities[3].d_q_d_ln_p, length / 3.0, 1e-3 * length);

  // Across (the shell asked for), at the sample's back edge: z_s is then the seam's distance
  // behind the front, 300 mm, which every ray lies below:
  // dL/dz_s = 10 L0 (1 + 0.1 sin θ) a0^(1/3).
  o.model = AcpmModelKind::kShell;
  o.seam.direction = AcpmSeamDirection::kAcross;
  o.seam.position = o.length;
  const AcpmResult across = RunAcpm(Fig8(), o);
  ASSERT_EQ(across.scene_sensitivities.size(), 2u);
  EXPECT_NEAR(across.scene_sensitivities[1].d_q_d_p, 10.0 * common * (1.0 + 0.1 * std::sin(theta)),
              1e-6 * common);
  EXPECT_EQ(across.notes.find("position of a seam along"), std::string::npos);
}

// --monte-carlo: where the covariance is small the law is linear over it and the sampled σ is
// the linear one; the shipped fit's covariance (c1 ±61 %) is not, and the note says so.
TEST(Acpm, MonteCarloSigmaMatchesTheLinearOneWhereTheLawIsLinearOverTheCovariance) {
  AcpmOptions o;
  o.num_rays = 1;
  o.monte_carlo_samples = 400;
  Material small = Fig8();
  small.fit["covariance_kes"] = {{1e-8, 0.0, 0.0}, {0.0, 1e-8, 0.0}, {0.0, 0.0, 1e-9}};
  const AcpmResult r = RunAcpm(small, o);
  ASSERT_TRUE(r.monte_carlo.has_value());
  EXPECT_FALSE(r.sensitivities.empty());  // implied: the linear σ beside the sampled one
  EXPECT_EQ(r.monte_carlo->samples, 400);
  EXPECT_EQ(r.monte_carlo->failed, 0);
  EXPECT_DOUBLE_EQ(r.monte_carlo->linear_sigma, r.crossing_length_sigma);
  EXPECT_NEAR(r.monte_carlo->ratio, 1.0, 0.12);  // sampling error 3.5 %
  EXPECT_NEAR(r.monte_carlo->mean, r.rays[0].overhang, 3.0 * r.crossing_length_sigma / 20.0);
  const nlohmann::json j = AcpmResultToJson(r, small, o);
  EXPECT_NEAR(j["monte_carlo"]["sigma"].get<double>(), 1e3 * r.monte_carlo->sigma, 1e-12);
  EXPECT_TRUE(j["crossing_length_sigma_mm"].is_number());

  const Material fitted = ReadMaterial(std::string(TEXTILE_SOURCE_DIR) +
                                           "/tests/data/sensitivity/fig8-fitted.json");
  const AcpmResult wide = RunAcpm(fitted, o);
  ASSERT_TRUE(wide.monte_carlo.has_value());
  EXPECT_GT(wide.monte_carlo->ratio, 1.4);
  EXPECT_NE(wide.monte_carlo->note.find("not linear"), std::string::npos) << wide.monte_carlo->note;

  EXPECT_THROW(RunAcpm(Fig8(), o), InputError);  // no covariance
  o.monte_carlo_samples = 1;
  EXPECT_THROW(RunAcpm(small, o), InputError);
}

}  // namespace
}  // namespace textile
