#ifndef TEXTILE_SIM_SCENES_DRAPE_MEASURE_H_
#define TEXTILE_SIM_SCENES_DRAPE_MEASURE_H_

// A measured drape: the drapemeter's measurement (drape.h, "Measurement") applied to a shadow
// that did not come from SimulateDrape: a draped mesh (a 3D scan, another simulator's output,
// `textile drape --obj`) or a top-view shadow photo of a Cusick test (textile::photo,
// drape_photo.h). Both reach the same stage, MeasureDrapeShadow, so a measured DC and a simulated
// one are the same quantity (docs/methods/drape-measure.md).
//
//   textile::DrapeMeasureOptions o;                      // 150 mm specimen, 90 mm support
//   textile::MeasuredDrape m = textile::MeasureDrapeMesh(scan, mesh_options);
//   std::cout << m.drape_coefficient << ", " << m.nodes.angles.size() << " nodes\n";
//   std::string json = textile::MeasuredDrapeJson(m);     // MEASURED.json, read back by
//   textile::MeasuredDrape back = textile::ParseMeasuredDrapeJson(json, "m.json");  // --compare
//
// Units: SI inside (m, rad); the JSON is in mm and degrees.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "textile/sim/core/note.h"
#include "textile/sim/mesh/mesh.h"
#include "textile/sim/scenes/drape.h"

namespace textile {

// The measurement's settings; the defaults are DrapeOptions' (the same measurement).
struct DrapeMeasureOptions {
  double specimen_radius = 0.15;  // R [m]: A_specimen = π R² (the flat specimen's own area)
  double support_radius = 0.09;   // R_s [m], 0 < R_s < R
  double raster_cell = 0.0005;    // shadow grid cell [m]
  int outline_bins = 360;
  int smoothing_bins = 5;
  double node_prominence = 0.003;          // [m]
  double node_prominence_relative = 0.15;  // [-]

  // False with "<field>: <problem>" when a field is out of range.
  bool Check(std::string* why) const;
};

// The measurement settings of a simulated drape's options (radii, raster, bins, node rules).
DrapeMeasureOptions MeasureOptionsOf(const DrapeOptions& options);

// How the support's centre was settled.
//   "origin"   the input's own origin (a mesh from `textile drape`, whose centre is the origin)
//   "plateau"  a mesh: the centroid of its flat top (the support's disk)
//   "shadow"   a photo: the shadow's centre (drape_photo.h)
//   "given"    a flag (--centre-mm, --centre-px)
struct MeasuredDrape {
  std::string source;      // the input file, for messages and the JSON
  std::string input_kind;  // "mesh" | "photo"
  double specimen_radius = 0.0, support_radius = 0.0;  // [m], as measured with
  double drape_coefficient = 0.0;  // (A_shadow - π R_s²) / (π R² - π R_s²)
  DrapeShadow shadow;              // about the support's centre (origin of the grid's frame)
  DrapeNodes nodes;
  double min_radius = 0.0, max_radius = 0.0, mean_radius = 0.0;  // of the outline [m]
  Eigen::Vector2d centre{0.0, 0.0};  // the support's centre in the input's frame [m] (photo: the
                                     // rig's plane)
  std::string centre_from;           // see above
  std::vector<Note> notes;           // what to know before trusting the figures
};

// The common stage: `fabric` is a raster of what the specimen covers (mask 1), its grid
// (origin_x/y, cell, width, height) in a frame centred on the support. Adds the support's own
// shadow, fills holes, measures area, outline, nodes and the DC (with A_specimen = π R²).
// Throws ComputeError "<source>: the outline is not a closed curve around the support: <why>"
// when a covered cell touches the grid's border (the shadow is cut), or when the fabric does not
// reach the support's radius in some direction (a torn or partial specimen). Throws InputError
// for options that fail Check or a malformed grid.
MeasuredDrape MeasureDrapeShadow(DrapeShadow fabric, const DrapeMeasureOptions& options,
                                 const std::string& source);

// The measured drape as the MEASURED.json that `textile drape --compare` reads (pretty JSON,
// mm and degrees, the outline embedded; docs/guide/drape-measure.md), and back. The parser
// throws InputError "<source>: <field>: <problem>" for a file that is not one.
std::string MeasuredDrapeJson(const MeasuredDrape& drape);
MeasuredDrape ParseMeasuredDrapeJson(const std::string& text, const std::string& source);

// The outline as CSV: theta_deg,r_mm,x_mm,y_mm (the same columns as `textile drape`'s).
std::string OutlineCsv(const DrapeShadow& shadow);

}  // namespace textile

#endif  // TEXTILE_SIM_SCENES_DRAPE_MEASURE_H_
