// Rig calibration from chessboard photos (calibrate.h).

#include "textile/photo/calibrate.h"

#include <gsl/gsl_cdf.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <span>
#include <sstream>

#include "calibrate_stages.h"
#include "deadline.h"
#include "textile/sim/core/error.h"

namespace textile {
namespace {

double MedianOf(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Corner spacing along rows and columns [px], median.
double SquarePx(const std::vector<cv::Point2f>& c, int cols, int rows) {
  std::vector<double> d;
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      const cv::Point2f p = c[j * cols + i];
      if (i + 1 < cols) d.push_back(cv::norm(c[j * cols + i + 1] - p));
      if (j + 1 < rows) d.push_back(cv::norm(c[(j + 1) * cols + i] - p));
    }
  }
  return MedianOf(d);
}

// Two boards whose corners all lie within this distance show one pose [px]: a copy of the same
// photo, or the board and camera not moved in between. A turn of the board by a degree moves its
// outer corners by several pixels; a re-encoded copy moves them by hundredths.
constexpr double kSamePosePx = 0.5;

// The largest distance between corresponding corners, in OpenCV's order or reversed (the
// detector may start from either end of a board turned by 180°) [px].
double CornerDistancePx(const std::vector<Eigen::Vector2d>& a,
                        const std::vector<Eigen::Vector2d>& b) {
  double forward = 0.0, reversed = 0.0;
  for (size_t k = 0; k < a.size(); ++k) {
    forward = std::max(forward, (a[k] - b[k]).norm());
    reversed = std::max(reversed, (a[k] - b[b.size() - 1 - k]).norm());
  }
  return std::min(forward, reversed);
}

// A lens model is replaced by the next richer one if that one, or the full model, lowers the
// squared reprojection error significantly (F-test p-value below this). k1 is seen over the
// boards' whole span; the terms after it grow as r^5 and faster beyond the boards, where a
// false one moves the photo's corners by many times its gain on the boards (a render without
// k2 gave k2 = 168 at p = 0.004, 9 mm off at the corners): they need the stricter level.
constexpr double kLensK1Significance = 0.01;
constexpr double kLensHigherTermsSignificance = 0.001;

Eigen::Vector2d Apply(const Eigen::Matrix3d& H, const Eigen::Vector2d& p) {
  const Eigen::Vector3d q = H * Eigen::Vector3d(p.x(), p.y(), 1.0);
  return q.head<2>() / q.z();
}

}  // namespace

bool CalibrateOptions::Check(std::string* why) const {
  std::ostringstream p;
  if (cols < 3 || rows < 3 || cols > 100 || rows > 100) {
    p << "board must have 3..100 inner corners a side, got " << cols << "x" << rows;
  } else if (cols == rows) {
    p << "board " << cols << "x" << rows
      << " is square: use a board with different inner-corner counts (its orientation is then "
         "unambiguous)";
  } else if (!(std::isfinite(square_mm) && square_mm > 0.0 && square_mm <= 1000.0)) {
    p << "square size must lie in (0, 1000] mm";
  } else if (!(std::isfinite(max_error_px) && max_error_px > 0.0 && max_error_px <= 100.0)) {
    p << "maximum error must lie in (0, 100] px";
  } else if (detect_side_px < 400 || detect_side_px > 20000) {
    p << "detect_side_px must lie in [400, 20000]";
  } else if (!(std::isfinite(max_seconds) && max_seconds >= 0.0)) {
    p << "max_seconds must be a finite number >= 0 [s]";
  }
  if (why) *why = p.str();
  return p.str().empty();
}

