#include "textile/sim/law/material.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/io/json_fields.h"
#include "textile/sim/io/json_text.h"
#include "textile/sim/law/textile_range.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

using nlohmann::json;

// Plausibility bounds. Outside them a value is far more likely a unit mix-up (an "si" file
// written in KES numbers, mm for m) than a fabric, so the file is refused with a hint.
// The ranges are textile_range.h's (docs/materials.md).
using range::kMaxGsm;
using range::kMinGsm;
constexpr double kMinBKes = range::kMinStiffnessKes, kMaxBKes = range::kMaxStiffnessKes;
constexpr double kMaxAbsC1Kes = range::kMaxAbsQuadraticKes;
constexpr double kMinBeta = 1e-3, kMaxBeta = 1e3;  // [-]

// The field checks below are shared by the parser, which quotes a value as the file writes it
// (`got`), and by Material::Check, which quotes it as MaterialToJson would write it. Each returns
// "" or the problem; a Pabst or spline law's returns "<field>: <problem>".

// A Pabst law in KES numbers (b1, b2 in gf·cm, c1 in gf·cm²); got_b[i]: b1, b2 as written.
std::string PabstLawProblem(double b1, double b2, double c1, const std::string& key,
                            const std::string got_b[2], const std::string& unit_hint) {
  const char* names[2] = {"b1", "b2"};
  for (int i = 0; i < 2; ++i) {
    const double bk = i == 0 ? b1 : b2;
    const std::string field = key + "." + names[i];
    if (bk <= 0.0) return field + ": must be > 0, got " + got_b[i];
    if (bk < kMinBKes || bk > kMaxBKes) {
      std::ostringstream s;
      s << field << ": suspicious magnitude " << bk << " gf·cm, outside the textile range "
        << kMinBKes << " .. " << kMaxBKes << " gf·cm" << unit_hint;
      return s.str();
    }
  }
  if (std::abs(c1) > kMaxAbsC1Kes) {
    std::ostringstream s;
    s << key << ".c1: suspicious magnitude " << c1 << " gf·cm², |c1| above " << kMaxAbsC1Kes
      << " gf·cm²" << unit_hint;
    return s.str();
  }
  // |c1| alone says little (a technical fabric's sharp knee needs ~1e6 gf·cm²); a kink at a
  // radius of curvature beyond a kilometre is a c1 out of scale with b1 and b2.
  if (c1 != 0.0 && b1 != b2 && (b2 - b1) / (2.0 * c1) > 0.0 &&
      (b2 - b1) / (2.0 * c1) < range::kMinKinkCurvatureKes) {
    std::ostringstream s;
    s << key << ".c1: suspicious magnitude " << c1
      << " gf·cm²: it puts the kink κ0 = (b2 - b1)/(2 c1) at " << (b2 - b1) / (2.0 * c1)
      << " /cm, below " << range::kMinKinkCurvatureKes << " /cm (a radius of 1 km)" << unit_hint;
    return s.str();
  }
  const double sb1 = units::KesStiffnessToSi(b1), sb2 = units::KesStiffnessToSi(b2);
  const double sc1 = units::KesQuadraticToSi(c1);
  if (std::string why = BendingLaw::Invalidity(sb1, sb2, sc1); !why.empty())
    return key + ": " + why;
  return "";
}

// A spline law's knots, in KES (kes) or SI numbers.
std::string SplineLawProblem(const std::vector<double>& kappa, const std::vector<double>& moment,
                             const std::vector<double>& sd, const std::string& key, bool kes) {
  if (std::string why = BendingLaw::SplineInvalidity(kappa, moment, sd, key + ".kappa",
                                                     key + ".moment", key + ".moment_sd");
      !why.empty()) {
    return why;  // why starts with the field
  }
  // The secant stiffness M_i/κ_i of each knot against the bounds of b1, b2 (KES), where a
  // unit mix-up shows.
  const std::string unit_hint = kes ? " (units: kes)" : " (units: si; is this file in kes?)";
  for (size_t i = 1; i < kappa.size(); ++i) {
    const double secant =
        kes ? moment[i] / kappa[i] : units::SiStiffnessToKes(moment[i] / kappa[i]);
    if (secant < kMinBKes || secant > kMaxBKes) {
      std::ostringstream s;
      s << key << ".moment[" << i << "]: suspicious secant stiffness M/kappa = " << secant
        << " gf·cm at this knot, outside the textile range " << kMinBKes << " .. " << kMaxBKes
        << " gf·cm" << unit_hint;
      return s.str();
    }
  }
  return "";
}

std::string ArealDensityProblem(double gsm, const std::string& got) {
  if (gsm <= 0.0) return "must be > 0 g/m², got " + got;
  if (gsm < kMinGsm || gsm > kMaxGsm) {
    std::ostringstream s;
    s << "suspicious areal density " << gsm << " g/m², outside " << kMinGsm << " .. " << kMaxGsm
      << " g/m² (the unit is g/m², not kg/m²)";
    return s.str();
  }
  return "";
}

