#include "textile/sim/scenes/drape_compare.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/core/units.h"
#include "textile/sim/io/json_text.h"

namespace textile {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegree = kPi / 180.0;
// The radii compared are the flags' values (mm, as typed), not measured lengths: 0.01 mm tells
// another test from round-off in the mm ↔ m conversions and the mesh's circle.
constexpr double kRadiusMatch = 1e-5;  // [m]
// Above this many bins the whole-bin search steps over bins (every ⌊B/720⌋-th shift, half a
// degree or less) and then tries the neighbours of the best: a fold spans tens of degrees.
constexpr int kExhaustiveBins = 1440;

bool Fail(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}

std::string Mm(double metres) { return NumberText(units::MToMm(metres), 4) + " mm"; }

// Mean and sample sd (0 for one value).
void MeanSd(const std::vector<double>& v, double* mean, double* sd) {
  double sum = 0.0;
  for (double x : v) sum += x;
  *mean = sum / static_cast<double>(v.size());
  double ss = 0.0;
  for (double x : v) ss += (x - *mean) * (x - *mean);
  *sd = v.size() > 1 ? std::sqrt(ss / static_cast<double>(v.size() - 1)) : 0.0;
}

// Index b of a circular signal of n values, for any integer b.
int Wrap(long b, int n) {
  const long m = b % n;
  return static_cast<int>(m < 0 ? m + n : m);
}

// Σ_b (m[b - shift] - s[b])²: the squared error of the measured outline turned by `shift` bins.
double SquaredError(const Eigen::VectorXd& s, const Eigen::VectorXd& m, long shift) {
  const int n = static_cast<int>(s.size());
  double sum = 0.0;
  for (int b = 0; b < n; ++b) {
    const double e = m(Wrap(b - shift, n)) - s(b);
    sum += e * e;
  }
  return sum;
}

// Stage 1 of AlignOutlines: the whole-bin shift of least squared error.
long BestWholeShift(const Eigen::VectorXd& s, const Eigen::VectorXd& m) {
  const int n = static_cast<int>(s.size());
  const int step = n > kExhaustiveBins ? n / 720 : 1;
  long best = 0;
  double best_error = std::numeric_limits<double>::infinity();
  auto consider = [&](long shift) {
    const double e = SquaredError(s, m, shift);
    if (e < best_error) {
      best_error = e;
      best = shift;
    }
  };
  for (long shift = 0; shift < n; shift += step) consider(shift);
  if (step > 1) {
    const long coarse = best;
    for (long shift = coarse - step + 1; shift < coarse + step; ++shift) consider(shift);
  }
  return Wrap(best, n);
}

// The measured outline turned by `shift` + t bins (0 ≤ t ≤ 1), interpolated linearly between
// the whole shifts `shift` and `shift` + 1.
Eigen::VectorXd Turned(const Eigen::VectorXd& m, long shift, double t) {
  const int n = static_cast<int>(m.size());
  Eigen::VectorXd out(n);
  for (int b = 0; b < n; ++b)
    out(b) = (1.0 - t) * m(Wrap(b - shift, n)) + t * m(Wrap(b - shift - 1, n));
  return out;
}

// The fraction t ∈ [0, 1] of a bin past `shift` that minimises the squared error: each residual
// is linear in t, d0 + t (d1 − d0), so the error is a quadratic with its minimum at
// −Σ d0 (d1 − d0) / Σ (d1 − d0)², clamped.
double BestFraction(const Eigen::VectorXd& s, const Eigen::VectorXd& m, long shift) {
  const Eigen::VectorXd d0 = Turned(m, shift, 0.0) - s, d1 = Turned(m, shift, 1.0) - s;
  const double a = (d1 - d0).squaredNorm();
  if (!(a > 0.0)) return 0.0;
  return std::clamp(-d0.dot(d1 - d0) / a, 0.0, 1.0);
}

double Rms(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return std::sqrt((a - b).squaredNorm() / static_cast<double>(a.size()));
}

// The simulation's specimen radius: its pattern's outermost vertex (on the meshed circle).
double SimulatedSpecimenRadius(const DrapeResult& r) {
  double radius = 0.0;
  for (int v = 0; v < r.mesh.num_vertices(); ++v)
    radius = std::max(radius, std::hypot(r.mesh.vertices(v, 0), r.mesh.vertices(v, 1)));
  return radius;
}

void CheckRadii(const MeasuredDrape& m, double specimen_radius, double support_radius) {
  if (std::abs(m.specimen_radius - specimen_radius) <= kRadiusMatch &&
      std::abs(m.support_radius - support_radius) <= kRadiusMatch)
    return;
  throw InputError("measured with a " + Mm(m.specimen_radius) + " specimen on a " +
                   Mm(m.support_radius) + " support; the simulation's is " + Mm(specimen_radius) +
                   " on " + Mm(support_radius) +
                   ": another test (give the simulation the same --specimen-mm and --support-mm)");
}

// The verdict's parts and their notes.
void JudgeDc(const DrapeCompareOptions& o, DrapeComparison* c) {
  c->dc_tolerance = o.dc_tolerance;
  c->dc_ok = std::abs(c->dc_difference) <= o.dc_tolerance;
  if (c->dc_ok) return;
  c->notes.push_back({"dc_differs", std::string("the simulation drapes ") +
                                        (c->dc_difference > 0.0 ? "less" : "more") +
                                        " than measured: DC " + NumberText(c->simulated_dc, 3) +
                                        " simulated against " + NumberText(c->measured_dc, 3) +
                                        " measured, " + NumberText(std::abs(c->dc_difference), 2) +
                                        " apart, beyond " + NumberText(o.dc_tolerance, 3)});
}

void JudgeNodes(const DrapeCompareOptions& o, DrapeComparison* c) {
  c->node_tolerance = o.node_tolerance;
  const double difference = c->simulated_nodes - c->measured_nodes;
  c->nodes_ok = std::abs(difference) <= o.node_tolerance;
  if (c->nodes_ok) return;
  const std::string simulated =
      NumberText(c->simulated_nodes, 3) +
      (c->per_seed.size() > 1 ? " ± " + NumberText(c->simulated_nodes_sd, 2) : std::string());
  c->notes.push_back({"nodes_differ", std::string("the simulation forms ") +
                                          (difference > 0.0 ? "more" : "fewer") +
                                          " folds than measured: " + simulated + " nodes against " +
                                          std::to_string(c->measured_nodes) + ", beyond ± " +
                                          NumberText(o.node_tolerance, 3)});
}

void JudgeOutline(const DrapeCompareOptions& o, DrapeComparison* c) {
  c->outline_tolerance = o.outline_tolerance;
  c->outline_judged = o.outline_tolerance > 0.0;
  c->outline_ok = !c->outline_judged || c->outline_rms <= o.outline_tolerance;
  if (c->outline_ok) return;
  c->notes.push_back(
      {"outline_differs", "the outlines differ by " + Mm(c->outline_rms) +
                              " RMS after the best rotation" +
                              (c->per_seed.size() > 1 ? " (mean over the seeds)" : "") +
                              ", beyond " + Mm(o.outline_tolerance)});
}

// What to know about the verdict beyond its parts.
void TrustNotes(const DrapeResult& r, const DrapeCompareOptions& o, DrapeComparison* c) {
  if (c->per_seed.size() > 1 && c->simulated_dc_sd > 0.5 * o.dc_tolerance)
    c->notes.push_back(
        {"seed_spread", "the seeds' DCs scatter by sd " + NumberText(c->simulated_dc_sd, 2) +
                            ", over half the tolerance " + NumberText(o.dc_tolerance, 3) +
                            ": the verdict may change with the seeds"});
  if (c->per_seed.size() == 1)
    c->notes.push_back({"single_seed",
                        "one seed: the simulated DC and node count show no spread over "
                        "handlings (--seeds 3 or more shows it)"});
  if (HasNote(r.notes, "rim_shortfall"))
    c->notes.push_back({"simulated_dc_low",
                        "the simulated DC may be low (the drape's rim_shortfall note): a DC that "
                        "disagrees may be the mesh's, not the fabric's"});
}

}  // namespace

