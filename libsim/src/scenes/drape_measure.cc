#include "textile/sim/scenes/drape_measure.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "drape_stages.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/core/units.h"
#include "textile/sim/io/json_fields.h"
#include "textile/sim/io/json_text.h"

namespace textile {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegree = kPi / 180.0;
// Outline radii beyond the flat specimen's: up to this factor a note (threshold, stretch), past
// it a refusal (wrong scale or wrong specimen radius).
constexpr double kBeyondSpecimenNote = 1.02;
constexpr double kBeyondSpecimenRefuse = 1.10;

bool Fail(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}

std::string Mm(double metres) { return NumberText(units::MToMm(metres), 4) + " mm"; }

void CheckGrid(const DrapeShadow& s, const std::string& source) {
  if (!(s.cell > 0.0) || !std::isfinite(s.cell) || !std::isfinite(s.origin_x) ||
      !std::isfinite(s.origin_y))
    throw InputError(source + ": shadow grid: the cell must be > 0 and the origin finite");
  if (s.width < 3 || s.height < 3 ||
      s.mask.size() != static_cast<size_t>(s.width) * static_cast<size_t>(s.height))
    throw InputError(source + ": shadow grid: need at least 3 × 3 cells and one mask value each");
}

// Stage 1: a covered cell on the grid's border means the shadow runs out of what was measured.
void CheckNotCut(const DrapeShadow& s, const std::string& source) {
  auto covered = [&s](int i, int j) { return s.mask[static_cast<size_t>(j) * s.width + i] != 0; };
  for (int i = 0; i < s.width; ++i)
    if (covered(i, 0) || covered(i, s.height - 1))
      throw ComputeError(source +
                         ": the outline is not a closed curve around the support: the shadow "
                         "runs out of the measured area (cut by the photo's border?)");
  for (int j = 0; j < s.height; ++j)
    if (covered(0, j) || covered(s.width - 1, j))
      throw ComputeError(source +
                         ": the outline is not a closed curve around the support: the shadow "
                         "runs out of the measured area (cut by the photo's border?)");
}

// Stage 2: in every direction the fabric must reach the support's edge (within two cells), or
// the specimen is torn, partial or off centre.
void CheckCoversSupport(const DrapeShadow& s, const DrapeMeasureOptions& o,
                        const std::string& source) {
  const int bins = o.outline_bins;
  std::vector<double> reach(bins, -1.0);
  for (int j = 0; j < s.height; ++j) {
    const double y = s.origin_y + j * s.cell;
    for (int i = 0; i < s.width; ++i) {
      if (!s.mask[static_cast<size_t>(j) * s.width + i]) continue;
      const double x = s.origin_x + i * s.cell;
      double theta = std::atan2(y, x);
      if (theta < 0.0) theta += 2.0 * kPi;
      const int b = std::min(bins - 1, static_cast<int>(theta / (2.0 * kPi) * bins));
      reach[b] = std::max(reach[b], std::hypot(x, y));
    }
  }
  const double needed = o.support_radius - 2.0 * s.cell;
  int short_bins = 0, first_short = -1;
  for (int b = 0; b < bins; ++b) {
    if (reach[b] >= needed) continue;
    if (first_short < 0) first_short = b;
    ++short_bins;
  }
  if (short_bins == 0) return;
  throw ComputeError(source + ": the outline is not a closed curve around the support: in " +
                     std::to_string(short_bins) + " of " + std::to_string(bins) +
                     " directions (the first at " +
                     NumberText((first_short + 0.5) * 360.0 / bins, 4) +
                     "°) the specimen does not reach the support's edge at " +
                     Mm(o.support_radius) +
                     " (a partial or torn specimen, or the wrong centre or scale)");
}

// Stage 4: the outline against the flat specimen's radius.
void CheckWithinSpecimen(const MeasuredDrape& m, const std::string& source,
                         std::vector<Note>* notes) {
  const double r = m.specimen_radius;
  if (m.max_radius > kBeyondSpecimenRefuse * r)
    throw InputError(source + ": the outline reaches " + Mm(m.max_radius) +
                     " from the centre, beyond the specimen's radius " + Mm(r) +
                     ": check the specimen radius (--specimen-mm) and the scale (--units, "
                     "--mm-per-px or --rig)");
  if (m.max_radius > kBeyondSpecimenNote * r)
    notes->push_back({"beyond_specimen", "the outline reaches " + Mm(m.max_radius) +
                                             ", beyond the flat specimen's radius " + Mm(r) +
                                             ": a stretched specimen or a loose scale"});
}

nlohmann::json NotesJson(const std::vector<Note>& notes) {
  nlohmann::json j = nlohmann::json::array();
  for (const Note& n : notes) j.push_back({{"code", n.code}, {"text", n.text}});
  return j;
}

}  // namespace