std::string CalibrationSummary::BriefReport() const {
  std::ostringstream s;
  s.precision(4);
  if (!success) {
    s << "calibration failed: " << message;
    return s.str();
  }
  s << "rig from " << boards << " board photo(s)" << (lens_model ? " with lens distortion" : "")
    << ": " << mm_per_px << " mm/px at the board's centre; reprojection error " << rms_error_px
    << " px RMS (max " << max_error_px << " px) = " << rms_error_mm << " mm RMS (max "
    << max_error_mm << " mm)";
  if (lens_terms.empty()) return s.str();
  // The nested models add k1, k2, (p1, p2), k3 in this order: what was left out follows the
  // kept terms.
  static const char* const kNames[] = {"k1", "k2", "p1", "p2", "k3"};
  const size_t kept =
      lens_terms == "none" ? 0 : std::count(lens_terms.begin(), lens_terms.end(), ',') + 1;
  s << "\nlens: ";
  if (lens_model) {
    for (size_t k = 0; k < kept; ++k) {
      s << kNames[k] << " = " << rig.lens->distortion[k] << " ± " << distortion_sigma[k] << ", ";
    }
    s << lens_rms_px << " px RMS over all boards";
  } else {
    s << "no distortion term kept, " << lens_rms_px
      << " px RMS over all boards; the rig is the homography alone";
  }
  if (kept < 5 && !lens_candidates.empty()) {
    // Why the next terms were left out: neither the next model nor the full one lowers the
    // squared error significantly (their F-test p-values, to two digits).
    const LensCandidate& last = lens_candidates.back();
    const size_t next = kept == 2 ? 4 : kept + 1;  // p1 and p2 come together
    const auto p2 = [](double p) {
      std::ostringstream t;
      t.precision(2);
      t << p;
      return t.str();
    };
    std::string left, added;
    for (size_t k = kept; k < 5; ++k) left += std::string(k > kept ? ", " : "") + kNames[k];
    for (size_t k = kept; k < next; ++k) added += std::string(k > kept ? ", " : "") + kNames[k];
    s << "; " << left << " left out, not significant at " << p2(100.0 * last.significance)
      << " %: with " << added << " " << lens_next_rms_px << " px, p = " << p2(last.p_next);
    if (next < 5) {
      s << "; with all " << lens_full_rms_px << " px, p = " << p2(last.p_value);
    }
  }
  return s.str();
}

BoardDetection DetectChessboard(const cv::Mat& gray, int cols, int rows, const std::string& source,
                                int detect_side_px) {
  if (gray.empty() || gray.type() != CV_8UC1) {
    throw InputError(source + ": expected an 8-bit grey image");
  }
  BoardDetection d;
  d.source = source;
  d.image_size = gray.size();
  const cv::Size pattern(cols, rows);
  // Detect on a reduced image: the sector-based detector is slow on tens of megapixels, and
  // the corners are refined at full resolution afterwards.
  const double scale =
      std::min(1.0, static_cast<double>(detect_side_px) / std::max(gray.cols, gray.rows));
  cv::Mat small = gray;
  if (scale < 1.0) cv::resize(gray, small, cv::Size(), scale, scale, cv::INTER_AREA);
  std::vector<cv::Point2f> corners;
  // The sector-based detector alone: the classic cv::findChessboardCorners takes about a minute
  // to give up on a board whose corner count is wrong (adaptive thresholds tried one by one), and
  // the exhaustive search takes as long on a photo without a board.
  const bool found = cv::findChessboardCornersSB(small, pattern, corners, cv::CALIB_CB_NORMALIZE_IMAGE);
  if (!found || corners.size() != static_cast<size_t>(cols) * static_cast<size_t>(rows)) return d;
  for (auto& c : corners) {
    // Pixel centres at integers in both images: x_full = (x_small + 0.5) / scale - 0.5.
    c = cv::Point2f(static_cast<float>((c.x + 0.5) / scale - 0.5),
                    static_cast<float>((c.y + 0.5) / scale - 0.5));
  }
  // Sub-pixel refinement at full resolution, in a window of about a third of a square.
  const double sq = SquarePx(corners, cols, rows);
  const int win = std::clamp(static_cast<int>(sq / 3.0), 3, 25);
  cv::cornerSubPix(gray, corners, cv::Size(win, win), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 60, 1e-4));
  d.found = true;
  d.square_px = SquarePx(corners, cols, rows);
  for (const auto& c : corners) d.corners_px.emplace_back(c.x, c.y);
  return d;
}