bool DrapeCompareOptions::Check(std::string* why) const {
  if (!(std::isfinite(dc_tolerance) && dc_tolerance > 0.0 && dc_tolerance <= 1.0))
    return Fail(why, "dc_tolerance: must be in (0, 1]");
  if (!(std::isfinite(node_tolerance) && node_tolerance >= 0.0 && node_tolerance <= 100.0))
    return Fail(why, "node_tolerance: must be in [0, 100]");
  if (!(std::isfinite(outline_tolerance) && outline_tolerance >= 0.0 && outline_tolerance <= 1.0))
    return Fail(why, "outline_tolerance: must be in [0, 1] m (0: not judged)");
  return true;
}

std::string DrapeComparison::FailureReason() const {
  std::string reason;
  for (const Note& n : notes)
    if (n.code == "dc_differs" || n.code == "nodes_differ" || n.code == "outline_differs")
      reason += (reason.empty() ? "" : "; ") + n.text;
  return reason;
}

Eigen::VectorXd ResampleOutline(const Eigen::VectorXd& radii, int bins) {
  const int n = static_cast<int>(radii.size());
  if (n < 1 || bins < 1) throw InputError("ResampleOutline: need at least one bin each way");
  if (n == bins) return radii;
  Eigen::VectorXd out(bins);
  for (int b = 0; b < bins; ++b) {
    // Bin b's centre in the input's bin units, from its bin 0's centre.
    const double u = (b + 0.5) * n / static_cast<double>(bins) - 0.5;
    const double lower = std::floor(u), t = u - lower;
    const long i = static_cast<long>(lower);
    out(b) = (1.0 - t) * radii(Wrap(i, n)) + t * radii(Wrap(i + 1, n));
  }
  return out;
}

