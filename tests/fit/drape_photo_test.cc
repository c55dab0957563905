#include "textile/photo/drape_photo.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "lobed_drape.h"
#include "photo/drape_photo_stages.h"
#include "textile/photo/calibrate.h"
#include "textile/photo/render_shadow.h"
#include "textile/sim/core/error.h"
#include "textile/sim/law/material.h"

namespace textile {
namespace {

using namespace drape_photo;
constexpr double kPi = std::numbers::pi;

// The target is a DC from a rendered photo within 0.005 of the drape's own; these
// photos measured within 0.00023 (2026-12), so a fifth of the target still catches a
// regression long before it matters.
constexpr double kDcTolerance = 0.001;

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// A photo of paper (level `paper`) with dark disks (level `dark`) at the given centres and
// radii [px], blurred by 1 px.
cv::Mat Disks(cv::Size size, const std::vector<std::pair<cv::Point2d, double>>& disks,
              double paper = 210, double dark = 40) {
  cv::Mat img(size, CV_32F, cv::Scalar(paper));
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u)
      for (const auto& [c, r] : disks)
        if (std::hypot(u - c.x, v - c.y) <= r) img.at<float>(v, u) = static_cast<float>(dark);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 1.0);
  cv::Mat out;
  img.convertTo(out, CV_8U);
  return out;
}

using testing::Lobed;
using testing::SmallPhoto;

RenderedShadow Render(const RenderShadowOptions& o, const TriangleMesh& mesh = Lobed()) {
  return RenderShadowPhoto(mesh.vertices, mesh.triangles, o);
}

TEST(DrapePhotoStages, GreyOfConvertsColourAndRefusesOtherTypes) {
  cv::Mat bgr(64, 80, CV_8UC3, cv::Scalar(10, 100, 200));
  const cv::Mat g = GreyOf(bgr, "p.png");
  EXPECT_EQ(g.type(), CV_8UC1);
  EXPECT_NEAR(g.at<uchar>(2, 2), 0.114 * 10 + 0.587 * 100 + 0.299 * 200, 1.0);
  EXPECT_NE(ErrorOf([] { GreyOf(cv::Mat(), "p.png"); }).find("p.png: empty photo"),
            std::string::npos);
  EXPECT_THROW(GreyOf(cv::Mat(100, 100, CV_16UC1), "p.png"), InputError);
  EXPECT_NE(ErrorOf([] { GreyOf(cv::Mat(20, 20, CV_8UC1), "t.png"); }).find("too small"),
            std::string::npos);
}

TEST(DrapePhotoStages, ReduceUsesAWholeFactor) {
  const Reduced r = Reduce(cv::Mat(1000, 2410, CV_8UC1, cv::Scalar(7)), 800);
  EXPECT_EQ(r.factor, 4);
  EXPECT_EQ(r.grey.cols, 602);
  EXPECT_EQ(r.grey.rows, 250);
  EXPECT_EQ(Reduce(cv::Mat(600, 800, CV_8UC1), 800).factor, 1);
}

TEST(DrapePhotoStages, CheckExposureRefusesDarkAndFlatPhotos) {
  EXPECT_NE(ErrorOf([] {
              CheckExposure(cv::Mat(50, 50, CV_8UC1, cv::Scalar(12)), "d.png");
            }).find("the photo is all dark"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] {
              CheckExposure(cv::Mat(50, 50, CV_8UC1, cv::Scalar(180)), "f.png");
            }).find("no contrast"),
            std::string::npos);
  EXPECT_NO_THROW(CheckExposure(Disks({100, 80}, {{{50, 40}, 20}}), "ok.png"));
}

