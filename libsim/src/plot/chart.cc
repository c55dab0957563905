#include "textile/sim/plot/chart.h"

#include <cairo.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <tuple>

#include "textile/sim/core/error.h"

namespace textile::chart {
namespace {

// ---- Tick values and labels (no Cairo) ----

// m × 10^e computed so that e.g. 3 × 10⁻¹ is the double nearest 0.3, not 0.30000000000000004.
double Scaled(double m, int e) { return e >= 0 ? m * std::pow(10.0, e) : m / std::pow(10.0, -e); }

std::string Superscript(int n) {
  static const std::array<const char*, 10> kDigits = {"⁰", "¹", "²", "³", "⁴",
                                                      "⁵", "⁶", "⁷", "⁸", "⁹"};
  std::string s = n < 0 ? "⁻" : "";
  for (char c : std::to_string(std::abs(n))) s += kDigits[c - '0'];
  return s;
}

// Typeset a leading '-' as a minus sign, which is as wide as the digits.
std::string WithMinusSign(std::string s) {
  if (!s.empty() && s[0] == '-') s.replace(0, 1, "−");
  return s;
}

std::string Fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return WithMinusSign(buf);
}

// v as "m×10ⁿ" with enough mantissa digits to resolve 10^resolution_exp.
std::string Scientific(double v, int resolution_exp) {
  const int e = static_cast<int>(std::floor(std::log10(std::abs(v))));
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*e", std::clamp(e - resolution_exp, 0, 15), v);
  const std::string s(buf);
  const size_t pos = s.find('e');
  std::string mantissa = s.substr(0, pos);
  // Each value keeps only the digits it needs: 1×10⁹ next to 1.2×10⁹, not 1.0×10⁹.
  if (mantissa.find('.') != std::string::npos) {
    mantissa.erase(mantissa.find_last_not_of('0') + 1);
    if (mantissa.back() == '.') mantissa.pop_back();
  }
  return WithMinusSign(mantissa) + "×10" + Superscript(std::stoi(s.substr(pos + 1)));
}

// Labels for values on a grid of spacing 10^step_exp (times 1, 2 or 5): fixed-point with the
// decimals the step needs, or scientific when the values are very large or very small.
std::string Label(double v, int step_exp, double axis_max_abs) {
  if (v == 0) return "0";
  const int magnitude = static_cast<int>(std::floor(std::log10(axis_max_abs)));
  if (magnitude >= 6 || magnitude <= -4) return Scientific(v, step_exp);
  return Fixed(v, std::max(0, -step_exp));
}

double MaxAbs(const std::vector<double>& values) {
  double m = 0;
  for (double v : values) m = std::max(m, std::abs(v));
  return m;
}

// ---- Geometry ----

struct Px {
  double x = 0, y = 0;
};

struct Rect {
  double x = 0, y = 0, w = 0, h = 0;
  double right() const { return x + w; }
  double bottom() const { return y + h; }
  bool Contains(Px p) const { return p.x >= x && p.x <= right() && p.y >= y && p.y <= bottom(); }
  Rect Inset(double d) const { return {x + d, y + d, w - 2 * d, h - 2 * d}; }
};

// Clips segment a→b to r (Liang–Barsky); false if nothing is left. Keeps Cairo's
// fixed-point coordinates in range when a point lies far outside the axes.
bool ClipSegment(const Rect& r, Px* a, Px* b) {
  const double dx = b->x - a->x, dy = b->y - a->y;
  double t0 = 0, t1 = 1;
  const std::array<double, 4> p = {-dx, dx, -dy, dy};
  const std::array<double, 4> q = {a->x - r.x, r.right() - a->x, a->y - r.y, r.bottom() - a->y};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0) return false;
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
    if (t0 > t1) return false;
  }
  const Px a0 = *a;
  *a = {a0.x + t0 * dx, a0.y + t0 * dy};
  *b = {a0.x + t1 * dx, a0.y + t1 * dy};
  return true;
}

// Cairo stops drawing for good after invalid UTF-8; labels may come from file names.
std::string ValidUtf8(const std::string& s) {
  std::string out;
  size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    const int n = c < 0x80           ? 1
                  : (c >> 5) == 0x6  ? 2
                  : (c >> 4) == 0xE  ? 3
                  : (c >> 3) == 0x1E ? 4
                                     : 0;
    bool ok = n > 0 && i + n <= s.size();
    for (int k = 1; ok && k < n; ++k) ok = (static_cast<unsigned char>(s[i + k]) >> 6) == 0x2;
    if (ok && c != 0) {
      out.append(s, i, n);
      i += n;
    } else {
      out += '?';
      ++i;
    }
  }
  return out;
}

// ---- Axes ----

struct Axis {
  bool log = false;
  double lo = 0, hi = 1;  // [axis units]

  double ToAxis(double v) const { return log ? std::log10(v) : v; }
  bool Drawable(double v) const { return std::isfinite(v) && (!log || v > 0); }
  // Fraction of the way from lo to hi, in drawing space.
  double Fraction(double v) const { return (ToAxis(v) - ToAxis(lo)) / (ToAxis(hi) - ToAxis(lo)); }
};

