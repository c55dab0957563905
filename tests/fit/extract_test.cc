// The photo extractor on synthetic photos with a known truth (tests/fit/synthetic_photo.h):
// sub-pixel mid-line and boundaries for both polarities, both overhang directions, uneven light
// and a shadow, platform and clamp rigs, a rolled camera, a frayed tip; detection failures;
// unreadable files refused from their headers; and the two real photos, when present.

#include "textile/photo/extract.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "photo/extract_internal.h"
#include "synthetic_photo.h"
#include "textile/fit/profile.h"
#include "textile/photo/render_photo.h"
#include "textile/photo/rig.h"
#include "textile/sim/law/bending_law.h"
#include "textile/sim/core/error.h"

namespace textile {
namespace {

namespace fs = std::filesystem;
using testing::PhotoScene;
using testing::SyntheticPhoto;

// Required accuracy of the traced line against the truth: a fifth of the 1.5 px that separates
// the paper's fabrics at 0.1 mm/px, and the target of the brief. Measured: 0.01-0.02 px RMS at
// σ = 2 grey levels of noise, 1 px of blur, 140 grey levels of contrast.
constexpr double kLineRmsPx = 0.3;
// Worst single point: twice the RMS budget plus the noise of one section.
constexpr double kLineMaxPx = 1.0;
// Origin and tip along the strip: a pixel or so (the tip is an axial half-contrast point).
constexpr double kOriginPx = 0.5;
constexpr double kTipPx = 1.5;
constexpr double kScale = 0.1;  // [mm/px] of all synthetic photos

// The synthetic scenes are a straight run and a circular arc, no heavy cantilever: the physics
// check (ExtractOptions::check_shape) is off for them; rendered elastica photos keep it.
ExtractionSummary Extract(const cv::Mat& gray, ExtractOptions options = {},
                          const Rig& rig = Rig::FromScale(kScale)) {
  options.check_shape = false;
  return ExtractProfile(gray, rig, options, "synthetic.png");
}

// RMS and maximum distance of the traced line from the truth line at `offset` [px]; the last
// point (the tip, extrapolated along the strip) is judged by the tip test instead.
struct LineError {
  double rms = 0.0, max = 0.0;
};
LineError Compare(const SyntheticPhoto& photo, const ExtractionSummary& r, double offset = 0.0) {
  LineError e;
  int n = 0;
  for (size_t i = 0; i + 1 < r.trace_px.size(); ++i) {
    const double d = photo.DistanceToLine(r.trace_px[i], offset);
    e.rms += d * d;
    e.max = std::max(e.max, d);
    ++n;
  }
  e.rms = std::sqrt(e.rms / std::max(n, 1));
  return e;
}

using testing::BorderScene;

void ExpectAccurate(const SyntheticPhoto& photo, const ExtractionSummary& r) {
  ASSERT_TRUE(r.success) << r.message;
  const LineError e = Compare(photo, r);
  EXPECT_LT(e.rms, kLineRmsPx);
  EXPECT_LT(e.max, kLineMaxPx);
  EXPECT_LT((r.tip_px - photo.tip).norm(), kTipPx);
  // Length from the origin to the tip, against the truth's free length.
  EXPECT_NEAR(r.length_mm, photo.free_length * kScale, kTipPx * kScale);
  EXPECT_NO_THROW(CheckProfile(r.profile));
}

TEST(ExtractSynthetic, DarkStripLeavingTheBorderIsTracedToSubpixelAccuracy) {
  const SyntheticPhoto photo = testing::Render(BorderScene());
  const ExtractionSummary r = Extract(photo.gray);
  ExpectAccurate(photo, r);
  EXPECT_EQ(r.rig_type, "clamp");
  EXPECT_EQ(r.polarity, "dark");
  EXPECT_EQ(r.direction, "right");
  EXPECT_LT((r.origin_px - photo.origin).norm(), kOriginPx);
  EXPECT_NEAR(r.mm_per_px, kScale, 1e-12);
  EXPECT_NEAR(r.width_px, photo.scene.thickness, 0.5);
  // Frame of docs/spec/cantilever.md: starts at the origin, x towards the overhang, hanging below.
  EXPECT_NEAR(r.profile.x.front(), 0.0, 1e-9);
  EXPECT_NEAR(r.profile.y.front(), 0.0, 1e-9);
  EXPECT_GT(r.tip_mm.x(), 0.0);
  EXPECT_LT(r.tip_mm.y(), 0.0);
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front().text;
}

TEST(ExtractSynthetic, LightStripOnDarkBackground) {
  PhotoScene s = BorderScene();
  s.strip = 0.85;
  s.background = 0.2;
  const SyntheticPhoto photo = testing::Render(s);
  const ExtractionSummary r = Extract(photo.gray);
  ExpectAccurate(photo, r);
  EXPECT_EQ(r.polarity, "light");
}

TEST(ExtractSynthetic, MirroredPhotoGivesTheSameProfile) {
  PhotoScene s = BorderScene();
  const ExtractionSummary right = Extract(testing::Render(s).gray);
  s.mirror = true;
  const SyntheticPhoto photo = testing::Render(s);
  const ExtractionSummary left = Extract(photo.gray);
  ExpectAccurate(photo, left);
  EXPECT_EQ(left.direction, "left");
  ASSERT_TRUE(right.success) << right.message;
  // The same strip seen from the other side: the same profile, to the extraction's noise
  // (0.3 px = 0.03 mm).
  const size_t n = std::min(left.profile.size(), right.profile.size());
  ASSERT_GE(n + 1, std::max(left.profile.size(), right.profile.size()));
  for (size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(left.profile.x[i], right.profile.x[i], 3e-5) << i;
    EXPECT_NEAR(left.profile.y[i], right.profile.y[i], 3e-5) << i;
  }
}

TEST(ExtractSynthetic, UnevenLightAndShadowDoNotMatter) {
  PhotoScene s = BorderScene();
  s.uneven_light = true;
  const SyntheticPhoto photo = testing::Render(s);
  ExpectAccurate(photo, Extract(photo.gray));
}

TEST(ExtractSynthetic, BlurAndHeavyNoiseStayWithinTolerance) {
  PhotoScene s = BorderScene();
  s.blur_sigma = 2.0;
  s.noise_sigma = 12.0;  // contrast/noise about 12
  const SyntheticPhoto photo = testing::Render(s);
  ExpectAccurate(photo, Extract(photo.gray));
}

TEST(ExtractSynthetic, UpperAndLowerBoundariesAreTraced) {
  const SyntheticPhoto photo = testing::Render(BorderScene());
  const double half = photo.scene.thickness / 2.0;
  for (const TraceLine line : {TraceLine::kUpper, TraceLine::kLower}) {
    ExtractOptions o;
    o.trace = line;
    const ExtractionSummary r = Extract(photo.gray, o);
    ASSERT_TRUE(r.success) << r.message;
    const LineError e = Compare(photo, r, line == TraceLine::kUpper ? half : -half);
    EXPECT_LT(e.rms, kLineRmsPx);
    EXPECT_LT(e.max, kLineMaxPx);
    // The origin is where the traced line leaves the border.
    EXPECT_NEAR(r.origin_px.y(), photo.origin.y() - (line == TraceLine::kUpper ? half : -half),
                kOriginPx);
  }
}

TEST(ExtractSynthetic, ThinStrip) {
  PhotoScene s = BorderScene();
  s.thickness = 4.0;
  const SyntheticPhoto photo = testing::Render(s);
  ExpectAccurate(photo, Extract(photo.gray));
}

TEST(ExtractSynthetic, PlatformCornerIsTheOriginAndTheMidlineStartsHalfAThicknessAbove) {
  PhotoScene s;
  s.holder = PhotoScene::Holder::kPlatform;
  s.root_x = 500.0;
  s.root_y = 300.0;
  const SyntheticPhoto photo = testing::Render(s);
  const ExtractionSummary r = Extract(photo.gray);
  ExpectAccurate(photo, r);
  EXPECT_EQ(r.rig_type, "platform");
  EXPECT_LT((r.origin_px - photo.origin).norm(), kOriginPx);
  EXPECT_NEAR(r.level_deg, 0.0, 0.05);
  ASSERT_EQ(r.platform_px.size(), 3u);
  // docs/spec/cantilever.md: the mid-line starts at (0, t/2), not at (0, 0).
  EXPECT_NEAR(r.profile.x.front(), 0.0, 1e-9);
  EXPECT_NEAR(r.profile.y.front() * 1e3, s.thickness / 2.0 * kScale, kOriginPx * kScale);
  // Forcing the platform finds the same.
  ExtractOptions forced;
  forced.rig = RigKind::kPlatform;
  EXPECT_TRUE(Extract(photo.gray, forced).success);
}

TEST(ExtractSynthetic, RolledCameraIsLevelledByThePlatformTop) {
  PhotoScene s;
  s.holder = PhotoScene::Holder::kPlatform;
  s.root_x = 500.0;
  s.root_y = 300.0;
  const ExtractionSummary level = Extract(testing::Render(s).gray);
  s.rotate_deg = 3.0;
  const SyntheticPhoto photo = testing::Render(s);
  const ExtractionSummary rolled = Extract(photo.gray);
  ExpectAccurate(photo, rolled);
  ASSERT_TRUE(level.success) << level.message;
  EXPECT_NEAR(rolled.level_deg, 3.0, 0.05);
  EXPECT_LT((rolled.origin_px - photo.origin).norm(), kOriginPx);
  // Rotation invariance: the profile does not depend on the camera's roll.
  const size_t n = std::min(level.profile.size(), rolled.profile.size());
  for (size_t i = 0; i < n; i += 10) {
    EXPECT_NEAR(level.profile.x[i], rolled.profile.x[i], 5e-5) << i;
    EXPECT_NEAR(level.profile.y[i], rolled.profile.y[i], 5e-5) << i;
  }
  // The same with the edge and the level given by hand, the rig taken as a clamp.
  ExtractOptions manual;
  manual.rig = RigKind::kClamp;
  manual.edge_px = photo.origin;
  manual.level_deg = 3.0;
  const ExtractionSummary by_hand = Extract(photo.gray, manual);
  ASSERT_TRUE(by_hand.success) << by_hand.message;
  EXPECT_EQ(by_hand.rig_type, "clamp");
  for (size_t i = 0; i < std::min(n, by_hand.profile.size()); i += 10) {
    EXPECT_NEAR(by_hand.profile.y[i], rolled.profile.y[i], 5e-5) << i;
  }
}

TEST(ExtractSynthetic, MirroredPlatformIsOnTheRightAndLevelsTheOtherWay) {
  PhotoScene s;
  s.holder = PhotoScene::Holder::kPlatform;
  s.root_x = 500.0;
  s.root_y = 300.0;
  s.rotate_deg = 3.0;
  s.mirror = true;  // a counter-clockwise roll, mirrored, is a clockwise one
  const SyntheticPhoto photo = testing::Render(s);
  const ExtractionSummary r = Extract(photo.gray);
  ExpectAccurate(photo, r);
  EXPECT_EQ(r.rig_type, "platform");
  EXPECT_EQ(r.direction, "left");
  EXPECT_NEAR(r.level_deg, -3.0, 0.05);
  EXPECT_LT((r.origin_px - photo.origin).norm(), kOriginPx);
}

TEST(ExtractSynthetic, PlatformUnderUnevenLightWithARolledCameraAndFibres) {
  // Each trouble alone passes above; together they once made the platform's slanted front face
  // look like a strip in the hats, and the light's fall-off hide half of the block.
  for (const double strip : {0.2, 0.12}) {
    PhotoScene s;
    s.holder = PhotoScene::Holder::kPlatform;
    s.root_x = 450.0;
    s.root_y = 330.0;
    s.rotate_deg = 2.0;
    s.uneven_light = true;
    s.noise_sigma = 3.0;
    s.fibres = 12;
    s.strip = strip;  // 0.12: the strip lying on the platform contrasts with it, too
    const SyntheticPhoto photo = testing::Render(s);
    const ExtractionSummary r = Extract(photo.gray);
    ASSERT_TRUE(r.success) << r.message;
    EXPECT_EQ(r.rig_type, "platform");
    EXPECT_LT(Compare(photo, r).rms, kLineRmsPx);
    EXPECT_LT((r.origin_px - photo.origin).norm(), kOriginPx);
    EXPECT_NEAR(r.level_deg, 2.0, 0.05);
    EXPECT_NEAR(r.length_mm, photo.free_length * kScale, 0.2 * s.thickness * kScale);
  }
}

TEST(ExtractSynthetic, ClampInsideThePhotoIsWhereTheStripStarts) {
  PhotoScene s;
  s.holder = PhotoScene::Holder::kClampBlock;
  s.root_x = 300.0;
  s.block = 0.08;
  const SyntheticPhoto photo = testing::Render(s);
  const ExtractionSummary r = Extract(photo.gray);
  ExpectAccurate(photo, r);
  EXPECT_EQ(r.rig_type, "clamp");
  EXPECT_NE(r.rig_detail.find("clamp inside"), std::string::npos) << r.rig_detail;
  // The first measured section lies within about a pixel of the clamp's face.
  EXPECT_LT((r.origin_px - photo.origin).norm(), 1.5);
}

TEST(ExtractSynthetic, FrayedTipIsNotFollowed) {
  PhotoScene s = BorderScene();
  s.fibres = 30;
  const SyntheticPhoto photo = testing::Render(s);
  const ExtractionSummary r = Extract(photo.gray);
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_LT(Compare(photo, r).rms, kLineRmsPx);
  // Fibres reach up to three thicknesses beyond the tip; the tip stays within a fifth of one.
  EXPECT_LT((r.tip_px - photo.tip).norm(), 0.2 * s.thickness);
}

TEST(ExtractSynthetic, HomographyRigThatIsASimilarityGivesThePlainScaleProfile) {
  const SyntheticPhoto photo = testing::Render(BorderScene());
  Rig rig;
  // Plane frame turned by 90°, shifted, 0.1 mm/px: only distances and angles matter.
  rig.plane_from_image << 0.0, -kScale, 50.0, kScale, 0.0, -20.0, 0.0, 0.0, 1.0;
  rig.source = "similarity";
  const ExtractionSummary plain = Extract(photo.gray);
  const ExtractionSummary homography = Extract(photo.gray, {}, rig);
  ASSERT_TRUE(plain.success && homography.success);
  ASSERT_EQ(plain.profile.size(), homography.profile.size());
  for (size_t i = 0; i < plain.profile.size(); ++i) {
    EXPECT_NEAR(plain.profile.x[i], homography.profile.x[i], 1e-9);
    EXPECT_NEAR(plain.profile.y[i], homography.profile.y[i], 1e-9);
  }
}

TEST(ExtractSynthetic, LargePhotoIsDetectedReducedAndMeasuredAtFullResolution) {
  PhotoScene s = BorderScene();
  s.width = 4000;
  s.height = 3000;
  s.root_y = 800;
  s.straight = 500;
  s.radius = 2500;
  s.thickness = 24;
  s.blur_sigma = 1.5;
  const SyntheticPhoto photo = testing::Render(s);
  const ExtractionSummary r = Extract(photo.gray);
  ExpectAccurate(photo, r);
  std::printf("12 MP synthetic photo: %.2f s, line RMS %.3f px\n", r.seconds,
              Compare(photo, r).rms);
}

// ------------------------------------------------------------------ rendered photos

// The first 12 MP photo of `textile bench extract-accuracy` (Fig. 8 fabric at 60 mm, medium:
// pose, light gradient, shadow, fibres, JPEG). Near the platform's corner the strip's shadow
// merges with it, so its sections are measured only from 2-4 mm beyond the edge. The
// gap used to be bridged by a straight line along the first measured slope, which put the
// profile's start 0.93 mm above the truth (1.7 mm on the 50 MP photo); a strip resting on a
// platform leaves its edge level, and the level parabola that meets the first measured point
// with its slope stays within 0.23 mm.
TEST(ExtractRendered, ProfileLeavesThePlatformEdgeLevelWhereTheCornerIsNotMeasured) {
  RenderPhotoOptions o = RenderPhotoOptions::ForDifficulty(PhotoDifficulty::kMedium, 4000001);
  o.width_px = 4000;
  o.height_px = 3000;
  o.mm_per_px = 0.0433;
  o.overhang = 0.06;
  const RenderedPhoto photo = RenderPhoto(BendingLaw::FromKes(0.1, 0.0892, -0.0092), 0.2, o);
  const ExtractionSummary r = ExtractProfile(photo.photo, photo.rig, {}, "rendered 12 MP");
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_EQ(r.rig_type, "platform");
  // Distance from the true mid-line over the first 3 mm beyond the edge: the budget of the
  // extract-accuracy benchmark's worst case (0.5 mm RMS) less a margin; was 0.93 mm.
  constexpr double kNearEdgeMm = 0.3;
  double worst = 0.0, rms = 0.0;
  for (size_t i = 0; i < r.profile.size(); ++i) {
    const double d = DistanceToProfile(photo.truth, r.profile.x[i], r.profile.y[i]) * 1e3;
    if (r.profile.x[i] < 3e-3) worst = std::max(worst, d);
    rms += d * d;
  }
  rms = std::sqrt(rms / r.profile.size());
  EXPECT_LT(worst, kNearEdgeMm);
  // The whole profile: the benchmark's median at 12 MP is 0.01 mm; this photo was 0.12 mm.
  EXPECT_LT(rms, 0.06);
}

// Issue #4: the second 50 MP medium photo of the benchmark (dress fabric at 60 mm, a light
// strip 24 px thick on a light platform) came out as a clamp at the image border, 33 mm RMS
// from the truth. The platform's front face was scanned from 2 strip thicknesses inside the
// block, and over 48 px of it the noise had derivative peaks above 30 % of the face's, so a
// third of the scans stopped inside the block and the face was "not straight". The same photo
// at 2 MP with the strip 2.4 mm thick (24 px again) shows it in a second.
TEST(ExtractRendered, ThickStripOnAPlatformFindsItsFrontFaceThroughTheNoise) {
  RenderPhotoOptions o = RenderPhotoOptions::ForDifficulty(PhotoDifficulty::kMedium, 8165002);
  o.width_px = 1732;
  o.height_px = 1299;
  o.mm_per_px = 0.1;
  o.overhang = 0.06;
  o.thickness = 2.4e-3;
  const RenderedPhoto photo = RenderPhoto(BendingLaw::FromKes(0.0973, 0.0973, 0.0453), 0.13, o);
  const ExtractionSummary r = ExtractProfile(photo.photo, photo.rig, {}, "rendered, thick strip");
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_EQ(r.rig_type, "platform");
  EXPECT_EQ(r.direction, "left");
  double rms = 0.0;
  for (size_t i = 0; i < r.profile.size(); ++i) {
    const double d = DistanceToProfile(photo.truth, r.profile.x[i], r.profile.y[i]) * 1e3;
    rms += d * d;
  }
  rms = std::sqrt(rms / r.profile.size());
  // Measured 0.03 mm (0.3 px); a clamp at the border gave 30-40 mm.
  EXPECT_LT(rms, 0.1);
  EXPECT_NEAR(r.length_mm, 60.0, 0.3);
}

// ------------------------------------------------------------------ detection failures

TEST(ExtractFailures, BlankPhotoHasNoStrip) {
  PhotoScene s = BorderScene();
  s.strip = s.background;
  const ExtractionSummary r = Extract(testing::Render(s).gray);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("no strip"), std::string::npos) << r.message;
}

TEST(ExtractFailures, TipCutOffByTheImageBorder) {
  PhotoScene s = BorderScene();
  s.root_y = 600;
  s.radius = 800;
  s.bend_deg = 60;  // ends 100 px below the photo
  const ExtractionSummary r = Extract(testing::Render(s).gray);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("the free tip is cut off by the image border (bottom)"),
            std::string::npos)
      << r.message;
  EXPECT_NE(r.message.find("must be in view"), std::string::npos) << r.message;
}