TEST(DrapePhotoStages, FitIlluminationRecoversASmoothLight) {
  // A light of exp(5 + 0.3 x − 0.2 y + 0.1 x²) over the normalised photo, a dark disk on it.
  const int W = 400, H = 300;
  cv::Mat img(H, W, CV_8UC1), background(H, W, CV_8UC1, cv::Scalar(255));
  auto light = [&](double u, double v) {
    const double x = 2 * u / (W - 1) - 1, y = 2 * v / (H - 1) - 1;
    return std::exp(5.0 + 0.3 * x - 0.2 * y + 0.1 * x * x);
  };
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const bool dark = std::hypot(u - 200, v - 150) < 80;
      img.at<uchar>(v, u) = cv::saturate_cast<uchar>(light(u, v) * (dark ? 0.2 : 1.0));
      if (std::hypot(u - 200, v - 150) < 85) background.at<uchar>(v, u) = 0;
    }
  const Illumination fit = FitIllumination(img, background, 3, 1, W, H);
  // Quantisation to whole grey levels: 0.5 / 110 at the darkest background.
  for (const auto& [u, v] :
       std::vector<std::pair<int, int>>{{0, 0}, {399, 299}, {200, 150}, {50, 250}})
    EXPECT_NEAR(fit.At(u, v) / light(u, v), 1.0, 0.006) << u << ", " << v;
}

TEST(DrapePhotoStages, SeparateShadowFlattensAStrongGradient) {
  // Light falling by half from left to right, with vignetting; a dark disk in the middle.
  const int W = 1600, H = 1000;
  cv::Mat photo(H, W, CV_8UC1);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const double r2 =
          (std::pow(u - 800.0, 2) + std::pow(v - 500.0, 2)) / (800.0 * 800 + 500 * 500);
      const double light = 230.0 * (1.0 - 0.5 * u / (W - 1.0)) * (1.0 - 0.2 * r2);
      const bool dark = std::hypot(u - 800.0, v - 500.0) < 300;
      photo.at<uchar>(v, u) = cv::saturate_cast<uchar>(light * (dark ? 0.15 : 1.0));
    }
  const Reduced reduced = Reduce(photo);
  const Separation s = SeparateShadow(reduced, W, H, "g.png");
  EXPECT_TRUE(s.levels.shadow_darker);
  EXPECT_NEAR(s.levels.background, 1.0, 0.02);
  EXPECT_NEAR(s.levels.shadow, 0.15, 0.02);
  // The paper at the darkest corner and beside the disk flattens to 1.
  EXPECT_NEAR(s.flat.at<float>(reduced.grey.rows - 1, reduced.grey.cols - 1), 1.0, 0.02);
  EXPECT_NEAR(s.flat.at<float>(250 / reduced.factor, 1150 / reduced.factor), 1.0, 0.02);
  // The light's fit used no pixel of the disk or its edge.
  const cv::Mat background = BackgroundMask(s.flat, s.levels);
  EXPECT_EQ(background.at<uchar>(500 / reduced.factor, 1095 / reduced.factor), 0);
  EXPECT_EQ(background.at<uchar>(500 / reduced.factor, 1120 / reduced.factor), 255);
}

TEST(DrapePhotoStages, SeparateLevelsFindsBothPolarities) {
  const cv::Mat dark_on_light = Disks({200, 150}, {{{100, 75}, 40}});
  cv::Mat flat;
  dark_on_light.convertTo(flat, CV_32F, 1.0 / 210.0);
  const Levels l = SeparateLevels(flat, "a.png");
  EXPECT_TRUE(l.shadow_darker);
  EXPECT_NEAR(l.background, 1.0, 0.01);
  EXPECT_NEAR(l.shadow, 40.0 / 210.0, 0.01);
  EXPECT_NEAR(l.threshold, 0.5 * (1.0 + 40.0 / 210.0), 0.01);
  const cv::Mat light_on_dark = Disks({200, 150}, {{{100, 75}, 40}}, 60, 200);
  light_on_dark.convertTo(flat, CV_32F, 1.0 / 60.0);
  EXPECT_FALSE(SeparateLevels(flat, "b.png").shadow_darker);
  // Noise about one level is not a shadow.
  cv::Mat noise(150, 200, CV_32F);
  cv::RNG(3).fill(noise, cv::RNG::NORMAL, 1.0, 0.01);
  EXPECT_NE(ErrorOf([&] { SeparateLevels(noise, "n.png"); }).find("n.png: no shadow found"),
            std::string::npos);
}