OutlineAlignment AlignOutlines(const Eigen::VectorXd& simulated, const Eigen::VectorXd& measured) {
  if (simulated.size() < 8 || measured.size() < 8)
    throw InputError("outline comparison: need at least 8 angle bins in each outline (have " +
                     std::to_string(simulated.size()) + " and " + std::to_string(measured.size()) +
                     ")");
  const int n = static_cast<int>(simulated.size());
  const Eigen::VectorXd m = ResampleOutline(measured, n);
  // Stage 2: the best fraction of a bin on either side of the best whole shift.
  const long whole = BestWholeShift(simulated, m);
  long shift = whole;
  double t = BestFraction(simulated, m, whole);
  const double t_before = BestFraction(simulated, m, whole - 1);
  if ((Turned(m, whole - 1, t_before) - simulated).squaredNorm() <
      (Turned(m, whole, t) - simulated).squaredNorm()) {
    shift = whole - 1;
    t = t_before;
  }
  OutlineAlignment a;
  a.aligned = Turned(m, shift, t);
  a.rms = Rms(a.aligned, simulated);
  a.rms_unrotated = Rms(m, simulated);
  a.rotation = std::remainder((static_cast<double>(shift) + t) * 2.0 * kPi / n, 2.0 * kPi);
  if (a.rotation <= -kPi) a.rotation += 2.0 * kPi;
  return a;
}

void CheckDrapesComparable(const MeasuredDrape& measured, const DrapeOptions& options) {
  CheckRadii(measured, options.specimen_radius, options.support_radius);
}

