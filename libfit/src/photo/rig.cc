#include "textile/photo/rig.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <sstream>

#include "textile/sim/core/error.h"
#include "textile/sim/io/json_fields.h"
#include "textile/sim/io/json_text.h"

namespace textile {
namespace {

using nlohmann::json;

// Plausible pixel scales: a microscope at 1 µm/px to a wide shot at 1 m/px.
constexpr double kMinMmPerPx = 1e-3;
constexpr double kMaxMmPerPx = 1e3;
// Largest image side a rig may describe [px].
constexpr int kMaxSidePx = 100000;

// A 3×3 matrix read by JsonFields::Matrix3 (row-major).
Eigen::Matrix3d Matrix3(const JsonFields& f, const json& j, const std::string& field) {
  const std::array<double, 9> v = f.Matrix3(f.Require(j, field), field);
  return Eigen::Matrix<double, 3, 3, Eigen::RowMajor>(v.data());
}

// A lens model must be undone exactly where photos are measured: undistorting a point and
// distorting it back must return it within this distance [px] (a tenth of the extraction's
// sub-pixel scatter). Real lenses meet it by orders of magnitude.
constexpr double kLensRoundTripPx = 0.05;
// The most a lens model may magnify (or shrink) its image locally, relative to the optical
// axis: strong wide angles reach 2 (k1 = -0.4, k2 = 0.15 at r = 1.5: 1.3).
constexpr double kLensMaxScale = 10.0;
// Grid cells per side on which the lens model is checked over a photo.
constexpr int kLensGridCells = 24;

std::string Px(double x, double y) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(1);
  s << "(" << x << ", " << y << ") px";
  return s.str();
}

// NaN-safe JSON: the file format has no NaN.
json Matrix3ToJson(const Eigen::Matrix3d& m) {
  json rows = json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

// Lens::Undistort: converged when the distorted guess is this close to the observed point
// [normalised units]; at most this many Newton steps, each halved at most kMaxHalvings times.
constexpr double kUndistortTolerance = 1e-10;
constexpr int kMaxNewtonSteps = 100;
constexpr int kMaxHalvings = 40;
// Points along the ray from the optical axis to an undistorted point at which the model must
// keep its orientation (Jacobian determinant > 0).
constexpr int kFoldSamples = 32;
// Continuation out from the optical axis (UndoLens): first step, and the smallest step before
// it gives up [fraction of the way].
constexpr double kContinuationFirstStep = 0.125;
constexpr double kMinContinuationStep = 1e-4;

enum class UndoStatus { kConverged, kNoConvergence, kFolded };

// OpenCV's sensor tilt (computeTiltProjectionMatrix in its distortion_model.hpp): the
// projective map of the distorted normalised coordinates onto a sensor tilted by τx, τy.
Eigen::Matrix3d TiltProjection(double tau_x, double tau_y) {
  const double cx = std::cos(tau_x), sx = std::sin(tau_x);
  const double cy = std::cos(tau_y), sy = std::sin(tau_y);
  Eigen::Matrix3d rot_x, rot_y, proj_z;
  rot_x << 1, 0, 0, 0, cx, sx, 0, -sx, cx;
  rot_y << cy, 0, -sy, 0, 1, 0, sy, 0, cy;
  const Eigen::Matrix3d rot_xy = rot_y * rot_x;
  proj_z << rot_xy(2, 2), 0, -rot_xy(0, 2), 0, rot_xy(2, 2), -rot_xy(1, 2), 0, 0, 1;
  return proj_z * rot_xy;
}

Eigen::Vector2d NormalisedFromPixel(const Eigen::Matrix3d& K, const Eigen::Vector2d& px) {
  const double y = (px.y() - K(1, 2)) / K(1, 1);
  return {(px.x() - K(0, 2) - K(0, 1) * y) / K(0, 0), y};
}

Eigen::Vector2d PixelFromNormalised(const Eigen::Matrix3d& K, const Eigen::Vector2d& x) {
  return {K(0, 0) * x.x() + K(0, 1) * x.y() + K(0, 2), K(1, 1) * x.y() + K(1, 2)};
}

// Solves DistortNormalized(x) = target for x by damped Newton from x = *x (the step halved
// while the residual grows); true if it converged.
bool SolveNewton(const std::vector<double>& d, const Eigen::Vector2d& target, Eigen::Vector2d* x) {
  Eigen::Matrix2d J;
  Eigen::Vector2d f = DistortNormalized(d, *x, &J) - target;
  double residual = f.norm();
  for (int step = 0; step <= kMaxNewtonSteps && std::isfinite(residual); ++step) {
    if (residual < kUndistortTolerance) return true;
    const double det = J.determinant();
    if (!(std::abs(det) > 1e-300) || step == kMaxNewtonSteps) break;
    const Eigen::Vector2d dx = -J.inverse() * f;
    // Halve the step until the residual falls (damping far from the root, or near a fold).
    double lambda = 1.0;
    bool fell = false;
    for (int h = 0; h <= kMaxHalvings; ++h, lambda *= 0.5) {
      Eigen::Matrix2d J_try;
      const Eigen::Vector2d x_try = *x + lambda * dx;
      const Eigen::Vector2d f_try = DistortNormalized(d, x_try, &J_try) - target;
      if (f_try.norm() < residual) {
        *x = x_try, f = f_try, J = J_try, residual = f_try.norm();
        fell = true;
        break;
      }
    }
    if (!fell) break;
  }
  return false;
}

// The physical pre-image is reached from the optical axis (where the model is about the
// identity) without the model folding over on the way: its Jacobian determinant stays
// positive along the segment from a to b. A root beyond a fold is another point that the lens
// would put on the same pixel (k1 = -5 puts r = 0.6 on the opposite side, with det > 0 there).
bool KeepsOrientation(const std::vector<double>& d, const Eigen::Vector2d& a,
                      const Eigen::Vector2d& b, int samples) {
  for (int k = 1; k <= samples; ++k) {
    Eigen::Matrix2d J;
    DistortNormalized(d, a + (b - a) * (static_cast<double>(k) / samples), &J);
    if (!(J.determinant() > 0.0)) return false;
  }
  return true;
}

// Solves DistortNormalized(x) = target for x: Newton from x = target, and if that does not
// converge or lands beyond a fold, by continuation out from the optical axis: the solution
// for t · target, t from 0 (x = 0) to 1, each step solved from the previous one and kept only
// if the model keeps its orientation between them (else the step is halved). Newton from
// the pixel's own coordinates lands beyond the fold when the observed radius lies past the
// model's turn-over although the physical pre-image lies before it: a pincushion lens with
// k1 = 0.204, k2 = -0.011, k3 = -0.017 at fx = 757 px puts the corner of a 2000 x 1500 photo
// at r_d = 1.651, from r = 1.340, and turns over at r = 1.631.
UndoStatus UndoLens(const std::vector<double>& d, const Eigen::Vector2d& target,
                    Eigen::Vector2d* x_out) {
  Eigen::Vector2d x = target;
  const bool converged = SolveNewton(d, target, &x);
  if (converged && KeepsOrientation(d, Eigen::Vector2d::Zero(), x, kFoldSamples)) {
    *x_out = x;
    return UndoStatus::kConverged;
  }
  Eigen::Vector2d y = Eigen::Vector2d::Zero();
  double t = 0.0, h = kContinuationFirstStep;
  while (t < 1.0) {
    const double t_next = std::min(1.0, t + h);
    Eigen::Vector2d y_next = y;
    if (SolveNewton(d, t_next * target, &y_next) &&
        KeepsOrientation(d, y, y_next, kFoldSamples / 4)) {
      y = y_next, t = t_next, h *= 2.0;
    } else if ((h *= 0.5) < kMinContinuationStep) {
      break;
    }
  }
  if (t >= 1.0 && KeepsOrientation(d, Eigen::Vector2d::Zero(), y, kFoldSamples)) {
    *x_out = y;
    return UndoStatus::kConverged;
  }
  *x_out = converged ? x : y;
  return converged || t >= 1.0 ? UndoStatus::kFolded : UndoStatus::kNoConvergence;
}

}  // namespace

Eigen::Vector2d DistortNormalized(const std::vector<double>& distortion, const Eigen::Vector2d& x,
                                  Eigen::Matrix2d* jacobian) {
  double c[14] = {0};
  for (size_t i = 0; i < std::min<size_t>(14, distortion.size()); ++i) c[i] = distortion[i];
  const double k1 = c[0], k2 = c[1], p1 = c[2], p2 = c[3], k3 = c[4], k4 = c[5], k5 = c[6],
               k6 = c[7], s1 = c[8], s2 = c[9], s3 = c[10], s4 = c[11];
  const double u = x.x(), v = x.y();
  const double r2 = u * u + v * v, r4 = r2 * r2, r6 = r4 * r2;
  // Radial factor a / b and its derivative with respect to r².
  const double a = 1.0 + k1 * r2 + k2 * r4 + k3 * r6;
  const double b = 1.0 + k4 * r2 + k5 * r4 + k6 * r6;
  const double radial = a / b;
  const double d_radial =
      ((k1 + 2.0 * k2 * r2 + 3.0 * k3 * r4) * b - a * (k4 + 2.0 * k5 * r2 + 3.0 * k6 * r4)) /
      (b * b);
  const Eigen::Vector2d xd(
      u * radial + 2.0 * p1 * u * v + p2 * (r2 + 2.0 * u * u) + s1 * r2 + s2 * r4,
      v * radial + p1 * (r2 + 2.0 * v * v) + 2.0 * p2 * u * v + s3 * r2 + s4 * r4);
  const double prism_x = s1 + 2.0 * s2 * r2, prism_y = s3 + 2.0 * s4 * r2;  // d/d(r²)
  Eigen::Matrix2d J;
  J(0, 0) = radial + 2.0 * u * u * d_radial + 2.0 * p1 * v + 6.0 * p2 * u + 2.0 * u * prism_x;
  J(0, 1) = 2.0 * u * v * d_radial + 2.0 * p1 * u + 2.0 * p2 * v + 2.0 * v * prism_x;
  J(1, 0) = 2.0 * u * v * d_radial + 2.0 * p1 * u + 2.0 * p2 * v + 2.0 * u * prism_y;
  J(1, 1) = radial + 2.0 * v * v * d_radial + 6.0 * p1 * v + 2.0 * p2 * u + 2.0 * v * prism_y;
  Eigen::Vector2d out = xd;
  if (c[12] != 0.0 || c[13] != 0.0) {
    // Tilted sensor: a projective map of the distorted coordinates, chained into J.
    const Eigen::Matrix3d T = TiltProjection(c[12], c[13]);
    const Eigen::Vector3d h = T * xd.homogeneous();
    out = h.head<2>() / h.z();
    const Eigen::Matrix2d dT =
        (T.topLeftCorner<2, 2>() * h.z() - h.head<2>() * T.block<1, 2>(2, 0)) / (h.z() * h.z());
    J = dT * J;
  }
  if (jacobian) *jacobian = J;
  return out;
}

Eigen::Vector2d Lens::Distort(const Eigen::Vector2d& ideal_px) const {
  return PixelFromNormalised(
      camera_matrix, DistortNormalized(distortion, NormalisedFromPixel(camera_matrix, ideal_px)));
}

std::optional<Eigen::Vector2d> Lens::Undistort(const Eigen::Vector2d& px) const {
  Eigen::Vector2d x;
  if (UndoLens(distortion, NormalisedFromPixel(camera_matrix, px), &x) != UndoStatus::kConverged)
    return std::nullopt;
  return PixelFromNormalised(camera_matrix, x);
}

std::string LensProblemOverImage(const Lens& lens, int width, int height) {
  const int n = kLensGridCells;
  const std::string photo =
      " of a " + std::to_string(width) + "x" + std::to_string(height) + " px photo";
  std::vector<cv::Point2d> px;
  std::vector<Eigen::Vector2d> normalized;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const Eigen::Vector2d p(-0.5 + width * static_cast<double>(i) / n,
                              -0.5 + height * static_cast<double>(j) / n);
      // Undone as Rig::PlaneFromImage does it.
      Eigen::Vector2d x;
      switch (UndoLens(lens.distortion, NormalisedFromPixel(lens.camera_matrix, p), &x)) {
        case UndoStatus::kConverged:
          break;
        case UndoStatus::kNoConvergence:
          return "it cannot be undone at " + Px(p.x(), p.y()) + photo +
                 " (no undistorted point is put there: Newton's method does not converge)";
        case UndoStatus::kFolded:
          return "it folds the photo over near " + Px(p.x(), p.y()) + photo;
      }
      // Invertible but absurd (k1 = 1e6 squeezes the photo into a few pixels round the axis):
      // no lens magnifies or shrinks its image locally by more than kLensMaxScale.
      Eigen::Matrix2d J;
      DistortNormalized(lens.distortion, x, &J);
      const double scale = std::sqrt(J.determinant());
      if (!(scale <= kLensMaxScale && scale >= 1.0 / kLensMaxScale)) {
        std::ostringstream m;
        m << "it scales the photo by " << std::setprecision(3) << scale << " near "
          << Px(p.x(), p.y()) << photo << " (a lens stays within " << 1.0 / kLensMaxScale << " to "
          << kLensMaxScale << ")";
        return m.str();
      }
      px.emplace_back(p.x(), p.y());
      normalized.push_back(x);
    }
  }
  // Distorted back by OpenCV's own forward model (without the skew, added after): the model
  // undone is the one OpenCV calibrated.
  std::vector<cv::Point2d> back;
  try {
    Eigen::Matrix3d K0 = lens.camera_matrix;
    K0(0, 1) = 0.0;
    cv::Mat K, D(lens.distortion, true);
    cv::eigen2cv(K0, K);
    std::vector<cv::Point3d> rays;
    for (const auto& q : normalized) rays.emplace_back(q.x(), q.y(), 1.0);
    cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, back);
    const double skew = lens.camera_matrix(0, 1) / lens.camera_matrix(1, 1);
    for (auto& q : back) q.x += skew * (q.y - lens.camera_matrix(1, 2));
  } catch (const cv::Exception& e) {
    return "OpenCV cannot apply it (" + e.err + ")";
  }
  size_t worst = 0;
  double miss = 0.0;
  for (size_t k = 0; k < px.size(); ++k) {
    const double d = std::hypot(back[k].x - px[k].x, back[k].y - px[k].y);
    if (!(d <= miss)) {  // NaN counts as the worst
      worst = k;
      miss = std::isnan(d) ? std::numeric_limits<double>::infinity() : d;
      if (std::isinf(miss)) break;
    }
  }
  if (!(miss <= kLensRoundTripPx)) {
    std::ostringstream m;
    m << "it cannot be undone at " << Px(px[worst].x, px[worst].y) << photo
      << " (undistorted and distorted back, it comes out at "
      << (std::isinf(miss) ? std::string("infinity") : Px(back[worst].x, back[worst].y)) << ")";
    return m.str();
  }
  // The undistorted grid must keep its order: a model that folds the photo over maps two
  // places to one.
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const Eigen::Vector2d& q = normalized[j * (n + 1) + i];
      const bool right = i < n && !(normalized[j * (n + 1) + i + 1].x() > q.x());
      const bool down = j < n && !(normalized[(j + 1) * (n + 1) + i].y() > q.y());
      if (right || down) {
        return "it folds the photo over near " + Px(px[j * (n + 1) + i].x, px[j * (n + 1) + i].y) +
               photo;
      }
    }
  }
  return "";
}