TEST(DrapePhotoStages, FindShadowIgnoresSpecksAndRefusesTwoShadows) {
  Levels l;
  l.threshold = 0.5;
  auto flat = [](const cv::Mat& u8) {
    cv::Mat f;
    u8.convertTo(f, CV_32F, 1.0 / 210.0);
    return f;
  };
  const Blob b = FindShadow(flat(Disks({300, 200}, {{{150, 100}, 50}, {{30, 30}, 3}})), l, "s.png");
  EXPECT_NEAR(b.area_px, kPi * 50 * 50, 0.02 * kPi * 50 * 50);
  EXPECT_NEAR(b.centroid_px.x(), 150, 0.5);
  EXPECT_NEAR(b.centroid_px.y(), 100, 0.5);
  const std::string two = ErrorOf([&] {
    FindShadow(flat(Disks({300, 200}, {{{80, 100}, 50}, {{220, 100}, 40}})), l, "t.png");
  });
  EXPECT_NE(two.find("t.png: two shadows"), std::string::npos) << two;
  EXPECT_NE(ErrorOf([&] {
              FindShadow(flat(Disks({300, 200}, {{{80, 100}, 3}})), l, "u.png");
            }).find("no shadow found"),
            std::string::npos);
}

TEST(DrapePhotoStages, CheckNotCutRefusesAShadowAtTheBorder) {
  Levels l;
  l.threshold = 0.5;
  cv::Mat f;
  Disks({300, 200}, {{{280, 100}, 50}}).convertTo(f, CV_32F, 1.0 / 210.0);
  const Blob b = FindShadow(f, l, "c.png");
  const std::string why = ErrorOf([&] { CheckNotCut(b, f.size(), "c.png"); });
  EXPECT_NE(why.find("c.png: the shadow is cut by the photo's border (on the right)"),
            std::string::npos)
      << why;
}

TEST(DrapePhotoStages, CheckShadowSizeRefusesLessThanTheSupport) {
  Blob b;
  b.area_px = 1000;  // at 0.5 mm/px: 250 mm², a speck beside the 25 447 mm² support
  EXPECT_NE(ErrorOf([&] {
              CheckShadowSize(b, 1, 0.5, DrapeMeasureOptions{}, "k.png");
            }).find("k.png: the shadow found covers only 250 mm²"),
            std::string::npos);
  b.area_px = 200000;
  EXPECT_NO_THROW(CheckShadowSize(b, 1, 0.5, DrapeMeasureOptions{}, "k.png"));
}

TEST(DrapePhotoStages, RectifyShadowGetsADiskAreaRightThroughAScaleRig) {
  // A 120 mm disk at 0.3 mm/px: its area on the paper to 0.2 %.
  const double r_px = 120.0 / 0.3;
  const cv::Mat photo = Disks({1000, 900}, {{{480.3, 455.7}, r_px}});
  const Rig rig = Rig::FromScale(0.3);
  const Reduced reduced = Reduce(photo);
  const Separation s = SeparateShadow(reduced, photo.cols, photo.rows, "d.png");
  const Blob blob = FindShadow(s.flat, s.levels, "d.png");
  const DrapeShadow shadow = RectifyShadow(photo, s, blob, reduced.factor, rig, 0.0005, "d.png");
  double cells = 0;
  for (const auto m : shadow.mask) cells += m;
  const double area = cells * shadow.cell * shadow.cell;
  EXPECT_NEAR(area / (kPi * 0.12 * 0.12), 1.0, 0.002);
  const Eigen::Vector2d c = ShadowCentre(shadow);
  EXPECT_NEAR(c.x(), 480.3 * 0.3e-3, 0.1e-3);
  EXPECT_NEAR(c.y(), 455.7 * 0.3e-3, 0.1e-3);
}

