// The photo renderer: its truth is the elastica (resting half a thickness above the edge), its
// camera maps that truth to where the strip is drawn, it is deterministic per seed, its options
// are checked, and the extractor recovers the truth from its photos (easy and medium levels)
// through the true rig.

#include "textile/photo/render_photo.h"

#include <gtest/gtest.h>

#include <cmath>

#include "textile/photo/extract.h"
#include "textile/sim/elastica/elastica.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"

namespace textile {
namespace {

const BendingLaw kFig8 = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
constexpr double kRho = 0.2;  // 200 g/m² [kg/m²]

// Small photos keep the tests fast: 1000 x 750 px at 0.12 mm/px (120 x 90 mm).
RenderPhotoOptions Small(PhotoDifficulty d, std::uint64_t seed) {
  RenderPhotoOptions o = RenderPhotoOptions::ForDifficulty(d, seed);
  o.width_px = 1000;
  o.height_px = 750;
  o.mm_per_px = 0.12;
  o.overhang = 0.06;
  return o;
}

// RMS and max distance [mm] of a profile's points from the truth mid-line.
std::pair<double, double> ErrorMm(const Profile& p, const Profile& truth) {
  double s2 = 0, mx = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const double d = DistanceToProfile(truth, p.x[i], p.y[i]) * 1e3;
    s2 += d * d;
    mx = std::max(mx, d);
  }
  return {std::sqrt(s2 / p.size()), mx};
}

TEST(RenderPhoto, TruthIsTheElasticaHalfAThicknessUp) {
  RenderPhotoOptions o = Small(PhotoDifficulty::kEasy, 3);
  o.thickness = 0.6e-3;
  const RenderedPhoto r = RenderPhoto(kFig8, kRho, o);
  const ElasticaProfile e = SolveHeavyElastica(kFig8, kRho, 0.06);
  ASSERT_TRUE(e.converged);
  // Exact by construction, up to the elastica's own tolerance (1e-9 relative of 60 mm).
  constexpr double kTol = 1e-9;
  EXPECT_NEAR(r.truth.x.front(), 0.0, kTol);
  EXPECT_NEAR(r.truth.y.front(), 0.3e-3, kTol);
  EXPECT_NEAR(r.truth.x.back(), e.tip_x, 1e-8);
  EXPECT_NEAR(r.truth.y.back(), e.tip_y + 0.3e-3, 1e-8);
  EXPECT_NEAR(r.truth.s.back(), 0.06, kTol);
  EXPECT_NEAR(r.tip_x_mm, e.tip_x * 1e3, 1e-5);
  // Boundaries a half thickness either side of the mid-line.
  for (size_t i = 0; i < r.truth.size(); i += 97) {
    const double du = std::hypot(r.truth_upper.x[i] - r.truth.x[i], r.truth_upper.y[i] - r.truth.y[i]);
    const double dl = std::hypot(r.truth_lower.x[i] - r.truth.x[i], r.truth_lower.y[i] - r.truth.y[i]);
    EXPECT_NEAR(du, 0.3e-3, 1e-12);
    EXPECT_NEAR(dl, 0.3e-3, 1e-12);
  }
}

TEST(RenderPhoto, TheRigMapsTheDrawnStripToItsTruth) {
  for (auto d : {PhotoDifficulty::kEasy, PhotoDifficulty::kMedium, PhotoDifficulty::kHard}) {
    const RenderedPhoto r = RenderPhoto(kFig8, kRho, Small(d, 11));
    ASSERT_EQ(r.truth_px.size(), r.truth.size());
    for (size_t i = 0; i < r.truth.size(); i += 50) {
      const Eigen::Vector2d mm = r.rig.PlaneFromImage(r.truth_px[i]);
      // Homography and its inverse: round-off only.
      EXPECT_NEAR(mm.x(), r.truth.x[i] * 1e3, 1e-6);
      EXPECT_NEAR(mm.y(), r.truth.y[i] * 1e3, 1e-6);
    }
    // The origin is the projected corner; the local scale near the requested one (perspective
    // and the aim point's offset change it by a few per cent at most).
    const Eigen::Vector2d o = r.rig.PlaneFromImage(r.origin_px);
    EXPECT_NEAR(o.norm(), 0.0, 1e-6);
    EXPECT_NEAR(r.rig.MmPerPxAt(r.origin_px), 0.12, 0.12 * 0.1);
  }
}

TEST(RenderPhoto, DrawsTheStripWherePolarityAndDirectionSay) {
  for (bool light : {false, true}) {
    for (bool left : {false, true}) {
      RenderPhotoOptions o = Small(PhotoDifficulty::kEasy, 5);
      o.light_strip = light;
      o.overhang_left = left;
      o.strip_reflectance = light ? 0.84 : 0.16;
      o.background_reflectance = light ? 0.22 : 0.78;
      const RenderedPhoto r = RenderPhoto(kFig8, kRho, o);
      // On the mid-line half way along vs 25 px (3 mm) beside it, across the strip.
      const size_t i = r.truth.size() / 2;
      const Eigen::Vector2d on = r.truth_px[i];
      const Eigen::Vector2d t = (r.truth_px[i + 1] - r.truth_px[i - 1]).normalized();
      const Eigen::Vector2d off = on + 25.0 * Eigen::Vector2d(-t.y(), t.x());
      const int v_on = r.photo.at<uchar>(int(std::lround(on.y())), int(std::lround(on.x())));
      const int v_off = r.photo.at<uchar>(int(std::lround(off.y())), int(std::lround(off.x())));
      SCOPED_TRACE(std::string(light ? "light" : "dark") + (left ? " left" : " right"));
      // Contrast of the easy level: about 0.6 of full scale; demand a third.
      if (light) EXPECT_GT(v_on - v_off, 80);
      else EXPECT_GT(v_off - v_on, 80);
      // The tip lies on the overhang side of the origin in the photo.
      EXPECT_EQ(r.truth_px.back().x() < r.origin_px.x(), left);
    }
  }
}

TEST(RenderPhoto, SameSeedSamePhotoOtherSeedOtherPhoto) {
  const RenderPhotoOptions o = Small(PhotoDifficulty::kMedium, 21);
  const RenderedPhoto a = RenderPhoto(kFig8, kRho, o);
  const RenderedPhoto b = RenderPhoto(kFig8, kRho, o);
  EXPECT_EQ(cv::norm(a.photo, b.photo, cv::NORM_INF), 0.0);
  EXPECT_EQ(a.encoded, b.encoded);
  const RenderedPhoto c = RenderPhoto(kFig8, kRho, Small(PhotoDifficulty::kMedium, 22));
  EXPECT_GT(cv::norm(a.photo, c.photo, cv::NORM_L1), 0.0);
}

TEST(RenderPhoto, BoardCornersLieOnTheGridThroughTheCamera) {
  const RenderedPhoto r = RenderPhoto(kFig8, kRho, Small(PhotoDifficulty::kMedium, 4));
  ASSERT_EQ(r.board_corners_px.size(), size_t(r.board_cols * r.board_rows));
  EXPECT_EQ(r.board.size(), r.photo.size());
  // Neighbouring corners are one square apart in the plane.
  for (int k = 0; k + 1 < r.board_cols; ++k) {
    const Eigen::Vector2d a = r.rig.PlaneFromImage(r.board_corners_px[k]);
    const Eigen::Vector2d b = r.rig.PlaneFromImage(r.board_corners_px[k + 1]);
    EXPECT_NEAR((a - b).norm(), r.board_square_mm, 1e-6);
  }
  // A black square's centre is dark, the card around the board light.
  const Eigen::Vector2d c = 0.5 * (r.board_corners_px[0] + r.board_corners_px[r.board_cols + 1]);
  const int inner = r.board.at<uchar>(int(std::lround(c.y())), int(std::lround(c.x())));
  EXPECT_TRUE(inner < 60 || inner > 180) << inner;
}

TEST(RenderPhoto, BadOptionsAndAStripThatDoesNotFitAreRefused) {
  RenderPhotoOptions o = Small(PhotoDifficulty::kEasy, 1);
  o.mm_per_px = -1;
  EXPECT_THROW(RenderPhoto(kFig8, kRho, o), InputError);
  o = Small(PhotoDifficulty::kEasy, 1);
  o.board_cols = o.board_rows = 6;
  EXPECT_THROW(RenderPhoto(kFig8, kRho, o), InputError);
  o = Small(PhotoDifficulty::kEasy, 1);
  o.jpeg_quality = 101;
  EXPECT_THROW(RenderPhoto(kFig8, kRho, o), InputError);
  o = Small(PhotoDifficulty::kEasy, 1);
  o.overhang = 0.3;  // 300 mm in a 120 x 90 mm view
  try {
    RenderPhoto(kFig8, kRho, o);
    ADD_FAILURE() << "no error";
  } catch (const ComputeError& e) {
    EXPECT_NE(std::string(e.what()).find("does not fit"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ParsePhotoDifficulty("tricky", "--difficulty"), InputError);
}

TEST(RenderPhoto, ExtractorRecoversTheTruthOnEasyAndMediumPhotos) {
  struct Case {
    PhotoDifficulty d;
    std::uint64_t seed;
    double rms_mm, max_mm;  // limits: issue 4's medium target at about 0.1 mm/px (0.1 / 0.5)
  };
  for (const Case& c : {Case{PhotoDifficulty::kEasy, 1, 0.05, 0.3},
                        Case{PhotoDifficulty::kEasy, 2, 0.05, 0.3},
                        Case{PhotoDifficulty::kMedium, 3, 0.1, 0.5},
                        Case{PhotoDifficulty::kMedium, 4, 0.1, 0.5}}) {
    const RenderPhotoOptions o = Small(c.d, c.seed);
    const RenderedPhoto r = RenderPhoto(kFig8, kRho, o);
    SCOPED_TRACE(ToString(c.d) + " seed " + std::to_string(c.seed) + ": " + r.description);
    const ExtractionSummary x = ExtractProfile(r.photo, r.rig, ExtractOptions{}, "rendered");
    ASSERT_TRUE(x.success) << x.message;
    EXPECT_EQ(x.rig_type, "platform");
    EXPECT_EQ(x.polarity, o.light_strip ? "light" : "dark");
    EXPECT_EQ(x.direction, o.overhang_left ? "left" : "right");
    const auto [rms, mx] = ErrorMm(x.profile, r.truth);
    EXPECT_LT(rms, c.rms_mm);
    EXPECT_LT(mx, c.max_mm);
    // The length to within a few pixels (the tip is blurred and, on medium, frayed).
    EXPECT_NEAR(x.length_mm, 60.0, 0.6);
  }
}

TEST(RenderPhoto, PlatformsThatTheLightHidesAreFoundByTheirFrontFace) {
  // The hard level's light gradient and shadow (45-55 %) make the platform's faces as light as
  // the background somewhere, so it does not stand out as a region. Before the front-face
  // search, these photos were taken for clamps at the image border (seeds 1-4) or had their
  // held end guessed, and their profiles were 2-40 mm off without an error. Now the platform's
  // corner is found within a couple of pixels (the oblique view still biases the mid-line,
  // which the extractor warns about: not measured here).
  int found = 0;
  for (std::uint64_t seed : {1u, 2u, 3u, 4u, 5u, 6u}) {
    RenderPhotoOptions o = RenderPhotoOptions::ForDifficulty(PhotoDifficulty::kHard, seed);
    o.overhang = 0.06;  // the default 2000 x 1500 px at 0.1 mm/px
    const RenderedPhoto r = RenderPhoto(kFig8, kRho, o);
    SCOPED_TRACE("hard seed " + std::to_string(seed) + ": " + r.description);
    const ExtractionSummary x = ExtractProfile(r.photo, r.rig, ExtractOptions{}, "rendered");
    // Whatever else happens, a photo is never measured from a clamp that is not there.
    if (!x.success) continue;
    EXPECT_EQ(x.rig_type, "platform");
    if (x.rig_type != "platform") continue;
    ++found;
    // 2.5 px = 0.25 mm. Measured: 0.3-0.8 px.
    EXPECT_LT((x.origin_px - r.origin_px).norm(), 2.5);
  }
  EXPECT_GE(found, 5);
}

// A 2 MP photo of the extract-accuracy benchmark (1732 x 1299 px at 0.1 mm/px): level d,
// benchmark seed `seed`.
RenderedPhoto BenchmarkPhoto(PhotoDifficulty d, std::uint64_t seed, const BendingLaw& law,
                             double rho, double overhang) {
  RenderPhotoOptions o = RenderPhotoOptions::ForDifficulty(d, 1732000 + seed);
  o.width_px = 1732;
  o.height_px = 1299;
  o.mm_per_px = 0.1;
  o.overhang = overhang;
  return RenderPhoto(law, rho, o);
}

TEST(RenderPhoto, ACurvingStripIsFollowedPastTheStraightExtension) {
  // Hard benchmark photo 2 (the dress fabric): the tracking passes extend the measured line
  // straight ahead, and the strip curves away from that extension before its far end. Tracking
  // used to stop there, and the profile ended 15 mm before the tip (no error); it now goes on
  // while each pass gets well past the previous guide. Measured: tip 1.1 mm off (the oblique
  // view's bias), RMS 0.24 mm.
  const RenderedPhoto r = BenchmarkPhoto(PhotoDifficulty::kHard, 2,
                                         BendingLaw::FromKes(0.0973, 0.0973, 0.0453), 0.13, 0.06);
  SCOPED_TRACE(r.description);
  const ExtractionSummary x = ExtractProfile(r.photo, r.rig, ExtractOptions{}, "rendered");
  ASSERT_TRUE(x.success) << x.message;
  EXPECT_LT(std::hypot(x.tip_mm.x() - r.tip_x_mm, x.tip_mm.y() - r.tip_y_mm), 3.0);
  EXPECT_NEAR(x.length_mm, 60.0, 3.0);
}

TEST(RenderPhoto, TipThatEndsJustBehindTheLastSectionIsNotExtrapolatedBackwards) {
  // Medium photo 3 of the extract-accuracy benchmark (the interlining at 100 mm, dark, overhang
  // left): the strip's width falls below half just before the tip search's window opens, and
  // the crossing used to be extrapolated from two samples already near zero, putting the tip
  // 87 px (8.7 mm) back along the strip. The profile was 7 mm short with no warning.
  const RenderedPhoto r = BenchmarkPhoto(PhotoDifficulty::kMedium, 3,
                                         BendingLaw::FromKes(0.5168, 1.8856, 2.2683), 0.25, 0.1);
  SCOPED_TRACE(r.description);
  const ExtractionSummary x = ExtractProfile(r.photo, r.rig, ExtractOptions{}, "rendered");
  ASSERT_TRUE(x.success) << x.message;
  // Measured: L = 100.09 mm, tip 0.15 mm off, RMS 0.024 mm.
  EXPECT_NEAR(x.length_mm, 100.0, 0.6);
  EXPECT_LT(std::hypot(x.tip_mm.x() - r.tip_x_mm, x.tip_mm.y() - r.tip_y_mm), 0.5);
  EXPECT_LT(ErrorMm(x.profile, r.truth).first, 0.1);
}

}  // namespace
}  // namespace textile