Rig Rig::FromScale(double mm_per_px, const std::string& source) {
  if (!std::isfinite(mm_per_px) || mm_per_px <= 0.0) {
    throw InputError(source + ": the scale must be a number > 0 (mm per pixel)");
  }
  if (mm_per_px < kMinMmPerPx || mm_per_px > kMaxMmPerPx) {
    std::ostringstream s;
    s << source << ": " << mm_per_px << " mm/px is implausible (" << kMinMmPerPx << " .. "
      << kMaxMmPerPx << ")";
    throw InputError(s.str());
  }
  Rig rig;
  rig.plane_from_image = Eigen::Vector3d(mm_per_px, mm_per_px, 1.0).asDiagonal();
  rig.plain_scale = true;
  rig.source = source;
  return rig;
}

Eigen::Vector2d Rig::PlaneFromImage(const Eigen::Vector2d& px) const {
  Eigen::Vector2d p = px;
  if (lens) {
    const std::optional<Eigen::Vector2d> ideal = lens->Undistort(px);
    if (!ideal) return Eigen::Vector2d::Constant(std::nan(""));
    p = *ideal;
  }
  const Eigen::Vector3d h = plane_from_image * p.homogeneous();
  if (!(std::abs(h.z()) > 1e-12)) return Eigen::Vector2d::Constant(std::nan(""));
  return h.hnormalized();
}