struct Bounds {
  double x_lo = HUGE_VAL, x_hi = -HUGE_VAL, y_lo = HUGE_VAL, y_hi = -HUGE_VAL;
  bool empty() const { return x_lo > x_hi; }
};

// Range shown for data in [lo, hi] (in drawing space, i.e. log10 for log axes): a 4% margin
// so points do not sit on the frame; a single value is widened to a visible interval.
Range AutoRange(double lo, double hi, bool log) {
  if (log) {
    lo = std::log10(lo);
    hi = std::log10(hi);
  }
  double margin = 0.04 * (hi - lo);
  if (!(hi - lo > 1e-12 * std::max(std::abs(lo), std::abs(hi)))) {
    margin = log ? 0.5 : (lo != 0 ? 0.1 * std::abs(lo) : 1.0);
  }
  lo -= margin;
  hi += margin;
  if (log) return {std::pow(10.0, lo), std::pow(10.0, hi)};
  return {lo, hi};
}

// ---- Drawing ----

constexpr Rgb kText = {0.13, 0.13, 0.13};
constexpr Rgb kAxisColor = {0.27, 0.27, 0.27};
constexpr Rgb kGrid = {0.87, 0.87, 0.87};
constexpr Rgb kMinorGrid = {0.94, 0.94, 0.94};
constexpr Rgb kMuted = {0.55, 0.55, 0.55};

enum class HAlign { kLeft, kCenter, kRight };
enum class VAlign { kTop, kCenter, kBaseline };

struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};

// A Cairo context plus the figure's scale, with text helpers.
class Canvas {
 public:
  Canvas(cairo_t* cr, double scale) : cr_(cr), s_(scale) {}
  cairo_t* cr() const { return cr_; }
  double s() const { return s_; }  // figure scale: 1 at 1000×700

  void Color(Rgb c, double alpha = 1) { cairo_set_source_rgba(cr_, c.r, c.g, c.b, alpha); }
  void Font(double size_px, bool bold = false) {
    cairo_select_font_face(cr_, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr_, size_px * s_);
  }
  double TextWidth(const std::string& text) {
    cairo_text_extents_t e;
    cairo_text_extents(cr_, ValidUtf8(text).c_str(), &e);
    return e.x_advance;
  }
  double CapHeight() {
    cairo_text_extents_t e;
    cairo_text_extents(cr_, "H", &e);
    return -e.y_bearing;
  }
  double LineHeight() {
    cairo_font_extents_t e;
    cairo_font_extents(cr_, &e);
    return e.ascent + e.descent;
  }
  // Draws text anchored at (x, y); kTop/kCenter align to the capital height.
  void Text(const std::string& text, double x, double y, HAlign h, VAlign v) {
    const std::string t = ValidUtf8(text);
    const double w = TextWidth(t);
    if (h == HAlign::kCenter) x -= w / 2;
    if (h == HAlign::kRight) x -= w;
    if (v == VAlign::kTop) y += CapHeight();
    if (v == VAlign::kCenter) y += CapHeight() / 2;
    cairo_move_to(cr_, x, y);
    cairo_show_text(cr_, t.c_str());
  }
  // Width of hairlines (frame, grid, ticks): whole pixels so they stay crisp.
  double Hairline() const { return std::max(1.0, std::round(s_)); }
  // Coordinate of a crisp hairline near v.
  double Snap(double v) const {
    return static_cast<int>(Hairline()) % 2 ? std::floor(v) + 0.5 : std::round(v);
  }
  void Line(double x0, double y0, double x1, double y1) {
    cairo_move_to(cr_, x0, y0);
    cairo_line_to(cr_, x1, y1);
    cairo_stroke(cr_);
  }
  void RoundedRect(const Rect& r, double radius) {
    cairo_new_sub_path(cr_);
    cairo_arc(cr_, r.right() - radius, r.y + radius, radius, -M_PI / 2, 0);
    cairo_arc(cr_, r.right() - radius, r.bottom() - radius, radius, 0, M_PI / 2);
    cairo_arc(cr_, r.x + radius, r.bottom() - radius, radius, M_PI / 2, M_PI);
    cairo_arc(cr_, r.x + radius, r.y + radius, radius, M_PI, 3 * M_PI / 2);
    cairo_close_path(cr_);
  }

 private:
  cairo_t* cr_;
  double s_;
};

// Font sizes [px at scale 1].
constexpr double kFigureTitleSize = 19;
constexpr double kPanelTitleSize = 15;
constexpr double kLabelSize = 13.5;
constexpr double kTickSize = 12;
constexpr double kLegendSize = 12.5;

bool HasLine(Series::Style s) { return s != Series::Style::kMarkers; }
bool HasMarkers(Series::Style s) { return s != Series::Style::kLine; }
double MarkerRadius(const Series& s, double scale) {
  return (HasLine(s.style) ? 1.5 : 1.75) * s.line_width * scale;
}

