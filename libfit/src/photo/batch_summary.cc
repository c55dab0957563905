// The statistics of a specimen series (batch.h): per fabric and direction, n, mean, sample sd
// and CV of the law's constants and of the classic 41.5° outputs, as FAST and ASTM D1388 report
// them; the overall rigidity sqrt(G_warp G_weft) (ASTM D1388 section 11, FAST's "overall");
// and one material per fabric from its direction means.

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "textile/photo/batch.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

using nlohmann::json;

// A reported quantity: its JSON key and CSV stem, its unit, and where a specimen's value is.
// A law constant counts only where its fit observed it (the report's <name>_observed): a short
// noisy profile leaves b1 or c1 undetermined, and such a value (b1 9x the truth on one 40 mm
// profile) would swamp the mean.
struct Quantity {
  const char* name;  // "b1"
  const char* unit;  // "gfcm"
  std::optional<double> (*value)(const Material&);
  bool law_constant = false;
  // The same quantity in another unit as the one before: its CV and n are that one's, and the
  // CSV does not repeat them (two columns of one name).
  bool another_unit = false;
};

std::optional<double> FitNumber(const Material& m, const char* key) {
  if (!m.fit.is_object() || !m.fit.contains(key) || !m.fit[key].is_number()) return std::nullopt;
  return m.fit[key].get<double>();
}

// False when the fit report says that `constant` ("b1") was not determined by the data.
bool Observed(const Material& m, const std::string& constant) {
  const std::string key = constant + "_observed";
  return !(m.fit.is_object() && m.fit.contains(key) && m.fit[key].is_boolean() &&
           !m.fit[key].get<bool>());
}

const std::vector<Quantity>& Quantities() {
  static const std::vector<Quantity> q = {
      {"b1", "gfcm", [](const Material& m) -> std::optional<double> { return m.bending.b1_kes(); },
       true},
      {"b2", "gfcm", [](const Material& m) -> std::optional<double> { return m.bending.b2_kes(); },
       true},
      {"c1", "gfcm2", [](const Material& m) -> std::optional<double> { return m.bending.c1_kes(); },
       true},
      {"bending_length", "mm",
       [](const Material& m) { return FitNumber(m, "bending_length_mm"); }},
      {"flexural_rigidity", "uNm",
       [](const Material& m) { return FitNumber(m, "flexural_rigidity_uNm"); }},
      {"flexural_rigidity", "mgcm",
       [](const Material& m) { return FitNumber(m, "flexural_rigidity_mgcm"); }, false, true}};
  return q;
}

std::string Key(const Quantity& q) { return std::string(q.name) + "_" + q.unit; }

json OrNull(const std::optional<double>& v) { return v ? json(*v) : json(); }

json StatsJson(const SeriesStats& s, size_t unobserved) {
  return {{"n", s.n},
          {"n_unobserved", unobserved},
          {"mean", s.n > 0 ? json(s.mean) : json()},
          {"sd", OrNull(s.sd)},
          {"cv", OrNull(s.cv)}};
}

constexpr StripDirection kDirections[] = {StripDirection::kWarp, StripDirection::kWeft,
                                          StripDirection::kBias};

// The fabrics in manifest order.
std::vector<std::string> Fabrics(const std::vector<SpecimenOutcome>& specimens) {
  std::vector<std::string> out;
  std::set<std::string> seen;
  for (const SpecimenOutcome& o : specimens)
    if (seen.insert(o.row->fabric).second) out.push_back(o.row->fabric);
  return out;
}

std::vector<const SpecimenOutcome*> Fitted(const std::vector<SpecimenOutcome>& specimens,
                                           const std::string& fabric, StripDirection d) {
  std::vector<const SpecimenOutcome*> out;
  for (const SpecimenOutcome& o : specimens)
    if (o.row->fabric == fabric && o.row->direction == d && o.material) out.push_back(&o);
  return out;
}

// The quantity's values over the specimens whose fit determined it; *unobserved counts the rest.
std::vector<double> ObservedValues(const std::vector<const SpecimenOutcome*>& fitted,
                                   const Quantity& q, size_t* unobserved) {
  std::vector<double> v;
  *unobserved = 0;
  for (const SpecimenOutcome* o : fitted) {
    if (q.law_constant && !Observed(*o->material, q.name)) {
      ++*unobserved;
      continue;
    }
    if (std::optional<double> x = q.value(*o->material)) v.push_back(*x);
  }
  return v;
}