// Two cantilevers in one photo: nothing says which to measure (the stronger one was taken
// without a word). Refused naming where both lie, unless --edge-px picks one.
PhotoScene LeftOfTwo() {
  PhotoScene s = BorderScene();
  s.root_y = 200;
  s.straight = 150;
  s.radius = 500;
  s.bend_deg = 40;  // the tip at x ≈ 470 px, clear of a mirrored twin
  return s;
}

TEST(ExtractFailures, TwoStripsSideBySideAreRefusedNamingBoth) {
  PhotoScene right = LeftOfTwo();
  right.mirror = true;
  right.root_y = 300;
  right.seed = 2;
  const ExtractionSummary r = Extract(testing::RenderTwoStrips(LeftOfTwo(), right));
  EXPECT_FALSE(r.success);
  EXPECT_TRUE(r.message.starts_with("two strips in the photo, one from (")) << r.message;
  EXPECT_NE(r.message.find(")-(0,"), std::string::npos) << r.message;     // at the left border
  EXPECT_NE(r.message.find(")-(1399,"), std::string::npos) << r.message;  // at the right border
  EXPECT_NE(r.message.find("--edge-px"), std::string::npos) << r.message;
}

TEST(ExtractFailures, TwoStripsOneAboveTheOtherAreRefused) {
  PhotoScene lower = LeftOfTwo();
  lower.root_y = 550;
  lower.seed = 3;
  const ExtractionSummary r = Extract(testing::RenderTwoStrips(LeftOfTwo(), lower));
  EXPECT_FALSE(r.success);
  EXPECT_TRUE(r.message.starts_with("two strips in the photo")) << r.message;
}