Ticks ChooseTicks(Canvas& c, const Axis& axis, double length_px, bool horizontal) {
  // Aim for a tick every ~100 px along x and ~60 px along y; fewer if x labels would touch.
  const double spacing = (horizontal ? 100 : 60) * c.s();
  int max_count = std::clamp(static_cast<int>(length_px / spacing) + 1, 2, 11);
  c.Font(kTickSize);
  Ticks t;
  for (; max_count >= 2; --max_count) {
    t = axis.log ? LogTicks(axis.lo, axis.hi, max_count) : NiceTicks(axis.lo, axis.hi, max_count);
    if (!horizontal) break;
    bool fits = true;
    for (size_t i = 1; i < t.values.size(); ++i) {
      const double gap = (axis.Fraction(t.values[i]) - axis.Fraction(t.values[i - 1])) * length_px;
      const double need = (c.TextWidth(t.labels[i]) + c.TextWidth(t.labels[i - 1])) / 2;
      fits = fits && gap >= need + 14 * c.s();
    }
    if (fits) break;
  }
  return t;
}

double MaxLabelWidth(Canvas& c, const Ticks& t) {
  c.Font(kTickSize);
  double w = 0;
  for (const auto& l : t.labels) w = std::max(w, c.TextWidth(l));
  return w;
}

struct PanelLayout {
  Rect plot;
  Axis x, y;
  Ticks x_ticks, y_ticks;
};

// Fits the plot area into the cell around its titles, tick labels and axis labels, and, for
// equal aspect, widens one range (or shrinks the plot if that range is fixed).
PanelLayout Layout(Canvas& c, const Panel& panel, const Rect& cell, const Bounds& data) {
  const double s = c.s();
  const double pad = 10 * s, tick_len = 5 * s;
  c.Font(kPanelTitleSize, true);
  const double title_h = panel.title.empty() ? 0 : c.LineHeight() + 6 * s;
  c.Font(kLabelSize);
  const double label_h = c.LineHeight();
  c.Font(kTickSize);
  const double tick_h = c.LineHeight();

  PanelLayout L;
  L.x.log = panel.log_x;
  L.y.log = panel.log_y;
  const Range base_x = panel.x_range ? *panel.x_range : AutoRange(data.x_lo, data.x_hi, L.x.log);
  const Range base_y = panel.y_range ? *panel.y_range : AutoRange(data.y_lo, data.y_hi, L.y.log);
  const bool equal_aspect = panel.equal_aspect && !panel.log_x && !panel.log_y;

  const double top = pad + title_h + tick_h / 2;
  const double bottom =
      pad + tick_len + 5 * s + tick_h + (panel.x_label.empty() ? 0 : 4 * s + label_h);
  double left = pad + 40 * s, right = 2 * pad;
  // Tick labels depend on the plot size and the plot size on their width: iterate.
  for (int pass = 0; pass < 3; ++pass) {
    L.plot = {std::round(cell.x + left), std::round(cell.y + top), 0, 0};
    L.plot.w = std::max(10.0, std::round(cell.right() - right) - L.plot.x);
    L.plot.h = std::max(10.0, std::round(cell.bottom() - bottom) - L.plot.y);
    L.x.lo = base_x.lo, L.x.hi = base_x.hi;
    L.y.lo = base_y.lo, L.y.hi = base_y.hi;
    if (equal_aspect) {
      const double ux = L.plot.w / (L.x.hi - L.x.lo), uy = L.plot.h / (L.y.hi - L.y.lo);
      const bool widen_x = ux > uy;  // x is drawn more zoomed in: give it more range
      const bool fixed = widen_x ? panel.x_range.has_value() : panel.y_range.has_value();
      const double u = std::min(ux, uy);
      Axis& a = widen_x ? L.x : L.y;
      const double length = widen_x ? L.plot.w : L.plot.h;
      if (!fixed) {
        const double mid = (a.lo + a.hi) / 2, half = length / u / 2;
        a.lo = mid - half, a.hi = mid + half;
      } else if (widen_x) {
        const double w = std::round((L.x.hi - L.x.lo) * uy);
        L.plot.x += std::round((L.plot.w - w) / 2), L.plot.w = w;
      } else {
        const double h = std::round((L.y.hi - L.y.lo) * ux);
        L.plot.y += std::round((L.plot.h - h) / 2), L.plot.h = h;
      }
    }
    L.x_ticks = ChooseTicks(c, L.x, L.plot.w, true);
    L.y_ticks = ChooseTicks(c, L.y, L.plot.h, false);
    left = pad + (panel.y_label.empty() ? 0 : label_h + 8 * s) + MaxLabelWidth(c, L.y_ticks) +
           tick_len + 5 * s;
    c.Font(kTickSize);
    const double last_w = L.x_ticks.labels.empty() ? 0 : c.TextWidth(L.x_ticks.labels.back());
    right = std::max(2 * pad, last_w / 2 + 4 * s);
  }
  return L;
}

Px ToPx(const PanelLayout& L, double x, double y) {
  return {L.plot.x + L.x.Fraction(x) * L.plot.w, L.plot.bottom() - L.y.Fraction(y) * L.plot.h};
}

