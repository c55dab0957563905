#ifndef TEXTILE_PHOTO_BATCH_H_
#define TEXTILE_PHOTO_BATCH_H_

// A specimen series (docs/guide/batch.md): a manifest of cantilever specimens, each fitted as
// `textile fit` would (extracting photos first), into DIR/<fabric>/<specimen>/, then the
// per-fabric, per-direction statistics a lab reports (FAST, ASTM D1388: n, mean, sd, CV, the
// overall rigidity sqrt(G_warp G_weft)) in DIR/summary.csv and DIR/summary.json, and one
// material per fabric from the direction means, DIR/<fabric>/material.json.
//
//   const textile::Manifest m = textile::ReadManifest("series.csv");   // throws InputError
//   textile::BatchOptions o;
//   o.out_dir = "out";
//   o.jobs = 2;
//   const textile::BatchResult r = textile::RunBatch(m, o);
//   if (r.failed > 0) ...   // each failed specimen's error is in r.specimens and summary.json
//
// Outputs are the same bytes for the same inputs (no times, no absolute paths), so that shards
// run on several machines into copies of DIR can be merged by copying the specimen folders
// together and running the whole manifest once more with `resume`.

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "textile/sim/law/material.h"

namespace textile {

enum class StripDirection { kWarp, kWeft, kBias };
enum class FabricSide { kFace, kBack };

const char* DirectionName(StripDirection d);  // "warp", "weft", "bias"
const char* SideName(FabricSide s);           // "face", "back"

// What `validate` asks of a specimen (docs/guide/validate.md): nothing (empty or "no"), the
// elastica ("yes": goodness of fit, and held-out prediction when it has two or more profiles),
// or the elastica and the 3D shell ("shell", some seconds a profile).
enum class SpecimenValidation { kNone, kElastica, kShell };

// One row of the manifest: one specimen (one strip, one or more photos or profiles of it).
struct ManifestRow {
  int line = 0;  // its line in the manifest (the header is line 1)
  std::string fabric, specimen;  // path-safe names: [A-Za-z0-9._+-], not starting with '.'
  StripDirection direction = StripDirection::kWarp;
  FabricSide side = FabricSide::kFace;
  std::vector<std::string> inputs;    // as the manifest spells them (';'-separated)
  std::vector<std::string> paths;     // the same, resolved against the manifest's folder
  double gsm = 0.0;                   // areal density [g/m²]
  std::string rig;                    // rig file as spelled (photos), or empty
  std::string rig_path;               // resolved, or empty
  std::optional<double> mm_per_px;    // plain scale (photos), or none
  std::optional<double> width_mm;     // strip width [mm], carried into the records
  std::string notes;                  // free text, carried into the records
  SpecimenValidation validate = SpecimenValidation::kNone;  // the `validate` column
};

struct Manifest {
  std::string source;  // the file, for messages
  std::vector<ManifestRow> rows;
};

// The manifest's columns: required ones first. Any order in the file; named by the header.
extern const std::vector<std::string> kManifestRequiredColumns;  // fabric .. gsm
extern const std::vector<std::string> kManifestOptionalColumns;  // rig .. notes, validate

// Parses manifest text (CSV, header first; a field may be "quoted", with "" for a quote).
// `base_dir` resolves relative inputs and rigs. Throws InputError naming the row and column:
// "series.csv line 4, column gsm: '200 g/m2' is not a number (g/m², without units)". Checks
// what text alone can: columns, names, duplicate specimens, directions, sides, numbers.
Manifest ParseManifest(const std::string& text, const std::string& source,
                       const std::string& base_dir);
// Reads and parses a manifest file, and checks that every input and rig file exists (InputError
// naming the row and column otherwise).
Manifest ReadManifest(const std::string& path);

// Part K of N of a manifest (--shard K/N): the rows whose index i (0-based, manifest order)
// has i % N == K - 1.
struct Shard {
  int index = 1, count = 1;
  bool Contains(size_t row_index) const {
    return static_cast<int>(row_index % static_cast<size_t>(count)) == index - 1;
  }
};
// "K/N" with 1 <= K <= N; InputError otherwise ("--shard 3/2: K must lie in 1..N").
Shard ParseShard(const std::string& text);

// What one specimen came to.
enum class SpecimenStatus { kFitted, kResumed, kFailed, kNotInShard };
const char* SpecimenStatusName(SpecimenStatus s);  // "fitted", "resumed", "failed", "other shard"

struct SpecimenOutcome {
  const ManifestRow* row = nullptr;
  SpecimenStatus status = SpecimenStatus::kFailed;
  std::string error;                // one line, for kFailed
  int exit_code = 0;                // 2 bad input, 3 computation failed (kFailed)
  std::optional<Material> material;  // the fitted material (kFitted, kResumed)
  std::string input_hash;           // HashContent of the row and its inputs' bytes
  // The verdicts when the row asked for validation: {goodness_of_fit: pass|fail, held_out:
  // none|pass|fail, pass, reason}; null otherwise.
  nlohmann::json validation;
  // The photos' extraction overlays, as PNG bytes named "<photo stem>.overlay.png" (kFitted).
  std::vector<std::pair<std::string, std::vector<unsigned char>>> overlays;
};

struct BatchProgress {
  size_t done = 0, total = 0;  // specimens of this shard finished / to do
  const SpecimenOutcome* last = nullptr;
};

struct BatchOptions {
  std::string out_dir;  // DIR; made when missing
  int jobs = 1;         // specimens fitted at once (threads), >= 1
  Shard shard;
  bool resume = false;  // skip specimens whose outputs are complete and whose inputs match
  std::function<void(const BatchProgress&)> on_progress;  // after each specimen
};

struct BatchResult {
  std::vector<SpecimenOutcome> specimens;  // manifest order
  int failed = 0;
  bool summary_written = false;  // false for a shard of several: the merge run writes it
  nlohmann::json summary;        // summary.json's content (when written)
};

// Runs every specimen of the shard (failures recorded, the others go on), writes each
// specimen's folder, and then, for a whole manifest (shard 1/1), the summary and the fabric
// materials. Throws InputError for options or a DIR it cannot write, before any specimen runs.
BatchResult RunBatch(const Manifest& manifest, const BatchOptions& options);

// Long side of the overlay thumbnails a photo specimen keeps [px].
inline constexpr int kBatchOverlaySidePx = 640;

// ---- The stages, exposed for tests ------------------------------------------------------

// The fingerprint a specimen's outputs remember: the row's fields and every input's bytes (and
// the rig file's). Throws InputError when an input cannot be read.
std::string SpecimenInputHash(const ManifestRow& row);

// Fits one specimen (photos extracted with the row's rig or scale, each with an overlay of at
// most kBatchOverlaySidePx), validates it when the row asks, never throwing: failures come back
// as kFailed with the error and its exit code. The material's fit report has no `seconds` and
// names the inputs as the manifest spells them.
SpecimenOutcome FitSpecimen(const ManifestRow& row);

// n, mean, sample sd (n - 1; null below n = 2) and CV = sd / |mean| of a set of values.
struct SeriesStats {
  size_t n = 0;
  double mean = 0.0;
  std::optional<double> sd, cv;
};
SeriesStats Stats(const std::vector<double>& values);

// summary.json: {"directions": [{fabric, direction, n, n_failed, b1_gfcm: {n, n_unobserved, mean,
// sd, cv}, ...}], "fabrics": [{fabric, material_note, overall_rigidity_uNm, overall_rigidity_mgcm,
// material}], "specimens": [{fabric, specimen, direction, side, line, status, error, b1_gfcm ...,
// rms_mm, unobserved, validation}]}, fabrics in manifest order, directions warp, weft, bias.
nlohmann::json SummaryJson(const std::vector<SpecimenOutcome>& specimens);
// summary.csv from SummaryJson: one row a fabric and direction.
std::string SummaryCsv(const nlohmann::json& summary);
// The material of one fabric from its direction means: the warp law (or the only one measured),
// the weft law when both were measured, and the bias mean as bending_bias (the drape blends
// it in by angle, exports carry it; a note says so).
// None, with the reason in *why (if non-null), when no specimen of the fabric was fitted or the
// means make no law a material file takes.
std::optional<Material> FabricMaterial(const std::string& fabric,
                                       const std::vector<SpecimenOutcome>& specimens,
                                       std::string* why = nullptr);

}  // namespace textile

#endif  // TEXTILE_PHOTO_BATCH_H_
