#include "textile/sim/law/material.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

#include "textile/sim/core/error.h"
#include "textile/sim/io/json_text.h"
#include "textile/sim/law/textile_range.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

using nlohmann::json;

// Plausibility bounds. Outside them a value is far more likely a unit mix-up (an "si" file
// written in KES numbers, mm for m) than a fabric, so the file is refused with a hint.
// The ranges are textile_range.h's (docs/methods/materials.md).
using range::kMaxGsm;
using range::kMinGsm;
constexpr double kMinBKes = range::kMinStiffnessKes, kMaxBKes = range::kMaxStiffnessKes;
constexpr double kMaxAbsC1Kes = range::kMaxAbsQuadraticKes;
constexpr double kMinBeta = 1e-3, kMaxBeta = 1e3;  // [-]

// The text of a JSON value in a message, cut to 40 characters.
std::string Brief(const json& v) {
  std::string s = v.dump();
  return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

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

std::string StretchStiffnessProblem(double k) {
  if (k <= 0.0) return "must be > 0 N/m";
  if (k > 1e7) return "suspicious magnitude, above 1e7 N/m";
  return "";
}

std::string PoissonProblem(double nu) {
  return nu < 0.0 || nu >= 0.5 ? "must lie in [0, 0.5)" : "";
}

std::string CompressionRatioProblem(double r) {
  return r >= kMinCompressionRatio && r <= 1.0
             ? ""
             : "must lie in [0.001, 1] (1: as stiff as in tension)";
}

std::string FrictionProblem(double mu) {
  return mu < 0.0 || mu > 10.0 ? "must lie in [0, 10]" : "";
}

class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void Fail(const std::string& field, const std::string& problem) const {
    throw InputError(source_ + ": " + field + ": " + problem);
  }

  double Number(const json& obj, const std::string& key, const std::string& field) const {
    const json& v = obj.at(key);
    if (!v.is_number()) Fail(field, "must be a number, got " + Brief(v));
    const double d = v.get<double>();
    if (!std::isfinite(d)) Fail(field, "must be finite, got " + Brief(v));
    return d;
  }

  void CheckKeys(const json& obj, const std::string& where, const std::set<std::string>& known) const {
    for (const auto& [key, value] : obj.items()) {
      if (!known.count(key)) {
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        Fail(where.empty() ? key : where + "." + key, "unknown field (known: " + list + ")");
      }
    }
  }

  BendingLaw Law(const json& root, const std::string& key) const {
    const json& b = root.at(key);
    if (!b.is_object()) {
      Fail(key,
           "must be an object {\"units\", \"b1\", \"b2\", \"c1\"} or {\"law\": \"spline\", "
           "\"units\", \"kappa\", \"moment\"}");
    }
    std::string law = "pabst";
    if (b.contains("law")) {
      if (!b.at("law").is_string()) Fail(key + ".law", "must be \"pabst\" or \"spline\"");
      law = b.at("law").get<std::string>();
      if (law != "pabst" && law != "spline") {
        Fail(key + ".law",
             "unknown law '" + law + "' (use \"pabst\": b1, b2, c1; or \"spline\": kappa, moment)");
      }
    }
    if (law == "spline") return SplineLaw(b, key);
    CheckKeys(b, key, {"law", "units", "b1", "b2", "c1"});
    for (const char* k : {"units", "b1", "b2", "c1"}) {
      if (!b.contains(k)) Fail(key + "." + k, "missing");
    }
    const bool kes = Units(b, key, "gf·cm, gf·cm²", "N·m, N·m²");
    double v[3];
    const char* names[3] = {"b1", "b2", "c1"};
    for (int i = 0; i < 3; ++i) v[i] = Number(b, names[i], key + "." + names[i]);
    // Everything below in KES, which is how people read these numbers.
    const double b1 = kes ? v[0] : units::SiStiffnessToKes(v[0]);
    const double b2 = kes ? v[1] : units::SiStiffnessToKes(v[1]);
    const double c1 = kes ? v[2] : units::SiQuadraticToKes(v[2]);
    const std::string unit_hint = kes ? " (units: kes)" : " (units: si; is this file in kes?)";
    const std::string got_b[2] = {Brief(b.at("b1")), Brief(b.at("b2"))};
    if (std::string p = PabstLawProblem(b1, b2, c1, key, got_b, unit_hint); !p.empty())
      throw InputError(source_ + ": " + p);
    const double sb1 = units::KesStiffnessToSi(b1), sb2 = units::KesStiffnessToSi(b2);
    const double sc1 = units::KesQuadraticToSi(c1);
    return BendingLaw::FromSi(sb1, sb2, sc1);
  }

  // The "units" field of a law object: true for "kes", false for "si".
  bool Units(const json& b, const std::string& key, const char* kes_units,
             const char* si_units) const {
    if (!b.at("units").is_string()) Fail(key + ".units", "must be \"kes\" or \"si\"");
    const std::string units = b.at("units").get<std::string>();
    if (units != "kes" && units != "si") {
      Fail(key + ".units", "unknown units '" + units + "' (use \"kes\": " + kes_units +
                               "; or \"si\": " + si_units + ")");
    }
    return units == "kes";
  }

  std::vector<double> Numbers(const json& obj, const std::string& key,
                              const std::string& field) const {
    const json& v = obj.at(key);
    if (!v.is_array()) Fail(field, "must be an array of numbers, got " + Brief(v));
    std::vector<double> out;
    for (size_t i = 0; i < v.size(); ++i) {
      if (!v[i].is_number())
        Fail(field + "[" + std::to_string(i) + "]", "must be a number, got " + Brief(v[i]));
      out.push_back(v[i].get<double>());
    }
    return out;
  }

  // {"law": "spline", "units", "kappa", "moment"[, "moment_sd"]}: knots in 1/cm and gf·cm/cm
  // ("kes") or 1/m and N ("si").
  BendingLaw SplineLaw(const json& b, const std::string& key) const {
    CheckKeys(b, key, {"law", "units", "kappa", "moment", "moment_sd"});
    for (const char* k : {"units", "kappa", "moment"}) {
      if (!b.contains(k))
        Fail(key + "." + k,
             "missing (a spline law is {\"law\": \"spline\", \"units\", \"kappa\", \"moment\"})");
    }
    const bool kes =
        Units(b, key, "kappa in 1/cm, moment in gf·cm/cm", "kappa in 1/m, moment in N");
    std::vector<double> kappa = Numbers(b, "kappa", key + ".kappa");
    std::vector<double> moment = Numbers(b, "moment", key + ".moment");
    std::vector<double> sd;
    if (b.contains("moment_sd")) sd = Numbers(b, "moment_sd", key + ".moment_sd");
    if (std::string p = SplineLawProblem(kappa, moment, sd, key, kes); !p.empty())
      throw InputError(source_ + ": " + p);
    if (kes) return BendingLaw::FromSplineKes(std::move(kappa), std::move(moment), std::move(sd));
    return BendingLaw::FromSpline(std::move(kappa), std::move(moment), std::move(sd));
  }

 private:
  std::string source_;
};

}  // namespace

