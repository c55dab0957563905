// Rig files: plain scale and homography (with or without a lens model), their mapping, their
// round trip through JSON, and every way a rig file can be wrong.

#include "textile/photo/rig.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

void ExpectRefused(const std::string& text, const std::string& words) {
  try {
    ParseRigJson(text, "rig.json");
    ADD_FAILURE() << "accepted: " << text;
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("rig.json", 0), 0u) << m;
    EXPECT_NE(m.find(words), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

TEST(Rig, PlainScaleMapsPixelsToMillimetres) {
  const Rig rig = Rig::FromScale(0.1101);
  const Eigen::Vector2d p = rig.PlaneFromImage({100.0, 200.0});
  EXPECT_NEAR(p.x(), 11.01, 1e-12);
  EXPECT_NEAR(p.y(), 22.02, 1e-12);
  EXPECT_NEAR(rig.MmPerPxAt({5, 5}), 0.1101, 1e-12);
  EXPECT_NO_THROW(rig.CheckForImage(2193, 1294, "photo.jpg"));
}

TEST(Rig, HomographyMapsLikeTheMatrixAndHasALocalScale) {
  Rig rig;
  rig.plane_from_image << 0.1, 0.01, -3.0, -0.005, 0.12, 4.0, 1e-5, 2e-5, 1.0;
  const Eigen::Vector2d px(800.0, 600.0);
  const Eigen::Vector3d h = rig.plane_from_image * Eigen::Vector3d(px.x(), px.y(), 1.0);
  const Eigen::Vector2d p = rig.PlaneFromImage(px);
  EXPECT_NEAR(p.x(), h.x() / h.z(), 1e-12);
  EXPECT_NEAR(p.y(), h.y() / h.z(), 1e-12);
  // Local scale: the square root of the Jacobian's determinant, by finite differences of the
  // exact map (tolerance: their truncation error at ±1 px).
  const double e = 1e-3;
  const Eigen::Vector2d dx = (rig.PlaneFromImage(px + Eigen::Vector2d(e, 0)) -
                              rig.PlaneFromImage(px - Eigen::Vector2d(e, 0))) /
                             (2 * e);
  const Eigen::Vector2d dy = (rig.PlaneFromImage(px + Eigen::Vector2d(0, e)) -
                              rig.PlaneFromImage(px - Eigen::Vector2d(0, e))) /
                             (2 * e);
  EXPECT_NEAR(rig.MmPerPxAt(px), std::sqrt(std::abs(dx.x() * dy.y() - dx.y() * dy.x())), 1e-6);
}

TEST(Rig, LensModelWithoutDistortionChangesNothing) {
  Rig rig = Rig::FromScale(0.2);
  rig.plain_scale = false;
  Lens lens;
  lens.camera_matrix << 1000, 0, 640, 0, 1000, 480, 0, 0, 1;
  lens.distortion = {0, 0, 0, 0, 0};
  rig.lens = lens;
  const Eigen::Vector2d p = rig.PlaneFromImage({100.0, 900.0});
  EXPECT_NEAR(p.x(), 20.0, 1e-9);
  EXPECT_NEAR(p.y(), 180.0, 1e-9);
  // Barrel distortion moves an off-centre point outwards once undistorted.
  rig.lens->distortion = {-0.2, 0, 0, 0, 0};
  EXPECT_GT((rig.PlaneFromImage({100.0, 900.0}) - Eigen::Vector2d(128, 96)).norm(),
            (p - Eigen::Vector2d(128, 96)).norm());
}

TEST(Rig, JsonRoundTrip) {
  Rig rig;
  rig.plane_from_image << 0.1, 0.01, -3.0, -0.005, 0.12, 4.0, 1e-5, 2e-5, 1.0;
  rig.image_size = Eigen::Vector2i(4000, 3000);
  Lens lens;
  lens.camera_matrix << 3000, 0, 2000, 0, 3000, 1500, 0, 0, 1;
  lens.distortion = {-0.1, 0.01, 0.001, -0.001, 0.0};
  rig.lens = lens;
  rig.reprojection_error_px = 0.21;
  const Rig back = ParseRigJson(RigToJson(rig), "round trip");
  EXPECT_TRUE(back.plane_from_image.isApprox(rig.plane_from_image, 1e-15));
  ASSERT_TRUE(back.image_size && back.lens);
  EXPECT_EQ(*back.image_size, *rig.image_size);
  EXPECT_TRUE(back.lens->camera_matrix.isApprox(lens.camera_matrix));
  EXPECT_EQ(back.lens->distortion, lens.distortion);
  EXPECT_DOUBLE_EQ(back.reprojection_error_px, 0.21);
  const Rig scale = ParseRigJson(RigToJson(Rig::FromScale(0.05)), "round trip");
  EXPECT_TRUE(scale.plain_scale);
  EXPECT_NEAR(scale.MmPerPxAt({0, 0}), 0.05, 1e-15);
}

TEST(Rig, ChecksThePhotoAgainstTheCalibration) {
  Rig rig = ParseRigJson(R"({"type": "homography", "image_size": [4000, 3000],
    "plane_from_image": [[0.1, 0, 0], [0, 0.1, 0], [0, 0, 1]]})",
                         "rig.json");
  EXPECT_NO_THROW(rig.CheckForImage(4000, 3000, "a.jpg"));
  EXPECT_THROW(rig.CheckForImage(2000, 1500, "a.jpg"), InputError);
  // A horizon through the photo: w = 1 - x/1000 changes sign at x = 1000.
  Rig horizon = ParseRigJson(R"({"type": "homography",
    "plane_from_image": [[0.1, 0, 0], [0, 0.1, 0], [-0.001, 0, 1]]})",
                             "rig.json");
  EXPECT_THROW(horizon.CheckForImage(2000, 1500, "a.jpg"), InputError);
}

