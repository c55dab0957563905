#include "textile/sim/scenes/drape_what_if.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "textile/sim/core/content_hash.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/core/units.h"
#include "textile/sim/law/material_parameters.h"
#include "textile/sim/law/seam.h"

namespace textile {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kEntrySuffix = ".drape-cache.json";
constexpr int kEntryVersion = 2;  // 2: the scene's notes, every solver option in the key
// SC §4's weight 1/(|d − d_m|² + ε²), in relative parameter changes: ε = 0.1 %.
constexpr double kWeightEpsilon2 = 1e-6;

// The law constants' prefix of a parameter name ("", "bending_weft.", "bending_bias."), or none.
std::optional<std::string> LawPrefix(const std::string& name) {
  const size_t dot = name.rfind('.');
  const std::string constant = dot == std::string::npos ? name : name.substr(dot + 1);
  if (constant != "b1" && constant != "b2" && constant != "c1") return std::nullopt;
  const std::string prefix = dot == std::string::npos ? "" : name.substr(0, dot + 1);
  if (!prefix.empty() && prefix != "bending_weft." && prefix != "bending_bias.") return std::nullopt;
  return prefix;
}

// 0, 1, 2 for a name ending in b1, b2, c1.
int ConstantIndex(const std::string& name) {
  return name.ends_with("b1") ? 0 : name.ends_with("b2") ? 1 : 2;
}

std::optional<BendingLaw>* LawOf(Material* m, const std::string& prefix) {
  return prefix == "bending_weft." ? &m->bending_weft : prefix == "bending_bias." ? &m->bending_bias : nullptr;
}

// The material with `names` set to `values` [SI]: each law's constants together (a law that is
// valid at both ends may not be with one constant moved), the others one by one
// (WithMaterialParameter, which also clears their defaulted and given forms). Throws
// InputError when the values make no valid material.
Material WithParameterValues(const Material& material, const std::vector<std::string>& names,
                             const std::vector<double>& values) {
  Material m = material;
  for (const std::string prefix : {"", "bending_weft.", "bending_bias."}) {
    std::vector<size_t> named;  // the names of this law's constants
    for (size_t i = 0; i < names.size(); ++i)
      if (const std::optional<std::string> p = LawPrefix(names[i]); p && *p == prefix)
        named.push_back(i);
    if (named.empty()) continue;
    if (!prefix.empty() && !LawOf(&m, prefix)->has_value())
      throw InputError("'" + names[named.front()] + "' is not a parameter of this material (it has no " +
                       prefix.substr(0, prefix.size() - 1) + " law)");
    const BendingLaw law = prefix.empty() ? m.bending : **LawOf(&m, prefix);
    if (law.is_spline())
      throw InputError("'" + names[named.front()] + "' is not a parameter of this material (a spline law)");
    double k[3] = {law.b1(), law.b2(), law.c1()};
    bool b1_named = false;
    for (size_t i : named) {
      k[ConstantIndex(names[i])] = values[i];
      b1_named = b1_named || names[i] == prefix + "b1";
    }
    if (law.kappa0() == 0.0 && !b1_named) k[0] = k[1];  // M = b2 κ: b2 is the line's slope
    if (const std::string why = BendingLaw::Invalidity(k[0], k[1], k[2]); !why.empty())
      throw InputError(why);
    if (prefix.empty())
      m.bending = BendingLaw::FromSi(k[0], k[1], k[2]);
    else
      *LawOf(&m, prefix) = BendingLaw::FromSi(k[0], k[1], k[2]);
  }
  for (size_t i = 0; i < names.size(); ++i)
    if (!LawPrefix(names[i])) m = WithMaterialParameter(m, names[i], values[i]);
  for (const std::string& name : names) std::erase(m.defaulted, name);
  if (std::string why; !m.Check(&why)) throw InputError(why);
  return m;
}

// What of a material must match for an entry to answer: its file form with the parameters set
// through WithParameterValues, without the name and the fit (which move no drape).
json MaterialForm(const Material& m) {
  json j = MaterialToJson(m);
  j.erase("name");
  j.erase("fit");
  return j;
}

// The two forms agree: the same keys and strings, numbers to 1e-9 relative (a tensile curve
// scaled there and back is the same curve to round-off).
bool SameForm(const json& a, const json& b) {
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    return std::abs(x - y) <= 1e-9 * std::max(std::abs(x), std::abs(y));
  }
  if (a.type() != b.type() || a.size() != b.size()) return false;
  if (a.is_object()) {
    for (auto it = a.begin(); it != a.end(); ++it)
      if (!b.contains(it.key()) || !SameForm(it.value(), b[it.key()])) return false;
    return true;
  }
  if (a.is_array()) {
    for (size_t i = 0; i < a.size(); ++i)
      if (!SameForm(a[i], b[i])) return false;
    return true;
  }
  return a == b;
}

