// The drapemeter's shadow picture (textile/sim/plot/drape_picture.h, textile::plot): drawn from the
// result's raster, read back here with Cairo.
#include "textile/sim/plot/drape_picture.h"

#include <cairo.h>
#include <gtest/gtest.h>

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

TEST(DrapePicture, FalseWhenTheFileCannotBeWritten) {
  DrapeResult r;
  DrapeSeedResult seed;
  EXPECT_FALSE(WriteDrapeShadowPng(r, seed, DrapeOptions{}, "/nonexistent-folder/x.png"));
}

}  // namespace
}  // namespace textile
