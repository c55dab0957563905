#include "textile/sim/plot/measured_drape_picture.h"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <string>

#include "textile/sim/core/number_text.h"
#include "top_view.h"

namespace textile {
namespace {

using plot_internal::Circle;
using plot_internal::ContextDeleter;
using plot_internal::SetRgb;
using plot_internal::SurfaceDeleter;
using View = plot_internal::TopView;
constexpr int kSize = plot_internal::kTopViewSize;
constexpr double kDegree = std::numbers::pi / 180.0;

// The polar outline r(θ) as a closed polyline; dashed for the second drape.
void DrawOutline(cairo_t* cr, const View& view, const DrapeShadow& sh, bool dashed) {
  if (sh.angles.size() < 2) return;
  cairo_new_path(cr);
  for (int b = 0; b < sh.angles.size(); ++b) {
    const double t = sh.angles(b), r = sh.radii(b);
    cairo_line_to(cr, view.U(r * std::cos(t)), view.V(r * std::sin(t)));
  }
  cairo_close_path(cr);
  const double dash[] = {10.0, 6.0};
  cairo_set_dash(cr, dash, dashed ? 2 : 0, 0.0);
  cairo_set_line_width(cr, 2.5);
  cairo_stroke(cr);
  cairo_set_dash(cr, dash, 0, 0.0);
}

void Cross(cairo_t* cr, const View& view, double size_px) {
  const double u = view.U(0.0), v = view.V(0.0);
  cairo_new_path(cr);
  cairo_move_to(cr, u - size_px, v);
  cairo_line_to(cr, u + size_px, v);
  cairo_move_to(cr, u, v - size_px);
  cairo_line_to(cr, u, v + size_px);
  cairo_set_line_width(cr, 2.0);
  cairo_stroke(cr);
}

// Each node as a ring (first drape, with its angle written beside it) or a small square.
void DrawNodes(cairo_t* cr, const View& view, const DrapeNodes& nodes, bool first) {
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 15.0);
  for (size_t k = 0; k < nodes.angles.size(); ++k) {
    const double t = nodes.angles[k], r = nodes.radii[k];
    const double u = view.U(r * std::cos(t)), v = view.V(r * std::sin(t));
    cairo_new_path(cr);
    if (first) {
      cairo_arc(cr, u, v, 7.0, 0.0, 2.0 * std::numbers::pi);
    } else {
      cairo_rectangle(cr, u - 5.0, v - 5.0, 10.0, 10.0);
    }
    cairo_set_line_width(cr, 2.0);
    cairo_stroke(cr);
    if (!first) continue;
    const std::string label = NumberText(t / kDegree, 3) + "°";
    cairo_move_to(cr, u + 18.0 * std::cos(t) - 12.0, v - 18.0 * std::sin(t) + 5.0);
    cairo_show_text(cr, label.c_str());
  }
}

std::string Figures(const MeasuredDrape& m) {
  return "DC " + NumberText(m.drape_coefficient, 3) + ", " + std::to_string(m.nodes.angles.size()) +
         " nodes";
}

void DrawCaption(cairo_t* cr, const MeasuredDrape& m, const MeasuredDrapeOverlay* second) {
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cr, 20.0);
  SetRgb(cr, 30, 30, 30);
  cairo_move_to(cr, 12.0, 28.0);
  const std::string first = "measured " + m.input_kind + ": " + Figures(m);
  cairo_show_text(cr, first.c_str());
  if (!second) return;
  cairo_move_to(cr, 12.0, 54.0);
  SetRgb(cr, 200, 60, 60);
  const std::string line = "dashed, " + second->label + ": " + Figures(*second->drape);
  cairo_show_text(cr, line.c_str());
}

}  // namespace

bool WriteMeasuredDrapePng(const MeasuredDrape& m, const std::string& file,
                           const MeasuredDrapeOverlay* second) {
  if (second && !second->drape) second = nullptr;
  double radius = m.specimen_radius;
  if (second) radius = std::max(radius, second->drape->specimen_radius);
  if (!(radius > 0.0)) radius = std::max(m.max_radius, 0.01);
  const double half = 1.08 * radius;
  const View view{.half = half, .px_per_m = kSize / (2.0 * half)};
  const std::unique_ptr<cairo_surface_t, SurfaceDeleter> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, kSize, kSize));
  const std::unique_ptr<cairo_t, ContextDeleter> cr(cairo_create(surface.get()));
  SetRgb(cr.get(), 250, 250, 250);
  cairo_paint(cr.get());
  plot_internal::PaintShadow(surface.get(), m.shadow, view, 0x00b4bec8);
  cairo_translate(cr.get(), 0.5, 0.5);  // pixel centres sit at half-pixel coordinates in Cairo
  SetRgb(cr.get(), 150, 150, 150);
  Circle(cr.get(), view, 0.0, 0.0, m.specimen_radius * view.px_per_m, 1.0);
  SetRgb(cr.get(), 240, 160, 60);
  Circle(cr.get(), view, 0.0, 0.0, m.support_radius * view.px_per_m, 2.0);
  Cross(cr.get(), view, 8.0);
  if (second) {
    SetRgb(cr.get(), 200, 60, 60);
    DrawOutline(cr.get(), view, second->drape->shadow, true);
    DrawNodes(cr.get(), view, second->drape->nodes, false);
  }
  SetRgb(cr.get(), 30, 60, 160);
  DrawOutline(cr.get(), view, m.shadow, false);
  SetRgb(cr.get(), 30, 150, 30);
  DrawNodes(cr.get(), view, m.nodes, true);
  cairo_identity_matrix(cr.get());
  DrawCaption(cr.get(), m, second);
  if (cairo_status(cr.get()) != CAIRO_STATUS_SUCCESS) return false;
  cairo_surface_flush(surface.get());
  return cairo_surface_write_to_png(surface.get(), file.c_str()) == CAIRO_STATUS_SUCCESS;
}

}  // namespace textile
