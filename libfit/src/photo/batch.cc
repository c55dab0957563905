// textile batch's run (batch.h): specimens fitted in parallel into their folders, resumable by
// content hash, then the summary and the fabric materials. Stages: PrepareOutDir,
// ResumeOrFit (SpecimenInputHash, ReadCompleteSpecimen, FitSpecimen, WriteSpecimen), and
// WriteSummary.

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "textile/fit/fit_material.h"
#include "textile/fit/validate.h"
#include "textile/photo/extract.h"
#include "textile/photo/image_codecs.h"
#include "textile/photo/batch.h"
#include "textile/photo/profile_inputs.h"
#include "textile/sim/core/content_hash.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The file a specimen's folder is complete with: written last.
constexpr const char* kSpecimenRecord = "specimen.json";
constexpr const char* kSpecimenMaterial = "material.json";

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot read");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Writes through a temporary file renamed into place: a reader sees the old file or the new.
void WriteAtomically(const fs::path& path, const std::string& text) {
  std::error_code ec;
  fs::create_directories(path.parent_path(), ec);
  if (ec) throw InputError(path.parent_path().string() + ": cannot make the folder (" + ec.message() + ")");
  std::ostringstream tid;
  tid << std::this_thread::get_id();
  const fs::path temp = path.string() + ".partial-" + tid.str();
  {
    std::ofstream out(temp, std::ios::binary);
    out << text;
    if (!out.flush()) throw InputError(path.string() + ": cannot write");
  }
  fs::rename(temp, path, ec);
  if (ec) {
    fs::remove(temp, ec);
    throw InputError(path.string() + ": cannot write");
  }
}

fs::path SpecimenDir(const std::string& out_dir, const ManifestRow& row) {
  return fs::path(out_dir) / row.fabric / row.specimen;
}

json RowJson(const ManifestRow& r) {
  return {{"fabric", r.fabric},
          {"specimen", r.specimen},
          {"direction", DirectionName(r.direction)},
          {"side", SideName(r.side)},
          {"inputs", r.inputs},
          {"gsm", r.gsm},
          {"rig", r.rig.empty() ? json() : json(r.rig)},
          {"mm_per_px", r.mm_per_px ? json(*r.mm_per_px) : json()},
          {"width_mm", r.width_mm ? json(*r.width_mm) : json()},
          {"notes", r.notes},
          {"validate", r.validate == SpecimenValidation::kNone       ? "no"
                       : r.validate == SpecimenValidation::kElastica ? "yes"
                                                                     : "shell"}};
}

// An error message as the manifest spells the paths: the same bytes from any working folder.
std::string AsSpelled(std::string message, const ManifestRow& row) {
  const auto replace = [&message](const std::string& from, const std::string& to) {
    if (from.empty() || from == to) return;
    for (size_t at = message.find(from); at != std::string::npos; at = message.find(from, at + to.size()))
      message.replace(at, from.size(), to);
  };
  for (size_t i = 0; i < row.paths.size(); ++i) replace(row.paths[i], row.inputs[i]);
  replace(row.rig_path, row.rig);
  return message;
}

// The specimen's material (and its validation, into *validation) when its folder is complete
// and remembers `hash`; else none.
std::optional<Material> ReadCompleteSpecimen(const fs::path& dir, const std::string& hash,
                                             json* validation) {
  std::error_code ec;
  if (!fs::is_regular_file(dir / kSpecimenRecord, ec) ||
      !fs::is_regular_file(dir / kSpecimenMaterial, ec))
    return std::nullopt;
  try {
    const json record = json::parse(ReadBytes((dir / kSpecimenRecord).string()));
    if (record.value("status", "") != "fitted" || record.value("input_hash", "") != hash)
      return std::nullopt;
    *validation = record.value("validation", json());
    return ReadMaterial((dir / kSpecimenMaterial).string());
  } catch (const std::exception&) {
    return std::nullopt;  // a damaged folder is fitted again
  }
}

