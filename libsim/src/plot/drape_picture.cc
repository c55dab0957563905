#include "textile/sim/plot/drape_picture.h"

#include <cairo.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <sstream>

#include "top_view.h"

namespace textile {
namespace {

using plot_internal::Circle;
using plot_internal::ContextDeleter;
using plot_internal::SetRgb;
using plot_internal::SurfaceDeleter;
using View = plot_internal::TopView;
constexpr int kSize = plot_internal::kTopViewSize;

// The seams as they lie on the draped cloth: their vertex paths at the seed's positions.
void DrawSeams(cairo_t* cr, const View& view, const DrapeResult& r, const DrapeSeedResult& s) {
  SetRgb(cr, 230, 80, 80);
  cairo_set_line_width(cr, 2.0);
  for (const std::vector<int>& path : r.seam_paths) {
    cairo_new_path(cr);
    for (size_t k = 0; k < path.size(); ++k)
      cairo_line_to(cr, view.U(s.positions(path[k], 0)), view.V(s.positions(path[k], 1)));
    cairo_stroke(cr);
  }
}

void DrawCaption(cairo_t* cr, const DrapeSeedResult& s, const DrapeOptions& o) {
  std::ostringstream caption;
  caption.precision(3);
  caption << "DC " << s.drape_coefficient << ", " << s.nodes.angles.size() << " nodes, seams "
          << DrapeSeamsName(o.seams) << ", seed " << s.seed;
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cr, 20.0);
  SetRgb(cr, 30, 30, 30);
  cairo_move_to(cr, 12.0, 28.0);
  cairo_show_text(cr, caption.str().c_str());
}

// The picture's surface with the shadow, circles, seams and nodes of seed s drawn; the caller
// adds the caption (and the overlay) in pixel coordinates.
std::unique_ptr<cairo_surface_t, SurfaceDeleter> DrawScene(const DrapeResult& r,
                                                           const DrapeSeedResult& s,
                                                           const DrapeOptions& o, View* view_out) {
  const double half = 1.08 * o.specimen_radius;
  const View view{.half = half, .px_per_m = kSize / (2.0 * half)};
  *view_out = view;
  std::unique_ptr<cairo_surface_t, SurfaceDeleter> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, kSize, kSize));
  const std::unique_ptr<cairo_t, ContextDeleter> cr(cairo_create(surface.get()));
  SetRgb(cr.get(), 250, 250, 250);
  cairo_paint(cr.get());
  plot_internal::PaintShadow(surface.get(), s.shadow, view, 0x00323c46);
  // Pixel centres sit at half-pixel coordinates in Cairo.
  cairo_translate(cr.get(), 0.5, 0.5);
  SetRgb(cr.get(), 160, 160, 160);
  Circle(cr.get(), view, 0.0, 0.0, std::floor(o.specimen_radius * view.px_per_m), 1.0);
  SetRgb(cr.get(), 240, 160, 60);
  Circle(cr.get(), view, 0.0, 0.0, std::floor(o.support_radius * view.px_per_m), 2.0);
  DrawSeams(cr.get(), view, r, s);
  SetRgb(cr.get(), 40, 200, 40);
  for (size_t k = 0; k < s.nodes.angles.size(); ++k) {
    const double t = s.nodes.angles[k], radius = s.nodes.radii[k];
    Circle(cr.get(), view, radius * std::cos(t), radius * std::sin(t), 6.0, 2.0);
  }
  return surface;
}

bool WritePng(cairo_surface_t* surface, cairo_t* cr, const std::string& file) {
  if (cairo_status(cr) != CAIRO_STATUS_SUCCESS) return false;
  cairo_surface_flush(surface);
  return cairo_surface_write_to_png(surface, file.c_str()) == CAIRO_STATUS_SUCCESS;
}