std::string BetaProblem(double beta, const std::string& got) {
  if (beta <= 0.0) return "must be > 0, got " + got;
  if (beta < kMinBeta || beta > kMaxBeta)
    return "suspicious factor " + got + ", outside 0.001 .. 1000";
  return "";
}

std::string StretchStiffnessProblem(double k, const std::string& got) {
  if (k <= 0.0) return "must be > 0 N/m, got " + got;
  if (k > 1e7) return "suspicious magnitude, above 1e7 N/m";
  return "";
}

std::string PoissonProblem(double nu, const std::string& got) {
  return nu < 0.0 || nu >= 0.5 ? "must lie in [0, 0.5), got " + got : "";
}

std::string CompressionRatioProblem(double r, const std::string& got) {
  return r >= kMinCompressionRatio && r <= 1.0
             ? ""
             : "must lie in [0.001, 1] (1: as stiff as in tension), got " + got;
}

std::string FrictionProblem(double mu, const std::string& got) {
  return mu < 0.0 || mu > 10.0 ? "must lie in [0, 10], got " + got : "";
}

// A field's problem (from the checks above) refused as "<source>: <field>: <problem>"; nothing
// when there is none.
void Refuse(const JsonFields& f, const std::string& field, const std::string& problem) {
  if (!problem.empty()) f.Fail(field, problem);
}

// A law's problem, which starts with its field, refused as "<source>: <problem>".
void RefuseLaw(const JsonFields& f, const std::string& problem) {
  if (!problem.empty()) throw InputError(f.source() + ": " + problem);
}

// The "units" field of a law object: true for "kes", false for "si".
bool LawUnits(const JsonFields& f, const json& b, const std::string& key, const char* kes_units,
              const char* si_units) {
  const json& v = b.at("units");
  if (!v.is_string()) f.Must(key + ".units", "be \"kes\" or \"si\"", v);
  const std::string units = v.get<std::string>();
  if (units != "kes" && units != "si") {
    f.Unknown(key + ".units", "units", units,
              std::string("\"kes\": ") + kes_units + "; or \"si\": " + si_units);
  }
  return units == "kes";
}

// {"law": "spline", "units", "kappa", "moment"[, "moment_sd"]}: knots in 1/cm and gf·cm/cm
// ("kes") or 1/m and N ("si").
BendingLaw SplineLaw(const JsonFields& f, const json& b, const std::string& key) {
  f.CheckKeys(b, key, {"law", "units", "kappa", "moment", "moment_sd"});
  for (const char* k : {"units", "kappa", "moment"}) {
    f.Require(b, k, "a spline law is {\"law\": \"spline\", \"units\", \"kappa\", \"moment\"}",
              key + "." + k);
  }
  const bool kes =
      LawUnits(f, b, key, "kappa in 1/cm, moment in gf·cm/cm", "kappa in 1/m, moment in N");
  std::vector<double> kappa = f.Numbers(b.at("kappa"), key + ".kappa");
  std::vector<double> moment = f.Numbers(b.at("moment"), key + ".moment");
  std::vector<double> sd;
  if (b.contains("moment_sd")) sd = f.Numbers(b.at("moment_sd"), key + ".moment_sd");
  RefuseLaw(f, SplineLawProblem(kappa, moment, sd, key, kes));
  if (kes) return BendingLaw::FromSplineKes(std::move(kappa), std::move(moment), std::move(sd));
  return BendingLaw::FromSpline(std::move(kappa), std::move(moment), std::move(sd));
}

// root[key]: a Pabst law {"units", "b1", "b2", "c1"} or a spline law.
BendingLaw Law(const JsonFields& f, const json& root, const std::string& key) {
  const json& b = f.Object(root.at(key), key,
                           "{\"units\", \"b1\", \"b2\", \"c1\"} or {\"law\": \"spline\", "
                           "\"units\", \"kappa\", \"moment\"}");
  std::string law = "pabst";
  if (b.contains("law")) {
    if (!b.at("law").is_string()) f.Must(key + ".law", "be \"pabst\" or \"spline\"", b.at("law"));
    law = b.at("law").get<std::string>();
    if (law != "pabst" && law != "spline") {
      f.Unknown(key + ".law", "law", law,
                "\"pabst\": b1, b2, c1; or \"spline\": kappa, moment");
    }
  }
  if (law == "spline") return SplineLaw(f, b, key);
  f.CheckKeys(b, key, {"law", "units", "b1", "b2", "c1"});
  for (const char* k : {"units", "b1", "b2", "c1"}) f.Require(b, k, "", key + "." + k);
  const bool kes = LawUnits(f, b, key, "gf·cm, gf·cm²", "N·m, N·m²");
  double v[3];
  const char* names[3] = {"b1", "b2", "c1"};
  for (int i = 0; i < 3; ++i) v[i] = f.Number(b.at(names[i]), key + "." + names[i]);
  // Everything below in KES, which is how people read these numbers.
  const double b1 = kes ? v[0] : units::SiStiffnessToKes(v[0]);
  const double b2 = kes ? v[1] : units::SiStiffnessToKes(v[1]);
  const double c1 = kes ? v[2] : units::SiQuadraticToKes(v[2]);
  const std::string unit_hint = kes ? " (units: kes)" : " (units: si; is this file in kes?)";
  const std::string got_b[2] = {JsonFields::Brief(b.at("b1")), JsonFields::Brief(b.at("b2"))};
  RefuseLaw(f, PabstLawProblem(b1, b2, c1, key, got_b, unit_hint));
  const double sb1 = units::KesStiffnessToSi(b1), sb2 = units::KesStiffnessToSi(b2);
  const double sc1 = units::KesQuadraticToSi(c1);
  return BendingLaw::FromSi(sb1, sb2, sc1);
}