bool DrapeMeasureOptions::Check(std::string* why) const {
  if (!(std::isfinite(support_radius) && support_radius > 0.0))
    return Fail(why, "support radius: must be > 0");
  if (!(std::isfinite(specimen_radius) && specimen_radius > support_radius))
    return Fail(why, "specimen radius: must be larger than the support's");
  if (!(std::isfinite(raster_cell) && raster_cell > 0.0 && raster_cell <= 0.05 * support_radius))
    return Fail(why, "raster cell: must be > 0 and at most 5 % of the support radius");
  if (outline_bins < 8 || outline_bins > 100000)
    return Fail(why, "outline bins: must be between 8 and 100000");
  if (smoothing_bins < 1 || smoothing_bins % 2 == 0 || smoothing_bins > outline_bins)
    return Fail(why, "smoothing bins: must be odd and between 1 and the outline bins");
  if (!(std::isfinite(node_prominence) && node_prominence >= 0.0))
    return Fail(why, "node prominence: must be >= 0");
  if (!(std::isfinite(node_prominence_relative) && node_prominence_relative >= 0.0 &&
        node_prominence_relative < 1.0))
    return Fail(why, "relative node prominence: must lie in [0, 1)");
  return true;
}

DrapeMeasureOptions MeasureOptionsOf(const DrapeOptions& o) {
  DrapeMeasureOptions m;
  m.specimen_radius = o.specimen_radius;
  m.support_radius = o.support_radius;
  m.raster_cell = o.raster_cell;
  m.outline_bins = o.outline_bins;
  m.smoothing_bins = o.smoothing_bins;
  m.node_prominence = o.node_prominence;
  m.node_prominence_relative = o.node_prominence_relative;
  return m;
}

MeasuredDrape MeasureDrapeShadow(DrapeShadow fabric, const DrapeMeasureOptions& o,
                                 const std::string& source) {
  if (std::string why; !o.Check(&why)) throw InputError(source + ": " + why);
  CheckGrid(fabric, source);
  CheckNotCut(fabric, source);
  CheckCoversSupport(fabric, o, source);
  MeasuredDrape m;
  m.source = source;
  m.specimen_radius = o.specimen_radius;
  m.support_radius = o.support_radius;
  m.shadow = std::move(fabric);
  m.shadow.area = 0.0;
  m.shadow.bare_support_area = 0.0;
  drape_internal::AddSupportShadow(o.support_radius, &m.shadow);
  drape_internal::FloodFromBorder(&m.shadow);
  drape_internal::MeasureOutline(o.outline_bins, &m.shadow);
  drape_internal::FillEmptyBins(&m.shadow.radii);
  m.drape_coefficient = DrapeCoefficient(m.shadow.area, kPi * o.specimen_radius * o.specimen_radius,
                                         kPi * o.support_radius * o.support_radius);
  m.nodes = FindNodes(m.shadow.radii, o.smoothing_bins, o.node_prominence,
                      o.node_prominence_relative);
  m.min_radius = m.shadow.radii.minCoeff();
  m.max_radius = m.shadow.radii.maxCoeff();
  m.mean_radius = m.shadow.radii.mean();
  CheckWithinSpecimen(m, source, &m.notes);
  return m;
}

