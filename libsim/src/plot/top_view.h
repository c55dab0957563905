#ifndef TEXTILE_SIM_SRC_PLOT_TOP_VIEW_H_
#define TEXTILE_SIM_SRC_PLOT_TOP_VIEW_H_

// What the drape pictures share (drape_picture.cc, measured_drape_picture.cc): a square Cairo
// image seen from above with the support's centre in the middle, the shadow's raster painted
// into it, circles.

#include <cairo.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>

#include "textile/sim/scenes/drape.h"

namespace textile::plot_internal {

inline constexpr int kTopViewSize = 800;  // [px] square

struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};

// Pixels of the picture: x to the right, y up, the centre in the middle.
struct TopView {
  double half = 0.0;      // [m] from the centre to the image edge
  double px_per_m = 0.0;  // [px/m]
  double U(double x) const { return (x + half) * px_per_m; }
  double V(double y) const { return (half - y) * px_per_m; }
};

inline void SetRgb(cairo_t* cr, int r, int g, int b) {
  cairo_set_source_rgb(cr, r / 255.0, g / 255.0, b / 255.0);
}

// The shadow's raster, sampled at each pixel's centre, painted straight into the surface (an
// RGB24 image of kTopViewSize square) in the colour 0x00RRGGBB. Nothing for an empty raster.
inline void PaintShadow(cairo_surface_t* surface, const DrapeShadow& sh, const TopView& view,
                        std::uint32_t rgb) {
  if (sh.mask.empty() || !(sh.cell > 0.0)) return;
  cairo_surface_flush(surface);
  unsigned char* data = cairo_image_surface_get_data(surface);
  const int stride = cairo_image_surface_get_stride(surface);
  for (int v = 0; v < kTopViewSize; ++v) {
    auto* row = reinterpret_cast<std::uint32_t*>(data + static_cast<std::ptrdiff_t>(v) * stride);
    const double y = view.half - v / view.px_per_m;
    const long j = std::lround((y - sh.origin_y) / sh.cell);
    if (j < 0 || j >= sh.height) continue;
    for (int u = 0; u < kTopViewSize; ++u) {
      const double x = u / view.px_per_m - view.half;
      const long i = std::lround((x - sh.origin_x) / sh.cell);
      if (i < 0 || i >= sh.width) continue;
      if (sh.mask[static_cast<size_t>(j) * sh.width + i]) row[u] = rgb;
    }
  }
  cairo_surface_mark_dirty(surface);
}

// A circle of radius_px about (x, y) [m], stroked `width` px wide in the current colour.
inline void Circle(cairo_t* cr, const TopView& view, double x, double y, double radius_px,
                   double width) {
  cairo_new_path(cr);
  cairo_arc(cr, view.U(x), view.V(y), radius_px, 0.0, 2.0 * std::numbers::pi);
  cairo_set_line_width(cr, width);
  cairo_stroke(cr);
}

}  // namespace textile::plot_internal

#endif  // TEXTILE_SIM_SRC_PLOT_TOP_VIEW_H_