json EntryJson(const DrapeCacheEntry& e) {
  json parameters = json::array();
  for (const DrapeCacheEntry::Parameter& p : e.parameters)
    parameters.push_back(
        {{"name", p.name}, {"value_si", p.value}, {"scale_si", p.scale}, {"d_dc_d_p", p.d_dc_d_p}});
  json notes = json::array();
  for (const Note& n : e.notes) notes.push_back({{"code", n.code}, {"text", n.text}});
  return {{"textile_drape_cache", kEntryVersion}, {"scene_key", e.scene_key},
          {"material", e.material},               {"parameters", parameters},
          {"drape_coefficient", e.drape_coefficient}, {"nodes", e.nodes},
          {"notes", notes}};
}

DrapeCacheEntry EntryFromJson(const json& j, const std::string& path) {
  const auto bad = [&path](const std::string& why) {
    return InputError(path + ": not a drape cache entry (" + why + ")");
  };
  if (!j.is_object() || !j.contains("textile_drape_cache")) throw bad("no textile_drape_cache");
  if (j["textile_drape_cache"] != kEntryVersion)
    throw bad("version " + j["textile_drape_cache"].dump() + ", this textile reads " +
              std::to_string(kEntryVersion));
  try {
    DrapeCacheEntry e;
    e.scene_key = j.at("scene_key").get<std::string>();
    e.material = j.at("material");
    for (const json& p : j.at("parameters"))
      e.parameters.push_back({p.at("name").get<std::string>(), p.at("value_si").get<double>(),
                              p.at("scale_si").get<double>(), p.at("d_dc_d_p").get<double>()});
    e.drape_coefficient = j.at("drape_coefficient").get<double>();
    e.nodes = j.at("nodes").get<double>();
    for (const json& n : j.value("notes", json::array()))
      e.notes.push_back({n.at("code").get<std::string>(), n.at("text").get<std::string>()});
    for (const DrapeCacheEntry::Parameter& p : e.parameters)
      if (!std::isfinite(p.value) || !(p.scale > 0.0) || !std::isfinite(p.d_dc_d_p))
        throw bad(p.name + ": a value, scale or derivative that is not a finite number");
    return e;
  } catch (const json::exception& x) {
    throw bad(x.what());
  }
}

// A value in the material file's unit, in SI.
double LabToSi(const std::string& unit, double lab) {
  if (unit == "gf·cm") return units::KesStiffnessToSi(lab);
  if (unit == "gf·cm²") return units::KesQuadraticToSi(lab);
  if (unit == "g/m²") return units::GsmToSi(lab);
  return lab;  // N/m, N/m/rad, -
}

// One cached drape's view of the target: where the target lies from it, relative to each
// parameter's scale, and the entry's DC and gradient in those units.
struct EntryView {
  Eigen::VectorXd offset;    // d_e − d: the entry's relative position from the target
  Eigen::VectorXd gradient;  // ∂DC/∂d [per relative change]
  double dc = 0.0;
  double distance = 0.0;     // max |offset|
  std::vector<Note> notes;   // the cached drape's scene notes
};

// The entry's view of `target`, over the target's parameters (`names`, in their order): none
// unless the entry has exactly these parameters and the same material form.
std::optional<EntryView> ViewFrom(const DrapeCacheEntry& e, const Material& target,
                                  const std::vector<std::string>& names) {
  if (e.parameters.size() != names.size()) return std::nullopt;
  std::vector<const DrapeCacheEntry::Parameter*> by_name;
  for (const std::string& name : names) {
    const auto p = std::find_if(e.parameters.begin(), e.parameters.end(),
                                [&](const DrapeCacheEntry::Parameter& q) { return q.name == name; });
    if (p == e.parameters.end()) return std::nullopt;
    by_name.push_back(&*p);
  }
  std::vector<double> values;
  for (const DrapeCacheEntry::Parameter* p : by_name) values.push_back(p->value);
  try {
    if (!SameForm(e.material, MaterialForm(WithParameterValues(target, names, values))))
      return std::nullopt;
  } catch (const InputError&) {
    return std::nullopt;  // the entry's values make no valid material of the target's form
  }
  EntryView v;
  const long n = static_cast<long>(names.size());
  v.offset.resize(n);
  v.gradient.resize(n);
  for (long k = 0; k < n; ++k) {
    const DrapeCacheEntry::Parameter& p = *by_name[static_cast<size_t>(k)];
    const double scale = MaterialParameterScale(target, p.name);
    v.offset(k) = (p.value - GetMaterialParameter(target, p.name).si) / scale;
    v.gradient(k) = p.d_dc_d_p * scale;
  }
  v.dc = e.drape_coefficient;
  v.distance = n ? v.offset.cwiseAbs().maxCoeff() : 0.0;
  v.notes = e.notes;
  return v;
}