TEST(ExtractFailures, EdgePxPicksOneOfTwoStrips) {
  const PhotoScene left = LeftOfTwo();
  PhotoScene right = left;
  right.mirror = true;
  right.root_y = 300;
  right.seed = 2;
  const cv::Mat both = testing::RenderTwoStrips(left, right);
  for (const PhotoScene& scene : {left, right}) {
    const SyntheticPhoto photo = testing::Render(scene);
    ExtractOptions o;
    o.edge_px = photo.origin;
    const ExtractionSummary r = Extract(both, o);
    ASSERT_TRUE(r.success) << r.message;
    EXPECT_EQ(r.direction, scene.mirror ? "left" : "right");
    EXPECT_LT(Compare(photo, r).rms, kLineRmsPx);
  }
}

// Strips along one line, joined by a dim stretch, are one strip, not two: a strip whose middle
// is in a shadow is measured as before.
TEST(ExtractFailures, OneStripWithADimStretchIsNotTwo) {
  PhotoScene s = BorderScene();
  SyntheticPhoto photo = testing::Render(s);
  cv::Mat dimmed = photo.gray.clone();
  const cv::Rect stretch(300, 0, 40, s.height);
  cv::Mat part = dimmed(stretch);
  part.convertTo(part, CV_8U, 0.3, 0.7 * 190);  // the strip's contrast down to 30 %
  const ExtractionSummary r = Extract(dimmed);
  EXPECT_EQ(r.message.find("two strips"), std::string::npos) << r.message;
}