namespace fit_internal {

std::vector<CalibrationSummary::LensCandidate> SelectLensModel(std::span<const LensModelFit> fits,
                                                               int boards, int corners) {
  const int models = static_cast<int>(fits.size());
  const double points = static_cast<double>(boards) * corners;
  // p-value of model b's gain over the nested model a.
  const auto p_gain = [&](int a, int b) {
    const double dof = 2.0 * points - (4.0 + 6.0 * boards + fits[b].count);
    const double extra = fits[b].count - fits[a].count;
    const double sse_a = fits[a].rms_px * fits[a].rms_px * points;
    const double sse_b = fits[b].rms_px * fits[b].rms_px * points;
    const double F = dof > 0 && sse_b > 0 ? ((sse_a - sse_b) / extra) / (sse_b / dof) : 0.0;
    return F > 0 ? gsl_cdf_fdist_Q(F, extra, std::max(dof, 1.0)) : 1.0;
  };
  std::vector<CalibrationSummary::LensCandidate> candidates;
  for (int chosen = 0;; ++chosen) {
    CalibrationSummary::LensCandidate c{fits[chosen].terms, fits[chosen].rms_px, 1.0, 1.0, 0.0};
    if (chosen + 1 < models) {
      c.p_next = p_gain(chosen, chosen + 1);
      c.p_value = p_gain(chosen, models - 1);
      c.significance = chosen == 0 ? kLensK1Significance : kLensHigherTermsSignificance;
    }
    candidates.push_back(c);
    if (!(std::min(c.p_next, c.p_value) < c.significance)) break;
  }
  return candidates;
}

}  // namespace fit_internal

namespace {

// Nested lens models, simplest first; the last is OpenCV's default. Each is fitted, and only
// the terms that lower the reprojection error significantly are kept (SelectLensModel): boards
// that barely differ in pose (a few degrees) do not determine k2 or k3, and a fit gave
// k2 = -7.6 on four distortion-free renders, 6 px at the photo's corners.
struct LensModel {
  const char* terms;
  int flags;
  int count;  // free distortion coefficients
};
const LensModel kLensModels[] = {
    {"none", cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3 | cv::CALIB_ZERO_TANGENT_DIST,
     0},
    {"k1", cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3 | cv::CALIB_ZERO_TANGENT_DIST, 1},
    {"k1, k2", cv::CALIB_FIX_K3 | cv::CALIB_ZERO_TANGENT_DIST, 2},
    {"k1, k2, p1, p2", cv::CALIB_FIX_K3, 4},
    {"k1, k2, p1, p2, k3", 0, 5}};
constexpr int kLensModelCount = static_cast<int>(std::size(kLensModels));

// What the stages of CalibrateRig share; the summary s is the result.
struct Calibration {
  Calibration(const std::vector<cv::Mat>& boards, const std::vector<std::string>& sources,
              const CalibrateOptions& o)
      : boards(boards), sources(sources), o(o), deadline(o.max_seconds) {}
  const std::vector<cv::Mat>& boards;
  const std::vector<std::string>& sources;
  const CalibrateOptions& o;
  const fit_internal::Deadline deadline;
  CalibrationSummary s;
  std::vector<cv::Point3f> object;  // the board's corners in its own frame [mm]
  std::vector<cv::Point2f> plane;   // ... in the plane [mm]
  std::vector<cv::Point2f> first;   // the first board's corners, undistorted once a lens is kept
  Rig rig;

