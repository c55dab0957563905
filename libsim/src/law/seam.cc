#include "textile/sim/law/seam.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "textile/sim/core/error.h"
#include "textile/sim/io/json_fields.h"
#include "textile/sim/io/json_text.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

using nlohmann::json;

// Plausibility bounds. Outside them a value is far more likely a unit mix-up (metres for mm,
// coefficients fitted against d in m) than a seam. Table 2's stiffest seam reaches 9.07.
constexpr int kMaxLayers = 20;
constexpr double kMaxFactor = kMaxSeamFactor;  // largest plausible B_f [-] (seam.h)
constexpr double kMaxRangeMm = 1000.0;         // fit range, influence range, fade [mm]
constexpr double kMinInfluenceMm = 1.0;        // below this d_max is surely in metres [mm]
constexpr double kMaxAllowanceMm = 200.0;      // seam allowance [mm]
constexpr double kMaxRibFactor = 1000.0;       // lengthwise factor on S [-]
// Coefficients of a file that names a preset must be Table 2's up to JSON round-off.
constexpr double kPresetTolerance = 1e-12;

struct PresetRow {
  const char* type;
  const char* name;
  int layers;
  std::array<double, 3> coefficients_mm;  // a2, a1, a0
};

// Pabst et al. 2008, Table 2 (layers from Table 1).
constexpr PresetRow kTable2[] = {
    {"A-plain", "ISO 1.01.01 joining seam, plain weave", 2, {5.0e-5, -0.0211, 3.46}},
    {"A-twill", "ISO 1.01.01 joining seam, twill weave", 2, {2.0e-5, -0.0127, 2.64}},
    {"B-plain", "ISO 2.02.04 safety seam, plain weave", 3, {4.0e-5, -0.0322, 5.92}},
    {"B-twill", "ISO 2.02.04 safety seam, twill weave", 3, {4.0e-5, -0.0287, 4.37}},
    {"C-plain", "ISO 2.04.05 double lap seam, plain weave", 4, {2.0e-4, -0.0702, 9.07}},
    {"C-twill", "ISO 2.04.05 double lap seam, twill weave", 4, {1.0e-4, -0.0524, 6.86}},
};

const PresetRow* FindPreset(const std::string& type) {
  for (const PresetRow& row : kTable2) {
    if (type == row.type) return &row;
  }
  return nullptr;
}

std::string KnownTypes() {
  std::string list;
  for (const PresetRow& row : kTable2) list += std::string(row.type) + ", ";
  return list + "fitted";
}

// min and max of B_f(d) = a2 d² + a1 d + a0 over [lo, hi], with where they occur.
struct Extremes {
  double min_value, min_at, max_value, max_at;
};
Extremes QuadraticExtremes(const std::array<double, 3>& a, double lo, double hi) {
  const auto f = [&](double d) { return (a[0] * d + a[1]) * d + a[2]; };
  Extremes e{f(lo), lo, f(lo), lo};
  std::vector<double> candidates{hi};
  if (a[0] != 0.0) {
    const double vertex = -a[1] / (2.0 * a[0]);
    if (vertex > lo && vertex < hi) candidates.push_back(vertex);
  }
  for (double d : candidates) {
    const double v = f(d);
    if (v < e.min_value) e.min_value = v, e.min_at = d;
    if (v > e.max_value) e.max_value = v, e.max_at = d;
  }
  return e;
}

// c(d) and dc/dd under either reading: B_f itself, or eq. 6 as printed.
double ReadingValue(const SeamProfile& p, SeamMultiplierReading reading, double d_mm) {
  const double b = p.StiffnessFactor(d_mm);
  return reading == SeamMultiplierReading::kPaperLiteral ? 1.0 + b * (p.coefficients_mm[2] - 1.0)
                                                         : b;
}
double ReadingSlope(const SeamProfile& p, SeamMultiplierReading reading, double d_mm) {
  const double db = 2.0 * p.coefficients_mm[0] * d_mm + p.coefficients_mm[1];
  return reading == SeamMultiplierReading::kPaperLiteral ? db * (p.coefficients_mm[2] - 1.0) : db;
}

