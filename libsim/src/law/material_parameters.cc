#include "textile/sim/law/material_parameters.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>

#include "textile/sim/core/error.h"
#include "textile/sim/core/join_text.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

// The law a "b1"-style name addresses ("" the `bending` law, "bending_weft." ...), or null.
const std::optional<BendingLaw>* LawSlot(const Material& m, const std::string& prefix) {
  if (prefix == "bending_weft.") return &m.bending_weft;
  if (prefix == "bending_bias.") return &m.bending_bias;
  return nullptr;
}

// Splits "bending_weft.b1" into ("bending_weft.", "b1"); ("", "b1") for a bare constant.
bool SplitLawName(const std::string& name, std::string* prefix, std::string* constant) {
  const size_t dot = name.rfind('.');
  *prefix = dot == std::string::npos ? "" : name.substr(0, dot + 1);
  *constant = dot == std::string::npos ? name : name.substr(dot + 1);
  if (*constant != "b1" && *constant != "b2" && *constant != "c1") return false;
  return prefix->empty() || *prefix == "bending_weft." || *prefix == "bending_bias.";
}

// The Pabst law a constant's name addresses, or none (no such law, or a spline).
std::optional<BendingLaw> AddressedLaw(const Material& m, const std::string& prefix) {
  if (prefix.empty()) return m.bending.is_spline() ? std::nullopt : std::optional(m.bending);
  const std::optional<BendingLaw>& law = *LawSlot(m, prefix);
  if (!law || law->is_spline()) return std::nullopt;
  return law;
}

double LawConstant(const BendingLaw& law, const std::string& constant) {
  return constant == "b1" ? law.b1() : constant == "b2" ? law.b2() : law.c1();
}

TensileCurve ScaledCurve(const TensileCurve& c, double factor) {
  std::vector<double> strain(c.strains().begin() + 1, c.strains().end());
  std::vector<double> force(c.forces().begin() + 1, c.forces().end());
  std::vector<double> slope = c.slopes();
  for (double& f : force) f *= factor;
  for (double& s : slope) s *= factor;
  return TensileCurve::FromHermite(strain, force, slope);
}

[[noreturn]] void Unknown(const Material& m, const std::string& name) {
  throw InputError("'" + name + "' is not a parameter of this material; it has " +
                   JoinText(MaterialParameterNames(m), ", "));
}

}  // namespace

std::vector<std::string> MaterialParameterNames(const Material& m) {
  std::vector<std::string> names;
  for (const std::string prefix : {"", "bending_weft.", "bending_bias."}) {
    const std::optional<BendingLaw> law = AddressedLaw(m, prefix);
    if (!law) continue;
    for (const char* c : {"b1", "b2", "c1"})
      if (ParameterWithoutEffect(m, prefix + c).empty()) names.push_back(prefix + c);
  }
  names.insert(names.end(), {"beta", "areal_density_gsm"});
  if (m.orthotropic) {
    names.insert(names.end(), {"stretch.warp", "stretch.weft", "stretch.shear"});
  } else {
    names.insert(names.end(), {"stretch.stiffness_N_per_m", "stretch.poisson"});
  }
  names.push_back("stretch.compression_ratio");
  return names;
}

std::string ParameterWithoutEffect(const Material& m, const std::string& name) {
  GetMaterialParameter(m, name);  // throws for an unknown name
  std::string prefix, constant;
  if (!SplitLawName(name, &prefix, &constant)) return "";
  const double kappa0 = AddressedLaw(m, prefix)->kappa0();
  if (kappa0 == 0.0 && constant != "b2")
    return name + ": the law is linear (b1 = b2, kappa0 = 0: M = b2 kappa), so " + constant +
           " has no effect on it and b1 cannot move alone; ask for " + prefix + "b2";
  if (std::isinf(kappa0) && constant == "b2")
    return name + ": the law is linear (c1 = 0, kappa0 infinite: M = b1 kappa), so b2 never "
                  "takes over; ask for " + prefix + "b1 and " + prefix + "c1";
  return "";
}

