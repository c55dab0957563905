#include "textile/fit/seam_fit.h"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

#include "seam_fit_stages.h"
#include "textile/sim/core/error.h"
#include "textile/sim/io/json_text.h"
#include "textile/sim/core/number_text.h"

namespace textile {
namespace {

constexpr int kParams = 3;  // a2, a1, a0

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

// Parses one CSV field as a double, the whole field.
bool ParseNumber(const std::string& field, double* v) {
  const std::string t = Trim(field);
  if (t.empty()) return false;
  std::istringstream in(t);
  in >> *v;
  return !in.fail() && in.eof();
}

// The farthest sample from the seam line a fit takes [mm].
constexpr double kMaxSeamDistanceMm = 1000.0;

// The checks every sample must pass, wherever it came from; `where` prefixes the message.
void CheckSample(const SeamSample& p, const std::string& where) {
  if (!std::isfinite(p.d_mm) || !std::isfinite(p.factor) ||
      (!std::isnan(p.sd) && !std::isfinite(p.sd)))
    throw InputError(where + ": values must be finite numbers");
  if (p.d_mm < 0.0)
    throw InputError(where + ": d_mm = " + NumberText(p.d_mm) +
                     " is negative (distance from the seam line)");
  // A seam's influence spans centimetres (the ACPM sample's half-width is 100 mm); far larger
  // distances are a unit mix-up, and 1e200 mm overflowed the least squares to NaN coefficients.
  if (p.d_mm > kMaxSeamDistanceMm)
    throw InputError(where + ": d_mm = " + NumberText(p.d_mm) + " is beyond " +
                     NumberText(kMaxSeamDistanceMm) + " mm from the seam line (d in mm, not µm?)");
  if (!(p.factor >= 1e-6 && p.factor <= kMaxSeamFactor))
    throw InputError(where + ": factor = " + NumberText(p.factor) + " must be in [1e-6, " +
                     NumberText(kMaxSeamFactor) +
                     "] (stiffness relative to the plain fabric; more is likely a unit mix-up)");
  if (!std::isnan(p.sd) && !(p.sd > 0.0))
    throw InputError(where + ": sd = " + NumberText(p.sd) + " must be > 0");
  // The weights are 1/sd²: below 1e-9 of the factor they overflow the least squares (sd 1e-300
  // gave NaN coefficients); no measurement of a stiffness ratio is that exact.
  if (!std::isnan(p.sd) && p.sd < 1e-9 * p.factor)
    throw InputError(where + ": sd = " + NumberText(p.sd) + " is below 1e-9 of the factor " +
                     NumberText(p.factor));
  if (!std::isnan(p.sd) && p.sd > 1e6 * p.factor)  // weights underflowed: B_f = 0
    throw InputError(where + ": sd = " + NumberText(p.sd) + " is over 1e6 times the factor " +
                     NumberText(p.factor));
}

// Excel's "CSV UTF-8" (and some editors) start the file with a UTF-8 byte-order mark.
constexpr char kUtf8Bom[] = "\xEF\xBB\xBF";
std::string WithoutBom(const std::string& text) {
  return text.rfind(kUtf8Bom, 0) == 0 ? text.substr(3) : text;
}

double Quadratic(const std::array<double, 3>& a, double d) { return (a[0] * d + a[1]) * d + a[2]; }

// Where max(1, B_f) rises on [lo, hi]: B_f' = 2 a2 d + a1 is linear, so B_f increases on one
// interval [from, to] (possibly empty), and the rise is max(1, B_f(to)) - max(1, B_f(from)).
struct Rise {
  double amount = 0.0, from = 0.0, to = 0.0;
};
Rise RiseOn(const std::array<double, 3>& a, double lo, double hi) {
  double from = lo, to = hi;
  if (a[0] > 0.0) {
    from = std::max(lo, -a[1] / (2.0 * a[0]));
  } else if (a[0] < 0.0) {
    to = std::min(hi, -a[1] / (2.0 * a[0]));
  } else if (!(a[1] > 0.0)) {
    return {};
  }
  if (!(to > from)) return {};
  return {std::max(1.0, Quadratic(a, to)) - std::max(1.0, Quadratic(a, from)), from, to};
}

struct GslMatrixDeleter {
  void operator()(gsl_matrix* m) const { gsl_matrix_free(m); }
};
struct GslVectorDeleter {
  void operator()(gsl_vector* v) const { gsl_vector_free(v); }
};
struct GslWorkspaceDeleter {
  void operator()(gsl_multifit_linear_workspace* w) const { gsl_multifit_linear_free(w); }
};

}  // namespace

std::vector<SeamSample> ParseSeamSamplesCsv(const std::string& text, const std::string& source) {
  std::vector<SeamSample> samples;
  std::istringstream in(WithoutBom(text));
  std::string line;
  int line_no = 0, columns = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = Trim(line);
    if (t.empty() || t[0] == '#') continue;
    std::vector<std::string> fields;
    std::string f;
    std::istringstream row(t);
    while (std::getline(row, f, ',')) fields.push_back(Trim(f));
    if (t.back() == ',') fields.push_back("");
    const std::string where = source + ":" + std::to_string(line_no);
    if (columns == 0) {
      if (fields == std::vector<std::string>{"d_mm", "factor"}) {
        columns = 2;
      } else if (fields == std::vector<std::string>{"d_mm", "factor", "sd"}) {
        columns = 3;
      } else {
        // Quote at most 40 printable characters of whatever the line holds (binary garbage).
        std::string shown;
        for (char ch : t.substr(0, 40))
          shown += std::isprint(static_cast<unsigned char>(ch)) ? ch : '?';
        throw InputError(where + ": expected the header d_mm,factor or d_mm,factor,sd, got '" +
                         shown + (t.size() > 40 ? "...'" : "'"));
      }
      continue;
    }
    if (static_cast<int>(fields.size()) != columns)
      throw InputError(where + ": expected " + std::to_string(columns) + " values, got " +
                       std::to_string(fields.size()));
    SeamSample p;
    double* targets[3] = {&p.d_mm, &p.factor, &p.sd};
    for (int i = 0; i < columns; ++i) {
      if (!ParseNumber(fields[i], targets[i]))
        throw InputError(where + ": '" + fields[i] + "' is not a number");
    }
    CheckSample(p, where);
    samples.push_back(p);
  }
  if (columns == 0) throw InputError(source + ": empty (expected the header d_mm,factor[,sd])");
  return samples;
}

