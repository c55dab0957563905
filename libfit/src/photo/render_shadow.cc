#include "textile/photo/render_shadow.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "textile/photo/image_codecs.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"

namespace textile {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegree = kPi / 180.0;
// The lens map is solved exactly (Lens::Undistort) on a grid this many pixels apart and
// interpolated between: its curvature over 8 px is far below the 0.01 px the edges need.
constexpr int kLensGridPx = 8;
// The shadow must stay this far inside the photo [px] (the blur and a margin to measure in).
constexpr double kFitMarginPx = 8.0;

bool Fail(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}

bool InRange(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

// The camera: K, and the paper's homography into its ideal (undistorted) pixels.
struct Camera {
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d image_from_plane = Eigen::Matrix3d::Identity();  // ideal px ~ H (mm, 1)
  std::optional<Lens> lens;
};

// A pinhole `distance` from the aim point, leaning tilt_deg off vertical towards
// tilt_azimuth_deg, looking at the aim point; image x along the paper's x for no roll, image y
// down (the paper's -y): a view from above, not mirrored.
Camera MakeCamera(const RenderShadowOptions& o) {
  const double d = o.distance * 1000.0;  // [mm]
  const double t = o.tilt_deg * kDegree, a = o.tilt_azimuth_deg * kDegree;
  const Eigen::Vector3d aim(o.aim_mm.x(), o.aim_mm.y(), 0.0);
  const Eigen::Vector3d centre =
      aim + d * Eigen::Vector3d(std::sin(t) * std::cos(a), std::sin(t) * std::sin(a), std::cos(t));
  const Eigen::Vector3d forward = (aim - centre).normalized();
  Eigen::Vector3d right =
      Eigen::Vector3d::UnitX() - forward.dot(Eigen::Vector3d::UnitX()) * forward;
  right.normalize();
  Eigen::Vector3d down = forward.cross(right);
  const double r = o.roll_deg * kDegree;
  const Eigen::Vector3d x_c = std::cos(r) * right + std::sin(r) * down;
  const Eigen::Vector3d y_c = -std::sin(r) * right + std::cos(r) * down;
  Eigen::Matrix3d R;
  R.row(0) = x_c.transpose();
  R.row(1) = y_c.transpose();
  R.row(2) = forward.transpose();
  const Eigen::Vector3d tr = -R * centre;
  Camera cam;
  const double f = d / o.mm_per_px;
  cam.K << f, 0, (o.width_px - 1) / 2.0, 0, f, (o.height_px - 1) / 2.0, 0, 0, 1;
  Eigen::Matrix3d Rt;
  Rt.col(0) = R.col(0);
  Rt.col(1) = R.col(1);
  Rt.col(2) = tr;
  cam.image_from_plane = cam.K * Rt;
  cam.image_from_plane /= cam.image_from_plane(2, 2);
  if (o.k1 != 0.0) cam.lens = Lens{cam.K, {o.k1, 0.0, 0.0, 0.0, 0.0}};
  return cam;
}

Eigen::Vector2d PhotoPxOf(const Camera& cam, const Eigen::Vector2d& mm) {
  const Eigen::Vector2d ideal = (cam.image_from_plane * mm.homogeneous()).hnormalized();
  return cam.lens ? cam.lens->Distort(ideal) : ideal;
}

// Ideal pixel of every photo pixel: the identity without a lens, else Lens::Undistort on a
// kLensGridPx grid, interpolated bilinearly (CV_32FC2, width × height).
cv::Mat IdealPixels(const Camera& cam, int width, int height) {
  cv::Mat ideal(height, width, CV_32FC2);
  if (!cam.lens) {
    for (int v = 0; v < height; ++v)
      for (int u = 0; u < width; ++u) ideal.at<cv::Vec2f>(v, u) = cv::Vec2f(u, v);
    return ideal;
  }
  const int gw = width / kLensGridPx + 2, gh = height / kLensGridPx + 2;
  cv::Mat grid(gh, gw, CV_64FC2);
  for (int j = 0; j < gh; ++j)
    for (int i = 0; i < gw; ++i) {
      const Eigen::Vector2d p(i * kLensGridPx, j * kLensGridPx);
      const std::optional<Eigen::Vector2d> q = cam.lens->Undistort(p);
      if (!q) throw InputError("render-shadow: k1: the lens model cannot be undone over the photo");
      grid.at<cv::Vec2d>(j, i) = cv::Vec2d(q->x(), q->y());
    }
  for (int v = 0; v < height; ++v) {
    const int j = v / kLensGridPx;
    const double fy = (v - j * kLensGridPx) / static_cast<double>(kLensGridPx);
    for (int u = 0; u < width; ++u) {
      const int i = u / kLensGridPx;
      const double fx = (u - i * kLensGridPx) / static_cast<double>(kLensGridPx);
      const cv::Vec2d a = grid.at<cv::Vec2d>(j, i) * (1 - fx) + grid.at<cv::Vec2d>(j, i + 1) * fx;
      const cv::Vec2d b =
          grid.at<cv::Vec2d>(j + 1, i) * (1 - fx) + grid.at<cv::Vec2d>(j + 1, i + 1) * fx;
      const cv::Vec2d p = a * (1 - fy) + b * fy;
      ideal.at<cv::Vec2f>(v, u) = cv::Vec2f(static_cast<float>(p[0]), static_cast<float>(p[1]));
    }
  }
  return ideal;
}

// The fraction of each pixel for which `inside(mm)` holds (CV_32F): one sample at the pixel's
// centre, then supersample² samples where a neighbour's centre disagrees (the edges only).
template <typename Inside>
cv::Mat Coverage(const Camera& cam, const cv::Mat& ideal, int supersample, Inside inside) {
  const Eigen::Matrix3d plane_from_image = cam.image_from_plane.inverse();
  auto at = [&](double x, double y) {
    const Eigen::Vector3d h = plane_from_image * Eigen::Vector3d(x, y, 1.0);
    return inside(h.x() / h.z(), h.y() / h.z());
  };
  cv::Mat centre(ideal.rows, ideal.cols, CV_8U);
  cv::parallel_for_(cv::Range(0, ideal.rows), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v)
      for (int u = 0; u < ideal.cols; ++u) {
        const cv::Vec2f& p = ideal.at<cv::Vec2f>(v, u);
        centre.at<uchar>(v, u) = at(p[0], p[1]) ? 1 : 0;
      }
  });
  cv::Mat cover;
  centre.convertTo(cover, CV_32F);
  const int n = supersample;
  if (n == 1) return cover;
  const float weight = 1.0f / static_cast<float>(n * n);
  cv::parallel_for_(cv::Range(0, ideal.rows), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v)
      for (int u = 0; u < ideal.cols; ++u) {
        const uchar c = centre.at<uchar>(v, u);
        bool edge = false;
        for (int dv = -1; dv <= 1 && !edge; ++dv)
          for (int du = -1; du <= 1 && !edge; ++du) {
            const int vv = std::clamp(v + dv, 0, ideal.rows - 1);
            const int uu = std::clamp(u + du, 0, ideal.cols - 1);
            edge = centre.at<uchar>(vv, uu) != c;
          }
        if (!edge) continue;
        const cv::Vec2f p = ideal.at<cv::Vec2f>(v, u);
        float sum = 0.0f;
        for (int sy = 0; sy < n; ++sy)
          for (int sx = 0; sx < n; ++sx)
            if (at(p[0] + (sx + 0.5) / n - 0.5, p[1] + (sy + 0.5) / n - 0.5)) sum += weight;
        cover.at<float>(v, u) = sum;
      }
  });
  return cover;
}