// The measured outline r(θ_b) on the seed's bins as a closed dashed line, light under dark so
// that it shows on the shadow and on the paper alike.
void DrawMeasuredOutline(cairo_t* cr, const View& view, const Eigen::VectorXd& angles,
                         const Eigen::VectorXd& radii) {
  cairo_new_path(cr);
  for (int b = 0; b < radii.size(); ++b)
    cairo_line_to(cr, view.U(radii(b) * std::cos(angles(b))),
                  view.V(radii(b) * std::sin(angles(b))));
  cairo_close_path(cr);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  const double dashes[] = {10.0, 6.0};
  cairo_set_dash(cr, dashes, 2, 0.0);
  SetRgb(cr, 255, 255, 255);
  cairo_set_line_width(cr, 4.5);
  cairo_stroke_preserve(cr);
  SetRgb(cr, 220, 30, 150);
  cairo_set_line_width(cr, 2.5);
  cairo_stroke(cr);
  cairo_set_dash(cr, nullptr, 0, 0.0);
}

// The legend, bottom left: a swatch of the shadow and of the dashed line, each with its label.
void DrawLegend(cairo_t* cr, const std::string& simulated, const std::string& measured) {
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 17.0);
  const double x = 14.0, y1 = kSize - 44.0, y2 = kSize - 18.0;
  SetRgb(cr, 50, 60, 70);
  cairo_rectangle(cr, x, y1 - 12.0, 34.0, 14.0);
  cairo_fill(cr);
  const double dashes[] = {10.0, 6.0};
  cairo_set_dash(cr, dashes, 2, 0.0);
  SetRgb(cr, 220, 30, 150);
  cairo_set_line_width(cr, 2.5);
  cairo_move_to(cr, x, y2 - 5.0);
  cairo_line_to(cr, x + 34.0, y2 - 5.0);
  cairo_stroke(cr);
  cairo_set_dash(cr, nullptr, 0, 0.0);
  SetRgb(cr, 30, 30, 30);
  cairo_move_to(cr, x + 44.0, y1);
  cairo_show_text(cr, simulated.c_str());
  cairo_move_to(cr, x + 44.0, y2);
  cairo_show_text(cr, measured.c_str());
}

std::string Fixed(double v, int decimals) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(decimals);
  s << v;
  return s.str();
}

}  // namespace

bool WriteDrapeShadowPng(const DrapeResult& r, const DrapeSeedResult& s, const DrapeOptions& o,
                         const std::string& file) {
  View view;
  const auto surface = DrawScene(r, s, o, &view);
  const std::unique_ptr<cairo_t, ContextDeleter> cr(cairo_create(surface.get()));
  DrawCaption(cr.get(), s, o);
  return WritePng(surface.get(), cr.get(), file);
}

bool WriteDrapeComparisonPng(const DrapeResult& r, const DrapeComparison& c, const DrapeOptions& o,
                             const std::string& file) {
  const DrapeSeedResult& s = r.per_seed.front();
  const DrapeSeedComparison& sc = c.per_seed.front();
  View view;
  const auto surface = DrawScene(r, s, o, &view);
  const std::unique_ptr<cairo_t, ContextDeleter> cr(cairo_create(surface.get()));
  cairo_translate(cr.get(), 0.5, 0.5);
  DrawMeasuredOutline(cr.get(), view, s.shadow.angles, sc.outline.aligned);
  cairo_identity_matrix(cr.get());
  std::ostringstream caption;
  caption << "DC " << Fixed(c.simulated_dc, 3) << " simulated, " << Fixed(c.measured_dc, 3)
          << " measured: " << c.Verdict();
  cairo_select_font_face(cr.get(), "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cr.get(), 20.0);
  SetRgb(cr.get(), 30, 30, 30);
  cairo_move_to(cr.get(), 12.0, 28.0);
  cairo_show_text(cr.get(), caption.str().c_str());
  DrawLegend(cr.get(),
             "simulated, seed " + std::to_string(s.seed) + ": DC " + Fixed(s.drape_coefficient, 3) +
                 ", " + std::to_string(s.nodes.angles.size()) + " nodes",
             "measured, turned " + Fixed(sc.outline.rotation * 180.0 / std::numbers::pi, 1) +
                 "\u00b0: DC " + Fixed(c.measured_dc, 3) + ", " + std::to_string(c.measured_nodes) +
                 " nodes, " + Fixed(sc.outline.rms * 1e3, 1) + " mm RMS");
  return WritePng(surface.get(), cr.get(), file);
}

}  // namespace textile
