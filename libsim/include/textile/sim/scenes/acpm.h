#ifndef TEXTILE_SIM_SCENES_ACPM_H_
#define TEXTILE_SIM_SCENES_ACPM_H_

// The virtual ACPM200 bending tester (Pabst et al. 2008, sections 4.1 and 5.1;
// docs/spec/cantilever.md, "Virtual ACPM200"). A sample up to 200 mm wide lies on a
// platform and is pushed over its edge at 12 cm/min; the light barrier is the plane through
// the edge inclined 41.5° below the horizontal, sampled by 17 rays across the width. Ray i is
// cut when the sample's front at its width position z_i crosses that plane; the device records
// the overhang L_i then, and reports c_i = L_i / 2, G_i = ρ g c_i³ and G_i relative to the
// same fabric without seams (the "factor", Fig. 5).
//
//   textile::Material fabric = textile::ReadMaterial("samples/materials/pabst-fig8.json");
//   textile::AcpmOptions options;                        // 200 × 300 mm, 17 rays, auto model
//   options.seam.direction = textile::AcpmSeamDirection::kAcross;
//   options.seam.profile = textile::SeamPreset("C-plain");
//   options.seam.position = 0.02;                        // 20 mm behind the front [m]
//   textile::AcpmResult r = textile::RunAcpm(fabric, options);   // elastica, exact
//   // r.rays[i].overhang, .factor; r.model_reason says why the elastica answers it
//
// Models:
//  - elastica: the exact 1D heavy elastica (elastica.h). Exact whenever nothing varies across
//    the width: a plain sample (all rays cut together) and a seam across the push direction
//    (the stiffness multiplier S(d) and the seam band's mass vary along the strip only).
//  - shell: the 3D cloth engine, needed when something varies across the width (a seam along
//    the push direction). It is plugged in as an AcpmModel (acpm_types.h; ShellAcpmModel below).
//  - auto: the elastica when it is exact, else the shell model; the result says which and why.
//
// Everything here is SI (m, kg, s); the result JSON (docs/spec/cli.md) is in lab units.

#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "textile/sim/core/note.h"
#include "textile/sim/law/material_parameters.h"
#include "textile/sim/law/monte_carlo.h"
#include "textile/sim/scenes/acpm_types.h"
#include "textile/sim/mesh/mesh.h"

namespace textile {

// The shell model of this build: empty until the 3D engine provides one (then RunAcpm uses it
// whenever the options carry none). Defined in libsim/src/scenes/acpm.cc.
AcpmModel ShellAcpmModel();

struct AcpmRay {
  double z = 0.0;         // width position [m] from the left edge
  double d = std::numeric_limits<double>::quiet_NaN();  // distance from the seam line [m]
                          // (along: |z - z_s|; across: the seam's distance behind the front;
                          // NaN for a plain sample)
  double overhang = 0.0;  // L_i [m]
  double bending_length = 0.0;  // c_i from L_i at the barrier angle (L_i / 2 at 41.5°) [m]
  double rigidity = 0.0;        // G_i = ρ g c_i³ [N·m], ρ the plain fabric's density
  double factor = 1.0;          // G_i / G of the same fabric without seams [-]
  double device_time = 0.0;     // L_i / push speed [s]
};

struct AcpmResult {
  AcpmModelKind model = AcpmModelKind::kElastica;  // the model that answered
  std::string model_reason;                        // why that model (auto), or "requested"
  std::vector<AcpmRay> rays;
  double plain_overhang = 0.0;   // L* of the same fabric without seams [m]
  double plain_bending_length = 0.0;  // its c, as the rays' (L* / 2 at 41.5° only) [m]
  double plain_rigidity = 0.0;   // its G [N·m]
  double device_time = 0.0;      // until the last ray is cut [s]
  int profile_ray = 0;           // the ray of the side profile
  std::vector<double> profile_x, profile_y;  // side profile at that crossing [m]
  int solves = 0;
  std::string notes;
  // The membrane's defaulted fields (MaterialDefaultNotes) when the shell model answered, whose
  // sample has a membrane; empty for the elastica, which has none.
  std::vector<Note> membrane_defaults;
  TriangleMesh shape;  // the sample at that crossing (AcpmCrossings::shape), for --obj
  // With options.sensitivity: the crossing length's influences (Q = the rays' mean overhang
  // [m]; the elastica's rays are cut together), the largest change first, and its 1-σ from the
  // fit's covariance (NaN with sigma_note when the material carries none).
  std::vector<ParameterInfluence> sensitivities;
  // With options.sensitivity (not only implied by monte_carlo_samples) and no
  // sensitivity_parameters: the crossing length's derivatives in the scene, "barrier_angle"
  // (deg) and with a seam "seam_position" (mm, as AcpmSeam::position), and in the seam's
  // coefficients (SeamInfluences: "seam.a2", "seam.a1", "seam.a0", "seam.scale"), by the same
  // differences of whole runs. Not in the σ.
  std::vector<ParameterInfluence> scene_sensitivities;
  std::vector<ParameterInfluence> seam_sensitivities;
  double crossing_length_sigma = std::numeric_limits<double>::quiet_NaN();
  std::string sigma_note;
  // With options.monte_carlo_samples: the crossing length's spread over the samples [m],
  // beside the linear σ.
  std::optional<MonteCarloSpread> monte_carlo;

  // One line: model, crossing range, factor range, device time.
  std::string BriefReport() const;
};

// Runs the scene. Throws InputError for options that fail Check() and for a material the tester
// cannot bend to the barrier within the sample length ("does not reach the barrier within
// 300 mm"); ComputeError when the shell model is needed but not available in this build, or a
// model fails to converge.
AcpmResult RunAcpm(const Material& material, const AcpmOptions& options = {});

// docs/spec/cli.md's ACPM result JSON: {"model", "model_reason", "rays": [{"z_mm", "d_mm",
// "overhang_mm", "bending_length_mm", "rigidity_uNm", "factor", "device_time_s"}], "plain": {...},
// "device_time_s", "seam": {"direction", "at_mm", "profile"}, "side_profile": {...}, ...}.
// d_mm is null for a plain sample.
nlohmann::json AcpmResultToJson(const AcpmResult& result, const Material& material,
                                const AcpmOptions& options);

}  // namespace textile

#endif  // TEXTILE_SIM_SCENES_ACPM_H_