MaterialParameterValue GetMaterialParameter(const Material& m, const std::string& name) {
  MaterialParameterValue v;
  v.defaulted = m.IsDefaulted(name);
  std::string prefix, constant;
  if (SplitLawName(name, &prefix, &constant)) {
    const std::optional<BendingLaw> law = AddressedLaw(m, prefix);
    if (!law) Unknown(m, name);
    v.si = LawConstant(*law, constant);
    v.lab = constant == "c1" ? units::SiQuadraticToKes(v.si) : units::SiStiffnessToKes(v.si);
    v.unit = constant == "c1" ? "gf·cm²" : "gf·cm";
    return v;
  }
  const auto plain = [&v](double si, double lab, const char* unit) {
    v.si = si;
    v.lab = lab;
    v.unit = unit;
    return v;
  };
  if (name == "beta") return plain(m.beta, m.beta, "-");
  if (name == "areal_density_gsm")
    return plain(m.areal_density, units::SiToGsm(m.areal_density), "g/m²");
  if (name == "stretch.compression_ratio")
    return plain(m.compression_ratio, m.compression_ratio, "-");
  if (m.orthotropic) {
    const OrthotropicMembrane& o = *m.orthotropic;
    if (name == "stretch.warp")
      return plain(o.warp.SmallStrainModulus(), o.warp.SmallStrainModulus(), "N/m");
    if (name == "stretch.weft")
      return plain(o.weft.SmallStrainModulus(), o.weft.SmallStrainModulus(), "N/m");
    if (name == "stretch.shear") return plain(o.shear_modulus, o.shear_modulus, "N/m/rad");
  } else {
    if (name == "stretch.stiffness_N_per_m")
      return plain(m.stretch_stiffness, m.stretch_stiffness, "N/m");
    if (name == "stretch.poisson") return plain(m.poisson, m.poisson, "-");
  }
  Unknown(m, name);
}

Material WithMaterialParameter(const Material& material, const std::string& name, double si) {
  const MaterialParameterValue old = GetMaterialParameter(material, name);  // throws if unknown
  if (!std::isfinite(si))
    throw InputError(name + ": must be a finite number, got " + NumberText(si));
  Material m = material;
  std::string prefix, constant;
  if (SplitLawName(name, &prefix, &constant)) {
    const BendingLaw law = *AddressedLaw(m, prefix);
    double k[3] = {law.b1(), law.b2(), law.c1()};
    k[constant == "b1" ? 0 : constant == "b2" ? 1 : 2] = si;
    if (constant == "b2" && law.kappa0() == 0.0) k[0] = si;  // M = b2 κ: the line's slope
    if (const std::string why = BendingLaw::Invalidity(k[0], k[1], k[2]); !why.empty())
      throw InputError(name + " = " + NumberText(si) + " (SI) makes no valid law: " + why);
    const BendingLaw changed = BendingLaw::FromSi(k[0], k[1], k[2]);
    if (prefix.empty())
      m.bending = changed;
    else if (prefix == "bending_weft.")
      m.bending_weft = changed;
    else
      m.bending_bias = changed;
  } else if (name == "beta") {
    m.beta = si;
  } else if (name == "areal_density_gsm") {
    m.areal_density = si;
  } else if (name == "stretch.compression_ratio") {
    m.compression_ratio = si;
  } else if (name == "stretch.stiffness_N_per_m") {
    m.stretch_stiffness = si;
  } else if (name == "stretch.poisson") {
    m.poisson = si;
  } else if (name == "stretch.shear") {
    if (!(si > 0.0)) throw InputError(name + ": must be > 0 N/m, got " + NumberText(si));
    m.orthotropic->shear_modulus = si;
  } else {  // stretch.warp, stretch.weft: the whole curve scaled
    if (!(si > 0.0)) throw InputError(name + ": must be > 0 N/m, got " + NumberText(si));
    TensileCurve& c = name == "stretch.warp" ? m.orthotropic->warp : m.orthotropic->weft;
    c = ScaledCurve(c, si / old.si);
  }
  // The value is no longer the file's nor a default (material.h: code that replaces a
  // membrane field erases it from stretch_given).
  if (name.rfind("stretch.", 0) == 0 && m.stretch_given.is_object())
    m.stretch_given.erase(name.substr(std::string("stretch.").size()));
  std::erase(m.defaulted, name);
  if (std::string why; !m.Check(&why))
    throw InputError(name + " = " + NumberText(si) + " (SI) makes no valid material: " + why);
  return m;
}