// ---- The membrane (docs/methods/materials.md, "Membrane") ----

constexpr double kMaxMembraneModulus = 1e7;  // [N/m], as for stretch.stiffness_N_per_m
// KES values beyond these are another unit's numbers (docs/methods/materials.md, "Membrane").
constexpr double kMaxKesShear = 20.0;        // G [gf/cm/deg]; 20 gf/cm/deg = 1124 N/m
constexpr double kMinPercent = 0.1;          // EMT, E100, EB5 [%]: below, a fraction's number
// WT must agree with LT·½·500 gf/cm·EMT/100 within this (docs/methods/materials.md).
constexpr double kWtTolerance = 0.05;
// FAST-3 shear rigidity G = 123 / EB5 [N/m] (EB5 in %).
constexpr double kFastShearConstant = 123.0;

std::string ShearModulusProblem(double g, const std::string& got) {
  if (g <= 0.0) return "must be > 0 N/m, got " + got;
  if (g > kMaxMembraneModulus) return "suspicious magnitude, above 1e7 N/m";
  return "";
}

std::string BucklingStrainProblem(double e, const std::string& got) {
  return e >= 0.0 && e <= kMaxBucklingStrain
             ? ""
             : "must lie in [0, 0.05] (a fraction: 0.2 % is 0.002), got " + got;
}

// EMT, E100 or EB5 [%] (name: "EMT"): in (0, 100], and not a fraction's number.
std::string PercentProblem(double p, const std::string& got, const std::string& name) {
  if (p <= 0.0) return "must be > 0 %, got " + got;
  if (p > 100.0) return "must be at most 100 %, got " + got;
  if (p < kMinPercent) {
    return "suspicious magnitude " + got + " %, below 0.1 %: looks like a fraction: " + name +
           " is in % (4 % is 4)";
  }
  return "";
}

std::string LinearityProblem(double lt, const std::string& got) {
  return lt > 0.1 && lt < 1.25 ? "" : "must lie in (0.1, 1.25), got " + got;
}

// The KES tensile energy WT [gf·cm/cm²] of a curve with linearity LT and EMT [%].
double KesTensileEnergy(double lt, double emt_percent) {
  return lt * 0.5 * 500.0 * emt_percent / 100.0;
}

std::string TensileEnergyProblem(double wt, double lt, double emt, const std::string& got) {
  if (wt <= 0.0) return "must be > 0 gf·cm/cm², got " + got;
  const double expected = KesTensileEnergy(lt, emt);
  if (std::abs(wt - expected) <= kWtTolerance * expected) return "";
  return got + " gf·cm/cm² disagrees with LT·½·500 gf/cm·EMT/100 = " + NumberText(expected) +
         " gf·cm/cm² (LT " + NumberText(lt) + ", EMT " + NumberText(emt) +
         " %) by more than 5 %";
}

std::string KesShearProblem(double g, const std::string& got) {
  if (g <= 0.0) return "must be > 0 gf/cm/deg, got " + got;
  if (g > kMaxKesShear) {
    return "suspicious magnitude " + got +
           " gf/cm/deg, above 20: looks like N/m: use modulus_N_per_m";
  }
  return "";
}

std::string ShearHysteresisProblem(double h, const std::string& got) {
  return h < 0.0 ? "must be >= 0 gf/cm, got " + got : "";
}

// The one key of obj among `forms`, or "<field>: give one of ..." (none or several).
std::string OneForm(const JsonFields& f, const json& obj, const std::string& field,
                    const std::vector<std::string>& forms) {
  std::string all, given;
  int count = 0;
  for (const std::string& k : forms) {
    all += (all.empty() ? "" : ", ") + k;
    if (obj.contains(k)) {
      given += (given.empty() ? "" : " and ") + k;
      ++count;
    }
  }
  if (count == 0) f.Fail(field, "needs one of " + all);
  if (count > 1) f.Fail(field, "give one of " + all + ", got " + given);
  for (const std::string& k : forms)
    if (obj.contains(k)) return k;
  return "";
}

