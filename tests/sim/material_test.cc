#include "textile/sim/law/material.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

const std::string kSamples = std::string(TEXTILE_SOURCE_DIR) + "/samples/materials/";
const std::string kBad = std::string(TEXTILE_SOURCE_DIR) + "/tests/data/materials/";

TEST(Material, AcceptsTechnicalFabricsAndRefusesBeyondTheTextileRange) {
  // A law fitted to a real technical fabric's photo: b1 ~ 8600 gf·cm softening to 119 gf·cm at
  // κ0 = 0.005 /cm (|c1| ~ 8e5 gf·cm²); the range now reaches composite prepregs (1e5 gf·cm).
  const Material technical = ParseMaterialJson(
      R"({"areal_density_gsm": 1387, "bending": {"units": "kes", "b1": 8557.3, "b2": 119.37,
          "c1": -816710}})",
      "technical.json");
  EXPECT_NEAR(technical.bending.b1_kes(), 8557.3, 1e-9);
  EXPECT_NEAR(units::SiCurvatureToKes(technical.bending.kappa0()), 0.0051658, 1e-6);
  for (const char* text :
       {R"({"areal_density_gsm": 1387, "bending": {"units": "kes", "b1": 2e5, "b2": 100, "c1": -1e7}})",
        R"({"areal_density_gsm": 200, "bending": {"units": "kes", "b1": 0.1, "b2": 0.2, "c1": 1e6}})"}) {
    EXPECT_THROW(ParseMaterialJson(text, "beyond.json"), InputError) << text;
  }
}

TEST(Material, ReadsThePapersFabrics) {
  const Material fig8 = ReadMaterial(kSamples + "pabst-fig8.json");
  EXPECT_DOUBLE_EQ(fig8.areal_density, 0.2);
  EXPECT_NEAR(fig8.bending.b1_kes(), 0.1, 1e-15);
  EXPECT_NEAR(fig8.bending.b2_kes(), 0.0892, 1e-15);
  EXPECT_NEAR(fig8.bending.c1_kes(), -0.0092, 1e-15);
  const Material dress = ReadMaterial(kSamples + "pabst-dress.json");
  EXPECT_EQ(dress.bending.kappa0(), 0.0);
  const Material inter = ReadMaterial(kSamples + "pabst-interlining.json");
  EXPECT_NEAR(units::SiCurvatureToKes(inter.bending.kappa0()), (1.8856 - 0.5168) / (2 * 2.2683),
              1e-12);
}

TEST(Material, SiAndKesUnitsAgree) {
  const Material kes = ParseMaterialJson(
      R"({"areal_density_gsm": 180, "bending": {"units": "kes", "b1": 0.1, "b2": 0.0892, "c1": -0.0092}})",
      "kes");
  const Material si = ParseMaterialJson(
      R"({"areal_density_gsm": 180, "bending": {"units": "si", "b1": 9.80665e-6, "b2": 8.7475318e-6, "c1": -9.022118e-9}})",
      "si");
  EXPECT_NEAR(si.bending.b1(), kes.bending.b1(), 1e-15);
  EXPECT_NEAR(si.bending.b2(), kes.bending.b2(), 1e-13);
  EXPECT_NEAR(si.bending.c1(), kes.bending.c1(), 1e-15);
}

TEST(Material, DefaultsAndOptionalFields) {
  const Material m = ParseMaterialJson(
      R"({"areal_density_gsm": 180, "bending": {"units": "kes", "b1": 0.1, "b2": 0.0892, "c1": -0.0092},
          "bending_weft": {"units": "kes", "b1": 0.08, "b2": 0.07, "c1": -0.006}, "beta": 1.5,
          "stretch": {"stiffness_N_per_m": 2000}, "friction": 0.5})",
      "opt");
  ASSERT_TRUE(m.bending_weft.has_value());
  EXPECT_NEAR(m.bending_weft->b1_kes(), 0.08, 1e-15);
  EXPECT_DOUBLE_EQ(m.beta, 1.5);
  EXPECT_NEAR(m.EffectiveLaw().b1(), 1.5 * m.bending.b1(), 1e-18);
  EXPECT_DOUBLE_EQ(m.stretch_stiffness, 2000.0);
  EXPECT_DOUBLE_EQ(m.poisson, 0.3);
  EXPECT_DOUBLE_EQ(m.friction, 0.5);
}

TEST(Material, CompressionRatioDefaultsAndSurvivesTheRoundTrip) {
  const std::string law = R"("bending": {"units": "kes", "b1": 0.1, "b2": 0.0892, "c1": -0.0092})";
  const Material plain = ParseMaterialJson(R"({"areal_density_gsm": 180, )" + law + "}", "plain");
  EXPECT_EQ(plain.compression_ratio, kDefaultCompressionRatio);
  EXPECT_FALSE(MaterialToJson(plain)["stretch"].contains("compression_ratio"));
  const Material soft = ParseMaterialJson(
      R"({"areal_density_gsm": 180, )" + law + R"(, "stretch": {"compression_ratio": 0.02}})",
      "soft");
  EXPECT_DOUBLE_EQ(soft.compression_ratio, 0.02);
  EXPECT_DOUBLE_EQ(soft.stretch_stiffness, 1000.0);
  EXPECT_DOUBLE_EQ(ParseMaterialJson(MaterialToJson(soft).dump(), "round trip").compression_ratio,
                   0.02);
  EXPECT_THROW(ParseMaterialJson(R"({"areal_density_gsm": 180, )" + law +
                                     R"(, "stretch": {"compression_ratio": 1.5}})",
                                 "above one"),
               InputError);
}