double MaterialParameterScale(const Material& m, const std::string& name) {
  const double v = std::abs(GetMaterialParameter(m, name).si);
  if (v > 0.0) return v;
  std::string prefix, constant;
  if (SplitLawName(name, &prefix, &constant)) return AddressedLaw(m, prefix)->b1() * 0.01;
  return 1.0;
}

std::optional<Eigen::Matrix3d> MaterialFitCovariance(const Material& m, std::string* why) {
  const auto none = [why](const std::string& reason) {
    if (why) *why = reason;
    return std::nullopt;
  };
  if (!m.fit.is_object() || !m.fit.contains("covariance_kes"))
    return none("the material carries no fit covariance (fit.covariance_kes)");
  for (const char* k : {"b1_sd", "b2_sd", "c1_sd"})
    if (m.fit.contains(k) && !m.fit[k].is_number())
      return none(std::string("the fit left ") + std::string(k, 2) +
                  " undetermined (fit." + k + " is null)");
  const nlohmann::json& c = m.fit["covariance_kes"];
  const double to_si[3] = {units::KesStiffnessToSi(1.0), units::KesStiffnessToSi(1.0),
                           units::KesQuadraticToSi(1.0)};
  Eigen::Matrix3d cov;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      if (!c.is_array() || c.size() != 3 || !c[i].is_array() || c[i].size() != 3 ||
          !c[i][j].is_number())
        throw InputError("fit.covariance_kes must be a 3×3 array of numbers");
      cov(i, j) = c[i][j].get<double>() * to_si[i] * to_si[j];
    }
  if (!cov.allFinite() || (cov - cov.transpose()).cwiseAbs().maxCoeff() >
                              1e-9 * cov.cwiseAbs().maxCoeff())
    throw InputError("fit.covariance_kes must be finite and symmetric");
  // Scaled to unit diagonal, so that b and c1's different units do not hide a negative mode.
  const Eigen::Vector3d d = cov.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::Matrix3d unit = d.asDiagonal() * cov * d.asDiagonal();
  if ((cov.diagonal().array() < 0.0).any() ||
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(unit).eigenvalues().minCoeff() < -1e-9)
    throw InputError("fit.covariance_kes is not positive semi-definite");
  return cov;
}

ParameterUncertainty DefaultParameterUncertainty(const Material& m, const std::string& name,
                                                 const std::optional<Eigen::Matrix3d>& covariance) {
  const MaterialParameterValue v = GetMaterialParameter(m, name);
  const double p = std::abs(v.si);
  const auto relative = [p](double ln, std::string source) {
    return ParameterUncertainty{ln, p * ln, std::move(source)};
  };
  const auto absolute = [p](double si, std::string source) {
    return ParameterUncertainty{p > 0.0 ? si / p : std::nan(""), si, std::move(source)};
  };
  const double decade = std::numbers::ln10;
  if (name == "b1" || name == "b2" || name == "c1") {
    if (covariance) {
      const int i = name == "b1" ? 0 : name == "b2" ? 1 : 2;
      return absolute(std::sqrt((*covariance)(i, i)), "the fit's covariance");
    }
    return relative(0.1, "10 % (the material carries no fit covariance)");
  }
  if (name.rfind("bending_", 0) == 0) return relative(0.1, "10 % (no covariance for this law)");
  if (name == "beta") return relative(0.0, "none (a chosen factor, not a measurement)");
  if (name == "areal_density_gsm") return relative(0.02, "2 % (a weighed specimen)");
  if (!v.defaulted) return relative(0.1, "10 % (a measured membrane value)");
  if (name == "stretch.poisson") return absolute(0.15, "±0.15 (unmeasured default)");
  if (name == "stretch.shear") return relative(std::log(2.5), "×/÷ 2.5 (unmeasured default)");
  return relative(decade, "×/÷ 10 (unmeasured default)");
}

