#include "textile/photo/render_shadow.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "lobed_drape.h"
#include "textile/photo/calibrate.h"
#include "textile/sim/core/error.h"

namespace textile {
namespace {

using testing::Lobed;
using testing::SmallPhoto;

RenderedShadow Render(const RenderShadowOptions& o) {
  return RenderShadowPhoto(Lobed().vertices, Lobed().triangles, o);
}

TEST(RenderShadow, IsDeterministicPerSeed) {
  RenderShadowOptions o = SmallPhoto();
  o.width_px = 900, o.height_px = 800, o.mm_per_px = 0.42, o.noise = 4, o.seed = 3;
  const RenderedShadow a = Render(o), b = Render(o);
  EXPECT_EQ(cv::norm(a.photo, b.photo, cv::NORM_INF), 0.0);
  o.seed = 4;
  EXPECT_GT(cv::norm(a.photo, Render(o).photo, cv::NORM_INF), 0.0);
}

TEST(RenderShadow, AVerticalCameraHasTheScaleAndCentreAsked) {
  RenderShadowOptions o = SmallPhoto();
  o.width_px = 900, o.height_px = 800, o.mm_per_px = 0.42, o.noise = 0, o.blur_px = 0;
  o.aim_mm = Eigen::Vector2d(10.0, -5.0);
  const RenderedShadow r = Render(o);
  EXPECT_NEAR(r.centre_mm_per_px, 0.42, 1e-6);
  // The aim point (10, -5) mm is the photo's centre: the support's centre lies 10 mm to its
  // left and 5 mm up the paper (y up on the paper, down in the photo).
  EXPECT_NEAR(r.centre_px.x(), 449.5 - 10.0 / 0.42, 1e-6);
  EXPECT_NEAR(r.centre_px.y(), 399.5 - 5.0 / 0.42, 1e-6);
  EXPECT_LT(r.rig.PlaneFromImage(r.centre_px).norm(), 1e-9);
  // The dark pixels cover the shadow's area (the support's disk inside it), to the edge's
  // anti-aliasing.
  double dark = 0;
  for (int v = 0; v < r.photo.rows; ++v)
    for (int u = 0; u < r.photo.cols; ++u)
      dark += r.photo.at<uchar>(v, u) < 0.5 * (0.85 + 0.12) * 255;
  EXPECT_NEAR(dark * 0.42 * 0.42 / (r.truth.shadow.area * 1e6), 1.0, 0.003);
  EXPECT_EQ(r.truth.nodes.angles.size(), 6u);
}

TEST(RenderShadow, TiltPutsTheCentreWhereTheRigSays) {
  RenderShadowOptions o = SmallPhoto();
  o.tilt_deg = 10, o.tilt_azimuth_deg = 70, o.k1 = 0.05, o.roll_deg = 12;
  const RenderedShadow r = Render(o);
  EXPECT_LT(r.rig.PlaneFromImage(r.centre_px).norm(), 1e-6);
  // Perspective: the scale changes across the photo.
  EXPECT_GT(std::abs(r.rig.MmPerPxAt({100, 100}) - r.rig.MmPerPxAt({1150, 850})), 0.005);
}

TEST(RenderShadow, TheBoardCalibratesToTheTrueRig) {
  RenderShadowOptions o = SmallPhoto(true);
  o.tilt_deg = 8, o.tilt_azimuth_deg = 20, o.gradient = 0.2;
  const RenderedShadow r = Render(o);
  CalibrateOptions co;
  co.cols = r.board_cols, co.rows = r.board_rows, co.square_mm = r.board_square_mm;
  const CalibrationSummary c = CalibrateRig({r.board}, {"board.png"}, co);
  ASSERT_TRUE(c.success) << c.message;
  // The board's frame is not the drape's, but distances agree: two photo points 1000 px apart.
  const Eigen::Vector2d a(200, 200), b(1000, 800);
  const double truth = (r.rig.PlaneFromImage(a) - r.rig.PlaneFromImage(b)).norm();
  const double calibrated = (c.rig.PlaneFromImage(a) - c.rig.PlaneFromImage(b)).norm();
  EXPECT_NEAR(calibrated / truth, 1.0, 0.002);
}

TEST(RenderShadow, TruthJsonCarriesTheRigAndTheDc) {
  RenderShadowOptions o = SmallPhoto();
  o.tilt_deg = 3;
  const RenderedShadow r = Render(o);
  const nlohmann::json j = nlohmann::json::parse(RenderedShadowTruthJson(r, o));
  EXPECT_EQ(j["format"], "textile-rendered-shadow");
  EXPECT_DOUBLE_EQ(j["drape_coefficient"].get<double>(), r.truth.drape_coefficient);
  EXPECT_EQ(j["nodes"], 6);
  EXPECT_EQ(j["rig"]["type"], "homography");
  EXPECT_EQ(j["centre_px"].size(), 2u);
}

TEST(RenderShadow, RefusesBadOptionsAndAShadowLargerThanThePhoto) {
  RenderShadowOptions o = SmallPhoto();
  o.tilt_deg = 30;
  EXPECT_THROW(Render(o), InputError);
  o = SmallPhoto();
  o.jpeg_quality = 101;
  EXPECT_THROW(Render(o), InputError);
  o = SmallPhoto();
  o.mm_per_px = 0.1;  // 120 x 90 mm: the 268 mm shadow does not fit
  try {
    Render(o);
    ADD_FAILURE() << "no error";
  } catch (const ComputeError& e) {
    EXPECT_NE(std::string(e.what()).find("does not fit in the photo"), std::string::npos);
  }
  EXPECT_THROW(ParseShadowStyle("side", "--style"), InputError);
  EXPECT_EQ(ParseShadowStyle("top", "--style"), ShadowStyle::kTop);
}

}  // namespace
}  // namespace textile