// Minor gridlines help reading a log axis only where decades are wide; elsewhere they are
// noise and the minor tick marks suffice.
bool MinorGridlines(const Axis& axis, double length_px, double scale) {
  return axis.log && length_px / std::log10(axis.hi / axis.lo) >= 150 * scale;
}

void DrawGrid(Canvas& c, const PanelLayout& L) {
  cairo_t* cr = c.cr();
  cairo_set_line_width(cr, c.Hairline());
  c.Color(kMinorGrid);
  if (MinorGridlines(L.x, L.plot.w, c.s())) {
    for (double v : L.x_ticks.minor) {
      const double px = c.Snap(ToPx(L, v, L.y.lo).x);
      c.Line(px, L.plot.y, px, L.plot.bottom());
    }
  }
  if (MinorGridlines(L.y, L.plot.h, c.s())) {
    for (double v : L.y_ticks.minor) {
      const double py = c.Snap(ToPx(L, L.x.lo, v).y);
      c.Line(L.plot.x, py, L.plot.right(), py);
    }
  }
  c.Color(kGrid);
  for (double v : L.x_ticks.values) {
    const double px = c.Snap(ToPx(L, v, L.y.lo).x);
    c.Line(px, L.plot.y, px, L.plot.bottom());
  }
  for (double v : L.y_ticks.values) {
    const double py = c.Snap(ToPx(L, L.x.lo, v).y);
    c.Line(L.plot.x, py, L.plot.right(), py);
  }
}

void DrawFrameAndTicks(Canvas& c, const PanelLayout& L) {
  cairo_t* cr = c.cr();
  const double s = c.s(), hw = c.Hairline();
  const double x0 = c.Snap(L.plot.x), x1 = c.Snap(L.plot.right());
  const double y0 = c.Snap(L.plot.y), y1 = c.Snap(L.plot.bottom());
  c.Color(kAxisColor);
  cairo_set_line_width(cr, hw);
  cairo_rectangle(cr, x0, y0, x1 - x0, y1 - y0);
  cairo_stroke(cr);
  const double major = 5 * s, minor = 3 * s;
  for (double v : L.x_ticks.values)
    c.Line(c.Snap(ToPx(L, v, L.y.lo).x), y1, c.Snap(ToPx(L, v, L.y.lo).x), y1 + major);
  for (double v : L.x_ticks.minor)
    c.Line(c.Snap(ToPx(L, v, L.y.lo).x), y1, c.Snap(ToPx(L, v, L.y.lo).x), y1 + minor);
  for (double v : L.y_ticks.values)
    c.Line(x0 - major, c.Snap(ToPx(L, L.x.lo, v).y), x0, c.Snap(ToPx(L, L.x.lo, v).y));
  for (double v : L.y_ticks.minor)
    c.Line(x0 - minor, c.Snap(ToPx(L, L.x.lo, v).y), x0, c.Snap(ToPx(L, L.x.lo, v).y));

  c.Font(kTickSize);
  c.Color(kText);
  for (size_t i = 0; i < L.x_ticks.values.size(); ++i) {
    c.Text(L.x_ticks.labels[i], ToPx(L, L.x_ticks.values[i], L.y.lo).x, y1 + major + 5 * s,
           HAlign::kCenter, VAlign::kTop);
  }
  for (size_t i = 0; i < L.y_ticks.values.size(); ++i) {
    c.Text(L.y_ticks.labels[i], x0 - major - 5 * s, ToPx(L, L.x.lo, L.y_ticks.values[i]).y,
           HAlign::kRight, VAlign::kCenter);
  }
}

void DrawAxisLabels(Canvas& c, const Panel& panel, const Rect& cell, const Rect& plot) {
  const double s = c.s(), pad = 10 * s;
  c.Color(kText);
  c.Font(kPanelTitleSize, true);
  if (!panel.title.empty()) {
    c.Text(panel.title, plot.x + plot.w / 2, cell.y + pad, HAlign::kCenter, VAlign::kTop);
  }
  c.Font(kLabelSize);
  cairo_font_extents_t fe;
  cairo_font_extents(c.cr(), &fe);
  if (!panel.x_label.empty()) {
    c.Text(panel.x_label, plot.x + plot.w / 2, cell.bottom() - pad - fe.descent, HAlign::kCenter,
           VAlign::kBaseline);
  }
  if (!panel.y_label.empty()) {
    cairo_save(c.cr());
    cairo_translate(c.cr(), cell.x + pad + fe.ascent, plot.y + plot.h / 2);
    cairo_rotate(c.cr(), -M_PI / 2);
    c.Text(panel.y_label, 0, 0, HAlign::kCenter, VAlign::kBaseline);
    cairo_restore(c.cr());
  }
}

// Samples of where ink lands, to keep the legend and notes off the data.
void AddSamples(Px a, Px b, double step, std::vector<Px>* ink) {
  const int n = std::clamp(static_cast<int>(std::hypot(b.x - a.x, b.y - a.y) / step), 1, 1000);
  for (int i = 0; i <= n; ++i) {
    const double t = static_cast<double>(i) / n;
    ink->push_back({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)});
  }
}

