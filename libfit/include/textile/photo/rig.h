#ifndef TEXTILE_PHOTO_RIG_H_
#define TEXTILE_PHOTO_RIG_H_

// How a camera's pixels map to millimetres in the bending plane (docs/spec/cantilever.md, "Photo
// protocol"): either a plain scale (a perpendicular, distortion-free setup) or the homography
// from a chessboard held in the bending plane, optionally after removing lens distortion.
//
//   textile::Rig rig = textile::ReadRigJson("rig.json");       // or Rig::FromScale(0.1101)
//   Eigen::Vector2d p = rig.PlaneFromImage({1024.5, 700.0});    // [mm], in the board's frame
//   double s = rig.MmPerPxAt({1024.5, 700.0});                  // local scale [mm/px]
//
// The plane frame is whatever the calibration chose (the board's axes); extraction takes
// orientation and origin from each photo, so only distances and angles in the plane matter.
//
// Rig file (JSON; unknown fields are kept out of the way, not refused):
//
//   {"type": "scale", "mm_per_px": 0.1101}
//   {"type": "homography",
//    "plane_from_image": [[h11, h12, h13], [h21, h22, h23], [h31, h32, h33]],   // px -> mm
//    "image_size": [4000, 3000],                         // optional: the calibrated camera's
//    "camera_matrix": [[fx, 0, cx], [0, fy, cy], [0, 0, 1]],            // optional, with
//    "distortion": [k1, k2, p1, p2, k3],                 // OpenCV's model (4, 5, 8, 12, 14)
//    "reprojection_error_px": 0.21}                      // optional, informative
//
// Pixel coordinates are OpenCV's: x right, y down, the centre of the top-left pixel at (0, 0).
// With a lens model, pixels are undistorted (to the same camera matrix) before the homography.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace textile {

// A camera's lens: OpenCV's pinhole camera matrix and distortion model.
//
//   Eigen::Vector2d seen = lens.Distort(ideal);                    // where the lens puts it
//   std::optional<Eigen::Vector2d> back = lens.Undistort(seen);    // ideal again, or nothing
struct Lens {
  Eigen::Matrix3d camera_matrix = Eigen::Matrix3d::Identity();  // [px] fx, fy, cx, cy (skew s)
  // OpenCV's k1, k2, p1, p2[, k3[, k4, k5, k6[, s1, s2, s3, s4[, τx, τy]]]]; all of them are
  // applied (DistortNormalized).
  std::vector<double> distortion;

  // The pixel on which the lens puts the ray through an ideal (undistorted) pixel of the same
  // camera matrix [px -> px]: OpenCV's projectPoints of that ray.
  Eigen::Vector2d Distort(const Eigen::Vector2d& ideal_px) const;
  // The inverse: the ideal pixel that the lens puts on `px`. Newton's method on the normalised
  // coordinates (from px's own), with the model's analytic Jacobian and the step halved while
  // the residual grows; converged below 1e-10 normalised units (1e-7 px at fx = 1000 px). If it
  // does not converge, or converges beyond a fold (the Jacobian determinant not positive
  // somewhere between the optical axis and the root: not the physical pre-image), it is solved
  // again by continuation out from the axis (for t·px's coordinates, t from 0 to 1, each step
  // from the last and kept only if the model keeps its orientation between them). Nothing if
  // that fails too. Unlike OpenCV's fixed-point cv::undistortPoints, it converges at the
  // corners of strong wide angles (k1 = -0.4), and of pincushion lenses seen past their
  // turn-over (k1 = 0.204, k2 = -0.011, k3 = -0.017 at fx = 757 px on 2000 x 1500).
  std::optional<Eigen::Vector2d> Undistort(const Eigen::Vector2d& px) const;
};

// OpenCV's distortion model on normalised coordinates x = K⁻¹ (u, v, 1) [1]: radial (rational)
// k1..k6, tangential p1, p2, thin prism s1..s4 and sensor tilt τx, τy (coefficients in
// OpenCV's order, missing ones zero). Returns the distorted normalised coordinates and, if
// `jacobian` is given, d(distorted)/dx (2×2, analytic).
Eigen::Vector2d DistortNormalized(const std::vector<double>& distortion, const Eigen::Vector2d& x,
                                  Eigen::Matrix2d* jacobian = nullptr);

struct Rig {
  // Homogeneous map from image pixels to plane millimetres: p_mm ~ H · (x, y, 1).
  Eigen::Matrix3d plane_from_image = Eigen::Matrix3d::Identity();
  std::optional<Lens> lens;                   // distortion to remove first, if calibrated
  std::optional<Eigen::Vector2i> image_size;  // [px] width, height of the calibrated camera
  double reprojection_error_px = -1.0;        // from the calibration; < 0 when unknown
  bool plain_scale = false;                   // true for {"type": "scale"}
  std::string source;                         // file name or "--mm-per-px", for messages

  // A perpendicular, distortion-free rig: mm = px · mm_per_px. Throws InputError unless
  // 0 < mm_per_px < 1000 and finite.
  static Rig FromScale(double mm_per_px, const std::string& source = "--mm-per-px");

  // Maps an image point [px] to the plane [mm]; NaN if it lies on or beyond the horizon.
  Eigen::Vector2d PlaneFromImage(const Eigen::Vector2d& px) const;
  // Local scale at an image point: the square root of the Jacobian's area ratio [mm/px].
  double MmPerPxAt(const Eigen::Vector2d& px) const;
  // Throws InputError (naming the rig source and the photo) if the rig cannot map a photo of
  // this size: wrong size for the calibrated camera, the horizon crossing the image, or a lens
  // model that is not one to one over it (LensProblemOverImage).
  void CheckForImage(int width, int height, const std::string& photo) const;
};

// Empty if the lens model is one to one over a width x height photo: on a 25 × 25 grid over
// the whole photo, Lens::Undistort (as Rig::PlaneFromImage uses it) converges at every point
// with a positive Jacobian determinant, the model's local magnification lies within 0.1-10,
// OpenCV's projectPoints distorts the result back within 0.05 px, and the undistorted grid
// keeps its order (no fold). Otherwise a phrase saying where
// it fails. Catches models that are not invertible over the photo (k1 = -5 with fx = 2000 px on
// a 2000 px photo, k1 = 1e6, k6 = 1e9); accepts strong wide angles that are (k1 = -0.4,
// k2 = 0.15 with fx = 700 px on a 1400 px photo).
std::string LensProblemOverImage(const Lens& lens, int width, int height);

// Parses rig JSON; throws InputError "<source>: <field>: <problem>" (one line). A lens model
// with an image_size is checked over that size (LensProblemOverImage).
Rig ParseRigJson(const std::string& text, const std::string& source);
// Reads a rig file; throws InputError if it cannot be read or is invalid.
Rig ReadRigJson(const std::string& path);
// The rig in the file format (pretty JSON text), readable by ParseRigJson.
std::string RigToJson(const Rig& rig);

}  // namespace textile

#endif  // TEXTILE_PHOTO_RIG_H_