TEST(Material, JsonRoundTrip) {
  const Material a = ReadMaterial(kSamples + "pabst-interlining.json");
  const Material b = ParseMaterialJson(MaterialToJson(a).dump(), "round trip");
  EXPECT_NEAR(b.bending.b1(), a.bending.b1(), 1e-18);
  EXPECT_NEAR(b.bending.b2(), a.bending.b2(), 1e-18);
  EXPECT_NEAR(b.bending.c1(), a.bending.c1(), 1e-20);
  EXPECT_DOUBLE_EQ(b.areal_density, a.areal_density);
  EXPECT_EQ(b.name, a.name);
  EXPECT_EQ(b.extra, a.extra);
}

TEST(Material, AMeasuredBiasLawIsReadCheckedWrittenAndBlendedAt45Degrees) {
  const std::string text = R"({"areal_density_gsm": 200,
    "bending": {"units": "kes", "b1": 0.1, "b2": 0.0892, "c1": -0.0092},
    "bending_weft": {"units": "kes", "b1": 0.06, "b2": 0.05, "c1": -0.004},
    "bending_bias": {"units": "kes", "b1": 0.05, "b2": 0.04, "c1": -0.003},
    "beta": 2})";
  const Material m = ParseMaterialJson(text, "bias.json");
  ASSERT_TRUE(m.bending_bias.has_value());
  EXPECT_NEAR(m.bending_bias->b1_kes(), 0.05, 1e-12);
  EXPECT_NEAR(m.EffectiveBiasLaw()->b1_kes(), 0.1, 1e-12);  // β applied
  const Material back = ParseMaterialJson(MaterialToJson(m).dump(), "round trip");
  ASSERT_TRUE(back.bending_bias.has_value());
  EXPECT_NEAR(back.bending_bias->c1_kes(), -0.003, 1e-12);
  // Bending at 45° is the measured bias (β applied), not the mean of warp and weft (0.08 x 2).
  const double k = 30.0;  // [1/m]
  EXPECT_DOUBLE_EQ(m.EffectiveLawAt(0.25 * M_PI).Moment(k), m.EffectiveBiasLaw()->Moment(k));
  EXPECT_DOUBLE_EQ(m.EffectiveLawAt(0.0).Moment(k), m.EffectiveLaw().Moment(k));
  EXPECT_DOUBLE_EQ(m.EffectiveLawAt(0.5 * M_PI).Moment(k), m.EffectiveWeftLaw().Moment(k));
  // A bias law a file would refuse is named by its field.
  Material bad = m;
  bad.bending_bias = BendingLaw::FromKes(2e5, 100, -1e7);
  std::string why;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_EQ(why.rfind("bending_bias", 0), 0u) << why;
}

TEST(Material, SplineLawsReadInKesAndSiAndSurviveTheRoundTrip) {
  const Material kes = ParseMaterialJson(
      R"({"areal_density_gsm": 300, "bending": {"law": "spline", "units": "kes",
          "kappa": [0, 0.02, 0.1, 0.5, 2], "moment": [0, 0.2, 0.45, 0.56, 0.72],
          "moment_sd": [0, 0.01, 0.01, 0.02, 0.03]},
          "bending_weft": {"law": "spline", "units": "si", "kappa": [0, 2, 10, 50, 200],
          "moment": [0, 0.0019613, 0.0044130, 0.0054917, 0.0070608]}})",
      "spline");
  ASSERT_TRUE(kes.bending.is_spline());
  ASSERT_TRUE(kes.bending_weft && kes.bending_weft->is_spline());
  // The same knots, once in KES and once in SI (moments to 5 digits).
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_NEAR(kes.bending.knot_kappa()[i], kes.bending_weft->knot_kappa()[i], 1e-13);
    EXPECT_NEAR(kes.bending.knot_moment()[i], kes.bending_weft->knot_moment()[i], 1e-7);
  }
  EXPECT_NEAR(kes.bending.knot_moment_sd()[4], 0.03 * units::kGramForce, 1e-18);
  EXPECT_TRUE(kes.bending_weft->knot_moment_sd().empty());
  // Written in KES; read back to rounding (1/cm -> 1/m -> 1/cm: an ulp or two).
  const nlohmann::json written = MaterialToJson(kes);
  EXPECT_EQ(written["bending"]["law"], "spline");
  EXPECT_EQ(written["bending"]["units"], "kes");
  EXPECT_FALSE(written["bending"].contains("b1"));
  EXPECT_FALSE(written["bending_weft"].contains("moment_sd"));
  const Material back = ParseMaterialJson(written.dump(), "round trip");
  for (const auto& [a, b] : {std::pair{&kes.bending, &back.bending},
                             std::pair{&*kes.bending_weft, &*back.bending_weft}}) {
    ASSERT_TRUE(b->is_spline());
    ASSERT_EQ(b->knot_kappa().size(), a->knot_kappa().size());
    for (size_t i = 0; i < a->knot_kappa().size(); ++i) {
      EXPECT_NEAR(b->knot_kappa()[i], a->knot_kappa()[i], 1e-15 * a->knot_kappa().back());
      EXPECT_NEAR(b->knot_moment()[i], a->knot_moment()[i], 1e-15 * a->knot_moment().back());
    }
    EXPECT_EQ(b->knot_moment_sd().size(), a->knot_moment_sd().size());
  }
  // β scales the spline like any law.
  Material scaled = kes;
  scaled.beta = 2.0;
  EXPECT_NEAR(scaled.EffectiveLaw().Moment(30.0), 2.0 * kes.bending.Moment(30.0),
              1e-14 * kes.bending.Moment(30.0));
  // A Pabst law is written as before (no "law" key), and "law": "pabst" reads as one.
  const Material fig8 = ReadMaterial(kSamples + "pabst-fig8.json");
  EXPECT_EQ(MaterialToJson(fig8)["bending"].dump(),
            R"({"b1":0.1,"b2":0.0892,"c1":-0.0092,"units":"kes"})");
  const Material explicit_pabst = ParseMaterialJson(
      R"({"areal_density_gsm": 200,
          "bending": {"law": "pabst", "units": "kes", "b1": 0.1, "b2": 0.0892, "c1": -0.0092}})",
      "explicit");
  EXPECT_FALSE(explicit_pabst.bending.is_spline());
  EXPECT_EQ(explicit_pabst.bending.b1(), fig8.bending.b1());
}