// A strip lying over the whole top of a platform that stands in the photo and hanging off
// both of its ends is not a cantilever from one edge: one overhang used to be measured as if
// the other were not there. Seen lying on the platform (light platform), the strip is one
// band draped over it; unseen there (dark platform), two bands that hang away from it.
TEST(ExtractFailures, StripHangingOffBothEndsOfAPlatformIsRefused) {
  testing::DrapedScene s;
  s.width = 1400;
  s.height = 900;
  s.platform_left = 420;
  s.platform_right = 875;
  s.platform_top = 315;
  s.radius = 350;
  for (const double platform : {240.0, 100.0}) {
    SCOPED_TRACE(platform);
    s.platform = platform;
    const ExtractionSummary r = Extract(testing::RenderDraped(s));
    EXPECT_FALSE(r.success);
    EXPECT_TRUE(r.message.starts_with("the strip hangs off both ends of the platform"))
        << r.message;
    EXPECT_NE(r.message.find("not a cantilever from one edge"), std::string::npos) << r.message;
  }
}

TEST(ExtractGeometry, DrapedOverBlockNeedsBothEndsDownAndABlockUnderTheTop) {
  using extract_internal::Block;
  Block block;
  block.mask = cv::Mat::zeros(100, 200, CV_8U);
  block.mask(cv::Rect(80, 50, 40, 50)).setTo(255);
  block.sign = -1;
  block.box = cv::Rect(80, 50, 40, 50);
  const auto line = [](double left_end_y, double right_end_y) {
    std::vector<extract_internal::Vec2> l;
    for (int i = 0; i <= 20; ++i) l.emplace_back(40 + i, left_end_y + (47 - left_end_y) * i / 20.0);
    for (int x = 61; x < 140; ++x) l.emplace_back(x, 47);
    for (int i = 0; i <= 20; ++i) l.emplace_back(140 + i, 47 + (right_end_y - 47) * i / 20.0);
    return l;
  };
  extract_internal::Vec2 peak;
  EXPECT_TRUE(extract_internal::DrapedOverBlock(line(90, 90), {block}, 2.0, &peak));
  EXPECT_NEAR(peak.y(), 47, 1e-12);
  // One end at the top's level: a strip held there, hanging from one edge.
  EXPECT_FALSE(extract_internal::DrapedOverBlock(line(47, 90), {block}, 2.0, &peak));
  EXPECT_FALSE(extract_internal::DrapedOverBlock(line(90, 50), {block}, 2.0, &peak));
  // Both ends down but nothing under the top (a strip over a rod out of view): not this case.
  EXPECT_FALSE(extract_internal::DrapedOverBlock(line(90, 90), {}, 2.0, &peak));
}