void DrawMarker(Canvas& c, Px p, double radius) {
  cairo_new_sub_path(c.cr());
  cairo_arc(c.cr(), p.x, p.y, radius, 0, 2 * M_PI);
  cairo_fill(c.cr());
}

void DrawSeries(Canvas& c, const PanelLayout& L, const Series& series, Rgb color,
                std::vector<Px>* ink) {
  cairo_t* cr = c.cr();
  const double lw = series.line_width * c.s();
  c.Color(color);
  const size_t n = series.x.size();
  auto drawable = [&](size_t i) {
    return i < n && L.x.Drawable(series.x[i]) && L.y.Drawable(series.y[i]);
  };
  // Lines may run a little past the frame (they are clipped there) but never far.
  const Rect bounds = L.plot.Inset(-4 * lw - 10);

  if (HasLine(series.style)) {
    cairo_save(cr);
    cairo_set_line_width(cr, lw);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_set_line_cap(cr, series.dashed ? CAIRO_LINE_CAP_BUTT : CAIRO_LINE_CAP_ROUND);
    if (series.dashed) {
      const std::array<double, 2> dash = {3.5 * lw + 2 * c.s(), 2.5 * lw};
      cairo_set_dash(cr, dash.data(), 2, 0);
    }
    cairo_new_path(cr);
    std::optional<Px> pen;  // end of the current subpath
    for (size_t i = 1; i < n; ++i) {
      if (!drawable(i - 1) || !drawable(i)) continue;
      Px a = ToPx(L, series.x[i - 1], series.y[i - 1]), b = ToPx(L, series.x[i], series.y[i]);
      const bool finite =
          std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(b.x) && std::isfinite(b.y);
      if (!finite || !ClipSegment(bounds, &a, &b)) continue;
      if (!pen || pen->x != a.x || pen->y != a.y) cairo_move_to(cr, a.x, a.y);
      cairo_line_to(cr, b.x, b.y);
      pen = b;
      AddSamples(a, b, 3 * c.s(), ink);
    }
    cairo_stroke(cr);
    cairo_restore(cr);
  }
  for (size_t i = 0; i < n; ++i) {
    if (!drawable(i)) continue;
    // A point with no drawable neighbour would be invisible on a line: give it a dot.
    const bool isolated = (i == 0 || !drawable(i - 1)) && !drawable(i + 1);
    if (!HasMarkers(series.style) && !isolated) continue;
    const Px p = ToPx(L, series.x[i], series.y[i]);
    if (!bounds.Contains(p)) continue;
    DrawMarker(c, p, HasMarkers(series.style) ? MarkerRadius(series, c.s()) : 1.25 * lw);
    ink->push_back(p);
  }
}

// A legend or notes box placed in a corner of the plot.
struct Box {
  double w = 0, h = 0;
};

Rect PlaceInCorner(const Rect& plot, const Box& box, Corner corner, double inset) {
  const bool left = corner == Corner::kTopLeft || corner == Corner::kBottomLeft;
  const bool top = corner == Corner::kTopLeft || corner == Corner::kTopRight;
  return {std::round(left ? plot.x + inset : plot.right() - inset - box.w),
          std::round(top ? plot.y + inset : plot.bottom() - inset - box.h), box.w, box.h};
}

// The requested corner, or the one whose box would cover the least ink (ties in reading order
// of preference: top right, top left, bottom right, bottom left).
Corner ChooseCorner(Corner wanted, const Rect& plot, const Box& box, double inset,
                    const std::vector<Px>& ink, Corner taken) {
  if (wanted != Corner::kAuto) return wanted;
  Corner best = Corner::kAuto;
  size_t best_count = 0;
  for (Corner corner :
       {Corner::kTopRight, Corner::kTopLeft, Corner::kBottomRight, Corner::kBottomLeft}) {
    if (corner == taken) continue;
    const Rect r = PlaceInCorner(plot, box, corner, inset).Inset(-inset / 2);
    const auto count = static_cast<size_t>(
        std::count_if(ink.begin(), ink.end(), [&](Px p) { return r.Contains(p); }));
    if (best == Corner::kAuto || count < best_count) best = corner, best_count = count;
  }
  return best;
}

void DrawBoxBackground(Canvas& c, const Rect& r) {
  c.RoundedRect(r.Inset(0.5), 3 * c.s());
  c.Color({1, 1, 1}, 0.88);
  cairo_fill_preserve(c.cr());
  c.Color({0.8, 0.8, 0.8});
  cairo_set_line_width(c.cr(), 1);
  cairo_stroke(c.cr());
}

struct LegendEntry {
  const Series* series;
  Rgb color;
};

