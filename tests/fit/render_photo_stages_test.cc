#include "photo/render_photo_stages.h"

#include <gtest/gtest.h>

namespace textile::fit_internal {
namespace {

// 2000 × 1500 px at 0.1 mm/px: a photo 200 × 150 mm; margin 12 mm; t = 0.5 mm.
RenderPhotoOptions Photo() {
  RenderPhotoOptions o;
  o.width_px = 2000;
  o.height_px = 1500;
  o.mm_per_px = 0.1;
  o.thickness = 0.5e-3;
  return o;
}

TEST(FrameAim, AShortStripLeavesAQuarterOfTheWidthToThePlatform) {
  // Platform 200 - 50 - 24 = 126 mm, capped at 50; background 0.6 · 89.5, capped at 45 mm.
  const Eigen::Vector2d aim = FrameAim(Photo(), 50.0, -60.0);
  EXPECT_DOUBLE_EQ(aim.x(), -50.0 + 100.0);
  EXPECT_DOUBLE_EQ(aim.y(), 0.5 + 45.0 - 75.0);
}

TEST(FrameAim, ALongStripStillShowsASixthOfTheWidthOfPlatform) {
  const Eigen::Vector2d aim = FrameAim(Photo(), 190.0, -20.0);
  EXPECT_DOUBLE_EQ(aim.x(), -200.0 / 6.0 + 100.0);
  // Background 0.6 · (150 - 20.5) = 77.7, capped at 45 mm.
  EXPECT_DOUBLE_EQ(aim.y(), 0.5 + 45.0 - 75.0);
}

TEST(FrameAim, AHangingStripKeepsAtLeastSixPercentOfBackground) {
  // Spare height 150 - 140.5 = 9.5 mm: 0.6 of it is below the floor of 9 mm.
  const Eigen::Vector2d aim = FrameAim(Photo(), 20.0, -140.0);
  EXPECT_DOUBLE_EQ(aim.y(), 0.5 + 9.0 - 75.0);
}

TEST(FrameAim, ShiftsAndAGivenAimPoint) {
  RenderPhotoOptions o = Photo();
  o.aim_dx = 0.1;
  o.aim_dy = 0.1;
  const Eigen::Vector2d shifted = FrameAim(o, 50.0, -60.0);
  EXPECT_DOUBLE_EQ(shifted.x(), -50.0 + 100.0 + 20.0);
  EXPECT_DOUBLE_EQ(shifted.y(), 0.5 + 45.0 - 75.0 - 15.0);
  o.aim_mm = Eigen::Vector2d(3.0, -4.0);
  EXPECT_EQ(FrameAim(o, 50.0, -60.0), Eigen::Vector2d(3.0, -4.0));
}

}  // namespace
}  // namespace textile::fit_internal