json DirectionJson(const std::vector<SpecimenOutcome>& specimens, const std::string& fabric,
                   StripDirection d) {
  const std::vector<const SpecimenOutcome*> fitted = Fitted(specimens, fabric, d);
  size_t failed = 0;
  for (const SpecimenOutcome& o : specimens)
    failed += o.row->fabric == fabric && o.row->direction == d &&
              o.status == SpecimenStatus::kFailed;
  json j = {{"fabric", fabric}, {"direction", DirectionName(d)}, {"n", fitted.size()},
            {"n_failed", failed}};
  for (const Quantity& q : Quantities()) {
    size_t unobserved = 0;
    const std::vector<double> v = ObservedValues(fitted, q, &unobserved);
    j[Key(q)] = StatsJson(Stats(v), unobserved);
  }
  return j;
}

// sqrt(G_warp G_weft) from the direction means [unit of `key`], or null.
json OverallRigidity(const json& directions, const std::string& fabric, const std::string& key) {
  std::optional<double> warp, weft;
  for (const json& d : directions) {
    if (d["fabric"] != fabric || d[key]["n"].get<size_t>() == 0) continue;
    if (d["direction"] == "warp") warp = d[key]["mean"].get<double>();
    if (d["direction"] == "weft") weft = d[key]["mean"].get<double>();
  }
  return warp && weft ? json(std::sqrt(*warp * *weft)) : json();
}

json SpecimenJson(const SpecimenOutcome& o) {
  json j = {{"fabric", o.row->fabric},
            {"specimen", o.row->specimen},
            {"direction", DirectionName(o.row->direction)},
            {"side", SideName(o.row->side)},
            {"line", o.row->line},
            // A resumed specimen is reported as the fit it resumed: the same bytes either way.
            {"status", o.status == SpecimenStatus::kFailed      ? "failed"
                       : o.status == SpecimenStatus::kNotInShard ? "other shard"
                                                                  : "fitted"},
            {"error", o.error.empty() ? json() : json(o.error)}};
  for (const Quantity& q : Quantities())
    j[Key(q)] = o.material ? OrNull(q.value(*o.material)) : json();
  j["rms_mm"] = o.material ? OrNull(FitNumber(*o.material, "rms_mm")) : json();
  json unobserved = json::array();
  for (const char* c : {"b1", "b2", "c1"})
    if (o.material && !Observed(*o.material, c)) unobserved.push_back(c);
  j["unobserved"] = unobserved;
  j["validation"] = o.validation;
  return j;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The direction's law: each constant the mean over the specimens that determined it; one that
// none determined takes the median of the fits, and a note in *notes says so.
BendingLaw MeanLaw(const std::vector<const SpecimenOutcome*>& fitted, StripDirection d,
                   json* notes) {
  double k[3];
  for (int i = 0; i < 3; ++i) {
    const Quantity& q = Quantities()[static_cast<size_t>(i)];
    size_t unobserved = 0;
    const std::vector<double> v = ObservedValues(fitted, q, &unobserved);
    if (!v.empty()) {
      k[i] = Stats(v).mean;
      continue;
    }
    std::vector<double> all;
    for (const SpecimenOutcome* o : fitted) all.push_back(*q.value(*o->material));
    k[i] = Median(all);
    if (notes)
      notes->push_back(std::string(q.name) + " (" + DirectionName(d) +
                       "): no specimen's curvatures determine it; the median of the fits is "
                       "used, which the data do not pin down");
  }
  return BendingLaw::FromKes(k[0], k[1], k[2]);
}

std::string CsvCell(const json& v) {
  if (v.is_null()) return "";
  if (v.is_number_unsigned()) return std::to_string(v.get<size_t>());
  if (v.is_number()) return NumberText(v.get<double>(), 10);
  return v.get<std::string>();
}

}  // namespace

SeriesStats Stats(const std::vector<double>& values) {
  SeriesStats s;
  s.n = values.size();
  if (s.n == 0) return s;
  for (double v : values) s.mean += v;
  s.mean /= static_cast<double>(s.n);
  if (s.n < 2) return s;
  double ss = 0.0;
  for (double v : values) ss += (v - s.mean) * (v - s.mean);
  s.sd = std::sqrt(ss / static_cast<double>(s.n - 1));
  if (s.mean != 0.0) s.cv = *s.sd / std::abs(s.mean);
  return s;
}