// SC §4's GMLS with the linear basis p(d) = (1, d): the coefficients a minimise
// Σ w_m (a·p(d_m) − DC_m)² + Σ w_m Σ_j (a·∂p/∂d_j − s_j^m)², w_m = 1/(|d_m − d|² + ε²), d the
// target (0 here); the prediction is a·p(0) = a_0.
double Gmls(const std::vector<EntryView>& views) {
  const long n = views.front().offset.size() + 1;
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  for (const EntryView& v : views) {
    const double w = 1.0 / (v.offset.squaredNorm() + kWeightEpsilon2);
    Eigen::VectorXd p(n);
    p << 1.0, v.offset;
    g += w * p * p.transpose();
    rhs += w * v.dc * p;
    for (long j = 1; j < n; ++j) {  // ∂p/∂d_j = e_j
      g(j, j) += w;
      rhs(j) += w * v.gradient(j - 1);
    }
  }
  return g.ldlt().solve(rhs)(0);
}

// The error estimate of a prediction `dc` (docs/methods/sensitivity.md, "What-if"), the largest
// of: the entries' disagreement at the target (their first-order values against dc); from the
// nearest entry, the second-order term ½ Σ |∂DC/∂d_k| d_k² and half its first-order change
// (the what-if bench: the DC curved by up to that much within ±10 %); and, for any change at
// all, the DC's jitter between neighbouring solves (kJitter).
constexpr double kJitter = 0.002;
double ErrorEstimate(const EntryView& nearest, const std::vector<EntryView>& views, double dc) {
  double spread = 0.0;
  for (const EntryView& v : views)
    spread = std::max(spread, std::abs(v.dc - v.gradient.dot(v.offset) - dc));
  double second_order = 0.0;
  for (long k = 0; k < nearest.offset.size(); ++k)
    second_order += 0.5 * std::abs(nearest.gradient(k)) * nearest.offset(k) * nearest.offset(k);
  const double half_change = 0.5 * std::abs(nearest.gradient.dot(nearest.offset));
  const double jitter = nearest.distance > 0.0 ? kJitter : 0.0;
  return std::max({spread, second_order, half_change, jitter});
}

// One note for the cache files that are no entry: how many, and the first one's reason.
Note SkippedNote(const std::vector<std::string>& skipped) {
  return {"cache_entry_skipped",
          std::to_string(skipped.size()) + " cache file" + (skipped.size() > 1 ? "s were" : " was") +
              " not used (" + skipped.front() + (skipped.size() > 1 ? "; ..." : "") + ")"};
}

}  // namespace