TEST(DrapePhotoStages, RecentreMovesTheGridOrigin) {
  DrapeShadow s;
  s.origin_x = 0.01, s.origin_y = -0.02;
  Recentre({0.05, 0.03}, &s);
  EXPECT_DOUBLE_EQ(s.origin_x, 0.01 - 0.05);
  EXPECT_DOUBLE_EQ(s.origin_y, -0.02 - 0.03);
}

TEST(DrapePhotoStages, PhotoPxOfPlaneInvertsTheRigWithALens) {
  RenderShadowOptions o = SmallPhoto();
  o.tilt_deg = 10, o.k1 = -0.1;
  const RenderedShadow r = Render(o);
  for (const Eigen::Vector2d& px :
       {Eigen::Vector2d(20, 30), Eigen::Vector2d(1150, 880), Eigen::Vector2d(800, 600)}) {
    EXPECT_LT((PhotoPxOfPlane(r.rig, r.rig.PlaneFromImage(px)) - px).norm(), 1e-6);
  }
}

// --- the whole measurement on rendered photos ---

struct Case {
  double tilt_deg;
  ShadowStyle style;
  double k1;
};

MeasuredDrape MeasureRendered(const RenderShadowOptions& o, const RenderedShadow& r, bool use_rig,
                              cv::Mat* overlay = nullptr) {
  const Rig rig = use_rig ? r.rig : Rig::FromScale(o.mm_per_px);
  return MeasureDrapePhoto(r.photo, rig, DrapePhotoOptions{}, "rendered.png", overlay);
}

TEST(DrapePhoto, VerticalShadowWithAScaleMeasuresTheTruthDc) {
  RenderShadowOptions o = SmallPhoto();
  o.gradient = 0.35, o.vignetting = 0.2, o.noise = 3, o.jpeg_quality = 90, o.seed = 5;
  const RenderedShadow r = Render(o);
  cv::Mat overlay;
  const MeasuredDrape m = MeasureRendered(o, r, false, &overlay);
  EXPECT_NEAR(m.drape_coefficient, r.truth.drape_coefficient, kDcTolerance);
  EXPECT_EQ(m.nodes.angles.size(), r.truth.nodes.angles.size());
  EXPECT_EQ(m.input_kind, "photo");
  EXPECT_EQ(m.centre_from, "shadow");
  // The lobed drape is symmetric: the shadow's centroid is the support's centre, to a cell.
  // (The scale rig's frame: mm from the photo's top-left pixel, y down.)
  EXPECT_LT((m.centre * 1e3 - r.centre_px * o.mm_per_px).norm(), 0.5);
  EXPECT_EQ(overlay.type(), CV_8UC3);
  EXPECT_EQ(overlay.size(), r.photo.size());
  // The nodes are drawn in red where the rig puts them (the scale rig: mm / 0.34 px).
  const Eigen::Vector2d node = (m.centre * 1e3 + 1e3 * m.nodes.radii[0] *
                                                     Eigen::Vector2d(std::cos(m.nodes.angles[0]),
                                                                     std::sin(m.nodes.angles[0]))) /
                               o.mm_per_px;
  const cv::Vec3b red = overlay.at<cv::Vec3b>(static_cast<int>(std::lround(node.y())),
                                              static_cast<int>(std::lround(node.x())));
  EXPECT_GT(red[2], 200);
  EXPECT_LT(red[1], 60);
}

TEST(DrapePhoto, SpecksBesideTheShadowAndColourChangeNothing) {
  RenderShadowOptions o = SmallPhoto();
  o.tilt_deg = 5, o.gradient = 0.2, o.seed = 8;
  const RenderedShadow r = Render(o);
  const MeasuredDrape clean = MeasureDrapePhoto(r.photo, r.rig, DrapePhotoOptions{}, "c.png");
  cv::Mat dirty;
  cv::cvtColor(r.photo, dirty, cv::COLOR_GRAY2BGR);
  cv::rectangle(dirty, cv::Rect(30, 30, 25, 25), cv::Scalar(20, 20, 20), cv::FILLED);  // a coin
  cv::RNG rng(5);
  for (int k = 0; k < 40; ++k)  // dust
    cv::circle(dirty, cv::Point(rng.uniform(0, 1200), rng.uniform(0, 60)), 2,
               cv::Scalar(30, 30, 30), cv::FILLED);
  const MeasuredDrape m = MeasureDrapePhoto(dirty, r.rig, DrapePhotoOptions{}, "d.png");
  EXPECT_NEAR(m.drape_coefficient, clean.drape_coefficient, 1e-4);
  EXPECT_EQ(m.nodes.angles.size(), clean.nodes.angles.size());
}

