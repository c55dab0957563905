#ifndef TEXTILE_TOOLS_COMMON_PROFILE_INPUTS_H_
#define TEXTILE_TOOLS_COMMON_PROFILE_INPUTS_H_

// Inputs of the subcommands that consume profiles (fit, validate): each path is either a
// profile CSV (s_mm,x_mm,y_mm) or a photo of the cantilever, which is extracted on the fly
// with the rig given by --rig RIG.json or --mm-per-px S (docs/methods/extraction.md).
//
//   auto flags = std::make_shared<textile::cli::PhotoFlags>();
//   textile::cli::AddPhotoFlags(sub, flags.get());          // --rig, --mm-per-px, --trace, ...
//   sub->callback([flags, inputs] {
//     const textile::cli::PhotoInputOptions o = flags->Options();     // throws InputError
//     for (const auto& in : textile::cli::LoadProfileInputs(*inputs, o)) { ... in.profile ... }
//   });
//
// A file is a photo when its first bytes are those of a PNG, JPEG, TIFF or BMP, or when its
// extension says so (a damaged image then fails as an image, not as a CSV); anything else is
// read as a profile CSV. Errors: InputError (exit 2) for unreadable files, bad flags and a photo
// without --rig/--mm-per-px; ComputeError (exit 3) when a photo does not show a usable strip.
// Messages are one line naming the file or flag.

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "textile/photo/extract.h"
#include "textile/fit/profile.h"
#include "textile/photo/rig.h"

namespace textile::cli {

struct PhotoInputOptions {
  std::optional<std::string> rig_path;  // rig file (textile calibrate), or
  std::optional<double> mm_per_px;      // a plain scale [mm/px]; at most one of the two
  ExtractOptions extract;               // trace, rig type, edge, level, step
  bool keep_photos = false;             // keep the decoded grey photos (for overlays)
  bool progress = false;  // "extracting ..." lines on stderr even when it is not a terminal
};

struct LoadedProfile {
  std::string source;  // the path as given
  Profile profile;     // frame of docs/spec/cantilever.md [m]; profile.source == source
  bool from_photo = false;
  std::optional<ExtractionSummary> extraction;  // for photos
  cv::Mat photo;  // the grey photo when from_photo and options.keep_photos, else empty
};

// True if the file looks like a photo (magic bytes, or an image extension when unreadable).
bool IsPhotoPath(const std::string& path);

// The rig the options name; throws InputError when neither or both are given ("<what>: give
// exactly one of --rig RIG.json and --mm-per-px S ..."), or when the rig file is not one.
Rig RigFromOptions(const PhotoInputOptions& options, const std::string& what);

// Loads every path in order: CSVs read and checked, photos extracted. Throws on the first
// failure (InputError or ComputeError, naming the file). A photo without a rig or scale is an
// InputError naming it; both --rig and --mm-per-px is one too. The rig file is read once.
// A photo over 4 MP gets a progress line "extracting <path> ..." on stderr, printed only when
// stderr is a terminal or options.progress is set (Progress in cli.h).
std::vector<LoadedProfile> LoadProfileInputs(const std::vector<std::string>& paths,
                                             const PhotoInputOptions& options);

// What a fit report says of a photo input (fit, validate): photo, rig_type, polarity,
// direction, trace, points, length_mm, tip_mm, mm_per_px, confidence, warnings. in.extraction
// must be set.
nlohmann::json ExtractionJson(const LoadedProfile& in);

// An extraction's confidence report: {held_end, held_end_how, tip, sections_measured,
// shape_rms_mm, shape_max_mm (null when not checked or no cantilever fits), shape_plausible
// (null when not checked), guesses}.
nlohmann::json ConfidenceJson(const ExtractionConfidence& confidence);

// The shared photo flags, as CLI11 binds them (raw strings; Options() validates them).
struct PhotoFlags {
  std::string rig_file, edge, trace = "mid", rig_type = "auto";
  double mm_per_px = 0.0, level_deg = 0.0, step_mm = 0.5;
  bool progress = false, accept_guesses = false, no_shape_check = false;
  CLI::Option *rig_option = nullptr, *scale_option = nullptr, *level_option = nullptr;

  // The options these flags give; throws InputError naming the flag ("--edge-px: ...").
  PhotoInputOptions Options() const;
};

// Adds --rig, --mm-per-px, --trace, --rig-type, --edge-px, --level-deg, --step-mm,
// --accept-guesses, --no-shape-check and --progress to a subcommand, bound to *flags (which must outlive the parse).
void AddPhotoFlags(CLI::App* sub, PhotoFlags* flags);

// "X,Y" in pixels (--edge-px); throws InputError.
Eigen::Vector2d ParseEdgePx(const std::string& text);

}  // namespace textile::cli

#endif  // TEXTILE_TOOLS_COMMON_PROFILE_INPUTS_H_