// The excess S - 1 across the fade, t in [0, 1]: value e0 ≥ 0 and slope g (per unit t) at
// t = 0, value and slope 0 at t = 1, never negative. The cubic Hermite does this unless the
// descent is steep (3 e0 + g < 0, where it would dip below 0); then (1-t)² e^{kt} with the same
// end conditions decays monotonically instead.
double FadedExcess(double e0, double g, double t) {
  const double u = 1.0 - t;
  if (3.0 * e0 + g >= 0.0) return u * u * (e0 + (2.0 * e0 + g) * t);
  return e0 * u * u * std::exp((g / e0 + 2.0) * t);  // 3 e0 + g < 0 implies e0 > 0
}

// The multiplier under either reading (AreaFactor always uses kFactor).
double MultiplierWith(const SeamProfile& p, SeamMultiplierReading reading, double d_mm) {
  assert(d_mm >= 0.0);
  const double d_max = p.influence_mm;
  if (d_mm <= d_max) return std::max(1.0, ReadingValue(p, reading, d_mm));
  const double t = (d_mm - d_max) / p.fade_mm;
  if (t >= 1.0) return 1.0;
  // Only value and slope at d_max enter: the fit is not extrapolated beyond the influence range.
  const double e0 = ReadingValue(p, reading, d_max) - 1.0;
  if (e0 <= 0.0) return 1.0;  // S has been 1 since B_f fell below 1
  return 1.0 + FadedExcess(e0, p.fade_mm * ReadingSlope(p, reading, d_max), t);
}

}  // namespace

double SeamProfile::StiffnessFactor(double d_mm) const {
  const auto& a = coefficients_mm;
  return (a[0] * d_mm + a[1]) * d_mm + a[2];
}

double SeamProfile::Multiplier(double d_mm) const {
  return MultiplierWith(*this, multiplier, d_mm);
}

double SeamProfile::AreaFactor(double d_mm) const {
  return std::ceil(MultiplierWith(*this, SeamMultiplierReading::kFactor, d_mm));
}