// An earlier run's overlays (a photo since replaced by a profile) and temporary files left by
// a killed run: none may outlive the run that writes the folder anew.
void RemoveStaleFiles(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return;
  std::vector<fs::path> stale;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.ends_with(".overlay.png") || name.find(".partial-") != std::string::npos)
      stale.push_back(e.path());
  }
  for (const fs::path& p : stale) fs::remove(p, ec);
}

// The folder of one specimen: material.json (when fitted), then specimen.json. A failed
// specimen's stale material is removed, so that its folder never shows an old fit.
void WriteSpecimen(const std::string& out_dir, const SpecimenOutcome& o) {
  const fs::path dir = SpecimenDir(out_dir, *o.row);
  std::error_code ec;
  fs::remove(dir / kSpecimenRecord, ec);
  RemoveStaleFiles(dir);
  if (o.material) {
    WriteAtomically(dir / kSpecimenMaterial, MaterialToJson(*o.material).dump(2) + "\n");
  } else {
    fs::remove(dir / kSpecimenMaterial, ec);
  }
  for (const auto& [name, png] : o.overlays)
    WriteAtomically(dir / name, std::string(png.begin(), png.end()));
  json record = RowJson(*o.row);
  record["validation"] = o.validation;
  record["status"] = o.status == SpecimenStatus::kFailed ? "failed" : "fitted";
  record["error"] = o.error.empty() ? json() : json(o.error);
  record["exit_code"] = o.exit_code;
  record["input_hash"] = o.input_hash;
  WriteAtomically(dir / kSpecimenRecord, record.dump(2) + "\n");
}

SpecimenOutcome Failed(const ManifestRow& row, const std::string& what, int exit_code) {
  SpecimenOutcome o;
  o.row = &row;
  o.status = SpecimenStatus::kFailed;
  o.error = AsSpelled(what, row);
  o.exit_code = exit_code;
  return o;
}

SpecimenOutcome ResumeOrFit(const ManifestRow& row, const BatchOptions& options) {
  std::string hash;
  try {
    hash = SpecimenInputHash(row);
  } catch (const InputError& e) {
    // The folder must not keep an earlier fit of inputs that can no longer be read.
    SpecimenOutcome failed = Failed(row, e.what(), 2);
    try {
      WriteSpecimen(options.out_dir, failed);
    } catch (const InputError&) {
      // the folder cannot be written either: the outcome says why the specimen failed
    }
    return failed;
  }
  const fs::path dir = SpecimenDir(options.out_dir, row);
  if (options.resume) {
    json validation;
    if (std::optional<Material> m = ReadCompleteSpecimen(dir, hash, &validation)) {
      SpecimenOutcome o;
      o.row = &row;
      o.validation = std::move(validation);
      o.status = SpecimenStatus::kResumed;
      o.material = std::move(m);
      o.input_hash = hash;
      return o;
    }
  }
  SpecimenOutcome o = FitSpecimen(row);
  o.input_hash = hash;
  try {
    WriteSpecimen(options.out_dir, o);
  } catch (const InputError& e) {
    return Failed(row, e.what(), 2);
  }
  return o;
}

void PrepareOutDir(const BatchOptions& o) {
  if (o.out_dir.empty()) throw InputError("-o: give the output folder");
  if (o.jobs < 1 || o.jobs > 256) throw InputError("--jobs must lie in 1..256");
  std::error_code ec;
  if (fs::exists(o.out_dir, ec) && !fs::is_directory(o.out_dir, ec))
    throw InputError("-o " + o.out_dir + ": exists and is not a folder");
  fs::create_directories(o.out_dir, ec);
  if (ec) throw InputError("-o " + o.out_dir + ": cannot make the folder (" + ec.message() + ")");
  // One probe a process: shards of one manifest may start into one folder at once.
  const fs::path probe =
      fs::path(o.out_dir) / (".textile-batch-probe-" + std::to_string(::getpid()));
  if (!std::ofstream(probe)) throw InputError("-o " + o.out_dir + ": cannot write in the folder");
  fs::remove(probe, ec);
}

