#ifndef TEXTILE_SIM_LAW_SEAM_H_
#define TEXTILE_SIM_LAW_SEAM_H_

// Seams (Pabst et al. 2008, section 4): how a seam stiffens the fabric around it, where it lies
// on a pattern, and the extra mass of its seam allowance.
//
//   textile::SeamProfile c = textile::SeamPreset("C-plain");     // Table 2, 4 layers
//   double s = c.Multiplier(10.0);                                // S at d = 10 mm: 8.39
//   textile::SeamProfile fitted = textile::ReadSeamProfile("my-seam.json");
//
//   textile::Seam seam{c, textile::SeamLine(2, 2)};
//   seam.line << 0.0, 0.1,  0.2, 0.1;                             // along y = 0.1 m
//   textile::TriangleMesh mesh = textile::RegularGridMesh(0.2, 0.2, 40, 40);
//   std::vector<textile::Hinge> hinges = textile::BuildHinges(mesh);
//   std::vector<double> s_h = textile::HingeSeamMultipliers(mesh, hinges, {seam});  // #H, ≥ 1
//   Eigen::VectorXd m = textile::LumpedMasses(mesh, 0.2, {seam});              // #V [kg]
//   auto area_factor = textile::SeamAreaFactor({c});   // d [m] -> ⌈B_f⌉, for the mesher
//
// Units: the profile works in mm (d, as in the paper's Table 2); geometry is in metres.
// The readings of the paper that this file fixes are in docs/spec/physics.md ("Seams")
// and docs/methods/seams.md.

#include <Eigen/Core>
#include <array>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "textile/sim/mesh/mesh.h"

namespace textile {

// How the measured factor B_f(d) becomes the hinge multiplier S(d) of eq. 6.
enum class SeamMultiplierReading {
  kFactor,        // S = B_f(d): Fig. 5 defines B_f as stiffness relative to the plain fabric
  kPaperLiteral,  // S = 1 + B_f(d) (B_f(0) - 1), eq. 6 as printed
};

// The largest plausible stiffness factor B_f [-] (Table 2's stiffest seam reaches 9.07):
// above it a value is far more likely a unit mix-up than a seam. Seam files and measurements
// are checked against it.
inline constexpr double kMaxSeamFactor = 100.0;

// The stiffness profile of one seam type: B_f(d) = a2 d² + a1 d + a0, d in mm from the seam
// line, plus this project's settings (influence range, fade, allowance, reading).
// Invariants are stated by Check(); ParseSeamJson and SeamPreset only return profiles that pass.
struct SeamProfile {
  std::string type = "fitted";  // a Table 2 preset ("A-plain" .. "C-twill") or "fitted"
  std::string name;             // free text (e.g. the fabric and ISO seam it was measured on)
  int layers = 2;               // fabric layers stitched together in the seam band [-]
  std::array<double, 3> coefficients_mm{0.0, 0.0, 1.0};  // {a2 [1/mm²], a1 [1/mm], a0 [-]}
  std::array<double, 2> range_mm{0.0, 100.0};  // d range the fit saw [mm]; informative only
  std::optional<Eigen::Matrix3d> covariance;   // of (a2, a1, a0), from fit-seam [mm units]
  double influence_mm = 100.0;                 // d_max: S follows B_f up to here [mm]
  double fade_mm = 20.0;       // S fades (C1) from its value at d_max to 1 over this [mm]
  double allowance_mm = 10.0;  // width of the band (centred on the seam line) that carries
                               // `layers` times the fabric's areal density [mm]
  SeamMultiplierReading multiplier = SeamMultiplierReading::kFactor;
  // Lengthwise stiffness of the seam band, as a factor on S [-]. Inside the band (d <
  // allowance/2) a hinge whose rest edge makes the angle φ with the seam line gets
  // S(d) (1 + (rib_factor - 1) sin²φ): sin²φ is the share of its bend that bends the seam line
  // itself, which the ACPM200 (bending about axes parallel to the seam) does not measure.
  // 1 = the paper's scalar S of eq. 6 (the default). See docs/methods/seams.md, "Lengthwise stiffness".
  double rib_factor = 1.0;
  nlohmann::json fit;    // fit-seam's report, when a fit made this file (carried through)
  nlohmann::json extra;  // "notes", "source", "assumptions" (carried through)

  // B_f(d): the fitted polynomial itself, d [mm]. Not clamped; may be < 1.
  double StiffnessFactor(double d_mm) const;

  // S(d) ≥ 1, the bending multiplier of eq. 6 at distance d ≥ 0 [mm] from the seam line:
  //   c(d) = B_f(d)                      (kFactor)
  //   c(d) = 1 + B_f(d) (B_f(0) - 1)     (kPaperLiteral)
  //   S(d) = max(1, c(d))                for d ≤ d_max,
  //   S(d) = 1 + E(t), t = (d - d_max) / fade,  for d_max < d < d_max + fade,
  //   S(d) = 1                           from d_max + fade on.
  // E is the cubic Hermite from (c(d_max) - 1, slope c'(d_max)) to (0, slope 0), or, where that
  // would dip below 0 (steep descent: 3 (c - 1) + fade c' < 0), (c - 1)(1 - t)² e^{kt} with the
  // same end values and slopes. So S is C1 at d_max and at d_max + fade, ≥ 1 everywhere, and
  // the fit is not extrapolated beyond d_max. Inside [0, d_max] S has a kink where c crosses 1
  // (none of the Table 2 fits does on [0, 100] mm).
  double Multiplier(double d_mm) const;

  // The refinement factor of section 4.3 at distance d [mm]: ⌈S_factor(d)⌉ ≥ 1, where S_factor
  // is Multiplier() under the kFactor reading, so ⌈max(1, B_f(d))⌉ for d ≤ d_max, and 1 from
  // d_max + fade on (the fade band is refined like the influence band: S changes fastest there).
  double AreaFactor(double d_mm) const;

