#ifndef TEXTILE_SIM_PLOT_MEASURED_DRAPE_PICTURE_H_
#define TEXTILE_SIM_PLOT_MEASURED_DRAPE_PICTURE_H_

// The picture of a measured drape (target textile::plot, drawn with Cairo): the shadow's raster
// seen from above about the support's centre, its outline, the support's and the flat
// specimen's circles, the centre, the nodes with their angles and a caption with the DC and the
// node count. A second drape (e.g. a simulated one, `textile drape --compare`) adds its outline
// dashed, its nodes as small squares and its figures to the caption.
//
//   const textile::MeasuredDrape m = textile::MeasureDrapeMesh(scan, options, "scan.ply");
//   if (!textile::WriteMeasuredDrapePng(m, "overlay.png")) ...            // one outline
//   textile::MeasuredDrapeOverlay sim{.drape = &simulated, .label = "simulated"};
//   textile::WriteMeasuredDrapePng(m, "compare.png", &sim);               // and a dashed one

#include <string>

#include "textile/sim/scenes/drape_measure.h"

namespace textile {

// A second outline for the picture: a drape measured or simulated about the same centre (its
// shadow's angles and radii; a mask is not needed) and its name in the caption.
struct MeasuredDrapeOverlay {
  const MeasuredDrape* drape = nullptr;
  std::string label = "second";
};

// Writes an 800×800 PNG to `file`; the view spans 1.08 specimen radii (the larger of the two
// drapes') from the centre. The raster is painted when drape.shadow has a mask. False when the
// file cannot be written.
bool WriteMeasuredDrapePng(const MeasuredDrape& drape, const std::string& file,
                           const MeasuredDrapeOverlay* second = nullptr);

}  // namespace textile

#endif  // TEXTILE_SIM_PLOT_MEASURED_DRAPE_PICTURE_H_