// A number obj[key] (field: where.key), its problem refused.
double ReadNumber(const JsonFields& f, const json& obj, const std::string& where,
                  const std::string& key,
                  const std::function<std::string(double, const std::string&)>& problem) {
  const std::string field = where + "." + key;
  const json& v = obj.at(key);
  const double x = f.Number(v, field);
  Refuse(f, field, problem(x, JsonFields::Brief(v)));
  return x;
}

// {"curve": [[strain, N_per_m], ...]}: the knots checked here to name the bad point.
TensileCurve CurveForm(const JsonFields& f, const json& v, const std::string& field) {
  if (!v.is_array() || v.empty()) f.Must(field, "be an array of [strain, N_per_m] points", v);
  std::vector<double> strain, force;
  double last_strain = 0.0, last_force = 0.0;
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string point = JsonFields::Element(field, i);
    const auto p = f.FixedNumbers<2>(v[i], point, "[strain, N_per_m]");
    if (p[0] > 1.0) {
      f.Fail(point, "strain " + NumberText(p[0]) +
                        " above 1: strain is a fraction (4 % is 0.04)");
    }
    if (!(p[0] > last_strain) || !(p[1] > last_force)) {
      f.Fail(point, "(" + NumberText(p[0]) + ", " + NumberText(p[1]) +
                        " N/m) is not monotone: strains and forces must increase from (0, 0)");
    }
    strain.push_back(last_strain = p[0]);
    force.push_back(last_force = p[1]);
  }
  try {
    return TensileCurve::FromPoints(strain, force);
  } catch (const InputError& e) {
    f.Fail(field, e.what());
  }
}

// {"kes": {"EMT_percent", "LT", "WT_gfcm_per_cm2"}}: EMT and LT or WT or both.
TensileCurve KesTensileForm(const JsonFields& f, const json& v, const std::string& field) {
  const json& k = f.Object(v, field, "{\"EMT_percent\", \"LT\", \"WT_gfcm_per_cm2\"}");
  f.CheckKeys(k, field, {"EMT_percent", "LT", "WT_gfcm_per_cm2"});
  f.Require(k, "EMT_percent", "%, required", field + ".EMT_percent");
  const double emt = ReadNumber(f, k, field, "EMT_percent", [](double x, const std::string& g) {
    return PercentProblem(x, g, "EMT");
  });
  if (!k.contains("LT") && !k.contains("WT_gfcm_per_cm2"))
    f.Fail(field, "needs LT or WT_gfcm_per_cm2 (or both) beside EMT_percent");
  double lt = 0.0;
  if (k.contains("LT")) lt = ReadNumber(f, k, field, "LT", LinearityProblem);
  if (k.contains("WT_gfcm_per_cm2")) {
    const std::string wt_field = field + ".WT_gfcm_per_cm2";
    const json& v_wt = k.at("WT_gfcm_per_cm2");
    const double wt = f.Number(v_wt, wt_field);
    const std::string got = JsonFields::Brief(v_wt);
    if (k.contains("LT")) {
      Refuse(f, wt_field, TensileEnergyProblem(wt, lt, emt, got));
    } else {
      if (wt <= 0.0) f.Fail(wt_field, "must be > 0 gf·cm/cm², got " + got);
      lt = wt / KesTensileEnergy(1.0, emt);
      if (!LinearityProblem(lt, "").empty()) {
        f.Fail(wt_field, got + " gf·cm/cm² gives LT = WT / (½·500 gf/cm·EMT/100) = " +
                             NumberText(lt) + ", outside (0.1, 1.25)");
      }
    }
  }
  return TensileCurveFromKes(emt, lt);
}

// stretch.warp or stretch.weft: one of modulus_N_per_m, curve, kes, fast.
TensileCurve TensileForm(const JsonFields& f, const json& v, const std::string& field) {
  const json& o = f.Object(v, field,
                           "{\"modulus_N_per_m\"}, {\"curve\"}, {\"kes\"} or {\"fast\"}");
  f.CheckKeys(o, field, {"modulus_N_per_m", "curve", "kes", "fast"});
  const std::string form = OneForm(f, o, field, {"modulus_N_per_m", "curve", "kes", "fast"});
  if (form == "modulus_N_per_m")
    return TensileCurve::Linear(ReadNumber(f, o, field, form, StretchStiffnessProblem));
  if (form == "curve") return CurveForm(f, o.at(form), field + ".curve");
  if (form == "kes") return KesTensileForm(f, o.at(form), field + ".kes");
  const std::string fast = field + ".fast";
  const json& k = f.Object(o.at(form), fast, "{\"E100_percent\"}");
  f.CheckKeys(k, fast, {"E100_percent"});
  f.Require(k, "E100_percent", "%, required", fast + ".E100_percent");
  return TensileCurveFromFastE100(
      ReadNumber(f, k, fast, "E100_percent",
                 [](double x, const std::string& g) { return PercentProblem(x, g, "E100"); }));
}