// Lens models that are not one to one over the photo gave a profile identical to no lens
// (k1 = -5), or a crash in extraction (k6 = 1e9). They are refused naming the field, at parse
// time when the rig gives image_size, else when it meets a photo; real lenses pass.
TEST(Rig, RefusesLensModelsThatCannotBeUndoneOverThePhoto) {
  const std::string h =
      R"("type": "homography", "plane_from_image": [[0.1, 0, 0], [0, 0.1, 0], [0, 0, 1]],
         "camera_matrix": [[2000, 0, 1000], [0, 2000, 750], [0, 0, 1]])";
  for (const char* d : {"[-5, 0, 0, 0, 0]", "[1e6, 0, 0, 0, 0]", "[0, 0, 0, 0, 0, 0, 0, 1e9]",
                        "[0, -40, 0, 0, 0]", "[0, 0, 0.9, 0, 0]"}) {
    const Rig rig = ParseRigJson("{" + h + R"(, "distortion": )" + d + "}", "rig.json");
    try {
      rig.CheckForImage(2000, 1500, "a.jpg");
      ADD_FAILURE() << "accepted: " << d;
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind("rig.json: distortion: lens model not undone over a.jpg", 0), 0u) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
    ExpectRefused("{" + h + R"(, "image_size": [2000, 1500], "distortion": )" + d + "}",
                  "distortion: lens model not undone");
  }
  // Real lenses, from a phone's wide angle (strong barrel) to a long lens, and a calibration's
  // rational model: undone everywhere to far better than the 0.05 px demanded.
  for (const char* d : {"[-0.3, 0.12, 0.001, -0.001, -0.02]", "[0.05, -0.1, 0, 0, 0.1]",
                        "[-0.12, 0.05, 0, 0, 0, 0.1, 0.02, 0.01]", "[0, 0, 0, 0]"}) {
    const std::string text = "{" + h + R"(, "image_size": [2000, 1500], "distortion": )" + d + "}";
    EXPECT_NO_THROW(ParseRigJson(text, "rig.json").CheckForImage(2000, 1500, "a.jpg")) << d;
  }
  // A barrel lens (k1 = -0.3: r_d = r (1 - 0.3 r^2) turns back at r_d = 0.70) is fine over
  // its 800x600 photo (corners at r_d = 0.5) but not over a larger one through the same camera
  // matrix (corners at r_d = 2).
  Lens barrel;
  barrel.camera_matrix << 1000, 0, 400, 0, 1000, 300, 0, 0, 1;
  barrel.distortion = {-0.3, 0, 0, 0, 0};
  EXPECT_EQ(LensProblemOverImage(barrel, 800, 600), "");
  EXPECT_NE(LensProblemOverImage(barrel, 2000, 1500), "");
}

