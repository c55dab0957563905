#ifndef TEXTILE_FIT_SRC_EXTRACT_INTERNAL_H_
#define TEXTILE_FIT_SRC_EXTRACT_INTERNAL_H_

// Pieces of the photo extractor shared by its source files (extract_*.cc); not public API.

#include <Eigen/Core>
#include <limits>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "deadline.h"
#include "textile/photo/extract.h"
#include "textile/photo/rig.h"
#include "textile/sim/core/note.h"

namespace textile::extract_internal {

using Vec2 = Eigen::Vector2d;

// Median of a non-empty sample (copied: the caller's order is kept).
double Median(std::vector<double> v);

// Gaussian smoothing of a sequence, with the window truncated symmetrically at the ends so that
// straight runs stay straight up to the last point. sigma in samples; <= 0, NaN or infinite
// returns the input.
std::vector<Vec2> SmoothPolyline(const std::vector<Vec2>& p, double sigma);

// Points every `step` along a polyline's arc length, from its first point to its last (which is
// always included).
std::vector<Vec2> ResampleByArc(const std::vector<Vec2>& p, double step);

// Bilinear sample of an 8-bit grey image at (x, y) [px]; false outside the pixel centres' hull.
bool SampleGray(const cv::Mat& gray, double x, double y, double* value);

// 8-connected components of a CV_8U mask: labels (CV_32S) and stats (n × 5 CV_32S, columns
// cv::CC_STAT_LEFT, TOP, WIDTH, HEIGHT, AREA) as cv::connectedComponentsWithStats gives them,
// without the centroids, which cost more than the labelling itself. Returns n, the number of
// labels including the background (0).
int ConnectedComponents(const cv::Mat& mask, cv::Mat* labels, cv::Mat* stats);

// A large region that differs from the background (clamp, platform, fixture), found on the
// reduced image.
struct Block {
  cv::Mat mask;  // CV_8U, reduced-image size, 255 inside
  int sign = 0;  // +1 lighter than the background, -1 darker
  cv::Rect box;  // bounding box on the reduced image
};

// Blocks of the reduced grey image: a smooth (quadratic) background is fitted robustly, and
// regions that differ from it by much more than the noise, are thicker than `min_thickness`
// [px] and cover at least 1 % of the image are returned. `ignore` (CV_8U) marks pixels to leave
// out of the background fit (the strip).
std::vector<Block> FindBlocks(const cv::Mat& small, const cv::Mat& ignore, double min_thickness);

// A platform that does not stand out from the background as a region (a strong light gradient
// or shadow makes its faces as light as the background somewhere), found by its front face
// instead: the straightest long edge of one sign that runs from just below the held, level part
// of the strip's line (`path`, full px) down to the bottom of the reduced image `small`, within
// ±12° of the vertical. `ignore` marks the strip. Returns the region behind that edge and below
// the strip as a block for FitPlatform, or nothing if no edge stands out from the noise.
std::optional<Block> FindBlockByFrontEdge(const cv::Mat& small, const cv::Mat& ignore,
                                          const std::vector<Vec2>& path, double scale,
                                          int direction, double min_thickness);

// A platform found at full resolution: its top face and front face as lines, and their corner.
struct PlatformFit {
  bool found = false;
  std::string why_not;   // when not found
  Vec2 corner{0, 0};     // top/front corner [px]
  Vec2 top_far{0, 0};    // far end of the measured top face [px]
  Vec2 front_low{0, 0};  // low end of the measured front face [px]
  double top_angle = 0;  // top face direction, counter-clockwise from the image rows [rad]
  // The strip lies on the block's top behind its corner (also when not found: a platform
  // that could not be measured).
  bool under_strip = false;
};

// Looks for a platform block under the root of the strip. `block` is on the reduced image
// (scale = reduced px per full px); `direction` is +1 if the overhang points right, -1 left;
// `path` is the strip's coarse centre line [full px], which must pass near the corner; `thickness`
// is the strip's silhouette width [full px].
PlatformFit FitPlatform(const cv::Mat& gray, const Block& block, double scale, int direction,
                        const std::vector<Vec2>& path, double thickness);

// Whether the reduced grey image `small` shows a chessboard (a calibration board given as a strip
// photo): at least 8 dark and 4 light squares of one size, in the Otsu threshold eroded by a
// pixel. Strip photos show none (a strip is one long component).
bool LooksLikeCalibrationBoard(const cv::Mat& small);

// Whether a strip is draped over a block rather than held at one end: its centre line `line`
// (from one end to the other) has both ends more than 3 `thickness` + 5 px below its highest
// point, and its top stretch lies on one of `blocks` (within 2 `thickness` + 4 px above its
// mask); all on the reduced image [px]. Sets `peak` to the highest point. Such a strip lies over
// a whole platform and off its far edge too: not a cantilever from one edge.
bool DrapedOverBlock(const std::vector<Vec2>& line, const std::vector<Block>& blocks,
                     double thickness, Vec2* peak);

// ---------------------------------------------------------------- the stages of ExtractProfile

// The two ends of a band-like mask (a double sweep of geodesic distances) and its length.
struct Sweep {
  cv::Rect box;  // bounding box of the mask
  cv::Point a, b;
  cv::Mat dist_a, dist_b;  // box-sized geodesic distances from a and b [px]
  double length = 0.0;
  // Distance from end a (or b) of image pixel (x, y), which must lie in the box.
  float DistA(int x, int y) const { return dist_a.at<float>(y - box.y, x - box.x); }
  float DistB(int x, int y) const { return dist_b.at<float>(y - box.y, x - box.x); }
};

// A strip candidate on the reduced image.
struct Strip {
  int polarity = 0;        // +1 lighter than the background, -1 darker
  cv::Mat mask;            // CV_8U, reduced-image size
  double score = 0.0;      // length x mean contrast
  double length = 0.0;     // geodesic length [reduced px]
  double thickness = 0.0;  // area / length [reduced px]
};

// One cross-section of the strip at full resolution.
struct Section {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double n_lo = kNaN, n_up = kNaN;    // boundaries along the normal [px] (n_up on the top side)
  double peak = 0.0;                  // contrast at the core [grey levels]
  double bg = 0.0;                    // background level (mean of both sides)
  bool present = false;               // the strip is there (clear contrast at the core)
  bool valid = false;                 // ... and both boundaries were measured
  bool lo_ok = false, up_ok = false;  // each boundary measured and not an outlier
  double solid = 0.0;                 // longest run above half the peak contrast [px]: the
                                      // strip's body, where loose fibres give only short runs
  double solid_mid = kNaN;            // centre of that run along the normal [px]: a steadier
                                      // guide than the mid-line when a faint face comes and goes
  double width() const { return n_up - n_lo; }
  // Whether the line to trace is known here.
  bool Usable(TraceLine line) const {
    return line == TraceLine::kUpper ? up_ok : line == TraceLine::kLower ? lo_ok : lo_ok && up_ok;
  }
};

// Cross-sections of the strip at stations along a guide line.
struct SectionSet {
  std::vector<Vec2> p, t, n;  // #M station [px], unit tangent (root -> tip), unit normal (top side)
  std::vector<Section> s;     // #M
  double noise = 0.0;         // σ of the smoothed background [grey levels]
  double contrast = 0.0;      // median peak contrast of valid sections
  double width = 0.0;         // median width of valid sections [px]
  int rejected = 0;           // sections dropped as outliers
};

// What the extraction of one photo has found so far. ExtractProfile runs the stages below in
// order over one of these; each reads what the stages before it left and adds its part, and
// `summary` collects what goes to the caller (warnings included). Pixels are full-resolution
// unless a field says "reduced".
struct ExtractState {
  ExtractState(const cv::Mat& gray, const Rig& rig, const ExtractOptions& options,
               const std::string& source)
      : gray(gray), rig(rig), options(options), deadline(options.max_seconds) {
    summary.source = source;
  }
  const cv::Mat& gray;  // CV_8UC1, the photo
  const Rig& rig;
  const ExtractOptions& options;
  fit_internal::Deadline deadline;  // started when the state is made
  ExtractionSummary summary;