std::optional<Material> FabricMaterial(const std::string& fabric,
                                       const std::vector<SpecimenOutcome>& specimens,
                                       std::string* why) {
  std::map<StripDirection, std::vector<const SpecimenOutcome*>> by;
  double gsm = 0.0, gsm_min = 1e300, gsm_max = 0.0;
  size_t n = 0;
  for (StripDirection d : kDirections) {
    by[d] = Fitted(specimens, fabric, d);
    for (const SpecimenOutcome* o : by[d]) {
      gsm += o->row->gsm;
      gsm_min = std::min(gsm_min, o->row->gsm);
      gsm_max = std::max(gsm_max, o->row->gsm);
      ++n;
    }
  }
  if (n == 0) {
    if (why) *why = "no specimen of it was fitted";
    return std::nullopt;
  }
  const bool warp = !by[StripDirection::kWarp].empty(), weft = !by[StripDirection::kWeft].empty();
  const StripDirection main = warp   ? StripDirection::kWarp
                              : weft ? StripDirection::kWeft
                                     : StripDirection::kBias;
  json notes = json::array();
  std::map<StripDirection, BendingLaw> mean;  // one a measured direction, its notes once
  for (StripDirection d : kDirections)
    if (!by[d].empty()) mean.emplace(d, MeanLaw(by[d], d, &notes));
  Material m = LawOnlyMaterial(mean.at(main), units::GsmToSi(gsm / static_cast<double>(n)));
  m.name = fabric;
  if (warp && weft) m.bending_weft = mean.at(StripDirection::kWeft);
  if (mean.contains(StripDirection::kBias) && main != StripDirection::kBias)
    m.bending_bias = mean.at(StripDirection::kBias);
  if (gsm_max > 1.01 * gsm_min)
    notes.push_back("the specimens' gsm range " + NumberText(gsm_min) + " .. " +
                    NumberText(gsm_max) + " g/m²: the material takes their mean");
  if (main == StripDirection::kBias)
    notes.push_back("only the bias direction was fitted: the material takes its law for every "
                    "direction");
  else if (!(warp && weft))
    notes.push_back(std::string("of warp and weft only the ") + DirectionName(main) +
                    " direction was fitted: the material takes its law for both");
  if (m.bending_bias)
    notes.push_back(
        "bending_bias is the bias mean: the drape blends it with warp and weft by angle "
        "(docs/methods/materials.md, \"Warp, weft and bias\") and the exports carry it");
  json directions = json::object();
  for (StripDirection d : kDirections) {
    if (by[d].empty()) continue;
    json names = json::array();
    for (const SpecimenOutcome* o : by[d]) names.push_back(o->row->specimen);
    directions[DirectionName(d)] = {{"n", by[d].size()},
                                    {"specimens", names},
                                    {"law_kes", LawToJson(mean.at(d), false)}};
  }
  m.fit = {{"method", "batch mean"}, {"directions", directions}};
  if (!notes.empty()) m.extra["notes"] = notes;
  if (std::string problem; !m.Check(&problem)) {
    if (why)
      *why = "the direction means make no valid law (" + problem +
             "): the specimens disagree too much to average; see each specimen's fit";
    return std::nullopt;
  }
  return m;
}

json SummaryJson(const std::vector<SpecimenOutcome>& specimens) {
  json directions = json::array(), fabrics = json::array(), list = json::array();
  for (const std::string& fabric : Fabrics(specimens)) {
    for (StripDirection d : kDirections) {
      bool listed = false;
      for (const SpecimenOutcome& o : specimens) listed |= o.row->fabric == fabric && o.row->direction == d;
      if (listed) directions.push_back(DirectionJson(specimens, fabric, d));
    }
    std::string why;
    const std::optional<Material> m = FabricMaterial(fabric, specimens, &why);
    fabrics.push_back({{"fabric", fabric},
                       {"material_note", m ? json() : json(why)},
                       {"overall_rigidity_uNm",
                        OverallRigidity(directions, fabric, "flexural_rigidity_uNm")},
                       {"overall_rigidity_mgcm",
                        OverallRigidity(directions, fabric, "flexural_rigidity_mgcm")},
                       {"material", m ? MaterialToJson(*m) : json()}});
  }
  for (const SpecimenOutcome& o : specimens) list.push_back(SpecimenJson(o));
  return {{"directions", directions}, {"fabrics", fabrics}, {"specimens", list}};
}

std::string SummaryCsv(const json& summary) {
  std::ostringstream out;
  out << "fabric,direction,n,n_failed";
  for (const Quantity& q : Quantities())
    out << ',' << q.name << "_mean_" << q.unit << ',' << q.name << "_sd_" << q.unit
        << (q.another_unit ? "" : std::string(",") + q.name + "_cv," + q.name + "_n");
  out << ",overall_rigidity_uNm,overall_rigidity_mgcm\n";
  for (const json& d : summary["directions"]) {
    out << CsvCell(d["fabric"]) << ',' << CsvCell(d["direction"]) << ',' << CsvCell(d["n"])
        << ',' << CsvCell(d["n_failed"]);
    for (const Quantity& q : Quantities()) {
      const json& s = d[Key(q)];
      out << ',' << CsvCell(s["mean"]) << ',' << CsvCell(s["sd"]);
      if (!q.another_unit) out << ',' << CsvCell(s["cv"]) << ',' << CsvCell(s["n"]);
    }
    for (const json& f : summary["fabrics"]) {
      if (f["fabric"] != d["fabric"]) continue;
      out << ',' << CsvCell(f["overall_rigidity_uNm"]) << ','
          << CsvCell(f["overall_rigidity_mgcm"]);
    }
    out << '\n';
  }
  return out.str();
}

}  // namespace textile
