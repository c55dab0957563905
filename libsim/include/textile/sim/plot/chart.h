#ifndef TEXTILE_SIM_PLOT_CHART_H_
#define TEXTILE_SIM_PLOT_CHART_H_

// Declarative line/scatter charts rendered to PNG with Cairo (target textile::plot, apart from
// textile::sim so that the physics does not need Cairo): the CLI's plots of
// moment-curvature and stiffness curves, measured vs fitted profiles and benchmark curves.
// Describe what to show; ranges, ticks, legend placement and layout are automatic.
//
//   namespace chart = textile::chart;
//   chart::Panel mk{.title = "Moment-curvature", .x_label = "κ [1/cm]", .y_label = "M [gf·cm/cm]"};
//   mk.series.push_back({.label = "measured", .x = kappa, .y = moment,
//                        .style = chart::Series::Style::kMarkers});
//   mk.series.push_back({.label = "fit", .x = kappa_fit, .y = moment_fit});
//   mk.notes = {"B₀ = 0.12 gf·cm²/cm"};
//   chart::Panel profile{.title = "Profile", .x_label = "x [mm]", .y_label = "z [mm]",
//                        .equal_aspect = true};
//   ...
//   chart::RenderPng({.title = "Sample 3", .columns = 2, .panels = {mk, profile}}, "fit.png");
//
// Points that cannot be drawn (NaN/inf, or ≤ 0 on a log axis) are skipped and break the
// line there; a series with no drawable point is left out (also from the legend), and a
// panel with nothing to draw says "no data".

#include <optional>
#include <string>
#include <vector>

namespace textile::chart {

// A colour; components in [0, 1].
struct Rgb {
  double r = 0, g = 0, b = 0;
};

// Colour i of the Okabe–Ito palette (distinguishable with common colour-vision deficiencies),
// cycling; the default colour of the i-th series of a panel.
Rgb PaletteColor(int index);

struct Series {
  enum class Style { kLine, kMarkers, kLineAndMarkers };

  std::string label;         // legend text; empty: not in the legend
  std::vector<double> x, y;  // #N points each, in the panel's axis units
  Style style = Style::kLine;
  std::optional<Rgb> color;  // default: PaletteColor(index of the series in its panel)
  double line_width = 2.0;   // [px at 1000×700; scaled with the figure]
  bool dashed = false;       // dashed line (e.g. a fit or reference curve)
};

// An axis range [lo, hi], lo < hi, in axis units (positive for log axes).
struct Range {
  double lo = 0, hi = 1;
};

enum class Corner { kAuto, kTopLeft, kTopRight, kBottomLeft, kBottomRight };

struct Panel {
  std::string title;
  std::string x_label, y_label;  // UTF-8, e.g. "κ [1/cm]"
  std::vector<Series> series;
  bool log_x = false, log_y = false;  // decades; points ≤ 0 on a log axis are skipped
  // Same pixels per unit on both axes (profiles in mm); the shorter range is widened.
  // Ignored when either axis is logarithmic.
  bool equal_aspect = false;
  std::optional<Range> x_range, y_range;  // default: all drawable points plus a margin
  Corner legend_corner = Corner::kAuto;   // kAuto: the corner covering the fewest points
  Corner notes_corner = Corner::kAuto;    // kAuto: the emptiest corner the legend left free
  std::vector<std::string> notes;         // text lines in a box, e.g. fitted constants
};

struct Figure {
  std::string title;
  int width_px = 1000, height_px = 700;  // image size [px]
  int columns = 1;                       // panels fill a grid row by row
  std::vector<Panel> panels;

  // False with a reason if the figure cannot be drawn (sizes, mismatched x/y, bad ranges).
  bool Check(std::string* why) const;
};

// Renders the figure and writes it as PNG to `file`, as it is (the CLI stages it in an
// AtomicFile: tools/common/chart_file.h). Errors name shown_path (default: file): InputError if
// it does not end in .png, the figure fails Check() or the file cannot be written.
void RenderPng(const Figure& figure, const std::string& file, const std::string& shown_path = "");
// Throws InputError naming the path unless it ends in .png (any case): callers that stage a
// chart check its name before the work.
void CheckPngPath(const std::string& path);

// ---- Building blocks, exposed for tests ----

struct Ticks {
  std::vector<double> values;       // major ticks, ascending, inside [lo, hi]
  std::vector<std::string> labels;  // one compact label per value ("0.3", "2×10⁸", "10⁻⁶")
  std::vector<double> minor;        // unlabelled ticks (log axes)
};

// Ticks at multiples of a 1-2-5 step (1, 2 or 5 × 10^k), the finest giving at most
// max_count ticks in [lo, hi]. Empty if the range is empty or not finite.
Ticks NiceTicks(double lo, double hi, int max_count);

// Ticks for a log axis over [lo, hi], 0 < lo < hi: every k-th decade (labelled 10ⁿ) if the
// range holds at least two, otherwise 1-2-5 values or NiceTicks; minor ticks in between.
Ticks LogTicks(double lo, double hi, int max_count);

}  // namespace textile::chart

#endif  // TEXTILE_SIM_PLOT_CHART_H_
