#ifndef TEXTILE_PHOTO_DRAPE_PHOTO_STAGES_H_
#define TEXTILE_PHOTO_DRAPE_PHOTO_STAGES_H_

// The stages of MeasureDrapePhoto (drape_photo.h; docs/methods/drape-photos.md), in order, each
// with its own test (tests/fit/drape_photo_test.cc). The blob search works on a reduced copy
// of the photo (kReducedSide); only the rectification samples the full resolution, at the
// raster's cell centres.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>

#include "textile/photo/drape_photo.h"

namespace textile::drape_photo {

// Long side of the reduced copy on which the light and the blob are found [px].
inline constexpr int kReducedSide = 800;

// (a) The photo in grey (CV_8UC1; BGR and BGRA are converted). InputError for an empty photo,
// one under 64 px a side, or another type.
cv::Mat GreyOf(const cv::Mat& photo, const std::string& source);

// The photo reduced by a whole factor (INTER_AREA) to a long side of at most `long_side`.
struct Reduced {
  cv::Mat grey;    // CV_8UC1
  int factor = 1;  // full px = (reduced px + 0.5) · factor − 0.5
};
Reduced Reduce(const cv::Mat& grey, int long_side = kReducedSide);

// ComputeError "<source>: no shadow found: the photo is all dark" (or "... has no contrast")
// when the reduced photo has nothing to separate.
void CheckExposure(const cv::Mat& reduced, const std::string& source);

// (b) The light on the paper: log(grey) of the background as a polynomial in the photo's
// normalised coordinates (x, y ∈ [−1, 1]), degree 2 fitted on the photo's border band, then
// degree 3 on every background pixel away from the shadow's edge. Grey / Light = 1 on the
// background.
struct Illumination {
  Eigen::VectorXd coefficients;  // monomials x^i y^j, i + j ≤ degree, in Monomials' order
  int degree = 0;
  int width = 0, height = 0;  // full photo [px]
  // The light at a full-resolution pixel [grey levels].
  double At(double x, double y) const;
};
// Fits `degree` to log(reduced) where `background` (CV_8UC1, same size) is set.
Illumination FitIllumination(const cv::Mat& reduced, const cv::Mat& background, int degree,
                             int factor, int full_width, int full_height);
// The light at the reduced photo's pixels (CV_32F), and the reduced photo divided by it
// (CV_32F, 1 on the background).
cv::Mat LightMap(const Illumination& light, cv::Size size, int factor);
cv::Mat Flatten(const cv::Mat& reduced, const cv::Mat& light_map);

// (c) The two levels of a flattened photo: Otsu's threshold, the background being the class
// that holds most of the photo's border; the threshold used is the middle of the two classes'
// medians. ComputeError "<source>: no shadow found (...)" when they are not apart.
struct Levels {
  double background = 1.0, shadow = 0.0;  // medians of the classes (flattened)
  double threshold = 0.5;
  bool shadow_darker = true;
  bool Shadow(double flat_value) const {
    return shadow_darker ? flat_value < threshold : flat_value > threshold;
  }
};
Levels SeparateLevels(const cv::Mat& flat, const std::string& source);
// The background pixels of a flattened photo (CV_8UC1 255), kept kEdgeGapPx away from the
// shadow class.
cv::Mat BackgroundMask(const cv::Mat& flat, const Levels& levels);

// The light and the levels together: (b) and (c) alternated twice.
struct Separation {
  Illumination light;
  cv::Mat light_map;  // LightMap of the reduced photo
  Levels levels;
  cv::Mat flat;  // the reduced photo flattened (CV_32F)
};
Separation SeparateShadow(const Reduced& reduced, int full_width, int full_height,
                          const std::string& source);

// (d) The one shadow: the largest connected region of the shadow class. Regions under
// kSpeckFraction of the largest are specks (ignored); a second region of at least
// kSecondShadowFraction of it is a second shadow. ComputeError "<source>: no shadow found"
// and "<source>: two shadows ...".
inline constexpr double kSpeckFraction = 0.05;
inline constexpr double kSecondShadowFraction = 0.25;
struct Blob {
  cv::Mat mask;          // CV_8UC1 reduced, 255 on the region, dilated by kGateDilationPx
  cv::Rect box;          // the region's bounding box (reduced px, undilated)
  double area_px = 0.0;  // the region's area in reduced px
  Eigen::Vector2d centroid_px{0, 0};  // full-resolution px
};
Blob FindShadow(const cv::Mat& flat, const Levels& levels, const std::string& source);

// (e) ComputeError "<source>: the shadow is cut by the photo's border (...)" when the region
// touches the reduced photo's border.
void CheckNotCut(const Blob& blob, const cv::Size& reduced_size, const std::string& source);
// ComputeError when the shadow is smaller than the support's disk (a speck, not a drape, or
// the wrong scale): `mm_per_px` at its centroid.
void CheckShadowSize(const Blob& blob, int factor, double mm_per_px, const DrapeMeasureOptions& o,
                     const std::string& source);

// (f) The shadow on the paper: a raster of `cell` [m] over the blob's extent on the paper
// plane; each cell centre is mapped to the photo through the rig (inverse homography, then
// the lens's Distort), the full-resolution grey sampled there (bilinear), divided by the light
// (the light map, bilinear) and compared with the threshold; only cells inside the blob's gate
// count. The grid is in the rig's plane frame [m] (not yet centred).
DrapeShadow RectifyShadow(const cv::Mat& grey, const Separation& s, const Blob& blob, int factor,
                          const Rig& rig, double cell, const std::string& source);

// The photo pixel of a plane point [mm] (the rig's inverse).
Eigen::Vector2d PhotoPxOfPlane(const Rig& rig, const Eigen::Vector2d& mm);

// (g) The support's centre [m, plane frame]: the area centroid of the rectified shadow.
Eigen::Vector2d ShadowCentre(const DrapeShadow& shadow);
// The given centre [px] on the plane [m]; InputError if the rig cannot map it.
Eigen::Vector2d GivenCentre(const Rig& rig, const Eigen::Vector2d& centre_px,
                            const std::string& source);

// (h) The grid's frame moved to `centre` [m] (the support's centre becomes the origin).
void Recentre(const Eigen::Vector2d& centre, DrapeShadow* shadow);

// The overlay: the photo (BGR) with the outline, the support's circle, the centre and the
// nodes drawn on it.
cv::Mat DrawOverlay(const cv::Mat& photo, const Rig& rig, const MeasuredDrape& m);

}  // namespace textile::drape_photo

#endif  // TEXTILE_PHOTO_DRAPE_PHOTO_STAGES_H_
