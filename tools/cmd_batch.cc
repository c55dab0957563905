// textile batch: a manifest of specimens, each fitted into DIR/<fabric>/<specimen>/, then the
// per-direction statistics and one material per fabric; textile::RunBatch does the work
// (libfit photo/batch.h, docs/guide/batch.md).

#include <unistd.h>

#include <iostream>

#include "common/cli.h"
#include "textile/photo/batch.h"
#include "textile/sim/core/error.h"

namespace textile::cli {
namespace {

struct BatchArgs {
  std::string manifest, out, shard = "1/1";
  int jobs = 1;
  bool resume = false, json = false;
};

// A bar redrawn in place on a terminal; a line a specimen otherwise (logs, CI).
void ShowSpecimen(const BatchProgress& p) {
  const SpecimenOutcome& o = *p.last;
  const std::string what = o.row->fabric + "/" + o.row->specimen + " " +
                           SpecimenStatusName(o.status) +
                           (o.error.empty() ? "" : ": " + o.error);
  if (::isatty(STDERR_FILENO) == 1) {
    constexpr size_t kWidth = 30;
    const size_t filled = p.total ? kWidth * p.done / p.total : kWidth;
    std::cerr << "\r[" << std::string(filled, '#') << std::string(kWidth - filled, ' ') << "] "
              << p.done << "/" << p.total << "  " << what.substr(0, 60) << "\033[K"
              << (p.done == p.total ? "\n" : "") << std::flush;
    return;
  }
  std::cerr << "[" << p.done << "/" << p.total << "] " << what << std::endl;
}

void Run(const BatchArgs& a) {
  BatchOptions o;
  o.out_dir = a.out;
  o.jobs = a.jobs;
  o.shard = ParseShard(a.shard);
  o.resume = a.resume;
  o.on_progress = ShowSpecimen;
  const Manifest manifest = ReadManifest(a.manifest);
  const BatchResult r = RunBatch(manifest, o);
  size_t fitted = 0, resumed = 0, other = 0;
  for (const SpecimenOutcome& s : r.specimens) {
    fitted += s.status == SpecimenStatus::kFitted;
    resumed += s.status == SpecimenStatus::kResumed;
    other += s.status == SpecimenStatus::kNotInShard;
  }
  if (a.json) {
    nlohmann::json failed = nlohmann::json::array();
    for (const SpecimenOutcome& s : r.specimens)
      if (s.status == SpecimenStatus::kFailed)
        failed.push_back({{"fabric", s.row->fabric}, {"specimen", s.row->specimen},
                          {"line", s.row->line}, {"error", s.error}});
    PrintJson({{"out", a.out}, {"fitted", fitted}, {"resumed", resumed}, {"failed", failed},
               {"other_shard", other}, {"summary_written", r.summary_written}});
  } else {
    std::cout << "specimens: " << fitted << " fitted, " << resumed << " resumed, " << r.failed
              << " failed" << (other ? ", " + std::to_string(other) + " in other shards" : "")
              << "\n";
    for (const SpecimenOutcome& s : r.specimens)
      if (s.status == SpecimenStatus::kFailed)
        std::cout << "failed: " << s.row->fabric << "/" << s.row->specimen << " (line "
                  << s.row->line << "): " << s.error << "\n";
    if (r.summary_written)
      for (const nlohmann::json& f : r.summary["fabrics"])
        if (f["material_note"].is_string())
          std::cout << "note: fabric " << f["fabric"].get<std::string>()
                    << " has no material: " << f["material_note"].get<std::string>() << "\n";
    if (r.summary_written)
      std::cout << "wrote " << a.out << "/summary.csv, summary.json and a material per fabric\n";
    else
      std::cout << "shard " << a.shard << ": no summary; run the whole manifest with --resume "
                << "into the merged folder to write it\n";
  }
  if (r.failed > 0)
    throw ComputeError("batch: " + std::to_string(r.failed) + " of " +
                       std::to_string(r.specimens.size() - other) +
                       " specimens failed (each is listed with its error)");
}

}  // namespace

void RegisterBatch(CLI::App& app) {
  auto a = std::make_shared<BatchArgs>();
  CLI::App* sub = AddSubcommand(
      app, "batch",
      "Fit a series of specimens from a manifest; per-direction statistics and a material "
      "per fabric",
      "textile batch samples/series/manifest.csv -o series-out --jobs 2");
  sub->add_option("MANIFEST", a->manifest,
                  "CSV, one specimen a row: fabric, specimen, direction, side, inputs, gsm[, "
                  "rig, mm_per_px, width_mm, notes, validate]")
      ->required();
  sub->add_option("-o,--out", a->out, "Output folder (made when missing)")->required();
  sub->add_option("--jobs", a->jobs, "Specimens fitted at once (default 1)");
  sub->add_option("--shard", a->shard,
                  "Run part K of N (K/N): rows i with i mod N = K - 1; the summary is left to a "
                  "whole run with --resume");
  sub->add_flag("--resume", a->resume,
                "Skip specimens whose folder is complete and whose inputs did not change");
  sub->add_flag("--json", a->json, "Print one JSON object instead of text");
  sub->callback([a] { Run(*a); });
}

namespace {
const bool kRegistered = AddCommand(45, RegisterBatch);
}  // namespace

}  // namespace textile::cli
