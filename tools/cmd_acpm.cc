// textile acpm: the virtual ACPM200 bending tester (Pabst et al. sections 4.1, 5.1): per-ray
// crossing lengths, bending lengths, rigidities and seam factors, a result JSON (docs/spec/cli.md)
// and a picture of the front across the width and the side profile at the crossing.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <numbers>
#include <optional>

#include "common/atomic_file.h"
#include "common/chart_file.h"
#include "common/cli.h"
#include "textile/sim/scenes/acpm.h"
#include "textile/sim/core/error.h"
#include "textile/sim/law/material.h"
#include "textile/sim/io/mesh_io.h"
#include "textile/sim/law/seam.h"
#include "textile/sim/core/units.h"

namespace textile::cli {
namespace {

struct AcpmArgs {
  std::string material, seam, seam_dir, model = "auto", out, png, obj;
  std::optional<double> seam_at_mm;
  std::optional<double> margin_mm;  // default 5 mm; more than one ray only
  double width_mm = 200, length_mm = 300, barrier_deg = 41.5;
  double speed_cm_per_min = 12, crossing_tol_mm = 0.05;
  int rays = 17;
  bool json = false;
  SensitivityArgs sensitivity;
};

constexpr double kDegree = std::numbers::pi / 180.0;

SeamProfile LoadSeam(const std::string& what) {
  for (const std::string& name : SeamPresetNames())
    if (name == what) return SeamPreset(name);
  return ReadSeamProfile(what);
}

AcpmOptions Options(const AcpmArgs& a) {
  AcpmOptions o;
  o.width = units::MmToM(a.width_mm);
  o.length = units::MmToM(a.length_mm);
  o.num_rays = a.rays;
  // One ray sits at the centre: a margin would be ignored.
  if (a.margin_mm && a.rays == 1)
    throw InputError(
        "--margin-mm: one ray (--rays 1) sits at the centre; the margin would be ignored");
  o.ray_margin = units::MmToM(a.margin_mm.value_or(5.0));
  o.barrier_angle = a.barrier_deg * kDegree;
  o.push_speed = a.speed_cm_per_min / 100.0 / 60.0;
  o.crossing_tolerance = units::MmToM(a.crossing_tol_mm);
  o.model = ParseAcpmModel(a.model);
  if (a.seam.empty()) {
    if (a.seam_at_mm) throw InputError("--seam-at: needs --seam (a Table 2 type or a seam file)");
    if (!a.seam_dir.empty())
      throw InputError("--seam-dir: needs --seam (a Table 2 type or a seam file)");
  } else {
    o.seam.direction = ParseAcpmSeamDirection(a.seam_dir.empty() ? "along" : a.seam_dir);
    o.seam.profile = LoadSeam(a.seam);
    if (a.seam_at_mm) {
      // NaN is the library's "not given" (the middle of the width, along): a NaN typed here
      // would silently become that.
      if (!std::isfinite(*a.seam_at_mm))
        throw InputError("--seam-at: must be a finite number [mm], got " + Num(*a.seam_at_mm));
      o.seam.position = units::MmToM(*a.seam_at_mm);
    }
  }
  o.sensitivity = a.sensitivity.sensitivity;
  o.sensitivity_parameters = a.sensitivity.Parameters();
  o.monte_carlo_samples = a.sensitivity.monte_carlo;
  o.monte_carlo_seed = a.sensitivity.Seed();
  if (std::string why; !o.Check(&why)) throw InputError("acpm: " + why);
  // RunAcpm refuses this too; here it is the flags' fault, not the material's.
  if (o.model == AcpmModelKind::kElastica && o.seam.direction == AcpmSeamDirection::kAlong)
    throw InputError(
        "--model elastica: a seam along the push direction varies across the width; "
        "the 1D elastica cannot represent it (use --model shell or auto)");
  return o;
}

void Plot(const AcpmResult& r, const AcpmOptions& o, const Material& m, AtomicFile& out) {
  namespace chart = textile::chart;
  chart::Panel front{
      .title = "Front across the width (crossing overhang per ray)",
      .x_label = "z across the width [mm]",
      .y_label = "overhang L at the " + Num(o.barrier_angle / kDegree) + "° barrier [mm]"};
  chart::Series rays{.label = "rays", .style = chart::Series::Style::kLineAndMarkers};
  double lo = 1e300, hi = -1e300;
  for (const auto& ray : r.rays) {
    rays.x.push_back(units::MToMm(ray.z));
    rays.y.push_back(units::MToMm(ray.overhang));
    lo = std::min(lo, units::MToMm(ray.overhang));
    hi = std::max(hi, units::MToMm(ray.overhang));
  }
  const double plain = units::MToMm(r.plain_overhang);
  front.series.push_back(rays);
  front.series.push_back(
      {.label = "no seam", .x = {0.0, units::MToMm(o.width)}, .y = {plain, plain}, .dashed = true});
  lo = std::min(lo, plain);
  hi = std::max(hi, plain);
  const double pad = std::max(0.1 * (hi - lo), 0.05 * hi);
  front.x_range = chart::Range{0.0, units::MToMm(o.width)};
  front.y_range = chart::Range{std::max(0.0, lo - pad), hi + pad};
  if (o.seam.direction == AcpmSeamDirection::kAlong) {
    const double zs = units::MToMm(r.rays.empty() ? 0.0 : o.seam.position);
    front.series.push_back({.label = "seam line",
                            .x = {zs, zs},
                            .y = {std::max(0.0, lo - pad), hi + pad},
                            .color = chart::Rgb{0.4, 0.4, 0.4},
                            .dashed = true});
  }
  double flo = 1e300, fhi = -1e300;
  for (const auto& ray : r.rays) {
    flo = std::min(flo, ray.factor);
    fhi = std::max(fhi, ray.factor);
  }
  front.notes = {"model: " + AcpmModelName(r.model),
                 "factor G/G_plain: " + Num(flo, 4) + (fhi > flo ? " .. " + Num(fhi, 4) : ""),
                 "device time " + Num(r.device_time, 4) + " s"};

  chart::Panel side{
      .title = "Side profile at the crossing (ray " + std::to_string(r.profile_ray + 1) + ")",
      .x_label = "x [mm]",
      .y_label = "y [mm]",
      .equal_aspect = true};
  chart::Series strip{.label = "sample"};
  for (size_t i = 0; i < r.profile_x.size(); ++i) {
    strip.x.push_back(units::MToMm(r.profile_x[i]));
    strip.y.push_back(units::MToMm(r.profile_y[i]));
  }
  const double reach = 1.15 * units::MToMm(r.rays.empty() ? 0.0 : r.rays[r.profile_ray].overhang);
  side.series.push_back(strip);
  side.series.push_back({.label = Num(o.barrier_angle / kDegree) + "° barrier",
                         .x = {0.0, reach * std::cos(o.barrier_angle)},
                         .y = {0.0, -reach * std::sin(o.barrier_angle)},
                         .color = chart::Rgb{0.8, 0.1, 0.1},
                         .dashed = true});
  side.series.push_back({.label = "platform",
                         .x = {-0.4 * reach, 0.0},
                         .y = {0.0, 0.0},
                         .color = chart::Rgb{0.3, 0.3, 0.3},
                         .line_width = 4.0});
  if (o.seam.direction == AcpmSeamDirection::kAcross && !r.profile_x.empty()) {
    // The seam sits at arc length s = L - D from the edge (samples are uniform in s).
    const double overhang = r.rays[r.profile_ray].overhang;
    const double s = overhang - o.seam.position;
    if (s >= 0.0) {
      const double f = s / overhang * (r.profile_x.size() - 1.0);
      const size_t i = std::min(static_cast<size_t>(f), r.profile_x.size() - 2);
      const double t = f - i;
      side.series.push_back({.label = "seam line",
                             .x = {units::MToMm((1 - t) * r.profile_x[i] + t * r.profile_x[i + 1])},
                             .y = {units::MToMm((1 - t) * r.profile_y[i] + t * r.profile_y[i + 1])},
                             .style = chart::Series::Style::kMarkers});
    } else {
      side.notes.push_back("seam on the platform, " + Num(units::MToMm(-s), 4) +
                           " mm behind the edge");
    }
  }
  side.notes.push_back(
      "L = " + Num(units::MToMm(r.rays.empty() ? 0.0 : r.rays[r.profile_ray].overhang), 6) + " mm");
  chart::WritePng(
      {.title =
           "Virtual ACPM200: " + (m.name.empty() ? std::string("material") : m.name) +
           (o.seam.direction == AcpmSeamDirection::kNone
                ? std::string(", plain sample")
                : ", " + o.seam.profile.type + " seam " + AcpmSeamDirectionName(o.seam.direction)),
       .width_px = 1400,
       .height_px = 600,
       .columns = 2,
       .panels = {front, side}},
      out);
}

void Run(const AcpmArgs& a) {
  const AcpmOptions o = Options(a);
  // Check the outputs' names and folders before reading or computing (an output must not be an
  // input); they appear together at the end.
  CheckDistinctOutputs({{"-o", a.out}, {"--png", a.png}, {"--obj", a.obj}},
                       {{"--material", a.material}, {"--seam", a.seam}});
  const Material m = ReadMaterial(a.material);
  if (!a.png.empty()) chart::CheckPngPath(a.png);
  AtomicFileSet outputs;
  AtomicFile& result_file = outputs.Add(a.out);
  AtomicFile* png_file = a.png.empty() ? nullptr : &outputs.Add(a.png);
  AtomicFile* obj_file = a.obj.empty() ? nullptr : &outputs.Add(a.obj);

  const auto start = std::chrono::steady_clock::now();
  AcpmResult r;
  try {
    r = RunAcpm(m, o);
  } catch (const InputError& e) {
    throw InputError(a.material + ": " + e.what());
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

  nlohmann::json j = AcpmResultToJson(r, m, o);
  j["material"]["file"] = a.material;
  j["compute_ms"] = ms;
  result_file.Write(j.dump(2) + "\n");
  if (png_file) Plot(r, o, m, *png_file);
  if (obj_file) obj_file->Write(ObjText(r.shape));
  outputs.Commit();

  if (a.json) {
    j["output"] = a.out;
    if (!a.png.empty()) j["png"] = a.png;
    if (!a.obj.empty()) j["obj"] = a.obj;
    PrintJson(j);
    return;
  }
  std::cout << "material: " << (m.name.empty() ? a.material : m.name) << "  [" << a.material
            << "], " << Num(units::SiToGsm(m.areal_density)) << " g/m²\n"
            << "sample: " << Num(a.width_mm) << " x " << Num(a.length_mm) << " mm, " << o.num_rays
            << " rays, barrier " << Num(a.barrier_deg) << "°, push " << Num(a.speed_cm_per_min)
            << " cm/min\n";
  if (o.seam.direction == AcpmSeamDirection::kNone) {
    std::cout << "seam: none\n";
  } else {
    const double at = o.seam.direction == AcpmSeamDirection::kAlong && std::isnan(o.seam.position)
                          ? o.width / 2.0
                          : o.seam.position;
    std::cout << "seam: " << o.seam.profile.type << " (" << o.seam.profile.layers << " layers) "
              << AcpmSeamDirectionName(o.seam.direction) << " the push direction, "
              << (o.seam.direction == AcpmSeamDirection::kAlong ? "at z = " : "")
              << Num(units::MToMm(at)) << " mm"
              << (o.seam.direction == AcpmSeamDirection::kAcross ? " behind the front" : "")
              << "\n";
  }
  std::cout << "model: " << AcpmModelName(r.model) << " (" << r.model_reason << ")\n";
  // (µ and · are two bytes each in UTF-8: the header is spelled out, not padded by printf.)
  std::cout << "  ray   z [mm]   d [mm]     L [mm]    c [mm]   G [µN·m]   factor   t [s]\n";
  for (size_t i = 0; i < r.rays.size(); ++i) {
    const AcpmRay& ray = r.rays[i];
    std::printf("  %3zu %8.2f %8s %10.4f %9.4f %10.5g %8.4f %7.2f\n", i + 1, units::MToMm(ray.z),
                std::isnan(ray.d) ? "-" : Num(units::MToMm(ray.d), 5).c_str(),
                units::MToMm(ray.overhang), units::MToMm(ray.bending_length),
                units::SiRigidityToMicroNm(ray.rigidity), ray.factor, ray.device_time);
  }
  std::cout << "without seams: L = " << Num(units::MToMm(r.plain_overhang))
            << " mm, c = " << Num(units::MToMm(r.plain_bending_length))
            << " mm, G = " << Num(units::SiRigidityToMicroNm(r.plain_rigidity))
            << " µN·m = " << Num(units::SiRigidityToMgCm(r.plain_rigidity))
            << " mg·cm = " << Num(units::SiRigidityToGfCm(r.plain_rigidity)) << " gf·cm\n"
            << "device time " << Num(r.device_time, 4) << " s; computed in " << Num(ms, 3)
            << " ms (" << r.solves << " solves)\n";
  for (const Note& n : r.membrane_defaults) std::cout << "note: " << n.text << "\n";
  if (!r.notes.empty()) std::cout << "note: " << r.notes << "\n";
  if (o.sensitivity || o.monte_carlo_samples > 0)
    PrintInfluences("L", "mm", 1e3, r.crossing_length_sigma, r.sigma_note, r.sensitivities);
  PrintInfluencesBesideSigma("scene", "mm", 1e3, r.scene_sensitivities);
  PrintInfluencesBesideSigma("seam", "mm", 1e3, r.seam_sensitivities);
  if (r.monte_carlo) PrintMonteCarlo("L", "mm", 1e3, *r.monte_carlo);
  std::cout << "wrote " << a.out << (a.png.empty() ? "" : ", " + a.png)
            << (a.obj.empty() ? "" : ", " + a.obj) << "\n";
}

}  // namespace

void RegisterAcpm(CLI::App& app) {
  auto a = std::make_shared<AcpmArgs>();
  CLI::App* sub = AddSubcommand(
      app, "acpm",
      "Virtual ACPM200: push a sample over the 41.5° light barrier, 17 rays across the width; "
      "per-ray L, c, G and seam factor",
      "textile acpm --material samples/materials/pabst-fig8.json -o acpm.json --png front.png\n"
      "  textile acpm --material samples/materials/pabst-fig8.json --seam C-plain --seam-dir "
      "across "
      "--seam-at 20 -o acpm.json");
  sub->add_option("-m,--material", a->material, "Material JSON file (docs/spec/cli.md format)")
      ->required();
  sub->add_option("--seam", a->seam,
                  "Seam: a Table 2 type (A-plain .. C-twill) or a seam JSON file");
  sub->add_option("--seam-at", a->seam_at_mm,
                  "along: width position of the seam from the left edge [mm] (default centre); "
                  "across: its distance behind the sample's front [mm] (required)");
  sub->add_option("--seam-dir", a->seam_dir,
                  "Seam direction relative to the push: along (default) or across")
      ->check(CLI::IsMember({"along", "across"}));
  sub->add_option("--model", a->model,
                  "auto (default: the elastica when it is exact), elastica or shell")
      ->check(CLI::IsMember({"auto", "elastica", "shell"}));
  sub->add_option("-o,--out", a->out, "Result JSON to write (docs/spec/cli.md's ACPM result)")
      ->required();
  sub->add_option("--png", a->png,
                  "Write the front across the width and the side profile to a PNG");
  sub->add_option("--obj", a->obj,
                  "Write the sample at the middle ray's crossing as an OBJ mesh [m] (the shell's "
                  "mesh, or the elastica's profile swept across the width)");
  sub->add_option("--width-mm", a->width_mm, "Sample width [mm], at most 200 (default 200)");
  sub->add_option("--length-mm", a->length_mm,
                  "Sample length, the longest overhang [mm] (default 300)");
  sub->add_option("--rays", a->rays, "Number of rays across the width (default 17)");
  sub->add_option("--margin-mm", a->margin_mm,
                  "Distance of the outer rays from the edges [mm] (default 5)");
  sub->add_option("--barrier-deg", a->barrier_deg,
                  "Barrier angle below the horizontal [deg] (default 41.5)");
  sub->add_option("--speed-cm-per-min", a->speed_cm_per_min, "Push speed [cm/min] (default 12)");
  sub->add_option(
      "--crossing-tol-mm", a->crossing_tol_mm,
      "Crossing refinement of stepping models [mm] (default 0.05; the elastica is exact)");
  AddSensitivityFlags(sub, &a->sensitivity, "the crossing length L",
                      "differences of exact elastica solves, or of whole shell runs (two a "
                      "parameter, about 1.5 s a run with a seam along) when the shell answers",
                      "b1,b2,c1,beta,areal_density_gsm; the shell also stretch.*");
  sub->add_flag("--json", a->json, "Print one JSON object instead of text");
  sub->callback([a] { Run(*a); });
}

namespace {
const bool kRegistered = AddCommand(50, RegisterAcpm);
}  // namespace

}  // namespace textile::cli
