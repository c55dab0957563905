#include "textile/photo/drape_photo.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "drape_photo_stages.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"

namespace textile {
namespace drape_photo {
namespace {

constexpr double kPi = std::numbers::pi;
// The smallest photo side measured [px] (a 300 mm shadow at 2 mm/px).
constexpr int kMinPhotoSide = 64;
// An all-dark photo: its brightest reduced pixel below this [grey levels].
constexpr int kDarkestUsable = 25;
// A photo with no contrast: its 1st and 99th percentiles closer than this [grey levels].
constexpr int kMinSpread = 10;
// The two flattened levels must differ by this much (the shadow style gives about 0.85, a
// light specimen on a dark ground or the reverse 0.3 or more).
constexpr double kMinContrast = 0.1;
// The border band on which the light is first fitted [fraction of the short side].
constexpr double kBorderBand = 0.04;
// Background pixels this far from the shadow class are used to fit the light [reduced px].
constexpr int kEdgeGapPx = 3;
// The blob's gate is the region dilated by this much [reduced px].
constexpr int kGateDilationPx = 3;
// Regions below this many reduced pixels are never a shadow.
constexpr double kMinBlobPx = 50.0;
// At most this many samples enter the light's least-squares fit.
constexpr int kMaxLightSamples = 20000;
// A log-residual this large excludes a border pixel from the refit (a stray object).
constexpr double kLightOutlier = 0.15;
// Cells beyond this refuse the photo: the shadow spans far more paper than a drape.
constexpr double kMaxCells = 25e6;
// Margin of the rectified raster around the shadow [cells].
constexpr int kRasterMarginCells = 3;

int MonomialCount(int degree) { return (degree + 1) * (degree + 2) / 2; }

constexpr int kMaxDegree = 3;

void Monomials(double x, double y, int degree, double* out) {
  double xp[kMaxDegree + 1] = {1.0}, yp[kMaxDegree + 1] = {1.0};
  for (int d = 1; d <= degree; ++d) xp[d] = xp[d - 1] * x, yp[d] = yp[d - 1] * y;
  int k = 0;
  for (int d = 0; d <= degree; ++d)
    for (int i = 0; i <= d; ++i) out[k++] = xp[d - i] * yp[i];
}

double FullPx(int reduced_px, int factor) { return (reduced_px + 0.5) * factor - 0.5; }

// The flattened reduced photo as 8-bit for Otsu, its brightest pixel at 250 (a light specimen
// on a dark ground flattens to several times the ground's 1); *scale receives the factor.
cv::Mat Flat8(const cv::Mat& flat, double* scale) {
  double lo = 0.0, hi = 0.0;
  cv::minMaxLoc(flat, &lo, &hi);
  *scale = 250.0 / std::max(hi, 1e-6);
  cv::Mat u8;
  flat.convertTo(u8, CV_8U, *scale);
  return u8;
}

// Median of the 8-bit values where `mask` is set (or unset if !set).
double MaskedMedian(const cv::Mat& u8, const cv::Mat& mask) {
  std::array<long, 256> hist{};
  long n = 0;
  for (int v = 0; v < u8.rows; ++v)
    for (int u = 0; u < u8.cols; ++u)
      if (mask.at<uchar>(v, u)) ++hist[u8.at<uchar>(v, u)], ++n;
  long seen = 0;
  for (int g = 0; g < 256; ++g)
    if ((seen += hist[g]) * 2 >= n) return g;
  return 255;
}

double Bilinear(const cv::Mat& grey, double x, double y) {
  const int i = static_cast<int>(std::floor(x)), j = static_cast<int>(std::floor(y));
  const double fx = x - i, fy = y - j;
  const uchar* r0 = grey.ptr<uchar>(j);
  const uchar* r1 = grey.ptr<uchar>(j + 1);
  return (r0[i] * (1 - fx) + r0[i + 1] * fx) * (1 - fy) + (r1[i] * (1 - fx) + r1[i + 1] * fx) * fy;
}

// The light map (reduced, CV_32F) at a full-resolution pixel, bilinear: the light is smooth
// over a reduced pixel (a cubic over the photo).
double LightAt(const cv::Mat& map, const Eigen::Vector2d& px, int factor) {
  const double x = std::clamp((px.x() + 0.5) / factor - 0.5, 0.0, map.cols - 1.001);
  const double y = std::clamp((px.y() + 0.5) / factor - 0.5, 0.0, map.rows - 1.001);
  const int i = static_cast<int>(x), j = static_cast<int>(y);
  const double fx = x - i, fy = y - j;
  const float* r0 = map.ptr<float>(j);
  const float* r1 = map.ptr<float>(j + 1);
  return (r0[i] * (1 - fx) + r0[i + 1] * fx) * (1 - fy) + (r1[i] * (1 - fx) + r1[i + 1] * fx) * fy;
}

}  // namespace

cv::Mat GreyOf(const cv::Mat& photo, const std::string& source) {
  if (photo.empty()) throw InputError(source + ": empty photo");
  if (photo.cols < kMinPhotoSide || photo.rows < kMinPhotoSide)
    throw InputError(source + ": a photo of " + std::to_string(photo.cols) + "x" +
                     std::to_string(photo.rows) + " px is too small for a drape (at least " +
                     std::to_string(kMinPhotoSide) + " px a side)");
  if (photo.type() == CV_8UC1) return photo;
  cv::Mat grey;
  if (photo.type() == CV_8UC3) {
    cv::cvtColor(photo, grey, cv::COLOR_BGR2GRAY);
  } else if (photo.type() == CV_8UC4) {
    cv::cvtColor(photo, grey, cv::COLOR_BGRA2GRAY);
  } else {
    throw InputError(source + ": a photo must be 8-bit grey or colour");
  }
  return grey;
}

Reduced Reduce(const cv::Mat& grey, int long_side) {
  Reduced r;
  r.factor = std::max(1, (std::max(grey.cols, grey.rows) + long_side - 1) / long_side);
  if (r.factor == 1) {
    r.grey = grey;
    return r;
  }
  // A whole factor keeps reduced pixel k over full pixels k·f .. k·f + f − 1.
  const cv::Mat whole =
      grey(cv::Rect(0, 0, grey.cols / r.factor * r.factor, grey.rows / r.factor * r.factor));
  cv::resize(whole, r.grey, cv::Size(whole.cols / r.factor, whole.rows / r.factor), 0, 0,
             cv::INTER_AREA);
  return r;
}

void CheckExposure(const cv::Mat& reduced, const std::string& source) {
  std::array<long, 256> hist{};
  for (int v = 0; v < reduced.rows; ++v)
    for (int u = 0; u < reduced.cols; ++u) ++hist[reduced.at<uchar>(v, u)];
  const long n = static_cast<long>(reduced.total());
  int p1 = -1, p99 = -1, top = 0;
  long seen = 0;
  for (int g = 0; g < 256; ++g) {
    if (hist[g]) top = g;
    seen += hist[g];
    if (p1 < 0 && seen * 100 >= n) p1 = g;
    if (p99 < 0 && seen * 100 >= 99 * n) p99 = g;
  }
  if (top < kDarkestUsable)
    throw ComputeError(source + ": no shadow found: the photo is all dark (brightest grey " +
                       std::to_string(top) + ")");
  if (p99 - p1 < kMinSpread)
    throw ComputeError(source + ": no shadow found: the photo has no contrast (grey " +
                       std::to_string(p1) + " to " + std::to_string(p99) + ")");
}

double Illumination::At(double x, double y) const {
  const double xn = 2.0 * x / std::max(1, width - 1) - 1.0;
  const double yn = 2.0 * y / std::max(1, height - 1) - 1.0;
  double m[16];
  Monomials(xn, yn, degree, m);
  double s = 0.0;
  for (int k = 0; k < coefficients.size(); ++k) s += coefficients(k) * m[k];
  return std::exp(s);
}

Illumination FitIllumination(const cv::Mat& reduced, const cv::Mat& background, int degree,
                             int factor, int full_width, int full_height) {
  Illumination light;
  light.degree = degree;
  light.width = full_width;
  light.height = full_height;
  const int count = cv::countNonZero(background);
  const int terms = MonomialCount(degree);
  if (count < 4 * terms) {  // no background to speak of: a flat light
    light.coefficients = Eigen::VectorXd::Zero(terms);
    light.coefficients(0) = std::log(std::max(1.0, cv::mean(reduced)[0]));
    return light;
  }
  const int stride = std::max(1, static_cast<int>(std::sqrt(count / double(kMaxLightSamples))));
  std::vector<double> rows, values;
  double m[16];
  for (int v = 0; v < reduced.rows; v += stride)
    for (int u = 0; u < reduced.cols; u += stride) {
      if (!background.at<uchar>(v, u)) continue;
      const double xn = 2.0 * FullPx(u, factor) / std::max(1, full_width - 1) - 1.0;
      const double yn = 2.0 * FullPx(v, factor) / std::max(1, full_height - 1) - 1.0;
      Monomials(xn, yn, degree, m);
      rows.insert(rows.end(), m, m + terms);
      values.push_back(std::log(std::max<double>(1.0, reduced.at<uchar>(v, u))));
    }
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> A(
      rows.data(), static_cast<Eigen::Index>(values.size()), terms);
  const Eigen::Map<const Eigen::VectorXd> b(values.data(),
                                            static_cast<Eigen::Index>(values.size()));
  Eigen::VectorXd c = A.colPivHouseholderQr().solve(b);
  // One refit without outliers (a stray object on the paper, the shadow's blurred edge).
  const Eigen::VectorXd residual = A * c - b;
  std::vector<Eigen::Index> keep;
  for (Eigen::Index k = 0; k < residual.size(); ++k)
    if (std::abs(residual(k)) < kLightOutlier) keep.push_back(k);
  if (static_cast<int>(keep.size()) >= 4 * terms && keep.size() < values.size()) {
    Eigen::MatrixXd A2(keep.size(), terms);
    Eigen::VectorXd b2(keep.size());
    for (size_t k = 0; k < keep.size(); ++k) A2.row(k) = A.row(keep[k]), b2(k) = b(keep[k]);
    c = A2.colPivHouseholderQr().solve(b2);
  }
  light.coefficients = c;
  return light;
}

cv::Mat LightMap(const Illumination& light, cv::Size size, int factor) {
  cv::Mat map(size, CV_32F);
  cv::parallel_for_(cv::Range(0, size.height), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v)
      for (int u = 0; u < size.width; ++u)
        map.at<float>(v, u) = static_cast<float>(light.At(FullPx(u, factor), FullPx(v, factor)));
  });
  return map;
}