  // The time cap (CalibrateOptions::max_seconds): each board's corner search and the lens fit
  // are bounded by OpenCV's own criteria; the cap is read before each of them. Once reached,
  // s says so and the calibration stops.
  bool PastCap(const std::string& stage) {
    const std::optional<std::string> why = deadline.Reached(stage);
    if (!why) return false;
    s.message = "calibrate: " + *why + "; no rig";
    s.seconds = deadline.Elapsed();
    return true;
  }
};

std::vector<cv::Point2f> ToCv(const std::vector<Eigen::Vector2d>& v) {
  std::vector<cv::Point2f> out;
  for (const auto& p : v) out.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  return out;
}

// Bad options, no photo, or photos of several sizes (InputError).
void CheckCalibrateInputs(const std::vector<cv::Mat>& boards,
                          const std::vector<std::string>& sources, const CalibrateOptions& o) {
  if (std::string why; !o.Check(&why)) throw InputError("calibrate: " + why);
  if (boards.empty()) throw InputError("calibrate: no board photo given");
  if (sources.size() != boards.size()) throw InputError("calibrate: one source name per photo");
  for (size_t i = 1; i < boards.size(); ++i) {
    if (boards[i].size() != boards[0].size()) {
      throw InputError(sources[i] + ": " + std::to_string(boards[i].cols) + "x" +
                       std::to_string(boards[i].rows) + " px, but " + sources[0] + " is " +
                       std::to_string(boards[0].cols) + "x" + std::to_string(boards[0].rows) +
                       " px (one camera, one size)");
    }
  }
}

// The corners of every board; false (with the message) at the first board without them.
bool DetectBoards(Calibration& c) {
  for (size_t i = 0; i < c.boards.size(); ++i) {
    if (c.PastCap("before the corners of " + c.sources[i] + " were searched")) return false;
    c.s.detections.push_back(
        DetectChessboard(c.boards[i], c.o.cols, c.o.rows, c.sources[i], c.o.detect_side_px));
    if (!c.s.detections.back().found) {
      c.s.message = c.sources[i] + ": chessboard with " + std::to_string(c.o.cols) + "x" +
                    std::to_string(c.o.rows) +
                    " inner corners not found (check --board: inner corners, not squares)";
      return false;
    }
  }
  return true;
}

// A second photo of a pose adds no pose: the lens would be fitted to fewer views than given
// (a copy of the one board under another name gave fx 7417 px instead of 8000 and k2 = -26).
void RefuseRepeatedPoses(const Calibration& c) {
  for (size_t j = 1; j < c.boards.size(); ++j) {
    for (size_t i = 0; i < j; ++i) {
      const double d =
          CornerDistancePx(c.s.detections[i].corners_px, c.s.detections[j].corners_px);
      if (d < kSamePosePx) {
        std::ostringstream m;
        m.setf(std::ios::fixed);
        m.precision(2);
        m << c.sources[j] << ": the board is in the same pose as in " << c.sources[i]
          << " (every corner within " << d << " px; a copy?): more boards must show other poses";
        throw InputError(m.str());
      }
    }
  }
}

// The board's own frame [mm]: corner (i, j) at (i, j) squares.
void LayOutGrid(Calibration& c) {
  for (int j = 0; j < c.o.rows; ++j) {
    for (int i = 0; i < c.o.cols; ++i) {
      const float x = static_cast<float>(i * c.o.square_mm);
      const float y = static_cast<float>(j * c.o.square_mm);
      c.object.emplace_back(x, y, 0.f);
      c.plane.emplace_back(x, y);
    }
  }
}

// One nested model fitted over all boards by OpenCV.
struct LensFit {
  cv::Mat K, dist, sigma;
  double rms = 0.0;
};

// Fits every nested model, the full one first: it decides plausibility. False (with the
// message) if a fit throws, the full model's error is too large, or the time cap is reached.
bool FitLensModels(Calibration& c, std::vector<LensFit>* fits) {
  std::vector<std::vector<cv::Point3f>> objects(c.boards.size(), c.object);
  std::vector<std::vector<cv::Point2f>> images;
  for (const auto& d : c.s.detections) images.push_back(ToCv(d.corners_px));
  fits->resize(kLensModelCount);
  for (int m = kLensModelCount - 1; m >= 0; --m) {
    LensFit& f = (*fits)[m];
    std::vector<cv::Mat> rvecs, tvecs;
    cv::Mat sigma_extrinsic, per_view;
    if (c.PastCap("before the lens fit")) return false;
    f.dist = cv::Mat::zeros(5, 1, CV_64F);
    try {
      f.rms = cv::calibrateCamera(objects, images, c.boards[0].size(), f.K, f.dist, rvecs, tvecs,
                                  f.sigma, sigma_extrinsic, per_view, kLensModels[m].flags);
    } catch (const cv::Exception& e) {
      c.s.message = "lens calibration failed: " + e.err;
      return false;
    }
    if (m == kLensModelCount - 1 && (!std::isfinite(f.rms) || f.rms > c.o.max_error_px)) {
      std::ostringstream msg;
      msg << "lens calibration over " << c.boards.size() << " boards has an RMS error of "
          << f.rms << " px (more than " << c.o.max_error_px
          << " px): the boards or the corner counts are inconsistent";
      c.s.message = msg.str();
      return false;
    }
  }
  return true;
}

// Takes the chosen model's lens into the rig if it is plausible over the photo, and undoes it
// on the first board's corners. False (with the message) if it folds the photo or cannot be
// undone at a corner.
bool AdoptLens(Calibration& c, const LensFit& fit) {
  Lens lens;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) lens.camera_matrix(r, k) = fit.K.at<double>(r, k);
  for (int k = 0; k < static_cast<int>(fit.dist.total()); ++k)
    lens.distortion.push_back(fit.dist.at<double>(k));
  // 1-σ of k1, k2, p1, p2, k3 (OpenCV's intrinsics order: fx, fy, cx, cy, then these).
  for (int k = 0; k < 5; ++k) c.s.distortion_sigma.push_back(fit.sigma.at<double>(4 + k));
  // A model fitted to too few or too similar views can fold the photo's corners over: extract
  // would refuse the rig, so it is not written.
  if (const std::string why = LensProblemOverImage(lens, c.boards[0].cols, c.boards[0].rows);
      !why.empty()) {
    c.s.message = "lens calibration over " + std::to_string(c.boards.size()) +
                  " boards gives an implausible distortion: " + why +
                  " (add boards in other poses, or --no-lens)";
    return false;
  }
  c.rig.lens = lens;
  c.s.lens_model = true;
  // The first board's corners without distortion, in the same camera's pixels, undone as
  // extraction undoes the photos (Lens::Undistort; the check above made sure it converges
  // over the whole photo).
  for (cv::Point2f& p : c.first) {
    const std::optional<Eigen::Vector2d> ideal = lens.Undistort({p.x, p.y});
    if (!ideal) {
      c.s.message = "lens calibration: the fitted model cannot be undone at a corner of " +
                    c.sources[0] + " (add boards in other poses, or --no-lens)";
      return false;
    }
    p = cv::Point2f(static_cast<float>(ideal->x()), static_cast<float>(ideal->y()));
  }
  return true;
}

