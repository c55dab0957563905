#ifndef TEXTILE_SIM_SCENES_DRAPE_WHAT_IF_H_
#define TEXTILE_SIM_SCENES_DRAPE_WHAT_IF_H_

// What-if drapes (Sensitive Couture §4, "Progressive nonlinear modeling", adapted to material edits; docs/methods/sensitivity.md,
// "What-if"): a drape solved with its sensitivities is kept in a cache folder, and the DC of a
// material near a cached one is predicted from the cached DCs and derivatives in microseconds
// instead of solved in seconds.
//
//   textile::SimulateDrapeCached(material, options, "cache/");   // solved once, with sensitivities
//   const textile::DrapeWhatIfPrediction p = textile::PredictDrapeWhatIf(
//       material, "b1=0.11,stretch.warp=3300", options, "cache/", {});
//   if (p.what_if.predicted) std::cout << p.what_if.drape_coefficient << " ± "
//                                      << p.what_if.error_estimate;
//   else textile::SimulateDrapeCached(p.material, options, "cache/");  // too far: solve

#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "textile/sim/core/note.h"
#include "textile/sim/law/material.h"
#include "textile/sim/scenes/drape.h"

namespace textile {

// The scene of a drape as far as it shapes the DC (the options without progress,
// sensitivities and Monte Carlo), and its 32-digit fingerprint: cached drapes of another scene
// are not used.
nlohmann::json DrapeSceneJson(const DrapeOptions& options);
std::string DrapeSceneKey(const DrapeOptions& options);

// A solved drape as the cache keeps it.
struct DrapeCacheEntry {
  std::string scene_key;
  // MaterialToJson of the material with its parameters set through WithMaterialParameter (so
  // in the form any edit of them takes), without name and fit: what must match, the
  // parameters' values aside.
  nlohmann::json material;
  struct Parameter {
    std::string name;
    double value = 0.0;  // [SI]
    double scale = 0.0;  // MaterialParameterScale [SI]: the unit of a relative change
    double d_dc_d_p = 0.0;
  };
  std::vector<Parameter> parameters;
  double drape_coefficient = 0.0;
  double nodes = 0.0;
  std::vector<Note> notes;  // the drape's notes on its scene (the membrane defaults left out)
};

// The entry of a converged drape run with sensitivities (every parameter it differentiated).
// InputError when the result has no sensitivities or did not converge, ComputeError when a
// derivative is not a number.
DrapeCacheEntry MakeDrapeCacheEntry(const Material& material, const DrapeOptions& options,
                                    const DrapeResult& result);
// Writes the entry into `dir` (created if missing) as <hash>.drape-cache.json, atomically; the
// same material and scene overwrite their entry. InputError when the folder cannot be written.
void WriteDrapeCacheEntry(const std::string& dir, const DrapeCacheEntry& entry);
// The entries of `dir` for this scene (none when the folder does not exist; InputError when it
// is not a folder). A file that is no entry of this version is left out, its reason in
// *skipped when given.
std::vector<DrapeCacheEntry> ReadDrapeCache(const std::string& dir, const DrapeOptions& options,
                                            std::vector<std::string>* skipped = nullptr);

// The material with edits "NAME=VALUE,NAME=VALUE", names as the material file spells them
// (MaterialParameterNames) and values in the file's units (gf·cm, gf·cm², g/m², N/m, N/m/rad,
// -), applied together (a law's constants at once). InputError for a malformed edit, an
// unknown name, a name given twice, a value that leaves the material's valid range, or one
// that moves nothing in the edited law (ParameterWithoutEffect).
Material ApplyWhatIfEdits(const Material& material, const std::string& edits);

struct WhatIfOptions {
  // An entry can answer when no parameter differs from it by more than this relative change
  // (|Δp| / MaterialParameterScale).
  double reach = 0.1;
  // A prediction whose error estimate is larger is not made: the drape is solved.
  double max_error = 0.01;
};

struct DrapeWhatIf {
  bool predicted = false;  // false: no cached drape could answer (reason), solve instead
  double drape_coefficient = std::numeric_limits<double>::quiet_NaN();
  double error_estimate = std::numeric_limits<double>::quiet_NaN();
  int entries_used = 0;    // cached drapes within reach, blended
  int entries_matching = 0;  // cached drapes of this scene and material form
  // The nearest matching entry's largest relative parameter change (NaN without one).
  double distance = std::numeric_limits<double>::quiet_NaN();
  std::string reason;  // how it was predicted, or why not
  // When predicted: the nearest cached drape's scene notes, and (PredictDrapeWhatIf) the edited
  // material's membrane defaults; cache files left out.
  std::vector<Note> notes;
};

// The DC of `material` from the cached drapes of its scene (docs/methods/sensitivity.md,
// "What-if"): Sensitive Couture's GMLS (§4) with the linear basis (1, d) over the entries
// within reach, d each parameter's relative change; one entry gives its first-order Taylor
// value DC_e + Σ ∂DC/∂p (p − p_e). The error estimate is the largest of the entries'
// disagreement, the nearest entry's second-order term ½ Σ |∂DC/∂ln p| (Δ ln p)², half its
// first-order change, and 0.002 (the DC's jitter between neighbouring solves): measured by
// `textile bench what-if`, not a bound. A change of the node count is not foreseen.
DrapeWhatIf PredictDrape(const Material& material, const std::vector<DrapeCacheEntry>& cache,
                         const WhatIfOptions& options);

// The what-if's JSON: {predicted, drape_coefficient, error_estimate, entries_used,
// entries_matching, distance_percent, reason} (NaN as null).
nlohmann::json DrapeWhatIfJson(const DrapeWhatIf& what_if);

// `textile drape --what-if EDITS --cache DIR`, first step: the edited material
// (ApplyWhatIfEdits) and its prediction from the cached drapes of the scene (PredictDrape).
// When what_if.predicted is false, SimulateDrapeCached(material, ...) solves it.
struct DrapeWhatIfPrediction {
  Material material;
  DrapeWhatIf what_if;
  double seconds = 0.0;  // reading the cache included
};
DrapeWhatIfPrediction PredictDrapeWhatIf(const Material& material, const std::string& edits,
                                         const DrapeOptions& options, const std::string& cache_dir,
                                         const WhatIfOptions& what_if);

// `textile drape --cache DIR`: the drape with every parameter's sensitivity
// (options.sensitivity_parameters must be empty and the mount clamped: InputError), added to
// the cache when it
// converged (with a note instead when a derivative is not a number; another note names cache
// files that are no entry).
DrapeResult SimulateDrapeCached(const Material& material, const DrapeOptions& options,
                                const std::string& cache_dir);

}  // namespace textile

#endif  // TEXTILE_SIM_SCENES_DRAPE_WHAT_IF_H_
