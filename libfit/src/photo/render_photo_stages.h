#ifndef TEXTILE_FIT_SRC_RENDER_PHOTO_STAGES_H_
#define TEXTILE_FIT_SRC_RENDER_PHOTO_STAGES_H_

// The framing decision inside RenderPhoto, apart from the rendering so that it can be tested
// on its own (render_photo.cc runs it once the strip's shape is known). Not public API.

#include <Eigen/Core>

#include "textile/photo/render_photo.h"

namespace textile::fit_internal {

// Where the camera aims in the bending plane [mm]: options.aim_mm when given; else the whole
// strip with a margin of 8 % of the photo's short side, the platform taking a sixth to a
// quarter of the width, and most of the spare height (at least 6 %, at most 30 % of it) above
// the platform as background, shifted by options.aim_dx, aim_dy (fractions of the photo).
// xmax: the strip's furthest reach along x, ymin: its lowest point (<= 0) [mm].
Eigen::Vector2d FrameAim(const RenderPhotoOptions& options, double xmax, double ymin);

}  // namespace textile::fit_internal

#endif  // TEXTILE_FIT_SRC_RENDER_PHOTO_STAGES_H_