  // Checks every invariant; on failure writes "<field>: <problem>" to *why and returns false:
  // known type (a preset's layers and coefficients must be Table 2's: use "fitted" otherwise),
  // 1 ≤ layers ≤ 20, finite coefficients, 0 < B_f ≤ 100 on [0, d_max] (larger values are a unit
  // mix-up), 0 ≤ lo < hi ≤ 1000 mm, 1 ≤ d_max ≤ 1000 mm,
  // 0 < fade ≤ 1000 mm, 0 ≤ allowance ≤ 200 mm, 1 ≤ rib_factor ≤ 1000, covariance finite,
  // symmetric, diagonal ≥ 0, positive semi-definite (eigenvalues ≥ -1e-9 of its largest
  // entry); under the paper-literal reading also 1 + B_f(d) (B_f(0) - 1) ≤ 100 on [0, d_max].
  bool Check(std::string* why) const;
};

// The six Table 2 seams (A = ISO 1.01.01, B = 2.02.04, C = 2.04.05; plain or twill weave),
// with layers 2, 2, 3, 3, 4, 4, range_mm [0, 100] (the half-width of the 20 cm ACPM200 sample)
// and the default settings. Throws InputError for an unknown name.
SeamProfile SeamPreset(const std::string& type);
// "A-plain", "A-twill", "B-plain", "B-twill", "C-plain", "C-twill".
std::vector<std::string> SeamPresetNames();

// Seam JSON (docs/spec/cli.md): {"type", "layers", "coefficients_mm": [a2, a1, a0], "range_mm":
// [lo, hi], "covariance": [[3], [3], [3]], "name", "influence_mm", "fade_mm", "allowance_mm",
// "multiplier": "factor" | "paper-literal", "rib_factor", "fit": {...}, "notes", "source",
// "assumptions"}.
// type, layers and coefficients_mm are required. Throws InputError "<source>: <field>: <problem>".
SeamProfile ParseSeamJson(const std::string& text, const std::string& source);
// Reads a seam file. Throws InputError (unreadable file or any invalid field).
SeamProfile ReadSeamProfile(const std::string& path);
// The profile in the file format, every setting written out.
nlohmann::json SeamProfileToJson(const SeamProfile& profile);

// A seam line in pattern coordinates: #K×2 polyline vertices (x, y) [m], K ≥ 2.
using SeamLine = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

// One seam on a pattern: its type and where it runs. The band (for mass) is every point within
// allowance/2 of the polyline, round caps at its ends included (a seam that ends on the
// pattern boundary has its caps outside the pattern).
struct Seam {
  SeamProfile profile;
  SeamLine line;
};

// Exact Euclidean distance [m] from point p (x, y) [m] to the polyline (nearest segment point).
double DistanceToSeamLine(const Eigen::Vector2d& p, const SeamLine& line);

// Throws InputError "seam <index>: <problem>" if the profile fails Check(), the line has fewer
// than two points, a NaN or infinite coordinate, a zero-length segment (shorter than 1e-9 of
// the mesh's bounding box), or leaves the pattern: a point outside every triangle, or a segment
// that crosses a boundary edge of the mesh (checked against the mesh itself, so concave
// patterns and holes count). Lines along the boundary or ending on it are inside.
void CheckSeams(const std::vector<Seam>& seams, const TriangleMesh& mesh);

// Per-hinge distance [m] (#H) from the hinge's rest edge midpoint (v[2], v[3]) to the line.
std::vector<double> HingeSeamDistances(const TriangleMesh& mesh, const std::vector<Hinge>& hinges,
                                       const SeamLine& line);

// Per-hinge bending multipliers S (#H, ≥ 1), as BendingElements takes them: for each hinge the
// largest S_i(d_i) over the seams, times the lengthwise term of rib_factor inside a seam's band
// (max, not product: crossing seams are as stiff as the stiffer one; docs/spec/physics.md fixes no
// rule). No seams: all ones. Calls CheckSeams.
std::vector<double> HingeSeamMultipliers(const TriangleMesh& mesh, const std::vector<Hinge>& hinges,
                                         const std::vector<Seam>& seams);

// The mesher's area factor (section 4.3) as a function of the distance d [m] to the nearest
// seam: the largest AreaFactor over the profiles (all 1 for an empty list).
std::function<double(double d_m)> SeamAreaFactor(const std::vector<SeamProfile>& profiles);

// Area [m²] of the seam's band inside the pattern, per triangle (#F). Integrated adaptively:
// triangles wholly inside or outside the band (decided with the 1-Lipschitz distance) count
// exactly; so do triangles on which the distance is affine (one segment nearest, one side of
// it), clipped as polygons; the rest (at round caps and bends) are split into pieces below
// allowance/256 and clipped against the linearly interpolated distance. Exact to round-off
// (~1e-13 of the band area) along straight band edges; caps and bends lose ~1e-7 of it.
Eigen::VectorXd SeamBandAreas(const TriangleMesh& mesh, const Seam& seam);

// Lumped vertex masses [kg] (#V): each triangle's ρ A split equally among its vertices, plus,
// for each seam, (layers - 1) ρ on its band, lumped with the linear shape functions
// (vertex i of a triangle gets ∫ λ_i over the band part of the triangle), which keeps the
// total and the centre of mass of the seam exact on any mesh. Overlapping bands of several
// seams add. areal_density ρ [kg/m²] > 0. Calls CheckSeams.
Eigen::VectorXd LumpedMasses(const TriangleMesh& mesh, double areal_density,
                             const std::vector<Seam>& seams);

}  // namespace textile

#endif  // TEXTILE_SIM_LAW_SEAM_H_
