#ifndef TEXTILE_SIM_PLOT_DRAPE_PICTURE_H_
#define TEXTILE_SIM_PLOT_DRAPE_PICTURE_H_

// The drapemeter's photo (target textile::plot, drawn with Cairo): one seed's shadow seen from
// above, the support's and the flat specimen's circles, the seams as they lie on the draped
// cloth and the nodes, with a caption; with a comparison, the measured outline over it.
//
//   const textile::DrapeResult r = textile::SimulateDrape(material, options);
//   if (!textile::WriteDrapeShadowPng(r, r.per_seed.front(), options, "shadow.png")) ...
//   const textile::DrapeComparison c = textile::CompareDrapes(r, measured, {});
//   if (!textile::WriteDrapeComparisonPng(r, c, options, "compare.png")) ...

#include <string>

#include "textile/sim/scenes/drape.h"
#include "textile/sim/scenes/drape_compare.h"

namespace textile {

// Writes the picture of `seed` (one of result.per_seed, converged) of a drape run with `options`
// as an 800×800 PNG to `file`; the view spans 1.08 specimen radii from the centre. False when
// the file cannot be written.
bool WriteDrapeShadowPng(const DrapeResult& result, const DrapeSeedResult& seed,
                         const DrapeOptions& options, const std::string& file);

// The picture of the first seed (as above) with the measured outline of `comparison` (of
// `result`) drawn over it as a dashed magenta line, turned by that seed's best rotation so that
// the folds can be compared, a legend (simulated and measured DC, the rotation, the outline
// RMS) and the verdict in the caption. False when the file cannot be written.
bool WriteDrapeComparisonPng(const DrapeResult& result, const DrapeComparison& comparison,
                             const DrapeOptions& options, const std::string& file);

}  // namespace textile

#endif  // TEXTILE_SIM_PLOT_DRAPE_PICTURE_H_