json DrapeSceneJson(const DrapeOptions& o) {
  // Each field that shapes the DC. A field added to DrapeOptions must be added here or to the
  // list of those that do not (progress, sensitivity, Monte Carlo; the solver's time cap and
  // verbosity): the size check, on the 64-bit libstdc++ the project builds with, says so.
#if defined(__GLIBCXX__) && defined(__LP64__)
  static_assert(sizeof(DrapeOptions) == 640, "DrapeOptions changed: update DrapeSceneJson");
  static_assert(sizeof(SolveOptions) == 112, "SolveOptions changed: update DrapeSceneJson");
#endif
  const SolveOptions& v = o.solver;
  const json solver = {{"method", SolverMethodName(v.method)},
                       {"linear", static_cast<int>(v.linear)},
                       {"projection", static_cast<int>(v.projection)},
                       {"exact_below", v.exact_below},
                       {"expand_steps", v.expand_steps},
                       {"tolerance", v.tolerance},
                       {"max_iterations", v.max_iterations},
                       {"max_step", v.max_step},
                       {"time_step", v.time_step},
                       {"cg_tolerance", v.cg_tolerance},
                       {"cg_max_iterations", v.cg_max_iterations},
                       {"anchor_tolerance", v.anchor_tolerance},
                       {"fall_limit", v.fall_limit}};
  return {{"specimen_radius", o.specimen_radius},
          {"support_radius", o.support_radius},
          {"mount", DrapeMountName(o.mount)},
          {"support_thickness", o.support_thickness},
          {"rim_rounding", o.rim_rounding},
          {"drop_height", o.drop_height},
          {"contact_sink", o.contact_sink},
          {"seeds", o.seeds},
          {"first_seed", o.first_seed},
          {"perturbation", o.perturbation},
          {"start_droop", o.start_droop},
          {"harmonics", {o.min_harmonic, o.max_harmonic}},
          {"frame_angle", o.frame_angle},
          {"element_size", o.element_size},
          {"rim_element_size", o.rim_element_size},
          {"rim_band", o.rim_band},
          {"rim_extrapolation", o.rim_extrapolation},
          {"coarse_to_fine", o.coarse_to_fine},
          {"coarse_factor", o.coarse_factor},
          {"circle_segments", o.circle_segments},
          {"seams", DrapeSeamsName(o.seams)},
          {"seam_profile", o.seams == DrapeSeams::kNone ? json() : SeamProfileToJson(o.seam_profile)},
          {"seam_shift", o.seam_shift},
          {"seam_refinement_range", o.seam_refinement_range},
          {"solver", solver},
          {"raster_cell", o.raster_cell},
          {"outline_bins", o.outline_bins},
          {"smoothing_bins", o.smoothing_bins},
          {"node_prominence", o.node_prominence},
          {"node_prominence_relative", o.node_prominence_relative}};
}

std::string DrapeSceneKey(const DrapeOptions& options) {
  return HashContent(DrapeSceneJson(options).dump()).Hex();
}

DrapeCacheEntry MakeDrapeCacheEntry(const Material& material, const DrapeOptions& options,
                                    const DrapeResult& result) {
  if (!result.converged) throw InputError("drape cache: the drape did not converge");
  if (result.sensitivities.empty())
    throw InputError("drape cache: the drape has no sensitivities (run it with them)");
  DrapeCacheEntry e;
  e.scene_key = DrapeSceneKey(options);
  std::vector<std::string> names;
  std::vector<double> values;
  for (const std::string& name : MaterialParameterNames(material)) {
    const auto row = std::find_if(result.sensitivities.begin(), result.sensitivities.end(),
                                  [&](const ParameterInfluence& s) { return s.parameter == name; });
    if (row == result.sensitivities.end())
      throw InputError("drape cache: the drape has no sensitivity for " + name +
                       " (a cached drape needs every parameter's)");
    const double value = GetMaterialParameter(material, name).si;
    e.parameters.push_back({name, value, MaterialParameterScale(material, name), row->d_q_d_p});
    names.push_back(name);
    values.push_back(value);
  }
  e.material = MaterialForm(WithParameterValues(material, names, values));
  e.drape_coefficient = result.drape_coefficient;
  e.nodes = result.nodes;
  for (const DrapeCacheEntry::Parameter& p : e.parameters)
    if (!std::isfinite(p.d_dc_d_p))
      throw ComputeError("drape cache: the DC's derivative in " + p.name + " is not a number");
  if (!std::isfinite(e.drape_coefficient)) throw ComputeError("drape cache: the DC is not a number");
  // The scene's notes (a coarse rim, a bare support ...); the material's own defaults are the
  // predicted material's to say.
  for (const Note& n : result.notes)
    if (n.code != "membrane_default") e.notes.push_back(n);
  return e;
}

void WriteDrapeCacheEntry(const std::string& dir, const DrapeCacheEntry& entry) {
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) throw InputError("--cache " + dir + ": cannot create the folder: " + error.message());
  const json j = EntryJson(entry);
  std::string identity = entry.scene_key + entry.material.dump();
  for (const DrapeCacheEntry::Parameter& p : entry.parameters) identity += NumberText(p.value, 17);
  const fs::path path = fs::path(dir) / (HashContent(identity).Hex() + kEntrySuffix);
  const fs::path temporary = path.string() + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(temporary);
    out << j.dump(1) << "\n";
    out.close();
    if (out.fail()) {
      fs::remove(temporary, error);
      throw InputError("--cache " + dir + ": cannot write " + temporary.string());
    }
  }
  fs::rename(temporary, path, error);
  if (error) {
    fs::remove(temporary, error);
    throw InputError("--cache " + dir + ": cannot write " + path.string());
  }
}

