// Material exports: ARCSim, U3M 1.1, CSV (material_export.h; docs/guide/export.md).

#include "textile/sim/exchange/material_export.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <numbers>
#include <sstream>

#include <Eigen/Dense>

#include "textile/sim/core/content_hash.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/join_text.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/core/units.h"
#include "textile/sim/elastica/cantilever_outputs.h"
#include "textile/sim/law/membrane_law.h"

namespace textile {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- Shared: the three directions ----------------------------------------------------------

struct Direction {
  const char* name;   // "warp", "weft", "bias"
  double angle_deg;   // of the strip's length to the warp
  BendingLaw law;     // β applied
  const char* kind;   // "pabst", "spline", "blend"
};

const char* LawKind(const BendingLaw& law) { return law.is_spline() ? "spline" : "pabst"; }

std::vector<Direction> Directions(const Material& m) {
  const BendingLaw warp = m.EffectiveLaw(), weft = m.EffectiveWeftLaw();
  std::vector<Direction> d = {{"warp", 0.0, warp, LawKind(warp)},
                              {"weft", 90.0, weft, LawKind(weft)}};
  if (const std::optional<BendingLaw> measured = m.EffectiveBiasLaw()) {
    d.push_back({"bias", 45.0, *measured, LawKind(*measured)});
    return d;
  }
  const BendingLaw bias = BiasLaw(m);
  d.push_back({"bias", 45.0, bias, m.bending_weft ? "blend" : LawKind(warp)});
  return d;
}

// ---- ARCSim -------------------------------------------------------------------------------

// Row i of ARCSim's bending table serves hinges whose edge runs at 45 i degrees to the material
// u axis (dde.cpp: the angle of the edge's du). An edge along u (the warp) is bent by a
// curvature along the weft: row 0 is the weft law, row 2 the warp law.
nlohmann::json ArcsimBendingTable(const Material& m) {
  // The 45° row is the measured bias law where the material has one (the blend's weights).
  const BlendedLaw by_edge[3] = {m.EffectiveLawAt(0.5 * std::numbers::pi),  // curvature ∥ weft
                                 m.EffectiveLawAt(0.25 * std::numbers::pi),
                                 m.EffectiveLawAt(0.0)};  // curvature ∥ warp
  nlohmann::json table = nlohmann::json::array();
  for (const BlendedLaw& law : by_edge) {
    nlohmann::json row = nlohmann::json::array();
    for (double alpha : kArcsimBendingAlpha)
      row.push_back(kArcsimStiffnessPerSecant *
                    SecantStiffness(law, kArcsimCurvaturePerAlpha * alpha));
    table.push_back(row);
  }
  return table;
}

nlohmann::json PcbJson(const QuadraticBending& q) { return nlohmann::json::array({q.k1, q.k2}); }

// ARCSim's "stretching": 6 rows [k0, k1, k2, k3], the first at small strain and five at a
// principal strain of 1/6 along 0-90°, each doubled on load (conf.cpp); its energy per area is
// ½ (k0 G00² + 2 k1 G00 G11 + k2 G11² + k3 G01²) in the Green strain G, u the warp. A linear
// membrane writes the same row six times: the orthotropic {E_warp, 0, E_weft, 4 G} and the
// isotropic StVK {λ + 2μ, λ, λ + 2μ, 4μ}, halved.
nlohmann::json ArcsimStretching(const Material& m) {
  std::array<double, 4> k{};
  if (m.orthotropic) {
    k = {m.orthotropic->warp.SmallStrainModulus(), 0.0, m.orthotropic->weft.SmallStrainModulus(),
         4.0 * m.orthotropic->shear_modulus};
  } else {
    const double nu = m.poisson, e = m.stretch_stiffness;
    const double lambda = e * nu / (1.0 - nu * nu), mu = e / (2.0 * (1.0 + nu));
    k = {lambda + 2.0 * mu, lambda, lambda + 2.0 * mu, 4.0 * mu};
  }
  nlohmann::json row = nlohmann::json::array();
  for (double v : k) row.push_back(0.5 * v);
  return nlohmann::json::array({row, row, row, row, row, row});
}

// The membrane fields a file must give for ARCSim's stretching, that this one left to defaults.
std::vector<std::string> MissingMembraneFields(const Material& m) {
  std::vector<std::string> missing;
  const std::vector<std::string> fields =
      m.orthotropic ? std::vector<std::string>{"stretch.warp", "stretch.weft", "stretch.shear"}
                    : std::vector<std::string>{"stretch.stiffness_N_per_m", "stretch.poisson"};
  for (const std::string& f : fields)
    if (m.IsDefaulted(f)) missing.push_back(f);
  return missing;
}

bool IsLinearCurve(const TensileCurve& c) { return c.strains().size() <= 1; }

void AddStretching(const Material& m, const ExportOptions& o, nlohmann::json* out,
                   std::vector<Note>* notes) {
  const std::vector<std::string> missing = MissingMembraneFields(m);
  if (!missing.empty()) {
    if (o.strict)
      throw InputError(JoinText(missing, ", ") +
                       ": ARCSim's stretching needs the membrane measured; the material leaves it "
                       "to defaults (drop --strict to export without stretching)");
    notes->push_back({"stretching_left_out",
                      "stretching left out: the material does not give " + JoinText(missing, ", ") +
                          " (its simulations use documented defaults); add ARCSim's stretching "
                          "from your own tensile data"});
    return;
  }
  (*out)["stretching"] = ArcsimStretching(m);
  if (m.orthotropic && !(IsLinearCurve(m.orthotropic->warp) && IsLinearCurve(m.orthotropic->weft)))
    notes->push_back({"stretching_linearised",
                      "stretching: the tensile curves are written at their small-strain moduli "
                      "(ARCSim samples a curve only at 0 and 16.7 % strain, past a woven's EMT)"});
  if (m.compression_ratio < 1.0)
    notes->push_back({"compression_not_exported",
                      "stretching: ARCSim's membrane is as stiff in compression as in tension; "
                      "the material's compression ratio " + NumberText(m.compression_ratio) +
                          " is not carried"});
}

// One note a law of the fork's keys that is not exact for every curvature; a material with one
// law has one note for all three keys.
void AddPcbNotes(const Material& m, const std::vector<Direction>& dirs, std::vector<Note>* notes) {
  for (const Direction& d : dirs) {
    if (std::string(d.kind) == "blend") continue;  // the mean of the other two keys
    const bool one_law = !m.bending_weft && !m.bending_bias;
    const std::string key = !one_law ? std::string("pcb_bending_") + d.name
                                     : std::string("pcb_bending_warp, _weft and _bias");
    const QuadraticBending q = PcbBending(d.law);
    if (d.law.is_spline()) {
      notes->push_back({"pcb_bending_fitted",
                        key + ": least-squares quadratic of the spline law up to " +
                            NumberText(units::SiCurvatureToKes(q.kappa_fit), 4) +
                            " /cm, moment within " + NumberText(100.0 * q.max_relative_error, 3) +
                            " %" +
                            (q.max_relative_error > 0.1
                                 ? ": a quadratic cannot follow this law, use the bending table"
                                 : "")});
    } else if (std::isfinite(q.kappa_fit)) {
      notes->push_back({"pcb_bending_quadratic",
                        key + ": the law's quadratic branch, exact up to kappa0 = " +
                            NumberText(units::SiCurvatureToKes(q.kappa_fit), 4) +
                            " /cm; past it the law is linear and the fork's moment " +
                            (d.law.c1() < 0.0 ? "falls below it" : "rises above it")});
    }
    if (one_law) return;
  }
}

ExportedMaterial ExportArcsim(const Material& m, const ExportOptions& o) {
  ExportedMaterial e;
  nlohmann::json j;
  j["density"] = m.areal_density;
  j["bending"] = ArcsimBendingTable(m);
  const std::vector<Direction> dirs = Directions(m);
  // The fork's bias key: the measured bias law's quadratic, else the 45° blend's (for two
  // quadratics, their mean).
  const QuadraticBending warp = PcbBending(dirs[0].law), weft = PcbBending(dirs[1].law);
  j["pcb_bending_warp"] = PcbJson(warp);
  j["pcb_bending_weft"] = PcbJson(weft);
  j["pcb_bending_bias"] =
      m.bending_bias ? PcbJson(PcbBending(dirs[2].law))
                     : nlohmann::json::array({0.5 * (warp.k1 + weft.k1), 0.5 * (warp.k2 + weft.k2)});
  AddStretching(m, o, &j, &e.notes);
  AddPcbNotes(m, dirs, &e.notes);
  e.notes.push_back({"arcsim_curvature_samples",
                     "bending: 4 M(kappa)/kappa at kappa = 0, 10, 20, 30, 40 /m (ARCSim's alpha = "
                     "kappa/2 = 0-20 /m); ARCSim holds the last beyond 40 /m (0.4 /cm)"});
  e.text = j.dump(2) + "\n";
  return e;
}

// ---- U3M 1.1 ------------------------------------------------------------------------------

nlohmann::json OrNull(const nlohmann::json& fit, const char* key, double scale) {
  if (!fit.is_object() || !fit.contains(key) || !fit[key].is_number()) return nullptr;
  return fit[key].get<double>() * scale;
}

// The law's 1-σ in KES units (β applied) from the fit report, null where unknown.
nlohmann::json BendingSigma(const Material& m) {
  if (!m.fit.is_object() || m.bending_weft || m.bending_bias) return nullptr;
  return {{"units", "kes"},
          {"b1", OrNull(m.fit, "b1_sd", m.beta)},
          {"b2", OrNull(m.fit, "b2_sd", m.beta)},
          {"c1", OrNull(m.fit, "c1_sd", m.beta)}};
}

nlohmann::json U3mCustom(const Material& m, const ExportOptions& o) {
  const nlohmann::json file = MaterialToJson(m);
  nlohmann::json t = {{"format", "textile material (docs/spec/cli.md)"},
                      {"bending", LawToJson(m.EffectiveLaw())},
                      {"bending_sigma", BendingSigma(m)},
                      {"beta_applied", m.beta},
                      {"areal_density_gsm", units::SiToGsm(m.areal_density)},
                      {"material", file}};
  if (m.bending_weft) t["bending_weft"] = LawToJson(m.EffectiveWeftLaw());
  if (m.bending_bias) t["bending_bias"] = LawToJson(*m.EffectiveBiasLaw());
  if (!o.producer.empty()) t["producer"] = o.producer;
  return t;
}

ExportedMaterial ExportU3m(const Material& m, const ExportOptions& o) {
  if (m.name.empty())
    throw InputError("name: U3M's material.name must not be empty; the material file has no "
                     "\"name\": add one");
  if (o.thickness_mm && !(std::isfinite(*o.thickness_mm) && *o.thickness_mm > 0.0 &&
                          *o.thickness_mm <= 100.0))
    throw InputError("--thickness-mm: " + NumberText(*o.thickness_mm) +
                     " mm is not a fabric's thickness (0 < t <= 100 mm)");
  ExportedMaterial e;
  const nlohmann::json custom = U3mCustom(m, o);
  const std::string stamp = o.timestamp.empty() ? ExportTimestamp() : o.timestamp;
  nlohmann::json physics = {
      {"thickness", o.thickness_mm ? nlohmann::json(*o.thickness_mm) : nlohmann::json()},
      {"weight", units::SiToGsm(m.areal_density)},
      {"devices", {{"fab", "null"}}},
      {"composition", nullptr},
      {"material_type", nullptr},
      {"construction", nullptr}};
  nlohmann::json material = {
      {"id", ""},
      {"name", m.name},
      {"description", "Bending measured by cantilever and fitted by textile (moment-curvature "
                      "law of Pabst et al. 2008); the law is in custom.textile"},
      {"created", stamp},
      {"modified", stamp},
      {"front", nullptr},
      {"back", nullptr},
      {"side", nullptr},
      {"physics", physics},
      {"metadata", nullptr}};
  nlohmann::json j = {{"schema", "1.1"}, {"material", material}, {"custom", {{"textile", custom}}}};
  // The id hashes everything exported but the id, the times and the producer's version: the
  // same material and thickness give the same id whenever and by whichever version.
  nlohmann::json hashed = j;
  hashed["material"].erase("created");
  hashed["material"].erase("modified");
  hashed["custom"]["textile"].erase("producer");
  j["material"]["id"] = ContentUuid4(hashed.dump());
  if (!o.thickness_mm)
    e.notes.push_back({"thickness_unknown",
                       "physics.thickness is null: a cantilever does not measure it "
                       "(give --thickness-mm)"});
  e.text = j.dump(2) + "\n";
  return e;
}

// ---- CSV ----------------------------------------------------------------------------------

std::string Cell(double v, int digits = 8) { return std::isfinite(v) ? NumberText(v, digits) : ""; }

std::string SigmaCell(const nlohmann::json& sigma, const char* key) {
  if (!sigma.is_object() || !sigma[key].is_number()) return "";
  return Cell(sigma[key].get<double>());
}

ExportedMaterial ExportCsv(const Material& m) {
  ExportedMaterial e;
  std::ostringstream out;
  out << "direction,angle_deg,law,b1_gfcm,b2_gfcm,c1_gfcm2,b1_sd_gfcm,b2_sd_gfcm,c1_sd_gfcm2,"
         "bending_length_mm,flexural_rigidity_uNm,flexural_rigidity_mgcm,areal_density_gsm,"
         "tensile_modulus_N_per_m,shear_modulus_N_per_m\n";
  const nlohmann::json sigma = BendingSigma(m);
  const std::optional<MembraneModuli> moduli = MeasuredMembraneModuli(m);
  for (const Direction& d : Directions(m)) {
    const bool pabst = std::string(d.kind) == "pabst";
    // Only a material with one law has the fit's σ, and then every direction shares it.
    const bool has_sigma = sigma.is_object();
    out << d.name << ',' << Cell(d.angle_deg) << ',' << d.kind << ',' << Cell(d.law.b1_kes())
        << ',' << (pabst ? Cell(d.law.b2_kes()) : "") << ',' << (pabst ? Cell(d.law.c1_kes()) : "")
        << ',' << (has_sigma ? SigmaCell(sigma, "b1") : "") << ','
        << (has_sigma ? SigmaCell(sigma, "b2") : "") << ','
        << (has_sigma ? SigmaCell(sigma, "c1") : "") << ',';
    const BarrierCrossing crossing = FindBarrierCrossing(d.law, m.areal_density);
    if (crossing.converged) {
      const ClassicOutputs c = ComputeClassicOutputs(m.areal_density, crossing.overhang);
      out << Cell(units::MToMm(c.bending_length)) << ',' << Cell(c.rigidity_micro_nm()) << ','
          << Cell(c.rigidity_mg_cm());
    } else {
      out << ",,";
      // One note for a material with one law: its three directions are the same strip.
      const bool one_law = !m.bending_weft && !m.bending_bias;
      if (!one_law || d.angle_deg == 0.0)
        e.notes.push_back({"no_bending_length",
                           std::string(!one_law ? d.name : "warp, weft and bias") +
                               ": no bending length: " + crossing.message});
    }
    out << ',' << Cell(units::SiToGsm(m.areal_density)) << ',';
    if (moduli) {
      const double k = d.angle_deg == 0.0 ? moduli->warp : d.angle_deg == 90.0 ? moduli->weft
                                                                                : moduli->bias;
      out << Cell(k) << ',' << Cell(moduli->shear);
    } else {
      out << ',';
    }
    out << '\n';
  }
  if (!moduli)
    e.notes.push_back({"membrane_not_measured",
                       "tensile and shear moduli left empty: the material does not give " +
                           JoinText(MissingMembraneFields(m), ", ")});
  if (m.bending_weft && !m.bending_bias)
    e.notes.push_back({"bias_blend",
                       "bias: the 45 degree blend of the warp and weft laws, M = (M_warp + "
                       "M_weft) / 2; b2 and c1 are empty (not a Pabst law)"});
  e.text = out.str();
  return e;
}

}  // namespace

