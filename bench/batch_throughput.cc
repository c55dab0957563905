// batch: specimens per minute of `textile batch` (textile::RunBatch) at 1 and 2 jobs, from
// profiles and from 12 MP photos, against the law each series was made with (the mean b1's
// error); and the time and size of the lab report of 100 photo specimens. Targets
// (docs/spec/benchmarks.md): 30 specimens from profiles <= 10 s, from 12 MP photos <= 30 s, on
// 2 cores; the report of 100 <= 2 s and <= 20 MB.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "bench/bench.h"
#include "common/chart_file.h"
#include "textile/fit/synthetic_profile.h"
#include "textile/photo/batch.h"
#include "textile/photo/batch_report.h"
#include "textile/photo/image_codecs.h"
#include "textile/photo/render_photo.h"
#include "textile/photo/rig.h"
#include "textile/sim/core/units.h"

namespace textile::bench {

Benchmark BatchBenchmark();

namespace {
const bool kRegistered = AddBenchmark(75, BatchBenchmark);

namespace fs = std::filesystem;

constexpr int kSpecimens = 30;
const char* const kDirections[] = {"warp", "weft", "bias"};

// The Fig. 8 fabric (Pabst et al. Table 1): the law every specimen of the series was made with.
BendingLaw Fig8() { return BendingLaw::FromKes(0.1, 0.0892, -0.0092); }

// 30 specimens, 3 fabrics x 3 directions, each of one noisy profile (σ 0.1 mm, its own seed).
std::string WriteProfileSeries(const fs::path& dir) {
  fs::create_directories(dir);
  std::ostringstream m;
  m << "fabric,specimen,direction,side,inputs,gsm\n";
  for (int i = 0; i < kSpecimens; ++i) {
    SyntheticOptions o;
    o.noise_sigma = 1e-4;
    o.seed = 100 + static_cast<std::uint64_t>(i);
    const double overhang = 0.04 + 0.02 * (i % 3);
    const std::string name = "p" + std::to_string(i) + ".csv";
    std::ofstream(dir / name) << ProfileToCsv(SyntheticProfile(Fig8(), 0.2, overhang, o));
    m << "f" << i / 10 << ",s" << i << "," << kDirections[i % 3] << ",face," << name << ",200\n";
  }
  std::ofstream(dir / "manifest.csv") << m.str();
  return (dir / "manifest.csv").string();
}

std::string WritePhotoManifest(const fs::path& dir, int specimens, const std::string& name) {
  std::ostringstream m;
  m << "fabric,specimen,direction,side,inputs,gsm,rig\n";
  for (int i = 0; i < specimens; ++i)
    m << "f" << i / 10 << ",s" << i << "," << kDirections[i % 3] << ",face,L"
      << 40 + 20 * (i % 3) << ".png,200,rig.json\n";
  std::ofstream(dir / name) << m.str();
  return (dir / name).string();
}

// `specimens` specimens on three 12 MP photos (4000 x 3000 px, 0.05 mm/px, overhangs 40/60/80
// mm), in manifest `name`; the photos are rendered once.
std::string WritePhotoSeries(const fs::path& dir, int specimens, const std::string& name) {
  fs::create_directories(dir);
  if (fs::exists(dir / "rig.json")) return WritePhotoManifest(dir, specimens, name);
  RenderPhotoOptions o = RenderPhotoOptions::ForDifficulty(PhotoDifficulty::kEasy, 7);
  o.width_px = 4000;
  o.height_px = 3000;
  o.mm_per_px = 0.05;
  o.overhang = 0.08;
  const RenderedPhoto longest = RenderPhoto(Fig8(), 0.2, o);
  o.aim_mm = longest.aim_mm;
  std::ofstream(dir / "rig.json") << RigToJson(longest.rig);
  for (int l : {40, 60, 80}) {
    o.overhang = l * 1e-3;
    const RenderedPhoto r = l == 80 ? longest : RenderPhoto(Fig8(), 0.2, o);
    image_codecs::Write((dir / ("L" + std::to_string(l) + ".png")).string(), r.photo);
  }
  return WritePhotoManifest(dir, specimens, name);
}

}  // namespace

Benchmark BatchBenchmark() {
  return {"batch", "textile batch: specimens per minute at 1 and 2 jobs, profiles and 12 MP photos",
          [](const Context& ctx) {
            Result res;
            res.columns = {"inputs", "jobs", "specimens", "seconds", "specimens_per_minute",
                           "failed", "b1_mean_error_rel", "target_seconds", "report_mb"};
            const fs::path work = fs::path(ctx.out_dir) / "batch-work";
            fs::remove_all(work);
            const struct {
              const char* name;
              std::string manifest;
              double target;
              const char* folder;
            } series[] = {{"profiles", WriteProfileSeries(work / "profiles"), 10.0, "profiles"},
                          {"12 MP photos", WritePhotoSeries(work / "photos", kSpecimens, "manifest.csv"), 30.0,
                           "photos"}};
            for (const auto& s : series) {
              const Manifest manifest = ReadManifest(s.manifest);
              for (int jobs : {1, 2}) {
                BatchOptions o;
                o.out_dir = (work / s.folder / ("out-" + std::to_string(jobs))).string();
                o.jobs = jobs;
                fs::remove_all(o.out_dir);
                const auto t0 = std::chrono::steady_clock::now();
                const BatchResult r = RunBatch(manifest, o);
                const double sec =
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
                double worst = 0.0;
                for (const auto& d : r.summary["directions"])
                  worst = std::max(worst, std::abs(d["b1_gfcm"]["mean"].get<double>() / 0.1 - 1.0));
                res.rows.push_back({{"inputs", s.name}, {"jobs", jobs}, {"specimens", kSpecimens},
                                    {"seconds", sec}, {"specimens_per_minute", 60.0 * kSpecimens / sec},
                                    {"failed", r.failed}, {"b1_mean_error_rel", worst},
                                    {"target_seconds", s.target}});
              }
            }
            // The lab report of 100 photo specimens (each with its overlay thumbnail); not --quick.
            if (!ctx.quick) {
              BatchOptions o;
              o.out_dir = (work / "report-100").string();
              o.jobs = 2;
              RunBatch(ReadManifest(WritePhotoSeries(work / "photos", 100, "100.csv")), o);
              std::string html;
              const double sec = MedianSeconds([&] { html = BatchReportHtml(o.out_dir); }, 3);
              res.rows.push_back({{"inputs", "report of 100"}, {"jobs", 1}, {"specimens", 100},
                                  {"seconds", sec}, {"report_mb", html.size() / 1e6},
                                  {"target_seconds", 2.0}});
            }
            std::ostringstream sum;
            char line[200];
            std::snprintf(line, sizeof line, "%-14s %4s %9s %12s %7s %14s %8s\n", "inputs", "jobs",
                          "seconds", "specimens/min", "failed", "b1 mean err", "target");
            sum << line;
            for (const auto& r : res.rows) {
              if (r.contains("report_mb")) {
                std::snprintf(line, sizeof line, "%-14s %4d %9.2f  report %.2f MB (targets 2 s, 20 MB)\n",
                              r["inputs"].get<std::string>().c_str(), r["jobs"].get<int>(),
                              r["seconds"].get<double>(), r["report_mb"].get<double>());
                sum << line;
                continue;
              }
              std::snprintf(line, sizeof line, "%-14s %4d %9.2f %12.0f %7d %13.2f%% %7.0fs\n",
                            r["inputs"].get<std::string>().c_str(), r["jobs"].get<int>(),
                            r["seconds"].get<double>(), r["specimens_per_minute"].get<double>(),
                            r["failed"].get<int>(), 100.0 * r["b1_mean_error_rel"].get<double>(),
                            r["target_seconds"].get<double>());
              sum << line;
            }
            res.summary = sum.str();
            namespace chart = textile::chart;
            chart::Panel p{.title = "textile batch, 30 specimens", .x_label = "jobs",
                           .y_label = "specimens per minute"};
            int k = 0;
            for (const auto& s : series) {
              chart::Series line_series{.label = s.name,
                                        .style = chart::Series::Style::kLineAndMarkers,
                                        .color = chart::PaletteColor(k++)};
              for (const auto& r : res.rows) {
                if (r["inputs"] != s.name || r.contains("report_mb")) continue;
                line_series.x.push_back(r["jobs"].get<int>());
                line_series.y.push_back(r["specimens_per_minute"].get<double>());
              }
              p.series.push_back(line_series);
            }
            chart::WritePng({.title = "batch benchmark", .panels = {p}}, ctx.out_dir + "/batch.png");
            fs::remove_all(work);
            return res;
          }};
}

}  // namespace textile::bench