double Rig::MmPerPxAt(const Eigen::Vector2d& px) const {
  // Central differences over ±1 px: exact for a homography to ~1e-6 relative at any sane scale.
  const Eigen::Vector2d dx =
      PlaneFromImage(px + Eigen::Vector2d(1, 0)) - PlaneFromImage(px - Eigen::Vector2d(1, 0));
  const Eigen::Vector2d dy =
      PlaneFromImage(px + Eigen::Vector2d(0, 1)) - PlaneFromImage(px - Eigen::Vector2d(0, 1));
  return std::sqrt(std::abs(dx.x() * dy.y() - dx.y() * dy.x())) / 2.0;
}

void Rig::CheckForImage(int width, int height, const std::string& photo) const {
  if (image_size && (image_size->x() != width || image_size->y() != height)) {
    throw InputError(source + ": calibrated for " + std::to_string(image_size->x()) + "x" +
                     std::to_string(image_size->y()) + " px images, but " + photo + " is " +
                     std::to_string(width) + "x" + std::to_string(height));
  }
  // The third homogeneous coordinate must keep one sign over the whole photo, else part of it
  // maps beyond the horizon.
  double lo = 1e300, hi = -1e300;
  for (const double x : {-0.5, width - 0.5}) {
    for (const double y : {-0.5, height - 0.5}) {
      const double w = plane_from_image.row(2).dot(Eigen::Vector3d(x, y, 1.0));
      lo = std::min(lo, w);
      hi = std::max(hi, w);
    }
  }
  if (!(lo * hi > 0.0)) {
    throw InputError(source + ": the homography maps part of " + photo +
                     " beyond the horizon (is it plane_from_image, px -> mm?)");
  }
  if (lens) {
    const std::string why = LensProblemOverImage(*lens, width, height);
    if (!why.empty()) {
      throw InputError(source + ": distortion: lens model not undone over " + photo + ": " + why +
                       " (not one to one there: an implausible model)");
    }
  }
  const double s = MmPerPxAt({width / 2.0, height / 2.0});
  if (!std::isfinite(s) || s < kMinMmPerPx || s > kMaxMmPerPx) {
    std::ostringstream m;
    m << source << ": the homography gives an implausible scale of " << s
      << " mm/px at the centre of " << photo << " (is it plane_from_image, px -> mm?)";
    throw InputError(m.str());
  }
}