std::vector<SeamSample> SeamSamplesFromAcpmJson(const nlohmann::json& result,
                                                const std::string& source) {
  if (!result.is_object() || !result.contains("rays"))
    throw InputError(source + ": not an ACPM result (no \"rays\")");
  const nlohmann::json& rays = result["rays"];
  if (!rays.is_array()) throw InputError(source + ": rays: must be an array");
  std::vector<SeamSample> samples;
  for (size_t i = 0; i < rays.size(); ++i) {
    const std::string where = source + ": rays[" + std::to_string(i) + "]";
    const nlohmann::json& r = rays[i];
    if (!r.is_object()) throw InputError(where + ": must be an object");
    auto number = [&](const char* key, bool required, double* v) {
      if (!r.contains(key) || r[key].is_null()) {
        if (!required) return;
        if (std::string(key) == "d_mm")
          throw InputError(where + ".d_mm: no seam distance (a plain sample has no B_f(d) to fit)");
        throw InputError(where + "." + key + ": missing");
      }
      if (!r[key].is_number()) throw InputError(where + "." + key + ": must be a number");
      *v = r[key].get<double>();
    };
    SeamSample p;
    number("d_mm", true, &p.d_mm);
    number("factor", true, &p.factor);
    number("factor_sd", false, &p.sd);
    CheckSample(p, where);
    samples.push_back(p);
  }
  return samples;
}