// The light falling on the paper: a linear gradient across the photo and vignetting (CV_32F,
// 1 at its brightest).
cv::Mat Light(const RenderShadowOptions& o) {
  cv::Mat light(o.height_px, o.width_px, CV_32F);
  const double ga = o.gradient_azimuth_deg * kDegree;
  const double cx = (o.width_px - 1) / 2.0, cy = (o.height_px - 1) / 2.0;
  const double half_extent =
      0.5 * (std::abs(std::cos(ga)) * o.width_px + std::abs(std::sin(ga)) * o.height_px);
  const double corner2 = cx * cx + cy * cy;
  for (int v = 0; v < o.height_px; ++v)
    for (int u = 0; u < o.width_px; ++u) {
      const double along = ((u - cx) * std::cos(ga) + (v - cy) * std::sin(ga)) / half_extent;
      const double g = 1.0 - o.gradient * 0.5 * (1.0 + along);  // 1 .. 1 - gradient
      const double r2 = ((u - cx) * (u - cx) + (v - cy) * (v - cy)) / corner2;
      light.at<float>(v, u) = static_cast<float>(g * (1.0 - o.vignetting * r2));
    }
  return light;
}

// The woven texture and stains of the specimen's top at a paper point [mm]: a relative
// modulation of σ about `texture`.
struct Texture {
  double phase[6];
  double Value(double x, double y, double amount) const {
    const double weave =
        std::sin(2 * kPi * x / 1.6 + phase[0]) * std::sin(2 * kPi * y / 1.6 + phase[1]);
    const double stain =
        std::cos(2 * kPi * x / 43.0 + phase[2]) * std::cos(2 * kPi * y / 37.0 + phase[3]) +
        0.5 * std::sin(2 * kPi * (x + y) / 71.0 + phase[4]);
    return amount * (1.2 * weave + 0.6 * stain);
  }
};