ExportFormat ParseExportFormat(const std::string& name) {
  if (name == "arcsim") return ExportFormat::kArcsim;
  if (name == "u3m") return ExportFormat::kU3m;
  if (name == "csv") return ExportFormat::kCsv;
  throw InputError("--to: '" + name + "' is not a format: arcsim, u3m or csv");
}

double SecantStiffness(const BendingLaw& law, double kappa) {
  return kappa == 0.0 ? law.Stiffness(0.0) : law.Moment(kappa) / kappa;
}

double SecantStiffness(const BlendedLaw& law, double kappa) {
  return kappa == 0.0 ? law.Stiffness(0.0) : law.Moment(kappa) / kappa;
}

QuadraticBending PcbBending(const BendingLaw& law) {
  if (!law.is_spline()) {
    if (law.kappa0() == 0.0) return {law.b2(), 0.0, 0.0, kInf};  // M = b2 κ
    return {law.b1(), law.c1(), 0.0, law.kappa0()};             // exact up to κ0 (∞: always)
  }
  // Least squares of the relative error of M(κ) = k1 κ + k2 κ² on 128 even samples of
  // (0, last knot]: each row divided by M(κ).
  constexpr int kSamples = 128;
  const double reach = law.kappa0();
  Eigen::MatrixXd a(kSamples, 2);
  Eigen::VectorXd b(kSamples);
  for (int i = 0; i < kSamples; ++i) {
    const double k = reach * (i + 1) / kSamples;
    const double m = law.Moment(k);
    a(i, 0) = k / m;
    a(i, 1) = k * k / m;
    b(i) = 1.0;
  }
  const Eigen::Vector2d x = a.colPivHouseholderQr().solve(b);
  QuadraticBending q{x(0), x(1), 0.0, reach};
  // The relative error tends to |k1 / B(0) - 1| as κ → 0, often the largest.
  q.max_relative_error = std::abs(x(0) / law.Stiffness(0.0) - 1.0);
  for (int i = 0; i < kSamples; ++i)
    q.max_relative_error = std::max(q.max_relative_error, std::abs((a.row(i) * x)(0) - 1.0));
  return q;
}