struct BadCase {
  const char* file;
  const char* field;    // must appear in the message
  const char* problem;  // must appear in the message
};

class BadMaterial : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadMaterial, IsRejectedWithFileFieldAndProblem) {
  const BadCase& c = GetParam();
  const std::string path = kBad + c.file;
  try {
    ReadMaterial(path);
    FAIL() << c.file << " was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(c.field), std::string::npos) << what;
    EXPECT_NE(what.find(c.problem), std::string::npos) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Material, BadMaterial,
    ::testing::Values(BadCase{"empty.json", "", "empty material file"},
                      BadCase{"not-json.json", "", "not valid JSON"},
                      BadCase{"truncated.json", "", "not valid JSON"},
                      BadCase{"array.json", "(top level)", "JSON object"},
                      BadCase{"missing-gsm.json", "areal_density_gsm", "missing"},
                      BadCase{"missing-bending.json", "bending", "missing"},
                      BadCase{"missing-b2.json", "bending.b2", "missing"},
                      BadCase{"unknown-units.json", "bending.units", "unknown units 'mN'"},
                      BadCase{"nan.json", "", "not valid JSON"},
                      BadCase{"inf.json", "", "number overflow parsing '1e999'"},
                      BadCase{"string-number.json", "areal_density_gsm", "must be a number"},
                      BadCase{"b1-zero.json", "bending.b1", "must be > 0"},
                      BadCase{"b2-negative.json", "bending.b2", "must be > 0"},
                      BadCase{"kappa0-negative.json", "bending", "kappa0 = (b2 - b1)/(2 c1) < 0"},
                      BadCase{"gsm-zero.json", "areal_density_gsm", "must be > 0"},
                      BadCase{"gsm-negative.json", "areal_density_gsm", "must be > 0"},
                      BadCase{"gsm-absurd.json", "areal_density_gsm", "suspicious"},
                      BadCase{"beta-zero.json", "beta", "must be > 0"},
                      BadCase{"beta-negative.json", "beta", "must be > 0"},
                      BadCase{"si-with-kes-numbers.json", "bending.b1", "is this file in kes?"},
                      BadCase{"b-absurdly-small.json", "bending.b1", "suspicious"},
                      BadCase{"c1-absurd.json", "bending.c1", "suspicious"},
                      BadCase{"unknown-field.json", "bendng", "unknown field"},
                      BadCase{"weft-invalid.json", "bending_weft", "kappa0"},
                      BadCase{"poisson-bad.json", "stretch.poisson", "[0, 0.5)"},
                      BadCase{"stretch-negative.json", "stretch.stiffness_N_per_m", "must be > 0"},
                      BadCase{"compression-zero.json", "stretch.compression_ratio", "[0.001, 1]"},
                      BadCase{"friction-negative.json", "friction", "[0, 10]"},
                      BadCase{"bending-not-object.json", "bending", "must be an object"},
                      BadCase{"spline-not-monotone.json", "bending.moment[3]", "is not above"},
                      BadCase{"spline-length-mismatch.json", "bending.moment",
                              "3 values for 4 knots"},
                      BadCase{"spline-kappa0-nonzero.json", "bending.kappa[0]", "must be 0"},
                      BadCase{"spline-negative.json", "bending.moment[1]", "-0.01 is not above"},
                      BadCase{"spline-null.json", "bending.moment[2]",
                              "must be a number, got null"},
                      BadCase{"spline-too-few.json", "bending.kappa", "at least 3"},
                      BadCase{"spline-with-b1.json", "bending.b1", "unknown field"},
                      BadCase{"spline-unknown-law.json", "bending.law", "unknown law 'cubic'"},
                      BadCase{"spline-si-with-kes-numbers.json", "bending.moment[1]",
                              "is this file in kes?"},
                      BadCase{"spline-missing-moment.json", "bending.moment", "missing"},
                      BadCase{"spline-sd-negative.json", "bending.moment_sd[1]", "must be >= 0"},
                      BadCase{"spline-kappa-not-array.json", "bending.kappa", "must be an array"},
                      BadCase{"spline-weft-invalid.json", "bending_weft.kappa[2]", "is not above"},
                      BadCase{"membrane-curve-not-monotone.json", "stretch.warp.curve[1]", "is not monotone"},
                      BadCase{"membrane-curve-percent.json", "stretch.warp.curve[0]", "strain is a fraction"},
                      BadCase{"membrane-shear-negative.json", "stretch.shear.modulus_N_per_m", "must be > 0 N/m"},
                      BadCase{"membrane-shear-zero.json", "stretch.shear.kes.G_gf_per_cm_deg", "must be > 0 gf/cm/deg"},
                      BadCase{"membrane-emt-above-100.json", "stretch.warp.kes.EMT_percent", "at most 100 %"},
                      BadCase{"membrane-emt-zero.json", "stretch.warp.kes.EMT_percent", "must be > 0 %"},
                      BadCase{"membrane-emt-fraction.json", "stretch.warp.kes.EMT_percent", "looks like a fraction: EMT is in %"},
                      BadCase{"membrane-lt-outside.json", "stretch.weft.kes.LT", "must lie in (0.1, 1.25)"},
                      BadCase{"membrane-wt-disagrees.json", "stretch.warp.kes.WT_gfcm_per_cm2", "disagrees with LT"},
                      BadCase{"membrane-compression-tiny.json", "stretch.compression_ratio", "[0.001, 1]"},
                      BadCase{"membrane-two-forms.json", "stretch.warp", "got modulus_N_per_m and kes"},
                      BadCase{"membrane-shear-in-newton.json", "stretch.shear.kes.G_gf_per_cm_deg", "looks like N/m: use modulus_N_per_m"},
                      BadCase{"membrane-poisson-orthotropic.json", "stretch.poisson", "no Poisson coupling"},
                      BadCase{"membrane-stiffness-and-warp.json", "stretch.stiffness_N_per_m", "ambiguous"},
                      BadCase{"membrane-buckling-large.json", "stretch.buckling_strain", "[0, 0.05]"},
                      BadCase{"membrane-kes-no-lt.json", "stretch.warp.kes", "needs LT or WT_gfcm_per_cm2"},
                      BadCase{"membrane-unknown-key.json", "stretch.warp.modulus", "unknown field"},
                      BadCase{"membrane-eb5-zero.json", "stretch.shear.fast.EB5_percent", "must be > 0 %"},
                      BadCase{"membrane-e100-above-100.json", "stretch.weft.fast.E100_percent", "at most 100 %"},
                      BadCase{"membrane-2hg-negative.json", "stretch.shear.kes.2HG_gf_per_cm", "must be >= 0 gf/cm"},
                      BadCase{"membrane-empty-form.json", "stretch.warp", "needs one of modulus_N_per_m, curve, kes, fast"}),
    [](const auto& info) {
      std::string n = info.param.file;
      n = n.substr(0, n.find('.'));
      for (char& ch : n)
        if (ch == '-') ch = '_';
      return n;
    });

TEST(Material, MissingFileIsInputError) {
  EXPECT_THROW(ReadMaterial(kBad + "does-not-exist.json"), InputError);
}

}  // namespace
}  // namespace textile