Material ParseMaterialJson(const std::string& text, const std::string& source) {
  Reader r(source);
  const json root = ParseJsonText(text, source);
  if (!root.is_object()) r.Fail("(top level)", "must be a JSON object");
  r.CheckKeys(root, "", {"name", "areal_density_gsm", "bending", "bending_weft", "beta", "stretch",
                         "friction", "fit", "notes", "assumptions", "source"});
  Material m;
  if (root.contains("name")) {
    if (!root["name"].is_string()) r.Fail("name", "must be a string");
    m.name = root["name"].get<std::string>();
  }
  if (!root.contains("areal_density_gsm")) r.Fail("areal_density_gsm", "missing (g/m², required)");
  const double gsm = r.Number(root, "areal_density_gsm", "areal_density_gsm");
  if (std::string p = ArealDensityProblem(gsm, Brief(root["areal_density_gsm"])); !p.empty())
    r.Fail("areal_density_gsm", p);
  m.areal_density = units::GsmToSi(gsm);
  if (!root.contains("bending")) r.Fail("bending", "missing (required: {\"units\", \"b1\", \"b2\", \"c1\"})");
  m.bending = r.Law(root, "bending");
  if (root.contains("bending_weft")) m.bending_weft = r.Law(root, "bending_weft");
  if (root.contains("beta")) {
    m.beta = r.Number(root, "beta", "beta");
    if (std::string p = BetaProblem(m.beta, Brief(root["beta"])); !p.empty()) r.Fail("beta", p);
  }
  if (root.contains("stretch")) {
    const json& st = root["stretch"];
    if (!st.is_object())
      r.Fail("stretch",
             "must be an object {\"stiffness_N_per_m\", \"poisson\", \"compression_ratio\"}");
    r.CheckKeys(st, "stretch", {"stiffness_N_per_m", "poisson", "compression_ratio"});
    if (st.contains("stiffness_N_per_m")) {
      m.stretch_stiffness = r.Number(st, "stiffness_N_per_m", "stretch.stiffness_N_per_m");
      if (std::string p = StretchStiffnessProblem(m.stretch_stiffness); !p.empty())
        r.Fail("stretch.stiffness_N_per_m", p);
    }
    if (st.contains("poisson")) {
      m.poisson = r.Number(st, "poisson", "stretch.poisson");
      if (std::string p = PoissonProblem(m.poisson); !p.empty()) r.Fail("stretch.poisson", p);
    }
    if (st.contains("compression_ratio")) {
      m.compression_ratio = r.Number(st, "compression_ratio", "stretch.compression_ratio");
      if (std::string p = CompressionRatioProblem(m.compression_ratio); !p.empty())
        r.Fail("stretch.compression_ratio", p);
    }
  }
  if (root.contains("friction")) {
    m.friction = r.Number(root, "friction", "friction");
    if (std::string p = FrictionProblem(m.friction); !p.empty()) r.Fail("friction", p);
  }
  if (root.contains("fit")) {
    if (!root["fit"].is_object()) r.Fail("fit", "must be an object");
    m.fit = root["fit"];
  }
  for (const char* k : {"notes", "assumptions", "source"}) {
    if (root.contains(k)) m.extra[k] = root[k];
  }
  return m;
}

namespace {

// A number as MaterialToJson writes it (JSON has no NaN or infinity: null).
std::string Written(double v) { return Brief(json(v)); }

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
    field("stretch.stiffness_N_per_m", StretchStiffnessProblem(stretch_stiffness));
  if (number("stretch.poisson", poisson)) field("stretch.poisson", PoissonProblem(poisson));
  if (number("stretch.compression_ratio", compression_ratio))
    field("stretch.compression_ratio", CompressionRatioProblem(compression_ratio));
  if (number("friction", friction)) field("friction", FrictionProblem(friction));
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
