#include "textile/sim/law/material.h"

#include <gtest/gtest.h>

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

TEST(Material, CompressionRatioDefaultsToOneAndSurvivesTheRoundTrip) {
  const std::string law = R"("bending": {"units": "kes", "b1": 0.1, "b2": 0.0892, "c1": -0.0092})";
  const Material plain = ParseMaterialJson(R"({"areal_density_gsm": 180, )" + law + "}", "plain");
  EXPECT_EQ(plain.compression_ratio, 1.0);
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
                      BadCase{"spline-weft-invalid.json", "bending_weft.kappa[2]", "is not above"}),
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
  for (const char* name : {"pabst-fig8", "pabst-dress", "pabst-interlining", "knee-spline"}) {
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