namespace textile {
namespace {

// Material::Check says what the parser says of the same material written out (MaterialToJson),
// without the file name: a fit's law is refused with the wording a material file gets.
TEST(MaterialCheck, RefusesWhatTheParserRefusesInItsWords) {
  std::vector<std::pair<std::string, Material>> bad;
  const auto with = [&bad](const std::string& what, auto change) {
    Material m;
    m.areal_density = 0.2;
    m.bending = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
    change(m);
    bad.emplace_back(what, m);
  };
  with("b1 beyond the range", [](Material& m) { m.bending = BendingLaw::FromKes(2e5, 100, -1e7); });
  with("b2 below the range",
       [](Material& m) { m.bending = BendingLaw::FromKes(0.1, 1e-6, -1e-4); });
  with("|c1| above the range", [](Material& m) { m.bending = BendingLaw::FromKes(1e4, 10, -1e9); });
  with("kink beyond a kilometre",
       [](Material& m) { m.bending = BendingLaw::FromKes(0.1, 0.2, 1e6); });
  with("weft law beyond the range",
       [](Material& m) { m.bending_weft = BendingLaw::FromKes(2e5, 100, -1e7); });
  with("bias law beyond the range",
       [](Material& m) { m.bending_bias = BendingLaw::FromKes(2e5, 100, -1e7); });
  with("spline secant below the range", [](Material& m) {
    m.bending = BendingLaw::FromSplineKes({0.0, 1.0, 2.0}, {0.0, 1e-7, 2e-7}, {});
  });
  with("areal density", [](Material& m) { m.areal_density = 20.0; });
  with("beta", [](Material& m) { m.beta = 1e4; });
  with("negative beta", [](Material& m) { m.beta = -1.0; });
  with("stretch stiffness", [](Material& m) { m.stretch_stiffness = 1e8; });
  with("poisson", [](Material& m) { m.poisson = 0.5; });
  with("compression ratio", [](Material& m) { m.compression_ratio = 1e-4; });
  with("friction", [](Material& m) { m.friction = 11.0; });
  for (const auto& [what, m] : bad) {
    std::string why;
    EXPECT_FALSE(m.Check(&why)) << what;
    EXPECT_FALSE(why.empty()) << what;
    try {
      ParseMaterialJson(MaterialToJson(m).dump(), "fitted law");
      ADD_FAILURE() << what << ": the parser took it";
    } catch (const InputError& e) {
      EXPECT_EQ("fitted law: " + why, e.what()) << what;
    }
  }
}

TEST(MaterialCheck, NamesTheFieldAndTheRange) {
  Material m;
  m.areal_density = 0.2;
  m.bending = BendingLaw::FromKes(2e5, 100, -1e7);
  std::string why;
  ASSERT_FALSE(m.Check(&why));
  EXPECT_EQ(why,
            "bending.b1: suspicious magnitude 200000 gf·cm, outside the textile range 1e-05 .. "
            "100000 gf·cm (units: kes)");
  EXPECT_FALSE(m.Check(nullptr));  // why is optional
  // A bound's refusal quotes the value, as JsonFields words it for a file.
  m.bending = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  m.poisson = 0.5;
  ASSERT_FALSE(m.Check(&why));
  EXPECT_EQ(why, "stretch.poisson: must lie in [0, 0.5), got 0.5");
}

TEST(MaterialCheck, AcceptsTheSamplesAndTheDefaults) {
  for (const char* name :
       {"pabst-fig8", "pabst-fig8-kes", "pabst-dress", "pabst-interlining", "knee-spline"}) {
    std::string why = "unset";
    EXPECT_TRUE(ReadMaterial(kSamples + name + ".json").Check(&why)) << name << ": " << why;
    EXPECT_EQ(why, "") << name;
  }
  Material m;
  m.areal_density = 0.2;
  EXPECT_TRUE(m.Check(nullptr));
}

}  // namespace
}  // namespace textile