int SeamLayersFromAcpmJson(const nlohmann::json& result, const std::string& source) {
  if (!result.is_object() || !result.contains("seam") || !result["seam"].is_object()) return 0;
  const nlohmann::json& seam = result["seam"];
  if (!seam.contains("profile") || !seam["profile"].is_object()) return 0;
  const nlohmann::json& profile = seam["profile"];
  if (!profile.contains("layers")) return 0;
  const nlohmann::json& layers = profile["layers"];
  const std::string where = source + ": seam.profile.layers";
  // Read wide and checked here: get<int>() would wrap a huge count into the valid range.
  if (layers.is_number_unsigned() || layers.is_number_integer()) {
    const bool in_range =
        layers.is_number_unsigned()
            ? layers.get<std::uint64_t>() >= 1 && layers.get<std::uint64_t>() <= 20
            : layers.get<std::int64_t>() >= 1 && layers.get<std::int64_t>() <= 20;
    if (!in_range) throw InputError(where + " must be in [1, 20], got " + layers.dump());
    return static_cast<int>(layers.get<std::int64_t>());
  }
  // 2.0 is a whole number; 3.5, "4" and null are not a count of plies.
  if (layers.is_number_float() && layers.get<double>() == std::floor(layers.get<double>()) &&
      layers.get<double>() >= 1.0 && layers.get<double>() <= 20.0)
    return static_cast<int>(layers.get<double>());
  throw InputError(where + " must be a whole number in [1, 20], got " + layers.dump());
}

SeamMeasurement ReadSeamMeasurement(const std::string& path) {
  // 64 MB: a measurement file is a few rows or one acpm result (kilobytes).
  const std::string text = WithoutBom(ReadInputFile(path, "seam measurement file", 64u << 20));
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) throw InputError(path + ": empty file");
  SeamMeasurement m;
  if (text[first] == '{') {
    const nlohmann::json result = ParseJsonText(text, path);
    m.samples = SeamSamplesFromAcpmJson(result, path);
    m.layers = SeamLayersFromAcpmJson(result, path);
  } else {
    m.samples = ParseSeamSamplesCsv(text, path);
  }
  return m;
}

std::vector<SeamSample> ReadSeamSamples(const std::string& path) {
  return ReadSeamMeasurement(path).samples;
}

bool SeamFitOptions::Check(std::string* why) const {
  std::ostringstream s;
  if (layers < 1 || layers > 20) {
    s << "layers must be in [1, 20], got " << layers;
  } else if (!std::isnan(influence_mm) && !(influence_mm >= 1.0 && influence_mm <= 1000.0)) {
    s << "influence_mm must be in [1, 1000] mm, got " << influence_mm;
  } else if (!(poor_probability > 0.0 && poor_probability < 1.0)) {
    s << "poor_probability must be in (0, 1), got " << poor_probability;
  } else if (!(poor_r2 >= 0.0 && poor_r2 <= 1.0)) {
    s << "poor_r2 must be in [0, 1], got " << poor_r2;
  } else if (!(poor_relative_rms >= 0.0 && poor_relative_rms < 1e6)) {
    s << "poor_relative_rms must be >= 0, got " << poor_relative_rms;
  } else if (!(rise_tolerance >= 0.0 && rise_tolerance < 1e6)) {
    s << "rise_tolerance must be >= 0, got " << rise_tolerance;
  }
  if (why != nullptr) *why = s.str();
  return s.str().empty();
}