cv::Mat Flatten(const cv::Mat& reduced, const cv::Mat& light_map) {
  cv::Mat grey, flat;
  reduced.convertTo(grey, CV_32F);
  cv::divide(grey, light_map, flat);
  return flat;
}

Levels SeparateLevels(const cv::Mat& flat, const std::string& source) {
  double to8 = 1.0;
  const cv::Mat u8 = Flat8(flat, &to8);
  cv::Mat above;
  const double otsu = cv::threshold(u8, above, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  // The background holds most of the border.
  long border_above = 0, border = 0;
  for (int u = 0; u < u8.cols; ++u)
    border_above += (above.at<uchar>(0, u) != 0) + (above.at<uchar>(u8.rows - 1, u) != 0),
        border += 2;
  for (int v = 0; v < u8.rows; ++v)
    border_above += (above.at<uchar>(v, 0) != 0) + (above.at<uchar>(v, u8.cols - 1) != 0),
        border += 2;
  Levels levels;
  levels.shadow_darker = border_above * 2 >= border;
  cv::Mat below;
  cv::bitwise_not(above, below);
  const cv::Mat& bg_mask = levels.shadow_darker ? above : below;
  const cv::Mat& sh_mask = levels.shadow_darker ? below : above;
  if (cv::countNonZero(sh_mask) == 0 || cv::countNonZero(bg_mask) == 0)
    throw ComputeError(source + ": no shadow found (the photo has one level)");
  levels.background = MaskedMedian(u8, bg_mask) / to8;
  levels.shadow = MaskedMedian(u8, sh_mask) / to8;
  levels.threshold = 0.5 * (levels.background + levels.shadow);
  // Relative to the brighter level (a black ground has a background of 0).
  const double contrast = std::abs(levels.background - levels.shadow) /
                          std::max({levels.background, levels.shadow, 1e-12});
  if (!(contrast >= kMinContrast))
    throw ComputeError(source + ": no shadow found (the two grey levels differ by only " +
                       NumberText(100.0 * contrast, 2) + " %; Otsu's threshold " +
                       NumberText(otsu / to8, 3) + ")");
  return levels;
}

cv::Mat BackgroundMask(const cv::Mat& flat, const Levels& levels) {
  cv::Mat shadow(flat.size(), CV_8U);
  for (int v = 0; v < flat.rows; ++v)
    for (int u = 0; u < flat.cols; ++u)
      shadow.at<uchar>(v, u) = levels.Shadow(flat.at<float>(v, u)) ? 255 : 0;
  cv::dilate(shadow, shadow,
             cv::getStructuringElement(cv::MORPH_ELLIPSE,
                                       cv::Size(2 * kEdgeGapPx + 1, 2 * kEdgeGapPx + 1)));
  cv::Mat background;
  cv::bitwise_not(shadow, background);
  return background;
}

Separation SeparateShadow(const Reduced& reduced, int full_width, int full_height,
                          const std::string& source) {
  // First the light from the border band (no shadow there unless it is cut, which stage (e)
  // refuses), then from all the background the first separation finds.
  cv::Mat band(reduced.grey.size(), CV_8U, cv::Scalar(255));
  const int w = std::max(1, static_cast<int>(kBorderBand * std::min(band.cols, band.rows)));
  if (band.cols > 2 * w && band.rows > 2 * w)
    band(cv::Rect(w, w, band.cols - 2 * w, band.rows - 2 * w)).setTo(0);
  Separation s;
  s.light = FitIllumination(reduced.grey, band, 2, reduced.factor, full_width, full_height);
  s.light_map = LightMap(s.light, reduced.grey.size(), reduced.factor);
  s.flat = Flatten(reduced.grey, s.light_map);
  s.levels = SeparateLevels(s.flat, source);
  s.light = FitIllumination(reduced.grey, BackgroundMask(s.flat, s.levels), 3, reduced.factor,
                            full_width, full_height);
  s.light_map = LightMap(s.light, reduced.grey.size(), reduced.factor);
  s.flat = Flatten(reduced.grey, s.light_map);
  s.levels = SeparateLevels(s.flat, source);
  return s;
}

Blob FindShadow(const cv::Mat& flat, const Levels& levels, const std::string& source) {
  cv::Mat mask(flat.size(), CV_8U);
  for (int v = 0; v < flat.rows; ++v)
    for (int u = 0; u < flat.cols; ++u)
      mask.at<uchar>(v, u) = levels.Shadow(flat.at<float>(v, u)) ? 255 : 0;
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  std::vector<std::pair<int, int>> regions;  // (area, label)
  for (int k = 1; k < n; ++k) regions.emplace_back(stats.at<int>(k, cv::CC_STAT_AREA), k);
  std::sort(regions.rbegin(), regions.rend());
  if (regions.empty() || regions[0].first < kMinBlobPx)
    throw ComputeError(source + ": no shadow found (nothing but specks on the paper)");
  if (regions.size() > 1 && regions[1].first >= kSecondShadowFraction * regions[0].first)
    throw ComputeError(source + ": two shadows (regions of " + std::to_string(regions[0].first) +
                       " and " + std::to_string(regions[1].first) +
                       " px in the reduced photo): one drape per photo");
  Blob blob;
  const int label = regions[0].second;
  blob.area_px = regions[0].first;
  blob.box =
      cv::Rect(stats.at<int>(label, cv::CC_STAT_LEFT), stats.at<int>(label, cv::CC_STAT_TOP),
               stats.at<int>(label, cv::CC_STAT_WIDTH), stats.at<int>(label, cv::CC_STAT_HEIGHT));
  blob.mask = (labels == label);
  cv::dilate(blob.mask, blob.mask,
             cv::getStructuringElement(cv::MORPH_ELLIPSE,
                                       cv::Size(2 * kGateDilationPx + 1, 2 * kGateDilationPx + 1)));
  // In reduced px here; MeasureDrapePhoto scales it to the full photo.
  blob.centroid_px =
      Eigen::Vector2d(centroids.at<double>(label, 0), centroids.at<double>(label, 1));
  return blob;
}

void CheckNotCut(const Blob& blob, const cv::Size& size, const std::string& source) {
  std::string side;
  if (blob.box.x <= 0)
    side = "left";
  else if (blob.box.y <= 0)
    side = "top";
  else if (blob.box.x + blob.box.width >= size.width)
    side = "right";
  else if (blob.box.y + blob.box.height >= size.height)
    side = "bottom";
  if (!side.empty())
    throw ComputeError(source + ": the shadow is cut by the photo's border (on the " + side +
                       "): the outline is not a closed curve around the support");
}

void CheckShadowSize(const Blob& blob, int factor, double mm_per_px, const DrapeMeasureOptions& o,
                     const std::string& source) {
  const double area_mm2 = blob.area_px * factor * factor * mm_per_px * mm_per_px;
  const double support_mm2 = kPi * std::pow(o.support_radius * 1e3, 2);
  if (!(area_mm2 >= 0.9 * support_mm2))
    throw ComputeError(source + ": the shadow found covers only " + NumberText(area_mm2, 3) +
                       " mm², less than the support's disk (" + NumberText(support_mm2, 3) +
                       " mm² for a " + NumberText(o.support_radius * 1e3, 4) +
                       " mm radius): not a drape, or the wrong scale (--mm-per-px, --rig)");
}

Eigen::Vector2d PhotoPxOfPlane(const Rig& rig, const Eigen::Vector2d& mm) {
  const Eigen::Vector2d ideal = (rig.plane_from_image.inverse() * mm.homogeneous()).hnormalized();
  return rig.lens ? rig.lens->Distort(ideal) : ideal;
}

DrapeShadow RectifyShadow(const cv::Mat& grey, const Separation& s, const Blob& blob, int factor,
                          const Rig& rig, double cell, const std::string& source) {
  // The paper's extent of the blob: the image of its (padded) box's boundary bounds it.
  const double x0 = std::max(0.0, FullPx(blob.box.x - 2, factor));
  const double y0 = std::max(0.0, FullPx(blob.box.y - 2, factor));
  const double x1 = std::min(grey.cols - 1.0, FullPx(blob.box.x + blob.box.width + 2, factor));
  const double y1 = std::min(grey.rows - 1.0, FullPx(blob.box.y + blob.box.height + 2, factor));
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
  constexpr int kEdgeSamples = 32;
  for (int k = 0; k <= kEdgeSamples; ++k) {
    const double t = static_cast<double>(k) / kEdgeSamples;
    for (const Eigen::Vector2d& p :
         {Eigen::Vector2d(x0 + t * (x1 - x0), y0), Eigen::Vector2d(x0 + t * (x1 - x0), y1),
          Eigen::Vector2d(x0, y0 + t * (y1 - y0)), Eigen::Vector2d(x1, y0 + t * (y1 - y0))}) {
      const Eigen::Vector2d mm = rig.PlaneFromImage(p);
      if (!mm.allFinite())
        throw InputError(source + ": the rig cannot map the shadow's part of the photo");
      lo = lo.cwiseMin(mm), hi = hi.cwiseMax(mm);
    }
  }
  const double cell_mm = cell * 1e3;
  DrapeShadow out;
  out.cell = cell;
  const double ox = (std::floor(lo.x() / cell_mm) - kRasterMarginCells) * cell_mm;
  const double oy = (std::floor(lo.y() / cell_mm) - kRasterMarginCells) * cell_mm;
  const double wx = std::ceil((hi.x() - ox) / cell_mm) + kRasterMarginCells + 1;
  const double wy = std::ceil((hi.y() - oy) / cell_mm) + kRasterMarginCells + 1;
  if (!(wx * wy <= kMaxCells))
    throw InputError(
        source + ": the shadow spans " + NumberText(hi.x() - lo.x(), 4) + " x " +
        NumberText(hi.y() - lo.y(), 4) +
        " mm on the paper, far more than a drape: check the scale (--mm-per-px, --rig)");
  out.width = static_cast<int>(wx);
  out.height = static_cast<int>(wy);
  out.origin_x = ox * 1e-3;
  out.origin_y = oy * 1e-3;
  out.mask.assign(static_cast<size_t>(out.width) * out.height, 0);
  const Eigen::Matrix3d image_from_plane = rig.plane_from_image.inverse();
  const cv::Mat& gate = blob.mask;
  cv::parallel_for_(cv::Range(0, out.height), [&](const cv::Range& range) {
    for (int j = range.start; j < range.end; ++j) {
      const double y = oy + j * cell_mm;
      for (int i = 0; i < out.width; ++i) {
        const double x = ox + i * cell_mm;
        Eigen::Vector2d px = (image_from_plane * Eigen::Vector3d(x, y, 1.0)).hnormalized();
        if (rig.lens) px = rig.lens->Distort(px);
        if (!(px.x() >= 0.0 && px.y() >= 0.0 && px.x() < grey.cols - 1 && px.y() < grey.rows - 1))
          continue;
        const int gu = static_cast<int>(std::lround((px.x() + 0.5) / factor - 0.5));
        const int gv = static_cast<int>(std::lround((px.y() + 0.5) / factor - 0.5));
        if (gu < 0 || gv < 0 || gu >= gate.cols || gv >= gate.rows || !gate.at<uchar>(gv, gu))
          continue;
        const double value = Bilinear(grey, px.x(), px.y()) / LightAt(s.light_map, px, factor);
        if (s.levels.Shadow(value)) out.mask[static_cast<size_t>(j) * out.width + i] = 1;
      }
    }
  });
  return out;
}

Eigen::Vector2d ShadowCentre(const DrapeShadow& shadow) {
  double si = 0.0, sj = 0.0, n = 0.0;
  for (int j = 0; j < shadow.height; ++j)
    for (int i = 0; i < shadow.width; ++i)
      if (shadow.mask[static_cast<size_t>(j) * shadow.width + i]) si += i, sj += j, n += 1.0;
  if (n == 0.0) return {shadow.origin_x, shadow.origin_y};
  return {shadow.origin_x + si / n * shadow.cell, shadow.origin_y + sj / n * shadow.cell};
}

Eigen::Vector2d GivenCentre(const Rig& rig, const Eigen::Vector2d& centre_px,
                            const std::string& source) {
  const Eigen::Vector2d mm = rig.PlaneFromImage(centre_px);
  if (!centre_px.allFinite() || !mm.allFinite())
    throw InputError(source + ": --centre-px: the rig cannot map (" + NumberText(centre_px.x()) +
                     ", " + NumberText(centre_px.y()) + ") px to the paper");
  return mm * 1e-3;
}

void Recentre(const Eigen::Vector2d& centre, DrapeShadow* shadow) {
  shadow->origin_x -= centre.x();
  shadow->origin_y -= centre.y();
}

cv::Mat DrawOverlay(const cv::Mat& photo, const Rig& rig, const MeasuredDrape& m) {
  cv::Mat out;
  if (photo.channels() == 1)
    cv::cvtColor(photo, out, cv::COLOR_GRAY2BGR);
  else if (photo.channels() == 4)
    cv::cvtColor(photo, out, cv::COLOR_BGRA2BGR);
  else
    out = photo.clone();
  // At most kOverlayMaxSidePx on the long side (a 20 MP overlay is a 40 MB PNG).
  const double f = std::min(1.0, kOverlayMaxSidePx / static_cast<double>(std::max(out.cols, out.rows)));
  if (f < 1.0) cv::resize(out, out, cv::Size(), f, f, cv::INTER_AREA);
  const int thick = std::max(1, std::max(out.cols, out.rows) / 800);
  const Eigen::Vector2d c_mm = m.centre * 1e3;
  auto px = [&](double theta, double r_m) {
    const Eigen::Vector2d p =
        PhotoPxOfPlane(rig, c_mm + 1e3 * r_m * Eigen::Vector2d(std::cos(theta), std::sin(theta)));
    // Pixel centres at integers in both images: x_out = (x + 0.5) f - 0.5.
    return cv::Point(static_cast<int>(std::lround((p.x() + 0.5) * f - 0.5)),
                     static_cast<int>(std::lround((p.y() + 0.5) * f - 0.5)));
  };
  std::vector<cv::Point> outline, support;
  for (int b = 0; b < m.shadow.angles.size(); ++b)
    outline.push_back(px(m.shadow.angles(b), m.shadow.radii(b)));
  for (int k = 0; k < 180; ++k) support.push_back(px(2 * kPi * k / 180.0, m.support_radius));
  cv::polylines(out, std::vector<std::vector<cv::Point>>{support}, true, cv::Scalar(255, 128, 0),
                thick, cv::LINE_AA);
  cv::polylines(out, std::vector<std::vector<cv::Point>>{outline}, true, cv::Scalar(0, 200, 0),
                thick, cv::LINE_AA);
  for (size_t k = 0; k < m.nodes.angles.size(); ++k)
    cv::circle(out, px(m.nodes.angles[k], m.nodes.radii[k]), 4 * thick, cv::Scalar(0, 0, 255),
               cv::FILLED, cv::LINE_AA);
  cv::drawMarker(out, px(0.0, 0.0), cv::Scalar(0, 0, 255), cv::MARKER_CROSS, 12 * thick, thick);
  return out;
}

}  // namespace drape_photo

