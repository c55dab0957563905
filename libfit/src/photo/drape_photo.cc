#include "textile/photo/drape_photo.h"

#include "textile/sim/core/error.h"

namespace textile {

// Placeholder until the photo measurement lands (the photo helper replaces this file).
MeasuredDrape MeasureDrapePhoto(const cv::Mat&, const Rig&, const DrapePhotoOptions&,
                                const std::string& source, cv::Mat*) {
  throw InputError(source + ": shadow photos are not measured yet");
}

}  // namespace textile