// OpenCV's projectPoints of the ray through normalised coordinates x [px].
Eigen::Vector2d OpenCvDistort(const Lens& lens, const Eigen::Vector2d& x) {
  cv::Mat K, D(lens.distortion, true);
  cv::eigen2cv(lens.camera_matrix, K);
  std::vector<cv::Point2d> out;
  cv::projectPoints(std::vector<cv::Point3d>{{x.x(), x.y(), 1.0}}, cv::Vec3d(0, 0, 0),
                    cv::Vec3d(0, 0, 0), K, D, out);
  return {out[0].x, out[0].y};
}

Eigen::Vector2d Normalised(const Lens& lens, const Eigen::Vector2d& px) {
  const Eigen::Matrix3d& K = lens.camera_matrix;
  return {(px.x() - K(0, 2)) / K(0, 0), (px.y() - K(1, 2)) / K(1, 1)};
}

// Every coefficient of OpenCV's model (radial rational, tangential, thin prism, tilt): the
// forward model is OpenCV's, and its Jacobian is the finite difference of it.
TEST(Lens, DistortionIsOpenCvsModelWithItsJacobian) {
  Lens lens;
  lens.camera_matrix << 1800, 0, 1010, 0, 1750, 740, 0, 0, 1;
  lens.distortion = {-0.21, 0.08,  0.0012, -0.0007, -0.015, 0.05, -0.01,
                     0.004, 0.002, -0.001, 0.0015,  0.0005, 0.01, -0.02};
  for (const size_t n : {4, 5, 8, 12, 14}) {
    Lens l = lens;
    l.distortion.resize(n);
    for (const Eigen::Vector2d& x : {Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(-0.55, 0.41),
                                     Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.7, 0.5)}) {
      // Against OpenCV: rounding only (1e-9 px at 1800 px per unit).
      const Eigen::Vector2d px =
          l.Distort(l.camera_matrix.topLeftCorner<2, 2>() * x + l.camera_matrix.block<2, 1>(0, 2));
      EXPECT_LT((px - OpenCvDistort(l, x)).norm(), 1e-9)
          << n << " coefficients at " << x.transpose();
      // Central differences of step 1e-6: truncation ~1e-12, rounding ~1e-10.
      Eigen::Matrix2d J;
      DistortNormalized(l.distortion, x, &J);
      const double h = 1e-6;
      for (int k = 0; k < 2; ++k) {
        const Eigen::Vector2d e = h * Eigen::Vector2d::Unit(k);
        const Eigen::Vector2d fd =
            (DistortNormalized(l.distortion, x + e) - DistortNormalized(l.distortion, x - e)) /
            (2 * h);
        EXPECT_LT((J.col(k) - fd).norm(), 1e-8) << n << " coefficients, column " << k;
      }
    }
  }
}

// Where OpenCV's fixed-point iteration converges (a mild lens), Newton's method finds the same
// undistorted points, to 1e-6 px.
TEST(Lens, UndistortAgreesWithOpenCvOnAMildLens) {
  Lens lens;
  lens.camera_matrix << 3000, 0, 2000, 0, 3000, 1500, 0, 0, 1;
  lens.distortion = {-0.1, 0.01, 0.001, -0.001, 0.002};
  cv::Mat K, D(lens.distortion, true);
  cv::eigen2cv(lens.camera_matrix, K);
  std::vector<cv::Point2d> px, ocv;
  for (int j = 0; j <= 10; ++j)
    for (int i = 0; i <= 10; ++i) px.emplace_back(-0.5 + 400.0 * i, -0.5 + 300.0 * j);
  cv::undistortPoints(
      px, ocv, K, D, cv::noArray(), K,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 1000, 1e-14));
  double worst = 0.0;
  for (size_t k = 0; k < px.size(); ++k) {
    const std::optional<Eigen::Vector2d> ours = lens.Undistort({px[k].x, px[k].y});
    ASSERT_TRUE(ours) << px[k];
    worst = std::max(worst, (*ours - Eigen::Vector2d(ocv[k].x, ocv[k].y)).norm());
  }
  EXPECT_LT(worst, 1e-6);
}