MeasuredDrape MeasureDrapePhoto(const cv::Mat& photo, const Rig& rig,
                                const DrapePhotoOptions& options, const std::string& source,
                                cv::Mat* overlay) {
  using namespace drape_photo;
  if (std::string why; !options.measure.Check(&why)) throw InputError(source + ": " + why);
  const cv::Mat grey = GreyOf(photo, source);
  rig.CheckForImage(grey.cols, grey.rows, source);
  const Reduced reduced = Reduce(grey);
  CheckExposure(reduced.grey, source);
  const Separation s = SeparateShadow(reduced, grey.cols, grey.rows, source);
  Blob blob = FindShadow(s.flat, s.levels, source);
  blob.centroid_px = Eigen::Vector2d(FullPx(0, reduced.factor), FullPx(0, reduced.factor)) +
                     blob.centroid_px * reduced.factor;
  CheckNotCut(blob, reduced.grey.size(), source);
  CheckShadowSize(blob, reduced.factor, rig.MmPerPxAt(blob.centroid_px), options.measure, source);
  DrapeShadow fabric =
      RectifyShadow(grey, s, blob, reduced.factor, rig, options.measure.raster_cell, source);
  const Eigen::Vector2d centre =
      options.centre_px ? GivenCentre(rig, *options.centre_px, source) : ShadowCentre(fabric);
  Recentre(centre, &fabric);
  MeasuredDrape m = MeasureDrapeShadow(std::move(fabric), options.measure, source);
  m.input_kind = "photo";
  m.centre = centre;
  m.centre_from = options.centre_px ? "given" : "shadow";
  if (overlay) *overlay = DrawOverlay(photo, rig, m);
  return m;
}

}  // namespace textile
