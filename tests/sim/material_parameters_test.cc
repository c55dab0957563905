#include "textile/sim/law/material_parameters.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

const char* kFig8 = R"({"areal_density_gsm": 200,
  "bending": {"units": "kes", "b1": 0.1, "b2": 0.0892, "c1": -0.0092}})";

std::string Error(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(MaterialParameters, NamesFollowTheFileAndTheMembraneItHas) {
  const Material file = ParseMaterialJson(kFig8, "fig8.json");  // orthotropic defaults
  EXPECT_EQ(MaterialParameterNames(file),
            (std::vector<std::string>{"b1", "b2", "c1", "beta", "areal_density_gsm",
                                      "stretch.warp", "stretch.weft", "stretch.shear",
                                      "stretch.compression_ratio"}));
  Material iso = LawOnlyMaterial(file.bending, 0.2);
  iso.orthotropic.reset();
  iso.bending_weft = BendingLaw::FromKes(0.08, 0.07, -0.006);
  const std::vector<std::string> names = MaterialParameterNames(iso);
  EXPECT_NE(std::find(names.begin(), names.end(), "bending_weft.c1"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "stretch.poisson"), names.end());
  // Values in lab units, defaults flagged.
  const MaterialParameterValue b1 = GetMaterialParameter(file, "b1");
  EXPECT_NEAR(b1.lab, 0.1, 1e-12);
  EXPECT_EQ(b1.unit, "gf·cm");
  EXPECT_NEAR(b1.si, units::KesStiffnessToSi(0.1), 1e-18);
  EXPECT_FALSE(b1.defaulted);
  EXPECT_EQ(GetMaterialParameter(file, "c1").unit, "gf·cm²");
  EXPECT_NEAR(GetMaterialParameter(file, "areal_density_gsm").lab, 200.0, 1e-9);
  EXPECT_TRUE(GetMaterialParameter(file, "stretch.shear").defaulted);
  EXPECT_NE(Error([&] { GetMaterialParameter(file, "stretch.poisson"); })
                .find("'stretch.poisson' is not a parameter of this material; it has b1"),
            std::string::npos);
}

TEST(MaterialParameters, SettingOneChangesOnlyItAndInvalidValuesAreNamed) {
  const Material file = ParseMaterialJson(kFig8, "fig8.json");
  const Material m = WithMaterialParameter(file, "b2", units::KesStiffnessToSi(0.09));
  EXPECT_NEAR(m.bending.b2_kes(), 0.09, 1e-12);
  EXPECT_EQ(m.bending.b1(), file.bending.b1());
  EXPECT_EQ(m.bending.c1(), file.bending.c1());
  // The warp curve scaled as a whole: twice the force at every strain, the weft untouched.
  const double e0 = file.orthotropic->warp.SmallStrainModulus();
  const Material w = WithMaterialParameter(file, "stretch.warp", 2.0 * e0);
  for (double strain : {0.001, 0.01, 0.03, 0.08})
    EXPECT_NEAR(w.orthotropic->warp.Force(strain), 2.0 * file.orthotropic->warp.Force(strain),
                1e-9 * file.orthotropic->warp.Force(strain));
  EXPECT_EQ(w.orthotropic->weft.Force(0.01), file.orthotropic->weft.Force(0.01));
  // A law with κ0 < 0, a ratio out of range, a NaN: refused with the parameter's name.
  EXPECT_EQ(Error([&] { WithMaterialParameter(file, "c1", 0.001); }).rfind("c1 = ", 0), 0u);
  EXPECT_EQ(Error([&] { WithMaterialParameter(file, "stretch.compression_ratio", 2.0); })
                .rfind("stretch.compression_ratio = 2", 0),
            0u);
  EXPECT_NE(Error([&] { WithMaterialParameter(file, "beta", std::nan("")); }).find("finite"),
            std::string::npos);
  // A zero c1 differs in steps of b1 × 1 cm.
  const Material linear = LawOnlyMaterial(BendingLaw::FromKes(0.1, 0.1, 0.0), 0.2);
  EXPECT_NEAR(MaterialParameterScale(linear, "c1"), linear.bending.b1() * 0.01, 1e-20);
  // A linear law (b1 = b2, the Fig. 9 dress fabric's) moves with b2 alone: b1 and c1 are left
  // out of the names, and asked for they are refused with the reason.
  const Material dress = LawOnlyMaterial(BendingLaw::FromKes(0.0973, 0.0973, 0.0453), 0.13);
  const std::vector<std::string> names = MaterialParameterNames(dress);
  EXPECT_EQ(std::count(names.begin(), names.end(), "b1"), 0);
  EXPECT_EQ(std::count(names.begin(), names.end(), "b2"), 1);
  EXPECT_NE(ParameterWithoutEffect(dress, "c1").find("ask for b2"), std::string::npos);
  EXPECT_EQ(ParameterWithoutEffect(dress, "b2"), "");
  EXPECT_EQ(ParameterWithoutEffect(file, "b1"), "");
}

// A linear law with b1 = b2 moves as a line: b2 carries b1 with it. At the edge of a range the
// difference is one-sided; a name twice, or one without effect, is refused before any work.
TEST(MaterialParameters, LinearLawsAndRangeEdgesStillHaveADifference) {
  const Material dress = LawOnlyMaterial(BendingLaw::FromKes(0.0973, 0.0973, 0.0453), 0.13);
  const Material steeper = WithMaterialParameter(dress, "b2", units::KesStiffnessToSi(0.1));
  EXPECT_NEAR(steeper.bending.b1_kes(), 0.1, 1e-12);
  EXPECT_NEAR(steeper.bending.b2_kes(), 0.1, 1e-12);
  const ParameterStep b2 = DifferenceStep(dress, "b2", 1e-4);
  EXPECT_NEAR(b2.span, 2e-4 * dress.bending.b2(), 1e-15);  // central: both sides valid
  Material stiff = ParseMaterialJson(kFig8, "fig8.json");
  stiff = WithMaterialParameter(stiff, "stretch.compression_ratio", 1.0);
  EXPECT_EQ(std::count(stiff.defaulted.begin(), stiff.defaulted.end(),
                       "stretch.compression_ratio"),
            0);
  const ParameterStep edge = DifferenceStep(stiff, "stretch.compression_ratio", 1e-4);
  EXPECT_EQ(edge.up.compression_ratio, 1.0);  // one-sided: 1.0001 is no material
  EXPECT_NEAR(edge.down.compression_ratio, 1.0 - 1e-4, 1e-15);
  EXPECT_NEAR(edge.span, 1e-4, 1e-15);
  EXPECT_NE(Error([&] { CheckSensitivityParameters(stiff, {"b1", "b2", "b1"}, 1e-4); })
                .find("b1: named twice"),
            std::string::npos);
  EXPECT_NE(Error([&] { CheckSensitivityParameters(dress, {"b2", "c1"}, 1e-4); })
                .find("the law is linear"),
            std::string::npos);
  EXPECT_EQ(Error([&] { CheckSensitivityParameters(dress, MaterialParameterNames(dress), 1e-4); }),
            "");
}

TEST(MaterialParameters, FitCovarianceIsReadInSiAndCheckedPositiveSemiDefinite) {
  Material m = ParseMaterialJson(kFig8, "fig8.json");
  EXPECT_FALSE(MaterialFitCovariance(m).has_value());
  m.fit["covariance_kes"] = {{1e-4, 0.0, 0.0}, {0.0, 4e-4, 0.0}, {0.0, 0.0, 1e-6}};
  const Eigen::Matrix3d c = *MaterialFitCovariance(m);
  EXPECT_NEAR(c(0, 0), 1e-4 * std::pow(units::KesStiffnessToSi(1.0), 2), 1e-30);
  EXPECT_NEAR(c(2, 2), 1e-6 * std::pow(units::KesQuadraticToSi(1.0), 2), 1e-12 * c(2, 2));
  // b1's uncertainty is its sd from the covariance; a defaulted membrane field a decade.
  const ParameterUncertainty b1 = DefaultParameterUncertainty(m, "b1", c);
  EXPECT_NEAR(b1.si, units::KesStiffnessToSi(0.01), 1e-18);
  EXPECT_NEAR(b1.ln, 0.1, 1e-12);
  EXPECT_NEAR(DefaultParameterUncertainty(m, "stretch.warp", c).ln, std::log(10.0), 1e-12);
  EXPECT_NEAR(DefaultParameterUncertainty(m, "areal_density_gsm", c).ln, 0.02, 1e-12);
  // A constant the fit left undetermined (its sd null): the matrix is a pseudo-inverse, no σ.
  Material undetermined = m;
  undetermined.fit["c1_sd"] = nullptr;
  std::string why;
  EXPECT_FALSE(MaterialFitCovariance(undetermined, &why).has_value());
  EXPECT_NE(why.find("left c1 undetermined"), std::string::npos) << why;
  m.fit["covariance_kes"][0][1] = 1.0;
  m.fit["covariance_kes"][1][0] = 1.0;
  EXPECT_NE(Error([&] { MaterialFitCovariance(m); }).find("not positive semi-definite"),
            std::string::npos);
  m.fit["covariance_kes"] = {{1.0, 2.0}};
  EXPECT_NE(Error([&] { MaterialFitCovariance(m); }).find("3×3"), std::string::npos);
}

}  // namespace
}  // namespace textile
