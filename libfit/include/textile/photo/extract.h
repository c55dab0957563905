#ifndef TEXTILE_PHOTO_EXTRACT_H_
#define TEXTILE_PHOTO_EXTRACT_H_

// Photo of a cantilevered strip -> its profile in the bending plane (docs/spec/cantilever.md,
// "Photo protocol" and "Frame"): millimetres, origin at the platform edge or where the strip leaves
// the clamp, x towards the overhang, y up, s the arc length from the edge.
//
//   cv::Mat photo = textile::ReadPhotoGray("strip.jpg");        // throws InputError
//   textile::ExtractOptions options;                             // mid-line, rig detected
//   const textile::ExtractionSummary r =
//       textile::ExtractProfile(photo, textile::Rig::FromScale(0.1101), options, "strip.jpg");
//   if (!r.success) throw textile::ComputeError(r.message);      // no strip, tip cut off, ...
//   std::string csv = textile::ProfileToCsv(r.profile);
//   cv::Mat overlay = textile::DrawExtractionOverlay(photo, r, 2000);
//
// How (docs/methods/extraction.md): the strip is found on a reduced image (background flattened by
// morphological top-/black-hats, so polarity, gradients and broad shadows do not matter), the
// rig is recognised (a platform block with a horizontal top face, or a strip leaving a clamp
// or the image border), and the silhouette's two boundaries are then located to sub-pixel
// precision at full resolution, on intensity profiles across the strip every pixel of its
// length. Pixel coordinates are OpenCV's: x right, y down, pixel centres at integers.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "textile/fit/profile.h"
#include "textile/fit/shape_check.h"
#include "textile/photo/rig.h"
#include "textile/sim/core/note.h"

namespace textile {

// Which line of the silhouette becomes the profile.
enum class TraceLine {
  kMid,    // half-way between the two boundaries (side-on rigs)
  kUpper,  // the boundary on the strip's top face side (the lit near edge of an oblique view)
  kLower,  // the other boundary
};

// What holds the strip.
enum class RigKind {
  kAuto,      // detect
  kPlatform,  // a block whose top face is horizontal; the edge is its top/front corner
  kClamp,     // the strip leaves a clamp or the image border; horizontal = image rows
};

// Limits on photos, checked from the file header before decoding.
inline constexpr int kMinPhotoSidePx = 32;
inline constexpr int kMaxPhotoSidePx = 40000;
inline constexpr double kMaxPhotoPixels = 64e6;  // 50 MP cameras plus margin

// Profile spacing along the arc [mm]: the default and the range ExtractOptions::Check accepts;
// a profile may not get more points than kMaxExtractedPoints.
inline constexpr double kDefaultStepMm = 0.5;
inline constexpr double kMinStepMm = 0.01;
inline constexpr double kMaxStepMm = 10.0;
inline constexpr int kMaxExtractedPoints = 1000000;

struct ExtractOptions {
  // Which line to trace.
  TraceLine trace = TraceLine::kMid;
  // Force the rig type; a forced platform that is not found is a failure.
  RigKind rig = RigKind::kAuto;
  // Manual origin [px, full resolution]: the edge (platform) or where the strip leaves the
  // clamp. The profile then starts where the traced line crosses the vertical through it.
  std::optional<Eigen::Vector2d> edge_px;
  // Manual tip [px, full resolution]: where the free end is, as the overlay shows the photo. It
  // replaces the search for the end face (a thin tip fading into the background is inferred,
  // and refused, without it): the traced line is cut where it passes the point, or continued
  // straight to it. It must lie within two strip widths of the line or its continuation
  // (else InputError). One photo's tip: a caller loading several photos refuses it.
  std::optional<Eigen::Vector2d> tip_px;
  // Horizontal = image rows turned by this angle [deg], counter-clockwise as seen in the image
  // (a camera rolled clockwise by 1° needs +1). Default: rows (clamp), or the platform's top.
  std::optional<double> level_deg;
  // Spacing of the profile along its arc length [mm], in [kMinStepMm, kMaxStepMm]. A strip
  // that would get fewer than kMinProfilePoints at it (but enough at the default) is refused
  // as bad input, as is one that would get more than kMaxExtractedPoints.
  double step_mm = kDefaultStepMm;
  // Long side of the reduced image on which the strip and the rig are detected [px].
  int detect_side_px = 1000;
  // Wall-time cap [s], checked between the stages: a run past it fails ("time cap ..."), with
  // no profile. A 12 MP photo takes about 0.1 s; 0 stops every run at the first check.
  double max_seconds = 30.0;
  // The physics check of the profile (CheckCantileverShape, 10-40 ms): a profile that is no
  // heavy cantilever within 1 mm RMS fails the run unless accept_guesses.
  bool check_shape = true;
  // Where a stage had to guess (the held end, the tip) or the physics check failed, the run
  // fails naming the flag that settles it (ExtractionConfidence::guesses); true takes the
  // guesses and reports them as warnings (`--accept-guesses`).
  bool accept_guesses = false;

