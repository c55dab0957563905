// textile drape: the virtual drapemeter (Cusick test; Pabst section 5.2). Drape coefficient and
// nodes of a disk of fabric on a smaller disk, over N seeded perturbations; result JSON, outline
// CSV, top-view shadow PNG, draped mesh OBJ; with --compare, against a measured drape.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "textile/sim/core/error.h"
#include "textile/sim/io/json_text.h"
#include "textile/sim/core/units.h"
#include "textile/sim/io/mesh_io.h"
#include "textile/sim/law/material.h"
#include "textile/sim/plot/drape_picture.h"
#include "textile/sim/scenes/drape.h"
#include "textile/sim/scenes/drape_compare.h"
#include "textile/sim/scenes/drape_measure.h"
#include "textile/sim/scenes/drape_what_if.h"

namespace textile::cli {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

struct DrapeArgs {
  std::string material, seams = "none", seam_type, seam_file, mount = "clamped", out, png, obj, ply;
  int seeds = 1;
  unsigned first_seed = 1;
  std::optional<double> resolution_mm;
  std::optional<double> seam_rib;
  std::optional<double> contact_sink_mm;
  std::optional<double> seam_refine_mm;
  std::optional<double> compression_ratio;
  std::string rim_mm = "auto";        // a length [mm], 0 (off) or "auto" (the default)
  std::string start_modes;            // "MIN-MAX"; empty: DrapeOptions' harmonics
  std::optional<double> rim_band_mm;  // default: 20 mm, or a third of a smaller overhang
  std::optional<double> shift_mm;     // --seams shifted only; default 50 mm
  double specimen_mm = 150.0, support_mm = 90.0, perturbation_mm = 2.0;
  double frame_deg = 0.0;
  std::optional<double> tolerance;
  double max_seconds = 600.0;
  bool coarse = false, no_coarse = false;
  bool progress = false;  // the solver's progress lines on stderr even when it is not a terminal
  bool extrapolate = false, no_extrapolate = false;
  bool json = false;
  // --compare MEASURED.json and its tolerances; --strict makes a failed verdict an error.
  std::string compare;
  std::optional<double> dc_tol, node_tol, outline_tol_mm;
  bool strict = false;
  // --sensitivity, the parameters it is taken for, --monte-carlo.
  SensitivityArgs sensitivity;
  // --cache DIR keeps the drape with its sensitivities; --what-if EDITS predicts from it.
  std::string cache, what_if;
  std::optional<double> what_if_reach_percent, what_if_max_error;
};

SeamProfile LoadSeamProfile(const DrapeArgs& a) {
  if (!a.seam_type.empty() && !a.seam_file.empty())
    throw InputError("--seam-type and --seam-file: give one of them, not both");
  if (!a.seam_type.empty()) {
    for (const std::string& name : SeamPresetNames())
      if (name == a.seam_type) return SeamPreset(name);
    std::string names;
    for (const std::string& name : SeamPresetNames()) names += (names.empty() ? "" : ", ") + name;
    throw InputError("--seam-type: '" + a.seam_type + "' is not a Table 2 seam (" + names + ")");
  }
  if (!a.seam_file.empty()) return ReadSeamProfile(a.seam_file);
  return SeamPreset("C-plain");  // Fig. 8: a double lap seam
}

// "C-plain", or "C-plain, rib 16" when the band is stiffer along its line (--seam-rib).
std::string SeamLabel(const SeamProfile& p) {
  if (p.rib_factor == 1.0) return p.type;
  std::ostringstream s;
  s << p.type << ", rib " << p.rib_factor;
  return s.str();
}

// The seam profile with --seam-rib applied (it overrides the file's or preset's rib_factor).
SeamProfile SeamProfileWithRib(const DrapeArgs& a) {
  SeamProfile p = LoadSeamProfile(a);
  if (!a.seam_rib) return p;
  p.rib_factor = *a.seam_rib;
  std::string why;
  if (!p.Check(&why)) throw InputError("--seam-rib: " + why);
  return p;
}

DrapeOptions Options(const DrapeArgs& a) {
  DrapeOptions o;
  try {
    o.seams = ParseDrapeSeams(a.seams);
  } catch (const InputError&) {
    throw InputError("--seams: '" + a.seams + "' is not none, weft, weft+warp or shifted");
  }
  try {
    o.mount = ParseDrapeMount(a.mount);
  } catch (const InputError&) {
    throw InputError("--mount: '" + a.mount + "' is not clamped or resting");
  }
  if (o.seams == DrapeSeams::kNone && (!a.seam_type.empty() || !a.seam_file.empty() || a.seam_rib))
    throw InputError("--seam-type/--seam-file/--seam-rib: need --seams weft, weft+warp or shifted");
  o.seam_profile = SeamProfileWithRib(a);
  if (a.seam_refine_mm) {
    if (o.seams == DrapeSeams::kNone)
      throw InputError("--seam-refine-mm: needs --seams weft, weft+warp or shifted");
    if (!(std::isfinite(*a.seam_refine_mm) && *a.seam_refine_mm >= 0.0 &&
          *a.seam_refine_mm <= 300.0))
      throw InputError("--seam-refine-mm: must be between 0 (off) and 300 mm");
    o.seam_refinement_range = units::MmToM(*a.seam_refine_mm);
  }
  auto finite = [](double v, const char* flag) {
    if (!std::isfinite(v)) throw InputError(std::string(flag) + ": must be a finite number");
    return v;
  };
  o.specimen_radius = units::MmToM(finite(a.specimen_mm, "--specimen-mm"));
  o.support_radius = units::MmToM(finite(a.support_mm, "--support-mm"));
  if (!(a.specimen_mm > 0.0 && a.specimen_mm <= 2000.0))
    throw InputError("--specimen-mm: must be in (0, 2000] mm");
  if (!(a.support_mm > 0.0)) throw InputError("--support-mm: must be > 0");
  if (a.specimen_mm <= a.support_mm)
    throw InputError("--specimen-mm: the specimen (" + Num(a.specimen_mm) +
                     " mm) must be larger than the support (" + Num(a.support_mm) + " mm)");
  if (a.shift_mm && o.seams != DrapeSeams::kShifted)
    throw InputError("--shift-mm: needs --seams shifted (the other seams run through the centre)");
  const double shift_mm = a.shift_mm ? finite(*a.shift_mm, "--shift-mm") : 50.0;
  if (std::abs(shift_mm) >= a.specimen_mm)
    throw InputError("--shift-mm: the seam must cross the specimen");
  o.seam_shift = units::MmToM(shift_mm);
  o.perturbation = units::MmToM(finite(a.perturbation_mm, "--perturbation-mm"));
  if (!(a.perturbation_mm > 0.0 && a.perturbation_mm <= a.specimen_mm))
    throw InputError("--perturbation-mm: must be in (0, the specimen radius " + Num(a.specimen_mm) +
                     " mm]");
  // Reduced exactly to (-180, 180]: past about 1e16 degrees a product with π/180 has no
  // fraction of a turn left, and cos and sin of it say nothing.
  o.frame_angle = std::remainder(finite(a.frame_deg, "--frame-deg"), 360.0) * kDegree;
  if (!a.start_modes.empty()) {
    try {
      ParseStartModes(a.start_modes, &o);
    } catch (const InputError& e) {
      // The library's "start_modes: ..." named as the flag.
      throw InputError("--start-modes" + std::string(e.what()).substr(std::strlen("start_modes")));
    }
  }
  if (a.seeds < 1 || a.seeds > 1000) throw InputError("--seeds: must be in 1..1000");
  o.seeds = a.seeds;
  o.sensitivity = a.sensitivity.sensitivity;
  o.sensitivity_parameters = a.sensitivity.Parameters();
  o.monte_carlo_samples = a.sensitivity.monte_carlo;
  o.monte_carlo_seed = a.sensitivity.Seed();
  o.first_seed = a.first_seed;
  if (a.resolution_mm) {
    const double h = finite(*a.resolution_mm, "--resolution-mm");
    const double overhang = a.specimen_mm - a.support_mm;
    if (h < 0.5 || h > 0.25 * overhang)
      throw InputError("--resolution-mm: must be between 0.5 mm and a quarter of the overhang (" +
                       Num(0.25 * overhang) + " mm)");
    o.element_size = units::MmToM(h);
  }
  o.element_size = std::min(o.element_size, 0.25 * (o.specimen_radius - o.support_radius));
  // The support circle is meshed with 24 chords or more; far below an element they are not
  // meshable (the mesher merges points closer than 1e-3 of the element size).
  if (o.support_radius < 0.25 * o.element_size)
    throw InputError("--support-mm: must be at least a quarter of the element size (" +
                     Num(0.25 * units::MToMm(o.element_size)) + " mm; --resolution-mm " +
                     Num(units::MToMm(o.element_size)) + " mm)");
  if (o.seams == DrapeSeams::kShifted && std::abs(o.seam_shift) > MaxSeamShift(o) * (1.0 + 1e-12))
    throw InputError(
        "--shift-mm: the shifted seam must lie at least one element (" +
        Num(units::MToMm(o.element_size)) +
        " mm) inside the specimen's edge: |shift| <= " + Num(units::MToMm(MaxSeamShift(o))) +
        " mm" + (a.shift_mm ? std::string() : std::string(" (the default is 50 mm)")));
  if (a.rim_mm != "auto") {  // "auto" needs the material: Run
    char* end = nullptr;
    const double rim = std::strtod(a.rim_mm.c_str(), &end);
    if (a.rim_mm.empty() || *end != '\0' || !std::isfinite(rim))
      throw InputError("--rim-mm: '" + a.rim_mm + "' is not a length in mm or auto");
    if (rim != 0.0 && !(rim >= 0.5 && units::MmToM(rim) <= o.element_size)) {
      throw InputError("--rim-mm: must be 0 (off), auto or between 0.5 mm and the element size (" +
                       Num(units::MToMm(o.element_size)) + " mm)");
    }
    o.rim_element_size = units::MmToM(rim);
  }
  if (a.rim_band_mm && a.rim_mm != "auto" && o.rim_element_size == 0.0)
    throw InputError("--rim-band-mm: needs a finer rim (--rim-mm auto or a size, not 0)");
  // The default band, 20 mm, is a third of the default overhang; a smaller overhang gets a
  // third of itself (as the default --resolution-mm shrinks to a quarter of it).
  const double band = a.rim_band_mm ? finite(*a.rim_band_mm, "--rim-band-mm")
                                    : std::min(20.0, (a.specimen_mm - a.support_mm) / 3.0);
  if (!(band >= 0.0 && band <= a.specimen_mm - a.support_mm)) {
    throw InputError("--rim-band-mm: must be between 0 and the overhang (" +
                     Num(a.specimen_mm - a.support_mm) + " mm)");
  }
  o.rim_band = units::MmToM(band);
  if (a.contact_sink_mm) {
    if (o.mount != DrapeMount::kResting)
      throw InputError("--contact-sink-mm: the resting mount's contact only (--mount resting)");
    const double sink = finite(*a.contact_sink_mm, "--contact-sink-mm");
    if (!(sink >= 1e-6 && sink <= 0.03))
      throw InputError("--contact-sink-mm: must be between 1e-06 and 0.03 mm");
    o.contact_sink = units::MmToM(sink);
  }
  if (a.coarse && a.no_coarse)
    throw InputError("--coarse-to-fine and --no-coarse-to-fine: give one");
  o.coarse_to_fine = a.coarse;
  if (a.extrapolate && a.no_extrapolate)
    throw InputError("--extrapolate and --no-extrapolate: give one");
  if (a.extrapolate && a.rim_mm != "auto" && o.rim_element_size == 0.0)
    throw InputError("--extrapolate: needs a rim band (--rim-mm auto or a size, not 0)");
  if (a.tolerance) {
    if (!(*a.tolerance > 0.0) || *a.tolerance > 0.1)
      throw InputError("--tolerance: must be in (0, 0.1]");
    o.solver.tolerance = *a.tolerance;
  }
  if (!(std::isfinite(a.max_seconds) && a.max_seconds > 0.0))
    throw InputError("--max-seconds: must be a finite number > 0");
  o.solver.max_seconds = a.max_seconds;
  if (std::string why; !o.Check(&why)) throw InputError("drape: " + why);
  return o;
}

// The comparison's tolerances; each flag needs --compare.
DrapeCompareOptions CompareOptions(const DrapeArgs& a) {
  DrapeCompareOptions o;
  if (a.compare.empty()) {
    for (const auto& [given, flag] : {std::pair{a.dc_tol.has_value(), "--dc-tol"},
                                      std::pair{a.node_tol.has_value(), "--node-tol"},
                                      std::pair{a.outline_tol_mm.has_value(), "--outline-tol-mm"},
                                      std::pair{a.strict, "--strict"}})
      if (given) throw InputError(std::string(flag) + ": needs --compare MEASURED.json");
    return o;
  }
  if (a.dc_tol) {
    if (!(std::isfinite(*a.dc_tol) && *a.dc_tol > 0.0 && *a.dc_tol <= 1.0))
      throw InputError("--dc-tol: must be in (0, 1]");
    o.dc_tolerance = *a.dc_tol;
  }
  if (a.node_tol) {
    if (!(std::isfinite(*a.node_tol) && *a.node_tol >= 0.0 && *a.node_tol <= 100.0))
      throw InputError("--node-tol: must be between 0 and 100 nodes");
    o.node_tolerance = *a.node_tol;
  }
  if (a.outline_tol_mm) {
    if (!(std::isfinite(*a.outline_tol_mm) && *a.outline_tol_mm > 0.0 &&
          *a.outline_tol_mm <= 1000.0))
      throw InputError("--outline-tol-mm: must be in (0, 1000] mm");
    o.outline_tolerance = units::MmToM(*a.outline_tol_mm);
  }
  if (std::string why; !o.Check(&why)) throw InputError("--compare: " + why);
  return o;
}

// The measured drape of --compare (a MEASURED.json from drape-measure; at most 64 MB: an
// outline of 100 000 bins is 2 MB), refused unless it was taken on the simulation's radii.
std::optional<MeasuredDrape> ReadMeasured(const DrapeArgs& a, const DrapeOptions& o) {
  if (a.compare.empty()) return std::nullopt;
  MeasuredDrape m = ParseMeasuredDrapeJson(
      ReadInputFile(a.compare, "measured drape (MEASURED.json)", 64u << 20), a.compare);
  try {
    CheckDrapesComparable(m, o);
  } catch (const InputError& e) {
    throw InputError(a.compare + ": " + e.what());
  }
  return m;
}

std::string OutlinePath(const std::string& result) {
  std::filesystem::path p(result);
  if (p.extension() == ".json") p.replace_extension();
  return p.string() + ".outline.csv";
}

// The first seed's draped mesh as PLY, with each vertex's pattern position (to map a scan or a
// texture onto it) and, with seams, its pattern distance to the nearest seam line [m].
std::string DrapedPly(const DrapeResult& r, const DrapeSeedResult& s) {
  TriangleMesh draped = r.mesh;
  draped.vertices = s.positions;
  std::vector<VertexScalar> scalars = {{"rest_x", r.mesh.vertices.col(0)},
                                       {"rest_y", r.mesh.vertices.col(1)}};
  if (!r.seam_lines.empty()) {
    Eigen::VectorXd d(r.mesh.num_vertices());
    for (int v = 0; v < r.mesh.num_vertices(); ++v) {
      d(v) = std::numeric_limits<double>::infinity();
      for (const SeamLine& line : r.seam_lines)
        d(v) =
            std::min(d(v), DistanceToSeamLine(r.mesh.vertices.row(v).head<2>().transpose(), line));
    }
    scalars.push_back({"seam_distance", d});
  }
  return PlyText(draped, scalars);
}

nlohmann::json SummaryJson(const SolveSummary& s) {
  return {{"converged", s.converged},
          {"method", s.method},
          {"message", s.message},
          {"iterations", s.iterations},
          {"coarse_iterations", s.coarse_iterations},
          {"factorizations", s.factorizations},
          {"exact_hessian_steps", s.exact_steps},
          {"friction_slips", s.slips},
          {"residual", s.residual},
          {"energy_J", s.energy},
          {"seconds", s.seconds},
          {"coarse_seconds", s.coarse_seconds},
          {"contacts", s.contacts},
          {"anchors", s.anchors}};
}

nlohmann::json NumberOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

// The comparison block of the text output.
void PrintComparison(const DrapeComparison& c, const DrapeArgs& a, bool several_seeds) {
  const auto ok = [](bool b) { return b ? "ok" : "FAIL"; };
  // Outline RMS to 0.01 mm: an outline compared with itself is 1e-8 mm off (the CSV's digits).
  const auto mm = [](double metres) {
    return Num(std::round(units::MToMm(metres) * 100.0) / 100.0) + " mm";
  };
  std::cout << "compared with: " << a.compare << " (measured from " << c.measured_source << ")\n"
            << "  DC: measured " << Num(c.measured_dc, 3) << ", simulated "
            << Num(c.simulated_dc, 3)
            << (several_seeds ? " ± " + Num(c.simulated_dc_sd, 2) : std::string()) << ": "
            << Num(std::abs(c.dc_difference), 2) << " apart, tolerance " << Num(c.dc_tolerance, 3)
            << ": " << ok(c.dc_ok) << "\n"
            << "  nodes: measured " << c.measured_nodes << ", simulated "
            << Num(c.simulated_nodes, 3)
            << (several_seeds ? " ± " + Num(c.simulated_nodes_sd, 2) : std::string())
            << ", tolerance ± " << Num(c.node_tolerance, 3) << ": " << ok(c.nodes_ok) << "\n"
            << "  outline: ";
  if (several_seeds) {
    std::cout << Num(std::round(units::MToMm(c.outline_rms) * 100.0) / 100.0) << " ± "
              << mm(c.outline_rms_sd) << " RMS after each seed's best rotation ("
              << mm(c.outline_rms_unrotated) << " as measured;";
    for (const DrapeSeedComparison& s : c.per_seed)
      std::cout << (&s == &c.per_seed.front() ? " seed " : ", seed ") << s.seed << ": "
                << mm(s.outline.rms) << " turned " << Num(s.outline.rotation / kDegree, 4) << "°";
    std::cout << ")";
  } else {
    std::cout << mm(c.outline_rms) << " RMS after turning the measured one by "
              << Num(c.best_rotation / kDegree, 4) << "° (" << mm(c.outline_rms_unrotated)
              << " as measured)";
  }
  std::cout << ": "
            << (c.outline_judged ? "tolerance " + Num(units::MToMm(c.outline_tolerance), 3) +
                                       " mm: " + ok(c.outline_ok)
                                 : std::string("not judged (--outline-tol-mm)"))
            << "\n  verdict: " << c.Verdict() << "\n";
  for (const Note& n : c.notes) std::cout << "  note: " << n.text << "\n";
}

// Where the membrane's compression ratio came from: --what-if, --compression-ratio over the
// file, or the file.
std::string CompressionRatioFrom(const DrapeArgs& a) {
  if (a.what_if.find("stretch.compression_ratio=") != std::string::npos) return "--what-if";
  return a.compression_ratio ? "--compression-ratio" : "material";
}

// The scene as the options give it, in mm (the result's `scene` without the mesh's figures).
nlohmann::json SceneJson(const DrapeOptions& o) {
  nlohmann::json j = {
      {"specimen_radius_mm", units::MToMm(o.specimen_radius)},
      {"support_radius_mm", units::MToMm(o.support_radius)},
      {"mount", DrapeMountName(o.mount)},
      {"seams", DrapeSeamsName(o.seams)},
      {"perturbation_mm", units::MToMm(o.perturbation)},
      {"frame_deg", o.frame_angle / kDegree},
      {"start_modes", {o.min_harmonic, o.max_harmonic}},
      {"resolution_mm", units::MToMm(o.element_size)},
      {"rim_mm", units::MToMm(o.rim_element_size)},
      {"rim_band_mm",
       o.rim_element_size > 0.0 ? nlohmann::json(units::MToMm(o.rim_band)) : nlohmann::json()},
      {"seam_refine_mm", o.seams != DrapeSeams::kNone
                             ? nlohmann::json(units::MToMm(o.seam_refinement_range))
                             : nlohmann::json()},
      {"contact_sink_mm", o.mount == DrapeMount::kResting
                              ? nlohmann::json(units::MToMm(o.contact_sink))
                              : nlohmann::json()},
      {"coarse_to_fine", o.coarse_to_fine},
      {"extrapolate", o.rim_extrapolation},
      {"tolerance", o.solver.tolerance},
      {"raster_cell_mm", units::MToMm(o.raster_cell)}};
  if (o.seams != DrapeSeams::kNone) {
    j["seam_profile"] = SeamProfileToJson(o.seam_profile);
    if (o.seams == DrapeSeams::kShifted) j["shift_mm"] = units::MToMm(o.seam_shift);
  }
  return j;
}

nlohmann::json ResultJson(const DrapeResult& r, const DrapeOptions& o, const Material& m,
                          const DrapeArgs& a) {
  nlohmann::json j;
  j["converged"] = r.converged;
  j["message"] = r.message;
  // The notes' texts (a refused run prints its one error line only, no notes).
  j["note"] = r.notes.empty() ? nlohmann::json() : nlohmann::json(JoinNoteTexts(r.notes, "; "));
  j["drape_coefficient"] = NumberOrNull(r.drape_coefficient);
  j["drape_coefficient_sd"] = NumberOrNull(r.drape_coefficient_sd);
  j["nodes"] = NumberOrNull(r.nodes);
  j["nodes_sd"] = NumberOrNull(r.nodes_sd);
  j["min_radius_mm"] = NumberOrNull(units::MToMm(r.min_radius));
  j["max_radius_mm"] = NumberOrNull(units::MToMm(r.max_radius));
  j["mean_radius_mm"] = NumberOrNull(units::MToMm(r.mean_radius));
  j["min_radius_sd_mm"] = NumberOrNull(units::MToMm(r.min_radius_sd));
  j["max_radius_sd_mm"] = NumberOrNull(units::MToMm(r.max_radius_sd));
  j["mean_radius_sd_mm"] = NumberOrNull(units::MToMm(r.mean_radius_sd));
  j["seeds"] = nlohmann::json::array();
  for (const DrapeSeedResult& s : r.per_seed) {
    nlohmann::json js = {
        {"seed", s.seed}, {"converged", s.converged}, {"solver", SummaryJson(s.summary)}};
    if (o.rim_extrapolation && s.summary.converged)
      js["split_solver"] = SummaryJson(s.split_summary);
    if (s.converged) {
      js["drape_coefficient"] = s.drape_coefficient;
      if (o.rim_extrapolation) {
        js["base_drape_coefficient"] = s.base_drape_coefficient;
        js["split_drape_coefficient"] = s.split_drape_coefficient;
        js["extrapolation_bound"] = s.extrapolation_bound;
        js["extrapolation_reversed"] = s.extrapolation_reversed;
      }
      js["nodes"] = s.nodes.angles.size();
      js["shadow_area_mm2"] = s.shadow.area * 1e6;
      js["min_radius_mm"] = units::MToMm(s.min_radius);
      js["max_radius_mm"] = units::MToMm(s.max_radius);
      js["mean_radius_mm"] = units::MToMm(s.mean_radius);
      if (o.mount == DrapeMount::kResting)
        js["max_penetration_mm"] = units::MToMm(s.max_penetration);
      nlohmann::json nodes = nlohmann::json::array();
      for (size_t k = 0; k < s.nodes.angles.size(); ++k)
        nodes.push_back({{"angle_deg", s.nodes.angles[k] / kDegree},
                         {"radius_mm", units::MToMm(s.nodes.radii[k])},
                         {"prominence_mm", units::MToMm(s.nodes.prominences[k])}});
      js["node_list"] = nodes;
    }
    j["seeds"].push_back(js);
  }
  j["scene"] = SceneJson(o);
  nlohmann::json& scene = j["scene"];
  scene["rim_turn_down_mm"] = units::MToMm(r.rim_turn_down);
  scene["base_vertices"] = r.base_vertices;
  scene["vertices"] = r.mesh.num_vertices();
  scene["triangles"] = r.mesh.num_triangles();
  scene["coarse_vertices"] = r.coarse_vertices;
  scene["specimen_area_mm2"] = r.specimen_area * 1e6;
  scene["support_area_mm2"] = r.support_area * 1e6;
  scene["mass_g"] = r.mass * 1e3;
  if (!r.sensitivities.empty()) {  // --sensitivity, --monte-carlo or --cache
    j["drape_coefficient_sigma"] = NumberOrNull(r.drape_coefficient_sigma);
    j["drape_coefficient_sigma_note"] = r.sigma_note;
    j["sensitivity_seconds"] = r.sensitivity_seconds;
    j["scene_sensitivity_seconds"] = r.scene_sensitivity_seconds;
    const auto rows = [](const std::vector<ParameterInfluence>& influences) {
      nlohmann::json list = nlohmann::json::array();
      for (const ParameterInfluence& s : influences)
        list.push_back({{"parameter", s.parameter},
                        {"value", s.value},
                        {"unit", s.unit},
                        {"defaulted", s.defaulted},
                        {"d_dc_d_ln_p", s.d_q_d_ln_p},
                        {"uncertainty_ln", NumberOrNull(s.uncertainty_ln)},
                        {"uncertainty_source", s.uncertainty_source},
                        {"dc_change", s.change}});
      return list;
    };
    j["sensitivities"] = rows(r.sensitivities);
    // The scene's radii and the seam's coefficients (not in the σ), null when the run did not
    // take them.
    const auto rows_or_null = [&rows](const std::vector<ParameterInfluence>& influences) {
      return influences.empty() ? nlohmann::json() : rows(influences);
    };
    j["scene_sensitivities"] = rows_or_null(r.scene_sensitivities);
    j["seam_sensitivities"] = rows_or_null(r.seam_sensitivities);
  }
  if (r.monte_carlo) {
    j["monte_carlo"] = MonteCarloJson(*r.monte_carlo, 1.0, "-");
    j["monte_carlo"]["node_changes"] = r.monte_carlo_node_changes;
  }
  j["material"] = MaterialToJson(m);
  // Where the membrane's compression ratio came from: the file, or --compression-ratio over it.
  j["scene"]["compression_ratio"] = m.compression_ratio;
  j["scene"]["compression_ratio_from"] = CompressionRatioFrom(a);
  j["material"]["file"] = a.material;
  j["seconds"] = r.seconds;
  return j;
}

// The result as text on stdout (the JSON's figures, rounded for people).
void PrintText(const DrapeResult& r, const DrapeOptions& o, const Material& m, const DrapeArgs& a,
               const std::string& outline_path, const std::optional<DrapeComparison>& comparison) {
  const std::string note = JoinNoteTexts(r.notes, "; ");
  std::cout << "material: " << (m.name.empty() ? a.material : m.name) << "  [" << a.material << "]"
            << (m.compression_ratio < 1.0
                    ? "; membrane soft in compression (ratio " + Num(m.compression_ratio) + ")"
                    : std::string())
            << "\n"
            << "scene: specimen " << Num(a.specimen_mm) << " mm on a " << Num(a.support_mm)
            << " mm support, " << DrapeMountName(o.mount) << ", seams " << DrapeSeamsName(o.seams)
            << (o.seams != DrapeSeams::kNone ? " (" + SeamLabel(o.seam_profile) + ")" : "") << ", "
            << r.mesh.num_vertices() << " vertices (h = " << Num(units::MToMm(o.element_size))
            << " mm"
            << (o.rim_element_size > 0.0
                    ? ", " + Num(units::MToMm(o.rim_element_size), 3) + " mm to " +
                          Num(units::MToMm(o.rim_band)) + " mm past the rim"
                    : std::string())
            << (o.seams != DrapeSeams::kNone && o.seam_refinement_range > 0.0
                    ? ", refined within " + Num(units::MToMm(o.seam_refinement_range)) +
                          " mm of the seams"
                    : std::string())
            << (o.rim_extrapolation
                    ? "; " + std::to_string(r.base_vertices) + " before the rim's split"
                    : std::string())
            << ")\n";
  for (const DrapeSeedResult& s : r.per_seed) {
    std::cout << "  seed " << s.seed << ": DC " << Num(s.drape_coefficient, 4) << ", "
              << s.nodes.angles.size() << " nodes, r " << Num(units::MToMm(s.min_radius), 4) << ".."
              << Num(units::MToMm(s.max_radius), 4) << " mm, " << s.summary.iterations
              << " iterations, " << Num(s.summary.seconds, 3) << " s";
    if (o.rim_extrapolation)
      std::cout << "; DC ± " << Num(s.extrapolation_bound, 2) << ": between the split rim's "
                << Num(s.split_drape_coefficient, 4) << " (" << s.split_summary.iterations
                << " iterations, " << Num(s.split_summary.seconds, 3) << " s) and "
                << Num(2.0 * s.split_drape_coefficient - s.base_drape_coefficient, 4)
                << " (first order from the base's " << Num(s.base_drape_coefficient, 4) << ")";
    std::cout << "\n";
  }
  std::cout << "drape coefficient: " << Num(r.drape_coefficient, 4);
  if (r.per_seed.size() > 1) std::cout << " ± " << Num(r.drape_coefficient_sd, 3);
  std::cout << "\nnodes: " << Num(r.nodes, 4);
  if (r.per_seed.size() > 1) {
    std::cout << " ± " << Num(r.nodes_sd, 3);
    const auto radius = [](double mean, double sd) {  // sd to 0.01 mm: seeds may agree to round-off
      return Num(units::MToMm(mean), 4) + " ± " + Num(std::round(units::MToMm(sd) * 100.0) / 100.0);
    };
    std::cout << "\noutline radius [mm]: min " << radius(r.min_radius, r.min_radius_sd) << ", mean "
              << radius(r.mean_radius, r.mean_radius_sd) << ", max "
              << radius(r.max_radius, r.max_radius_sd);
  }
  if (!note.empty()) std::cout << "\nnote: " << note;
  std::cout << "\n";
  if (!r.sensitivities.empty())
    PrintInfluences("DC", "", 1.0, r.drape_coefficient_sigma, r.sigma_note, r.sensitivities);
  PrintInfluencesBesideSigma("scene", "", 1.0, r.scene_sensitivities);
  PrintInfluencesBesideSigma("seam", "", 1.0, r.seam_sensitivities);
  if (r.monte_carlo) PrintMonteCarlo("DC", "", 1.0, *r.monte_carlo);
  if (comparison) PrintComparison(*comparison, a, r.per_seed.size() > 1);
  std::cout << "time: " << Num(r.seconds, 3) << " s\nresult: " << a.out
            << "\noutline: " << outline_path << "\n";
  if (!a.png.empty()) std::cout << "shadow: " << a.png << "\n";
  if (!a.obj.empty()) std::cout << "mesh: " << a.obj << "\n";
  if (!a.ply.empty()) std::cout << "mesh (PLY): " << a.ply << "\n";
}

// Where a what-if's scene comes from (docs/guide/drape.md, "What-if").
constexpr const char* kSceneFrom =
    "the --material file: --rim-mm auto sizes the rim before the edits, so a drape of the "
    "edited file alone may mesh its rim otherwise";

// --what-if answered from the cache: the result file holds the prediction, the edited material
// and the scene; no outline, picture or mesh (there is no drape).
void WritePrediction(const DrapeWhatIfPrediction& p, const DrapeOptions& o, const DrapeArgs& a) {
  nlohmann::json j = {{"what_if", DrapeWhatIfJson(p.what_if)},
                      {"drape_coefficient", p.what_if.drape_coefficient},
                      {"drape_coefficient_error_estimate", p.what_if.error_estimate},
                      {"scene", SceneJson(o)},
                      {"material", MaterialToJson(p.material)},
                      {"seconds", p.seconds}};
  j["what_if"]["edits"] = a.what_if;
  j["what_if"]["cache"] = a.cache;
  j["what_if"]["scene_from"] = kSceneFrom;
  j["scene"]["compression_ratio"] = p.material.compression_ratio;
  j["scene"]["compression_ratio_from"] = CompressionRatioFrom(a);
  j["note"] = p.what_if.notes.empty() ? nlohmann::json()
                                      : nlohmann::json(JoinNoteTexts(p.what_if.notes, "; "));
  j["material"]["file"] = a.material;
  AtomicFileSet outputs;
  outputs.Add(a.out).Write(j.dump(2) + "\n");
  outputs.Commit();
  if (a.json) {
    j["output"] = a.out;
    PrintJson(j);
    return;
  }
  std::cout << "what-if " << a.what_if << ": DC " << Num(p.what_if.drape_coefficient, 4)
            << ", estimated error " << Num(p.what_if.error_estimate, 2) << " ("
            << p.what_if.reason << "; a rule of thumb that does not foresee a change of the "
            << "node count) in " << Num(1e3 * p.seconds, 3) << " ms\n";
  for (const Note& n : p.what_if.notes) std::cout << "note: " << n.text << "\n";
  std::cout << "result: " << a.out << "\n";
}

// The what-if flags' own checks, with the flags' names: --what-if needs --cache and answers
// with a DC only; its options need it; --cache needs every parameter's sensitivity, and no
// output inside the cache folder.
void CheckWhatIfArgs(const DrapeArgs& a) {
  if (a.what_if.empty()) {
    if (a.what_if_reach_percent) throw InputError("--what-if-reach-pct: needs --what-if");
    if (a.what_if_max_error) throw InputError("--what-if-max-error: needs --what-if");
  } else {
    if (a.cache.empty())
      throw InputError("--what-if: needs --cache DIR (the solved drapes it predicts from)");
    for (const auto& [flag, value] : {std::pair{"--png", a.png}, {"--obj", a.obj}, {"--ply", a.ply},
                                      {"--compare", a.compare}})
      if (!value.empty())
        throw InputError(std::string("--what-if: predicts the DC only; ") + flag +
                         " needs a drape (run without --what-if)");
    if (a.sensitivity.sensitivity || a.sensitivity.monte_carlo > 0)
      throw InputError("--what-if: predicts the DC only; --sensitivity and --monte-carlo need a "
                       "drape (run without --what-if)");
    if (const double r = a.what_if_reach_percent.value_or(10.0); !(r > 0.0 && r <= 100.0))
      throw InputError("--what-if-reach-pct: must be in (0, 100], got " + Num(r));
    if (const double e = a.what_if_max_error.value_or(0.01); !(e > 0.0 && e < 1.0))
      throw InputError("--what-if-max-error: must be in (0, 1), got " + Num(e));
  }
  if (!a.cache.empty() && !a.sensitivity.params.empty())  // before --sensitivity-params' own
    throw InputError("--cache: a cached drape needs every parameter's sensitivity (leave out "
                     "--sensitivity-params)");
  if (!a.cache.empty()) {
    const std::filesystem::path cache = std::filesystem::weakly_canonical(a.cache);
    for (const std::string& out : {a.out, a.png, a.obj, a.ply})
      if (!out.empty() && std::filesystem::weakly_canonical(out).parent_path() == cache)
        throw InputError("--cache: " + out + " lies in the cache folder; write results elsewhere");
  }
}

void Run(const DrapeArgs& a) {
  CheckWhatIfArgs(a);
  DrapeOptions o = Options(a);
  if (a.compression_ratio &&
      !(*a.compression_ratio >= kMinCompressionRatio && *a.compression_ratio <= 1.0))
    throw InputError("--compression-ratio: must be between " + Num(kMinCompressionRatio) +
                     " and 1 (1: as stiff in compression as in tension)");
  // Check the outputs before reading or computing (an output must not be an input): distinct files
  // in usable folders. They appear together at the end, or none of them.
  const std::string outline_path = OutlinePath(a.out);
  CheckDistinctOutputs(
      {{"-o", a.out},
       {"the outline (next to -o)", outline_path},
       {"--png", a.png},
       {"--obj", a.obj},
       {"--ply", a.ply}},
      {{"--material", a.material}, {"--seam-file", a.seam_file}, {"--compare", a.compare}});
  const DrapeCompareOptions compare_options = CompareOptions(a);
  Material m = ReadMaterial(a.material);
  const std::optional<MeasuredDrape> measured = ReadMeasured(a, o);
  if (a.compression_ratio) {  // given, no longer the documented default
    m.compression_ratio = *a.compression_ratio;
    std::erase(m.defaulted, std::string("stretch.compression_ratio"));
  }
  ChooseDrapeRim(m, a.rim_mm == "auto",
                 a.extrapolate      ? DrapeExtrapolation::kOn
                 : a.no_extrapolate ? DrapeExtrapolation::kOff
                                    : DrapeExtrapolation::kDefault,
                 &o);
  if (std::string why; !o.Check(&why)) throw InputError("drape: " + why);
  // --what-if: the scene is the file material's (its rim), the material the edited one.
  std::optional<DrapeWhatIf> what_if;
  if (!a.what_if.empty()) {
    // The edits' and the cache's errors name their flag (no material-file prefix).
    DrapeWhatIfPrediction p = PredictDrapeWhatIf(
        m, a.what_if, o, a.cache,
        {a.what_if_reach_percent.value_or(10.0) / 100.0, a.what_if_max_error.value_or(0.01)});
    if (p.what_if.predicted) return WritePrediction(p, o, a);
    Progress("drape: what-if: solving, " + p.what_if.reason, a.progress);
    m = std::move(p.material);
    what_if = std::move(p.what_if);
  }
  AtomicFileSet outputs;
  AtomicFile& result_file = outputs.Add(a.out);
  AtomicFile& outline_file = outputs.Add(outline_path);
  AtomicFile* png_file = a.png.empty() ? nullptr : &outputs.Add(a.png);
  if (png_file) CheckOutputExtension("--png", a.png, {".png"});
  AtomicFile* obj_file = a.obj.empty() ? nullptr : &outputs.Add(a.obj);
  AtomicFile* ply_file = a.ply.empty() ? nullptr : &outputs.Add(a.ply);

  // Progress lines (the mesh, each seed's solves) only on a terminal or with --progress: a
  // failed run's stderr holds its one error line (docs/spec/cli.md).
  o.progress = [progress = a.progress](const std::string& line) {
    Progress("drape: " + line, progress);
  };
  DrapeResult r;
  try {
    r = a.cache.empty() ? SimulateDrape(m, o) : SimulateDrapeCached(m, o, a.cache);
  } catch (const InputError& e) {  // a flag's own error names the flag, not the material file
    const std::string what = e.what();
    throw InputError(what.rfind("--", 0) == 0 ? what : a.material + ": " + what);
  }
  if (!r.converged)
    throw ComputeError("drape: not converged (" + r.message + "); no drape coefficient");

  std::optional<DrapeComparison> comparison;
  if (measured) {
    comparison = CompareDrapes(r, *measured, compare_options);
    if (a.strict && !comparison->pass)
      throw ComputeError("drape: the comparison with " + a.compare +
                         " failed (--strict): " + comparison->FailureReason());
  }

  const DrapeSeedResult& first = r.per_seed.front();
  nlohmann::json j = ResultJson(r, o, m, a);
  if (comparison) {
    j["comparison"] = DrapeComparisonJson(*comparison);
    j["comparison"]["measured_file"] = a.compare;
  }
  if (what_if) {
    j["what_if"] = DrapeWhatIfJson(*what_if);
    j["what_if"]["edits"] = a.what_if;
    j["what_if"]["scene_from"] = kSceneFrom;
  }
  if (!a.cache.empty()) j["cache"] = a.cache;
  j["outline_csv"] = outline_file.path();
  outline_file.Write(OutlineCsv(first.shadow));  // drape_measure.h: the shared columns
  if (png_file) {
    if (!(comparison ? WriteDrapeComparisonPng(r, *comparison, o, png_file->temp_path())
                     : WriteDrapeShadowPng(r, first, o, png_file->temp_path())))
      throw InputError("--png: cannot write " + a.png);
    j["png"] = a.png;
  }
  if (obj_file) {
    TriangleMesh draped = r.mesh;
    draped.vertices = first.positions;
    obj_file->Write(ObjText(draped));
    j["obj"] = a.obj;
  }
  if (ply_file) {
    ply_file->Write(DrapedPly(r, first));
    j["ply"] = a.ply;
  }
  result_file.Write(j.dump(2) + "\n");
  outputs.Commit();

  if (a.json) {
    j["output"] = a.out;
    PrintJson(j);
    return;
  }
  PrintText(r, o, m, a, outline_file.path(), comparison);
  if (what_if) std::cout << "what-if " << a.what_if << ": solved, " << what_if->reason << "\n";
  if (!a.cache.empty()) std::cout << "cached in: " << a.cache << "\n";
}

}  // namespace