// stretch.shear: one of modulus_N_per_m, kes, fast [N/m per radian].
double ShearForm(const JsonFields& f, const json& v, const std::string& field) {
  const json& o = f.Object(v, field, "{\"modulus_N_per_m\"}, {\"kes\"} or {\"fast\"}");
  f.CheckKeys(o, field, {"modulus_N_per_m", "kes", "fast"});
  const std::string form = OneForm(f, o, field, {"modulus_N_per_m", "kes", "fast"});
  if (form == "modulus_N_per_m") return ReadNumber(f, o, field, form, ShearModulusProblem);
  const std::string sub = field + "." + form;
  if (form == "kes") {
    const json& k = f.Object(o.at(form), sub, "{\"G_gf_per_cm_deg\", \"2HG_gf_per_cm\"}");
    f.CheckKeys(k, sub, {"G_gf_per_cm_deg", "2HG_gf_per_cm"});
    f.Require(k, "G_gf_per_cm_deg", "gf/cm/deg, required", sub + ".G_gf_per_cm_deg");
    const double g = ReadNumber(f, k, sub, "G_gf_per_cm_deg", KesShearProblem);
    // 2HG (the hysteresis at 0.5°) is carried, not used: the static membrane is elastic.
    if (k.contains("2HG_gf_per_cm")) ReadNumber(f, k, sub, "2HG_gf_per_cm", ShearHysteresisProblem);
    return KesShearToNewtonPerMetre(g);
  }
  const json& k = f.Object(o.at(form), sub, "{\"EB5_percent\"}");
  f.CheckKeys(k, sub, {"EB5_percent"});
  f.Require(k, "EB5_percent", "%, required", sub + ".EB5_percent");
  const double eb5 = ReadNumber(f, k, sub, "EB5_percent", [](double x, const std::string& g) {
    return PercentProblem(x, g, "EB5");
  });
  return kFastShearConstant / eb5;
}

// compression_ratio and buckling_strain, each optional; a missing ratio is a default.
void ReadCompression(const JsonFields& f, const json& st, Material* m) {
  if (st.contains("compression_ratio")) {
    m->compression_ratio =
        ReadNumber(f, st, "stretch", "compression_ratio", CompressionRatioProblem);
    m->stretch_given["compression_ratio"] = m->compression_ratio;
  } else {
    m->compression_ratio = kDefaultCompressionRatio;
    m->defaulted.push_back("stretch.compression_ratio");
  }
  if (st.contains("buckling_strain")) {
    m->buckling_strain = ReadNumber(f, st, "stretch", "buckling_strain", BucklingStrainProblem);
    m->stretch_given["buckling_strain"] = m->buckling_strain;
  }
}

// Rule (i): stiffness_N_per_m and/or poisson, the isotropic membrane.
void ReadIsotropic(const JsonFields& f, const json& st, Material* m) {
  if (st.contains("stiffness_N_per_m")) {
    m->stretch_stiffness =
        ReadNumber(f, st, "stretch", "stiffness_N_per_m", StretchStiffnessProblem);
    m->stretch_given["stiffness_N_per_m"] = m->stretch_stiffness;
  } else {
    m->defaulted.push_back("stretch.stiffness_N_per_m");
  }
  if (st.contains("poisson")) {
    m->poisson = ReadNumber(f, st, "stretch", "poisson", PoissonProblem);
    m->stretch_given["poisson"] = m->poisson;
  } else {
    m->defaulted.push_back("stretch.poisson");
  }
}

// Rules (ii), (iii): warp, weft, shear, each given or its default.
void ReadOrthotropic(const JsonFields& f, const json& st, Material* m) {
  const bool directional = st.contains("warp") || st.contains("weft");
  if (st.contains("poisson")) {
    f.Fail("stretch.poisson",
           "the orthotropic membrane (stretch.warp, weft, shear) has no Poisson coupling: leave "
           "poisson out (docs/methods/materials.md, Membrane)");
  }
  if (st.contains("stiffness_N_per_m") && directional) {
    f.Fail("stretch.stiffness_N_per_m",
           "ambiguous beside stretch.warp or stretch.weft: give each direction's "
           "modulus_N_per_m there");
  }
  // stiffness_N_per_m beside shear alone: the modulus of both yarn directions.
  std::optional<double> both;
  if (st.contains("stiffness_N_per_m"))
    both = ReadNumber(f, st, "stretch", "stiffness_N_per_m", StretchStiffnessProblem);
  OrthotropicMembrane o = DefaultOrthotropicMembrane();
  for (const char* dir : {"warp", "weft"}) {
    TensileCurve& curve = std::string(dir) == "warp" ? o.warp : o.weft;
    const std::string field = std::string("stretch.") + dir;
    if (st.contains(dir)) {
      curve = TensileForm(f, st.at(dir), field);
      m->stretch_given[dir] = st.at(dir);
    } else if (both) {
      curve = TensileCurve::Linear(*both);
      m->stretch_given[dir] = {{"modulus_N_per_m", *both}};
    } else {
      m->defaulted.push_back(field);
    }
  }
  if (st.contains("shear")) {
    o.shear_modulus = ShearForm(f, st.at("shear"), "stretch.shear");
    m->stretch_given["shear"] = st.at("shear");
  } else {
    m->defaulted.push_back("stretch.shear");
  }
  m->orthotropic = std::move(o);
}

