#include "textile/photo/profile_inputs.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

bool HasImageMagic(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char b[8] = {};
  in.read(b, sizeof b);
  const auto n = static_cast<size_t>(in.gcount());
  const auto starts = [&](const char* magic, size_t m) {
    return n >= m && std::memcmp(b, magic, m) == 0;
  };
  // TIFF's magic numbers hold a NUL: spelled as arrays, not as literals cut short at it.
  static constexpr char kTiffLittle[] = {'I', 'I', '*', '\0'};
  static constexpr char kTiffBig[] = {'M', 'M', '\0', '*'};
  return starts("\x89PNG\r\n\x1a\n", 8) || starts("\xFF\xD8\xFF", 3) || starts(kTiffLittle, 4) ||
         starts(kTiffBig, 4) || starts("BM", 2);
}

bool HasImageExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" || ext == ".tiff" ||
         ext == ".bmp";
}

}  // namespace

bool IsPhotoPath(const std::string& path) { return HasImageMagic(path) || HasImageExtension(path); }

void CheckTipForPhotos(const ExtractOptions& options, size_t photos) {
  if (options.tip_px && photos > 1)
    throw InputError("--tip-px names one photo's tip: give one photo with it (each photo's tip "
                     "lies elsewhere)");
}

Rig RigFromOptions(const PhotoInputOptions& options, const std::string& what) {
  if (options.rig_path && options.mm_per_px) {
    throw InputError(what + ": give exactly one of --rig RIG.json and --mm-per-px S (both given)");
  }
  if (options.rig_path) return ReadRigJson(*options.rig_path);
  if (options.mm_per_px) return Rig::FromScale(*options.mm_per_px);
  throw InputError(what + ": give exactly one of --rig RIG.json and --mm-per-px S (pixels -> mm)");
}

std::vector<LoadedProfile> LoadProfileInputs(const std::vector<std::string>& paths,
                                             const PhotoInputOptions& options) {
  if (options.rig_path && options.mm_per_px) {
    throw InputError("give exactly one of --rig RIG.json and --mm-per-px S (both given)");
  }
  std::string why;
  if (!options.extract.Check(&why)) throw InputError("photo options: " + why);
  // One file given twice (or under two spellings) would count twice: its points would weigh
  // double in a fit. Missing files are left to the loader below, which names them.
  for (size_t i = 0; i < paths.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      std::error_code ec;
      if (!std::filesystem::equivalent(paths[j], paths[i], ec) || ec) continue;
      throw InputError(
          (paths[i] == paths[j] ? paths[i] + " is given twice"
                                : paths[j] + " and " + paths[i] + " are the same file") +
          ": give each profile once (twice, its points would weigh double in the fit)");
    }
  }
  CheckTipForPhotos(options.extract,
                    static_cast<size_t>(std::count_if(paths.begin(), paths.end(), IsPhotoPath)));
  std::optional<Rig> rig;  // read once, at the first photo
  std::vector<LoadedProfile> loaded;
  for (const auto& path : paths) {
    LoadedProfile in;
    in.source = path;
    if (!IsPhotoPath(path)) {
      in.profile = ReadProfileCsv(path);
      in.profile.source = path;
      loaded.push_back(std::move(in));
      continue;
    }
    if (!rig) rig = RigFromOptions(options, path + " is a photo");
    cv::Mat gray = ReadPhotoGray(path);
    if (gray.total() > 4e6 && options.on_progress) options.on_progress("extracting " + path + " ...");
    ExtractionSummary r = ExtractProfile(gray, *rig, options.extract, path);
    if (!r.success) throw ComputeError(path + ": " + r.message);
    in.profile = r.profile;
    in.profile.source = path;
    in.from_photo = true;
    in.extraction = std::move(r);
    if (options.keep_photos) in.photo = gray;
    loaded.push_back(std::move(in));
  }
  return loaded;
}

nlohmann::json ExtractionJson(const LoadedProfile& in) {
  const ExtractionSummary& r = *in.extraction;
  return {{"photo", in.source},
          {"rig_type", r.rig_type},
          {"polarity", r.polarity},
          {"direction", r.direction},
          {"trace", r.trace},
          {"points", r.profile.size()},
          {"length_mm", r.length_mm},
          {"tip_mm", {r.tip_mm.x(), r.tip_mm.y()}},
          {"mm_per_px", r.mm_per_px},
          {"confidence", ConfidenceJson(r.confidence)},
          {"warnings", r.WarningTexts()}};
}

nlohmann::json ConfidenceJson(const ExtractionConfidence& c) {
  const auto mm_or_null = [&c](double ShapeCheck::*field) {
    return c.shape && c.shape->converged ? nlohmann::json(units::MToMm((*c.shape).*field))
                                         : nlohmann::json();
  };
  return {{"held_end", c.held_end},
          {"held_end_how", c.held_end_how},
          {"tip", c.tip},
          {"sections_measured", c.sections_measured},
          {"shape_rms_mm", mm_or_null(&ShapeCheck::rms)},
          {"shape_max_mm", mm_or_null(&ShapeCheck::max)},
          {"shape_plausible", c.shape ? nlohmann::json(c.shape->plausible) : nlohmann::json()},
          {"guesses", c.guesses}};
}

}  // namespace textile