Corner DrawLegend(Canvas& c, const Panel& panel, const PanelLayout& L,
                  const std::vector<LegendEntry>& entries, const std::vector<Px>& ink) {
  if (entries.empty()) return Corner::kAuto;
  const double s = c.s(), pad = 8 * s, sample_w = 30 * s, gap = 8 * s;
  c.Font(kLegendSize);
  const double row_h = 1.5 * kLegendSize * s;
  double text_w = 0;
  for (const auto& e : entries) text_w = std::max(text_w, c.TextWidth(e.series->label));
  const Box box{std::ceil(2 * pad + sample_w + gap + text_w),
                std::ceil(2 * pad + entries.size() * row_h - (row_h - c.CapHeight()) + 2 * s)};
  const Corner corner = ChooseCorner(panel.legend_corner, L.plot, box, 10 * s, ink, Corner::kAuto);
  const Rect r = PlaceInCorner(L.plot, box, corner, 10 * s);
  DrawBoxBackground(c, r);
  double y = r.y + pad + c.CapHeight() / 2 + s;
  for (const auto& e : entries) {
    const Series& series = *e.series;
    const double x0 = r.x + pad, xm = x0 + sample_w / 2;
    c.Color(e.color);
    if (HasLine(series.style)) {
      cairo_save(c.cr());
      cairo_set_line_width(c.cr(), series.line_width * s);
      if (series.dashed) {
        const double lw = series.line_width * s;
        const std::array<double, 2> dash = {3.5 * lw + 2 * s, 2.5 * lw};
        cairo_set_dash(c.cr(), dash.data(), 2, 0);
      }
      c.Line(x0, y, x0 + sample_w, y);
      cairo_restore(c.cr());
    }
    if (HasMarkers(series.style)) DrawMarker(c, {xm, y}, MarkerRadius(series, s));
    c.Color(kText);
    c.Font(kLegendSize);
    c.Text(series.label, x0 + sample_w + gap, y, HAlign::kLeft, VAlign::kCenter);
    y += row_h;
  }
  return corner;
}

void DrawNotes(Canvas& c, const Panel& panel, const PanelLayout& L, const std::vector<Px>& ink,
               Corner legend_corner) {
  if (panel.notes.empty()) return;
  const double s = c.s(), pad = 8 * s;
  c.Font(kLegendSize);
  const double row_h = 1.45 * kLegendSize * s;
  double text_w = 0;
  for (const auto& line : panel.notes) text_w = std::max(text_w, c.TextWidth(line));
  const Box box{std::ceil(2 * pad + text_w),
                std::ceil(2 * pad + panel.notes.size() * row_h - (row_h - c.CapHeight()) + 2 * s)};
  const Corner corner = ChooseCorner(panel.notes_corner, L.plot, box, 10 * s, ink, legend_corner);
  const Rect r = PlaceInCorner(L.plot, box, corner, 10 * s);
  DrawBoxBackground(c, r);
  c.Color(kText);
  double y = r.y + pad + s;
  for (const auto& line : panel.notes) {
    c.Text(line, r.x + pad, y, HAlign::kLeft, VAlign::kTop);
    y += row_h;
  }
}

Bounds DataBounds(const Panel& panel) {
  const Axis x{panel.log_x}, y{panel.log_y};
  Bounds b;
  for (const auto& series : panel.series) {
    for (size_t i = 0; i < series.x.size(); ++i) {
      if (!x.Drawable(series.x[i]) || !y.Drawable(series.y[i])) continue;
      b.x_lo = std::min(b.x_lo, series.x[i]), b.x_hi = std::max(b.x_hi, series.x[i]);
      b.y_lo = std::min(b.y_lo, series.y[i]), b.y_hi = std::max(b.y_hi, series.y[i]);
    }
  }
  return b;
}

void DrawPanel(Canvas& c, const Panel& panel, const Rect& cell) {
  Bounds data = DataBounds(panel);
  if (data.empty()) {
    // Still lay out the axes so the panel reads as "this plot, empty".
    Panel frame_only = panel;
    frame_only.series.clear();
    frame_only.x_range = frame_only.y_range = std::nullopt;
    frame_only.log_x = frame_only.log_y = false;
    PanelLayout L = Layout(c, frame_only, cell, {0, 1, 0, 1});
    L.x_ticks = L.y_ticks = {};
    DrawFrameAndTicks(c, L);
    DrawAxisLabels(c, panel, cell, L.plot);
    c.Font(kPanelTitleSize);
    c.Color(kMuted);
    c.Text("no data", L.plot.x + L.plot.w / 2, L.plot.y + L.plot.h / 2, HAlign::kCenter,
           VAlign::kCenter);
    return;
  }
  const PanelLayout L = Layout(c, panel, cell, data);
  DrawGrid(c, L);

  std::vector<Px> ink;
  std::vector<LegendEntry> legend;
  cairo_save(c.cr());
  cairo_rectangle(c.cr(), L.plot.x, L.plot.y, L.plot.w, L.plot.h);
  cairo_clip(c.cr());
  for (size_t i = 0; i < panel.series.size(); ++i) {
    const Series& series = panel.series[i];
    const Rgb color = series.color.value_or(PaletteColor(static_cast<int>(i)));
    const size_t before = ink.size();
    DrawSeries(c, L, series, color, &ink);
    if (!series.label.empty() && ink.size() > before) legend.push_back({&series, color});
  }
  cairo_restore(c.cr());

  DrawFrameAndTicks(c, L);
  DrawAxisLabels(c, panel, cell, L.plot);
  const Corner legend_corner = DrawLegend(c, panel, L, legend, ink);
  DrawNotes(c, panel, L, ink, legend_corner);
}