ParameterStep DifferenceStep(const Material& m, const std::string& name, double relative_step) {
  const double p = GetMaterialParameter(m, name).si;
  const double h = relative_step * MaterialParameterScale(m, name);
  const auto at = [&](double value) -> std::optional<Material> {
    try {
      return WithMaterialParameter(m, name, value);
    } catch (const InputError&) {
      return std::nullopt;  // outside the valid range on this side
    }
  };
  std::optional<Material> up = at(p + h), down = at(p - h);
  if (up && down) return {std::move(*up), std::move(*down), 2.0 * h};
  if (up) return {std::move(*up), m, h};
  if (down) return {m, std::move(*down), h};
  throw InputError(name + ": no valid material within " + NumberText(relative_step) +
                   " of its value on either side, so it has no derivative");
}

void CheckSensitivityParameters(const Material& m, const std::vector<std::string>& names,
                                double relative_step) {
  for (size_t k = 0; k < names.size(); ++k) {
    if (std::find(names.begin(), names.begin() + static_cast<long>(k), names[k]) !=
        names.begin() + static_cast<long>(k))
      throw InputError(names[k] + ": named twice");
    if (const std::string why = ParameterWithoutEffect(m, names[k]); !why.empty())
      throw InputError(why);
    DifferenceStep(m, names[k], relative_step);
  }
}

InfluenceTable MakeInfluenceTable(const Material& material,
                                  const std::vector<std::string>& parameters,
                                  const std::vector<double>& d_q_d_p) {
  std::string no_covariance;
  const std::optional<Eigen::Matrix3d> covariance = MaterialFitCovariance(material, &no_covariance);
  Eigen::Vector3d law_gradient = Eigen::Vector3d::Zero();  // ∂Q/∂{b1, b2, c1}
  int law_terms = 0;
  InfluenceTable table;
  for (size_t k = 0; k < parameters.size(); ++k) {
    ParameterInfluence row;
    row.parameter = parameters[k];
    const MaterialParameterValue v = GetMaterialParameter(material, row.parameter);
    row.value = v.lab;
    row.unit = v.unit;
    row.defaulted = v.defaulted;
    row.d_q_d_p = d_q_d_p[k];
    row.d_q_d_ln_p = v.si * row.d_q_d_p;
    const ParameterUncertainty u = DefaultParameterUncertainty(material, row.parameter, covariance);
    row.uncertainty_ln = u.ln;
    row.uncertainty_source = u.source;
    row.change = std::abs(row.d_q_d_p) * u.si;
    const std::array<const char*, 3> law = {"b1", "b2", "c1"};
    for (int i = 0; i < 3; ++i)
      if (row.parameter == law[i]) {
        law_gradient(i) = row.d_q_d_p;
        ++law_terms;
      }
    table.rows.push_back(std::move(row));
  }
  std::stable_sort(table.rows.begin(), table.rows.end(),
                   [](const ParameterInfluence& a, const ParameterInfluence& b) {
                     return a.change > b.change;
                   });
  if (!covariance) {
    table.sigma_note = "no σ: " + no_covariance +
                       "; the table gives each input's change over its stated or default "
                       "uncertainty";
  } else if (law_terms < 3) {
    table.sigma_note = "no σ: b1, b2 and c1 must all be among the sensitivity's parameters";
  } else {
    table.sigma = std::sqrt(std::max(0.0, law_gradient.dot(*covariance * law_gradient)));
    table.sigma_note =
        "σ from the fit's covariance of b1, b2, c1 only; the other inputs' shares are the "
        "table's";
  }
  return table;
}

}  // namespace textile
