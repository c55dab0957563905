#ifndef TEXTILE_PHOTO_PROFILE_INPUTS_H_
#define TEXTILE_PHOTO_PROFILE_INPUTS_H_

// The inputs of a bending fit (fit, validate, batch): each path is either a profile CSV
// (s_mm,x_mm,y_mm) or a photo of the cantilever, which is extracted on the fly with a rig file
// (textile calibrate) or a plain scale (docs/methods/extraction.md).
//
//   textile::PhotoInputOptions o;
//   o.rig_path = "rig.json";
//   for (const auto& in : textile::LoadProfileInputs(paths, o)) { ... in.profile ... }
//
// A file is a photo when its first bytes are those of a PNG, JPEG, TIFF or BMP, or when its
// extension says so (a damaged image then fails as an image, not as a CSV); anything else is
// read as a profile CSV. Errors: InputError (exit 2) for unreadable files, bad options and a
// photo without a rig or scale; ComputeError (exit 3) when a photo does not show a usable strip.
// Messages are one line naming the file or the flag (--rig, --mm-per-px) that settles it.

#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "textile/fit/profile.h"
#include "textile/photo/extract.h"
#include "textile/photo/rig.h"

namespace textile {

struct PhotoInputOptions {
  std::optional<std::string> rig_path;  // rig file (textile calibrate), or
  std::optional<double> mm_per_px;      // a plain scale [mm/px]; at most one of the two
  ExtractOptions extract;               // trace, rig type, edge, level, step
  bool keep_photos = false;             // keep the decoded grey photos (for overlays)
  bool progress = false;  // the caller's: print progress even when stderr is not a terminal
  // Receives "extracting <path> ..." before a photo over 4 MP; none: silent.
  std::function<void(const std::string&)> on_progress;
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

// A tip position (ExtractOptions::tip_px) belongs to one photo: InputError naming --tip-px when
// it comes with more than one.
void CheckTipForPhotos(const ExtractOptions& options, size_t photos);

// The rig the options name; throws InputError when neither or both are given ("<what>: give
// exactly one of --rig RIG.json and --mm-per-px S ..."), or when the rig file is not one.
Rig RigFromOptions(const PhotoInputOptions& options, const std::string& what);

// Loads every path in order: CSVs read and checked, photos extracted. Throws on the first
// failure (InputError or ComputeError, naming the file). A photo without a rig or scale is an
// InputError naming it; both --rig and --mm-per-px is one too. The rig file is read once.
// A photo over 4 MP gets a progress line "extracting <path> ..." through options.on_progress.
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

}  // namespace textile

#endif  // TEXTILE_PHOTO_PROFILE_INPUTS_H_