// From levels in [0, 1] to grey levels: blur, noise (σ at mid grey, growing with the level's
// square root as shot noise does) and quantisation; deterministic per seed.
cv::Mat Expose(cv::Mat level, const RenderShadowOptions& o, std::uint64_t seed) {
  level *= 255.0;
  if (o.blur_px > 0.0) cv::GaussianBlur(level, level, cv::Size(0, 0), o.blur_px);
  if (o.noise > 0.0) {
    cv::Mat n(level.size(), CV_32F);
    cv::RNG rng(seed);
    rng.fill(n, cv::RNG::NORMAL, 0.0, 1.0);
    cv::Mat scale;
    cv::sqrt(cv::max(level, 1.0f) / 128.0f, scale);
    level += n.mul(scale) * o.noise;
  }
  cv::Mat out;
  level.convertTo(out, CV_8U);  // rounds and saturates
  return out;
}

// The mesh's projection at the render's raster, as a lookup in paper mm.
struct Projection {
  DrapeShadow shadow;
  bool Inside(double x_mm, double y_mm) const {
    const int i = static_cast<int>(std::lround((x_mm * 1e-3 - shadow.origin_x) / shadow.cell));
    const int j = static_cast<int>(std::lround((y_mm * 1e-3 - shadow.origin_y) / shadow.cell));
    if (i < 0 || j < 0 || i >= shadow.width || j >= shadow.height) return false;
    return shadow.mask[static_cast<size_t>(j) * shadow.width + i] != 0;
  }
};

double BoardSquareMm(const RenderShadowOptions& o) {
  if (o.board_square_mm > 0.0) return o.board_square_mm;
  const double w = o.width_px * o.mm_per_px, h = o.height_px * o.mm_per_px;
  return std::floor(0.6 * std::min(w / (o.board_cols + 1), h / (o.board_rows + 1)));
}

// The chessboard on the paper about the aim point, with one white square's margin.
cv::Mat RenderBoard(const RenderShadowOptions& o, const Camera& cam, const cv::Mat& ideal,
                    const cv::Mat& light) {
  const double sq = BoardSquareMm(o);
  const double x0 = o.aim_mm.x() - (o.board_cols - 1) * sq / 2.0;
  const double y0 = o.aim_mm.y() + (o.board_rows - 1) * sq / 2.0;
  const cv::Mat card = Coverage(cam, ideal, o.supersample, [&](double x, double y) {
    const double bx = (x - x0) / sq, by = (y0 - y) / sq;
    return bx >= -2 && bx < o.board_cols + 1 && by >= -2 && by < o.board_rows + 1;
  });
  const cv::Mat black = Coverage(cam, ideal, o.supersample, [&](double x, double y) {
    const double bx = (x - x0) / sq, by = (y0 - y) / sq;
    if (bx < -1 || bx >= o.board_cols || by < -1 || by >= o.board_rows) return false;
    return ((static_cast<int>(std::floor(bx)) + static_cast<int>(std::floor(by))) & 1) != 0;
  });
  cv::Mat level = o.paper + (0.92 - o.paper) * card - 0.86 * black;  // card 0.92, squares 0.06
  level = level.mul(light);
  return Expose(level, o, o.seed + 1000003u);
}

std::string Describe(const RenderShadowOptions& o) {
  std::ostringstream s;
  s << ToString(o.style) << " " << o.width_px << "x" << o.height_px << " "
    << NumberText(o.mm_per_px, 4) << " mm/px tilt " << NumberText(o.tilt_deg, 3) << "° k1 "
    << NumberText(o.k1, 3) << " gradient " << NumberText(o.gradient, 3) << " vignetting "
    << NumberText(o.vignetting, 3) << " blur " << NumberText(o.blur_px, 3) << " px noise "
    << NumberText(o.noise, 3) << " jpeg " << o.jpeg_quality << " seed " << o.seed;
  return s.str();
}

}  // namespace

ShadowStyle ParseShadowStyle(const std::string& text, const std::string& flag) {
  if (text == "shadow") return ShadowStyle::kShadow;
  if (text == "top") return ShadowStyle::kTop;
  throw InputError(flag + ": unknown style \"" + text + "\" (expected shadow or top)");
}