BendingLaw BiasLaw(const Material& m) {
  if (!m.bending_weft) return m.EffectiveLaw();
  const BlendedLaw blend(m.EffectiveLaw(), m.EffectiveWeftLaw(), 0.25 * std::numbers::pi);
  constexpr int kKnots = 40;  // besides κ = 0: 0.01 .. 1000 /m, 8 a decade
  std::vector<double> kappa = {0.0}, moment = {0.0};
  for (int i = 0; i <= kKnots; ++i) {
    const double k = std::pow(10.0, -2.0 + 5.0 * i / kKnots);
    kappa.push_back(k);
    moment.push_back(blend.Moment(k));
  }
  return BendingLaw::FromSpline(kappa, moment);
}

std::optional<MembraneModuli> MeasuredMembraneModuli(const Material& m) {
  if (!MissingMembraneFields(m).empty()) return std::nullopt;
  if (m.orthotropic) {
    const double ew = m.orthotropic->warp.SmallStrainModulus();
    const double ef = m.orthotropic->weft.SmallStrainModulus();
    const double g = m.orthotropic->shear_modulus;
    return MembraneModuli{ew, ef, 4.0 / (1.0 / ew + 1.0 / ef + 1.0 / g), g};
  }
  const double e = m.stretch_stiffness;
  return MembraneModuli{e, e, e, e / (2.0 * (1.0 + m.poisson))};
}