void Draw(cairo_t* cr, const Figure& figure) {
  // Text and lines grow with the image, but never below a readable size.
  const double scale = std::clamp(
      std::sqrt(static_cast<double>(figure.width_px) * figure.height_px / (1000.0 * 700.0)), 0.85,
      3.0);
  Canvas c(cr, scale);
  cairo_font_options_t* fo = cairo_font_options_create();
  cairo_font_options_set_antialias(fo, CAIRO_ANTIALIAS_GRAY);
  cairo_font_options_set_hint_metrics(fo, CAIRO_HINT_METRICS_OFF);
  cairo_set_font_options(cr, fo);
  cairo_font_options_destroy(fo);
  cairo_set_antialias(cr, CAIRO_ANTIALIAS_GOOD);

  c.Color({1, 1, 1});
  cairo_paint(cr);

  Rect area{0, 0, static_cast<double>(figure.width_px), static_cast<double>(figure.height_px)};
  area = area.Inset(6 * scale);
  if (!figure.title.empty()) {
    c.Font(kFigureTitleSize, true);
    c.Color(kText);
    const double h = c.LineHeight();
    c.Text(figure.title, area.x + area.w / 2, area.y + 6 * scale, HAlign::kCenter, VAlign::kTop);
    area.y += h + 8 * scale;
    area.h -= h + 8 * scale;
  }
  const int n = static_cast<int>(figure.panels.size());
  const int columns = std::min(figure.columns, n);
  const int rows = (n + columns - 1) / columns;
  for (int i = 0; i < n; ++i) {
    const double w = area.w / columns, h = area.h / rows;
    const int row = i / columns, column = i % columns;  // the panel's place, row by row
    const Rect cell{area.x + column * w, area.y + row * h, w, h};
    DrawPanel(c, figure.panels[i], cell);
  }
}

}  // namespace

Rgb PaletteColor(int index) {
  // Okabe & Ito (2008), "Color Universal Design", without yellow (too faint on white).
  static const std::array<Rgb, 7> kPalette = {{
      {0 / 255., 114 / 255., 178 / 255.},    // blue
      {213 / 255., 94 / 255., 0 / 255.},     // vermillion
      {0 / 255., 158 / 255., 115 / 255.},    // bluish green
      {204 / 255., 121 / 255., 167 / 255.},  // reddish purple
      {230 / 255., 159 / 255., 0 / 255.},    // orange
      {86 / 255., 180 / 255., 233 / 255.},   // sky blue
      {0, 0, 0},                             // black
  }};
  const int n = static_cast<int>(kPalette.size());
  return kPalette[((index % n) + n) % n];
}

bool Figure::Check(std::string* why) const {
  auto fail = [&](const std::string& message) {
    if (why) *why = message;
    return false;
  };
  constexpr int kMinPx = 100, kMaxPx = 10000;
  if (width_px < kMinPx || width_px > kMaxPx || height_px < kMinPx || height_px > kMaxPx) {
    return fail("image size " + std::to_string(width_px) + "×" + std::to_string(height_px) +
                " px is outside " + std::to_string(kMinPx) + ".." + std::to_string(kMaxPx));
  }
  if (columns < 1) return fail("columns must be at least 1");
  if (panels.empty()) return fail("the figure has no panels");
  for (size_t p = 0; p < panels.size(); ++p) {
    const Panel& panel = panels[p];
    const std::string where =
        "panel " + std::to_string(p + 1) + (panel.title.empty() ? "" : " (" + panel.title + ")");
    for (const auto& [range, log, axis] : {std::tuple{panel.x_range, panel.log_x, "x"},
                                           std::tuple{panel.y_range, panel.log_y, "y"}}) {
      if (!range) continue;
      if (!(std::isfinite(range->lo) && std::isfinite(range->hi) && range->lo < range->hi)) {
        return fail(where + ": " + axis + " range must be finite with lo < hi");
      }
      if (log && range->lo <= 0) return fail(where + ": log " + axis + " range must be positive");
    }
    for (const auto& series : panel.series) {
      const std::string name = where + ", series \"" + series.label + "\"";
      if (series.x.size() != series.y.size()) {
        return fail(name + ": x and y differ in length (" + std::to_string(series.x.size()) +
                    " vs " + std::to_string(series.y.size()) + ")");
      }
      if (!(series.line_width > 0 && series.line_width <= 50)) {
        return fail(name + ": line width must be in (0, 50] px");
      }
      if (series.color) {
        const Rgb& col = *series.color;
        for (double v : {col.r, col.g, col.b}) {
          if (!(v >= 0 && v <= 1)) return fail(name + ": colour components must be in [0, 1]");
        }
      }
    }
  }
  return true;
}

