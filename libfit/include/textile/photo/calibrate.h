#ifndef TEXTILE_PHOTO_CALIBRATE_H_
#define TEXTILE_PHOTO_CALIBRATE_H_

// Rig calibration from chessboard photos (docs/spec/cantilever.md, "Photo protocol"): a standard
// chessboard held in the bending plane, photographed by the camera that takes the cantilever
// photos, gives the image -> plane homography; several photos of the board (in the plane and in
// other poses) also give the lens distortion.
//
//   textile::CalibrateOptions o;
//   o.cols = 9; o.rows = 6; o.square_mm = 10.0;            // inner corners, square size
//   std::vector<cv::Mat> boards = {textile::ReadPhotoGray("board.png")};
//   textile::CalibrationSummary c = textile::CalibrateRig(boards, {"board.png"}, o);
//   if (!c.success) throw textile::ComputeError(c.message);  // board not found, error too large
//   std::string json = textile::RigToJson(c.rig);             // what `textile extract --rig` reads
//
// The first board defines the plane: it must lie in the bending plane. Its frame (mm): x along
// the board's rows of corners, y across them, origin at the first corner found; extraction takes
// orientation and origin from each photo, so only distances and angles in the plane matter.
// Corners: cv::findChessboardCornersSB on an image reduced to at most 2000 px, then
// cv::cornerSubPix at full resolution.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "textile/photo/rig.h"

namespace textile {

struct CalibrateOptions {
  int cols = 0, rows = 0;      // inner corners along a row and down a column (e.g. 9 x 6)
  double square_mm = 0.0;      // side of a square [mm]
  double max_error_px = 1.0;   // refuse a calibration whose RMS reprojection error is larger [px]
  bool lens = true;            // with several boards, also fit lens distortion (k1, k2, p1, p2,
                               // k3, as many as the boards determine)
  int detect_side_px = 2000;   // long side of the reduced image the corners are found on [px]
  double max_seconds = 60.0;   // wall-time cap, read after each board and after the lens fit [s]

  // True if every field is usable; otherwise *why says which and why.
  bool Check(std::string* why) const;
};

// The corners of one board photo.
struct BoardDetection {
  std::string source;
  bool found = false;
  cv::Size image_size;
  std::vector<Eigen::Vector2d> corners_px;  // #cols·rows, row-major as OpenCV orders them [px]
  double square_px = 0.0;                   // median corner spacing [px]
};

struct CalibrationSummary {
  bool success = false;
  std::string message;            // why not, one line (names the board photo)
  Rig rig;                        // homography (and lens) for the first board's camera
  int boards = 0;                 // photos used
  bool lens_model = false;        // distortion was fitted (several boards)
  double rms_error_px = 0.0;      // corners of the first board: reprojected vs found, RMS [px]
  double max_error_px = 0.0;      // ... and the largest [px]
  double rms_error_mm = 0.0;      // found corners mapped to the plane vs the true grid, RMS [mm]
  double max_error_mm = 0.0;
  double lens_rms_px = 0.0;       // cv::calibrateCamera's RMS over all boards, if fitted [px]
  // The lens fit (several boards): nested models none, k1, (k1, k2), (k1, k2, p1, p2) and
  // (k1, k2, p1, p2, k3) are fitted and, from none, the next is taken while it or the full
  // model lowers the squared error significantly (F-test: at 1 % for k1, 0.1 % for the
  // terms after it). lens_rms_px is the kept model's.
  std::string lens_terms;         // the kept model's terms ("none": no lens in the rig); empty
                                  // when no lens was fitted
  double lens_next_rms_px = 0.0;  // RMS over all boards of the next model, with one more term
                                  // (group) than the kept one [px]; the kept one's if full
  double lens_full_rms_px = 0.0;  // RMS over all boards of the full model [px]
  std::vector<double> distortion_sigma;  // 1-σ of k1, k2, p1, p2, k3 (0 for terms not kept)
  struct LensCandidate {
    std::string terms;
    double rms_px = 0.0;        // over all boards [px]
    double p_next = 1.0;        // of the next model's improvement on it (F-test); 1 for the full
    double p_value = 1.0;       // of the full model's improvement on it (F-test); 1 for the full
    double significance = 0.0;  // the level either must be below to go on (0.01 or 0.001)
  };
  std::vector<LensCandidate> lens_candidates;  // tried, simplest first, up to the kept one
  double mm_per_px = 0.0;         // local scale at the board's centre [mm/px]
  std::vector<BoardDetection> detections;
  double seconds = 0.0;

  // A line or two for people.
  std::string BriefReport() const;
};

// Finds the inner corners of a cols x rows chessboard in an 8-bit grey photo.
BoardDetection DetectChessboard(const cv::Mat& gray, int cols, int rows, const std::string& source,
                                int detect_side_px = 2000);

// Calibrates a rig from one or more board photos (the first lies in the bending plane). Throws
// InputError for bad options, an empty list, photos of different sizes or two boards in the same
// pose (every corner within half a pixel: a copy adds no view); returns success = false
// when a board is not found or the reprojection error exceeds options.max_error_px.
CalibrationSummary CalibrateRig(const std::vector<cv::Mat>& boards,
                                const std::vector<std::string>& sources,
                                const CalibrateOptions& options);

}  // namespace textile

#endif  // TEXTILE_PHOTO_CALIBRATE_H_