std::string OutlineCsv(const DrapeShadow& s) {
  std::ostringstream out;
  out.precision(10);
  out << "theta_deg,r_mm,x_mm,y_mm\n";
  for (int b = 0; b < s.angles.size(); ++b) {
    const double t = s.angles(b), r = s.radii(b);
    out << t / kDegree << "," << units::MToMm(r) << "," << units::MToMm(r * std::cos(t)) << ","
        << units::MToMm(r * std::sin(t)) << "\n";
  }
  return out.str();
}

std::string MeasuredDrapeJson(const MeasuredDrape& m) {
  nlohmann::json j;
  j["format"] = "textile-measured-drape";
  j["version"] = 1;
  j["source"] = m.source;
  j["input"] = m.input_kind;
  j["drape_coefficient"] = m.drape_coefficient;
  j["nodes"] = m.nodes.angles.size();
  nlohmann::json nodes = nlohmann::json::array();
  for (size_t k = 0; k < m.nodes.angles.size(); ++k)
    nodes.push_back({{"angle_deg", m.nodes.angles[k] / kDegree},
                     {"radius_mm", units::MToMm(m.nodes.radii[k])},
                     {"prominence_mm", units::MToMm(m.nodes.prominences[k])}});
  j["node_list"] = nodes;
  j["shadow_area_mm2"] = m.shadow.area * 1e6;
  j["min_radius_mm"] = units::MToMm(m.min_radius);
  j["max_radius_mm"] = units::MToMm(m.max_radius);
  j["mean_radius_mm"] = units::MToMm(m.mean_radius);
  j["specimen_radius_mm"] = units::MToMm(m.specimen_radius);
  j["support_radius_mm"] = units::MToMm(m.support_radius);
  j["raster_cell_mm"] = units::MToMm(m.shadow.cell);
  j["centre_mm"] = {units::MToMm(m.centre.x()), units::MToMm(m.centre.y())};
  j["centre_from"] = m.centre_from;
  j["notes"] = NotesJson(m.notes);
  nlohmann::json theta = nlohmann::json::array(), radius = nlohmann::json::array();
  for (int b = 0; b < m.shadow.angles.size(); ++b) {
    theta.push_back(m.shadow.angles(b) / kDegree);
    radius.push_back(units::MToMm(m.shadow.radii(b)));
  }
  j["outline"] = {{"theta_deg", theta}, {"r_mm", radius}};
  return j.dump(2) + "\n";
}