TEST(DrapePhoto, TiltedPhotosWithTheTrueRigMeasureTheTruthDc) {
  for (const Case c :
       {Case{10.0, ShadowStyle::kShadow, 0.0}, Case{7.0, ShadowStyle::kTop, -0.08}}) {
    RenderShadowOptions o = SmallPhoto();
    o.tilt_deg = c.tilt_deg, o.tilt_azimuth_deg = 55, o.style = c.style, o.k1 = c.k1;
    o.gradient = 0.3, o.noise = 3, o.jpeg_quality = 85, o.texture = 0.08, o.seed = 11;
    o.mm_per_px = 0.36;
    const RenderedShadow r = Render(o);
    const MeasuredDrape m = MeasureRendered(o, r, true);
    EXPECT_NEAR(m.drape_coefficient, r.truth.drape_coefficient, kDcTolerance) << r.description;
    EXPECT_EQ(m.nodes.angles.size(), r.truth.nodes.angles.size()) << r.description;
    EXPECT_LT(m.centre.norm() * 1e3, 1.0) << r.description;  // the rig's frame is the drape's
  }
}

TEST(DrapePhoto, ALightSpecimenOnADarkGroundIsMeasured) {
  RenderShadowOptions o = SmallPhoto();
  o.style = ShadowStyle::kTop, o.paper = 0.15, o.specimen_reflectance = 0.7, o.texture = 0.1;
  o.tilt_deg = 4, o.gradient = 0.2, o.seed = 2;
  const RenderedShadow r = Render(o);
  const MeasuredDrape m = MeasureRendered(o, r, true);
  EXPECT_NEAR(m.drape_coefficient, r.truth.drape_coefficient, kDcTolerance);
}

TEST(DrapePhoto, TheCalibratedBoardGivesARigGoodEnoughForTheDc) {
  RenderShadowOptions o = SmallPhoto(true);
  o.tilt_deg = 9, o.tilt_azimuth_deg = 200, o.gradient = 0.2, o.noise = 2, o.seed = 4;
  const RenderedShadow r = Render(o);
  CalibrateOptions co;
  co.cols = r.board_cols, co.rows = r.board_rows, co.square_mm = r.board_square_mm;
  const CalibrationSummary c = CalibrateRig({r.board}, {"board.png"}, co);
  ASSERT_TRUE(c.success) << c.message;
  const MeasuredDrape m = MeasureDrapePhoto(r.photo, c.rig, DrapePhotoOptions{}, "shadow.png");
  EXPECT_NEAR(m.drape_coefficient, r.truth.drape_coefficient, kDcTolerance);
  EXPECT_EQ(m.nodes.angles.size(), r.truth.nodes.angles.size());
}

TEST(DrapePhoto, AGivenCentreIsUsed) {
  testing::LobedDrape skewed;
  skewed.skew = 0.006;  // the shadow's centroid lies off the support's centre
  const TriangleMesh mesh = skewed.Mesh();
  RenderShadowOptions o = SmallPhoto();
  o.tilt_deg = 6;
  const RenderedShadow r = Render(o, mesh);
  DrapePhotoOptions po;
  po.centre_px = r.centre_px;
  const MeasuredDrape given = MeasureDrapePhoto(r.photo, r.rig, po, "g.png");
  EXPECT_EQ(given.centre_from, "given");
  EXPECT_LT(given.centre.norm(), 1e-9 + 1e-6);
  EXPECT_NEAR(given.mean_radius, r.truth.mean_radius, 0.5e-3);
  const MeasuredDrape found = MeasureDrapePhoto(r.photo, r.rig, DrapePhotoOptions{}, "f.png");
  // The centroid is pulled towards the skew (about 2/3 of it for a first harmonic): documented
  // in docs/methods/drape-photos.md; the DC does not depend on the centre.
  EXPECT_GT(found.centre.norm(), 1e-3);
  EXPECT_NEAR(found.drape_coefficient, given.drape_coefficient, 1e-3);
}

