// Synthetic cantilever photos (render_photo.h). The scene is a set of layers in the bending
// plane (background, platform, the strip's faces, the strip with its fibres), each a list of
// polygons projected into the photo by the camera's homography. Coverage is computed by
// supersampling, band by band of rows (memory stays bounded at 50 MP), composited with the light,
// blurred, made noisy and quantised; a JPEG round trip comes last.

#include "textile/photo/render_photo.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>

#include "textile/photo/image_codecs.h"
#include "textile/sim/elastica/elastica.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/polyline.h"
#include "render_photo_stages.h"

namespace textile {
namespace {

constexpr double kPi = 3.14159265358979323846;
double Deg(double d) { return d * kPi / 180.0; }

// A polygon in full-resolution photo pixels with its bounding box.
struct Polygon {
  std::vector<Eigen::Vector2d> pts;
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool convex = false;
  void Bound() {
    x0 = y0 = 1e300;
    x1 = y1 = -1e300;
    for (const auto& p : pts) {
      x0 = std::min(x0, p.x());
      x1 = std::max(x1, p.x());
      y0 = std::min(y0, p.y());
      y1 = std::max(y1, p.y());
    }
  }
};

// Coverage [0, 1] of the union of `polys` over the rows [row0, row1) of a `width` px wide photo,
// by ss × ss samples per pixel at the sub-pixel centres. CV_32F, (row1 - row0) × width.
cv::Mat Coverage(const std::vector<Polygon>& polys, int width, int row0, int row1, int ss) {
  const int rows = row1 - row0;
  cv::Mat out = cv::Mat::zeros(rows, width, CV_32F);
  double bx0 = 1e300, bx1 = -1e300;
  std::vector<const Polygon*> hit;
  for (const auto& p : polys) {
    if (p.y1 < row0 - 1 || p.y0 > row1 || p.x1 < -1 || p.x0 > width) continue;
    hit.push_back(&p);
    bx0 = std::min(bx0, p.x0);
    bx1 = std::max(bx1, p.x1);
  }
  if (hit.empty()) return out;
  const int c0 = std::clamp(static_cast<int>(std::floor(bx0)) - 1, 0, width);
  const int c1 = std::clamp(static_cast<int>(std::ceil(bx1)) + 2, 0, width);
  if (c1 <= c0) return out;
  cv::Mat mask = cv::Mat::zeros(rows * ss, (c1 - c0) * ss, CV_8U);
  constexpr int kShift = 8;
  const double unit = 1 << kShift;
  std::vector<cv::Point> pts;
  for (const Polygon* p : hit) {
    pts.clear();
    for (const auto& q : p->pts) {
      // Sub-sample (i, j) has its centre at pixel coordinate c0 - 0.5 + (i + 0.5) / ss.
      const double sx = ((q.x() - c0 + 0.5) * ss - 0.5) * unit;
      const double sy = ((q.y() - row0 + 0.5) * ss - 0.5) * unit;
      pts.emplace_back(static_cast<int>(std::lround(sx)), static_cast<int>(std::lround(sy)));
    }
    if (p->convex) {
      cv::fillConvexPoly(mask, pts, cv::Scalar(255), cv::LINE_8, kShift);
    } else {
      const cv::Point* data = pts.data();
      const int n = static_cast<int>(pts.size());
      cv::fillPoly(mask, &data, &n, 1, cv::Scalar(255), cv::LINE_8, kShift);
    }
  }
  cv::Mat small;
  cv::resize(mask, small, cv::Size(c1 - c0, rows), 0, 0, cv::INTER_AREA);
  small.convertTo(out.colRange(c0, c1), CV_32F, 1.0 / 255.0);
  return out;
}

// Bilinear lookup in a small CV_32F grid whose cell is `cell` px of the photo.
float Lookup(const cv::Mat& grid, double cell, double x, double y) {
  const double gx = std::clamp(x / cell, 0.0, grid.cols - 1.001);
  const double gy = std::clamp(y / cell, 0.0, grid.rows - 1.001);
  const int i = static_cast<int>(gx), j = static_cast<int>(gy);
  const double fx = gx - i, fy = gy - j;
  const float* r0 = grid.ptr<float>(j);
  const float* r1 = grid.ptr<float>(j + 1);
  return static_cast<float>((r0[i] * (1 - fx) + r0[i + 1] * fx) * (1 - fy) +
                            (r1[i] * (1 - fx) + r1[i + 1] * fx) * fy);
}

struct Camera {
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // world -> camera
  Eigen::Vector3d C = Eigen::Vector3d::Zero();      // centre [mm]
  int width = 0;
  bool mirror = false;

