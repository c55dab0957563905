// Rig files: plain scale and homography (with or without a lens model), their mapping, their
// round trip through JSON, and every way a rig file can be wrong.

#include "textile/fit/rig.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "textile/sim/error.h"

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

// Lens models that OpenCV cannot undo over the photo gave a profile identical to no lens
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

TEST(Rig, RefusesBadFiles) {
  ExpectRefused("", "not valid JSON");
  ExpectRefused("{\"type\": \"scale\", ", "not valid JSON");
  ExpectRefused("[1, 2]", "expected a JSON object");
  ExpectRefused("{}", "type: missing");
  ExpectRefused(R"({"type": "magic"})", "expected \"scale\" or \"homography\"");
  ExpectRefused(R"({"type": "scale"})", "mm_per_px: missing");
  ExpectRefused(R"({"type": "scale", "mm_per_px": "0.1"})", "expected a number");
  ExpectRefused(R"({"type": "scale", "mm_per_px": NaN})", "not valid JSON");
  ExpectRefused(R"({"type": "scale", "mm_per_px": 0})", "must be > 0");
  ExpectRefused(R"({"type": "scale", "mm_per_px": -0.1})", "must be > 0");
  ExpectRefused(R"({"type": "scale", "mm_per_px": 1e-9})", "implausible");
  ExpectRefused(R"({"type": "homography"})", "plane_from_image: missing");
  ExpectRefused(R"({"type": "homography", "plane_from_image": [[1, 0], [0, 1]]})", "3 rows of 3");
  ExpectRefused(R"({"type": "homography", "plane_from_image": [[1, 0, 0], [2, 0, 0], [0, 0, 1]]})",
                "singular");
  ExpectRefused(
      R"({"type": "homography", "plane_from_image": [[1, 0, 0], [0, 1, 0], [0, 0, null]]})",
      "expected a number");
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
  ExpectRefused("{" + h + R"(, "reprojection_error_px": -1})", "must be >= 0");
  EXPECT_THROW(ReadRigJson("/nonexistent/rig.json"), InputError);
  EXPECT_THROW(Rig::FromScale(std::nan("")), InputError);
  EXPECT_THROW(Rig::FromScale(0.0), InputError);
}

}  // namespace
}  // namespace textile