TEST(DrapePhoto, ARealDrapeRoundTrips) {
  const Material fig8 =
      ReadMaterial(std::string(TEXTILE_SOURCE_DIR) + "/samples/materials/pabst-fig8.json");
  DrapeOptions d;
  d.element_size = 0.015;
  const DrapeResult sim = SimulateDrape(fig8, d);
  ASSERT_TRUE(sim.converged) << sim.message;
  RenderShadowOptions o = SmallPhoto();
  o.tilt_deg = 10, o.tilt_azimuth_deg = 120, o.gradient = 0.3, o.vignetting = 0.15, o.noise = 3;
  o.jpeg_quality = 90;
  o.measure = MeasureOptionsOf(d);
  const RenderedShadow r = RenderShadowPhoto(sim.per_seed[0].positions, sim.mesh.triangles, o);
  const MeasuredDrape m = MeasureDrapePhoto(r.photo, r.rig, DrapePhotoOptions{}, "fig8.png");
  EXPECT_NEAR(m.drape_coefficient, r.truth.drape_coefficient, kDcTolerance);
  EXPECT_EQ(m.nodes.angles.size(), r.truth.nodes.angles.size());
  // The truth (π R² as the specimen's area) against the simulation's (the meshed pattern's).
  EXPECT_NEAR(r.truth.drape_coefficient, sim.drape_coefficient, 0.003);
}

// --- bad photos ---

TEST(DrapePhoto, RefusesBadPhotos) {
  const Rig rig = Rig::FromScale(0.25);
  auto why = [&](const cv::Mat& photo) {
    return ErrorOf([&] { MeasureDrapePhoto(photo, rig, DrapePhotoOptions{}, "bad.png"); });
  };
  cv::Mat blank(800, 1000, CV_8UC1);
  cv::RNG(1).fill(blank, cv::RNG::NORMAL, 200, 3);
  EXPECT_NE(why(blank).find("bad.png: no shadow found"), std::string::npos) << why(blank);
  EXPECT_NE(why(cv::Mat(800, 1000, CV_8UC1, cv::Scalar(5))).find("all dark"), std::string::npos);
  // 140 mm radius at 0.25 mm/px: 560 px.
  const std::string two = why(Disks({2400, 1300}, {{{620, 650}, 560}, {{1780, 650}, 560}}));
  EXPECT_NE(two.find("two shadows"), std::string::npos) << two;
  const std::string cut = why(Disks({1300, 1300}, {{{500, 650}, 560}}));
  EXPECT_NE(cut.find("cut by the photo's border (on the left)"), std::string::npos) << cut;
  const std::string tiny = why(Disks({1300, 1300}, {{{650, 650}, 100}}));
  EXPECT_NE(tiny.find("less than the support's disk"), std::string::npos) << tiny;
  EXPECT_THROW(MeasureDrapePhoto(cv::Mat(), rig, DrapePhotoOptions{}, "e.png"), InputError);
  DrapePhotoOptions wrong;
  wrong.measure.support_radius = 0.2;
  EXPECT_THROW(MeasureDrapePhoto(blank, rig, wrong, "o.png"), InputError);
  // A rig calibrated for another camera.
  Rig sized = rig;
  sized.image_size = Eigen::Vector2i(640, 480);
  EXPECT_THROW(MeasureDrapePhoto(blank, sized, DrapePhotoOptions{}, "s.png"), InputError);
}

}  // namespace
}  // namespace textile
