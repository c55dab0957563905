#ifndef TEXTILE_FIT_RIG_H_
#define TEXTILE_FIT_RIG_H_

// How a camera's pixels map to millimetres in the bending plane (cantilever.md, "Photo
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

struct Lens {
  Eigen::Matrix3d camera_matrix = Eigen::Matrix3d::Identity();  // [px] fx, fy, cx, cy
  std::vector<double> distortion;  // OpenCV's k1, k2, p1, p2[, k3[, k4, k5, k6[, ...]]]
};

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

// Empty if the lens model can be undone over a width x height photo: on a grid over the whole
// photo, undistorting a point (as Rig::PlaneFromImage does) and distorting it back returns it
// within 0.05 px, and the undistorted grid keeps its order (no fold). Otherwise a phrase saying
// where it fails. Catches coefficients that OpenCV cannot invert (k1 = -5 with fx = 2000 px on
// a 2000 px photo, k1 = 1e6, k6 = 1e9).
std::string LensProblemOverImage(const Lens& lens, int width, int height);

// Parses rig JSON; throws InputError "<source>: <field>: <problem>" (one line). A lens model
// with an image_size is checked over that size (LensProblemOverImage).
Rig ParseRigJson(const std::string& text, const std::string& source);
// Reads a rig file; throws InputError if it cannot be read or is invalid.
Rig ReadRigJson(const std::string& path);
// The rig in the file format (pretty JSON text), readable by ParseRigJson.
std::string RigToJson(const Rig& rig);

}  // namespace textile

#endif  // TEXTILE_FIT_RIG_H_