std::string ContentUuid4(const std::string& content) {
  const ContentHash h = HashContent(content);
  std::uint64_t hi = h.hi;
  std::uint64_t lo = h.lo;
  hi = (hi & ~0xF000ULL) | 0x4000ULL;                        // version 4 (bits 12-15)
  lo = (lo & 0x3FFFFFFFFFFFFFFFULL) | 0x8000000000000000ULL;  // variant 10
  char s[37];
  std::snprintf(s, sizeof s, "%08x-%04x-%04x-%04x-%012llx", static_cast<unsigned>(hi >> 32),
                static_cast<unsigned>((hi >> 16) & 0xFFFF), static_cast<unsigned>(hi & 0xFFFF),
                static_cast<unsigned>(lo >> 48),
                static_cast<unsigned long long>(lo & 0xFFFFFFFFFFFFULL));
  return s;
}

std::string ExportTimestamp() {
  std::time_t t = std::time(nullptr);
  if (const char* env = std::getenv("SOURCE_DATE_EPOCH"); env && *env) {
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(env, &end, 10);
    // 253402300799 is 9999-12-31T23:59:59Z, the last time ISO 8601's four-digit year writes.
    if (*end != '\0' || errno == ERANGE || v < 0 || v > 253402300799LL)
      throw InputError(std::string("SOURCE_DATE_EPOCH: '") + env +
                       "' is not a whole number of seconds from 0 to 253402300799");
    t = static_cast<std::time_t>(v);
  }
  std::tm tm{};
  if (gmtime_r(&t, &tm) == nullptr) throw ComputeError("the clock's time is not a date");
  char s[32];
  std::strftime(s, sizeof s, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return s;
}

ExportedMaterial ExportMaterial(const Material& material, ExportFormat format,
                                const ExportOptions& options) {
  if (options.thickness_mm && format != ExportFormat::kU3m)
    throw InputError("--thickness-mm: only U3M carries a thickness");
  switch (format) {
    case ExportFormat::kArcsim:
      return ExportArcsim(material, options);
    case ExportFormat::kU3m:
      return ExportU3m(material, options);
    case ExportFormat::kCsv:
      return ExportCsv(material);
  }
  throw InputError("unknown export format");
}

}  // namespace textile