DrapeComparison CompareDrapes(const DrapeResult& r, const MeasuredDrape& measured,
                              const DrapeCompareOptions& o) {
  if (std::string why; !o.Check(&why)) throw InputError("drape comparison: " + why);
  if (!r.converged || r.per_seed.empty())
    throw ComputeError("drape comparison: the simulated drape did not converge (" + r.message +
                     "): nothing to compare");
  const double specimen_radius = SimulatedSpecimenRadius(r);
  const double support_radius = std::sqrt(r.support_area / kPi);
  CheckRadii(measured, specimen_radius, support_radius);

  DrapeComparison c;
  c.measured_source = measured.source;
  c.measured_dc = measured.drape_coefficient;
  c.simulated_dc = r.drape_coefficient;
  c.simulated_dc_sd = r.drape_coefficient_sd;
  // DC × (A_mesh − A_s) / (π R² − A_s): the shadows' DC with the cut specimen's area.
  c.simulated_dc_pi_r2 = r.drape_coefficient * (r.specimen_area - r.support_area) /
                         (kPi * specimen_radius * specimen_radius - r.support_area);
  c.dc_difference = c.simulated_dc - c.measured_dc;
  c.measured_nodes = static_cast<int>(measured.nodes.angles.size());
  c.simulated_nodes = r.nodes;
  c.simulated_nodes_sd = r.nodes_sd;

  std::vector<double> rms, unrotated;
  for (const DrapeSeedResult& s : r.per_seed) {
    DrapeSeedComparison sc;
    sc.seed = s.seed;
    sc.drape_coefficient = s.drape_coefficient;
    sc.nodes = static_cast<int>(s.nodes.angles.size());
    sc.outline = AlignOutlines(s.shadow.radii, measured.shadow.radii);
    rms.push_back(sc.outline.rms);
    unrotated.push_back(sc.outline.rms_unrotated);
    c.per_seed.push_back(std::move(sc));
  }
  double unrotated_sd = 0.0;
  MeanSd(rms, &c.outline_rms, &c.outline_rms_sd);
  MeanSd(unrotated, &c.outline_rms_unrotated, &unrotated_sd);
  c.best_rotation = c.per_seed.front().outline.rotation;

  JudgeDc(o, &c);
  JudgeNodes(o, &c);
  JudgeOutline(o, &c);
  c.pass = c.dc_ok && c.nodes_ok && c.outline_ok;
  TrustNotes(r, o, &c);
  return c;
}

nlohmann::json DrapeComparisonJson(const DrapeComparison& c) {
  nlohmann::json seeds = nlohmann::json::array();
  for (const DrapeSeedComparison& s : c.per_seed)
    seeds.push_back({{"seed", s.seed},
                     {"drape_coefficient", s.drape_coefficient},
                     {"nodes", s.nodes},
                     {"outline_rms_mm", units::MToMm(s.outline.rms)},
                     {"outline_rms_unrotated_mm", units::MToMm(s.outline.rms_unrotated)},
                     {"best_rotation_deg", s.outline.rotation / kDegree}});
  return {{"measured_source", c.measured_source},
          {"measured_dc", c.measured_dc},
          {"simulated_dc", c.simulated_dc},
          {"simulated_dc_sd", c.simulated_dc_sd},
          {"simulated_dc_pi_r2", c.simulated_dc_pi_r2},
          {"dc_difference", c.dc_difference},
          {"dc_tol", c.dc_tolerance},
          {"dc_ok", c.dc_ok},
          {"measured_nodes", c.measured_nodes},
          {"simulated_nodes", c.simulated_nodes},
          {"simulated_nodes_sd", c.simulated_nodes_sd},
          {"node_tol", c.node_tolerance},
          {"nodes_ok", c.nodes_ok},
          {"outline_rms_mm", units::MToMm(c.outline_rms)},
          {"outline_rms_sd_mm", units::MToMm(c.outline_rms_sd)},
          {"outline_rms_unrotated_mm", units::MToMm(c.outline_rms_unrotated)},
          {"best_rotation_deg", c.best_rotation / kDegree},
          {"outline_tol_mm",
           c.outline_judged ? nlohmann::json(units::MToMm(c.outline_tolerance)) : nlohmann::json()},
          {"outline_ok", c.outline_judged ? nlohmann::json(c.outline_ok) : nlohmann::json()},
          {"seeds", seeds},
          {"verdict", c.Verdict()},
          {"notes", NotesJson(c.notes)}};
}

}  // namespace textile
