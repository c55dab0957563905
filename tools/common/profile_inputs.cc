#include "common/profile_inputs.h"

#include <cmath>
#include <sstream>

#include "common/cli.h"
#include "textile/sim/core/error.h"

namespace textile::cli {

Eigen::Vector2d ParsePixelPoint(const std::string& text, const std::string& flag) {
  std::stringstream in(text);
  std::string a, b, rest;
  if (!std::getline(in, a, ',') || !std::getline(in, b, ',') || std::getline(in, rest)) {
    throw InputError(flag + ": expected X,Y in pixels, got '" + text + "'");
  }
  Eigen::Vector2d p;
  for (int k = 0; k < 2; ++k) {
    const std::string& s = k == 0 ? a : b;
    char* end = nullptr;
    p[k] = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0' || !std::isfinite(p[k])) {
      throw InputError(flag + ": '" + s + "' is not a number (expected X,Y in pixels)");
    }
  }
  return p;
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
  if (!edge.empty()) e.edge_px = ParsePixelPoint(edge, "--edge-px");
  if (!tip.empty()) e.tip_px = ParsePixelPoint(tip, "--tip-px");
  if (level_option && level_option->count() > 0) e.level_deg = level_deg;
  e.step_mm = step_mm;
  e.accept_guesses = accept_guesses;
  e.check_shape = !no_shape_check;
  o.progress = progress;
  o.on_progress = [always = progress](const std::string& line) { Progress(line, always); };
  std::string why;
  if (!e.Check(&why)) {
    const std::string flag = why.rfind("step", 0) == 0    ? "--step-mm"
                             : why.rfind("level", 0) == 0 ? "--level-deg"
                             : why.rfind("tip", 0) == 0   ? "--tip-px"
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
  sub->add_option("--tip-px", f->tip,
                  "Tip override X,Y [px]: the free end, as the overlay shows it (one photo only; "
                  "a tip fading into the background)");
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