Ticks NiceTicks(double lo, double hi, int max_count) {
  Ticks t;
  const double span = hi - lo;
  if (!(std::isfinite(lo) && std::isfinite(hi) && std::isfinite(span) && span > 0)) return t;
  max_count = std::max(max_count, 1);
  // Start below the step that would give max_count ticks; the first that fits is the finest.
  for (int e = static_cast<int>(std::floor(std::log10(span / max_count))) - 1;; ++e) {
    for (int m : {1, 2, 5}) {
      const double step = Scaled(m, e);
      if (!std::isfinite(step)) return t;
      // Tolerate rounding in lo/step so that a tick exactly at an end is kept.
      const double k_lo = std::ceil(lo / step - 1e-9), k_hi = std::floor(hi / step + 1e-9);
      if (k_hi - k_lo + 1 > max_count) continue;
      for (int i = 0; i <= static_cast<int>(k_hi - k_lo); ++i) {
        t.values.push_back(Scaled((k_lo + i) * m, e));
      }
      const double max_abs = MaxAbs(t.values);
      for (double v : t.values) t.labels.push_back(Label(v, e, max_abs));
      return t;
    }
  }
}

Ticks LogTicks(double lo, double hi, int max_count) {
  Ticks t;
  if (!(lo > 0 && std::isfinite(hi) && lo < hi)) return t;
  max_count = std::max(max_count, 2);
  const auto inside = [&](double v) { return v >= lo * (1 - 1e-12) && v <= hi * (1 + 1e-12); };
  const int e_lo = static_cast<int>(std::ceil(std::log10(lo) - 1e-9));
  const int e_hi = static_cast<int>(std::floor(std::log10(hi) + 1e-9));
  const int decades = e_hi - e_lo + 1;
  if (decades >= 2) {
    // Label every stride-th decade (exponents divisible by stride, so 10⁰ stays a tick).
    int stride = 1;
    auto count = [&](int k) {
      int n = 0;
      for (int e = e_lo; e <= e_hi; ++e) n += (e % k == 0);
      return n;
    };
    for (int k : {1, 2, 3, 5, 10, 20, 50, 100}) {
      stride = k;
      if (count(k) <= max_count && count(k) >= 1) break;
    }
    for (int e = e_lo; e <= e_hi; ++e) {
      const double v = Scaled(1, e);
      if (e % stride == 0) {
        t.values.push_back(v);
        t.labels.push_back("10" + Superscript(e));
      } else {
        t.minor.push_back(v);
      }
    }
    if (stride == 1 && decades <= 12) {
      for (int e = e_lo - 1; e <= e_hi; ++e) {
        for (int m = 2; m <= 9; ++m) {
          if (inside(Scaled(m, e))) t.minor.push_back(Scaled(m, e));
        }
      }
    }
    std::sort(t.minor.begin(), t.minor.end());
    return t;
  }
  // Under two decade marks: 1-2-5 values if there are enough, else evenly spaced ones.
  const int f_lo = static_cast<int>(std::floor(std::log10(lo))) - 1;
  const int f_hi = static_cast<int>(std::ceil(std::log10(hi)));
  for (int e = f_lo; e <= f_hi; ++e) {
    for (int m : {1, 2, 5}) {
      if (inside(Scaled(m, e))) t.values.push_back(Scaled(m, e));
    }
  }
  if (t.values.size() >= 3 && t.values.size() <= static_cast<size_t>(max_count)) {
    const double max_abs = MaxAbs(t.values);
    for (double v : t.values) {
      t.labels.push_back(Label(v, static_cast<int>(std::floor(std::log10(v) + 1e-9)), max_abs));
    }
  } else {
    t = NiceTicks(lo, hi, max_count);
  }
  for (int e = f_lo; e <= f_hi; ++e) {
    for (int m = 1; m <= 9; ++m) {
      const double v = Scaled(m, e);
      const bool major = std::any_of(t.values.begin(), t.values.end(),
                                     [&](double u) { return std::abs(u - v) <= 1e-9 * v; });
      if (inside(v) && !major) t.minor.push_back(v);
    }
  }
  return t;
}

void CheckPngPath(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (extension != ".png") throw InputError(path + ": a chart is written as PNG; use a .png name");
}

void RenderPng(const Figure& figure, const std::string& file, const std::string& shown_path) {
  const std::string& path = shown_path.empty() ? file : shown_path;
  CheckPngPath(path);
  std::string why;
  if (!figure.Check(&why)) throw InputError(path + ": cannot draw the chart: " + why);

  const std::unique_ptr<cairo_surface_t, SurfaceDeleter> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, figure.width_px, figure.height_px));
  const std::unique_ptr<cairo_t, ContextDeleter> cr(cairo_create(surface.get()));
  Draw(cr.get(), figure);
  if (cairo_status(cr.get()) != CAIRO_STATUS_SUCCESS) {
    throw ComputeError(
        path + ": drawing the chart failed: " + cairo_status_to_string(cairo_status(cr.get())));
  }
  cairo_surface_flush(surface.get());
  const cairo_status_t written = cairo_surface_write_to_png(surface.get(), file.c_str());
  if (written != CAIRO_STATUS_SUCCESS) {
    throw InputError(path + ": cannot write PNG: " + cairo_status_to_string(written));
  }
}

}  // namespace textile::chart