void RegisterDrape(CLI::App& app) {
  auto a = std::make_shared<DrapeArgs>();
  CLI::App* sub = AddSubcommand(
      app, "drape",
      "Virtual drapemeter (Cusick test, Pabst 5.2): drape coefficient and nodes of a fabric disk, "
      "with or without seams",
      "textile drape --material samples/materials/pabst-fig8.json --seams weft --seam-type C-plain "
      "--seeds 3 -o drape.json --png drape.png");
  sub->add_option("-m,--material", a->material, "Material JSON file (docs/spec/cli.md format)")
      ->required();
  sub->add_option("--seams", a->seams, "none (default), weft, weft+warp or shifted");
  sub->add_option("--seam-type", a->seam_type,
                  "Table 2 seam type A-plain .. C-twill (default C-plain)");
  sub->add_option("--seam-file", a->seam_file,
                  "Seam JSON file (from fit-seam) instead of --seam-type");
  sub->add_option("--seam-rib", a->seam_rib,
                  "Lengthwise stiffness of the seam band as a factor on S (>= 1; default the "
                  "seam file's rib_factor, 1 for the presets: the paper's model; docs/methods/seams.md)");
  sub->add_option(
      "--mount", a->mount,
      "clamped (default: held between two disks) or resting (lies on the disk, "
      "held by Coulomb friction, the material's friction; one solve unless --extrapolate)");
  sub->add_option("--seeds", a->seeds, "Number of perturbations (repeated tests; default 1)");
  sub->add_option("--first-seed", a->first_seed, "First seed (default 1)");
  sub->add_option("--resolution-mm", a->resolution_mm,
                  "Element size away from seams [mm] (default 12)");
  sub->add_option(
      "--rim-mm", a->rim_mm,
      "Element size along the support's rim [mm]; auto (the default): half the fabric's "
      "turn-down length when extrapolating, else a third; 0: no finer rim and no "
      "extrapolation (10x faster; clamped: DC about 0.1 low; docs/methods/drapemeter.md)");
  sub->add_option("--rim-band-mm", a->rim_band_mm,
                  "Width of that finer band beyond the rim [mm] (default 20, or a third of an "
                  "overhang under 60 mm)");
  sub->add_option("--contact-sink-mm", a->contact_sink_mm,
                  "Resting mount: the contact's stiffness, as how far a node sinks into the "
                  "support under its own weight [mm] (1e-6 to 0.03, default 0.01; 0.001 sinks "
                  "the skirt a quarter as deep, takes twice the time and may not settle; "
                  "docs/methods/drapemeter.md, \"Contact stiffness\")");
  sub->add_option("--compression-ratio", a->compression_ratio,
                  "The membrane's stiffness against compression as a fraction of its stretch "
                  "stiffness (0.001 to 1; default the material's stretch.compression_ratio, or "
                  "0.01 when it gives none; 1: as stiff as in tension, the DC rises with it; "
                  "docs/methods/drapemeter.md, \"Compression\")");
  sub->add_option("--specimen-mm", a->specimen_mm, "Specimen radius [mm] (default 150)");
  sub->add_option("--support-mm", a->support_mm, "Support radius [mm] (default 90)");
  sub->add_option(
      "--seam-refine-mm", a->seam_refine_mm,
      "Refine the mesh within this distance of the seam lines [mm]: element area / ceil(S(d)) "
      "(Pabst 4.3; default 0: off; docs/methods/drapemeter.md, \"Seam refinement\")");
  sub->add_option("--shift-mm", a->shift_mm,
                  "Offset of the shifted seam from the centre [mm] (default 50)");
  sub->add_option("--perturbation-mm", a->perturbation_mm,
                  "Start perturbation at the rim [mm] (default 2)");
  sub->add_option("--start-modes", a->start_modes,
                  "The start perturbation's angular harmonics MIN-MAX (default 3-8); a wider band "
                  "lets the fabric, not the start, choose the node count "
                  "(docs/methods/drapemeter.md, \"Nodes\")");
  sub->add_option("--frame-deg", a->frame_deg,
                  "Rotate seams and perturbation about the centre [deg]");
  sub->add_option("--tolerance", a->tolerance,
                  "Solver tolerance on the residual / weight (default 1e-4)");
  sub->add_option("--max-seconds", a->max_seconds,
                  "Solver wall-time cap per level and seed [s] (default 600)");
  sub->add_flag("--coarse-to-fine", a->coarse, "Solve on a mesh twice as coarse first (cascadic)");
  sub->add_flag("--no-coarse-to-fine", a->no_coarse, "Solve on the fine mesh only (the default)");
  sub->add_flag(
      "--extrapolate", a->extrapolate,
      "Split the rim band's triangles, solve again from the drape and report the middle of "
      "the bracket the two DCs give for a zero rim element (the default where it applies: "
      "clamped, with a rim band)");
  sub->add_flag("--no-extrapolate", a->no_extrapolate, "One solve on the rim band as meshed");
  sub->add_option("-o,--output", a->out, "Result JSON file; the outline CSV goes next to it")
      ->required();
  sub->add_option("--png", a->png, "Top-view shadow picture (PNG)");
  sub->add_option("--obj", a->obj, "Draped mesh of the first seed (OBJ)");
  sub->add_option(
      "--ply", a->ply,
      "Draped mesh of the first seed (ASCII PLY, metres) with each vertex's pattern position "
      "rest_x, rest_y and, with seams, its distance to the nearest seam line seam_distance [m]");
  sub->add_flag(
      "--progress", a->progress,
      "Print the progress lines (the mesh, each seed's solves) on stderr even when it is not a "
      "terminal");
  sub->add_option(
      "--compare", a->compare,
      "A measured drape (MEASURED.json from drape-measure) to compare with: DC, nodes, outline "
      "RMS after the best rotation, a verdict; the --png overlays its outline (same specimen "
      "and support radii only)");
  sub->add_option("--dc-tol", a->dc_tol,
                  "--compare: the largest |DC simulated - DC measured| that agrees (default 0.03)");
  sub->add_option("--node-tol", a->node_tol,
                  "--compare: the largest difference of the mean simulated node count from the "
                  "measured one (default 1)");
  sub->add_option("--outline-tol-mm", a->outline_tol_mm,
                  "--compare: judge the outline too: the largest mean radius RMS after the best "
                  "rotation [mm] (default: reported, not judged)");
  sub->add_flag("--strict", a->strict,
                "--compare: a failed verdict is an error (exit 3, nothing written)");
  AddSensitivityFlags(sub, &a->sensitivity, "the DC", "clamped mount only",
                      "b1,b2,c1,beta,areal_density_gsm,stretch.warp,...");
  sub->add_option("--cache", a->cache,
                  "Keep this drape, with every parameter's sensitivity, in this folder for "
                  "--what-if (created if missing; implies --sensitivity)");
  sub->add_option("--what-if", a->what_if,
                  "Predict the DC of the material with these edits, NAME=VALUE,... in the "
                  "material file's names and units (b1=0.11,stretch.warp=3300), from the drapes "
                  "in --cache; solves (and caches) when none is near enough");
  sub->add_option("--what-if-reach-pct", a->what_if_reach_percent,
                  "--what-if: a cached drape answers within this change of every parameter [%] "
                  "(default 10)");
  sub->add_option("--what-if-max-error", a->what_if_max_error,
                  "--what-if: solve instead when the prediction's error estimate is above this "
                  "(default 0.01 DC)");
  sub->add_flag("--json", a->json, "Print one JSON object instead of text");
  sub->callback([a] { Run(*a); });
}

namespace {
const bool kRegistered = AddCommand(60, RegisterDrape);
}  // namespace

}  // namespace textile::cli