bool SeamProfile::Check(std::string* why) const {
  const auto fail = [&](const std::string& field, const std::string& problem) {
    if (why) *why = field + ": " + problem;
    return false;
  };
  const PresetRow* preset = FindPreset(type);
  if (!preset && type != "fitted") {
    return fail("type", "unknown seam type '" + type + "' (known: " + KnownTypes() + ")");
  }
  if (layers < 1) return fail("layers", "must be >= 1, got " + std::to_string(layers));
  if (layers > kMaxLayers) {
    return fail("layers", "suspicious count " + std::to_string(layers) + ", above " +
                              std::to_string(kMaxLayers));
  }
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(coefficients_mm[i])) {
      return fail("coefficients_mm", "a" + std::to_string(2 - i) + " must be finite, got " +
                                         NumberText(coefficients_mm[i]));
    }
  }
  if (!std::isfinite(range_mm[0]) || !std::isfinite(range_mm[1])) {
    return fail("range_mm", "must be finite, got [" + NumberText(range_mm[0]) + ", " +
                                NumberText(range_mm[1]) + "]");
  }
  if (range_mm[0] < 0.0)
    return fail("range_mm", "lo must be >= 0 mm, got " + NumberText(range_mm[0]));
  if (range_mm[0] >= range_mm[1]) {
    return fail("range_mm", "lo " + NumberText(range_mm[0]) + " mm must be < hi " +
                                NumberText(range_mm[1]) + " mm");
  }
  if (range_mm[1] > kMaxRangeMm) {
    return fail("range_mm", "suspicious hi " + NumberText(range_mm[1]) + " mm, above " +
                                NumberText(kMaxRangeMm) + " mm (the unit is mm)");
  }
  if (!(influence_mm >= kMinInfluenceMm && influence_mm <= kMaxRangeMm)) {
    return fail("influence_mm", "must lie in [" + NumberText(kMinInfluenceMm) + ", " +
                                    NumberText(kMaxRangeMm) + "] mm, got " +
                                    NumberText(influence_mm) + " (the unit is mm)");
  }
  if (!(fade_mm > 0.0 && fade_mm <= kMaxRangeMm)) {
    return fail("fade_mm",
                "must lie in (0, " + NumberText(kMaxRangeMm) + "] mm, got " + NumberText(fade_mm));
  }
  if (!(allowance_mm >= 0.0 && allowance_mm <= kMaxAllowanceMm)) {
    return fail("allowance_mm", "must lie in [0, " + NumberText(kMaxAllowanceMm) + "] mm, got " +
                                    NumberText(allowance_mm));
  }
  if (!(rib_factor >= 1.0 && rib_factor <= kMaxRibFactor)) {
    return fail("rib_factor", "must lie in [1, " + NumberText(kMaxRibFactor) + "], got " +
                                  NumberText(rib_factor));
  }
  if (covariance) {
    const Eigen::Matrix3d& c = *covariance;
    if (!c.allFinite()) return fail("covariance", "must be finite");
    const double scale = c.cwiseAbs().maxCoeff();
    if ((c - c.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) {
      return fail("covariance", "must be symmetric");
    }
    if ((c.diagonal().array() < 0.0).any()) return fail("covariance", "diagonal must be >= 0");
    // A covariance is positive semi-definite; round-off in a written file may leave an
    // eigenvalue a hair below 0 (1e-9 of the largest entry is far above that, far below a fit).
    const double lowest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(c, Eigen::EigenvaluesOnly)
                              .eigenvalues()
                              .minCoeff();
    if (lowest < -1e-9 * scale) {
      return fail("covariance", "must be positive semi-definite, has the eigenvalue " +
                                    NumberText(lowest) + " < 0");
    }
  }
  // The stiffness factor must be positive wherever S follows it (a non-positive factor is a
  // broken fit, not a softening seam).
  const Extremes inside = QuadraticExtremes(coefficients_mm, 0.0, influence_mm);
  if (!(inside.min_value > 0.0)) {
    return fail("coefficients_mm", "B_f(d) = " + NumberText(inside.min_value) +
                                       " <= 0 at d = " + NumberText(inside.min_at) +
                                       " mm; the stiffness factor must be "
                                       "positive on [0, influence_mm] = [0, " +
                                       NumberText(influence_mm) + "] mm");
  }
  if (inside.max_value > kMaxFactor) {
    return fail("coefficients_mm", "suspicious B_f(d) = " + NumberText(inside.max_value) +
                                       " at d = " + NumberText(inside.max_at) + " mm, above " +
                                       NumberText(kMaxFactor) +
                                       " (coefficients are per mm: was d in m or cm?)");
  }
  // The multiplier actually used must be plausible too: under paper-literal it is
  // 1 + B_f(d) (B_f(0) - 1), largest where B_f is (for B_f(0) > 1; else it is <= 1).
  if (multiplier == SeamMultiplierReading::kPaperLiteral) {
    const double b0 = StiffnessFactor(0.0);
    const double largest = 1.0 + inside.max_value * (b0 - 1.0);
    if (b0 > 1.0 && largest > kMaxFactor) {
      return fail("multiplier", "paper-literal: S(d) = 1 + B_f(d) (B_f(0) - 1) reaches " +
                                    NumberText(largest) + " at d = " + NumberText(inside.max_at) +
                                    " mm, above " + NumberText(kMaxFactor) +
                                    " (use \"factor\", or check the coefficients)");
    }
  }
  if (preset) {
    if (layers != preset->layers) {
      return fail("layers", type + " has " + std::to_string(preset->layers) + " layers, got " +
                                std::to_string(layers) + " (use type \"fitted\" for other seams)");
    }
    for (int i = 0; i < 3; ++i) {
      const double want = preset->coefficients_mm[i];
      if (std::abs(coefficients_mm[i] - want) > kPresetTolerance * std::abs(want)) {
        return fail("coefficients_mm", "differ from Table 2's " + type +
                                           " (use type \"fitted\" for your own coefficients)");
      }
    }
  }
  return true;
}

SeamProfile SeamPreset(const std::string& type) {
  const PresetRow* row = FindPreset(type);
  if (!row)
    throw InputError("seam type '" + type + "': unknown (known presets: " + KnownTypes() + ")");
  SeamProfile p;
  p.type = row->type;
  p.name = row->name;
  p.layers = row->layers;
  p.coefficients_mm = row->coefficients_mm;
  p.range_mm = {0.0, 100.0};
  p.extra["source"] = "Pabst et al. 2008, Seams and Bending in Cloth Simulation, Tables 1 and 2";
  return p;
}

std::vector<std::string> SeamPresetNames() {
  std::vector<std::string> names;
  for (const PresetRow& row : kTable2) names.push_back(row.type);
  return names;
}

// ---------------------------------------------------------------------------------------------
// Seam JSON

