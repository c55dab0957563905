// The measured drape's picture (textile/sim/plot/measured_drape_picture.h, textile::plot), read
// back with Cairo.
#include "textile/sim/plot/measured_drape_picture.h"

#include <cairo.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>

namespace textile {
namespace {

std::uint32_t Pixel(cairo_surface_t* image, int u, int v) {
  const unsigned char* data = cairo_image_surface_get_data(image);
  const int stride = cairo_image_surface_get_stride(image);
  return reinterpret_cast<const std::uint32_t*>(data + v * stride)[u] & 0xffffffu;
}

// A measured cone: a circular shadow of radius 120 mm (the picture spans ±162 mm: 2.47 px/mm).
MeasuredDrape Cone(double radius) {
  const TriangleMesh mesh =
      SyntheticDrapeMesh(0.15, 0.09, 20, 180, [radius](double) { return radius; });
  return MeasureDrapeMesh(mesh, {}, "cone.obj");
}

TEST(MeasuredDrapePicture, PaintsShadowOutlineAndTheSecondOutlineDashed) {
  const MeasuredDrape m = Cone(0.12);
  const MeasuredDrape second = Cone(0.14);
  const auto file = std::filesystem::path(::testing::TempDir()) / "measured_drape_picture.png";
  const MeasuredDrapeOverlay overlay{.drape = &second, .label = "simulated"};
  ASSERT_TRUE(WriteMeasuredDrapePng(m, file.string(), &overlay));
  cairo_surface_t* image = cairo_image_surface_create_from_png(file.string().c_str());
  ASSERT_EQ(cairo_surface_status(image), CAIRO_STATUS_SUCCESS);
  EXPECT_EQ(cairo_image_surface_get_width(image), 800);
  const double px_per_mm = 800.0 / (2.0 * 1.08 * 150.0);
  // Inside the shadow, between the support and the outline (105 mm right of the centre).
  EXPECT_EQ(Pixel(image, 400 + static_cast<int>(105 * px_per_mm), 400), 0xb4bec8u);
  // Past the shadow (130 mm), before the second outline: the light ground.
  EXPECT_EQ(Pixel(image, 400 + static_cast<int>(130 * px_per_mm), 400), 0xfafafau);
  // The first outline at 120 mm is drawn in blue over the shadow's edge.
  bool blue = false, red = false;
  for (int du = -3; du <= 3; ++du) {
    const std::uint32_t p =
        Pixel(image, 400 + static_cast<int>(std::lround(120 * px_per_mm)) + du, 400);
    blue = blue || ((p & 0xff) > 120 && (p >> 16) < 80);
  }
  // The second, dashed, at 140 mm: red along some of its circle.
  for (int k = 0; k < 360 && !red; ++k) {
    const double t = k * 3.14159265358979 / 180.0;
    const int u = 400 + static_cast<int>(std::lround(140 * px_per_mm * std::cos(t)));
    const int v = 400 - static_cast<int>(std::lround(140 * px_per_mm * std::sin(t)));
    const std::uint32_t p = Pixel(image, u, v);
    red = red || ((p >> 16) > 150 && (p & 0xff) < 100);
  }
  EXPECT_TRUE(blue);
  EXPECT_TRUE(red);
  cairo_surface_destroy(image);
  std::filesystem::remove(file);
}

TEST(MeasuredDrapePicture, FalseWhenTheFileCannotBeWritten) {
  EXPECT_FALSE(WriteMeasuredDrapePng(Cone(0.12), "/nonexistent-folder/x.png"));
}

}  // namespace
}  // namespace textile
