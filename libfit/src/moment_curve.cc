#include "textile/fit/moment_curve.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "csv_text.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"
#include "textile/sim/law/material_parameters.h"

namespace textile {
namespace {

using internal::SplitComma;
using internal::Trim;

// Which columns hold κ and M, and the factors that take them to SI.
struct Columns {
  int kappa = -1, moment = -1;
  double kappa_to_si = 1.0, moment_to_si = 1.0;
};

Columns FindColumns(const std::vector<std::string>& header) {
  Columns c;
  for (int i = 0; i < static_cast<int>(header.size()); ++i) {
    const std::string& h = header[i];
    if (h == "kappa_per_m") c.kappa = i, c.kappa_to_si = 1.0;
    if (h == "kappa_per_cm") c.kappa = i, c.kappa_to_si = units::KesCurvatureToSi(1.0);
    if (h == "M_N") c.moment = i, c.moment_to_si = 1.0;
    if (h == "M_gfcm_per_cm") c.moment = i, c.moment_to_si = units::KesMomentToSi(1.0);
  }
  return c;
}

}  // namespace

MomentCurvePairs ParseMomentCurvatureCsv(const std::string& text, const std::string& source) {
  MomentCurvePairs out;
  out.source = source;
  std::stringstream in(text);
  std::string line;
  int line_no = 0;
  bool header_seen = false;
  Columns cols;
  while (std::getline(in, line)) {
    ++line_no;
    std::string t = Trim(line);
    if (line_no == 1 && t.rfind("\xEF\xBB\xBF", 0) == 0) t = t.substr(3);  // byte-order mark
    if (t.empty() || t[0] == '#') continue;
    const std::string where = source + ":" + std::to_string(line_no) + ": ";
    const std::vector<std::string> cells = SplitComma(t);
    if (!header_seen) {
      header_seen = true;
      cols = FindColumns(cells);
      if (cols.kappa < 0 || cols.moment < 0) {
        throw InputError(where + "the header must name a curvature column (kappa_per_m or "
                                 "kappa_per_cm) and a moment column (M_N or M_gfcm_per_cm), got '" +
                         t.substr(0, 60) + "'");
      }
      continue;
    }
    const int need = std::max(cols.kappa, cols.moment) + 1;
    if (static_cast<int>(cells.size()) < need)
      throw InputError(where + "expected at least " + std::to_string(need) + " cells");
    double v[2];
    const int at[2] = {cols.kappa, cols.moment};
    for (int k = 0; k < 2; ++k) {
      const std::string& cell = cells[at[k]];
      char* end = nullptr;
      v[k] = std::strtod(cell.c_str(), &end);
      if (cell.empty() || *end != '\0' || !std::isfinite(v[k]))
        throw InputError(where + "'" + cell.substr(0, 30) + "' is not a finite number");
    }
    if (v[0] < 0.0 || v[1] < 0.0)
      throw InputError(where + "curvature and moment must be >= 0 (a strip bending downwards)");
    out.kappa.push_back(v[0] * cols.kappa_to_si);
    out.moment.push_back(v[1] * cols.moment_to_si);
  }
  if (!header_seen) throw InputError(source + ": empty (no header)");
  if (out.kappa.size() < 2)
    throw InputError(source + ": needs at least 2 (curvature, moment) rows, got " +
                     std::to_string(out.kappa.size()));
  return out;
}

MomentCurvePairs ReadMomentCurvatureCsv(const std::string& path) {
  return ParseMomentCurvatureCsv(ReadInputFile(path, "moment-curvature file", 16u << 20), path);
}

double MomentSigma(const BendingLaw& law, const Eigen::Matrix3d& covariance, double kappa) {
  const std::array<double, 3> g = law.MomentGradient(kappa);
  const Eigen::Vector3d v(g[0], g[1], g[2]);
  return std::sqrt(std::max(0.0, v.dot(covariance * v)));
}

std::optional<Eigen::Matrix3d> FitCovariance(const Material& m, const std::string& source,
                                             std::string* why) {
  if (m.bending.is_spline() || (m.bending_weft && m.bending_weft->is_spline())) {
    *why = "no band: a spline law carries its band at its knots (moment_sd)";
    return std::nullopt;
  }
  const nlohmann::json& f = m.fit;
  if (!f.is_object() || !f.contains("covariance_kes")) {
    *why = "no band: the material carries no fit covariance";
    return std::nullopt;
  }
  for (const char* k : {"b1_sd", "b2_sd", "c1_sd"}) {
    if (!f.contains(k) || !f[k].is_number()) {
      *why = std::string("no band: ") + k + " is undetermined";
      return std::nullopt;
    }
  }
  try {
    return MaterialFitCovariance(m);
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
}

std::optional<double> FitCurvatureReach(const Material& m) {
  const nlohmann::json& f = m.fit;
  if (!f.is_object() || !f.contains("kappa_max_per_cm") || !f["kappa_max_per_cm"].is_number())
    return std::nullopt;
  return units::KesCurvatureToSi(f["kappa_max_per_cm"].get<double>());
}

}  // namespace textile