Rig ParseRigJson(const std::string& text, const std::string& source) {
  const json j = ParseJsonText(text, source);
  const JsonFields f(source);
  f.RequireObject(j);
  const json& type = f.Require(j, "type");
  if (!type.is_string()) f.Must("type", "be \"scale\" or \"homography\"", type);
  Rig rig;
  if (type == "scale") {
    const json& v = f.Require(j, "mm_per_px");
    const double s = f.Number(v, "mm_per_px");
    if (s <= 0.0) f.Must("mm_per_px", "be > 0", v);
    rig = Rig::FromScale(s, source + ": mm_per_px");
  } else if (type == "homography") {
    rig.plane_from_image = Matrix3(f, j, "plane_from_image");
    const double det = rig.plane_from_image.determinant();
    const double size = rig.plane_from_image.cwiseAbs().maxCoeff();
    if (!(std::abs(det) > 1e-12 * size * size * size)) {
      f.Fail("plane_from_image", "is singular (determinant " + std::to_string(det) + ")");
    }
  } else {
    f.Unknown("type", "type", type.get<std::string>(), "\"scale\" or \"homography\"");
  }
  rig.source = source;
  if (j.contains("image_size")) {
    const auto v = f.Numbers(j["image_size"], "image_size");
    if (v.size() != 2) f.Must("image_size", "be [width, height] in pixels", j["image_size"]);
    for (const double x : v) {
      if (x < 1 || x > kMaxSidePx || x != std::floor(x)) {
        f.Must("image_size", "be two whole numbers of pixels in 1 .. 100000", j["image_size"]);
      }
    }
    rig.image_size = Eigen::Vector2i(static_cast<int>(v[0]), static_cast<int>(v[1]));
  }
  const bool has_k = j.contains("camera_matrix"), has_d = j.contains("distortion");
  if (has_k != has_d) {
    f.Fail(has_k ? "distortion" : "camera_matrix", "missing (a lens model needs both)");
  }
  if (has_k) {
    Lens lens;
    lens.camera_matrix = Matrix3(f, j, "camera_matrix");
    const Eigen::Matrix3d& K = lens.camera_matrix;
    if (!(K(0, 0) > 0 && K(1, 1) > 0) || K(1, 0) != 0 || K(2, 0) != 0 || K(2, 1) != 0 ||
        K(2, 2) != 1) {
      f.Must("camera_matrix", "be [[fx, s, cx], [0, fy, cy], [0, 0, 1]] with fx, fy > 0",
             j["camera_matrix"]);
    }
    lens.distortion = f.Numbers(j["distortion"], "distortion");
    const size_t n = lens.distortion.size();
    if (n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
      f.Must("distortion", "have 4, 5, 8, 12 or 14 coefficients (OpenCV's model)", j["distortion"]);
    }
    if (rig.plain_scale) f.Fail("distortion", "a plain scale rig has no lens model");
    if (rig.image_size) {
      const std::string why = LensProblemOverImage(lens, rig.image_size->x(), rig.image_size->y());
      if (!why.empty())
        f.Fail("distortion", "lens model not undone over the image: " + why +
                                 " (not one to one there: an implausible model)");
    }
    rig.lens = lens;
  }
  if (j.contains("reprojection_error_px")) {
    const json& v = j["reprojection_error_px"];
    const double e = f.Number(v, "reprojection_error_px");
    if (e < 0) f.Must("reprojection_error_px", "be >= 0", v);
    rig.reprojection_error_px = e;
  }
  return rig;
}

Rig ReadRigJson(const std::string& path) {
  std::stringstream buffer(ReadInputFile(path, "rig file", 16u << 20));  // kilobytes in use
  if (buffer.str().find_first_not_of(" \t\r\n") == std::string::npos) {
    throw InputError(path + ": empty rig file");
  }
  return ParseRigJson(buffer.str(), path);
}

std::string RigToJson(const Rig& rig) {
  json j;
  if (rig.plain_scale) {
    j["type"] = "scale";
    j["mm_per_px"] = rig.plane_from_image(0, 0);
  } else {
    j["type"] = "homography";
    j["plane_from_image"] = Matrix3ToJson(rig.plane_from_image);
  }
  if (rig.image_size) j["image_size"] = {rig.image_size->x(), rig.image_size->y()};
  if (rig.lens) {
    j["camera_matrix"] = Matrix3ToJson(rig.lens->camera_matrix);
    j["distortion"] = rig.lens->distortion;
  }
  if (rig.reprojection_error_px >= 0) j["reprojection_error_px"] = rig.reprojection_error_px;
  return j.dump(2) + "\n";
}

}  // namespace textile
