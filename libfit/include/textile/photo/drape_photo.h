#ifndef TEXTILE_PHOTO_DRAPE_PHOTO_H_
#define TEXTILE_PHOTO_DRAPE_PHOTO_H_

// Measured drapes from top-view shadow photos of a Cusick test (the drapemeter's lit shadow on
// paper, or a photo from above of the draped specimen on a contrasting ground): the shadow is
// found, mapped to the paper's plane through the rig and measured as the drapemeter measures a
// simulated one (textile/sim/scenes/drape_measure.h).
//
//   textile::DrapePhotoOptions o;                               // 150 / 90 mm, centre found
//   textile::Rig rig = textile::Rig::FromScale(0.25);           // or ReadRigJson (chessboard)
//   textile::MeasuredDrape m = textile::MeasureDrapePhoto(gray, rig, o, "shadow.jpg");

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "textile/photo/rig.h"
#include "textile/sim/scenes/drape_measure.h"

namespace textile {

inline constexpr int kOverlayMaxSidePx = 2000;

struct DrapePhotoOptions {
  DrapeMeasureOptions measure;
  // The support's centre in the photo [px]; when not given, the rectified shadow's area
  // centroid (centre_from "shadow"), which a lopsided outline pulls off the support's centre by
  // about its first harmonic (3.5 mm on the Fig. 8 drape; the DC does not depend on it;
  // docs/methods/drape-photos.md, "The centre").
  std::optional<Eigen::Vector2d> centre_px;
};

// Measures the one shadow of `photo` (CV_8UC1, CV_8UC3 or CV_8UC4), dark on light or light
// on dark (found), in stages (drape_photo_stages.h): grey, the light flattened, two levels,
// the one shadow, not cut, rectified to the paper through the rig at the measurement's cell,
// the centre, MeasureDrapeShadow (input_kind "photo"). Throws InputError for a photo the rig
// cannot map, ComputeError "<source>: <why>" for a photo with no shadow, two shadows, a shadow
// cut by the border, or an outline that is not a closed curve around the support. With
// `overlay`, it receives the photo (BGR, reduced to at most kOverlayMaxSidePx on its long side)
// with the outline, the support's circle, the centre and the nodes drawn on it.
MeasuredDrape MeasureDrapePhoto(const cv::Mat& photo, const Rig& rig,
                                const DrapePhotoOptions& options, const std::string& source,
                                cv::Mat* overlay = nullptr);

}  // namespace textile

#endif  // TEXTILE_PHOTO_DRAPE_PHOTO_H_
