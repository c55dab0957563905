#include "textile/sim/scenes/acpm.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <sstream>

#include "textile/sim/scenes/acpm_shell.h"
#include "textile/sim/elastica/elastica.h"
#include "textile/sim/core/error.h"
#include "textile/sim/io/json_text.h"
#include "textile/sim/law/input_influence.h"
#include "textile/sim/law/material.h"
#include "textile/sim/core/units.h"

// The elastica model (docs/methods/acpm.md). The push is quasi-static and the heavy elastica has one
// equilibrium per overhang (no friction, no hysteresis on the platform in this model), so the
// overhang at which the front meets the barrier does not depend on the path: it is the root of
// the chord angle in L, found directly by FindBarrierCrossing (bracketing + Brent, each solve
// warm-started from the last) to 1e-10 relative instead of stepping by 0.05 mm.

namespace textile {
namespace {

// The side profile (x_i, y_i) swept across the width w [m]: a ruled strip mesh with the
// profile's points along the push and 10 cells across (x along the push, y across, z up).
TriangleMesh SweptProfile(const std::vector<double>& px, const std::vector<double>& py, double w) {
  constexpr int kAcross = 10;
  TriangleMesh mesh;
  const int n = static_cast<int>(px.size());
  if (n < 2) return mesh;
  mesh.vertices.resize(static_cast<long>(n) * (kAcross + 1), 3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j <= kAcross; ++j)
      mesh.vertices.row(i * (kAcross + 1) + j) << px[i], w * j / kAcross, py[i];
  mesh.triangles.resize(2L * (n - 1) * kAcross, 3);
  int f = 0;
  for (int i = 0; i + 1 < n; ++i) {
    for (int j = 0; j < kAcross; ++j) {
      const int a = i * (kAcross + 1) + j, b = a + kAcross + 1;
      mesh.triangles.row(f++) << a, b, b + 1;
      mesh.triangles.row(f++) << a, b + 1, a + 1;
    }
  }
  return mesh;
}

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr double kMaxWidth = 0.2;  // the ACPM200 takes samples up to 20 cm wide (section 4.1)

std::string Mm(double m, int precision = 6) {
  std::ostringstream s;
  s.precision(precision);
  s << units::MToMm(m);
  return s.str();
}

// The across seam as a variation of the strip along its length (elastica.h), u the distance
// from the front [m]: S(u) = S(|u - D|) (Pabst eq. 6 with the multiplier of seam.h), and the
// seam band [D - a/2, D + a/2] (clipped at the front) carrying `layers` times the density.
StripVariation AcrossSeamVariation(const SeamProfile& profile, double distance) {
  StripVariation v;
  v.stiffness_multiplier = [profile, distance](double u) {
    return profile.Multiplier(units::MToMm(std::abs(u - distance)));
  };
  const double half = units::MmToM(profile.allowance_mm) / 2.0;
  const double lo = std::max(0.0, distance - half), hi = distance + half;
  const double extra = profile.layers - 1.0;
  if (hi > lo && extra > 0.0) {
    v.weight_from_tip = [lo, hi, extra](double u) {
      return u + extra * (std::clamp(u, lo, hi) - lo);
    };
    v.breakpoints = {lo, hi};
  }
  // Corners of S: the seam line, and the ends of the fade on either side (S is C1 there, not
  // C2: stopping costs nothing and keeps every step smooth).
  const double d_max = units::MmToM(profile.influence_mm);
  const double d_end = d_max + units::MmToM(profile.fade_mm);
  for (double b :
       {distance, distance - d_max, distance + d_max, distance - d_end, distance + d_end})
    if (b > 0.0) v.breakpoints.push_back(b);
  std::sort(v.breakpoints.begin(), v.breakpoints.end());
  return v;
}

// One elastica crossing with an optional variation. A stiff material that never reaches the
// barrier within the sample length is bad input for this tester (InputError).
BarrierCrossing Crossing(const BendingLaw& law, double rho, const AcpmOptions& o,
                         const StripVariation& variation, const std::string& what) {
  CrossingOptions c;
  c.barrier_angle = o.barrier_angle;
  c.max_length = o.length;
  c.elastica.variation = variation;
  BarrierCrossing crossing = FindBarrierCrossing(law, rho, c);
  if (!crossing.converged) {
    if (crossing.message.rfind("does not reach the barrier", 0) == 0)
      throw InputError(what + " " + crossing.message + ": too stiff for a " + Mm(o.length, 4) +
                       " mm sample on this tester");
    throw ComputeError("elastica crossing of " + what + " failed: " + crossing.message);
  }
  return crossing;
}

AcpmCrossings ElasticaModel(const Material& material, const AcpmOptions& o,
                            const std::vector<double>& ray_z) {
  const BendingLaw law = material.EffectiveLaw();
  StripVariation variation;
  std::string what = "the fabric";
  if (o.seam.direction == AcpmSeamDirection::kAcross) {
    variation = AcrossSeamVariation(o.seam.profile, o.seam.position);
    what = "the fabric with the seam across";
  }
  const BarrierCrossing crossing = Crossing(law, material.areal_density, o, variation, what);
  AcpmCrossings out;
  out.converged = true;
  out.overhang.assign(ray_z.size(), crossing.overhang);
  out.profile_ray = static_cast<int>(ray_z.size() / 2);
  out.solves = crossing.elastica_solves + 1;
  ElasticaOptions e;
  e.variation = variation;
  e.num_samples = 201;
  const ElasticaProfile p = SolveHeavyElastica(law, material.areal_density, crossing.overhang, e);
  if (!p.converged) throw ComputeError("elastica side profile at the crossing: " + p.message);
  out.profile_x = p.x;
  out.profile_y = p.y;
  out.shape = SweptProfile(p.x, p.y, o.width);
  return out;
}

}  // namespace

std::string AcpmModelName(AcpmModelKind kind) {
  switch (kind) {
    case AcpmModelKind::kAuto:
      return "auto";
    case AcpmModelKind::kElastica:
      return "elastica";
    case AcpmModelKind::kShell:
      return "shell";
  }
  return "?";
}

AcpmModelKind ParseAcpmModel(const std::string& name) {
  if (name == "auto") return AcpmModelKind::kAuto;
  if (name == "elastica") return AcpmModelKind::kElastica;
  if (name == "shell") return AcpmModelKind::kShell;
  throw InputError("model '" + name + "': expected auto, elastica or shell");
}

std::string AcpmSeamDirectionName(AcpmSeamDirection direction) {
  switch (direction) {
    case AcpmSeamDirection::kNone:
      return "none";
    case AcpmSeamDirection::kAlong:
      return "along";
    case AcpmSeamDirection::kAcross:
      return "across";
  }
  return "?";
}

AcpmSeamDirection ParseAcpmSeamDirection(const std::string& name) {
  if (name == "none") return AcpmSeamDirection::kNone;
  if (name == "along") return AcpmSeamDirection::kAlong;
  if (name == "across") return AcpmSeamDirection::kAcross;
  throw InputError("seam direction '" + name + "': expected along or across");
}

AcpmModel ShellAcpmModel() {
  // The 3D engine's quasi-static push (acpm_shell.h), at its default resolution.
  return [](const Material& material, const AcpmOptions& options, const std::vector<double>& z) {
    return ShellAcpmCrossings(material, options, z);
  };
}

bool AcpmOptions::Check(std::string* why) const {
  std::ostringstream s;
  if (!(std::isfinite(width) && width > 0.0)) {
    s << "width: must be a finite number > 0 mm, got " << Mm(width);
  } else if (width > kMaxWidth * (1.0 + 1e-12)) {
    s << "width: " << Mm(width) << " mm is wider than the ACPM200 takes (200 mm)";
  } else if (!(std::isfinite(length) && length > 0.0 && length <= 1.0)) {
    s << "length: must be in (0, 1000] mm, got " << Mm(length);
  } else if (num_rays < 1 || num_rays > 1000) {
    s << "rays: must be in [1, 1000], got " << num_rays;
  } else if (!(std::isfinite(ray_margin) && ray_margin >= 0.0)) {
    s << "ray margin: must be >= 0 mm, got " << Mm(ray_margin);
  } else if (num_rays > 1 && !(width - 2.0 * ray_margin > 0.0)) {
    s << "ray margin: " << Mm(ray_margin) << " mm on each side leaves no room on a " << Mm(width)
      << " mm wide sample";
  } else if (!(barrier_angle > 0.0 && barrier_angle < std::numbers::pi / 2.0)) {
    s << "barrier: must be in (0, 90) deg, got " << barrier_angle / kDegree;
  } else if (!(std::isfinite(push_speed) && push_speed > 0.0)) {
    s << "push speed: must be > 0, got " << push_speed << " m/s";
  } else if (!(std::isfinite(crossing_tolerance) && crossing_tolerance > 0.0 &&
               crossing_tolerance <= 0.01)) {
    s << "crossing tolerance: must be in (0, 10] mm, got " << Mm(crossing_tolerance);
  } else if (seam.direction != AcpmSeamDirection::kNone) {
    std::string profile_why;
    const double at = seam.position;
    if (!seam.profile.Check(&profile_why)) {
      s << "seam: " << profile_why;
    } else if (seam.direction == AcpmSeamDirection::kAlong && !std::isnan(at) &&
               !std::isfinite(at)) {
      s << "seam-at: must be a finite number, got " << at;
    } else if (seam.direction == AcpmSeamDirection::kAlong && at < 0.0) {
      s << "seam-at: " << Mm(at) << " mm is negative (the seam's width position from the left "
        << "edge, 0.." << Mm(width) << " mm)";
    } else if (seam.direction == AcpmSeamDirection::kAlong && at > width) {
      s << "seam-at: the seam at z = " << Mm(at) << " mm lies outside the " << Mm(width)
        << " mm wide sample";
    } else if (seam.direction == AcpmSeamDirection::kAcross && std::isnan(at)) {
      s << "seam-at: required for a seam across the push direction (its distance behind the "
        << "sample's front, mm)";
    } else if (seam.direction == AcpmSeamDirection::kAcross && !std::isfinite(at)) {
      s << "seam-at: must be a finite number, got " << at;
    } else if (seam.direction == AcpmSeamDirection::kAcross && at < 0.0) {
      s << "seam-at: " << Mm(at) << " mm is negative (the seam's distance behind the front)";
    } else if (seam.direction == AcpmSeamDirection::kAcross && at > length) {
      s << "seam-at: the seam " << Mm(at) << " mm behind the front lies outside the " << Mm(length)
        << " mm long sample";
    }
  }
  if (s.str().empty() && (monte_carlo_samples < 0 || monte_carlo_samples == 1 ||
                          monte_carlo_samples > 100000))
    s << "monte carlo: must be 0 (none) or 2..100000 samples, got " << monte_carlo_samples;
  if (why != nullptr) *why = s.str();
  return s.str().empty();
}

std::vector<double> AcpmOptions::RayPositions() const {
  std::vector<double> z(num_rays);
  if (num_rays == 1) {
    z[0] = width / 2.0;
    return z;
  }
  for (int i = 0; i < num_rays; ++i)
    z[i] = ray_margin + (width - 2.0 * ray_margin) * i / (num_rays - 1.0);
  return z;
}

std::string AcpmResult::BriefReport() const {
  double lo = 1e300, hi = -1e300, flo = 1e300, fhi = -1e300;
  for (const auto& r : rays) {
    lo = std::min(lo, r.overhang);
    hi = std::max(hi, r.overhang);
    flo = std::min(flo, r.factor);
    fhi = std::max(fhi, r.factor);
  }
  std::ostringstream s;
  s.precision(6);
  s << "ACPM200 (" << AcpmModelName(model) << "): " << rays.size() << " rays, L = " << Mm(lo);
  if (hi > lo) s << " .. " << Mm(hi);
  s << " mm, factor " << flo;
  if (fhi > flo) s << " .. " << fhi;
  s << ", device time " << device_time << " s (" << solves << " solves)";
  return s.str();
}

namespace {

// The relative steps of the crossing length's differences: the elastica solves the crossing to
// 1e-10 relative, so 1e-4 leaves a truncation error of ~1e-8; the shell's crossing is a
// stepped, extrapolated solve good to ~1e-5 relative, so 1e-2 keeps its noise under 0.1 % of
// the difference, with a truncation error of ~1e-4 (docs/methods/sensitivity.md, "ACPM").
constexpr double kElasticaSensitivityStep = 1e-4;
constexpr double kShellSensitivityStep = 1e-2;

// The parameters the ACPM's elastica takes: a warp strip bent without stretch.
bool ElasticaTakes(const std::string& name) {
  return name == "b1" || name == "b2" || name == "c1" || name == "beta" ||
         name == "areal_density_gsm";
}

// options.sensitivity's parameters, checked before any work (InputError): the elastica takes the
// `bending` law's constants, beta and the density; the shell every parameter of the material.
std::vector<std::string> AcpmSensitivityParameters(const Material& material, const AcpmOptions& o,
                                                   bool elastica) {
  if (!o.sensitivity) return {};
  MaterialFitCovariance(material);  // a malformed covariance is refused now
  std::vector<std::string> names;
  if (o.sensitivity_parameters.empty()) {
    for (const std::string& n : MaterialParameterNames(material))
      if (!elastica || ElasticaTakes(n)) names.push_back(n);
  } else {
    names = o.sensitivity_parameters;
    for (const std::string& n : names) {
      GetMaterialParameter(material, n);  // an unknown name, listing the material's
      if (elastica && !ElasticaTakes(n))
        throw InputError(n + ": does not enter the ACPM's elastica (a warp strip bent without "
                             "stretch takes b1, b2, c1, beta and areal_density_gsm; --model "
                             "shell takes the membrane too)");
    }
  }
  CheckSensitivityParameters(material, names,
                             elastica ? kElasticaSensitivityStep : kShellSensitivityStep);
  return names;
}

double MeanOverhang(const AcpmCrossings& c) {
  double sum = 0.0;
  for (double l : c.overhang) sum += l;
  return sum / static_cast<double>(c.overhang.size());
}

// The crossings of a material by the run's model (the elastica or the shell).
using CrossingsOf = std::function<AcpmCrossings(const Material&)>;

// (L(up) − L(down)) / span for one input's two stepped runs, run(+1) and run(−1): a run that
// does not converge, or a stepped scene the model refuses (a barrier no longer reached within
// the sample), fails the sensitivity naming the input (ComputeError).
double LengthDifference(const std::function<AcpmCrossings(int side)>& run, double span,
                        const std::string& name) {
  double length[2];
  for (const int side : {1, -1}) {
    AcpmCrossings c;
    try {
      c = run(side);
    } catch (const InputError& e) {
      throw ComputeError("sensitivity of " + name + ": a stepped run failed: " + e.what());
    } catch (const ComputeError& e) {
      throw ComputeError("sensitivity of " + name + ": a stepped run failed: " + e.what());
    }
    if (!c.converged) throw ComputeError("sensitivity of " + name + ": " + c.message);
    length[side > 0 ? 0 : 1] = MeanOverhang(c);
  }
  return (length[0] - length[1]) / span;
}

// ∂L/∂p by central differences of whole runs of the model at p ± `step` of its scale
// (one-sided at the edge of its range); the influence table and σ into *result.
void AcpmSensitivities(const Material& material, const CrossingsOf& model, double step_size,
                       const std::vector<std::string>& parameters, AcpmResult* result) {
  std::vector<double> d;
  for (const std::string& name : parameters) {
    const ParameterStep step = DifferenceStep(material, name, step_size);
    d.push_back(LengthDifference(
        [&](int side) { return model(side > 0 ? step.up : step.down); }, step.span, name));
  }
  InfluenceTable table = MakeInfluenceTable(material, parameters, d);
  result->sensitivities = std::move(table.rows);
  result->crossing_length_sigma = table.sigma;
  result->sigma_note = std::move(table.sigma_note);
}

// The crossings of the material in a scene by the run's model, for the scene's own inputs.
using CrossingsIn = std::function<AcpmCrossings(const AcpmOptions&)>;

// The stated uncertainties of the ACPM's scene (docs/methods/sensitivity.md, "ACPM"): the
// barrier's alignment, a seam sewn along a marked line.
constexpr double kBarrierAngleUncertainty = 0.5 * kDegree;  // [rad]
constexpr double kSeamPositionUncertainty = 1e-3;          // [m]

// One scene input: its value t in `o`, how a scene takes another value, and its range.
struct SceneInput {
  std::string name;
  double value = 0.0;
  std::function<void(AcpmOptions*, double)> set;
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
};

// ∂L/∂t by a central difference of whole runs at t ± h, one-sided where that leaves [lo, hi].
double SceneDerivative(const CrossingsIn& model, const AcpmOptions& o, const SceneInput& input,
                       double h) {
  const double up = std::min(input.value + h, input.hi);
  const double down = std::max(input.value - h, input.lo);
  return LengthDifference(
      [&](int side) {
        AcpmOptions stepped = o;
        input.set(&stepped, side > 0 ? up : down);
        return model(stepped);
      },
      up - down, input.name);
}

// The scene's rows (the barrier's angle; with a seam across its position) and the seam's (its
// coefficients, SeamInfluences) into *result, at the same relative step as the material's. A
// seam along has no position row: the shell's mesh follows the seam (a grid line moved onto
// it), so a step of its position may move another line, and the difference compares two meshes;
// result->notes says so.
void AcpmSceneSensitivities(const CrossingsIn& model, const AcpmOptions& o, double step_size,
                            AcpmResult* result) {
  const double angle = o.barrier_angle;
  const SceneInput barrier{"barrier_angle", angle,
                           [](AcpmOptions* s, double t) { s->barrier_angle = t; }, 0.0,
                           std::nextafter(std::numbers::pi / 2.0, 0.0)};
  const double d_angle = SceneDerivative(model, o, barrier, step_size * angle);
  result->scene_sensitivities.push_back(
      SceneInfluence("barrier_angle", angle, 1.0 / kDegree, "deg", d_angle,
                     kBarrierAngleUncertainty, "default: the barrier's alignment, ±0.5°"));
  if (o.seam.direction == AcpmSeamDirection::kNone) return;
  if (o.seam.direction == AcpmSeamDirection::kAcross) {
    const SceneInput at{"seam_position", o.seam.position,
                        [](AcpmOptions* s, double t) { s->seam.position = t; }, 0.0, o.length};
    result->scene_sensitivities.push_back(SceneInfluence(
        "seam_position", at.value, units::MToMm(1.0), "mm",
        SceneDerivative(model, o, at, step_size * o.length), kSeamPositionUncertainty,
        "default: a seam sewn along a marked line, ±1 mm"));
  } else {
    result->notes += std::string(result->notes.empty() ? "" : "; ") +
                     "no sensitivity in the position of a seam along the push: the shell's mesh "
                     "follows the seam, so a stepped position compares two meshes";
  }
  std::vector<double> d_a;
  const SeamProfile& profile = o.seam.profile;
  for (int k = 0; k < kSeamCoefficients; ++k) {
    const SceneInput a{"the seam's coefficients", 0.0, [k, &profile](AcpmOptions* s, double t) {
                         s->seam.profile = SteppedSeamProfile(profile, k, t);
                       }};
    d_a.push_back(SceneDerivative(model, o, a, SeamCoefficientStep(profile, k, step_size)));
  }
  result->seam_sensitivities = SeamInfluences(profile, d_a);
}

// The mean crossing length's spread over materials drawn from the fit's covariance, each
// through the model, beside the linear σ; into result->monte_carlo.
void AcpmMonteCarlo(const CovarianceSamples& draws, const CrossingsOf& model, AcpmResult* result) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<double> lengths;
  for (const Material& sample : draws.materials) {
    const AcpmCrossings c = model(sample);
    lengths.push_back(c.converged ? MeanOverhang(c) : std::numeric_limits<double>::quiet_NaN());
  }
  result->monte_carlo = SummariseMonteCarlo(lengths, draws.rejected, result->crossing_length_sigma);
  result->monte_carlo->seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

AcpmResult RunAcpm(const Material& material, const AcpmOptions& options) {
  if (std::string why; !options.Check(&why)) throw InputError(why);
  if (!(std::isfinite(material.areal_density) && material.areal_density > 0.0))
    throw InputError("material: areal density must be > 0");
  AcpmOptions o = options;
  if (o.monte_carlo_samples > 0) o.sensitivity = true;  // the linear σ beside the sampled one
  if (o.seam.direction == AcpmSeamDirection::kAlong && std::isnan(o.seam.position))
    o.seam.position = o.width / 2.0;

  // Which model: the elastica is exact when nothing varies across the width.
  const bool varies_across = o.seam.direction == AcpmSeamDirection::kAlong;
  AcpmResult result;
  bool use_elastica = false;
  switch (o.model) {
    case AcpmModelKind::kAuto:
      use_elastica = !varies_across;
      if (o.seam.direction == AcpmSeamDirection::kNone) {
        result.model_reason =
            "auto: nothing varies across the width (plain sample), so the front "
            "is straight and the 1D heavy elastica is exact";
      } else if (o.seam.direction == AcpmSeamDirection::kAcross) {
        result.model_reason =
            "auto: a seam across the push direction varies only along the "
            "strip, so the 1D heavy elastica with S(d) and the seam band's "
            "mass along its length is exact";
      } else {
        result.model_reason =
            "auto: a seam along the push direction varies across the width, "
            "which needs the shell model";
      }
      break;
    case AcpmModelKind::kElastica:
      if (varies_across)
        throw InputError(
            "model elastica: a seam along the push direction varies across the "
            "width; the 1D elastica cannot represent it (use --model shell or auto)");
      use_elastica = true;
      result.model_reason = "requested";
      break;
    case AcpmModelKind::kShell:
      result.model_reason = "requested";
      break;
  }

  const std::vector<std::string> parameters =
      AcpmSensitivityParameters(material, o, use_elastica);
  const double step = use_elastica ? kElasticaSensitivityStep : kShellSensitivityStep;
  // The scene's and the seam's inputs: asked for (not implied by Monte Carlo), no list.
  const bool scene_inputs = options.sensitivity && options.sensitivity_parameters.empty();
  if (scene_inputs && o.seam.direction != AcpmSeamDirection::kNone)
    CheckSeamCoefficientSteps(o.seam.profile, step);
  const CovarianceSamples draws =
      o.monte_carlo_samples > 0
          ? SampleFitCovariance(material, o.monte_carlo_samples, o.monte_carlo_seed)
          : CovarianceSamples{};
  const std::vector<double> z = o.RayPositions();
  CrossingsOf model;
  CrossingsIn scene_model;  // the material's crossings in another scene
  if (use_elastica) {
    result.model = AcpmModelKind::kElastica;
    model = [&o, &z](const Material& m) { return ElasticaModel(m, o, z); };
    scene_model = [&material, &z](const AcpmOptions& in) { return ElasticaModel(material, in, z); };
  } else {
    result.model = AcpmModelKind::kShell;
    const AcpmModel shell = o.shell_model ? o.shell_model : ShellAcpmModel();
    if (!shell) {
      throw ComputeError(std::string("the shell model is not available in this build (issue 6)") +
                         (varies_across ? ": a seam along the push direction needs it"
                                        : "; --model elastica answers plain samples and seams "
                                          "across the push direction exactly"));
    }
    model = [shell, &o, &z](const Material& m) { return shell(m, o, z); };
    scene_model = [shell, &material, &z](const AcpmOptions& in) { return shell(material, in, z); };
  }
  AcpmCrossings crossings = model(material);
  if (!use_elastica) {
    if (!crossings.converged) {
      // ShellAcpmCrossings' messages name the model already; a plugged-in one's may not.
      const bool named = crossings.message.rfind("shell model", 0) == 0;
      throw ComputeError((named ? "" : "shell model: ") + crossings.message);
    }
    if (crossings.overhang.size() != z.size())
      throw ComputeError("shell model: returned " + std::to_string(crossings.overhang.size()) +
                         " crossings for " + std::to_string(z.size()) + " rays");
  }
  if (o.sensitivity && crossings.converged)
    AcpmSensitivities(material, model, step, parameters, &result);
  if (scene_inputs && crossings.converged) AcpmSceneSensitivities(scene_model, o, step, &result);
  if (o.monte_carlo_samples > 0 && crossings.converged) AcpmMonteCarlo(draws, model, &result);

  // The same fabric without seams: the reference of the factor (Fig. 5). The model's own when
  // it gives one (a shell model's discretisation error then cancels in the ratio), else the
  // exact elastica (a plain sample is its exact case), reused when the sample is plain.
  double plain_overhang = 0.0;
  if (o.seam.direction == AcpmSeamDirection::kNone && use_elastica) {
    plain_overhang = crossings.overhang.front();
  } else if (!use_elastica && std::isfinite(crossings.plain_overhang) &&
             crossings.plain_overhang > 0.0) {
    plain_overhang = crossings.plain_overhang;
  } else {
    plain_overhang =
        Crossing(material.EffectiveLaw(), material.areal_density, o, {}, "the fabric without seams")
            .overhang;
    ++crossings.solves;
  }
  const ClassicOutputs plain =
      ComputeClassicOutputs(material.areal_density, plain_overhang, o.barrier_angle);
  result.plain_overhang = plain_overhang;
  result.plain_bending_length = plain.bending_length;
  result.plain_rigidity = plain.flexural_rigidity;

  for (size_t i = 0; i < z.size(); ++i) {
    AcpmRay r;
    r.z = z[i];
    if (o.seam.direction == AcpmSeamDirection::kAlong) r.d = std::abs(z[i] - o.seam.position);
    if (o.seam.direction == AcpmSeamDirection::kAcross) r.d = o.seam.position;
    r.overhang = crossings.overhang[i];
    if (!(std::isfinite(r.overhang) && r.overhang > 0.0))
      throw ComputeError("model returned no crossing for ray " + std::to_string(i));
    // c = L/2 and G = ρ g c³ as the device reports them (L/2 rule at 41.5°, Peirce elsewhere),
    // ρ the plain fabric's areal density (what the operator enters).
    const ClassicOutputs c =
        ComputeClassicOutputs(material.areal_density, r.overhang, o.barrier_angle);
    r.bending_length = c.bending_length;
    r.rigidity = c.flexural_rigidity;
    r.factor = r.rigidity / result.plain_rigidity;
    r.device_time = r.overhang / o.push_speed;
    result.device_time = std::max(result.device_time, r.device_time);
    result.rays.push_back(r);
  }
  result.profile_ray = crossings.profile_ray;
  result.profile_x = crossings.profile_x;
  result.profile_y = crossings.profile_y;
  result.solves = crossings.solves;
  // The model's notes first, then the sensitivities' (AcpmSceneSensitivities).
  if (!crossings.notes.empty())
    result.notes = crossings.notes + (result.notes.empty() ? "" : "; " + result.notes);
  if (result.model == AcpmModelKind::kShell)
    result.membrane_defaults = MaterialDefaultNotes(material);
  result.shape = std::move(crossings.shape);
  return result;
}

nlohmann::json AcpmResultToJson(const AcpmResult& r, const Material& material,
                                const AcpmOptions& o) {
  using nlohmann::json;
  const BendingLaw law = material.EffectiveLaw();
  json j;
  j["model"] = AcpmModelName(r.model);
  j["model_reason"] = r.model_reason;
  j["material"] = {{"name", material.name},
                   {"areal_density_gsm", units::SiToGsm(material.areal_density)},
                   {"law_kes", LawToJson(law, false)}};
  j["sample"] = {{"width_mm", units::MToMm(o.width)},
                 {"length_mm", units::MToMm(o.length)},
                 {"rays", o.num_rays},
                 {"ray_margin_mm", units::MToMm(o.ray_margin)},
                 {"barrier_deg", o.barrier_angle / kDegree},
                 {"push_speed_mm_per_s", units::MToMm(o.push_speed)},
                 {"crossing_tolerance_mm", units::MToMm(o.crossing_tolerance)}};
  json seam = {{"direction", AcpmSeamDirectionName(o.seam.direction)}};
  if (o.seam.direction != AcpmSeamDirection::kNone) {
    double at = o.seam.position;
    if (o.seam.direction == AcpmSeamDirection::kAlong && std::isnan(at)) at = o.width / 2.0;
    seam["at_mm"] = units::MToMm(at);
    seam["at_meaning"] = o.seam.direction == AcpmSeamDirection::kAlong
                             ? "width position from the left edge"
                             : "distance behind the sample's front";
    seam["profile"] = SeamProfileToJson(o.seam.profile);
  }
  j["seam"] = seam;
  json rays = json::array();
  for (const auto& ray : r.rays) {
    rays.push_back({{"z_mm", units::MToMm(ray.z)},
                    {"d_mm", std::isfinite(ray.d) ? json(units::MToMm(ray.d)) : json()},
                    {"overhang_mm", units::MToMm(ray.overhang)},
                    {"bending_length_mm", units::MToMm(ray.bending_length)},
                    {"rigidity_uNm", units::SiRigidityToMicroNm(ray.rigidity)},
                    {"rigidity_mgcm", units::SiRigidityToMgCm(ray.rigidity)},
                    {"rigidity_gfcm", units::SiRigidityToGfCm(ray.rigidity)},
                    {"factor", ray.factor},
                    {"device_time_s", ray.device_time}});
  }
  j["rays"] = rays;
  j["plain"] = {{"overhang_mm", units::MToMm(r.plain_overhang)},
                {"bending_length_mm", units::MToMm(r.plain_bending_length)},
                {"rigidity_uNm", units::SiRigidityToMicroNm(r.plain_rigidity)},
                {"rigidity_mgcm", units::SiRigidityToMgCm(r.plain_rigidity)},
                {"rigidity_gfcm", units::SiRigidityToGfCm(r.plain_rigidity)}};
  j["device_time_s"] = r.device_time;
  json x = json::array(), y = json::array();
  for (size_t i = 0; i < r.profile_x.size(); ++i) {
    x.push_back(units::MToMm(r.profile_x[i]));
    y.push_back(units::MToMm(r.profile_y[i]));
  }
  j["side_profile"] = {{"ray", r.profile_ray}, {"x_mm", x}, {"y_mm", y}};
  j["solves"] = r.solves;
  if (!r.notes.empty()) j["notes"] = r.notes;
  if (!r.membrane_defaults.empty()) j["membrane_defaults"] = NotesJson(r.membrane_defaults);
  if (o.sensitivity || o.monte_carlo_samples > 0) {
    j["crossing_length_sigma_mm"] =
        std::isfinite(r.crossing_length_sigma) ? json(units::MToMm(r.crossing_length_sigma)) : json();
    j["crossing_length_sigma_note"] = r.sigma_note;
    const auto rows = [](const std::vector<ParameterInfluence>& influences) {
      json list = json::array();
      for (const ParameterInfluence& s : influences)
        list.push_back({{"parameter", s.parameter},
                        {"value", s.value},
                        {"unit", s.unit},
                        {"defaulted", s.defaulted},
                        {"d_length_mm_d_ln_p", units::MToMm(s.d_q_d_ln_p)},
                        {"uncertainty_ln",
                         std::isfinite(s.uncertainty_ln) ? json(s.uncertainty_ln) : json()},
                        {"uncertainty_source", s.uncertainty_source},
                        {"length_change_mm", units::MToMm(s.change)}});
      return list;
    };
    j["sensitivities"] = rows(r.sensitivities);
    // The scene's and the seam's (not in the σ), null when the run did not take them.
    j["scene_sensitivities"] = r.scene_sensitivities.empty() ? json() : rows(r.scene_sensitivities);
    j["seam_sensitivities"] = r.seam_sensitivities.empty() ? json() : rows(r.seam_sensitivities);
  }
  if (r.monte_carlo) j["monte_carlo"] = MonteCarloJson(*r.monte_carlo, 1e3, "mm");
  return j;
}

}  // namespace textile