// Runs `work(i)` for every i in `todo` on `jobs` threads; `done(i)` is called under a lock.
void RunParallel(const std::vector<size_t>& todo, int jobs,
                 const std::function<void(size_t)>& work) {
  std::atomic<size_t> next{0};
  const auto worker = [&] {
    for (size_t k = next++; k < todo.size(); k = next++) work(todo[k]);
  };
  std::vector<std::thread> threads;
  const int n = std::min<int>(jobs, static_cast<int>(todo.size()));
  for (int t = 1; t < n; ++t) threads.emplace_back(worker);
  worker();
  for (std::thread& t : threads) t.join();
}

// A shard's run: an earlier whole run's summary and fabric materials no longer describe the
// folder, and the report must not take them (it refuses a folder without summary.json).
void RemoveSummary(const std::string& out_dir, const Manifest& manifest) {
  std::error_code ec;
  fs::remove(fs::path(out_dir) / "summary.json", ec);
  fs::remove(fs::path(out_dir) / "summary.csv", ec);
  for (const ManifestRow& row : manifest.rows)
    fs::remove(fs::path(out_dir) / row.fabric / "material.json", ec);
}

void WriteSummary(const std::string& out_dir, BatchResult* r) {
  r->summary = SummaryJson(r->specimens);
  for (const json& f : r->summary["fabrics"]) {
    const fs::path path = fs::path(out_dir) / f["fabric"].get<std::string>() / "material.json";
    if (f["material"].is_null()) {
      std::error_code ec;
      fs::remove(path, ec);  // no specimen of it was fitted: no stale material stays
      continue;
    }
    WriteAtomically(path, f["material"].dump(2) + "\n");
  }
  WriteAtomically(fs::path(out_dir) / "summary.csv", SummaryCsv(r->summary));
  WriteAtomically(fs::path(out_dir) / "summary.json", r->summary.dump(2) + "\n");
  r->summary_written = true;
}

// The extraction overlay of a photo input, as a thumbnail PNG named after the photo.
std::pair<std::string, std::vector<unsigned char>> OverlayPng(const LoadedProfile& in,
                                                              const std::string& as_spelled) {
  const cv::Mat overlay = DrawExtractionOverlay(in.photo, *in.extraction, kBatchOverlaySidePx);
  std::vector<unsigned char> png;
  if (!image_codecs::Encode(".png", overlay, &png))
    throw ComputeError(as_spelled + ": cannot encode its overlay");
  return {fs::path(as_spelled).stem().string() + ".overlay.png", std::move(png)};
}

// validate.h's verdicts on the specimen's profiles: ComputeError when the validation itself
// could not be completed.
json ValidationJson(const std::vector<Profile>& profiles, double rho, SpecimenValidation how) {
  ValidationOptions v;
  v.run_shell = how == SpecimenValidation::kShell;
  const ValidationSummary s = ValidateFit(profiles, rho, v);
  if (!s.completed) throw ComputeError("validation: " + s.message);
  return {{"models", v.run_shell ? "elastica, shell" : "elastica"},
          {"goodness_of_fit", s.pass ? "pass" : "fail"},
          {"held_out", HoldoutVerdictName(s.holdout_verdict)},
          {"pass", s.AllPass()},
          {"reason", s.AllPass() ? json() : json(s.FailureReason())}};
}

}  // namespace

const char* SpecimenStatusName(SpecimenStatus s) {
  switch (s) {
    case SpecimenStatus::kFitted: return "fitted";
    case SpecimenStatus::kResumed: return "resumed";
    case SpecimenStatus::kFailed: return "failed";
    case SpecimenStatus::kNotInShard: return "other shard";
  }
  return "?";
}