// A chessboard photo given as a strip photo: "no strip found" (or a later failure) said
// nothing of the mix-up.
TEST(ExtractFailures, CalibrationBoardIsRefusedNamingCalibrate) {
  for (const PhotoDifficulty level : {PhotoDifficulty::kEasy, PhotoDifficulty::kHard}) {
    SCOPED_TRACE(ToString(level));
    RenderPhotoOptions o = RenderPhotoOptions::ForDifficulty(level, 3);
    o.width_px = 1000;
    o.height_px = 750;
    o.mm_per_px = 0.2;
    const RenderedPhoto photo = RenderPhoto(BendingLaw::FromKes(0.1, 0.0892, -0.0092), 0.2, o);
    const ExtractionSummary r = Extract(photo.board);
    EXPECT_FALSE(r.success);
    EXPECT_TRUE(r.message.starts_with("this looks like a calibration board")) << r.message;
    EXPECT_NE(r.message.find("textile calibrate"), std::string::npos) << r.message;
    // Its strip photo is no board.
    EXPECT_FALSE(extract_internal::LooksLikeCalibrationBoard(photo.photo));
  }
}

TEST(ExtractGeometry, SyntheticStripPhotosDoNotLookLikeBoards) {
  PhotoScene platform;
  platform.holder = PhotoScene::Holder::kPlatform;
  platform.root_x = 500;
  PhotoScene uneven = BorderScene();
  uneven.uneven_light = true;
  uneven.fibres = 30;
  for (const PhotoScene& s : {BorderScene(), platform, uneven}) {
    cv::Mat small;
    cv::resize(testing::Render(s).gray, small, cv::Size(1000, 643), 0, 0, cv::INTER_AREA);
    EXPECT_FALSE(extract_internal::LooksLikeCalibrationBoard(small));
  }
}

TEST(ExtractFailures, ForcedPlatformThatIsNotThere) {
  ExtractOptions o;
  o.rig = RigKind::kPlatform;
  const ExtractionSummary r = Extract(testing::Render(BorderScene()).gray, o);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("platform not found"), std::string::npos) << r.message;
}

// A strip that lies on a block which the platform measurement rejects (here its front face is
// notched, 20 px deep every 40 px) must not be taken for a strip clamped at the image border:
// the origin would be extrapolated to the border, 50 mm behind the platform's edge. Given the
// edge, or told that the rig is a clamp, the extractor measures it.
TEST(ExtractFailures, RejectedPlatformUnderTheStripIsNotTakenForABorderClamp) {
  PhotoScene s;
  s.holder = PhotoScene::Holder::kPlatform;
  s.root_x = 500.0;
  s.root_y = 300.0;
  s.strip = 0.12;  // contrasts with the platform: the strip is seen lying on it to the border
  const SyntheticPhoto photo = testing::Render(s);
  cv::Mat notched = photo.gray.clone();
  const cv::Scalar background(photo.gray.at<uchar>(50, s.width - 50));
  for (int y = 340; y < s.height; y += 40)
    cv::rectangle(notched, cv::Rect(480, y, 21, 20), background, cv::FILLED);
  const ExtractionSummary r = Extract(notched);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("looks like a platform"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("not straight"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("--edge-px"), std::string::npos) << r.message;
  ExtractOptions edge;
  edge.edge_px = photo.origin;
  const ExtractionSummary by_edge = Extract(notched, edge);
  ASSERT_TRUE(by_edge.success) << by_edge.message;
  EXPECT_LT(Compare(photo, by_edge).rms, kLineRmsPx);
  ExtractOptions clamp;
  clamp.rig = RigKind::kClamp;
  const ExtractionSummary as_clamp = Extract(notched, clamp);
  ASSERT_TRUE(as_clamp.success) << as_clamp.message;
  EXPECT_EQ(as_clamp.rig_type, "clamp");
  // The unnotched platform is measured as before.
  EXPECT_EQ(Extract(photo.gray).rig_type, "platform");
}

TEST(ExtractFailures, ProfileThatFoldsBack) {
  PhotoScene s = BorderScene();
  s.radius = 250;
  s.bend_deg = 150;  // curls back 125 px = 12.5 mm
  const ExtractionSummary r = Extract(testing::Render(s).gray);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("folds back"), std::string::npos) << r.message;
}