namespace textile {
namespace {

// The membrane block (docs/methods/materials.md, "Membrane").
const std::string kLaw =
    R"("areal_density_gsm": 200, "bending": {"units": "kes", "b1": 0.1, "b2": 0.0892, "c1": -0.0092})";

Material WithStretch(const std::string& stretch) {
  return ParseMaterialJson("{" + kLaw + R"(, "stretch": )" + stretch + "}", "membrane.json");
}

// The message ParseMaterialJson gives for this stretch block ("" when accepted).
std::string StretchError(const std::string& stretch) {
  try {
    WithStretch(stretch);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool Lists(const Material& m, const std::string& field) {
  return std::find(m.defaulted.begin(), m.defaulted.end(), field) != m.defaulted.end();
}

// Forces of two curves agree at strains across the KES range, in tension and compression.
void ExpectSameCurve(const TensileCurve& a, const TensileCurve& b, const std::string& what) {
  constexpr double kRelative = 1e-12;  // the brief's round-trip tolerance
  for (double e : {-0.01, 0.001, 0.005, 0.01, 0.03, 0.06, 0.2}) {
    EXPECT_NEAR(a.Force(e), b.Force(e), kRelative * std::abs(b.Force(e))) << what << " at " << e;
  }
}

TEST(MaterialMembrane, StiffnessAndPoissonAloneAreTheIsotropicMembrane) {
  const Material both = WithStretch(R"({"stiffness_N_per_m": 2000, "poisson": 0.2})");
  EXPECT_FALSE(both.orthotropic.has_value());
  EXPECT_DOUBLE_EQ(both.stretch_stiffness, 2000.0);
  EXPECT_DOUBLE_EQ(both.poisson, 0.2);
  EXPECT_EQ(both.defaulted, std::vector<std::string>{"stretch.compression_ratio"});
  EXPECT_DOUBLE_EQ(both.MembraneModulus(), 2000.0);
  const Material no_poisson = WithStretch(R"({"stiffness_N_per_m": 2000})");
  EXPECT_FALSE(no_poisson.orthotropic.has_value());
  EXPECT_DOUBLE_EQ(no_poisson.poisson, kDefaultPoisson);
  EXPECT_TRUE(Lists(no_poisson, "stretch.poisson"));
  EXPECT_FALSE(Lists(no_poisson, "stretch.stiffness_N_per_m"));
  // The samples are isotropic, as before.
  const Material fig8 = ReadMaterial(kSamples + "pabst-fig8.json");
  EXPECT_FALSE(fig8.orthotropic.has_value());
  EXPECT_DOUBLE_EQ(fig8.stretch_stiffness, 1000.0);
}

TEST(MaterialMembrane, NoMembraneFieldIsTheDefaultOrthotropicMembrane) {
  for (const std::string& text :
       {"{" + kLaw + "}", "{" + kLaw + R"(, "stretch": {}})", "{" + kLaw + R"(, "stretch": {"compression_ratio": 0.05}})"}) {
    const Material m = ParseMaterialJson(text, "defaults.json");
    ASSERT_TRUE(m.orthotropic.has_value()) << text;
    const OrthotropicMembrane d = DefaultOrthotropicMembrane();
    ExpectSameCurve(m.orthotropic->warp, d.warp, "warp");
    ExpectSameCurve(m.orthotropic->weft, d.weft, "weft");
    EXPECT_EQ(m.orthotropic->shear_modulus, d.shear_modulus);
    for (const char* f : {"stretch.warp", "stretch.weft", "stretch.shear"})
      EXPECT_TRUE(Lists(m, f)) << f << " in " << text;
    EXPECT_EQ(Lists(m, "stretch.compression_ratio"),
              text.find("compression_ratio") == std::string::npos);
  }
  // The defaults are the documented KES values: EMT meets 500 gf/cm, G = 0.8 gf/cm/deg.
  const OrthotropicMembrane d = DefaultOrthotropicMembrane();
  EXPECT_NEAR(d.warp.Force(kDefaultWarpEmtPercent / 100), kKesMaxLoad, 1e-9 * kKesMaxLoad);
  EXPECT_NEAR(d.weft.Force(kDefaultWeftEmtPercent / 100), kKesMaxLoad, 1e-9 * kKesMaxLoad);
  EXPECT_GT(d.warp.SmallStrainModulus(), d.weft.SmallStrainModulus());  // warp the stiffer
  EXPECT_NEAR(d.shear_modulus, 45.0, 0.1);
}

TEST(MaterialMembrane, ReadsEveryTensileForm) {
  const Material m = WithStretch(
      R"({"warp": {"modulus_N_per_m": 1500},
          "weft": {"curve": [[0.01, 5], [0.02, 20], [0.04, 150], [0.05, 490]]},
          "shear": {"modulus_N_per_m": 30}})");
  ASSERT_TRUE(m.orthotropic.has_value());
  ExpectSameCurve(m.orthotropic->warp, TensileCurve::Linear(1500.0), "modulus");
  ExpectSameCurve(m.orthotropic->weft,
                  TensileCurve::FromPoints({0.01, 0.02, 0.04, 0.05}, {5, 20, 150, 490}), "curve");
  EXPECT_EQ(m.orthotropic->shear_modulus, 30.0);
  EXPECT_EQ(m.defaulted, std::vector<std::string>{"stretch.compression_ratio"});

  const Material kes = WithStretch(
      R"({"warp": {"kes": {"EMT_percent": 4, "LT": 0.65}},
          "weft": {"kes": {"EMT_percent": 6, "WT_gfcm_per_cm2": 9.75}},
          "shear": {"kes": {"G_gf_per_cm_deg": 0.8, "2HG_gf_per_cm": 1.2}}})");
  ExpectSameCurve(kes.orthotropic->warp, TensileCurveFromKes(4.0, 0.65), "kes LT");
  // WT alone gives LT = WT / (½·500·EMT/100) = 9.75 / 15 = 0.65.
  ExpectSameCurve(kes.orthotropic->weft, TensileCurveFromKes(6.0, 9.75 / 15.0), "kes WT");
  EXPECT_EQ(kes.orthotropic->shear_modulus, KesShearToNewtonPerMetre(0.8));
  // LT and WT both, agreeing within 5 %: LT decides.
  const Material both = WithStretch(
      R"({"warp": {"kes": {"EMT_percent": 4, "LT": 0.65, "WT_gfcm_per_cm2": 6.7}}})");
  ExpectSameCurve(both.orthotropic->warp, TensileCurveFromKes(4.0, 0.65), "kes LT and WT");

  const Material fast =
      WithStretch(R"({"warp": {"fast": {"E100_percent": 2}}, "shear": {"fast": {"EB5_percent": 3}}})");
  ExpectSameCurve(fast.orthotropic->warp, TensileCurveFromFastE100(2.0), "fast");
  EXPECT_DOUBLE_EQ(fast.orthotropic->shear_modulus, 123.0 / 3.0);
  EXPECT_TRUE(Lists(fast, "stretch.weft"));
  EXPECT_FALSE(Lists(fast, "stretch.warp"));
  EXPECT_FALSE(Lists(fast, "stretch.shear"));
}

// The shipped KES sample: the Fig. 8 fabric's bending with a lab's KES-FB1 membrane block. Its
// WT agrees with LT and EMT (the parser checks within 5 %), and the only default it takes is the
// in-plane compression, which KES-FB1 does not measure.
TEST(MaterialMembrane, TheKesSampleIsTheFig8FabricWithAMeasuredLikeMembrane) {
  const Material kes = ReadMaterial(kSamples + "pabst-fig8-kes.json");
  const Material fig8 = ReadMaterial(kSamples + "pabst-fig8.json");
  EXPECT_EQ(kes.areal_density, fig8.areal_density);
  EXPECT_EQ(kes.bending.b1(), fig8.bending.b1());
  EXPECT_EQ(kes.bending.b2(), fig8.bending.b2());
  EXPECT_EQ(kes.bending.c1(), fig8.bending.c1());
  ASSERT_TRUE(kes.orthotropic.has_value());
  ExpectSameCurve(kes.orthotropic->warp, TensileCurveFromKes(3.5, 0.68), "warp");
  ExpectSameCurve(kes.orthotropic->weft, TensileCurveFromKes(5.8, 0.62), "weft");
  EXPECT_EQ(kes.orthotropic->shear_modulus, KesShearToNewtonPerMetre(0.72));
  EXPECT_EQ(kes.defaulted, std::vector<std::string>{"stretch.compression_ratio"});
  EXPECT_EQ(kes.compression_ratio, kDefaultCompressionRatio);
  // The weft is the more extensible direction, as in a woven apparel fabric.
  EXPECT_LT(kes.orthotropic->weft.Force(0.02), kes.orthotropic->warp.Force(0.02));
}

// A material of a law alone (what a fit writes) reads as a file without `stretch`: the membrane's
// documented defaults, each listed; the file it makes claims no membrane, and reads back the same.
TEST(MaterialMembrane, ALawOnlyMaterialLeavesTheMembraneToItsDefaults) {
  const BendingLaw law = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  const Material m = LawOnlyMaterial(law, 0.2);
  const Material file = ParseMaterialJson(
      R"({"areal_density_gsm": 200, "bending": {"units": "kes", "b1": 0.1, "b2": 0.0892, "c1": -0.0092}})",
      "law-only.json");
  EXPECT_EQ(m.areal_density, 0.2);
  EXPECT_EQ(m.bending.b1(), law.b1());
  EXPECT_EQ(m.defaulted, file.defaulted);
  EXPECT_GE(m.defaulted.size(), 4u);  // warp, weft, shear, compression ratio
  ASSERT_TRUE(m.orthotropic.has_value());
  ExpectSameCurve(m.orthotropic->warp, file.orthotropic->warp, "warp");
  ExpectSameCurve(m.orthotropic->weft, file.orthotropic->weft, "weft");
  EXPECT_EQ(m.orthotropic->shear_modulus, file.orthotropic->shear_modulus);
  EXPECT_EQ(m.compression_ratio, kDefaultCompressionRatio);
  EXPECT_EQ(MaterialDefaultNotes(m).size(), m.defaulted.size());
  const nlohmann::json j = MaterialToJson(m);
  EXPECT_FALSE(j.contains("stretch")) << j.dump();
  EXPECT_EQ(ParseMaterialJson(j.dump(), "again.json").defaulted, m.defaulted);
  EXPECT_TRUE(m.Check(nullptr));
}

TEST(MaterialMembrane, StiffnessBesideShearAloneIsBothYarnModuli) {
  const Material m = WithStretch(R"({"stiffness_N_per_m": 800, "shear": {"modulus_N_per_m": 40}})");
  ASSERT_TRUE(m.orthotropic.has_value());
  ExpectSameCurve(m.orthotropic->warp, TensileCurve::Linear(800.0), "warp");
  ExpectSameCurve(m.orthotropic->weft, TensileCurve::Linear(800.0), "weft");
  EXPECT_DOUBLE_EQ(m.MembraneModulus(), 800.0);
  EXPECT_FALSE(Lists(m, "stretch.warp"));
  EXPECT_FALSE(Lists(m, "stretch.weft"));
  // Refused: the stiffness beside a direction, and any Poisson ratio with the orthotropic sheet.
  EXPECT_NE(StretchError(R"({"stiffness_N_per_m": 800, "weft": {"modulus_N_per_m": 900}})")
                .find("membrane.json: stretch.stiffness_N_per_m: ambiguous"),
            std::string::npos);
  EXPECT_NE(StretchError(R"({"poisson": 0.3, "shear": {"modulus_N_per_m": 40}})")
                .find("membrane.json: stretch.poisson: "),
            std::string::npos);
}

TEST(MaterialMembrane, CompressionFieldsAndTheirDefault) {
  const Material m = WithStretch(R"({"compression_ratio": 0.02, "buckling_strain": 0.003})");
  EXPECT_DOUBLE_EQ(m.Compression().ratio, 0.02);
  EXPECT_DOUBLE_EQ(m.Compression().buckling_strain, 0.003);
  EXPECT_FALSE(Lists(m, "stretch.compression_ratio"));
  const Material plain = WithStretch(R"({"stiffness_N_per_m": 1000})");
  EXPECT_EQ(plain.compression_ratio, kDefaultCompressionRatio);
  EXPECT_EQ(plain.buckling_strain, 0.0);
  EXPECT_TRUE(Lists(plain, "stretch.compression_ratio"));
  EXPECT_FALSE(Lists(plain, "stretch.buckling_strain"));  // 0 is the model's plain form
  // The ends of both ranges are accepted.
  EXPECT_EQ(StretchError(R"({"compression_ratio": 0.001, "buckling_strain": 0.05})"), "");
  EXPECT_EQ(StretchError(R"({"compression_ratio": 1, "buckling_strain": 0})"), "");
  EXPECT_NE(StretchError(R"({"buckling_strain": -0.001})").find("stretch.buckling_strain"),
            std::string::npos);
}

TEST(MaterialMembrane, KesPlausibilityNamesTheUnit) {
  // WT at 5 % off LT·EMT passes, 6 % off is refused: 4 % EMT, LT 0.65 → WT 6.5 gf·cm/cm².
  EXPECT_EQ(StretchError(R"({"warp": {"kes": {"EMT_percent": 4, "LT": 0.65, "WT_gfcm_per_cm2": 6.82}}})"), "");
  EXPECT_NE(StretchError(R"({"warp": {"kes": {"EMT_percent": 4, "LT": 0.65, "WT_gfcm_per_cm2": 6.9}}})")
                .find("stretch.warp.kes.WT_gfcm_per_cm2: 6.9 gf·cm/cm² disagrees"),
            std::string::npos);
  // WT alone whose LT falls outside (0.1, 1.25).
  EXPECT_NE(StretchError(R"({"warp": {"kes": {"EMT_percent": 4, "WT_gfcm_per_cm2": 40}}})")
                .find("stretch.warp.kes.WT_gfcm_per_cm2: 40 gf·cm/cm² gives LT"),
            std::string::npos);
  // G at the edge of plausibility (20 gf/cm/deg) passes, above it is N/m's number.
  EXPECT_EQ(StretchError(R"({"shear": {"kes": {"G_gf_per_cm_deg": 20}}})"), "");
  EXPECT_NE(StretchError(R"({"shear": {"kes": {"G_gf_per_cm_deg": 20.5}}})").find("looks like N/m"),
            std::string::npos);
  EXPECT_NE(StretchError(R"({"shear": {"kes": {"2HG_gf_per_cm": 1}}})")
                .find("stretch.shear.kes.G_gf_per_cm_deg: missing"),
            std::string::npos);
  EXPECT_NE(StretchError(R"({"shear": {"modulus_N_per_m": 40, "fast": {"EB5_percent": 3}}})")
                .find("stretch.shear: give one of"),
            std::string::npos);
  EXPECT_NE(StretchError(R"({"warp": {"curve": [[0.01, 5], [0.01, 6]]}})").find("stretch.warp.curve[1]"),
            std::string::npos);
  EXPECT_NE(StretchError(R"({"warp": {"curve": [[0.01]]}})").find("stretch.warp.curve[0]: must be an array [strain, N_per_m]"),
            std::string::npos);
  EXPECT_NE(StretchError(R"({"warp": {"modulus_N_per_m": 0}})").find("stretch.warp.modulus_N_per_m: must be > 0 N/m"),
            std::string::npos);
}

// ReadMaterial(MaterialToJson(m)) gives the same membrane, and what was defaulted stays so.
TEST(MaterialMembrane, SurvivesTheRoundTripWithDefaultsLeftOut) {
  for (const std::string stretch :
       {R"({"warp": {"kes": {"EMT_percent": 3.5, "LT": 0.7, "WT_gfcm_per_cm2": 6.1}},
            "weft": {"curve": [[0.01, 5], [0.02, 20], [0.05, 490]]},
            "shear": {"kes": {"G_gf_per_cm_deg": 1.1, "2HG_gf_per_cm": 2}}, "compression_ratio": 0.01,
            "buckling_strain": 0.002})",
        R"({"weft": {"fast": {"E100_percent": 3}}})", R"({"stiffness_N_per_m": 900, "shear": {"fast": {"EB5_percent": 2}}})",
        R"({})", R"({"poisson": 0.25})", R"({"stiffness_N_per_m": 1000, "poisson": 0.3, "compression_ratio": 1})"}) {
    const Material a = WithStretch(stretch);
    const nlohmann::json written = MaterialToJson(a);
    const Material b = ParseMaterialJson(written.dump(), "round trip");
    EXPECT_EQ(b.defaulted, a.defaulted) << stretch;
    ASSERT_EQ(b.orthotropic.has_value(), a.orthotropic.has_value()) << stretch;
    if (a.orthotropic) {
      ExpectSameCurve(b.orthotropic->warp, a.orthotropic->warp, stretch + " warp");
      ExpectSameCurve(b.orthotropic->weft, a.orthotropic->weft, stretch + " weft");
      EXPECT_EQ(b.orthotropic->shear_modulus, a.orthotropic->shear_modulus) << stretch;
    } else {
      EXPECT_EQ(b.stretch_stiffness, a.stretch_stiffness) << stretch;
      EXPECT_EQ(b.poisson, a.poisson) << stretch;
    }
    EXPECT_EQ(b.compression_ratio, a.compression_ratio) << stretch;
    EXPECT_EQ(b.buckling_strain, a.buckling_strain) << stretch;
    for (const std::string& field : a.defaulted) {
      const std::string key = field.substr(std::string("stretch.").size());
      EXPECT_FALSE(written.contains("stretch") && written["stretch"].contains(key))
          << field << " written: " << written.dump();
    }
  }
}