namespace internal {

void CheckSeamData(SeamFitState* state) {
  const std::vector<SeamSample>& samples = state->samples;
  if (std::string why; !state->options.Check(&why)) throw InputError("seam fit options: " + why);
  const int n = static_cast<int>(samples.size());
  if (n < kParams)
    throw InputError(std::to_string(n) + " point(s): the quadratic B_f(d) has 3 coefficients, " +
                     "at least 3 points are needed");
  int with_sd = 0;
  std::set<double>& distinct = state->distinct;
  for (int i = 0; i < n; ++i) {
    CheckSample(samples[i], "point " + std::to_string(i + 1));
    with_sd += std::isnan(samples[i].sd) ? 0 : 1;
    distinct.insert(samples[i].d_mm);
  }
  if (with_sd != 0 && with_sd != n)
    throw InputError("sd is given for " + std::to_string(with_sd) + " of " + std::to_string(n) +
                     " points: give it for all or none");
  if (distinct.size() < kParams)
    throw InputError(std::to_string(distinct.size()) +
                     " distinct distance(s) d: a quadratic needs at least 3 (a seam across the "
                     "push direction gives every ray the same d)");
  // A seam stiffens the fabric. With every factor below 1 the written S = max(1, B_f) would
  // be 1 everywhere: the measurement discarded without a word. Most likely the ratio is
  // inverted (plain / seamed).
  const auto [lowest, highest] = std::minmax_element(
      samples.begin(), samples.end(),
      [](const SeamSample& l, const SeamSample& r) { return l.factor < r.factor; });
  if (highest->factor < 1.0)
    throw InputError("every factor is below 1 (" + NumberText(lowest->factor, 4) + " to " +
                     NumberText(highest->factor, 4) +
                     "): a seam would make the fabric softer, and S = max(1, B_f) would be 1 "
                     "everywhere; is the ratio inverted (plain / seamed)? Its inverse is " +
                     NumberText(1.0 / highest->factor, 4) + " to " +
                     NumberText(1.0 / lowest->factor, 4));

  SeamFitSummary& fit = state->fit;
  fit.num_points = n;
  fit.distinct_distances = static_cast<int>(distinct.size());
  fit.dof = n - kParams;
  fit.weighted = with_sd == n;
  fit.range_mm = {*distinct.begin(), *distinct.rbegin()};
}

void SolveSeamQuadratic(SeamFitState* state) {
  const std::vector<SeamSample>& samples = state->samples;
  SeamFitSummary& fit = state->fit;
  const int n = static_cast<int>(samples.size());
  // Design matrix rows (d², d, 1), weights 1/sd² (or 1); d in mm as in Table 2.
  std::unique_ptr<gsl_matrix, GslMatrixDeleter> x(gsl_matrix_alloc(n, kParams));
  std::unique_ptr<gsl_matrix, GslMatrixDeleter> cov(gsl_matrix_alloc(kParams, kParams));
  std::unique_ptr<gsl_vector, GslVectorDeleter> y(gsl_vector_alloc(n)), w(gsl_vector_alloc(n)),
      c(gsl_vector_alloc(kParams));
  std::unique_ptr<gsl_multifit_linear_workspace, GslWorkspaceDeleter> work(
      gsl_multifit_linear_alloc(n, kParams));
  for (int i = 0; i < n; ++i) {
    const double d = samples[i].d_mm;
    gsl_matrix_set(x.get(), i, 0, d * d);
    gsl_matrix_set(x.get(), i, 1, d);
    gsl_matrix_set(x.get(), i, 2, 1.0);
    gsl_vector_set(y.get(), i, samples[i].factor);
    gsl_vector_set(w.get(), i, fit.weighted ? 1.0 / (samples[i].sd * samples[i].sd) : 1.0);
  }
  double chi2 = 0.0;
  gsl_error_handler_t* old_handler = gsl_set_error_handler_off();
  const int status =
      gsl_multifit_wlinear(x.get(), w.get(), y.get(), c.get(), cov.get(), &chi2, work.get());
  gsl_set_error_handler(old_handler);
  if (status != GSL_SUCCESS)
    throw ComputeError(std::string("seam fit: GSL weighted least squares failed: ") +
                       gsl_strerror(status));
  for (int k = 0; k < kParams; ++k) {
    fit.coefficients_mm[k] = gsl_vector_get(c.get(), k);
    for (int l = 0; l < kParams; ++l) fit.covariance(k, l) = gsl_matrix_get(cov.get(), k, l);
  }
  fit.chi2 = chi2;
  // (XᵀWX)⁻¹ is the covariance when the sd are true 1-σ; without them every point gets the
  // residual variance χ²/dof as its variance (undefined for dof = 0).
  if (fit.weighted) {
    fit.covariance_known = true;
    fit.chi2_probability = fit.dof > 0 ? gsl_cdf_chisq_Q(chi2, fit.dof) : 1.0;
  } else if (fit.dof > 0) {
    fit.covariance *= chi2 / fit.dof;
    fit.covariance_known = true;
  } else {
    fit.covariance.setZero();
  }
  fit.covariance = 0.5 * (fit.covariance + fit.covariance.transpose()).eval();
}

void MeasureSeamResiduals(SeamFitState* state) {
  const std::vector<SeamSample>& samples = state->samples;
  SeamFitSummary& fit = state->fit;
  const int n = static_cast<int>(samples.size());
  double ss_res = 0.0, ss_tot = 0.0, mean = 0.0;
  for (const auto& p : samples) mean += p.factor / n;
  for (const auto& p : samples) {
    const double d = p.d_mm;
    const double r = p.factor - (fit.coefficients_mm[0] * d * d + fit.coefficients_mm[1] * d +
                                 fit.coefficients_mm[2]);
    ss_res += r * r;
    ss_tot += (p.factor - mean) * (p.factor - mean);
    fit.max_residual = std::max(fit.max_residual, std::abs(r));
  }
  state->mean_factor = mean;
  fit.rms = std::sqrt(ss_res / n);
  fit.rms_relative = fit.rms / mean;  // mean > 0: every factor is
  // Factors that do not vary leave no variance to explain: the fit is perfect when it
  // reproduces them (r² = 1; it was NaN, printed "nan" and flagged as poor), undefined if not.
  const double round_off = 1e-20 * n * mean * mean;
  fit.r2 = ss_tot > round_off    ? 1.0 - ss_res / ss_tot
           : ss_res <= round_off ? 1.0
                                 : std::numeric_limits<double>::quiet_NaN();
}

void JudgeSeamFit(SeamFitState* state) {
  const SeamFitOptions& options = state->options;
  SeamFitSummary& fit = state->fit;
  if (fit.weighted && fit.dof > 0 && fit.chi2_probability < options.poor_probability) {
    fit.poor = true;
    fit.poor_reason =
        "residuals too large for the stated sd: chi2/dof = " + NumberText(fit.chi2 / fit.dof, 4) +
        ", Q(chi2, " + std::to_string(fit.dof) + ") = " + NumberText(fit.chi2_probability, 3) +
        " < " + NumberText(options.poor_probability);
  } else if (!fit.weighted && fit.dof > 0 && !(fit.r2 >= options.poor_r2) &&
             fit.rms_relative > options.poor_relative_rms) {
    // r² alone judges a flat profile by its round-off: with no variance to explain, residuals
    // of 0.001 on factors of 2 gave r² = 0.11. A fit is poor when it misses the trend (low r²)
    // by residuals that matter against the factors themselves.
    fit.poor = true;
    fit.poor_reason =
        "the quadratic explains only " +
        (std::isnan(fit.r2) ? std::string("none") : NumberText(100.0 * fit.r2, 3) + " %") +
        " of the factor's variance (r2 < " + NumberText(options.poor_r2) +
        ") and its rms residual " + NumberText(fit.rms, 3) + " is " +
        NumberText(100.0 * fit.rms_relative, 3) + " % of the mean factor " +
        NumberText(state->mean_factor, 4) + " (> " + NumberText(100.0 * options.poor_relative_rms) +
        " %)";
  }
}

void StartSeamProfile(SeamFitState* state) {
  const SeamFitOptions& options = state->options;
  SeamFitSummary& fit = state->fit;
  SeamProfile& p = fit.profile;
  p.type = "fitted";
  p.name = options.name;
  p.layers = options.layers;
  p.coefficients_mm = fit.coefficients_mm;
  p.range_mm = fit.range_mm;
  if (!(p.range_mm[1] > p.range_mm[0])) p.range_mm[1] = p.range_mm[0] + 1.0;  // not reached
  if (fit.covariance_known) p.covariance = fit.covariance;
  // The influence range: where the data are, unless given. Beyond d_max only the value and
  // slope of B_f at d_max enter (the fade, seam.h), so the default extrapolates nothing.
  fit.influence_from_data = std::isnan(options.influence_mm);
  fit.influence_mm =
      fit.influence_from_data ? std::max(1.0, fit.range_mm[1]) : options.influence_mm;
  p.influence_mm = fit.influence_mm;
}

void CheckExtrapolation(SeamFitState* state) {
  SeamFitSummary& fit = state->fit;
  const double hi = fit.range_mm[1];
  if (!(fit.influence_mm > hi)) return;
  const auto& a = fit.coefficients_mm;
  const Rise rise = RiseOn(a, hi, fit.influence_mm);
  if (rise.amount > state->options.rise_tolerance) {
    std::string advice = "leave the influence range to the data (" + NumberText(hi, 4) + " mm)";
    if (rise.from > hi) advice += " or end it by " + NumberText(rise.from, 4) + " mm";
    throw InputError("influence range " + NumberText(fit.influence_mm) +
                     " mm reaches beyond the data (d up to " + NumberText(hi, 4) +
                     " mm), and there the fitted B_f rises from " +
                     NumberText(Quadratic(a, rise.from), 4) + " at " + NumberText(rise.from, 4) +
                     " mm to " + NumberText(Quadratic(a, rise.to), 4) + " at " +
                     NumberText(rise.to, 4) +
                     " mm: a seam stiffer away from its line is the polynomial extrapolated, "
                     "not measured; " +
                     advice);
  }
  if (!fit.influence_from_data)
    fit.notes.push_back(
        {"influence_beyond_data", "the influence range " + NumberText(fit.influence_mm) +
                                      " mm reaches beyond the data (d up to " + NumberText(hi, 4) +
                                      " mm): S extrapolates the fit there, B_f " +
                                      NumberText(Quadratic(a, hi), 4) + " -> " +
                                      NumberText(Quadratic(a, fit.influence_mm), 4)});
}

void CheckSeamProfile(const SeamFitState& state) {
  const SeamProfile& p = state.fit.profile;
  if (std::string why; !p.Check(&why))
    throw ComputeError("fitted B_f(d) = " + NumberText(p.coefficients_mm[0]) + " d² + " +
                       NumberText(p.coefficients_mm[1]) + " d + " +
                       NumberText(p.coefficients_mm[2]) +
                       " cannot serve as a seam profile: " + why);
}

void NoteInfluenceInsideData(SeamFitState* state) {
  SeamFitSummary& fit = state->fit;
  const SeamProfile& p = fit.profile;
  const double hi = fit.range_mm[1];
  if (!(fit.influence_mm < hi)) return;
  // S fades to 1 from d_max on: say how far it then lies from the points it leaves out.
  int beyond = 0;
  const SeamSample* worst = nullptr;
  for (const auto& s : state->samples) {
    if (s.d_mm <= fit.influence_mm) continue;
    ++beyond;
    if (worst == nullptr || std::abs(s.factor - p.Multiplier(s.d_mm)) >
                                std::abs(worst->factor - p.Multiplier(worst->d_mm)))
      worst = &s;
  }
  fit.notes.push_back(
      {"influence_inside_data",
       "the influence range " + NumberText(fit.influence_mm) +
           " mm ends inside the data (d up to " + NumberText(hi, 4) + " mm): S fades to 1 by " +
           NumberText(fit.influence_mm + p.fade_mm) + " mm; at " + std::to_string(beyond) +
           " point(s) beyond it S departs from the measured factor by up to " +
           NumberText(std::abs(worst->factor - p.Multiplier(worst->d_mm)), 3) +
           " (S = " + NumberText(p.Multiplier(worst->d_mm), 4) + " where the data say " +
           NumberText(worst->factor, 4) + " at " + NumberText(worst->d_mm, 4) + " mm)"});
}

void NoteFadeOvershoot(SeamFitState* state) {
  SeamFitSummary& fit = state->fit;
  const SeamProfile& p = fit.profile;
  const auto& a = fit.coefficients_mm;
  // The fade starts with B_f's slope at d_max: a fit that still rises there overshoots.
  double peak = p.Multiplier(fit.influence_mm), peak_at = fit.influence_mm;
  for (int k = 1; k <= 200; ++k) {
    const double d = fit.influence_mm + p.fade_mm * k / 200.0;
    if (p.Multiplier(d) > peak) peak = p.Multiplier(d), peak_at = d;
  }
  if (peak > p.Multiplier(fit.influence_mm) + state->options.rise_tolerance)
    fit.notes.push_back(
        {"fade_overshoot", "B_f still rises at d_max = " + NumberText(fit.influence_mm, 4) +
                               " mm (slope " + NumberText(2.0 * a[0] * fit.influence_mm + a[1], 3) +
                               " /mm); the fade to 1, which starts with that slope, peaks at S = " +
                               NumberText(peak, 4) + " at " + NumberText(peak_at, 4) + " mm"});
}

}  // namespace internal