std::string ToString(ShadowStyle style) { return style == ShadowStyle::kTop ? "top" : "shadow"; }

bool RenderShadowOptions::Check(std::string* why) const {
  if (width_px < 64 || height_px < 64 || width_px > 12000 || height_px > 12000)
    return Fail(why, "size: each side must lie in 64..12000 px");
  if (!InRange(mm_per_px, 0.005, 10.0)) return Fail(why, "mm_per_px: must lie in 0.005..10");
  if (!InRange(distance, 0.1, 100.0)) return Fail(why, "distance: must lie in 0.1..100 m");
  if (!InRange(tilt_deg, 0.0, 20.0)) return Fail(why, "tilt_deg: must lie in 0..20");
  if (!std::isfinite(tilt_azimuth_deg) || !std::isfinite(roll_deg) || !aim_mm.allFinite() ||
      !std::isfinite(gradient_azimuth_deg))
    return Fail(why, "angles and the aim point must be finite");
  if (!InRange(k1, -0.3, 0.3)) return Fail(why, "k1: must lie in -0.3..0.3");
  for (const double level : {paper, shadow_level, specimen_reflectance})
    if (!InRange(level, 0.0, 1.0))
      return Fail(why, "levels: paper, shadow and specimen lie in 0..1");
  if (!InRange(texture, 0.0, 0.3)) return Fail(why, "texture: must lie in 0..0.3");
  if (!InRange(gradient, 0.0, 0.8)) return Fail(why, "gradient: must lie in 0..0.8");
  if (!InRange(vignetting, 0.0, 0.6)) return Fail(why, "vignetting: must lie in 0..0.6");
  if (!InRange(blur_px, 0.0, 20.0)) return Fail(why, "blur_px: must lie in 0..20");
  if (!InRange(noise, 0.0, 50.0)) return Fail(why, "noise: must lie in 0..50 grey levels");
  if (jpeg_quality < 0 || jpeg_quality > 100) return Fail(why, "jpeg: quality must lie in 0..100");
  if (supersample < 1 || supersample > 6) return Fail(why, "supersample: must lie in 1..6");
  if (!InRange(raster_cell, 1e-5, 0.005)) return Fail(why, "raster_cell: must lie in 0.01..5 mm");
  if (board_cols < 3 || board_rows < 3 || board_cols > 40 || board_rows > 40 ||
      board_cols == board_rows)
    return Fail(why, "board: needs 3..40 inner corners a side, different counts");
  if (!InRange(board_square_mm, 0.0, 500.0))
    return Fail(why, "board_square_mm: must lie in 0..500");
  if (BoardSquareMm(*this) / mm_per_px < 10.0)
    return Fail(why, "board: its squares would span fewer than 10 px");
  return measure.Check(why);
}

