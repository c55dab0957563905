#include "common/profile_inputs.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "common/cli.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile::cli {
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
    if (gray.total() > 4e6) Progress("extracting " + path + " ...", options.progress);
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

Eigen::Vector2d ParseEdgePx(const std::string& text) {
  std::stringstream in(text);
  std::string a, b, rest;
  if (!std::getline(in, a, ',') || !std::getline(in, b, ',') || std::getline(in, rest)) {
    throw InputError("--edge-px: expected X,Y in pixels, got '" + text + "'");
  }
  Eigen::Vector2d p;
  for (int k = 0; k < 2; ++k) {
    const std::string& s = k == 0 ? a : b;
    char* end = nullptr;
    p[k] = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0' || !std::isfinite(p[k])) {
      throw InputError("--edge-px: '" + s + "' is not a number (expected X,Y in pixels)");
    }
  }
  return p;
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

PhotoInputOptions PhotoFlags::Options() const {
  PhotoInputOptions o;
  const bool rig_given = rig_option && rig_option->count() > 0;
  const bool scale_given = scale_option && scale_option->count() > 0;
  if (rig_given && scale_given) {
    throw InputError("give exactly one of --rig RIG.json and --mm-per-px S (both given)");
  }
  if (rig_given) o.rig_path = rig_file;
  if (scale_given) o.mm_per_px = mm_per_px;
  ExtractOptions& e = o.extract;
  e.trace = trace == "upper"   ? TraceLine::kUpper
            : trace == "lower" ? TraceLine::kLower
                               : TraceLine::kMid;
  e.rig = rig_type == "platform" ? RigKind::kPlatform
          : rig_type == "clamp"  ? RigKind::kClamp
                                 : RigKind::kAuto;
  if (!edge.empty()) e.edge_px = ParseEdgePx(edge);
  if (level_option && level_option->count() > 0) e.level_deg = level_deg;
  e.step_mm = step_mm;
  e.accept_guesses = accept_guesses;
  e.check_shape = !no_shape_check;
  o.progress = progress;
  std::string why;
  if (!e.Check(&why)) {
    const std::string flag = why.rfind("step", 0) == 0    ? "--step-mm"
                             : why.rfind("level", 0) == 0 ? "--level-deg"
                                                          : "--edge-px";
    throw InputError(flag + ": " + why.substr(why.find(' ') + 1));
  }
  // The scale and the rig file are checked whatever the inputs (LoadProfileInputs reads them at
  // the first photo only): with profiles alone, --mm-per-px -1 or nan and a missing --rig ran.
  if (o.mm_per_px) (void)Rig::FromScale(*o.mm_per_px);
  if (o.rig_path) (void)ReadRigJson(*o.rig_path);
  return o;
}

void AddPhotoFlags(CLI::App* sub, PhotoFlags* f) {
  f->rig_option =
      sub->add_option("--rig", f->rig_file,
                      "Rig file (from `textile calibrate`): pixels -> mm in the bending plane");
  f->scale_option =
      sub->add_option("--mm-per-px", f->mm_per_px,
                      "Plain scale for a perpendicular, distortion-free camera [mm/px]");
  sub->add_option(
      "--edge-px", f->edge,
      "Origin override X,Y [px]: the platform edge, or where the strip leaves the clamp");
  f->level_option = sub->add_option(
      "--level-deg", f->level_deg,
      "Horizontal = image rows turned by this angle [deg], counter-clockwise as seen (default: "
      "the platform's top face, else the rows)");
  sub->add_option("--trace", f->trace,
                  "Line to trace: mid (silhouette mid-line, default), upper or lower boundary "
                  "(oblique views: the lit near edge)")
      ->check(CLI::IsMember({"mid", "upper", "lower"}));
  sub->add_option("--rig-type", f->rig_type,
                  "auto (default), platform (fail if none is found) or clamp")
      ->check(CLI::IsMember({"auto", "platform", "clamp"}));
  sub->add_option("--step-mm", f->step_mm,
                  "Profile spacing along the arc length [mm] (default 0.5)");
  sub->add_flag("--accept-guesses", f->accept_guesses,
                "Take what extraction had to guess (the held end, the tip, a profile failing the "
                "physics check) instead of failing; each guess becomes a warning");
  sub->add_flag("--no-shape-check", f->no_shape_check,
                "Skip the physics check (a strip that is no free cantilever; saves 10-40 ms a "
                "photo): the profile's confidence then rests on the extraction alone");
  sub->add_flag("--progress", f->progress,
                "Print the progress lines of photo extraction on stderr even when it is not a "
                "terminal");
}

}  // namespace textile::cli