  // True if every field is usable; otherwise *why says which and why.
  bool Check(std::string* why) const;
};

// How far an extracted profile can be trusted (docs/methods/extraction.md, "Confidence").
struct ExtractionConfidence {
  // "found" (a platform, a clamp or the image border holds the strip), "given" (--edge-px) or
  // "guessed" (nothing holds it in view: its higher end was taken).
  std::string held_end;
  std::string held_end_how;  // for people: the rig's detail ("edge at the platform's ...")
  // "found" (the strip's contrast falls off at its end), "given" (tip_px) or "inferred" (it
  // does not fall off: the last measured cross-section was taken as the tip).
  std::string tip;
  // Cross-sections from the origin to the tip whose traced line was measured, 0..1.
  double sections_measured = 0.0;
  // The physics check (ExtractOptions::check_shape): the best single-overhang heavy elastica
  // against the profile; empty when not run.
  std::optional<ShapeCheck> shape;
  // What the run had to take on trust, one phrase each naming what settles it; empty when
  // nothing was guessed. Without accept_guesses a non-empty list fails the run.
  std::vector<std::string> guesses;
};

// Result of one photo. On failure, success is false and message says why (one line);
// the geometry found so far may still be filled in for a diagnostic overlay.
struct ExtractionSummary {
  bool success = false;
  std::string message;
  std::string source;  // the photo, for messages

  Profile profile;                    // frame of docs/spec/cantilever.md [m]
  std::string rig_type;               // "platform" or "clamp"
  std::string rig_detail;             // how the origin was found, for people
  std::string polarity;               // "light" or "dark": the strip against the background
  std::string direction;              // "right" or "left": where the overhang points in the image
  std::string trace;                  // "mid", "upper" or "lower"
  double contrast = 0.0;              // strip minus background, typical [grey levels, 0..255]
  double noise = 0.0;                 // background noise σ after smoothing [grey levels]
  double width_px = 0.0;              // median silhouette width [px]
  double core_width_px = 0.0;         // median width of its solid core (above half the peak) [px]
  double widening = 1.0;              // silhouette width near the tip / near the root
  double length_mm = 0.0;             // arc length from the origin to the tip [mm]
  Eigen::Vector2d tip_mm{0, 0};       // tip in the profile frame [mm]
  double mm_per_px = 0.0;             // local scale at the origin [mm/px]
  double level_deg = 0.0;             // the horizontal used, counter-clockwise from rows [deg]
  int rejected_sections = 0;          // cross-sections dropped as outliers (fibres, specks)
  // Doubts worth a look, one line each, with their codes: other_polarity_band_ignored,
  // held_end_guessed, tip_end_unclear, edge_px_along_strip, border_gap_extrapolated,
  // trace_starts_beyond_edge, oblique_view, low_contrast, sections_rejected, guess_accepted
  // (ExtractOptions::accept_guesses).
  std::vector<Note> warnings;
  ExtractionConfidence confidence;    // filled in when the profile is done
  double seconds = 0.0;               // wall time of the extraction

  // Geometry in full-resolution pixels, for overlays and checks.
  Eigen::Vector2d origin_px{0, 0};
  Eigen::Vector2d tip_px{0, 0};
  std::vector<Eigen::Vector2d> trace_px;            // #N the traced line, origin to tip
  std::vector<Eigen::Vector2d> upper_px, lower_px;  // silhouette boundaries (valid sections)
  std::vector<Eigen::Vector2d> platform_px;         // far end of the top face, corner, bottom of
                                                    // the front face; empty without a platform
  std::vector<std::vector<cv::Point>> blocks_px;    // outlines of clamps/blocks found

  // Two or three lines for people: rig, polarity, direction, length, tip, warnings.
  std::string BriefReport() const;
  // The warnings' texts, in order (what JSON results list as "warnings").
  std::vector<std::string> WarningTexts() const;
};

// Reads a photo as 8-bit grey. The header is checked before anything is decoded: the format
// (PNG, JPEG, TIFF, BMP), the size (kMinPhotoSidePx .. kMaxPhotoSidePx, at most
// kMaxPhotoPixels) and, for PNG and JPEG, that the file is complete. The pixels are the
// sensor's: an EXIF orientation tag is ignored (rigs are calibrated in sensor pixels). Throws
// InputError "<path>: <problem>".
cv::Mat ReadPhotoGray(const std::string& path);

// Extracts the profile from an 8-bit grey photo (CV_8UC1). Throws InputError for bad input
// (wrong image type, options that fail Check, --edge-px outside the photo, a rig that cannot
// map it); returns success = false when the photo does not show what is needed.
ExtractionSummary ExtractProfile(const cv::Mat& gray, const Rig& rig, const ExtractOptions& options,
                                 const std::string& source);

// The photo (grey, as colour, scaled so that its long side is at most max_side_px) with the
// platform or clamp, the origin and the axes, the silhouette, the traced line and the tip.
cv::Mat DrawExtractionOverlay(const cv::Mat& gray, const ExtractionSummary& summary,
                              int max_side_px);

}  // namespace textile

#endif  // TEXTILE_PHOTO_EXTRACT_H_