// The stretch block (absent: an empty one) into m, by the rules of docs/methods/materials.md.
void ReadStretch(const JsonFields& f, const json& root, Material* m) {
  static const json kEmpty = json::object();
  const json& st =
      root.contains("stretch")
          ? f.Object(root.at("stretch"), "stretch",
                     "{\"warp\", \"weft\", \"shear\", \"compression_ratio\", ...}")
          : kEmpty;
  f.CheckKeys(st, "stretch",
              {"stiffness_N_per_m", "poisson", "warp", "weft", "shear", "compression_ratio",
               "buckling_strain"});
  m->stretch_given = json::object();
  m->defaulted.clear();
  const bool orthotropic = st.contains("warp") || st.contains("weft") || st.contains("shear") ||
                           !(st.contains("stiffness_N_per_m") || st.contains("poisson"));
  if (orthotropic) {
    ReadOrthotropic(f, st, m);
  } else {
    m->orthotropic.reset();
    ReadIsotropic(f, st, m);
  }
  ReadCompression(f, st, m);
}

// areal_density_gsm: required, > 0 and within the textile range [kg/m² returned].
double ReadArealDensity(const JsonFields& f, const json& root) {
  const json& v = f.Require(root, "areal_density_gsm", "g/m², required");
  const double gsm = f.Number(v, "areal_density_gsm");
  Refuse(f, "areal_density_gsm", ArealDensityProblem(gsm, JsonFields::Brief(v)));
  return units::GsmToSi(gsm);
}

}  // namespace

Material LawOnlyMaterial(const BendingLaw& law, double areal_density) {
  Material m;
  m.areal_density = areal_density;
  m.bending = law;
  ReadStretch(JsonFields("defaults"), json::object(), &m);  // no stretch block: every default
  return m;
}

Material ParseMaterialJson(const std::string& text, const std::string& source) {
  const JsonFields f(source);
  const json root = ParseJsonText(text, source);
  f.RequireObject(root);
  f.CheckKeys(root, "", {"name", "areal_density_gsm", "bending", "bending_weft", "bending_bias",
                         "beta", "stretch", "friction", "fit", "notes", "assumptions", "source"});
  Material m;
  if (root.contains("name")) m.name = f.String(root["name"], "name");
  m.areal_density = ReadArealDensity(f, root);
  f.Require(root, "bending", "required: {\"units\", \"b1\", \"b2\", \"c1\"}");
  m.bending = Law(f, root, "bending");
  if (root.contains("bending_weft")) m.bending_weft = Law(f, root, "bending_weft");
  if (root.contains("bending_bias")) m.bending_bias = Law(f, root, "bending_bias");
  if (root.contains("beta")) {
    m.beta = f.Number(root["beta"], "beta");
    Refuse(f, "beta", BetaProblem(m.beta, JsonFields::Brief(root["beta"])));
  }
  ReadStretch(f, root, &m);
  if (root.contains("friction")) {
    m.friction = f.Number(root["friction"], "friction");
    Refuse(f, "friction", FrictionProblem(m.friction, JsonFields::Brief(root["friction"])));
  }
  if (root.contains("fit")) m.fit = f.Object(root["fit"], "fit");
  for (const char* k : {"notes", "assumptions", "source"}) {
    if (root.contains(k)) m.extra[k] = root[k];
  }
  return m;
}