  // Photo pixel of a world point [mm]; z_cam > 0 assumed (checked by the caller via Depth).
  Eigen::Vector2d Project(const Eigen::Vector3d& X) const {
    const Eigen::Vector3d c = K * (R * (X - C));
    Eigen::Vector2d p(c.x() / c.z(), c.y() / c.z());
    if (mirror) p.x() = width - 1 - p.x();
    return p;
  }
  Eigen::Vector2d Project(const Eigen::Vector2d& X) const { return Project(Eigen::Vector3d(X.x(), X.y(), 0.0)); }
  double Depth(const Eigen::Vector3d& X) const { return (R * (X - C)).z(); }
  // Photo pixels <- plane (z = 0) [mm], mirror included.
  Eigen::Matrix3d ImageFromPlane() const {
    Eigen::Matrix3d M;
    M.col(0) = R.col(0);
    M.col(1) = R.col(1);
    M.col(2) = -R * C;
    Eigen::Matrix3d H = K * M;
    if (mirror) {
      Eigen::Matrix3d F;
      F << -1, 0, width - 1, 0, 1, 0, 0, 0, 1;
      H = F * H;
    }
    return H / H(2, 2);
  }
};

Camera MakeCamera(const RenderPhotoOptions& o, const Eigen::Vector2d& aim_mm) {
  Camera cam;
  const double d = o.distance * 1e3;  // [mm]
  const double f = d / o.mm_per_px;
  cam.K << f, 0, (o.width_px - 1) / 2.0, 0, f, (o.height_px - 1) / 2.0, 0, 0, 1;
  const double yaw = Deg(o.yaw_deg), pitch = Deg(o.pitch_deg), roll = Deg(o.roll_deg);
  const Eigen::Vector3d fwd(std::sin(yaw) * std::cos(pitch), -std::sin(pitch),
                            -std::cos(yaw) * std::cos(pitch));
  const Eigen::Vector3d up(0, 1, 0);
  const Eigen::Vector3d x0 = fwd.cross(up).normalized();
  const Eigen::Vector3d y0 = fwd.cross(x0);
  // Roll turns the camera about its axis: a world horizontal then appears turned
  // counter-clockwise by roll in the photo.
  const Eigen::Vector3d xc = std::cos(roll) * x0 + std::sin(roll) * y0;
  const Eigen::Vector3d yc = -std::sin(roll) * x0 + std::cos(roll) * y0;
  cam.R.row(0) = xc.transpose();
  cam.R.row(1) = yc.transpose();
  cam.R.row(2) = fwd.transpose();
  cam.C = Eigen::Vector3d(aim_mm.x(), aim_mm.y(), 0.0) - d * fwd;
  cam.width = o.width_px;
  cam.mirror = o.overhang_left;
  return cam;
}

Polygon Project(const Camera& cam, const std::vector<Eigen::Vector3d>& world, bool convex) {
  Polygon p;
  p.pts.reserve(world.size());
  for (const auto& X : world) p.pts.push_back(cam.Project(X));
  p.convex = convex;
  p.Bound();
  return p;
}

// A thin straight fibre from a to b [mm, plane] of width w [mm], as a quad.
std::vector<Eigen::Vector3d> FibreQuad(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                       double w) {
  const Eigen::Vector2d t = (b - a).normalized();
  const Eigen::Vector2d n(-t.y(), t.x());
  const Eigen::Vector2d h = 0.5 * w * n;
  return {{a.x() + h.x(), a.y() + h.y(), 0},
          {b.x() + h.x(), b.y() + h.y(), 0},
          {b.x() - h.x(), b.y() - h.y(), 0},
          {a.x() - h.x(), a.y() - h.y(), 0}};
}

Profile ToProfile(const std::vector<double>& s, const std::vector<Eigen::Vector2d>& pts_mm,
                  const std::string& source) {
  Profile p;
  p.source = source;
  p.s.resize(s.size());
  p.x.resize(s.size());
  p.y.resize(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    p.s[i] = s[i];
    p.x[i] = pts_mm[i].x() * 1e-3;
    p.y[i] = pts_mm[i].y() * 1e-3;
  }
  return p;
}

// The layers of a photo and how to light them.
struct Scene {
  std::vector<Polygon> platform, faces, strip, platform_top;
  double bg = 0.78, plat = 0.45, plat_top = 0.6, face = 0.3, strip_refl = 0.16;
  double gradient = 0.0;
  Eigen::Vector2d gradient_dir{1, 0};  // across the photo, unit
  double shadow = 0.0;
  cv::Mat shadow_map;  // CV_32F, cell shadow_cell px
  double shadow_cell = 8;
  double texture = 0.0;
  cv::Mat texture_map;  // CV_32F, zero-mean unit σ, cell texture_cell px
  double texture_cell = 4;
};

// Renders a scene into an 8-bit photo, band by band.
cv::Mat RenderScene(const Scene& sc, const RenderPhotoOptions& o, std::uint64_t noise_seed) {
  const int w = o.width_px, h = o.height_px;
  cv::Mat photo(h, w, CV_8U);
  const int halo = o.blur_px > 0 ? static_cast<int>(std::ceil(4.0 * o.blur_px)) + 1 : 0;
  const int band = 256;
  const double diag = std::hypot(w, h);
  for (int y0 = 0, tile = 0; y0 < h; y0 += band, ++tile) {
    const int y1 = std::min(h, y0 + band);
    const int r0 = std::max(0, y0 - halo), r1 = std::min(h, y1 + halo);
    const int ss = o.supersample;
    const cv::Mat c_plat = Coverage(sc.platform, w, r0, r1, ss);
    const cv::Mat c_top = Coverage(sc.platform_top, w, r0, r1, ss);
    const cv::Mat c_face = Coverage(sc.faces, w, r0, r1, ss);
    const cv::Mat c_strip = Coverage(sc.strip, w, r0, r1, ss);
    cv::Mat v(r1 - r0, w, CV_32F);
    for (int r = r0; r < r1; ++r) {
      float* out = v.ptr<float>(r - r0);
      const float* cp = c_plat.ptr<float>(r - r0);
      const float* ct = c_top.ptr<float>(r - r0);
      const float* cf = c_face.ptr<float>(r - r0);
      const float* cs = c_strip.ptr<float>(r - r0);
      for (int x = 0; x < w; ++x) {
        // Light falls off along gradient_dir, from 1 + g/2 to 1 - g/2 across the photo.
        const double u = ((x - w / 2.0) * sc.gradient_dir.x() + (r - h / 2.0) * sc.gradient_dir.y()) / diag;
        const double light = 1.0 - sc.gradient * u * 1.4;
        double bg = sc.bg;
        if (sc.shadow > 0) bg *= 1.0 - sc.shadow * Lookup(sc.shadow_map, sc.shadow_cell, x, r);
        double val = bg;
        if (cp[x] > 0) val += cp[x] * (sc.plat - val);
        if (ct[x] > 0) val += ct[x] * (sc.plat_top - val);
        if (cf[x] > 0) val += cf[x] * (sc.face - val);
        if (cs[x] > 0) {
          double s = sc.strip_refl;
          if (sc.texture > 0) s *= 1.0 + sc.texture * Lookup(sc.texture_map, sc.texture_cell, x, r);
          val += cs[x] * (s - val);
        }
        out[x] = static_cast<float>(255.0 * val * light);
      }
    }
    if (o.blur_px > 0) cv::GaussianBlur(v, v, cv::Size(0, 0), o.blur_px, o.blur_px, cv::BORDER_REFLECT);
    cv::Mat keep = v.rowRange(y0 - r0, y1 - r0);
    if (o.noise > 0) {
      // Gaussian read noise plus shot noise: σ grows as the square root of the signal.
      cv::Mat n(keep.size(), CV_32F);
      cv::RNG rng(noise_seed * 7919u + static_cast<std::uint64_t>(tile) + 1u);
      rng.fill(n, cv::RNG::NORMAL, 0.0, 1.0);
      cv::Mat sigma;
      cv::max(keep, 8.0, sigma);
      cv::sqrt(sigma * (1.0 / 128.0), sigma);
      keep = keep + n.mul(sigma) * o.noise;
    }
    keep.convertTo(photo.rowRange(y0, y1), CV_8U);
  }
  return photo;
}

// The board's square [mm]: as given, or about 60 % of the photo's short way across the card
// (the inner corners plus a square and a half of margin each side), whole or half millimetres.
double BoardSquareMm(const RenderPhotoOptions& o) {
  if (o.board_square_mm > 0) return o.board_square_mm;
  const double W = o.width_px * o.mm_per_px, H = o.height_px * o.mm_per_px;
  const double sq = 0.6 * std::min(W / (o.board_cols + 3), H / (o.board_rows + 3));
  return std::max(0.5, std::round(sq * 2.0) / 2.0);
}

// Fewest pixels a board square may span for `calibrate` to find its corners: rendered 9x6
// boards with 10 px squares were found on every level (the auto size cannot go lower without
// shrinking the photo below what holds a strip).
constexpr double kMinBoardSquarePx = 10.0;

}  // namespace

PhotoDifficulty ParsePhotoDifficulty(const std::string& text, const std::string& flag) {
  if (text == "easy") return PhotoDifficulty::kEasy;
  if (text == "medium") return PhotoDifficulty::kMedium;
  if (text == "hard") return PhotoDifficulty::kHard;
  throw InputError(flag + ": expected easy, medium or hard, got '" + text + "'");
}

std::string ToString(PhotoDifficulty d) {
  switch (d) {
    case PhotoDifficulty::kEasy: return "easy";
    case PhotoDifficulty::kMedium: return "medium";
    case PhotoDifficulty::kHard: return "hard";
  }
  return "?";
}

RenderPhotoOptions RenderPhotoOptions::ForDifficulty(PhotoDifficulty difficulty,
                                                     std::uint64_t seed) {
  RenderPhotoOptions o;
  o.seed = seed;
  std::mt19937_64 rng(seed * 2654435761u + 17u);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const auto polarity_and_direction = [&] {
    o.light_strip = u01(rng) < 0.5;
    o.overhang_left = u01(rng) < 0.5;
  };
  switch (difficulty) {
    case PhotoDifficulty::kEasy:
      o.blur_px = 0.8;
      o.noise = 1.5;
      o.distance = 2.0;
      polarity_and_direction();
      break;
    case PhotoDifficulty::kMedium:
      polarity_and_direction();
      o.distance = 0.8;
      o.yaw_deg = 4.0 * u(rng);
      o.pitch_deg = 4.0 * u(rng);
      o.roll_deg = 1.5 * u(rng);
      o.aim_dx = 0.05 * u(rng);
      o.aim_dy = 0.05 * u(rng);
      o.gradient = 0.25 + 0.1 * u(rng);
      o.shadow = 0.25 + 0.1 * u(rng);
      o.texture = 0.06;
      o.tip_fibres = 8;
      o.edge_fibres = 40;
      o.blur_px = 1.2;
      o.noise = 3.0;
      o.jpeg_quality = 92;
      o.strip_reflectance = 0.16 + 0.04 * u(rng);
      o.background_reflectance = 0.72 + 0.06 * u(rng);
      break;
    case PhotoDifficulty::kHard:
      polarity_and_direction();
      o.distance = 0.5;
      o.yaw_deg = 8.0 * u(rng);
      o.pitch_deg = 6.0 * u(rng);
      o.roll_deg = 3.0 * u(rng);
      o.aim_dx = 0.08 * u(rng);
      o.aim_dy = 0.08 * u(rng);
      o.gradient = 0.45 + 0.1 * u(rng);
      o.shadow = 0.45 + 0.1 * u(rng);
      o.texture = 0.12;
      o.tip_fibres = 60;
      o.edge_fibres = 150;
      o.blur_px = 2.0;
      o.noise = 6.0;
      o.jpeg_quality = 75;
      o.strip_width = 0.02;
      o.strip_reflectance = 0.22 + 0.04 * u(rng);
      o.background_reflectance = 0.6 + 0.05 * u(rng);
      break;
  }
  if (o.light_strip) {
    // Swap the roles: a light strip in front of a dark backdrop.
    const double s = o.strip_reflectance, b = o.background_reflectance;
    o.strip_reflectance = std::min(0.95, 1.05 - s);
    o.background_reflectance = std::max(0.05, 1.0 - b);
    o.face_reflectance = 0.6;
    o.platform_reflectance = 0.45;
  }
  return o;
}

bool RenderPhotoOptions::Check(std::string* why) const {
  std::ostringstream p;
  const auto finite_in = [](double v, double lo, double hi) {
    return std::isfinite(v) && v >= lo && v <= hi;
  };
  if (!finite_in(overhang, 1e-3, 2.0)) {
    p << "overhang must lie in [1, 2000] mm";
  } else if (!finite_in(thickness, 1e-5, kMaxRenderThickness)) {
    p << "thickness must lie in [0.01, " << kMaxRenderThickness * 1e3
      << "] mm (thicker strips rise too far above the platform for extract)";
  } else if (!finite_in(strip_width, 0.0, 0.5)) {
    p << "strip_width must lie in [0, 500] mm";
  } else if (width_px < 64 || height_px < 64 || width_px > 12000 || height_px > 12000 ||
             double(width_px) * height_px > 64e6) {
    p << "photo size must be 64..12000 px a side and at most 64 MP";
  } else if (!finite_in(mm_per_px, 1e-3, 10.0)) {
    p << "mm_per_px must lie in [0.001, 10]";
  } else if (!finite_in(distance, 0.05, 100.0)) {
    p << "distance must lie in [0.05, 100] m";
  } else if (!finite_in(std::abs(yaw_deg), 0, 30) || !finite_in(std::abs(pitch_deg), 0, 30) ||
             !finite_in(std::abs(roll_deg), 0, 30)) {
    p << "yaw, pitch and roll must lie within ±30°";
  } else if (!finite_in(std::abs(aim_dx), 0, 0.5) || !finite_in(std::abs(aim_dy), 0, 0.5)) {
    p << "aim offsets must lie within ±0.5";
  } else if (!finite_in(strip_reflectance, 0, 1) || !finite_in(background_reflectance, 0, 1) ||
             !finite_in(platform_reflectance, 0, 1) || !finite_in(face_reflectance, 0, 1)) {
    p << "reflectances must lie in [0, 1]";
  } else if (!finite_in(gradient, 0, 0.9) || !finite_in(shadow, 0, 0.9) ||
             !finite_in(texture, 0, 0.5)) {
    p << "gradient and shadow must lie in [0, 0.9], texture in [0, 0.5]";
  } else if (tip_fibres < 0 || edge_fibres < 0 || tip_fibres > 10000 || edge_fibres > 10000) {
    p << "fibre counts must lie in [0, 10000]";
  } else if (!finite_in(blur_px, 0, 20) || !finite_in(noise, 0, 100)) {
    p << "blur_px must lie in [0, 20] and noise in [0, 100]";
  } else if (jpeg_quality < 0 || jpeg_quality > 100) {
    p << "jpeg_quality must lie in [0, 100]";
  } else if (supersample < 1 || supersample > 8) {
    p << "supersample must lie in [1, 8]";
  } else if (board_cols < 3 || board_rows < 3 || board_cols > 40 || board_rows > 40 ||
             board_cols == board_rows) {
    p << "board needs 3..40 inner corners a side, different counts (its orientation)";
  } else if (aim_mm && !(std::isfinite(aim_mm->x()) && std::isfinite(aim_mm->y()))) {
    p << "aim_mm must be finite";
  } else if (!finite_in(board_square_mm, 0, 500)) {
    p << "board_square_mm must lie in [0, 500]";
  } else if (const double sq = BoardSquareMm(*this);
             sq / mm_per_px < kMinBoardSquarePx ||
             (board_cols + 1) * sq > 0.9 * width_px * mm_per_px ||
             (board_rows + 1) * sq > 0.9 * height_px * mm_per_px) {
    // A board that cannot be calibrated from is no use: its squares too small to be found, or
    // the board larger than the photo.
    p << "board " << board_cols << "x" << board_rows << " with " << sq << " mm squares ("
      << sq / mm_per_px << " px) does not fit a " << width_px << "x" << height_px
      << " px photo with squares of at least " << kMinBoardSquarePx
      << " px (fewer corners or a larger photo)";
  }
  if (why) *why = p.str();
  return p.str().empty();
}

double DistanceToProfile(const Profile& truth, double x, double y) {
  return DistanceToPolyline(truth.x, truth.y, x, y);
}

namespace {

// The strip's mid-line and faces in the bending plane [mm], resting on the platform.
struct StripShape {
  ElasticaProfile e;
  int n = 0;                                        // samples
  std::vector<Eigen::Vector2d> mid, upper, lower;   // #n points [mm]
  std::vector<Eigen::Vector2d> normal;              // #n unit normals, upwards at the edge
};

// What the stages of RenderPhoto share: the strip, the camera and the scene being built, and
// the one random stream (its draws keep their order: fibres, then the light).
struct PhotoBuild {
  explicit PhotoBuild(const RenderPhotoOptions& o) : o(o), rng(o.seed) {}
  const RenderPhotoOptions& o;
  double t_mm = 0.0;  // thickness [mm]
  StripShape shape;
  Eigen::Vector2d aim = Eigen::Vector2d::Zero();  // the point the camera looks at [mm]
  Camera cam;
  double far = 0.0;  // beyond the photo on every side [mm]
  std::vector<Eigen::Vector3d> band;  // the strip's outline, platform part included [mm]
  Scene sc;
  std::mt19937_64 rng;
  std::uniform_real_distribution<double> u01{0.0, 1.0};
  std::normal_distribution<double> gauss{0.0, 1.0};
};

// The strip's mid-line, sampled about every quarter pixel of arc, and its two faces.
StripShape SolveStripShape(const BendingLaw& law, double areal_density,
                           const RenderPhotoOptions& o) {
  const double t_mm = o.thickness * 1e3;
  ElasticaOptions eo;
  eo.num_samples = std::clamp(static_cast<int>(o.overhang * 1e3 / o.mm_per_px * 4.0), 201, 60001);
  eo.rel_tol = 1e-9;
  StripShape shape;
  shape.e = SolveHeavyElastica(law, areal_density, o.overhang, eo);
  const ElasticaProfile& e = shape.e;
  if (!e.converged) throw ComputeError("render-photo: elastica failed: " + e.message);
  const int n = shape.n = static_cast<int>(e.s.size());
  shape.mid.resize(n);
  shape.upper.resize(n);
  shape.lower.resize(n);
  shape.normal.resize(n);
  for (int i = 0; i < n; ++i) {
    // Resting on the platform, the mid-line starts at (0, t/2) (docs/spec/cantilever.md).
    shape.mid[i] = Eigen::Vector2d(e.x[i], e.y[i]) * 1e3 + Eigen::Vector2d(0, t_mm / 2);
    shape.normal[i] = Eigen::Vector2d(std::sin(e.theta[i]), std::cos(e.theta[i]));
    shape.upper[i] = shape.mid[i] + 0.5 * t_mm * shape.normal[i];
    shape.lower[i] = shape.mid[i] - 0.5 * t_mm * shape.normal[i];
  }
  return shape;
}

// The strip's reach [mm]: its furthest x and lowest y over both faces.
void StripExtent(const StripShape& shape, double* xmax, double* ymin) {
  *xmax = 0;
  *ymin = 0;
  for (int i = 0; i < shape.n; ++i) {
    *xmax = std::max(*xmax, shape.upper[i].x());
    *xmax = std::max(*xmax, shape.lower[i].x());
    *ymin = std::min(*ymin, shape.lower[i].y());
    *ymin = std::min(*ymin, shape.upper[i].y());
  }
}

}  // namespace

namespace fit_internal {

Eigen::Vector2d FrameAim(const RenderPhotoOptions& o, double xmax, double ymin) {
  const double t_mm = o.thickness * 1e3;
  const double W = o.width_px * o.mm_per_px, H = o.height_px * o.mm_per_px;
  const double margin = 0.08 * std::min(W, H);
  // The platform takes a sixth to a quarter of the width, the strip the rest.
  const double plat = std::clamp(W - xmax - 2 * margin, W / 6.0, W / 4.0);
  // Background above the platform: most of the spare height (the extractor models the
  // background from it), at least 6 % of the height.
  const double spare = H - (t_mm - ymin);
  const double top_margin = std::clamp(0.6 * spare, 0.06 * H, 0.3 * H);
  if (o.aim_mm) return *o.aim_mm;
  return Eigen::Vector2d(-plat + W / 2.0 + o.aim_dx * W,
                         t_mm + top_margin - H / 2.0 - o.aim_dy * H);
}

}  // namespace fit_internal

namespace {

// The platform and the strip: on the platform out of view to the left, over the edge, down to
// its tip; the shades of the layers.
void AddPlatformAndStrip(PhotoBuild& b) {
  const RenderPhotoOptions& o = b.o;
  Scene& sc = b.sc;
  sc.bg = o.background_reflectance;
  sc.plat = o.platform_reflectance;
  sc.plat_top = 0.5 * (o.platform_reflectance + (o.light_strip ? 0.3 : 0.9));
  sc.face = o.face_reflectance;
  sc.strip_refl = o.strip_reflectance;
  const double far = b.far;
  sc.platform.push_back(
      Project(b.cam, {{-far, 0, 0}, {0, 0, 0}, {0, -far, 0}, {-far, -far, 0}}, true));
  const int n = b.shape.n;
  b.band.push_back({-far, b.t_mm, 0});
  for (int i = 0; i < n; ++i) b.band.push_back({b.shape.upper[i].x(), b.shape.upper[i].y(), 0});
  for (int i = n - 1; i >= 0; --i)
    b.band.push_back({b.shape.lower[i].x(), b.shape.lower[i].y(), 0});
  b.band.push_back({-far, 0, 0});
  sc.strip.push_back(Project(b.cam, b.band, false));
}

// Oblique view: the top or bottom face behind the side face, whichever faces the camera, and
// the platform's top face on which the strip lies.
void AddObliqueFaces(PhotoBuild& b) {
  if (!(b.o.strip_width > 0)) return;
  const double depth = b.o.strip_width * 1e3, far = b.far, t_mm = b.t_mm;
  const Camera& cam = b.cam;
  const Eigen::Vector2d cam_xy = cam.C.head<2>();
  for (int i = 0; i + 1 < b.shape.n; ++i) {
    for (int side : {+1, -1}) {
      const auto& f = side > 0 ? b.shape.upper : b.shape.lower;
      const Eigen::Vector2d nrm = side * b.shape.normal[i];
      if (nrm.dot(cam_xy - f[i]) <= 0) continue;
      b.sc.faces.push_back(Project(cam,
                                   {{f[i].x(), f[i].y(), 0},
                                    {f[i + 1].x(), f[i + 1].y(), 0},
                                    {f[i + 1].x(), f[i + 1].y(), -depth},
                                    {f[i].x(), f[i].y(), -depth}},
                                   true));
    }
  }
  if (cam.C.y() > t_mm) {
    b.sc.faces.push_back(Project(
        cam, {{-far, t_mm, 0}, {0, t_mm, 0}, {0, t_mm, -depth}, {-far, t_mm, -depth}}, true));
  }
  if (cam.C.y() > 0) {
    const double pdepth = depth + 30.0;
    b.sc.platform_top.push_back(
        Project(cam, {{-far, 0, 0}, {0, 0, 0}, {0, 0, -pdepth}, {-far, 0, -pdepth}}, true));
  }
}

// Frayed tip and hairy edges: thin fibres of the strip's shade.
void AddFibres(PhotoBuild& b) {
  const StripShape& sh = b.shape;
  const int n = sh.n;
  const double t_mm = b.t_mm;
  const Eigen::Vector2d tip = sh.mid[n - 1];
  const Eigen::Vector2d tip_t(std::cos(sh.e.theta[n - 1]), -std::sin(sh.e.theta[n - 1]));
  for (int k = 0; k < b.o.tip_fibres; ++k) {
    const Eigen::Vector2d start =
        tip + (b.u01(b.rng) - 0.5) * t_mm * sh.normal[n - 1] - 0.2 * b.u01(b.rng) * tip_t;
    const double ang = Deg(45.0) * b.gauss(b.rng);
    const Eigen::Vector2d dir = std::cos(ang) * tip_t + std::sin(ang) * sh.normal[n - 1];
    const double len = 0.3 + 2.2 * b.u01(b.rng);
    b.sc.strip.push_back(
        Project(b.cam, FibreQuad(start, start + len * dir, 0.01 + 0.02 * b.u01(b.rng)), true));
  }
  for (int k = 0; k < b.o.edge_fibres; ++k) {
    const int i = std::clamp(static_cast<int>(n * (0.05 + 0.93 * b.u01(b.rng))), 0, n - 2);
    const double side = b.u01(b.rng) < 0.5 ? 1.0 : -1.0;
    const Eigen::Vector2d base = (side > 0 ? sh.upper[i] : sh.lower[i]) - side * 0.05 * sh.normal[i];
    const Eigen::Vector2d ti(std::cos(sh.e.theta[i]), -std::sin(sh.e.theta[i]));
    const double ang = Deg(50.0) * b.gauss(b.rng);
    const Eigen::Vector2d dir = std::cos(ang) * side * sh.normal[i] + std::sin(ang) * ti;
    const double len = 0.1 + 0.6 * b.u01(b.rng);
    b.sc.strip.push_back(
        Project(b.cam, FibreQuad(base, base + len * dir, 0.015 + 0.025 * b.u01(b.rng)), true));
  }
}

// Everything drawn must be in front of the camera, and the strip (beyond the edge) inside the
// photo with its tip clear of the border (ComputeError).
void CheckFraming(const PhotoBuild& b) {
  for (const auto& X : b.band) {
    if (b.cam.Depth(X) <= 1.0)
      throw ComputeError("render-photo: the scene passes behind the camera");
  }
  const int w = b.o.width_px, h = b.o.height_px;
  const Eigen::Vector2d tip = b.shape.mid[b.shape.n - 1];
  for (int i = 0; i < b.shape.n; ++i) {
    for (const auto* p : {&b.shape.upper[i], &b.shape.lower[i]}) {
      const Eigen::Vector2d q = b.cam.Project(*p);
      if (q.x() < 4 || q.y() < 4 || q.x() > w - 5 || q.y() > h - 5) {
        std::ostringstream m;
        m << "render-photo: the strip (L = " << b.o.overhang * 1e3 << " mm, tip at (" << tip.x()
          << ", " << tip.y() << ") mm) does not fit in a " << w << "x" << h << " photo at "
          << b.o.mm_per_px << " mm/px; use a larger photo or scale";
        throw ComputeError(m.str());
      }
    }
  }
}

// A soft shadow of the strip, down and away: its map over cells of sc.shadow_cell px.
void AddShadow(PhotoBuild& b) {
  const RenderPhotoOptions& o = b.o;
  Scene& sc = b.sc;
  const int w = o.width_px, h = o.height_px;
  sc.shadow = o.shadow;
  sc.shadow_cell = std::max(2.0, std::max(w, h) / 400.0);
  cv::Mat m = cv::Mat::zeros(static_cast<int>(h / sc.shadow_cell) + 2,
                             static_cast<int>(w / sc.shadow_cell) + 2, CV_32F);
  const Eigen::Vector2d shift(2.5 + 2.0 * b.u01(b.rng), -(3.0 + 3.0 * b.u01(b.rng)));  // [mm]
  std::vector<cv::Point> pts;
  for (const auto& X : b.band) {
    const Eigen::Vector2d q = b.cam.Project(Eigen::Vector2d(X.x() + shift.x(), X.y() + shift.y()));
    pts.emplace_back(static_cast<int>(std::lround(q.x() / sc.shadow_cell * 16)),
                     static_cast<int>(std::lround(q.y() / sc.shadow_cell * 16)));
  }
  const cv::Point* data = pts.data();
  const int np = static_cast<int>(pts.size());
  cv::Mat shadow_mask = cv::Mat::zeros(m.size(), CV_8U);
  cv::fillPoly(shadow_mask, &data, &np, 1, cv::Scalar(255), cv::LINE_8, 4);
  shadow_mask.convertTo(m, CV_32F, 1.0 / 255.0);
  // Broad and soft: a few mm of penumbra.
  const double sigma = std::max(1.0, 3.0 / o.mm_per_px / sc.shadow_cell);
  cv::GaussianBlur(m, m, cv::Size(0, 0), sigma);
  sc.shadow_map = m;
}

// Light: a gradient in a random direction, a shadow, and the weave's texture.
void AddLight(PhotoBuild& b) {
  const RenderPhotoOptions& o = b.o;
  Scene& sc = b.sc;
  std::uniform_real_distribution<double> ang(0.0, 2 * kPi);
  const double ga = ang(b.rng);
  sc.gradient = o.gradient;
  sc.gradient_dir = Eigen::Vector2d(std::cos(ga), std::sin(ga));
  if (o.shadow > 0) AddShadow(b);
  if (o.texture > 0) {
    sc.texture = o.texture;
    sc.texture_cell = std::max(1.5, 0.4 / o.mm_per_px);  // weave-sized blotches
    cv::Mat m(static_cast<int>(o.height_px / sc.texture_cell) + 2,
              static_cast<int>(o.width_px / sc.texture_cell) + 2, CV_32F);
    cv::RNG trng(o.seed * 31u + 5u);
    trng.fill(m, cv::RNG::NORMAL, 0.0, 1.0);
    sc.texture_map = m;
  }
}

// The chessboard in the bending plane, centred on the aim point, on a white card: its photo
// and its corners.
void RenderBoard(const PhotoBuild& b, RenderedPhoto* r) {
  const RenderPhotoOptions& o = b.o;
  const double sq = BoardSquareMm(o);
  Scene board;
  board.bg = o.light_strip ? 0.3 : o.background_reflectance;
  board.plat = 0.92;        // the card
  board.strip_refl = 0.06;  // the black squares
  board.gradient = o.gradient;
  board.gradient_dir = b.sc.gradient_dir;
  // Board frame: x along a row, y down the rows; corner (i, j) at (i sq, j sq).
  const Eigen::Vector2d b0 =
      b.aim - Eigen::Vector2d((o.board_cols - 1) * sq / 2.0, -(o.board_rows - 1) * sq / 2.0);
  const auto plane = [&](double bx, double by) {
    return Eigen::Vector3d(b0.x() + bx, b0.y() - by, 0.0);
  };
  const double m0 = -2.0 * sq, mx = (o.board_cols + 1) * sq, my = (o.board_rows + 1) * sq;
  board.platform.push_back(
      Project(b.cam, {plane(m0, m0), plane(mx, m0), plane(mx, my), plane(m0, my)}, true));
  for (int a = -1; a < o.board_cols; ++a) {
    for (int c = -1; c < o.board_rows; ++c) {
      if (((a + c) % 2 + 2) % 2 != 0) continue;
      const double x0 = a * sq, y0 = c * sq;
      board.strip.push_back(Project(
          b.cam, {plane(x0, y0), plane(x0 + sq, y0), plane(x0 + sq, y0 + sq), plane(x0, y0 + sq)},
          true));
    }
  }
  r->board = RenderScene(board, o, o.seed + 1000003u);
  r->board_cols = o.board_cols;
  r->board_rows = o.board_rows;
  r->board_square_mm = sq;
  for (int j = 0; j < o.board_rows; ++j) {
    for (int i = 0; i < o.board_cols; ++i) {
      r->board_corners_px.push_back(b.cam.Project(plane(i * sq, j * sq)));
      r->board_corners_mm.emplace_back(i * sq, j * sq);
    }
  }
}

// The truth: camera, rig, the strip's lines in the plane and in the photo.
void FillTruth(const PhotoBuild& b, RenderedPhoto* r) {
  const StripShape& sh = b.shape;
  r->image_from_plane = b.cam.ImageFromPlane();
  r->camera_matrix = b.cam.K;
  r->rig.plane_from_image = r->image_from_plane.inverse();
  r->rig.plane_from_image /= r->rig.plane_from_image(2, 2);
  r->rig.image_size = Eigen::Vector2i(b.o.width_px, b.o.height_px);
  r->rig.reprojection_error_px = 0.0;
  r->rig.source = "render-photo truth";
  r->truth = ToProfile(sh.e.s, sh.mid, "render-photo truth (mid-line)");
  r->truth_upper = ToProfile(sh.e.s, sh.upper, "render-photo truth (upper boundary)");
  r->truth_lower = ToProfile(sh.e.s, sh.lower, "render-photo truth (lower boundary)");
  r->truth_px.reserve(sh.n);
  for (int i = 0; i < sh.n; ++i) r->truth_px.push_back(b.cam.Project(sh.mid[i]));
  r->origin_px = b.cam.Project(Eigen::Vector2d(0, 0));
  r->tip_x_mm = sh.mid[sh.n - 1].x();
  r->tip_y_mm = sh.mid[sh.n - 1].y();
  r->aim_mm = b.aim;
}

// One line naming what the photo shows.
std::string DescribePhoto(const RenderPhotoOptions& o) {
  std::ostringstream d;
  d.precision(3);
  d << (o.light_strip ? "light" : "dark") << " strip, overhang "
    << (o.overhang_left ? "left" : "right") << ", yaw " << o.yaw_deg << "°, pitch "
    << o.pitch_deg << "°, roll " << o.roll_deg << "°, blur " << o.blur_px << " px, noise "
    << o.noise << ", jpeg " << o.jpeg_quality << ", fibres " << o.tip_fibres << "+"
    << o.edge_fibres << (o.strip_width > 0 ? ", oblique face" : "");
  return d.str();
}

}  // namespace

// Stages: the strip's shape, the framing and camera, the scene's layers (platform and strip,
// oblique faces, fibres), the framing check, the light; then the photo, the board and the truth.
RenderedPhoto RenderPhoto(const BendingLaw& law, double areal_density,
                          const RenderPhotoOptions& o) {
  if (std::string why; !o.Check(&why)) throw InputError("render-photo: " + why);
  PhotoBuild b(o);
  b.t_mm = o.thickness * 1e3;
  b.shape = SolveStripShape(law, areal_density, o);
  double xmax = 0.0, ymin = 0.0;
  StripExtent(b.shape, &xmax, &ymin);
  b.aim = fit_internal::FrameAim(o, xmax, ymin);
  b.cam = MakeCamera(o, b.aim);
  const double W = o.width_px * o.mm_per_px, H = o.height_px * o.mm_per_px;
  b.far = 1.5 * std::max(W, H) + std::abs(b.aim.x()) + std::abs(b.aim.y());
  AddPlatformAndStrip(b);
  AddObliqueFaces(b);
  AddFibres(b);
  CheckFraming(b);
  AddLight(b);

  RenderedPhoto r;
  r.photo = RenderScene(b.sc, o, o.seed);
  if (o.jpeg_quality > 0) {
    image_codecs::Encode(".jpg", r.photo, &r.encoded, {cv::IMWRITE_JPEG_QUALITY, o.jpeg_quality});
    r.photo = image_codecs::Decode(cv::Mat(r.encoded), cv::IMREAD_GRAYSCALE);
  }
  RenderBoard(b, &r);
  FillTruth(b, &r);
  r.description = DescribePhoto(o);
  return r;
}

}  // namespace textile