namespace {

// "layers": a whole number in the range of int.
int ReadLayers(const JsonFields& f, const json& layers) {
  if (!layers.is_number_integer()) f.Must("layers", "be a whole number", layers);
  // Above 2^63 - 1 nlohmann holds the number unsigned: read as int64 it would wrap.
  if (layers.is_number_unsigned() &&
      layers.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<int>::max())) {
    f.Fail("layers", "suspicious count " + JsonFields::Brief(layers));
  }
  const std::int64_t n = layers.get<std::int64_t>();
  if (n < std::numeric_limits<int>::min() || n > std::numeric_limits<int>::max()) {
    f.Fail("layers", "suspicious count " + JsonFields::Brief(layers));
  }
  return static_cast<int>(n);
}

// "multiplier": "factor" or "paper-literal".
SeamMultiplierReading ReadMultiplier(const JsonFields& f, const json& v) {
  const std::string m = f.String(v, "multiplier");
  if (m == "factor") return SeamMultiplierReading::kFactor;
  if (m != "paper-literal")
    f.Unknown("multiplier", "reading", m, "\"factor\" or \"paper-literal\"");
  return SeamMultiplierReading::kPaperLiteral;
}

}  // namespace

SeamProfile ParseSeamJson(const std::string& text, const std::string& source) {
  const JsonFields f(source);
  const json root = ParseJsonText(text, source);
  f.RequireObject(root);
  f.CheckKeys(root, "",
              {"type", "name", "layers", "coefficients_mm", "range_mm", "covariance",
               "influence_mm", "fade_mm", "allowance_mm", "multiplier", "rib_factor", "fit",
               "notes", "source", "assumptions"});
  for (const char* k : {"type", "layers", "coefficients_mm"})
    f.Require(root, k, "required: type, layers, coefficients_mm");
  SeamProfile p;
  p.type = f.String(root["type"], "type");
  p.layers = ReadLayers(f, root["layers"]);
  p.coefficients_mm = f.FixedNumbers<3>(root["coefficients_mm"], "coefficients_mm", "[a2, a1, a0]");
  if (root.contains("range_mm"))
    p.range_mm = f.FixedNumbers<2>(root["range_mm"], "range_mm", "[lo, hi]");
  if (root.contains("covariance")) {
    const std::array<double, 9> c = f.Matrix3(root["covariance"], "covariance");
    p.covariance = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>(c.data());
  }
  if (root.contains("name")) p.name = f.String(root["name"], "name");
  if (root.contains("influence_mm"))
    p.influence_mm = f.Number(root["influence_mm"], "influence_mm");
  if (root.contains("fade_mm")) p.fade_mm = f.Number(root["fade_mm"], "fade_mm");
  if (root.contains("allowance_mm"))
    p.allowance_mm = f.Number(root["allowance_mm"], "allowance_mm");
  if (root.contains("rib_factor")) p.rib_factor = f.Number(root["rib_factor"], "rib_factor");
  if (root.contains("multiplier")) p.multiplier = ReadMultiplier(f, root["multiplier"]);
  if (root.contains("fit")) p.fit = f.Object(root["fit"], "fit");
  for (const char* k : {"notes", "source", "assumptions"}) {
    if (root.contains(k)) p.extra[k] = root[k];
  }
  if (std::string why; !p.Check(&why)) throw InputError(source + ": " + why);
  return p;
}

SeamProfile ReadSeamProfile(const std::string& path) {
  std::stringstream buffer(ReadInputFile(path, "seam file", 16u << 20));  // kilobytes in use
  if (buffer.str().find_first_not_of(" \t\r\n") == std::string::npos) {
    throw InputError(path + ": empty seam file");
  }
  return ParseSeamJson(buffer.str(), path);
}

nlohmann::json SeamProfileToJson(const SeamProfile& p) {
  json j;
  j["type"] = p.type;
  if (!p.name.empty()) j["name"] = p.name;
  j["layers"] = p.layers;
  j["coefficients_mm"] = p.coefficients_mm;
  j["range_mm"] = p.range_mm;
  if (p.covariance) {
    json c = json::array();
    for (int i = 0; i < 3; ++i)
      c.push_back({(*p.covariance)(i, 0), (*p.covariance)(i, 1), (*p.covariance)(i, 2)});
    j["covariance"] = c;
  }
  j["influence_mm"] = p.influence_mm;
  j["fade_mm"] = p.fade_mm;
  j["allowance_mm"] = p.allowance_mm;
  j["multiplier"] = p.multiplier == SeamMultiplierReading::kFactor ? "factor" : "paper-literal";
  j["rib_factor"] = p.rib_factor;
  if (!p.fit.is_null()) j["fit"] = p.fit;
  for (const auto& [k, v] : p.extra.items()) j[k] = v;
  return j;
}

