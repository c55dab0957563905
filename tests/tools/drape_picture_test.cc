// The drapemeter's shadow picture (textile/sim/plot/drape_picture.h, textile::plot): drawn from the
// result's raster, read back here with Cairo.
#include "textile/sim/plot/drape_picture.h"

#include <cairo.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>

namespace textile {
namespace {

// RGB of pixel (u, v) of an RGB24 PNG.
std::uint32_t Pixel(cairo_surface_t* image, int u, int v) {
  const unsigned char* data = cairo_image_surface_get_data(image);
  const int stride = cairo_image_surface_get_stride(image);
  return reinterpret_cast<const std::uint32_t*>(data + v * stride)[u] & 0xffffffu;
}

TEST(DrapePicture, PaintsTheShadowFromTheRasterOnALightGround) {
  DrapeOptions o;  // specimen 150 mm: the picture spans ±162 mm
  DrapeResult r;
  DrapeSeedResult seed;
  // A 20 mm square of shadow about the centre, in 1 mm cells.
  seed.shadow.cell = 0.001;
  seed.shadow.origin_x = seed.shadow.origin_y = -0.01;
  seed.shadow.width = seed.shadow.height = 21;
  seed.shadow.mask.assign(21 * 21, 1);
  const std::filesystem::path file =
      std::filesystem::path(::testing::TempDir()) / "drape_picture_test.png";
  ASSERT_TRUE(WriteDrapeShadowPng(r, seed, o, file.string()));
  cairo_surface_t* image = cairo_image_surface_create_from_png(file.string().c_str());
  ASSERT_EQ(cairo_surface_status(image), CAIRO_STATUS_SUCCESS);
  EXPECT_EQ(cairo_image_surface_get_width(image), 800);
  EXPECT_EQ(cairo_image_surface_get_height(image), 800);
  EXPECT_EQ(Pixel(image, 400, 400), 0x323c46u);  // the shadow's slate
  EXPECT_EQ(Pixel(image, 430, 400), 0xfafafau);  // 12 mm out: past the square, inside the support
  EXPECT_EQ(Pixel(image, 5, 795), 0xfafafau);    // a corner, outside every circle
  cairo_surface_destroy(image);
  std::filesystem::remove(file);
}

// Whether a pixel within 2 px of (u, v) is the measured outline's magenta.
bool MagentaNear(cairo_surface_t* image, double u, double v) {
  for (int du = -2; du <= 2; ++du)
    for (int dv = -2; dv <= 2; ++dv) {
      const std::uint32_t p = Pixel(image, static_cast<int>(u) + du, static_cast<int>(v) + dv);
      const int r = (p >> 16) & 0xff, g = (p >> 8) & 0xff, b = p & 0xff;
      if (r > 180 && g < 90 && b > 110) return true;
    }
  return false;
}

TEST(DrapePicture, ComparisonDrawsTheMeasuredOutlineAsAlignedWithALegend) {
  DrapeOptions o;  // ±162 mm over 800 px: 2469 px/m
  DrapeResult r;
  DrapeSeedResult seed;
  seed.seed = 1;
  seed.shadow.cell = 0.001;
  seed.shadow.origin_x = seed.shadow.origin_y = -0.01;
  seed.shadow.width = seed.shadow.height = 21;
  seed.shadow.mask.assign(21 * 21, 1);
  seed.shadow.angles.resize(360);
  for (int b = 0; b < 360; ++b) seed.shadow.angles(b) = (b + 0.5) * M_PI / 180.0;
  r.per_seed.push_back(seed);
  DrapeComparison c;
  DrapeSeedComparison sc;
  // 120 mm over the first 20°, 100 mm elsewhere; drawn as aligned (the picture does not turn it
  // by the rotation again).
  sc.outline.rotation = 0.5;
  sc.outline.aligned = Eigen::VectorXd::Constant(360, 0.10);
  sc.outline.aligned.head(20).setConstant(0.12);
  c.per_seed.push_back(sc);
  const std::filesystem::path file =
      std::filesystem::path(::testing::TempDir()) / "drape_compare_picture_test.png";
  ASSERT_TRUE(WriteDrapeComparisonPng(r, c, o, file.string()));
  cairo_surface_t* image = cairo_image_surface_create_from_png(file.string().c_str());
  ASSERT_EQ(cairo_surface_status(image), CAIRO_STATUS_SUCCESS);
  const double px_per_m = 800.0 / (2.0 * 1.08 * 0.15);
  const auto magenta_at = [&](double radius, double degrees) {
    const double t = degrees * M_PI / 180.0;
    return MagentaNear(image, 400.5 + radius * px_per_m * std::cos(t),
                       400.5 - radius * px_per_m * std::sin(t));
  };
  // 120 mm at 1° (the first dash starts at the first bin, 0.5°), not 100 mm; from 40° to 60°
  // (dashes and gaps) 100 mm somewhere, 120 mm nowhere.
  EXPECT_TRUE(magenta_at(0.12, 1.0));
  EXPECT_FALSE(magenta_at(0.10, 1.0));
  bool at_100 = false, at_120 = false;
  for (double degrees = 40.0; degrees <= 60.0; degrees += 0.5) {
    at_100 = at_100 || magenta_at(0.10, degrees);
    at_120 = at_120 || magenta_at(0.12, degrees);
  }
  EXPECT_TRUE(at_100);
  EXPECT_FALSE(at_120);
  EXPECT_EQ(Pixel(image, 400, 400), 0x323c46u);  // the shadow under it
  EXPECT_EQ(Pixel(image, 30, 751), 0x323c46u);   // the legend's shadow swatch
  cairo_surface_destroy(image);
  std::filesystem::remove(file);
  EXPECT_FALSE(WriteDrapeComparisonPng(r, c, o, "/nonexistent-folder/x.png"));
}

TEST(DrapePicture, FalseWhenTheFileCannotBeWritten) {
  DrapeResult r;
  DrapeSeedResult seed;
  EXPECT_FALSE(WriteDrapeShadowPng(r, seed, DrapeOptions{}, "/nonexistent-folder/x.png"));
}

}  // namespace
}  // namespace textile