// Fits the nested lens models, keeps the significant terms (SelectLensModel) and, with any
// term kept, adopts the lens. False (with the message) when a stage fails.
bool CalibrateLens(Calibration& c) {
  std::vector<LensFit> fits;
  if (!FitLensModels(c, &fits)) return false;
  std::vector<fit_internal::LensModelFit> rms;
  for (int m = 0; m < kLensModelCount; ++m)
    rms.push_back({kLensModels[m].terms, kLensModels[m].count, fits[m].rms});
  c.s.lens_candidates = fit_internal::SelectLensModel(rms, static_cast<int>(c.boards.size()),
                                                      static_cast<int>(c.object.size()));
  const int chosen = static_cast<int>(c.s.lens_candidates.size()) - 1;
  c.s.lens_terms = kLensModels[chosen].terms;
  c.s.lens_rms_px = fits[chosen].rms;
  c.s.lens_next_rms_px = fits[std::min(chosen + 1, kLensModelCount - 1)].rms;
  c.s.lens_full_rms_px = fits[kLensModelCount - 1].rms;
  // With no distortion term determined by the boards, the rig is the homography alone, as
  // with one board.
  if (kLensModels[chosen].count == 0) return true;
  return AdoptLens(c, fits[chosen]);
}

// Plane <- image, least squares over all corners of the first board (no outliers on a found
// board). False (with the message) for a degenerate view.
bool FitHomography(Calibration& c) {
  const cv::Mat Hcv = cv::findHomography(c.first, c.plane, 0);
  if (Hcv.empty()) {
    c.s.message = c.sources[0] + ": no homography from the corners found (degenerate board view)";
    return false;
  }
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) c.rig.plane_from_image(r, k) = Hcv.at<double>(r, k);
  c.rig.plane_from_image /= c.rig.plane_from_image(2, 2);
  return true;
}

