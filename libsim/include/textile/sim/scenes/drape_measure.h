#ifndef TEXTILE_SIM_SCENES_DRAPE_MEASURE_H_
#define TEXTILE_SIM_SCENES_DRAPE_MEASURE_H_

// A measured drape: the drapemeter's measurement (drape.h, "Measurement") applied to a shadow
// that did not come from SimulateDrape: a draped mesh (a 3D scan, another simulator's output,
// `textile drape --obj`) or a top-view shadow photo of a Cusick test (textile::photo,
// drape_photo.h). Both reach the same stage, MeasureDrapeShadow, so a measured DC and a simulated
// one are the same quantity (docs/methods/drape-measure.md).
//
//   textile::DrapeMeshOptions o;                         // 150 mm specimen, 90 mm support
//   o.metres_per_unit = 0.001;                           // a scan in mm
//   const textile::TriangleMesh scan = textile::ReadDrapedMesh("scan.ply");   // mesh_io.h
//   textile::MeasuredDrape m = textile::MeasureDrapeMesh(scan, o, "scan.ply");
//   std::cout << m.drape_coefficient << ", " << m.nodes.angles.size() << " nodes\n";
//   std::string json = textile::MeasuredDrapeJson(m);     // MEASURED.json, read back by
//   textile::MeasuredDrape back = textile::ParseMeasuredDrapeJson(json, "m.json");  // --compare
//
// Units: SI inside (m, rad); the JSON is in mm and degrees.

#include <Eigen/Core>
#include <functional>
#include <numbers>
#include <optional>
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
  Eigen::Vector2d centre{0.0, 0.0};  // the support's centre in the input's frame [m] (a mesh:
                                     // levelled when noted; a photo: the rig's plane)
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

// A draped mesh's frame: which axis is up. Seen from above, the horizontal axes keep a
// right-handed frame: z up takes (x, y), y up takes (x, -z) (so a y-up mesh and the same mesh
// turned z-up give the same angles).
enum class MeshUpAxis { kZ, kY };
std::string MeshUpAxisName(MeshUpAxis up);         // "z" | "y"
MeshUpAxis ParseMeshUpAxis(const std::string& s);  // InputError naming the value

// How a draped mesh is read (MeasureDrapeMesh).
struct DrapeMeshOptions {
  DrapeMeasureOptions measure;
  // The file's unit [m]: 1 (metres, as `textile drape --obj` writes), 0.001 (mm).
  double metres_per_unit = 1.0;
  MeshUpAxis up = MeshUpAxis::kZ;
  // The support's centre in the horizontal frame above [m] (after metres_per_unit); found from
  // the mesh's flat top when not given (FindMeshSupportCentre).
  std::optional<Eigen::Vector2d> centre;
  // The flat top: the vertices at most this far below the top's height [m] (a scan's noise and
  // the first millimetre of the overhang's turn-down lie within it; LevelMeshTop).
  double plateau_tolerance = 0.001;
  // The flat top's least-squares plane may slope by at most this [rad]; less is levelled
  // (LevelMeshTop).
  double max_tilt = std::numbers::pi / 90.0;  // 2°

  // False with "<field>: <problem>" when a field is out of range (measure's fields too).
  bool Check(std::string* why) const;
};

// Stage 1: the vertices in the measurement's frame, #V×3 [m]: horizontal (x, y) as
// MeshUpAxis says, then height; scaled by metres_per_unit. Throws InputError "<source>: ..." for
// a mesh without triangles, NaN or infinite coordinates, or indices out of range.
Vertices MeshInMeasureFrame(const TriangleMesh& draped, const DrapeMeshOptions& options,
                            const std::string& source);

// Stage 2: the scale against the specimen: throws InputError "<source>: ... --units mm?" when the
// mesh spans more than 3 specimen diameters, "... --units m?" when it spans less than half the
// support's diameter (the suggestion follows metres_per_unit).
void CheckMeshScale(const Vertices& frame, const DrapeMeshOptions& options,
                    const std::string& source);