SeamFitSummary FitSeamFactor(const std::vector<SeamSample>& samples,
                             const SeamFitOptions& options) {
  internal::SeamFitState state(samples, options);
  internal::CheckSeamData(&state);
  internal::SolveSeamQuadratic(&state);
  internal::MeasureSeamResiduals(&state);
  internal::JudgeSeamFit(&state);
  internal::StartSeamProfile(&state);
  internal::CheckExtrapolation(&state);
  internal::CheckSeamProfile(state);
  internal::NoteInfluenceInsideData(&state);
  internal::NoteFadeOvershoot(&state);
  state.fit.profile.fit = state.fit.Report();
  return std::move(state.fit);
}

nlohmann::json SeamFitSummary::Report() const {
  auto or_null = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json sd = nlohmann::json::array();
  for (int k = 0; k < kParams; ++k)
    sd.push_back(covariance_known ? nlohmann::json(std::sqrt(covariance(k, k))) : nlohmann::json());
  // The notes' texts, as the seam file has always carried them.
  nlohmann::json note_texts = nlohmann::json::array();
  for (const Note& note : notes) note_texts.push_back(note.text);
  return {{"method", "gsl_multifit_wlinear"},
          {"weighted", weighted},
          {"points", num_points},
          {"distinct_d", distinct_distances},
          {"dof", dof},
          {"chi2", chi2},
          {"chi2_per_dof", dof > 0 ? nlohmann::json(chi2 / dof) : nlohmann::json()},
          {"chi2_probability", or_null(chi2_probability)},
          {"rms", rms},
          {"rms_relative", rms_relative},
          {"max_residual", max_residual},
          {"r2", or_null(r2)},
          {"range_mm", range_mm},
          {"coefficients_sd", sd},
          {"covariance_known", covariance_known},
          {"poor", poor},
          {"poor_reason", poor_reason},
          {"influence_mm", influence_mm},
          {"influence_from", influence_from_data ? "data" : "option"},
          {"notes", note_texts}};
}

std::string SeamFitSummary::BriefReport() const {
  std::ostringstream s;
  s.precision(4);
  const char* names[3] = {"a2", "a1", "a0"};
  s << "B_f(d) = " << NumberText(coefficients_mm[0], 5) << " d² + "
    << NumberText(coefficients_mm[1], 5) << " d + " << NumberText(coefficients_mm[2], 5)
    << " (d in mm);";
  for (int k = 0; k < kParams; ++k) {
    s << " " << names[k] << " ± "
      << (covariance_known ? NumberText(std::sqrt(covariance(k, k)), 3) : std::string("?"));
    if (k < kParams - 1) s << ",";
  }
  s << " (1-σ" << (weighted ? ", from the given sd" : ", from the scatter") << "); " << num_points
    << " points, d in [" << NumberText(range_mm[0], 4) << ", " << NumberText(range_mm[1], 4)
    << "] mm, rms " << NumberText(rms, 3) << ", r² "
    << (std::isfinite(r2) ? NumberText(r2, 5) : std::string("n/a"));
  if (weighted && dof > 0) s << ", chi²/dof " << NumberText(chi2 / dof, 3);
  if (poor) s << "; POOR FIT: " << poor_reason;
  return s.str();
}

}  // namespace textile