TEST(MaterialMembrane, CodeBuiltMembranesAreWrittenAndChecked) {
  Material m;
  m.areal_density = 0.2;
  m.orthotropic = OrthotropicMembrane{TensileCurve::Linear(1200.0),
                                      TensileCurveFromKes(5.0, 0.6), 50.0};
  m.compression_ratio = 0.05;
  EXPECT_TRUE(m.Check(nullptr));
  const nlohmann::json j = MaterialToJson(m);
  EXPECT_EQ(j["stretch"]["warp"], (nlohmann::json{{"modulus_N_per_m", 1200.0}}));
  EXPECT_TRUE(j["stretch"]["weft"].contains("curve"));
  EXPECT_FALSE(j["stretch"].contains("poisson"));
  const Material back = ParseMaterialJson(j.dump(), "code");
  ExpectSameCurve(back.orthotropic->warp, m.orthotropic->warp, "linear");
  // A knotted curve is read back through FromPoints: the knots' forces, not the slopes.
  for (size_t i = 0; i < m.orthotropic->weft.strains().size(); ++i) {
    const double e = m.orthotropic->weft.strains()[i];
    EXPECT_NEAR(back.orthotropic->weft.Force(e), m.orthotropic->weft.Force(e),
                1e-12 * m.orthotropic->weft.Force(e) + 1e-12);
  }
  // Check refuses in the parser's words, without the file name.
  const auto refused = [](const Material& bad, const std::string& expected) {
    std::string why;
    EXPECT_FALSE(bad.Check(&why)) << expected;
    EXPECT_EQ(why.find(expected), 0u) << why;
    try {
      ParseMaterialJson(MaterialToJson(bad).dump(), "fitted law");
      ADD_FAILURE() << expected << ": the parser took it";
    } catch (const InputError& e) {
      EXPECT_EQ("fitted law: " + why, e.what());
    }
  };
  Material bad = m;
  bad.orthotropic->shear_modulus = -3.0;
  refused(bad, "stretch.shear.modulus_N_per_m: must be > 0 N/m, got -3");
  bad = m;
  bad.buckling_strain = 0.2;
  refused(bad, "stretch.buckling_strain: must lie in [0, 0.05]");
  bad = m;
  bad.compression_ratio = 0.0;
  refused(bad, "stretch.compression_ratio: must lie in [0.001, 1]");
  bad = m;
  bad.orthotropic->warp = TensileCurve::Linear(2e7);
  refused(bad, "stretch.warp.modulus_N_per_m: suspicious magnitude");
}

TEST(MaterialMembrane, EachDefaultIsANoteNamingItsFieldValueAndPage) {
  const Material m = ParseMaterialJson("{" + kLaw + "}", "defaults.json");
  const std::vector<Note> notes = MaterialDefaultNotes(m);
  ASSERT_EQ(notes.size(), m.defaulted.size());
  for (size_t i = 0; i < notes.size(); ++i) {
    EXPECT_EQ(notes[i].code, "membrane_default");
    EXPECT_EQ(notes[i].text.find(m.defaulted[i] + " not given: "), 0u) << notes[i].text;
    EXPECT_NE(notes[i].text.find("(docs/methods/materials.md, Membrane)"), std::string::npos)
        << notes[i].text;
  }
  EXPECT_NE(notes[0].text.find("EMT 4 %"), std::string::npos) << notes[0].text;
  EXPECT_NE(notes[2].text.find("0.8 gf/cm/deg"), std::string::npos) << notes[2].text;
  // A file that gives every membrane field has none.
  EXPECT_TRUE(MaterialDefaultNotes(
                  WithStretch(R"({"stiffness_N_per_m": 1000, "poisson": 0.3, "compression_ratio": 0.5})"))
                  .empty());
}

}  // namespace
}  // namespace textile