// The top: its height is the highest h such that faces whose highest corner lies at h or above
// cover 2 % of the support's area (so a scan's stray faces and spikes, a few small faces, do
// not set it); the flat top is what lies within plateau_tolerance below it.
//
// Stage 3: levelling. The flat top's vertices (spike tips more than plateau_tolerance above
// the top's height left out) are fitted with a plane by least squares; when it slopes by
// kLevelBelow or more, *frame is turned about the top's mean so that the plane is horizontal, and
// again (at most six rounds) until the refitted top is level to 1e-9 rad: a scan taken on a
// drapemeter that was not quite level is measured as if it were. Below kLevelBelow nothing is
// turned (the shadow moves by under 0.1 mm: the skirt hangs about 60 mm below the top), so a level
// mesh keeps its own frame. Throws InputError "<source>: ... slopes by X°" naming --up and
// --centre-mm when the total turn exceeds max_tilt (a y-up mesh read as z-up slopes by about 90°).
inline constexpr double kLevelBelow = 0.1 * std::numbers::pi / 180.0;  // [rad]
struct MeshLevelling {
  // levelled = rotation · p + translation for every vertex p of the frame before [m].
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double tilt = 0.0;  // the top's slope before [rad] (0 when not levelled)
  bool levelled = false;
};
MeshLevelling LevelMeshTop(Vertices* frame, const Triangles& triangles,
                           const DrapeMeshOptions& options, const std::string& source);

// Stage 4: the support's centre. Given: options.centre ("given"). Found: the flat top is the
// triangles whose corners all lie at most plateau_tolerance below the top's height; its centre is
// their centroid weighted by projected area (so mesh density does not pull it), snapped to the
// origin when within kOriginSnap of it ("origin": a mesh that is centred already, as `textile
// drape` writes them; else "plateau"). Throws InputError "<source>: ..." naming --up and
// --centre-mm when the flat top covers less than half the support's area (a tilted mesh beyond
// levelling, or a y-up mesh read as z-up).
inline constexpr double kOriginSnap = 0.0005;  // [m]
struct MeshSupportCentre {
  Eigen::Vector2d centre{0.0, 0.0};  // [m], in the (levelled) frame
  std::string from;                  // "given" | "origin" | "plateau"
  double plateau_area = 0.0;         // [m²], 0 when given
};
MeshSupportCentre FindMeshSupportCentre(const Vertices& frame, const Triangles& triangles,
                                        const DrapeMeshOptions& options, const std::string& source);

// Stage 5: the fabric's raster (mask 1 where a projected triangle covers a cell centre) on a
// grid about `centre` [m], spanning the projection and the support's disk (support_radius [m])
// with two empty cells of margin, for MeasureDrapeShadow. Throws InputError beyond 1e8 cells.
DrapeShadow RasteriseFabric(const Vertices& frame, const Triangles& triangles,
                            const Eigen::Vector2d& centre, double cell, double support_radius);

// A draped mesh measured as the drapemeter measures a simulated one: vertices no face uses
// dropped (a scan's stray points), stages 1-5 (no levelling with a given centre, which is in
// the input's frame), then MeasureDrapeShadow (input_kind "mesh"; centre and centre_from from
// stage 4; the note "levelled" when stage 3 turned the mesh). Throws as the stages and
// MeasureDrapeShadow do (InputError for bad input, ComputeError for an outline that is not a
// closed curve around the support).
MeasuredDrape MeasureDrapeMesh(const TriangleMesh& draped, const DrapeMeshOptions& options,
                               const std::string& source);

// A synthetic drape for tests and benchmarks: a polar mesh of the flat specimen (radius R =
// specimen_radius [m]; `rings` rings, the one at the support's radius R_s exact, × `sectors`
// sectors, quads cut in two, a fan at the centre; about 2 rings sectors triangles, z up, centred
// on the origin) whose support disk stays flat at z = 0 and whose overhang is a ruled skirt: each
// radial line runs straight from the support's edge to a rim point projecting onto
// r = outline_radius(θ) [m] (R_s < r ≤ R), as long as it was flat (R − R_s), so that the shadow
// is exactly the polygon of the rim points. Throws InputError for sizes out of range.
TriangleMesh SyntheticDrapeMesh(double specimen_radius, double support_radius, int rings,
                                int sectors, const std::function<double(double)>& outline_radius);

// The measured drape as the MEASURED.json that `textile drape --compare` reads (pretty JSON,
// mm and degrees, the outline embedded; docs/guide/drape-measure.md), and back. The parser
// throws InputError "<source>: <field>: <problem>" for a file that is not one.
std::string MeasuredDrapeJson(const MeasuredDrape& drape);
MeasuredDrape ParseMeasuredDrapeJson(const std::string& text, const std::string& source);

// The outline as CSV: theta_deg,r_mm,x_mm,y_mm (the same columns as `textile drape`'s).
std::string OutlineCsv(const DrapeShadow& shadow);

}  // namespace textile

#endif  // TEXTILE_SIM_SCENES_DRAPE_MEASURE_H_
