#include "textile/fit/rig.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <sstream>

#include "textile/sim/error.h"
#include "textile/sim/json_text.h"

namespace textile {
namespace {

using nlohmann::json;

// Plausible pixel scales: a microscope at 1 µm/px to a wide shot at 1 m/px.
constexpr double kMinMmPerPx = 1e-3;
constexpr double kMaxMmPerPx = 1e3;
// Largest image side a rig may describe [px].
constexpr int kMaxSidePx = 100000;

class Fields {
 public:
  Fields(const json& j, std::string source) : j_(j), source_(std::move(source)) {}
  [[noreturn]] void Fail(const std::string& field, const std::string& problem) const {
    throw InputError(source_ + ": " + field + ": " + problem);
  }
  const json& Get(const std::string& field) const {
    if (!j_.contains(field)) Fail(field, "missing");
    return j_.at(field);
  }
  double Number(const json& v, const std::string& field) const {
    if (!v.is_number()) Fail(field, "expected a number, got " + std::string(v.type_name()));
    const double x = v.get<double>();
    if (!std::isfinite(x)) Fail(field, "is NaN or infinite");
    return x;
  }
  std::vector<double> Numbers(const json& v, const std::string& field) const {
    if (!v.is_array()) Fail(field, "expected an array of numbers");
    std::vector<double> out;
    for (size_t i = 0; i < v.size(); ++i) {
      out.push_back(Number(v[i], field + "[" + std::to_string(i) + "]"));
    }
    return out;
  }
  Eigen::Matrix3d Matrix3(const std::string& field) const {
    const json& v = Get(field);
    if (!v.is_array() || v.size() != 3) Fail(field, "expected 3 rows of 3 numbers");
    Eigen::Matrix3d m;
    for (int r = 0; r < 3; ++r) {
      const auto row = Numbers(v[r], field + "[" + std::to_string(r) + "]");
      if (row.size() != 3) Fail(field, "expected 3 rows of 3 numbers");
      for (int c = 0; c < 3; ++c) m(r, c) = row[c];
    }
    return m;
  }

 private:
  const json& j_;
  std::string source_;
};

// A lens model must be undone exactly where photos are measured: undistorting a point and
// distorting it back must return it within this distance [px] (a tenth of the extraction's
// sub-pixel scatter). Real lenses meet it by orders of magnitude.
constexpr double kLensRoundTripPx = 0.05;
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

}  // namespace

std::string LensProblemOverImage(const Lens& lens, int width, int height) {
  cv::Mat K, D(lens.distortion, true);
  cv::eigen2cv(lens.camera_matrix, K);
  const int n = kLensGridCells;
  std::vector<cv::Point2d> px, normalized, back;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      px.emplace_back(-0.5 + width * static_cast<double>(i) / n,
                      -0.5 + height * static_cast<double>(j) / n);
    }
  }
  // Undistorted as Rig::PlaneFromImage does it, then distorted back by the forward model.
  try {
    cv::undistortPoints(
        px, normalized, K, D, cv::noArray(), cv::noArray(),
        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-9));
    std::vector<cv::Point3d> rays;
    for (const auto& q : normalized) rays.emplace_back(q.x, q.y, 1.0);
    cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, back);
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
    m << "it cannot be undone at " << Px(px[worst].x, px[worst].y) << " of a " << width << "x"
      << height << " px photo (undistorted and distorted back, it comes out at "
      << (std::isinf(miss) ? std::string("infinity") : Px(back[worst].x, back[worst].y)) << ")";
    return m.str();
  }
  // The undistorted grid must keep its order: a model that folds the photo over maps two
  // places to one.
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const cv::Point2d& q = normalized[j * (n + 1) + i];
      const bool right = i < n && !(normalized[j * (n + 1) + i + 1].x > q.x);
      const bool down = j < n && !(normalized[(j + 1) * (n + 1) + i].y > q.y);
      if (right || down) {
        return "it folds the photo over near " + Px(px[j * (n + 1) + i].x, px[j * (n + 1) + i].y) +
               " of a " + std::to_string(width) + "x" + std::to_string(height) + " px photo";
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
    cv::Mat K, D(lens->distortion, true);
    cv::eigen2cv(lens->camera_matrix, K);
    std::vector<cv::Point2d> in{{px.x(), px.y()}}, out;
    cv::undistortPoints(
        in, out, K, D, cv::noArray(), K,
        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-9));
    p = {out[0].x, out[0].y};
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
                       " (an implausible model, or a wide angle that OpenCV's iterative "
                       "undistortion cannot invert there)");
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
  if (!j.is_object()) throw InputError(source + ": expected a JSON object (a rig file)");
  const Fields f(j, source);
  const json& type = f.Get("type");
  if (!type.is_string()) f.Fail("type", "expected \"scale\" or \"homography\"");
  Rig rig;
  if (type == "scale") {
    const double s = f.Number(f.Get("mm_per_px"), "mm_per_px");
    if (s <= 0.0) f.Fail("mm_per_px", "must be > 0");
    rig = Rig::FromScale(s, source + ": mm_per_px");
  } else if (type == "homography") {
    rig.plane_from_image = f.Matrix3("plane_from_image");
    const double det = rig.plane_from_image.determinant();
    const double size = rig.plane_from_image.cwiseAbs().maxCoeff();
    if (!(std::abs(det) > 1e-12 * size * size * size)) {
      f.Fail("plane_from_image", "is singular (determinant " + std::to_string(det) + ")");
    }
  } else {
    f.Fail("type", "expected \"scale\" or \"homography\", got " + type.dump());
  }
  rig.source = source;
  if (j.contains("image_size")) {
    const auto v = f.Numbers(j["image_size"], "image_size");
    if (v.size() != 2) f.Fail("image_size", "expected [width, height] in pixels");
    for (const double x : v) {
      if (x < 1 || x > kMaxSidePx || x != std::floor(x)) {
        f.Fail("image_size", "expected two whole numbers of pixels in 1 .. 100000");
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
    lens.camera_matrix = f.Matrix3("camera_matrix");
    const Eigen::Matrix3d& K = lens.camera_matrix;
    if (!(K(0, 0) > 0 && K(1, 1) > 0) || K(1, 0) != 0 || K(2, 0) != 0 || K(2, 1) != 0 ||
        K(2, 2) != 1) {
      f.Fail("camera_matrix", "expected [[fx, s, cx], [0, fy, cy], [0, 0, 1]] with fx, fy > 0");
    }
    lens.distortion = f.Numbers(j["distortion"], "distortion");
    const size_t n = lens.distortion.size();
    if (n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
      f.Fail("distortion",
             "expected 4, 5, 8, 12 or 14 coefficients (OpenCV's model), got " + std::to_string(n));
    }
    if (rig.plain_scale) f.Fail("distortion", "a plain scale rig has no lens model");
    if (rig.image_size) {
      const std::string why = LensProblemOverImage(lens, rig.image_size->x(), rig.image_size->y());
      if (!why.empty())
        f.Fail("distortion", "lens model not undone over the image: " + why +
                                 " (an implausible model, or a wide angle that OpenCV's iterative "
                                 "undistortion cannot invert there)");
    }
    rig.lens = lens;
  }
  if (j.contains("reprojection_error_px")) {
    const double e = f.Number(j["reprojection_error_px"], "reprojection_error_px");
    if (e < 0) f.Fail("reprojection_error_px", "must be >= 0");
    rig.reprojection_error_px = e;
  }
  return rig;
}

Rig ReadRigJson(const std::string& path) {
  std::ifstream in = OpenInputFile(path, "rig file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw InputError(path + ": cannot read rig file");
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
