#include "textile/sim/law/material.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include "textile/sim/core/error.h"
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

// {"stiffness_N_per_m", "poisson", "compression_ratio"}, each optional, into m.
void ReadStretch(const JsonFields& f, const json& root, Material* m) {
  const json& st = f.Object(root["stretch"], "stretch",
                            "{\"stiffness_N_per_m\", \"poisson\", \"compression_ratio\"}");
  f.CheckKeys(st, "stretch", {"stiffness_N_per_m", "poisson", "compression_ratio"});
  if (st.contains("stiffness_N_per_m")) {
    const json& v = st["stiffness_N_per_m"];
    m->stretch_stiffness = f.Number(v, "stretch.stiffness_N_per_m");
    Refuse(f, "stretch.stiffness_N_per_m",
           StretchStiffnessProblem(m->stretch_stiffness, JsonFields::Brief(v)));
  }
  if (st.contains("poisson")) {
    const json& v = st["poisson"];
    m->poisson = f.Number(v, "stretch.poisson");
    Refuse(f, "stretch.poisson", PoissonProblem(m->poisson, JsonFields::Brief(v)));
  }
  if (st.contains("compression_ratio")) {
    const json& v = st["compression_ratio"];
    m->compression_ratio = f.Number(v, "stretch.compression_ratio");
    Refuse(f, "stretch.compression_ratio",
           CompressionRatioProblem(m->compression_ratio, JsonFields::Brief(v)));
  }
}

// areal_density_gsm: required, > 0 and within the textile range [kg/m² returned].
double ReadArealDensity(const JsonFields& f, const json& root) {
  const json& v = f.Require(root, "areal_density_gsm", "g/m², required");
  const double gsm = f.Number(v, "areal_density_gsm");
  Refuse(f, "areal_density_gsm", ArealDensityProblem(gsm, JsonFields::Brief(v)));
  return units::GsmToSi(gsm);
}

}  // namespace

Material ParseMaterialJson(const std::string& text, const std::string& source) {
  const JsonFields f(source);
  const json root = ParseJsonText(text, source);
  f.RequireObject(root);
  f.CheckKeys(root, "", {"name", "areal_density_gsm", "bending", "bending_weft", "beta", "stretch",
                         "friction", "fit", "notes", "assumptions", "source"});
  Material m;
  if (root.contains("name")) m.name = f.String(root["name"], "name");
  m.areal_density = ReadArealDensity(f, root);
  f.Require(root, "bending", "required: {\"units\", \"b1\", \"b2\", \"c1\"}");
  m.bending = Law(f, root, "bending");
  if (root.contains("bending_weft")) m.bending_weft = Law(f, root, "bending_weft");
  if (root.contains("beta")) {
    m.beta = f.Number(root["beta"], "beta");
    Refuse(f, "beta", BetaProblem(m.beta, JsonFields::Brief(root["beta"])));
  }
  if (root.contains("stretch")) ReadStretch(f, root, &m);
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

}  // namespace

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
  if (number("beta", beta)) field("beta", BetaProblem(beta, Written(beta)));
  if (number("stretch.stiffness_N_per_m", stretch_stiffness))
    field("stretch.stiffness_N_per_m",
          StretchStiffnessProblem(stretch_stiffness, Written(stretch_stiffness)));
  if (number("stretch.poisson", poisson)) field("stretch.poisson", PoissonProblem(poisson, Written(poisson)));
  if (number("stretch.compression_ratio", compression_ratio))
    field("stretch.compression_ratio",
          CompressionRatioProblem(compression_ratio, Written(compression_ratio)));
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
  j["beta"] = m.beta;
  j["stretch"] = {{"stiffness_N_per_m", m.stretch_stiffness}, {"poisson", m.poisson}};
  if (m.compression_ratio != 1.0) j["stretch"]["compression_ratio"] = m.compression_ratio;
  j["friction"] = m.friction;
  for (const auto& [k, v] : m.extra.items()) j[k] = v;
  if (!m.fit.is_null()) j["fit"] = m.fit;
  return j;
}

}  // namespace textile