// A strong wide angle (fx = 700 px on a 1400 x 1000 photo, k1 = -0.4, k2 = 0.15) is one to
// one over its photo (r_d = r - 0.4 r³ + 0.15 r⁵ rises everywhere), but OpenCV's iterative
// undistortion does not converge at its corners, and such rigs were refused. Newton's method
// undoes it to 1e-7 px.
TEST(Lens, StrongWideAngleIsUndoneToTheCorners) {
  Lens lens;
  lens.camera_matrix << 700, 0, 699.5, 0, 700, 499.5, 0, 0, 1;
  lens.distortion = {-0.4, 0.15, 0, 0, 0};
  EXPECT_EQ(LensProblemOverImage(lens, 1400, 1000), "");
  for (const Eigen::Vector2d& corner :
       {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(1399.5, -0.5), Eigen::Vector2d(-0.5, 999.5),
        Eigen::Vector2d(1399.5, 999.5)}) {
    const std::optional<Eigen::Vector2d> ideal = lens.Undistort(corner);
    ASSERT_TRUE(ideal) << corner.transpose();
    // Back through OpenCV's own forward model.
    const Eigen::Vector2d back = OpenCvDistort(lens, Normalised(lens, *ideal));
    EXPECT_LT((back - corner).norm(), 0.01) << corner.transpose();
    // The corner lies at r_d = 1.23 normalised; undistorted, further out (barrel).
    EXPECT_GT(Normalised(lens, *ideal).norm(), Normalised(lens, corner).norm() + 0.1);
  }
  // And a rig with it maps the photo (it was refused: "lens model not undone").
  Rig rig;
  rig.plane_from_image = Eigen::Vector3d(0.1, 0.1, 1.0).asDiagonal();
  rig.lens = lens;
  EXPECT_NO_THROW(rig.CheckForImage(1400, 1000, "wide.jpg"));
  EXPECT_TRUE(rig.PlaneFromImage({-0.5, -0.5}).allFinite());
}

// Pincushion lenses whose photo corners lie past the model's turn-over as seen, though their
// ideal points lie before it: Newton's method from the corner's own coordinates converged on
// the folded branch beyond the turn-over, and the rig was refused ("it folds the photo over
// near (-0.5, -0.5)"); the continuation out from the optical axis finds the physical point.
// 25 of 2970 random invertible radial models over a 2000 x 1500 photo were refused so.
TEST(Lens, PincushionCornersPastTheTurnOverAsSeenAreUndone) {
  struct Case {
    double fx;
    int width, height;
    std::vector<double> distortion;
    double corner_r;  // the corner's ideal radius, normalised (0: not checked)
  };
  const Case cases[] = {
      // r_d(r) = r (1 + 0.204 r^2 - 0.011 r^4 - 0.017 r^6) turns over at r = 1.631; the corner
      // is seen at r_d = 1.651 and comes from r = 1.340.
      {757, 2000, 1500, {0.204, -0.011, 0, 0, -0.017}, 1.340},
      // A phone-like camera.
      {2867, 4000, 3000, {0.227, 0.304, 0, 0, -0.788}, 0.0},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.fx);
    Lens lens;
    lens.camera_matrix << c.fx, 0, (c.width - 1) / 2.0, 0, c.fx, (c.height - 1) / 2.0, 0, 0, 1;
    lens.distortion = c.distortion;
    EXPECT_EQ(LensProblemOverImage(lens, c.width, c.height), "");
    for (const Eigen::Vector2d& corner :
         {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(c.width - 0.5, -0.5),
          Eigen::Vector2d(-0.5, c.height - 0.5), Eigen::Vector2d(c.width - 0.5, c.height - 0.5)}) {
      const std::optional<Eigen::Vector2d> ideal = lens.Undistort(corner);
      ASSERT_TRUE(ideal) << corner.transpose();
      // Back through OpenCV's own forward model.
      EXPECT_LT((OpenCvDistort(lens, Normalised(lens, *ideal)) - corner).norm(), 0.01)
          << corner.transpose();
      // Pincushion: the ideal point lies nearer the axis than the one seen.
      EXPECT_LT(Normalised(lens, *ideal).norm(), Normalised(lens, corner).norm());
      if (c.corner_r > 0) {
        EXPECT_NEAR(Normalised(lens, *ideal).norm(), c.corner_r, 1e-3);
      }
    }
    // And a rig file with it is read (it was refused when read with its image_size).
    std::ostringstream text;
    text.precision(17);
    text << R"({"type": "homography", "plane_from_image": [[0.1, 0, 0], [0, 0.1, 0], [0, 0, 1]],)"
         << R"("image_size": [)" << c.width << ", " << c.height << R"(], "camera_matrix": [[)"
         << c.fx << ", 0, " << (c.width - 1) / 2.0 << "], [0, " << c.fx << ", "
         << (c.height - 1) / 2.0 << R"(], [0, 0, 1]], "distortion": [)";
    for (size_t k = 0; k < c.distortion.size(); ++k) text << (k ? ", " : "") << c.distortion[k];
    text << "]}";
    EXPECT_NO_THROW(ParseRigJson(text.str(), "rig.json")) << text.str();
  }
}