namespace {

// A number as MaterialToJson writes it (JSON has no NaN or infinity: null).
std::string Written(double v) { return JsonFields::Brief(json(v)); }

// A law as Material::Check sees it: in the numbers MaterialToJson writes, checked as the
// parser checks them. "" or "<key>.<field>: <problem>".
std::string LawProblem(const BendingLaw& law, const std::string& key) {
  if (law.is_spline()) {
    std::vector<double> kappa, moment, sd;
    for (double k : law.knot_kappa()) kappa.push_back(units::SiCurvatureToKes(k));
    for (double m : law.knot_moment()) moment.push_back(units::SiMomentToKes(m));
    for (double m : law.knot_moment_sd()) sd.push_back(units::SiMomentToKes(m));
    const std::pair<const char*, const std::vector<double>*> arrays[3] = {
        {"kappa", &kappa}, {"moment", &moment}, {"moment_sd", &sd}};
    for (const auto& [name, values] : arrays)
      for (size_t i = 0; i < values->size(); ++i)
        if (!std::isfinite((*values)[i]))
          return key + "." + name + "[" + std::to_string(i) + "]: must be a number, got null";
    return SplineLawProblem(kappa, moment, sd, key, true);
  }
  const double v[3] = {law.b1_kes(), law.b2_kes(), law.c1_kes()};
  const char* names[3] = {"b1", "b2", "c1"};
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(v[i])) return key + "." + names[i] + ": must be a number, got null";
  const std::string got_b[2] = {Written(v[0]), Written(v[1])};
  return PabstLawProblem(v[0], v[1], v[2], key, got_b, " (units: kes)");
}

// The membrane as Material::Check sees it: the stretch block MaterialToJson writes, read back
// by the parser (the same checks, the same words). "" or "<field>: <problem>".
std::string StretchProblem(const Material& m) {
  const json written = MaterialToJson(m);
  json root = json::object();
  // Through text, as a file would be: a NaN is written as null.
  if (written.contains("stretch")) root["stretch"] = json::parse(written["stretch"].dump());
  Material scratch;
  try {
    ReadStretch(JsonFields(""), root, &scratch);
  } catch (const InputError& e) {
    const std::string what = e.what();
    return what.rfind(": ", 0) == 0 ? what.substr(2) : what;
  }
  return "";
}

// A tensile curve built in code, in the file's form: a modulus when linear, else its knots
// (read back through TensileCurve::FromPoints, whose slopes may differ from the curve's).
json TensileCurveJson(const TensileCurve& c) {
  const std::vector<double>& e = c.strains();
  const std::vector<double>& force = c.forces();
  const std::vector<double>& k = c.slopes();
  if (e.size() == 2 && k[0] == k[1] && force[1] == k[0] * e[1])
    return {{"modulus_N_per_m", k[0]}};
  json points = json::array();
  for (size_t i = 1; i < e.size(); ++i) points.push_back({e[i], force[i]});
  return {{"curve", points}};
}

// The stretch block of MaterialToJson: the fields given (as read, or as built in code), not the
// defaulted ones unless code changed their value.
json StretchJson(const Material& m) {
  json st = json::object();
  const json& given = m.stretch_given.is_object() ? m.stretch_given : json::object();
  if (!m.orthotropic) {
    if (!m.IsDefaulted("stretch.stiffness_N_per_m") ||
        m.stretch_stiffness != kDefaultStretchStiffness)
      st["stiffness_N_per_m"] = m.stretch_stiffness;
    if (!m.IsDefaulted("stretch.poisson") || m.poisson != kDefaultPoisson)
      st["poisson"] = m.poisson;
  } else {
    const OrthotropicMembrane& o = *m.orthotropic;
    for (const char* dir : {"warp", "weft"}) {
      if (m.IsDefaulted(std::string("stretch.") + dir)) continue;
      st[dir] = given.contains(dir) ? given.at(dir)
                                    : TensileCurveJson(std::string(dir) == "warp" ? o.warp : o.weft);
    }
    if (!m.IsDefaulted("stretch.shear"))
      st["shear"] = given.contains("shear") ? given.at("shear")
                                            : json{{"modulus_N_per_m", o.shear_modulus}};
  }
  // A ratio is written when the file gave it or code set one other than the default.
  if (given.contains("compression_ratio") || m.compression_ratio != kDefaultCompressionRatio)
    st["compression_ratio"] = m.compression_ratio;
  if (given.contains("buckling_strain") || m.buckling_strain != 0.0)
    st["buckling_strain"] = m.buckling_strain;
  return st;
}

}  // namespace

OrthotropicMembrane DefaultOrthotropicMembrane() {
  return {TensileCurveFromKes(kDefaultWarpEmtPercent, kDefaultLinearity),
          TensileCurveFromKes(kDefaultWeftEmtPercent, kDefaultLinearity),
          KesShearToNewtonPerMetre(kDefaultShearKes)};
}

bool Material::IsDefaulted(const std::string& field) const {
  return std::find(defaulted.begin(), defaulted.end(), field) != defaulted.end();
}

