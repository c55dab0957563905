#ifndef TEXTILE_FIT_SRC_CALIBRATE_STAGES_H_
#define TEXTILE_FIT_SRC_CALIBRATE_STAGES_H_

// The lens-model choice inside CalibrateRig, apart from the OpenCV fits so that it can be
// tested on its own (calibrate.cc runs it between fitting the nested models and adopting the
// chosen one). Not public API.

#include <span>
#include <vector>

#include "textile/photo/calibrate.h"

namespace textile::fit_internal {

// One nested lens model as fitted over all boards.
struct LensModelFit {
  const char* terms;  // "none", "k1", "k1, k2", ...
  int count;          // free distortion coefficients
  double rms_px;      // cv::calibrateCamera's RMS over all boards [px]
};

// Forward selection by significance over nested models (simplest first, the last the full
// one): from the first, the next model is taken while it, or the full model, lowers the
// squared error over all boards significantly (F-test; k1 at 0.01, later terms at 0.001).
// Returns the candidates tried, the last one kept. boards: views; corners: per view.
std::vector<CalibrationSummary::LensCandidate> SelectLensModel(std::span<const LensModelFit> fits,
                                                               int boards, int corners);

}  // namespace textile::fit_internal

#endif  // TEXTILE_FIT_SRC_CALIBRATE_STAGES_H_