// A band bent round the platform's corner at a radius not much larger than its thickness (70 px
// at 120 px): its upper edge is measured on 6 of 168 cross-sections. The gaps were bridged from
// those few, and the profile followed the guide, 1.8 px RMS from the truth, with no error; a
// rendered 8 mm strip whose upper edge was measured nowhere crashed (a NaN smoothing width:
// "cannot create std::vector larger than max_size()"). It now fails naming the line.
TEST(ExtractFailures, LineMeasuredOnFewSectionsFailsNamingIt) {
  const PhotoScene s = testing::ThickBandRoundTheCornerScene();
  ExtractOptions upper;
  upper.trace = TraceLine::kUpper;
  const ExtractionSummary r = Extract(testing::Render(s).gray, upper);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("upper edge is measured on only"), std::string::npos) << r.message;
  EXPECT_EQ(r.message.find('\n'), std::string::npos) << r.message;
}

// The smoothing width came from the traced line's first point through the rig's scale: NaN
// when the line was measured nowhere, and ceil(3 NaN) cast to int is undefined (a huge
// allocation). A non-finite width now leaves the line as it is.
TEST(ExtractGeometry, SmoothPolylineReturnsTheInputForANonFiniteSigma) {
  std::vector<Eigen::Vector2d> line;
  for (int k = 0; k < 50; ++k) line.emplace_back(k, 0.01 * k * k);
  for (const double sigma :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity(), 0.0, -1.0}) {
    EXPECT_TRUE(extract_internal::SmoothPolyline(line, sigma) == line) << sigma;
  }
  // A huge finite width: the window stops at the sequence's length instead of overflowing.
  const std::vector<Eigen::Vector2d> wide = extract_internal::SmoothPolyline(line, 1e300);
  ASSERT_EQ(wide.size(), line.size());
  for (const Eigen::Vector2d& p : wide) EXPECT_TRUE(p.allFinite());
}

// --edge-px inside the photo but far from the strip (here 200 px above the platform's corner)
// moved the whole profile without a word. It is refused past 3 strip widths + 10 px from the
// traced line (or its continuation back from the held end), naming the held end; a corner
// given a few pixels off is fine.
TEST(ExtractFailures, EdgeFarFromTheStripIsRefused) {
  PhotoScene s;
  s.holder = PhotoScene::Holder::kPlatform;
  s.root_x = 500.0;
  s.root_y = 300.0;
  const SyntheticPhoto photo = testing::Render(s);
  ExtractOptions near;
  near.edge_px = photo.origin + Eigen::Vector2d(-3.0, 4.0);
  EXPECT_TRUE(Extract(photo.gray, near).success);
  ExtractOptions behind;  // on the platform, 300 px behind its corner under the strip
  behind.edge_px = photo.origin - Eigen::Vector2d(300.0, 0.0);
  EXPECT_TRUE(Extract(photo.gray, behind).success);
  ExtractOptions far;
  far.edge_px = photo.origin - Eigen::Vector2d(0.0, 200.0);
  try {
    Extract(photo.gray, far);
    ADD_FAILURE() << "accepted an edge 200 px above the strip";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("--edge-px"), std::string::npos) << m;
    EXPECT_NE(m.find("from the strip"), std::string::npos) << m;
    EXPECT_NE(m.find("held end"), std::string::npos) << m;
  }
}

// An edge well along the strip from its held end (here 300 px along a strip that leaves the
// left border) is where the strip leaves no support: the profile would start there and leave
// the rest out (a real photo gave L = 151 mm of 251 with no word). It is warned about; the
// held end itself is not.
TEST(ExtractFailures, EdgeWellAlongTheStripIsWarnedAbout) {
  const SyntheticPhoto photo = testing::Render(BorderScene());
  const auto warned = [](const ExtractionSummary& r) {
    bool text = false;
    for (const Note& w : r.warnings)
      text |= w.text.find("along the strip from its held end") != std::string::npos;
    // The code says the same as the text.
    EXPECT_EQ(text, HasNote(r.warnings, "edge_px_along_strip"));
    return text;
  };
  ExtractOptions at_border;
  at_border.edge_px = photo.origin;
  const ExtractionSummary held = Extract(photo.gray, at_border);
  ASSERT_TRUE(held.success) << held.message;
  EXPECT_FALSE(warned(held));
  // A point of the mid-line 300 px along it (on the straight run and the arc).
  const auto along = Extract(photo.gray);
  ASSERT_TRUE(along.success) << along.message;
  double run = 0.0;
  Eigen::Vector2d point = along.trace_px.front();
  for (size_t k = 1; k < along.trace_px.size() && run < 300.0; ++k) {
    run += (along.trace_px[k] - along.trace_px[k - 1]).norm();
    point = along.trace_px[k];
  }
  ExtractOptions far_along;
  far_along.edge_px = point;
  const ExtractionSummary cut = Extract(photo.gray, far_along);
  ASSERT_TRUE(cut.success) << cut.message;
  EXPECT_TRUE(warned(cut)) << cut.BriefReport();
  EXPECT_LT(cut.length_mm, held.length_mm - 20.0);
}

TEST(ExtractFailures, BadInputThrows) {
  const cv::Mat gray = testing::Render(BorderScene()).gray;
  cv::Mat colour;
  cv::cvtColor(gray, colour, cv::COLOR_GRAY2BGR);
  EXPECT_THROW(Extract(colour), InputError);
  EXPECT_THROW(Extract(cv::Mat()), InputError);
  ExtractOptions outside;
  outside.edge_px = Eigen::Vector2d(5000, 10);
  try {
    Extract(gray, outside);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--edge-px"), std::string::npos) << e.what();
  }
  ExtractOptions step;
  step.step_mm = 0.0;
  EXPECT_THROW(Extract(gray, step), InputError);
  ExtractOptions level;
  level.level_deg = 90.0;
  EXPECT_THROW(Extract(gray, level), InputError);
}