std::vector<DrapeCacheEntry> ReadDrapeCache(const std::string& dir, const DrapeOptions& options,
                                            std::vector<std::string>* skipped) {
  std::vector<DrapeCacheEntry> entries;
  std::error_code error;
  if (!fs::exists(dir, error)) return entries;
  if (!fs::is_directory(dir, error)) throw InputError("--cache " + dir + ": not a folder");
  const std::string key = DrapeSceneKey(options);
  std::vector<fs::path> files;
  for (const fs::directory_entry& f : fs::directory_iterator(dir, error)) {
    const std::string name = f.path().filename().string();
    if (name.size() > std::string(kEntrySuffix).size() && name.ends_with(kEntrySuffix))
      files.push_back(f.path());
  }
  std::sort(files.begin(), files.end());  // the same order on every file system
  for (const fs::path& path : files) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    try {
      json j;
      try {
        j = json::parse(text.str());
      } catch (const json::exception&) {
        throw InputError(path.string() + ": not a drape cache entry (not JSON)");
      }
      DrapeCacheEntry e = EntryFromJson(j, path.string());
      if (e.scene_key == key) entries.push_back(std::move(e));
    } catch (const InputError& e) {
      if (skipped) skipped->push_back(e.what());  // another version, a broken file: not used
    }
  }
  return entries;
}

// A decimal number as a person types it: digits, a point, a sign, an exponent; no spaces, no
// hexadecimal, nothing after it.
std::optional<double> ParseDecimal(const std::string& text) {
  if (text.empty() || text.find_first_not_of("0123456789+-.eE") != std::string::npos) return std::nullopt;
  size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

Material ApplyWhatIfEdits(const Material& material, const std::string& edits) {
  if (edits.empty()) throw InputError("--what-if: no edits (NAME=VALUE,...)");
  std::vector<std::string> names;
  std::vector<double> values;  // [SI]
  std::string shown;           // the edits in lab units, for messages
  for (size_t from = 0; from <= edits.size();) {
    const size_t comma = std::min(edits.find(',', from), edits.size());
    const std::string edit = edits.substr(from, comma - from);
    from = comma + 1;
    const size_t eq = edit.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == edit.size())
      throw InputError("--what-if: '" + edit + "' is not NAME=VALUE");
    const std::string name = edit.substr(0, eq), text = edit.substr(eq + 1);
    if (std::find(names.begin(), names.end(), name) != names.end())
      throw InputError("--what-if: " + name + " given twice");
    MaterialParameterValue old;
    try {
      old = GetMaterialParameter(material, name);
    } catch (const InputError& e) {
      throw InputError(std::string("--what-if: ") + e.what());
    }
    const std::optional<double> lab = ParseDecimal(text);
    if (!lab) throw InputError("--what-if: " + name + " = '" + text + "' is not a number");
    names.push_back(name);
    values.push_back(LabToSi(old.unit, *lab));
    shown += (shown.empty() ? "" : ", ") + name + " = " + text + " " + old.unit;
  }
  Material edited;
  try {
    edited = WithParameterValues(material, names, values);  // a law's constants together
  } catch (const InputError& e) {
    throw InputError("--what-if: " + shown + " is outside the material's valid range: " + e.what());
  }
  // An edit that moves nothing in the edited law (b2 of a law left with c1 = 0) is refused: the
  // material would carry a value no drape sees.
  for (const std::string& name : names)
    if (const std::string why = ParameterWithoutEffect(edited, name); !why.empty())
      throw InputError("--what-if: " + why);
  return edited;
}