  // ReduceImages
  double scale = 1.0;  // reduced px per full px
  int mid_factor = 1;  // integer reduction of `mid`; 1: no intermediate level
  cv::Mat mid;         // the photo box-averaged by mid_factor (empty if mid_factor == 1)
  cv::Mat small;       // the detection image (reduced)
  // FindStrip
  cv::Mat light, dark;            // top- and black-hat of `small`
  Strip strip;                    // the chosen strip, cleaned (reduced)
  std::vector<Block> own_blocks;  // thick parts split off the strip (reduced)
  // FindStripBlocks
  Sweep sweep;                // the strip's ends (reduced)
  double t_small = 0.0;       // the strip's thickness [reduced px]
  cv::Mat strip_zone;         // the strip dilated, and its own blocks (reduced)
  std::vector<Block> blocks;  // clamps, platforms, fixtures (reduced)
  // FindHeldEnd
  bool root_is_a = true;  // the held end is sweep.a
  std::string root_how;   // "edge" (--edge-px), "border", "block" or "guess"
  int root_borders = 0;   // image borders at the held end (bits: 1 left, 2 right, 4 top, 8 bottom)
  double end_radius = 0.0;  // what counts as an end of the strip [reduced px]
  // TraceCoarseLine
  std::vector<Vec2> coarse;  // centre line from the held end, every pixel of arc
  double t_full = 0.0;       // the strip's thickness [px]
  int direction = +1;        // +1: the overhang points right in the image, -1 left
  // FindRig
  PlatformFit platform;
  // MeasureSections
  SectionSet set;
  int first = 0, last = -1;  // the measured stretch of `set`
  int measured_from = 0;     // its first station before unusable ones were skipped
  double w_end = 0.0;        // silhouette width just before the end [px]
  // TraceMeasuredLine
  int end_i = 0;            // last station of the traced line (before the end face)
  std::vector<Vec2> trace;  // the traced line, origin to tip [px]
  // PlaceOrigin
  double level = 0.0;  // the horizontal, counter-clockwise from rows [rad]
  // MapToMillimetres
  std::vector<Vec2> curve;  // the traced line from x = 0 to the tip, in the profile frame [mm]
  size_t start = 0;         // first point of `trace` that lies in `curve`
};

// A stage that can fail returns why (one line, for ExtractionSummary::message), or nothing to
// go on.
using StageFailure = std::optional<std::string>;

// Throws InputError for what ExtractProfile refuses before it looks at the pixels: a photo that
// is not 8-bit grey, options that fail Check, --edge-px outside the photo, a rig that cannot map
// the photo.
void CheckExtractInputs(const cv::Mat& gray, const Rig& rig, const ExtractOptions& options,
                        const std::string& source);

// The detection image `small` (long side options.detect_side_px at most) and, for photos over
// 4000 px, the intermediate level `mid`.
void ReduceImages(ExtractState* s);

// The strip on the detection image: the most prominent long thin band of either polarity in
// the top- and black-hats, cleaned (PrepareStrip). Fails with no band, or with a second strip
// beside it (unless --edge-px picks one) or the two overhangs of one strip draped over a
// platform. Warns (other_polarity_band_ignored) of a band of the other polarity almost as
// prominent.
StageFailure FindStrip(ExtractState* s);

// The strip's polarity, ends and thickness, and the blocks (clamps, platforms) around it.
void FindStripBlocks(ExtractState* s);

// Which end is held: the one at a side border, at a block or nearer --edge-px, else the higher
// one (warning held_end_guessed). Fails when the free tip touches an image border.
StageFailure FindHeldEnd(ExtractState* s);

// The coarse centre line from the held end at full resolution, the strip's thickness there and
// the overhang's direction. Fails when the band is too short or is draped over a block.
StageFailure TraceCoarseLine(ExtractState* s);

// The platform under the held end, if any (unless options.rig is kClamp), and the outlines of
// the blocks for the overlay. Fails when a forced platform is not found, or when the strip lies
// on a block that cannot be measured as a platform and would be taken for a clamp.
StageFailure FindRig(ExtractState* s);

// Cross-sections along the strip at full resolution (TrackStrip) and their measured stretch.
// Fails when the edges cannot be measured, or when the line to trace is measured on fewer than
// a quarter of the stations (naming the lines that are measured enough).
StageFailure MeasureSections(ExtractState* s);

// The traced line from the measured offsets, gaps bridged and smoothed, up to where the end face
// begins; and the silhouette's boundaries for the overlay.
void TraceMeasuredLine(ExtractState* s);

// The tip: the traced line continued to where the strip's solid core ends (warning
// tip_end_unclear when it does not). Fails when the tip is cut off by, or too near, the border.
StageFailure FindTipEnd(ExtractState* s);

// With tip_px (FindTipEnd calls it): the line cut where it passes the given tip, or continued
// straight to it along `tangent` (the line's direction at its end). Throws InputError when the
// tip lies more than two strip widths off the line or its continuation.
StageFailure TakeGivenTip(ExtractState* s, const Vec2& tangent);

// With --edge-px: throws InputError if the edge lies far from the strip; warns
// (edge_px_along_strip) if it lies well along a strip that already bends there.
void CheckEdgeGiven(const ExtractState& s, std::vector<Note>* warnings);

// The rig type, the origin and the horizontal: the platform's corner and top, where the strip
// leaves the border (warning border_gap_extrapolated when far), the held end, or --edge-px.
// Fails when the strip leaves the border too steeply to place the origin.
StageFailure PlaceOrigin(ExtractState* s);

// The traced line in the profile frame [mm] from where it crosses x = 0 (bridged by a level
// parabola on a platform; warning trace_starts_beyond_edge when it starts far beyond). Fails
// when the strip does not reach past the edge.
StageFailure MapToMillimetres(ExtractState* s);

// The profile resampled every options.step_mm along the arc, its length and tip; the overlay's
// traced line. Throws InputError when the step gives too many points, or too few for a strip
// that has enough at the default step.
void AssembleProfile(ExtractState* s);

// Doubts about the silhouette, as warnings: oblique_view (widening or faint face),
// low_contrast, sections_rejected; sets widening, core_width_px and rejected_sections.
void DiagnoseSilhouette(ExtractState* s);

// Fails when the profile has too few points or is not a hanging strip (CheckProfile).
StageFailure CheckResult(const ExtractState& s);

// The confidence report of a finished profile (extract_confidence.cc): how the held end and
// the tip were found, the fraction of sections measured, the physics check (with
// options.check_shape) and the guesses, each naming what settles it.
ExtractionConfidence AssessConfidence(const ExtractState& s);

// Fails, listing the guesses, unless options.accept_guesses; with it, each guess is added to
// *warnings (code guess_accepted). Nothing to do without guesses.
StageFailure RefuseGuesses(const ExtractionConfidence& confidence, const ExtractOptions& options,
                           std::vector<Note>* warnings);

}  // namespace textile::extract_internal

#endif  // TEXTILE_FIT_SRC_EXTRACT_INTERNAL_H_