std::string SpecimenInputHash(const ManifestRow& row) {
  std::string content = RowJson(row).dump();
  for (const std::string& p : row.paths) {
    const std::string bytes = ReadBytes(p);
    content += "\n" + std::to_string(bytes.size()) + "\n" + bytes;
  }
  if (!row.rig_path.empty()) content += "\nrig\n" + ReadBytes(row.rig_path);
  return HashContent(content).Hex();
}

SpecimenOutcome FitSpecimen(const ManifestRow& row) {
  try {
    PhotoInputOptions photo;
    if (!row.rig_path.empty()) photo.rig_path = row.rig_path;
    photo.mm_per_px = row.mm_per_px;
    photo.keep_photos = true;
    const std::vector<LoadedProfile> loaded = LoadProfileInputs(row.paths, photo);
    std::vector<Profile> profiles;
    json photos = json::array();
    SpecimenOutcome o;
    for (size_t i = 0; i < loaded.size(); ++i) {
      profiles.push_back(loaded[i].profile);
      profiles.back().source = row.inputs[i];
      if (!loaded[i].extraction) continue;
      json p = ExtractionJson(loaded[i]);
      p["photo"] = row.inputs[i];
      photos.push_back(p);
      o.overlays.push_back(OverlayPng(loaded[i], row.inputs[i]));
      for (size_t k = 0; k + 1 < o.overlays.size(); ++k)
        if (o.overlays[k].first == o.overlays.back().first)  // L40.jpg and L40.png, a/ and b/
          o.overlays.back().first = std::to_string(i + 1) + "-" + o.overlays.back().first;
    }
    FitMaterialOptions fit;
    fit.areal_density = units::GsmToSi(row.gsm);
    fit.name = row.fabric + " " + row.specimen + " (" + DirectionName(row.direction) + ", " +
               SideName(row.side) + ")";
    FittedMaterial fitted = FitMaterial(profiles, fit);
    Material& m = fitted.material;
    m.fit.erase("seconds");  // the same bytes for the same inputs
    m.fit["inputs"] = row.inputs;
    if (!photos.empty()) m.fit["photos"] = photos;
    m.fit["areal_density_gsm"] = row.gsm;
    if (row.validate != SpecimenValidation::kNone)
      o.validation = ValidationJson(profiles, fit.areal_density, row.validate);
    o.row = &row;
    o.status = SpecimenStatus::kFitted;
    o.material = std::move(m);
    return o;
  } catch (const InputError& e) {
    return Failed(row, e.what(), 2);
  } catch (const std::exception& e) {
    return Failed(row, e.what(), 3);  // ComputeError, and whatever else a fit can throw
  }
}

BatchResult RunBatch(const Manifest& manifest, const BatchOptions& options) {
  PrepareOutDir(options);
  BatchResult r;
  r.specimens.resize(manifest.rows.size());
  std::vector<size_t> todo;
  for (size_t i = 0; i < manifest.rows.size(); ++i) {
    r.specimens[i].row = &manifest.rows[i];
    r.specimens[i].status = SpecimenStatus::kNotInShard;
    if (options.shard.Contains(i)) todo.push_back(i);
  }
  std::mutex lock;
  size_t done = 0;
  RunParallel(todo, options.jobs, [&](size_t i) {
    SpecimenOutcome o = ResumeOrFit(manifest.rows[i], options);
    const std::lock_guard<std::mutex> guard(lock);
    r.specimens[i] = std::move(o);
    ++done;
    if (options.on_progress) options.on_progress({done, todo.size(), &r.specimens[i]});
  });
  for (const SpecimenOutcome& o : r.specimens) r.failed += o.status == SpecimenStatus::kFailed;
  if (options.shard.count == 1) {
    WriteSummary(options.out_dir, &r);
  } else {
    RemoveSummary(options.out_dir, manifest);
  }
  return r;
}

}  // namespace textile