DrapeWhatIf PredictDrape(const Material& material, const std::vector<DrapeCacheEntry>& cache,
                         const WhatIfOptions& options) {
  DrapeWhatIf w;
  std::vector<EntryView> views;
  const EntryView* nearest = nullptr;
  const std::vector<std::string> names = MaterialParameterNames(material);
  for (const DrapeCacheEntry& e : cache) {
    std::optional<EntryView> v = ViewFrom(e, material, names);
    if (!v) continue;
    ++w.entries_matching;
    if (std::isnan(w.distance) || v->distance < w.distance) w.distance = v->distance;
    if (v->distance <= options.reach) views.push_back(std::move(*v));
  }
  if (views.empty()) {
    w.reason = w.entries_matching == 0
                   ? "no cached drape of this scene and material form"
                   : "the nearest of " + std::to_string(w.entries_matching) +
                         " cached drapes is " + NumberText(100.0 * w.distance, 3) +
                         " % away in a parameter, beyond the reach of " +
                         NumberText(100.0 * options.reach, 3) + " %";
    return w;
  }
  for (const EntryView& v : views)
    if (!nearest || v.distance < nearest->distance) nearest = &v;
  w.notes = nearest->notes;
  w.entries_used = static_cast<int>(views.size());
  w.drape_coefficient = Gmls(views);
  w.error_estimate = ErrorEstimate(*nearest, views, w.drape_coefficient);
  const std::string how = "from " + std::to_string(w.entries_used) + " cached drape" +
                          (w.entries_used > 1 ? "s" : "") + ", the nearest " +
                          NumberText(100.0 * nearest->distance, 3) + " % away";
  if (w.error_estimate > options.max_error) {
    w.notes.clear();  // the scene's notes are the solve's to give
    w.reason = "the estimated error " + NumberText(w.error_estimate, 2) + " (" + how +
               ") is above " + NumberText(options.max_error, 2);
    w.drape_coefficient = std::numeric_limits<double>::quiet_NaN();
    return w;
  }
  w.predicted = true;
  w.reason = "predicted " + how;
  return w;
}

json DrapeWhatIfJson(const DrapeWhatIf& w) {
  const auto number = [](double v) { return std::isfinite(v) ? json(v) : json(); };
  return {{"predicted", w.predicted},
          {"drape_coefficient", number(w.drape_coefficient)},
          {"error_estimate", number(w.error_estimate)},
          {"entries_used", w.entries_used},
          {"entries_matching", w.entries_matching},
          {"distance_percent", number(100.0 * w.distance)},
          {"reason", w.reason}};
}

DrapeWhatIfPrediction PredictDrapeWhatIf(const Material& material, const std::string& edits,
                                         const DrapeOptions& options, const std::string& cache_dir,
                                         const WhatIfOptions& what_if) {
  const auto start = std::chrono::steady_clock::now();
  if (!(what_if.reach > 0.0 && what_if.reach <= 1.0))
    throw InputError("what-if reach: must be in (0, 100] %, got " + NumberText(100.0 * what_if.reach) + " %");
  if (!(what_if.max_error > 0.0 && what_if.max_error < 1.0))
    throw InputError("what-if max error: must be in (0, 1), got " + NumberText(what_if.max_error));
  DrapeWhatIfPrediction p;
  p.material = ApplyWhatIfEdits(material, edits);
  std::vector<std::string> skipped;
  p.what_if = PredictDrape(p.material, ReadDrapeCache(cache_dir, options, &skipped), what_if);
  if (!skipped.empty()) p.what_if.notes.push_back(SkippedNote(skipped));
  if (p.what_if.predicted)
    for (Note& n : MaterialDefaultNotes(p.material)) p.what_if.notes.push_back(std::move(n));
  p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return p;
}

DrapeResult SimulateDrapeCached(const Material& material, const DrapeOptions& options,
                                const std::string& cache_dir) {
  if (!options.sensitivity_parameters.empty())
    throw InputError("--cache: a cached drape needs every parameter's sensitivity (leave out "
                     "--sensitivity-params)");
  if (options.mount != DrapeMount::kClamped)
    throw InputError("--cache: clamped mount only (a cached drape carries sensitivities, which "
                     "the resting mount has not)");
  std::vector<std::string> skipped;
  ReadDrapeCache(cache_dir, options, &skipped);  // a folder that is none: before the solve
  DrapeOptions o = options;
  // The cache keeps the material's derivatives: without --sensitivity, named so that the run
  // spends nothing on the scene's (TakesSceneParameters).
  if (!o.sensitivity) o.sensitivity_parameters = MaterialParameterNames(material);
  o.sensitivity = true;
  DrapeResult r = SimulateDrape(material, o);
  if (!skipped.empty()) r.notes.push_back(SkippedNote(skipped));
  if (!r.converged) return r;
  try {
    WriteDrapeCacheEntry(cache_dir, MakeDrapeCacheEntry(material, o, r));
  } catch (const ComputeError& e) {  // a derivative that is not a number: the DC stands
    r.notes.push_back({"not_cached", std::string("the drape was not cached: ") + e.what()});
  }
  return r;
}

}  // namespace textile