// The time cap: 0 s stops a run at its first check with a message and no profile; a cap the
// photo fits in changes nothing; a cap that is not a finite number >= 0 is refused.
TEST(ExtractFailures, TimeCapEndsInFailureWithoutAProfile) {
  const cv::Mat gray = testing::Render(BorderScene()).gray;
  ExtractOptions capped;
  capped.max_seconds = 0.0;
  const ExtractionSummary r = Extract(gray, capped);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("time cap of 0 s reached"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("no profile"), std::string::npos) << r.message;
  EXPECT_TRUE(r.profile.s.empty());
  ExtractOptions roomy;
  roomy.max_seconds = 1e6;
  const ExtractionSummary full = Extract(gray, roomy);
  ASSERT_TRUE(full.success) << full.message;
  EXPECT_EQ(full.profile.y, Extract(gray).profile.y);
  for (double bad : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    ExtractOptions o;
    o.max_seconds = bad;
    EXPECT_THROW(Extract(gray, o), InputError) << bad;
  }
}

// ------------------------------------------------------------------ reading photos

class ReadPhoto : public ::testing::Test {
 protected:
  void SetUp() override {
    // One folder per test: ctest runs the tests of this fixture in parallel processes.
    dir_ = fs::path(TEXTILE_BINARY_DIR) / "test_scratch" /
           ("read_photo_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  std::string Write(const std::string& name, const std::string& bytes) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << bytes;
    return p.string();
  }
  std::string Encoded(const std::string& name, const cv::Mat& img) {
    const fs::path p = dir_ / name;
    cv::imwrite(p.string(), img);
    return p.string();
  }
  static std::string Bytes(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
  }
  void ExpectRefused(const std::string& path, const std::string& words) {
    try {
      ReadPhotoGray(path);
      ADD_FAILURE() << path << ": expected InputError";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(path), std::string::npos) << m;
      EXPECT_NE(m.find(words), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  }
  fs::path dir_;
};

TEST_F(ReadPhoto, ReadsPngAndJpegAsGrey) {
  const cv::Mat img = testing::Render(BorderScene()).gray;
  for (const char* name : {"a.png", "a.jpg", "a.tif", "a.bmp"}) {
    const cv::Mat back = ReadPhotoGray(Encoded(name, img));
    EXPECT_EQ(back.type(), CV_8UC1) << name;
    EXPECT_EQ(back.size(), img.size()) << name;
  }
}

TEST_F(ReadPhoto, RefusesWhatIsNotAPhoto) {
  ExpectRefused((dir_ / "missing.png").string(), "cannot open");
  ExpectRefused(Write("empty.png", ""), "empty file");
  ExpectRefused(Write("text.jpg", "s_mm,x_mm,y_mm\n0,0,0\n"), "not a supported image");
  ExpectRefused(Encoded("tiny.png", cv::Mat(1, 1, CV_8U, cv::Scalar(7))), "too small");
}

TEST_F(ReadPhoto, RefusesTruncatedFiles) {
  const cv::Mat img = testing::Render(BorderScene()).gray;
  for (const char* name : {"t.png", "t.jpg", "t.bmp"}) {
    const std::string whole = Bytes(Encoded(name, img));
    ExpectRefused(Write(std::string("cut-") + name, whole.substr(0, whole.size() / 2)),
                  "truncated");
  }
  // OpenCV writes a TIFF's directory after its pixels: cut in half, the header is gone.
  const std::string tiff = Bytes(Encoded("t.tif", img));
  ExpectRefused(Write("cut-t.tif", tiff.substr(0, tiff.size() / 2)), "damaged TIFF header");
  ExpectRefused(Write("cut-t2.tif", tiff.substr(0, tiff.size() - 10)), "TIFF");
}

TEST_F(ReadPhoto, RefusesAbsurdHeadersBeforeDecoding) {
  // A valid small PNG whose IHDR claims 100000 x 100000 pixels (the CRC no longer matches,
  // but the size is refused before anything is decoded).
  std::string png = Bytes(Encoded("small.png", cv::Mat(64, 64, CV_8U, cv::Scalar(9))));
  for (int k = 0; k < 2; ++k) {
    const uint32_t v = 100000;
    for (int b = 0; b < 4; ++b) png[16 + 4 * k + b] = static_cast<char>((v >> (24 - 8 * b)) & 0xFF);
  }
  ExpectRefused(Write("huge.png", png), "100000x100000");
  // A JPEG whose frame header claims 65535 x 65535.
  std::string jpg = Bytes(Encoded("small.jpg", cv::Mat(64, 64, CV_8U, cv::Scalar(9))));
  for (size_t i = 2; i + 9 < jpg.size(); ++i) {
    if (static_cast<unsigned char>(jpg[i]) == 0xFF &&
        static_cast<unsigned char>(jpg[i + 1]) == 0xC0) {
      for (int b = 5; b < 9; ++b) jpg[i + b] = static_cast<char>(0xFF);
      break;
    }
  }
  ExpectRefused(Write("huge.jpg", jpg), "65535x65535");
}

// A camera held upright tags its JPEG with an EXIF orientation (APP1, tag 0x0112) instead of
// turning the pixels. Rigs are calibrated in sensor pixels, so the photo must be read as stored.
TEST_F(ReadPhoto, IgnoresTheExifOrientationTag) {
  // 120 x 80 px, dark top-left quadrant: any turn or flip moves it or changes the size.
  cv::Mat img(80, 120, CV_8U, cv::Scalar(220));
  img(cv::Rect(0, 0, 60, 40)).setTo(30);
  const std::string jpg = Bytes(Encoded("plain.jpg", img));
  ASSERT_EQ(static_cast<unsigned char>(jpg[0]), 0xFF);
  ASSERT_EQ(static_cast<unsigned char>(jpg[1]), 0xD8);
  for (const int orientation : {3, 6, 8}) {
    // APP1: "Exif\0\0", a little-endian TIFF header, one IFD with one SHORT entry.
    std::string exif("Exif\0\0", 6);
    exif += std::string("II*\0\x08\0\0\0", 8);           // IFD at offset 8
    exif += std::string("\x01\0", 2);                    // one entry
    exif += std::string("\x12\x01\x03\0\x01\0\0\0", 8);  // 0x0112, SHORT, count 1
    exif += std::string(1, static_cast<char>(orientation)) + std::string("\0\0\0", 3);
    exif += std::string("\0\0\0\0", 4);  // no next IFD
    const size_t len = exif.size() + 2;
    const std::string app1 = std::string("\xFF\xE1", 2) + static_cast<char>(len >> 8) +
                             static_cast<char>(len & 0xFF) + exif;
    const std::string tagged = jpg.substr(0, 2) + app1 + jpg.substr(2);
    const std::string name = "exif" + std::to_string(orientation) + ".jpg";
    const std::string path = Write(name, tagged);
    // The tag is real: OpenCV's default decoding turns (6, 8) or flips (3) the image.
    const cv::Mat turned = cv::imread(path, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(turned.empty()) << name;
    if (orientation == 3) {
      EXPECT_GT(turned.at<uint8_t>(10, 10), 128) << name;
    } else {
      EXPECT_EQ(turned.size(), cv::Size(80, 120)) << name;
    }
    const cv::Mat back = ReadPhotoGray(path);
    EXPECT_EQ(back.size(), img.size()) << name;
    EXPECT_LT(back.at<uint8_t>(10, 10), 80) << name;  // the dark quadrant stays top-left
    EXPECT_GT(back.at<uint8_t>(70, 110), 170) << name;
  }
}

// ------------------------------------------------------------------ real photos

// Distance of each profile point from the least-squares quadratic x(s), y(s) through its
// neighbours within ±k points [mm].
struct LocalScatter {
  double rms_mm = 0.0, max_mm = 0.0;
};
LocalScatter ScatterAroundLocalQuadratics(const Profile& p, int k) {
  LocalScatter out;
  const int n = static_cast<int>(p.size());
  for (int i = 0; i < n; ++i) {
    const int lo = std::max(0, i - k), hi = std::min(n - 1, i + k);
    Eigen::MatrixXd a(hi - lo + 1, 3);
    Eigen::MatrixXd b(hi - lo + 1, 2);
    for (int j = lo; j <= hi; ++j) {
      const double t = (p.s[j] - p.s[i]) * 1e3;
      a.row(j - lo) << 1.0, t, t * t;
      b.row(j - lo) << p.x[j] * 1e3, p.y[j] * 1e3;
    }
    const Eigen::MatrixXd c = a.colPivHouseholderQr().solve(b);
    const double d = std::hypot(c(0, 0) - p.x[i] * 1e3, c(0, 1) - p.y[i] * 1e3);
    out.rms_mm += d * d;
    out.max_mm = std::max(out.max_mm, d);
  }
  out.rms_mm = std::sqrt(out.rms_mm / std::max(n, 1));
  return out;
}

// The two real clamp-rig photos of Broberg et al. (not shipped with the project: set
// TEXTILE_REAL_PHOTOS to the folder that holds them, see CONTRIBUTING.md): a lit near edge, an
// oblique grey face widening to the tip, loose fibres, a dark clamp at the left border. At the published 0.1101 mm/px the visible strips are about 250 mm long.
class RealPhotos : public ::testing::TestWithParam<const char*> {};

TEST_P(RealPhotos, GivePlausibleProfiles) {
  const char* dir = std::getenv("TEXTILE_REAL_PHOTOS");
  if (dir == nullptr) GTEST_SKIP() << "TEXTILE_REAL_PHOTOS is not set";
  const fs::path photo = fs::path(dir) / GetParam();
  if (!fs::exists(photo)) GTEST_SKIP() << photo << " is not available";
  const cv::Mat gray = ReadPhotoGray(photo.string());
  for (const TraceLine line : {TraceLine::kUpper, TraceLine::kMid}) {
    ExtractOptions o;
    o.trace = line;
    const ExtractionSummary r = ExtractProfile(gray, Rig::FromScale(0.1101), o, photo.string());
    ASSERT_TRUE(r.success) << r.message;
    EXPECT_EQ(r.rig_type, "clamp");
    EXPECT_EQ(r.polarity, "light");
    EXPECT_EQ(r.direction, "right");
    EXPECT_NEAR(r.origin_px.x(), -0.5, 1e-9);  // the left border
    // The strip spans most of the photo's width (2185-2193 px = 241 mm) and sags by about 100 mm.
    EXPECT_GT(r.length_mm, 230.0);
    EXPECT_LT(r.length_mm, 270.0);
    EXPECT_GT(r.tip_mm.x(), 210.0);
    EXPECT_LT(r.tip_mm.y(), -80.0);
    EXPECT_NO_THROW(CheckProfile(r.profile));
    const Profile& p = r.profile;
    double max_y = -1.0;
    for (size_t i = 0; i < p.size(); ++i) max_y = std::max(max_y, p.y[i]);
    EXPECT_LT(max_y * 1e3, 0.5);  // never above the clamp by more than noise
    for (size_t i = 1; i < p.size(); ++i) EXPECT_GE(p.x[i], p.x[i - 1] - 1e-4) << i;
    // No jumps into fibres: every point lies close to a quadratic through its neighbours
    // within ±5 mm (the strip's own curvature is far below what that can follow). A jump into a
    // fibre is several pixels (0.3-3 mm); the fuzz of these edges gives about 0.05 mm RMS.
    const LocalScatter scatter = ScatterAroundLocalQuadratics(p, 10);
    EXPECT_LT(scatter.max_mm, 0.4);
    EXPECT_LT(scatter.rms_mm, 0.1);
    std::printf(
        "%s (%s): L = %.1f mm, tip (%.1f, %.1f) mm, scatter %.3f mm RMS (max %.3f), %.2f s\n",
        GetParam(), r.trace.c_str(), r.length_mm, r.tip_mm.x(), r.tip_mm.y(), scatter.rms_mm,
        scatter.max_mm, r.seconds);
  }
}

INSTANTIATE_TEST_SUITE_P(Broberg, RealPhotos,
                         ::testing::Values("broberg-example.jpg", "broberg-break.jpg"));

}  // namespace
}  // namespace textile