// ---------------------------------------------------------------------------------------------
// Geometry

namespace {

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

Eigen::Vector2d Xy(const TriangleMesh& mesh, int v) {
  return mesh.vertices.row(v).head<2>().transpose();
}

// True if p lies in (or within tol [m] of) some triangle of the mesh.
bool InsideMesh(const TriangleMesh& mesh, const Eigen::Vector2d& p, double tol) {
  for (int f = 0; f < mesh.num_triangles(); ++f) {
    const Eigen::Vector2d a = Xy(mesh, mesh.triangles(f, 0)), b = Xy(mesh, mesh.triangles(f, 1)),
                          c = Xy(mesh, mesh.triangles(f, 2));
    const double orientation = Cross(b - a, c - a) >= 0.0 ? 1.0 : -1.0;
    bool inside = true;
    for (const auto& [u, v] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      // Signed distance of p from edge uv, positive inside.
      if (orientation * Cross(v - u, p - u) < -tol * (v - u).norm()) {
        inside = false;
        break;
      }
    }
    if (inside) return true;
  }
  return false;
}

std::string Point(const Eigen::Vector2d& p) {
  std::ostringstream s;
  s << "(" << p.x() << ", " << p.y() << ") m";
  return s.str();
}

}  // namespace

namespace {

// The polyline's point nearest to p: its distance [m] and the segment it lies on (0 for a
// one-point line, the first of equally near segments).
struct NearestOnLine {
  double distance = 0.0;
  Eigen::Index segment = 0;
};

NearestOnLine Nearest(const Eigen::Vector2d& p, const SeamLine& line) {
  assert(line.rows() >= 1);
  NearestOnLine best{(p - line.row(0).transpose()).norm(), 0};
  for (Eigen::Index k = 0; k + 1 < line.rows(); ++k) {
    const Eigen::Vector2d a = line.row(k).transpose(), b = line.row(k + 1).transpose();
    const Eigen::Vector2d ab = b - a;
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    const double d = (p - (a + t * ab)).norm();
    if (d < best.distance) best = {d, k};
  }
  return best;
}

// Unit direction of the segment of `line` (≥ 2 points, CheckSeams passed) nearest to p.
Eigen::Vector2d NearestSegmentDirection(const Eigen::Vector2d& p, const SeamLine& line) {
  const Eigen::Index k = Nearest(p, line).segment;
  return (line.row(k + 1) - line.row(k)).transpose().normalized();
}

}  // namespace

double DistanceToSeamLine(const Eigen::Vector2d& p, const SeamLine& line) {
  return Nearest(p, line).distance;
}