// A point the lens puts nowhere in reach (k1 = -5: r_d = r - 5 r³ is at most 0.17) has no
// undistorted point; Newton's method says so instead of returning a wrong one.
TEST(Lens, UndistortFailsWhereTheModelIsNotInvertible) {
  Lens lens;
  lens.camera_matrix << 2000, 0, 1000, 0, 2000, 750, 0, 0, 1;
  lens.distortion = {-5, 0, 0, 0, 0};
  EXPECT_TRUE(lens.Undistort({1100.0, 750.0}));  // r_d = 0.05: still one to one
  EXPECT_FALSE(lens.Undistort({1999.5, 1499.5}));
  EXPECT_NE(LensProblemOverImage(lens, 2000, 1500), "");
}

TEST(Rig, RefusesBadFiles) {
  ExpectRefused("", "not valid JSON");
  ExpectRefused("{\"type\": \"scale\", ", "not valid JSON");
  ExpectRefused("[1, 2]", "rig.json: (top level): must be a JSON object, got [1,2]");
  ExpectRefused("{}", "type: missing");
  ExpectRefused(R"({"type": "magic"})", "type: unknown type 'magic' (use \"scale\" or \"homography\")");
  ExpectRefused(R"({"type": 3})", "type: must be \"scale\" or \"homography\", got 3");
  ExpectRefused(R"({"type": "scale"})", "mm_per_px: missing");
  ExpectRefused(R"({"type": "scale", "mm_per_px": "0.1"})", "mm_per_px: must be a number, got \"0.1\"");
  ExpectRefused(R"({"type": "scale", "mm_per_px": NaN})", "not valid JSON");
  ExpectRefused(R"({"type": "scale", "mm_per_px": 0})", "mm_per_px: must be > 0, got 0");
  ExpectRefused(R"({"type": "scale", "mm_per_px": -0.1})", "must be > 0");
  ExpectRefused(R"({"type": "scale", "mm_per_px": 1e-9})", "implausible");
  ExpectRefused(R"({"type": "homography"})", "plane_from_image: missing");
  ExpectRefused(R"({"type": "homography", "plane_from_image": [[1, 0], [0, 1]]})", "plane_from_image: must be a 3×3 array");
  ExpectRefused(R"({"type": "homography", "plane_from_image": [[1, 0, 0], [2, 0, 0], [0, 0, 1]]})",
                "singular");
  ExpectRefused(
      R"({"type": "homography", "plane_from_image": [[1, 0, 0], [0, 1, 0], [0, 0, null]]})",
      "plane_from_image[2][2]: must be a number, got null");
  const std::string h =
      R"("type": "homography", "plane_from_image": [[0.1, 0, 0], [0, 0.1, 0], [0, 0, 1]])";
  ExpectRefused("{" + h + R"(, "image_size": [0, 10]})", "image_size");
  ExpectRefused("{" + h + R"(, "camera_matrix": [[1000, 0, 1], [0, 1000, 1], [0, 0, 1]]})",
                "distortion: missing");
  ExpectRefused(
      "{" + h +
          R"(, "camera_matrix": [[-1, 0, 1], [0, 1000, 1], [0, 0, 1]], "distortion": [0, 0, 0, 0]})",
      "fx, fy > 0");
  ExpectRefused(
      "{" + h +
          R"(, "camera_matrix": [[1000, 0, 1], [0, 1000, 1], [0, 0, 1]], "distortion": [0, 0, 0]})",
      "4, 5, 8, 12 or 14");
  ExpectRefused("{" + h + R"(, "reprojection_error_px": -1})",
                "reprojection_error_px: must be >= 0, got -1");
  EXPECT_THROW(ReadRigJson("/nonexistent/rig.json"), InputError);
  EXPECT_THROW(Rig::FromScale(std::nan("")), InputError);
  EXPECT_THROW(Rig::FromScale(0.0), InputError);
}

}  // namespace
}  // namespace textile
