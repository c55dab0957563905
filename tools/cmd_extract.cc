// textile extract: cantilever photos -> profile CSVs (frame of docs/spec/cantilever.md) and
// overlays.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/profile_inputs.h"
#include "textile/photo/extract.h"
#include "textile/photo/image_codecs.h"
#include "textile/fit/profile.h"
#include "textile/photo/rig.h"
#include "textile/sim/core/error.h"

namespace textile::cli {
namespace {

struct ExtractArgs {
  std::vector<std::string> photos;
  std::string out_dir;
  PhotoFlags photo;
  int overlay_px = 2000;
  double max_seconds = 30.0;
  bool json = false;
};

nlohmann::json Point(const Eigen::Vector2d& p) { return {p.x(), p.y()}; }

void Run(const ExtractArgs& a) {
  const PhotoInputOptions options = a.photo.Options();
  const Rig rig = RigFromOptions(options, "extract");
  ExtractOptions o = options.extract;
  CheckTipForPhotos(o, a.photos.size());
  if (a.overlay_px < 200 || a.overlay_px > 20000)
    throw InputError("--overlay-px must lie in [200, 20000]");
  if (!(std::isfinite(a.max_seconds) && a.max_seconds >= 0.0))
    throw InputError("--max-seconds must be a finite number >= 0 [s]");
  o.max_seconds = a.max_seconds;
  // Outputs are named after the photos: two photos with one stem would overwrite each other.
  std::map<std::string, std::string> stems;
  for (const auto& photo : a.photos) {
    const std::string stem = std::filesystem::path(photo).stem().string();
    if (stems.count(stem)) {
      throw InputError(photo + ": same file name as " + stems[stem] + " (outputs would collide)");
    }
    stems[stem] = photo;
  }
  const OutputFolder folder(a.out_dir);  // made when the files are committed

  // All or nothing: every photo's profile and overlay wait in temporary files until the last
  // photo has succeeded, so a photo that cannot be read or extracted leaves no output of the
  // others behind either; the report waits as well (stdout stays empty on failure,
  // docs/spec/cli.md).
  AtomicFileSet outputs;
  std::string report;
  nlohmann::json results = nlohmann::json::array();
  for (const auto& photo : a.photos) {
    const cv::Mat gray = ReadPhotoGray(photo);
    if (a.photos.size() > 1 || gray.total() > 4e6) {
      Progress("extracting " + photo + " ...", options.progress);
    }
    const ExtractionSummary r = ExtractProfile(gray, rig, o, photo);
    if (!r.success) throw ComputeError(photo + ": " + r.message);
    const std::string stem = std::filesystem::path(photo).stem().string();
    const std::string csv = (std::filesystem::path(a.out_dir) / (stem + ".profile.csv")).string();
    const std::string png = (std::filesystem::path(a.out_dir) / (stem + ".overlay.png")).string();
    {
      AtomicFile& profile_file = outputs.Add(csv, folder.stage_dir());
      AtomicFile& overlay_file = outputs.Add(png, folder.stage_dir());
      std::ofstream(profile_file.temp_path(), std::ios::binary) << ProfileToCsv(r.profile);
      if (!image_codecs::Write(overlay_file.temp_path(),
                               DrawExtractionOverlay(gray, r, a.overlay_px))) {
        throw InputError(png + ": cannot write the overlay");
      }
    }
    results.push_back({{"photo", photo},
                       {"profile_csv", csv},
                       {"overlay_png", png},
                       {"rig_type", r.rig_type},
                       {"rig_detail", r.rig_detail},
                       {"polarity", r.polarity},
                       {"direction", r.direction},
                       {"trace", r.trace},
                       {"points", r.profile.size()},
                       {"length_mm", r.length_mm},
                       {"tip_mm", Point(r.tip_mm)},
                       {"origin_px", Point(r.origin_px)},
                       {"tip_px", Point(r.tip_px)},
                       {"level_deg", r.level_deg},
                       {"mm_per_px", r.mm_per_px},
                       {"image_size_px", {gray.cols, gray.rows}},
                       {"contrast", r.contrast},
                       {"noise", r.noise},
                       {"width_px", r.width_px},
                       {"core_width_px", r.core_width_px},
                       {"widening", r.widening},
                       {"rejected_sections", r.rejected_sections},
                       {"confidence", ConfidenceJson(r.confidence)},
                       {"warnings", r.WarningTexts()},
                       {"seconds", r.seconds}});
    report += r.BriefReport() + "\n  wrote " + csv + " and " + png + "\n";
  }
  outputs.Commit();
  if (!a.json) std::cout << report << std::flush;
  if (a.json) PrintJson({{"output_dir", a.out_dir}, {"rig", rig.source}, {"photos", results}});
}

}  // namespace

void RegisterExtract(CLI::App& app) {
  auto a = std::make_shared<ExtractArgs>();
  CLI::App* sub = AddSubcommand(
      app, "extract", "Extract cantilever profiles (s_mm,x_mm,y_mm) from photos",
      "textile extract photos/strip_60mm.jpg --mm-per-px 0.1101 -o out/profiles --trace upper");
  sub->add_option("photos", a->photos, "Photos (PNG, JPEG, TIFF, BMP) of cantilevered strips")
      ->required();
  sub->add_option("-o,--out", a->out_dir, "Folder for <stem>.profile.csv and <stem>.overlay.png")
      ->required();
  AddPhotoFlags(sub, &a->photo);
  sub->add_option("--overlay-px", a->overlay_px,
                  "Long side of the overlay PNG [px] (default 2000)");
  sub->add_option("--max-seconds", a->max_seconds,
                  "Wall-time cap per photo [s] (default 30): past it, nothing is written and the "
                  "exit is 3");
  sub->add_flag("--json", a->json, "Print one JSON object instead of text");
  sub->callback([a] { Run(*a); });
}

namespace {
const bool kRegistered = AddCommand(30, RegisterExtract);
}  // namespace

}  // namespace textile::cli