void CheckSeams(const std::vector<Seam>& seams, const TriangleMesh& mesh) {
  if (seams.empty()) return;
  assert(mesh.num_triangles() > 0);
  const Eigen::Vector2d lo = mesh.vertices.leftCols<2>().colwise().minCoeff().transpose();
  const Eigen::Vector2d hi = mesh.vertices.leftCols<2>().colwise().maxCoeff().transpose();
  const double tol = 1e-9 * (hi - lo).norm();  // geometric tolerance [m]
  const std::string box = "[" + NumberText(lo.x()) + ", " + NumberText(hi.x()) + "] × [" +
                          NumberText(lo.y()) + ", " + NumberText(hi.y()) + "] m";
  const std::vector<std::array<int, 2>> boundary = BoundaryEdges(mesh);
  for (std::size_t i = 0; i < seams.size(); ++i) {
    const Seam& seam = seams[i];
    const std::string where = "seam " + std::to_string(i) + " (" + seam.profile.type + ")";
    const auto fail = [&](const std::string& problem) { throw InputError(where + ": " + problem); };
    if (std::string why; !seam.profile.Check(&why)) fail(why);
    const SeamLine& line = seam.line;
    if (line.rows() < 2) fail("line: needs at least 2 points, got " + std::to_string(line.rows()));
    for (Eigen::Index k = 0; k < line.rows(); ++k) {
      if (!line.row(k).allFinite())
        fail("line: point " + std::to_string(k) + " has a NaN or infinite coordinate");
    }
    for (Eigen::Index k = 0; k + 1 < line.rows(); ++k) {
      if ((line.row(k + 1) - line.row(k)).norm() <= tol) {
        fail("line: segment " + std::to_string(k) + " (points " + std::to_string(k) + ", " +
             std::to_string(k + 1) + ") has zero length");
      }
    }
    for (Eigen::Index k = 0; k < line.rows(); ++k) {
      const Eigen::Vector2d p = line.row(k).transpose();
      if (!InsideMesh(mesh, p, tol)) {
        fail("line: point " + std::to_string(k) + " " + Point(p) +
             " lies outside the pattern (bounding box " + box + ")");
      }
    }
    // Between two consecutive places where a segment meets the boundary it is wholly inside or
    // wholly outside the pattern, so one midpoint per piece decides it.
    for (Eigen::Index k = 0; k + 1 < line.rows(); ++k) {
      const Eigen::Vector2d p = line.row(k).transpose(), q = line.row(k + 1).transpose();
      const Eigen::Vector2d pq = q - p;
      const double len = pq.norm();
      std::vector<double> cuts{0.0, 1.0};
      for (const auto& e : boundary) {
        const Eigen::Vector2d a = Xy(mesh, e[0]), b = Xy(mesh, e[1]);
        for (const Eigen::Vector2d& v : {a, b}) {  // boundary vertices on the segment
          const double t = (v - p).dot(pq) / (len * len);
          if (t > 0.0 && t < 1.0 && std::abs(Cross(pq, v - p)) / len <= tol) cuts.push_back(t);
        }
        const double sa = Cross(pq, a - p) / len, sb = Cross(pq, b - p) / len;
        const double sp = Cross(b - a, p - a) / (b - a).norm(),
                     sq = Cross(b - a, q - a) / (b - a).norm();
        if (((sa > tol && sb < -tol) || (sa < -tol && sb > tol)) &&
            ((sp > tol && sq < -tol) || (sp < -tol && sq > tol))) {
          cuts.push_back(sp / (sp - sq));  // proper crossing
        }
      }
      std::sort(cuts.begin(), cuts.end());
      for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
        if ((cuts[c + 1] - cuts[c]) * len <= tol) continue;
        const Eigen::Vector2d mid = p + 0.5 * (cuts[c] + cuts[c + 1]) * pq;
        if (!InsideMesh(mesh, mid, tol)) {
          fail("line: segment " + std::to_string(k) + " leaves the pattern at " + Point(mid) +
               " (bounding box " + box + ")");
        }
      }
    }
  }
}

std::vector<double> HingeSeamDistances(const TriangleMesh& mesh, const std::vector<Hinge>& hinges,
                                       const SeamLine& line) {
  std::vector<double> d(hinges.size());
  for (std::size_t h = 0; h < hinges.size(); ++h) {
    const Eigen::Vector2d mid = 0.5 * (Xy(mesh, hinges[h].v[2]) + Xy(mesh, hinges[h].v[3]));
    d[h] = DistanceToSeamLine(mid, line);
  }
  return d;
}

std::vector<double> HingeSeamMultipliers(const TriangleMesh& mesh, const std::vector<Hinge>& hinges,
                                         const std::vector<Seam>& seams) {
  CheckSeams(seams, mesh);
  std::vector<double> s(hinges.size(), 1.0);
  for (const Seam& seam : seams) {
    const std::vector<double> d = HingeSeamDistances(mesh, hinges, seam.line);
    const double half_band = 0.5 * units::MmToM(seam.profile.allowance_mm);
    const double rib = seam.profile.rib_factor;
    for (std::size_t h = 0; h < d.size(); ++h) {
      double lengthwise = 1.0;
      if (rib > 1.0 && d[h] < half_band) {
        const Eigen::Vector2d a = Xy(mesh, hinges[h].v[2]), b = Xy(mesh, hinges[h].v[3]);
        const double cos_phi =
            (b - a).normalized().dot(NearestSegmentDirection(0.5 * (a + b), seam.line));
        lengthwise = 1.0 + (rib - 1.0) * (1.0 - cos_phi * cos_phi);
      }
      s[h] = std::max(s[h], lengthwise * seam.profile.Multiplier(units::MToMm(d[h])));
    }
  }
  return s;
}

std::function<double(double)> SeamAreaFactor(const std::vector<SeamProfile>& profiles) {
  return [profiles](double d_m) {
    assert(d_m >= 0.0);
    double factor = 1.0;
    for (const SeamProfile& p : profiles)
      factor = std::max(factor, p.AreaFactor(units::MToMm(d_m)));
    return factor;
  };
}

// ---------------------------------------------------------------------------------------------
// Band integration and masses

