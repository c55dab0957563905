#ifndef TEXTILE_TOOLS_COMMON_PROFILE_INPUTS_H_
#define TEXTILE_TOOLS_COMMON_PROFILE_INPUTS_H_

// The photo flags of the subcommands that consume profiles (fit, validate, extract): they make
// the PhotoInputOptions of textile/photo/profile_inputs.h, whose loader reads each path as a
// profile CSV or extracts it as a photo (docs/methods/extraction.md).
//
//   auto flags = std::make_shared<textile::cli::PhotoFlags>();
//   textile::cli::AddPhotoFlags(sub, flags.get());          // --rig, --mm-per-px, --trace, ...
//   sub->callback([flags, inputs] {
//     const textile::PhotoInputOptions o = flags->Options();          // throws InputError
//     for (const auto& in : textile::LoadProfileInputs(*inputs, o)) { ... in.profile ... }
//   });

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <string>

#include "textile/photo/profile_inputs.h"

namespace textile::cli {

// The shared photo flags, as CLI11 binds them (raw strings; Options() validates them).
struct PhotoFlags {
  std::string rig_file, edge, tip, trace = "mid", rig_type = "auto";
  double mm_per_px = 0.0, level_deg = 0.0, step_mm = 0.5;
  bool progress = false, accept_guesses = false, no_shape_check = false;
  CLI::Option *rig_option = nullptr, *scale_option = nullptr, *level_option = nullptr;

  // The options these flags give; throws InputError naming the flag ("--edge-px: ...").
  PhotoInputOptions Options() const;
};

// Adds --rig, --mm-per-px, --trace, --rig-type, --edge-px, --tip-px, --level-deg, --step-mm,
// --accept-guesses, --no-shape-check and --progress to a subcommand, bound to *flags (which must outlive the parse).
void AddPhotoFlags(CLI::App* sub, PhotoFlags* flags);

// "X,Y" in pixels (--edge-px, --tip-px: `flag` names it in the message); throws InputError.
Eigen::Vector2d ParsePixelPoint(const std::string& text, const std::string& flag = "--edge-px");
inline Eigen::Vector2d ParseEdgePx(const std::string& text) { return ParsePixelPoint(text); }

}  // namespace textile::cli

#endif  // TEXTILE_TOOLS_COMMON_PROFILE_INPUTS_H_