std::vector<Note> MaterialDefaultNotes(const Material& m) {
  const auto text = [](const std::string& field, const std::string& value,
                       const std::string& what) {
    return field + " not given: " + value + ", " + what +
           " (docs/methods/materials.md, Membrane)";
  };
  const auto kes_curve = [](double emt) {
    return "KES EMT " + NumberText(emt) + " %, LT " + NumberText(kDefaultLinearity) +
           " (small-strain modulus " +
           NumberText(TensileCurveFromKes(emt, kDefaultLinearity).SmallStrainModulus(), 4) +
           " N/m)";
  };
  std::vector<Note> notes;
  for (const std::string& field : m.defaulted) {
    std::string t;
    if (field == "stretch.warp") {
      t = text(field, kes_curve(kDefaultWarpEmtPercent),
               "the warp tensile curve of a typical woven apparel fabric");
    } else if (field == "stretch.weft") {
      t = text(field, kes_curve(kDefaultWeftEmtPercent),
               "the weft tensile curve of a typical woven apparel fabric");
    } else if (field == "stretch.shear") {
      t = text(field,
               "KES G " + NumberText(kDefaultShearKes) + " gf/cm/deg (" +
                   NumberText(KesShearToNewtonPerMetre(kDefaultShearKes), 3) + " N/m)",
               "the shear rigidity of a typical woven apparel fabric");
    } else if (field == "stretch.compression_ratio") {
      t = text(field, NumberText(kDefaultCompressionRatio),
               "the membrane's stiffness in compression as a fraction of its tension's");
    } else if (field == "stretch.stiffness_N_per_m") {
      t = text(field, NumberText(kDefaultStretchStiffness) + " N/m",
               "the isotropic membrane's stretch stiffness");
    } else if (field == "stretch.poisson") {
      t = text(field, NumberText(kDefaultPoisson), "the isotropic membrane's Poisson ratio");
    } else {
      t = field + " not given: its default (docs/methods/materials.md, Membrane)";
    }
    notes.push_back({"membrane_default", t});
  }
  return notes;
}

bool Material::Check(std::string* why) const {
  std::string w;
  const auto field = [&w](const char* name, const std::string& problem) {
    if (w.empty() && !problem.empty()) w = std::string(name) + ": " + problem;
  };
  const auto number = [&field](const char* name, double v) {
    if (!std::isfinite(v)) field(name, "must be a number, got null");
    return std::isfinite(v);
  };
  const double gsm = units::SiToGsm(areal_density);
  if (number("areal_density_gsm", gsm))
    field("areal_density_gsm", ArealDensityProblem(gsm, Written(gsm)));
  if (w.empty()) w = LawProblem(bending, "bending");
  if (w.empty() && bending_weft) w = LawProblem(*bending_weft, "bending_weft");
  if (w.empty() && bending_bias) w = LawProblem(*bending_bias, "bending_bias");
  if (number("beta", beta)) field("beta", BetaProblem(beta, Written(beta)));
  if (w.empty()) w = StretchProblem(*this);
  if (number("friction", friction)) field("friction", FrictionProblem(friction, Written(friction)));
  if (why) *why = w;
  return w.empty();
}

Material ReadMaterial(const std::string& path) {
  std::stringstream buffer(ReadInputFile(path, "material file", 16u << 20));  // kilobytes in use
  if (buffer.str().find_first_not_of(" \t\r\n") == std::string::npos) {
    throw InputError(path + ": empty material file");
  }
  return ParseMaterialJson(buffer.str(), path);
}

nlohmann::json LawToJson(const BendingLaw& law, bool with_units) {
  nlohmann::json j;
  if (law.is_spline()) {
    const auto kes = [](const std::vector<double>& v, double (*to_kes)(double)) {
      nlohmann::json a = nlohmann::json::array();
      for (double x : v) a.push_back(to_kes(x));
      return a;
    };
    j = {{"law", "spline"},
         {"kappa", kes(law.knot_kappa(), units::SiCurvatureToKes)},
         {"moment", kes(law.knot_moment(), units::SiMomentToKes)}};
    if (!law.knot_moment_sd().empty())
      j["moment_sd"] = kes(law.knot_moment_sd(), units::SiMomentToKes);
  } else {
    j = {{"b1", law.b1_kes()}, {"b2", law.b2_kes()}, {"c1", law.c1_kes()}};
  }
  if (with_units) j["units"] = "kes";
  return j;
}

nlohmann::json MaterialToJson(const Material& m) {
  nlohmann::json j;
  if (!m.name.empty()) j["name"] = m.name;
  j["areal_density_gsm"] = units::SiToGsm(m.areal_density);
  j["bending"] = LawToJson(m.bending);
  if (m.bending_weft) j["bending_weft"] = LawToJson(*m.bending_weft);
  if (m.bending_bias) j["bending_bias"] = LawToJson(*m.bending_bias);
  j["beta"] = m.beta;
  if (json st = StretchJson(m); !st.empty()) j["stretch"] = std::move(st);
  j["friction"] = m.friction;
  for (const auto& [k, v] : m.extra.items()) j[k] = v;
  if (!m.fit.is_null()) j["fit"] = m.fit;
  return j;
}

}  // namespace textile