namespace {

// ∫ 1 dA and ∫ x dA over the band part of a region [m², m³].
struct BandMoments {
  double area = 0.0;
  Eigen::Vector2d first = Eigen::Vector2d::Zero();
};

constexpr double kLeafFraction = 1.0 / 256.0;  // leaf size as a fraction of the allowance
constexpr int kMaxDepth = 30;                  // guards against runaway splitting

class BandIntegrator {
 public:
  BandIntegrator(const SeamLine& line, double half_width, double leaf_size)
      : line_(line), r_(half_width), leaf_(leaf_size) {}

  // Adds the band part of triangle (a, b, c) to *m.
  void Triangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                int depth, BandMoments* m) const {
    const Eigen::Vector2d centroid = (a + b + c) / 3.0;
    const double reach =
        std::max({(a - centroid).norm(), (b - centroid).norm(), (c - centroid).norm()});
    // The distance is 1-Lipschitz: every point of the triangle is within `reach` of the centroid.
    const double phi = DistanceToSeamLine(centroid, line_) - r_;
    if (phi >= reach) return;
    if (phi <= -reach) {
      const double area = 0.5 * std::abs(Cross(b - a, c - a));
      m->area += area;
      m->first += area * centroid;
      return;
    }
    std::array<double, 3> exact_phi{};
    if (LinearOnTriangle(a, b, c, centroid, reach, &exact_phi)) {
      Clip(a, b, c, exact_phi, m);
      return;
    }
    const double diameter = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    if (diameter <= leaf_ || depth >= kMaxDepth) {
      std::array<double, 3> phi_corners{};
      for (const auto& [i, p] : {std::pair{0, a}, std::pair{1, b}, std::pair{2, c}}) {
        phi_corners[i] = DistanceToSeamLine(p, line_) - r_;
      }
      Clip(a, b, c, phi_corners, m);  // linearised: exact only where the band edge is straight
      return;
    }
    const Eigen::Vector2d ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
    Triangle(a, ab, ca, depth + 1, m);
    Triangle(ab, b, bc, depth + 1, m);
    Triangle(ca, bc, c, depth + 1, m);
    Triangle(ab, bc, ca, depth + 1, m);
  }

 private:
  // True if the distance to the line is an affine function on the whole triangle, with its
  // corner values minus r in *phi: every corner projects inside one segment k and lies on the
  // same side of it (so the distance to segment k is affine there), and every other segment is
  // farther from every point of the triangle (1-Lipschitz bound from the centroid). Then the
  // band part of the triangle is a polygon, clipped exactly however large the triangle.
  bool LinearOnTriangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                        const Eigen::Vector2d& c, const Eigen::Vector2d& centroid, double reach,
                        std::array<double, 3>* phi) const {
    Eigen::Index nearest = 0;
    double nearest_distance = std::numeric_limits<double>::infinity();
    for (Eigen::Index k = 0; k + 1 < line_.rows(); ++k) {
      const double dk = SegmentDistance(centroid, k);
      if (dk < nearest_distance) nearest_distance = dk, nearest = k;
    }
    const Eigen::Vector2d s0 = line_.row(nearest).transpose(),
                          s1 = line_.row(nearest + 1).transpose();
    const Eigen::Vector2d dir = s1 - s0;
    const double len = dir.norm();
    bool any_left = false, any_right = false;
    double farthest = 0.0;
    const std::array<Eigen::Vector2d, 3> corners{a, b, c};
    for (int i = 0; i < 3; ++i) {
      const double t = (corners[i] - s0).dot(dir) / (len * len);
      const double offset = Cross(dir, corners[i] - s0) / len;  // signed distance to the line
      if (t < 0.0 || t > 1.0) return false;
      any_left |= offset > 0.0;
      any_right |= offset < 0.0;
      (*phi)[i] = std::abs(offset) - r_;
      farthest = std::max(farthest, std::abs(offset));
    }
    if (any_left && any_right) return false;  // |offset| is affine only on one side
    for (Eigen::Index k = 0; k + 1 < line_.rows(); ++k) {
      if (k != nearest && SegmentDistance(centroid, k) - reach < farthest) return false;
    }
    return true;
  }

  double SegmentDistance(const Eigen::Vector2d& p, Eigen::Index k) const {
    const Eigen::Vector2d a = line_.row(k).transpose(), ab = line_.row(k + 1).transpose() - a;
    const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    return (p - (a + t * ab)).norm();
  }

  // Exact moments of {φ ≤ 0} on a triangle for φ affine with corner values phi.
  void Clip(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
            const std::array<double, 3>& phi, BandMoments* m) const {
    const std::array<Eigen::Vector2d, 3> p{a, b, c};
    std::array<Eigen::Vector2d, 4> poly;  // a triangle cut by a line keeps at most 4 corners
    int n = 0;
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3;
      if (phi[i] <= 0.0) poly[n++] = p[i];
      if ((phi[i] <= 0.0) != (phi[j] <= 0.0)) {
        poly[n++] = p[i] + (phi[i] / (phi[i] - phi[j])) * (p[j] - p[i]);
      }
    }
    if (n < 3) return;
    // Shoelace: signed area and first moment; the sign follows the triangle's orientation.
    double area2 = 0.0;
    Eigen::Vector2d first6 = Eigen::Vector2d::Zero();
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d& u = poly[i];
      const Eigen::Vector2d& v = poly[(i + 1) % n];
      const double w = Cross(u, v);
      area2 += w;
      first6 += w * (u + v);
    }
    const double sign = area2 >= 0.0 ? 1.0 : -1.0;
    m->area += 0.5 * sign * area2;
    m->first += sign * first6 / 6.0;
  }

  const SeamLine& line_;
  double r_;
  double leaf_;
};