// Errors on the first board: in the photo (reprojected grid vs corners found, undistorted) and
// in the plane (corners mapped through the rig vs the true grid); and the scale at the centre.
void MeasureRig(Calibration& c) {
  CalibrationSummary& s = c.s;
  const Eigen::Matrix3d image_from_plane = c.rig.plane_from_image.inverse();
  double se_px = 0, se_mm = 0;
  for (size_t k = 0; k < c.plane.size(); ++k) {
    const Eigen::Vector2d found(c.first[k].x, c.first[k].y);
    const Eigen::Vector2d grid(c.plane[k].x, c.plane[k].y);
    const double e_px = (Apply(image_from_plane, grid) - found).norm();
    const double e_mm = (Apply(c.rig.plane_from_image, found) - grid).norm();
    se_px += e_px * e_px;
    se_mm += e_mm * e_mm;
    s.max_error_px = std::max(s.max_error_px, e_px);
    s.max_error_mm = std::max(s.max_error_mm, e_mm);
  }
  s.rms_error_px = std::sqrt(se_px / c.plane.size());
  s.rms_error_mm = std::sqrt(se_mm / c.plane.size());
  c.rig.reprojection_error_px = s.rms_error_px;
  c.rig.source = c.sources[0];
  const Eigen::Vector2d centre =
      Apply(image_from_plane, Eigen::Vector2d((c.o.cols - 1) * c.o.square_mm / 2,
                                              (c.o.rows - 1) * c.o.square_mm / 2));
  Rig probe = c.rig;
  probe.lens.reset();  // the scale of the undistorted homography at the centre
  s.mm_per_px = probe.MmPerPxAt(centre);
}

}  // namespace

// Stages: check the inputs, find the corners, refuse repeated poses, fit and choose the lens
// (several boards), fit the homography on the first board, measure it, judge its error.
CalibrationSummary CalibrateRig(const std::vector<cv::Mat>& boards,
                                const std::vector<std::string>& sources,
                                const CalibrateOptions& o) {
  Calibration c(boards, sources, o);
  CheckCalibrateInputs(boards, sources, o);
  c.s.boards = static_cast<int>(boards.size());
  if (!DetectBoards(c)) return c.s;
  RefuseRepeatedPoses(c);
  LayOutGrid(c);
  c.rig.image_size = Eigen::Vector2i(boards[0].cols, boards[0].rows);
  c.first = ToCv(c.s.detections[0].corners_px);
  if (boards.size() > 1 && o.lens && !CalibrateLens(c)) return c.s;
  if (c.PastCap("before the homography")) return c.s;
  if (!FitHomography(c)) return c.s;
  MeasureRig(c);
  CalibrationSummary& s = c.s;
  s.seconds = c.deadline.Elapsed();
  s.rig = c.rig;
  if (!(s.rms_error_px <= o.max_error_px)) {
    std::ostringstream m;
    m.precision(3);
    m << sources[0] << ": reprojection error " << s.rms_error_px
      << " px RMS is implausible (more than " << o.max_error_px
      << " px): the board is not flat, is blurred, or the lens needs several board photos";
    s.message = m.str();
    return s;
  }
  s.success = true;
  return s;
}

}  // namespace textile