RenderedShadow RenderShadowPhoto(const Vertices& x, const Triangles& triangles,
                                 const RenderShadowOptions& o) {
  if (std::string why; !o.Check(&why)) throw InputError("render-shadow: " + why);
  RenderedShadow r;
  r.description = Describe(o);
  // The truth: the drapemeter's measurement of the mesh itself.
  r.truth = MeasureDrapeShadow(
      MeasureShadow(x, triangles, o.measure.raster_cell, o.measure.outline_bins, 0.0), o.measure,
      "render-shadow truth");
  r.truth.input_kind = "mesh";
  r.truth.centre_from = "origin";

  const Camera cam = MakeCamera(o);
  r.image_from_plane = cam.image_from_plane;
  r.rig.plane_from_image = cam.image_from_plane.inverse();
  r.rig.plane_from_image /= r.rig.plane_from_image(2, 2);
  r.rig.lens = cam.lens;
  r.rig.image_size = Eigen::Vector2i(o.width_px, o.height_px);
  r.rig.source = "render-shadow";
  r.centre_px = PhotoPxOf(cam, Eigen::Vector2d::Zero());
  r.centre_mm_per_px = r.rig.MmPerPxAt(r.centre_px);

  // The shadow must fit: its outline (and the support's disk) inside the photo.
  for (int b = 0; b < r.truth.shadow.angles.size(); ++b) {
    const double t = r.truth.shadow.angles(b), rad = r.truth.shadow.radii(b) * 1e3;
    const Eigen::Vector2d p = PhotoPxOf(cam, Eigen::Vector2d(rad * std::cos(t), rad * std::sin(t)));
    if (!(p.x() >= kFitMarginPx && p.y() >= kFitMarginPx &&
          p.x() <= o.width_px - 1 - kFitMarginPx && p.y() <= o.height_px - 1 - kFitMarginPx))
      throw ComputeError("render-shadow: the shadow does not fit in the photo (at " +
                         NumberText(t / kDegree, 4) +
                         "°): use a larger --size or --mm-per-px, or less tilt");
  }

  Projection projection{
      MeasureShadow(x, triangles, o.raster_cell, o.measure.outline_bins, o.measure.support_radius)};
  const cv::Mat ideal = IdealPixels(cam, o.width_px, o.height_px);
  const cv::Mat light = Light(o);
  const cv::Mat cover = Coverage(cam, ideal, o.supersample, [&projection](double xm, double ym) {
    return projection.Inside(xm, ym);
  });
  cv::Mat level(o.height_px, o.width_px, CV_32F);
  if (o.style == ShadowStyle::kShadow) {
    level = o.paper + (o.shadow_level - o.paper) * cover;
  } else {
    cv::RNG rng(o.seed);
    Texture tex;
    for (double& p : tex.phase) p = rng.uniform(0.0, 2 * kPi);
    const Eigen::Matrix3d plane_from_image = cam.image_from_plane.inverse();
    for (int v = 0; v < o.height_px; ++v)
      for (int u = 0; u < o.width_px; ++u) {
        const float c = cover.at<float>(v, u);
        double specimen = o.specimen_reflectance;
        if (c > 0.0f && o.texture > 0.0) {
          const cv::Vec2f& p = ideal.at<cv::Vec2f>(v, u);
          const Eigen::Vector2d mm =
              (plane_from_image * Eigen::Vector3d(p[0], p[1], 1.0)).hnormalized();
          specimen *= 1.0 + tex.Value(mm.x(), mm.y(), o.texture);
        }
        level.at<float>(v, u) = static_cast<float>(o.paper * (1.0 - c) + specimen * c);
      }
  }
  r.photo = Expose(level.mul(light), o, o.seed);
  if (o.jpeg_quality > 0) {
    image_codecs::Encode(".jpg", r.photo, &r.encoded, {cv::IMWRITE_JPEG_QUALITY, o.jpeg_quality});
    r.photo = image_codecs::Decode(cv::Mat(r.encoded), cv::IMREAD_GRAYSCALE);
  }
  if (o.render_board) r.board = RenderBoard(o, cam, ideal, light);
  r.board_cols = o.board_cols;
  r.board_rows = o.board_rows;
  r.board_square_mm = BoardSquareMm(o);
  return r;
}

std::string RenderedShadowTruthJson(const RenderedShadow& r, const RenderShadowOptions& o) {
  nlohmann::json j;
  j["format"] = "textile-rendered-shadow";
  j["description"] = r.description;
  j["drape_coefficient"] = r.truth.drape_coefficient;
  j["nodes"] = r.truth.nodes.angles.size();
  nlohmann::json nodes = nlohmann::json::array();
  for (size_t k = 0; k < r.truth.nodes.angles.size(); ++k)
    nodes.push_back({{"angle_deg", r.truth.nodes.angles[k] / kDegree},
                     {"radius_mm", r.truth.nodes.radii[k] * 1e3}});
  j["node_list"] = nodes;
  j["mean_radius_mm"] = r.truth.mean_radius * 1e3;
  j["centre_px"] = {r.centre_px.x(), r.centre_px.y()};
  j["mm_per_px_at_centre"] = r.centre_mm_per_px;
  j["style"] = ToString(o.style);
  j["tilt_deg"] = o.tilt_deg;
  j["k1"] = o.k1;
  j["specimen_radius_mm"] = o.measure.specimen_radius * 1e3;
  j["support_radius_mm"] = o.measure.support_radius * 1e3;
  j["rig"] = nlohmann::json::parse(RigToJson(r.rig));
  j["board"] = {{"cols", r.board_cols}, {"rows", r.board_rows}, {"square_mm", r.board_square_mm}};
  return j.dump(2) + "\n";
}

RenderedShadow RenderShadowPhoto(const TriangleMesh& draped, double metres_per_unit,
                                 const RenderShadowOptions& o, const std::string& source) {
  DrapeMeshOptions frame_options;
  frame_options.measure = o.measure;
  frame_options.metres_per_unit = metres_per_unit;
  if (std::string why; !frame_options.Check(&why)) throw InputError(source + ": " + why);
  const Vertices x = MeshInMeasureFrame(draped, frame_options, source);
  CheckMeshScale(x, frame_options, source);
  try {
    return RenderShadowPhoto(x, draped.triangles, o);
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  } catch (const ComputeError& e) {
    throw ComputeError(source + ": " + e.what());
  }
}

}  // namespace textile