// Band moments per triangle (#F).
std::vector<BandMoments> TriangleBandMoments(const TriangleMesh& mesh, const Seam& seam) {
  std::vector<BandMoments> out(mesh.num_triangles());
  const double width = units::MmToM(seam.profile.allowance_mm);
  if (width <= 0.0) return out;
  const BandIntegrator integrator(seam.line, 0.5 * width, kLeafFraction * width);
  for (int f = 0; f < mesh.num_triangles(); ++f) {
    integrator.Triangle(Xy(mesh, mesh.triangles(f, 0)), Xy(mesh, mesh.triangles(f, 1)),
                        Xy(mesh, mesh.triangles(f, 2)), 0, &out[f]);
  }
  return out;
}

}  // namespace

Eigen::VectorXd SeamBandAreas(const TriangleMesh& mesh, const Seam& seam) {
  CheckSeams({seam}, mesh);
  const std::vector<BandMoments> moments = TriangleBandMoments(mesh, seam);
  Eigen::VectorXd areas(mesh.num_triangles());
  for (int f = 0; f < mesh.num_triangles(); ++f) areas(f) = moments[f].area;
  return areas;
}

Eigen::VectorXd LumpedMasses(const TriangleMesh& mesh, double areal_density,
                             const std::vector<Seam>& seams) {
  if (!(areal_density > 0.0) || !std::isfinite(areal_density)) {
    throw InputError("lumped masses: areal density must be a finite number > 0 kg/m², got " +
                     NumberText(areal_density));
  }
  CheckSeams(seams, mesh);
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(mesh.num_vertices());
  const Eigen::VectorXd areas = TriangleAreas(mesh);
  for (int f = 0; f < mesh.num_triangles(); ++f) {
    for (int k = 0; k < 3; ++k) mass(mesh.triangles(f, k)) += areal_density * areas(f) / 3.0;
  }
  for (const Seam& seam : seams) {
    const double extra_density = (seam.profile.layers - 1) * areal_density;  // [kg/m²]
    if (extra_density == 0.0) continue;
    const std::vector<BandMoments> moments = TriangleBandMoments(mesh, seam);
    for (int f = 0; f < mesh.num_triangles(); ++f) {
      const BandMoments& m = moments[f];
      if (m.area <= 0.0) continue;
      // ∫ λ_i dA over the band part = area × λ_i(band centroid), since λ_i is linear.
      const Eigen::Vector2d a = Xy(mesh, mesh.triangles(f, 0)), b = Xy(mesh, mesh.triangles(f, 1)),
                            c = Xy(mesh, mesh.triangles(f, 2));
      const Eigen::Vector2d centroid = m.first / m.area;
      const double total = Cross(b - a, c - a);
      const std::array<double, 3> lambda{Cross(c - b, centroid - b) / total,
                                         Cross(a - c, centroid - c) / total,
                                         Cross(b - a, centroid - a) / total};
      for (int k = 0; k < 3; ++k) mass(mesh.triangles(f, k)) += extra_density * m.area * lambda[k];
    }
  }
  return mass;
}

}  // namespace textile