MeasuredDrape ParseMeasuredDrapeJson(const std::string& text, const std::string& source) {
  const nlohmann::json root = ParseJsonText(text, source);
  const JsonFields f(source);
  f.RequireObject(root);
  const std::string format = f.String(
      f.Require(root, "format", "a measured drape from `textile drape-measure`"), "format");
  if (format != "textile-measured-drape")
    f.Unknown("format", "format", format, "\"textile-measured-drape\"");
  const double version = f.Number(f.Require(root, "version"), "version");
  if (version != 1.0) f.Must("version", "be 1", root["version"]);

  MeasuredDrape m;
  m.source = root.contains("source") ? f.String(root["source"], "source") : source;
  m.input_kind = root.contains("input") ? f.String(root["input"], "input") : "";
  m.drape_coefficient = f.Number(f.Require(root, "drape_coefficient"), "drape_coefficient");
  if (!(m.drape_coefficient >= 0.0 && m.drape_coefficient <= 1.2))
    f.Must("drape_coefficient", "lie in [0, 1.2]", root["drape_coefficient"]);
  m.specimen_radius =
      units::MmToM(f.Number(f.Require(root, "specimen_radius_mm"), "specimen_radius_mm"));
  m.support_radius =
      units::MmToM(f.Number(f.Require(root, "support_radius_mm"), "support_radius_mm"));
  if (!(m.support_radius > 0.0))
    f.Must("support_radius_mm", "be > 0", root["support_radius_mm"]);
  if (!(m.specimen_radius > m.support_radius))
    f.Must("specimen_radius_mm", "be larger than support_radius_mm", root["specimen_radius_mm"]);

  const nlohmann::json& list = f.Require(root, "node_list");
  if (!list.is_array()) f.Must("node_list", "be an array of nodes", list);
  for (size_t k = 0; k < list.size(); ++k) {
    const std::string at = JsonFields::Element("node_list", k);
    const nlohmann::json& n = f.Object(list[k], at, "{\"angle_deg\", \"radius_mm\", ...}");
    m.nodes.angles.push_back(f.Number(f.Require(n, "angle_deg", "", at + ".angle_deg"),
                                      at + ".angle_deg") *
                             kDegree);
    m.nodes.radii.push_back(
        units::MmToM(f.Number(f.Require(n, "radius_mm", "", at + ".radius_mm"), at + ".radius_mm")));
    m.nodes.prominences.push_back(
        n.contains("prominence_mm") ? units::MmToM(f.Number(n["prominence_mm"], at + ".prominence_mm"))
                                    : 0.0);
  }

  const nlohmann::json& outline =
      f.Object(f.Require(root, "outline"), "outline", "{\"theta_deg\", \"r_mm\"}");
  const std::vector<double> theta =
      f.Numbers(f.Require(outline, "theta_deg", "", "outline.theta_deg"), "outline.theta_deg");
  const std::vector<double> radius =
      f.Numbers(f.Require(outline, "r_mm", "", "outline.r_mm"), "outline.r_mm");
  if (theta.size() < 8 || theta.size() != radius.size())
    f.Must("outline", "hold at least 8 angles and as many radii", outline);
  const double step = 360.0 / static_cast<double>(theta.size());
  m.shadow.angles.resize(static_cast<Eigen::Index>(theta.size()));
  m.shadow.radii.resize(static_cast<Eigen::Index>(theta.size()));
  for (size_t b = 0; b < theta.size(); ++b) {
    // Uniform bins from 0 (FindNodes' and the comparison's convention).
    if (std::abs(theta[b] - (static_cast<double>(b) + 0.5) * step) > 1e-6 * step)
      f.Must(JsonFields::Element("outline.theta_deg", b),
             "be the centre of uniform bins from 0° (" + NumberText((b + 0.5) * step) + ")",
             outline["theta_deg"][b]);
    if (!(radius[b] > 0.0))
      f.Must(JsonFields::Element("outline.r_mm", b), "be > 0", outline["r_mm"][b]);
    m.shadow.angles(static_cast<Eigen::Index>(b)) = theta[b] * kDegree;
    m.shadow.radii(static_cast<Eigen::Index>(b)) = units::MmToM(radius[b]);
  }
  m.min_radius = m.shadow.radii.minCoeff();
  m.max_radius = m.shadow.radii.maxCoeff();
  m.mean_radius = m.shadow.radii.mean();
  if (root.contains("shadow_area_mm2"))
    m.shadow.area = f.Number(root["shadow_area_mm2"], "shadow_area_mm2") * 1e-6;
  if (root.contains("centre_mm")) {
    const auto c = f.FixedNumbers<2>(root["centre_mm"], "centre_mm", "[x, y]");
    m.centre = {units::MmToM(c[0]), units::MmToM(c[1])};
  }
  if (root.contains("centre_from")) m.centre_from = f.String(root["centre_from"], "centre_from");
  if (root.contains("notes")) {
    const nlohmann::json& notes = root["notes"];
    if (!notes.is_array()) f.Must("notes", "be an array of {\"code\", \"text\"}", notes);
    for (size_t k = 0; k < notes.size(); ++k) {
      const std::string at = JsonFields::Element("notes", k);
      const nlohmann::json& n = f.Object(notes[k], at, "{\"code\", \"text\"}");
      m.notes.push_back({f.String(f.Require(n, "code", "", at + ".code"), at + ".code"),
                         f.String(f.Require(n, "text", "", at + ".text"), at + ".text")});
    }
  }
  return m;
}

}  // namespace textile
