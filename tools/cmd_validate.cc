// textile validate: photos or profiles -> direct fit -> the same cantilevers simulated with the
// fitted law at the photographed overhangs, by the elastica and by the shell model -> measured vs
// simulated (cantilever.md, "Closing the loop"): RMS and maximum deviation, tip difference, a
// verdict against a stated tolerance, a report JSON and a picture with all curves.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "common/atomic_file.h"
#include "common/chart.h"
#include "common/cli.h"
#include "common/profile_inputs.h"
#include "textile/fit/direct_fit.h"
#include "textile/fit/extract.h"
#include "textile/fit/profile_compare.h"
#include "textile/fit/rig.h"
#include "textile/sim/acpm_shell.h"
#include "textile/sim/cantilever_outputs.h"
#include "textile/sim/error.h"
#include "textile/sim/material.h"
#include "textile/sim/polyline.h"
#include "textile/sim/units.h"

namespace textile::cli {
namespace {

struct ValidateArgs {
  std::vector<std::string> inputs;
  double gsm = 0.0;
  std::string out_dir;
  double tolerance_mm = 0.5;
  double width_mm = 25.0;
  std::string model = "both";
  bool strict = false, json = false;
  bool width_given = false;
  PhotoFlags photo;
  std::vector<std::string> photo_flags_given;  // e.g. "--rig": unused when no input is a photo
};

// Per profile: the verdict's three criteria. The RMS normal distance carries the tolerance; a
// single point or the tip may stray up to 3× that (a frayed fibre, a speck) before it fails.
constexpr double kMaxOverRms = 3.0;

// One model's simulation of one profile.
struct ModelCheck {
  bool run = false;
  ProfileComparison c;
  bool pass = false;
  std::string why;
  int solves = 0;
  std::string notes;
};

struct Check {
  std::string source;
  bool from_photo = false;
  double data_length = 0.0, overhang = 0.0;  // [m]
  ModelCheck elastica, shell;
  double model_gap = std::numeric_limits<double>::quiet_NaN();  // shell vs elastica, max [m]
  bool pass = false;
  std::string why;
};

// Grades one comparison against the tolerance tol [m]; the failed criteria in k->why.
void Grade(double tol, double tol_mm, ModelCheck* k) {
  const ProfileComparison& c = k->c;
  const double tip = std::hypot(c.tip_dx, c.tip_dy);
  std::vector<std::string> fails;
  if (c.rms > tol) fails.push_back("rms " + Num(units::MToMm(c.rms), 3) + " mm > " + Num(tol_mm));
  if (c.max > kMaxOverRms * tol)
    fails.push_back("max " + Num(units::MToMm(c.max), 3) + " mm > " + Num(kMaxOverRms * tol_mm));
  if (tip > kMaxOverRms * tol)
    fails.push_back("tip " + Num(units::MToMm(tip), 3) + " mm > " + Num(kMaxOverRms * tol_mm));
  k->pass = fails.empty();
  k->why.clear();
  for (size_t f = 0; f < fails.size(); ++f) k->why += (f ? ", " : "") + fails[f];
}

nlohmann::json ModelJson(const ModelCheck& k) {
  if (!k.run) return nullptr;
  const ProfileComparison& c = k.c;
  return {
      {"rms_mm", units::MToMm(c.rms)},
      {"max_mm", units::MToMm(c.max)},
      {"tip_dx_mm", units::MToMm(c.tip_dx)},
      {"tip_dy_mm", units::MToMm(c.tip_dy)},
      {"tip_mm", units::MToMm(std::hypot(c.tip_dx, c.tip_dy))},
      {"clamp_curvature_per_cm", std::isfinite(c.clamp_curvature)
                                     ? nlohmann::json(units::SiCurvatureToKes(c.clamp_curvature))
                                     : nlohmann::json()},
      {"solves", k.solves},
      {"pass", k.pass},
      {"why", k.why}};
}

// JSON null for a value that is not available (an undetermined constant's σ).
nlohmann::json OrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

// The fit report `textile fit` writes into a material's `fit` (cli.md; cmd_fit.cc's RunDirect
// and AddClassicOutputs), for the direct fit with default options that validate runs: no
// rotation, offset fitted, Cauchy scale options.robust_scale. The classic outputs: what the
// 41.5° test would report for this law, and how that G relates to b1 and b2.
nlohmann::json FitReport(const DirectFitSummary& fit, const DirectFitOptions& options,
                         const std::vector<LoadedProfile>& loaded, double gsm) {
  const double rho = units::GsmToSi(gsm);
  nlohmann::json per = nlohmann::json::array();
  for (const auto& r : fit.profiles) {
    per.push_back({{"source", r.source},
                   {"overhang_mm", units::MToMm(r.overhang)},
                   {"data_length_mm", units::MToMm(r.data_length)},
                   {"rms_mm", units::MToMm(r.rms)},
                   {"max_mm", units::MToMm(r.max)},
                   {"clamp_curvature_per_cm", units::SiCurvatureToKes(r.clamp_curvature)}});
  }
  nlohmann::json report = {{"method", "direct"},
                           {"b1_sd", OrNull(units::SiStiffnessToKes(fit.b1_sd))},
                           {"b2_sd", OrNull(units::SiStiffnessToKes(fit.b2_sd))},
                           {"c1_sd", OrNull(units::SiQuadraticToKes(fit.c1_sd))},
                           {"sd_units", "kes"},
                           {"rms_mm", units::MToMm(fit.rms)},
                           {"b1_observed", fit.b1_observed},
                           {"b2_observed", fit.b2_observed},
                           {"c1_observed", fit.c1_observed},
                           {"observability", fit.observability},
                           {"kappa_max_per_cm", units::SiCurvatureToKes(fit.kappa_max)},
                           {"offset_mm", units::MToMm(fit.offset)},
                           {"offset_fitted", options.fit_offset},
                           {"rotation_deg", fit.rotation * 180.0 / M_PI},
                           {"rotation_fitted", options.fit_rotation},
                           {"robust_scale_mm", units::MToMm(options.robust_scale)},
                           {"iterations", fit.iterations},
                           {"seconds", fit.seconds},
                           {"profiles", per}};
  const BendingLaw& law = *fit.law;
  const BarrierCrossing x = FindBarrierCrossing(law, rho);
  if (x.converged) {
    const ClassicOutputs c = ComputeClassicOutputs(rho, x.overhang);
    report["crossing_overhang_mm"] = units::MToMm(x.overhang);
    report["bending_length_mm"] = units::MToMm(c.bending_length);
    report["flexural_rigidity_uNm"] = c.rigidity_micro_nm();
    report["flexural_rigidity_mgcm"] = c.rigidity_mg_cm();
    report["flexural_rigidity_gfcm"] = c.rigidity_gf_cm();
    report["G_over_b1"] = c.flexural_rigidity / law.b1();
    report["G_over_b2"] = c.flexural_rigidity / law.b2();
    report["classic_note"] = c.RelationToLaw(law);
  } else {
    report["classic_note"] = "no 41.5° crossing: " + x.message;
  }
  nlohmann::json photos = nlohmann::json::array();
  for (const auto& in : loaded) {
    if (!in.extraction) continue;
    photos.push_back(ExtractionJson(in));
  }
  std::vector<std::string> inputs;
  for (const auto& in : loaded) inputs.push_back(in.source);
  report["inputs"] = inputs;
  if (!photos.empty()) report["photos"] = photos;
  report["areal_density_gsm"] = gsm;
  return report;
}

void Plot(const std::vector<Check>& checks, const std::vector<Profile>& profiles,
          const BendingLaw& law, double tol_mm, bool pass, AtomicFile& out) {
  namespace chart = textile::chart;
  chart::Panel p{
      .title = "Measured (dots) and simulated cantilevers: elastica (solid), shell (dashed)",
      .x_label = "x [mm]",
      .y_label = "y [mm]",
      .equal_aspect = true,
      .legend_corner = chart::Corner::kTopRight};  // the notes: the corner with the least ink
  std::vector<chart::Series> lines;
  const auto curve = [](const ProfileComparison& c, const std::string& label, bool dashed,
                        chart::Rgb color) {
    chart::Series sim{.label = label, .color = color, .line_width = 1.2, .dashed = dashed};
    for (size_t j = 0; j < c.model_x.size(); ++j) {
      sim.x.push_back(units::MToMm(c.model_x[j]));
      sim.y.push_back(units::MToMm(c.model_y[j]));
    }
    return sim;
  };
  // The notes name each profile by its file stem without the stems' common prefix (cut at a
  // '_' or '-'), so that the box stays narrow enough to find a corner free of curves.
  std::vector<std::string> stems;
  for (const Check& k : checks) stems.push_back(std::filesystem::path(k.source).stem().string());
  size_t common = 0;
  if (stems.size() > 1) {
    common = stems[0].size();
    for (const auto& t : stems) {
      size_t n = 0;
      while (n < common && n < t.size() && t[n] == stems[0][n]) ++n;
      common = n;
    }
    const size_t cut = stems[0].find_last_of("_-", common == 0 ? 0 : common - 1);
    common = cut == std::string::npos || common == 0 ? 0 : cut + 1;
    for (const auto& t : stems)
      if (t.size() <= common) common = 0;
  }
  for (size_t i = 0; i < checks.size(); ++i) {
    const Check& k = checks[i];
    const std::string name = std::filesystem::path(k.source).filename().string();
    chart::Series data{.label = name,
                       .style = chart::Series::Style::kMarkers,
                       .color = chart::PaletteColor(static_cast<int>(i))};
    for (size_t j = 0; j < profiles[i].size(); ++j) {
      data.x.push_back(units::MToMm(profiles[i].x[j]));
      data.y.push_back(units::MToMm(profiles[i].y[j]));
    }
    p.series.push_back(data);
    // One short line per profile: rms and max of each model run ("elastica / shell").
    std::string rms, max;
    for (const ModelCheck* m : {&k.elastica, &k.shell}) {
      if (!m->run) continue;
      rms += (rms.empty() ? "" : "/") + Num(units::MToMm(m->c.rms), 2);
      max += (max.empty() ? "" : "/") + Num(units::MToMm(m->c.max), 2);
    }
    if (k.elastica.run)
      lines.push_back(curve(k.elastica.c, i == 0 ? "elastica" : "", false, {0.1, 0.1, 0.1}));
    if (k.shell.run)
      lines.push_back(curve(k.shell.c, i == 0 ? "shell" : "", true, {0.85, 0.1, 0.1}));
    const std::string note = stems[i].substr(common) + ": rms " + rms + ", max " + max + " mm";
    p.notes.push_back(note + (k.pass ? " ok" : " FAIL"));
  }
  for (auto& l : lines) p.series.push_back(std::move(l));
  if (!checks.empty() && checks[0].elastica.run && checks[0].shell.run)
    p.notes.push_back("(elastica/shell)");
  p.notes.push_back("law b1 = " + Num(law.b1_kes(), 4) + ", b2 = " + Num(law.b2_kes(), 4) +
                    " gf·cm, c1 = " + Num(law.c1_kes(), 4) + " gf·cm²");
  p.notes.push_back(std::string("verdict: ") + (pass ? "PASS" : "FAIL") + " (rms ≤ " + Num(tol_mm) +
                    " mm, max and tip ≤ " + Num(kMaxOverRms * tol_mm) + " mm)");
  chart::WritePng({.title = "textile validate", .width_px = 1100, .height_px = 800, .panels = {p}},
                  out);
}

void Run(const ValidateArgs& a) {
  if (!std::isfinite(a.gsm) || a.gsm < 1.0 || a.gsm > 1e4)
    throw InputError("--gsm must be an areal density in [1, 10000] g/m², got " + Num(a.gsm));
  if (!std::isfinite(a.tolerance_mm) || a.tolerance_mm <= 0.0 || a.tolerance_mm > 50.0)
    throw InputError("--tolerance-mm must lie in (0, 50] mm, got " + Num(a.tolerance_mm));
  // At least 5 mm: the standard strip is 25 mm wide, and a shell of 0.1 mm did not settle
  // (exit 3 after the fit instead of a refused flag).
  if (!std::isfinite(a.width_mm) || a.width_mm < 5.0 || a.width_mm > 200.0)
    throw InputError("--width-mm must lie in [5, 200] mm, got " + Num(a.width_mm));
  // As textile fit refuses the direct fit's options with --method clapp.
  if (a.width_given && a.model == "elastica")
    throw InputError("--width-mm: the shell's strip width; --model elastica simulates no shell");
  const bool run_elastica = a.model != "shell", run_shell = a.model != "elastica";
  const double rho = units::GsmToSi(a.gsm);
  const PhotoInputOptions photo = a.photo.Options();
  const std::string report_path = (std::filesystem::path(a.out_dir) / "validate.json").string();
  const std::string png_path = (std::filesystem::path(a.out_dir) / "validate.png").string();
  const std::string material_path = (std::filesystem::path(a.out_dir) / "fitted.json").string();
  // Before any work: an input in the folder under an output's name would be replaced by it
  // (the photo by the chart, the rig by the fitted material). (A profile given twice is refused
  // by LoadProfileInputs, as in textile fit.)
  std::vector<std::pair<std::string, std::string>> inputs{{"--rig", a.photo.rig_file}};
  for (const std::string& in : a.inputs) inputs.emplace_back(in, in);
  CheckDistinctOutputs({{"-o", report_path}, {"-o", png_path}, {"-o", material_path}}, inputs);
  const std::vector<LoadedProfile> loaded = LoadProfileInputs(a.inputs, photo);
  const bool any_photo =
      std::any_of(loaded.begin(), loaded.end(), [](const auto& in) { return in.from_photo; });
  // Valid photo flags with profiles only are not an error (textile fit takes them too, and a
  // glob may or may not match photos), but the run does not use them: say so.
  std::string note;
  if (!any_photo && !a.photo_flags_given.empty()) {
    note = "no input is a photo: ";
    for (size_t f = 0; f < a.photo_flags_given.size(); ++f)
      note += (f ? ", " : "") + a.photo_flags_given[f];
    note += " not used";
  }
  const OutputFolder folder(a.out_dir);  // made when the files are committed
  // Fail fast on an unusable folder; the three files appear together or not at all.
  AtomicFileSet outputs;
  AtomicFile& report_file = outputs.Add(report_path, folder.stage_dir());
  AtomicFile& png_file = outputs.Add(png_path, folder.stage_dir());
  AtomicFile& material_file = outputs.Add(material_path, folder.stage_dir());

  std::vector<Profile> profiles;
  for (const auto& in : loaded) profiles.push_back(in.profile);
  // The fit textile fit runs: a tilted rig is found and fitted with its rotation (and the
  // simulated curves below are turned with it).
  DirectFitOptions fit_options;
  std::vector<std::string> fit_notes;
  const DirectFitSummary fit =
      FitDirectCheckingTilt(profiles, rho, DirectFitOptions{}, &fit_notes, &fit_options);
  if (!fit.converged || !fit.law) throw ComputeError("fit: " + fit.message);
  for (const std::string& n : fit_notes) note += (note.empty() ? "" : "; ") + n;
  const BendingLaw& law = *fit.law;
  // Only a law a material file accepts is worth simulating (as textile fit checks): a fit to a
  // straight or vertical strip can run to constants no fabric has.
  Material fitted;
  fitted.name = "validated fit";
  fitted.areal_density = rho;
  fitted.bending = law;
  try {
    ParseMaterialJson(MaterialToJson(fitted).dump(), "fitted law");
  } catch (const InputError& e) {
    throw ComputeError(std::string("fit gave an implausible law: ") + e.what());
  }

  // The same cantilevers simulated: the fitted law at each photo's overhang. The overhang is the
  // fitted L_i (the arc length of noisy data is biased long: 0.1 mm noise on 0.6 mm spacing
  // lengthens it by ~3 %), and the mid-line offset at the edge is the fitted one. The shell is
  // the 3D engine on a strip --width-mm wide (acpm_shell.h, SolveShellCantilever).
  const double tol = units::MmToM(a.tolerance_mm);
  std::vector<Check> checks;
  bool all_pass = true;
  std::string shell_notes;
  int shell_solves = 0;
  for (size_t i = 0; i < profiles.size(); ++i) {
    Check k;
    k.source = loaded[i].source;
    k.from_photo = loaded[i].from_photo;
    k.data_length = profiles[i].s.back();
    k.overhang = fit.profiles[i].overhang;
    if (run_elastica) {
      k.elastica.run = true;
      k.elastica.c =
          CompareWithElastica(law, rho, profiles[i], k.overhang, fit.offset, fit.rotation);
      Grade(tol, a.tolerance_mm, &k.elastica);
    }
    if (run_shell) {
      const ShellCantilever sc = SolveShellCantilever(fitted, k.overhang, units::MmToM(a.width_mm));
      if (!sc.converged) throw ComputeError(k.source + ": " + sc.message);
      k.shell.run = true;
      // The shell's curve turned by the fitted rig rotation about the edge (0 for a level rig).
      std::vector<double> sx(sc.x.size()), sy(sc.y.size());
      const double cr = std::cos(fit.rotation), sr = std::sin(fit.rotation);
      for (size_t j = 0; j < sc.x.size(); ++j) {
        sx[j] = cr * sc.x[j] - sr * sc.y[j];
        sy[j] = sr * sc.x[j] + cr * sc.y[j];
      }
      k.shell.c = CompareWithCurve(profiles[i], sx, sy, fit.offset);
      k.shell.solves = sc.solves;
      k.shell.notes = sc.notes;
      shell_notes = sc.notes;
      shell_solves += sc.solves;
      Grade(tol, a.tolerance_mm, &k.shell);
      if (run_elastica) {
        // How far the shell's curve lies from the elastica's (both lifted by the offset).
        std::vector<double> lifted = sy;
        for (double& y : lifted) y += fit.offset;
        k.model_gap = MaxDistanceToPolyline(k.elastica.c.model_x, k.elastica.c.model_y, sx, lifted);
      }
    }
    std::vector<std::string> why;
    for (const auto* m : {&k.elastica, &k.shell})
      if (m->run && !m->pass) why.push_back((m == &k.elastica ? "elastica: " : "shell: ") + m->why);
    k.pass = why.empty();
    for (size_t f = 0; f < why.size(); ++f) k.why += (f ? "; " : "") + why[f];
    all_pass = all_pass && k.pass;
    checks.push_back(k);
  }

  nlohmann::json per = nlohmann::json::array();
  for (const auto& k : checks) {
    per.push_back({{"source", k.source},
                   {"from_photo", k.from_photo},
                   {"data_length_mm", units::MToMm(k.data_length)},
                   {"overhang_mm", units::MToMm(k.overhang)},
                   {"elastica", ModelJson(k.elastica)},
                   {"shell", ModelJson(k.shell)},
                   {"shell_vs_elastica_max_mm", std::isfinite(k.model_gap)
                                                    ? nlohmann::json(units::MToMm(k.model_gap))
                                                    : nlohmann::json()},
                   {"pass", k.pass},
                   {"why", k.why}});
  }
  nlohmann::json report = {
      {"inputs", a.inputs},
      {"areal_density_gsm", a.gsm},
      {"law_kes", LawToJson(law, false)},
      {"fit",
       {{"rms_mm", units::MToMm(fit.rms)},
        {"offset_mm", units::MToMm(fit.offset)},
        {"b1_sd_kes", std::isfinite(fit.b1_sd) ? nlohmann::json(units::SiStiffnessToKes(fit.b1_sd))
                                               : nlohmann::json()},
        {"b2_sd_kes", std::isfinite(fit.b2_sd) ? nlohmann::json(units::SiStiffnessToKes(fit.b2_sd))
                                               : nlohmann::json()},
        {"c1_sd_kes", std::isfinite(fit.c1_sd) ? nlohmann::json(units::SiQuadraticToKes(fit.c1_sd))
                                               : nlohmann::json()},
        {"observability", fit.observability}}},
      {"models",
       {{"elastica", run_elastica ? "simulated" : "not run (--model shell)"},
        {"shell", run_shell ? "simulated: 3D shell, tensor bending, " + shell_notes + ", strip " +
                                  Num(a.width_mm) + " mm wide"
                            : "not run (--model elastica)"}}},
      {"tolerance",
       {{"rms_mm", a.tolerance_mm},
        {"max_mm", kMaxOverRms * a.tolerance_mm},
        {"tip_mm", kMaxOverRms * a.tolerance_mm}}},
      {"profiles", per},
      {"verdict", all_pass ? "pass" : "fail"},
      {"note", note.empty() ? nlohmann::json() : nlohmann::json(note)},
      {"png", png_path},
      {"material", material_path}};
  if (all_pass || !a.strict) {
    fitted.fit = FitReport(fit, fit_options, loaded, a.gsm);
    std::string fit_note;  // as textile fit's report has it: the fit's own notes only
    for (const std::string& n : fit_notes) fit_note += (fit_note.empty() ? "" : "; ") + n;
    fitted.fit["note"] = fit_note.empty() ? nlohmann::json() : nlohmann::json(fit_note);
    fitted.fit["validate"] = report_path;
    fitted.fit["verdict"] = all_pass ? "pass" : "fail";
    material_file.Write(MaterialToJson(fitted).dump(2) + "\n");
    Plot(checks, profiles, law, a.tolerance_mm, all_pass, png_file);
    report_file.Write(report.dump(2) + "\n");
    outputs.Commit();
  }
  if (!all_pass && a.strict) {
    std::string why;
    for (const auto& k : checks)
      if (!k.pass) why += (why.empty() ? "" : "; ") + k.source + ": " + k.why;
    throw ComputeError("validation failed (--strict): " + why);
  }

  if (a.json) {
    PrintJson(report);
    return;
  }
  std::cout << "fitted law: b1 = " << Num(law.b1_kes(), 5)
            << " gf·cm, b2 = " << Num(law.b2_kes(), 5) << " gf·cm, c1 = " << Num(law.c1_kes(), 5)
            << " gf·cm² (fit rms " << Num(units::MToMm(fit.rms), 3) << " mm, offset "
            << Num(units::MToMm(fit.offset), 3) << " mm)\n"
            << "simulated at each fitted overhang with " << (run_elastica ? "the elastica" : "")
            << (run_elastica && run_shell ? " and " : "")
            << (run_shell ? "the shell (" + shell_notes + "; " + std::to_string(shell_solves) +
                                " static solves in all)"
                          : "")
            << "\n";
  const auto line = [](const char* name, const ModelCheck& m) {
    std::cout << "    " << name << ": rms " << Num(units::MToMm(m.c.rms), 3) << " mm, max "
              << Num(units::MToMm(m.c.max), 3) << " mm, tip (" << Num(units::MToMm(m.c.tip_dx), 3)
              << ", " << Num(units::MToMm(m.c.tip_dy), 3) << ") mm  "
              << (m.pass ? "ok" : "FAIL: " + m.why) << "\n";
  };
  for (const auto& k : checks) {
    std::cout << "  " << k.source << ": L = " << Num(units::MToMm(k.overhang), 5) << " mm";
    if (std::isfinite(k.model_gap))
      std::cout << ", shell within " << Num(units::MToMm(k.model_gap), 3) << " mm of the elastica";
    std::cout << "\n";
    if (k.elastica.run) line("elastica", k.elastica);
    if (k.shell.run) line("shell   ", k.shell);
  }
  if (!note.empty()) std::cout << "note: " << note << "\n";
  std::cout << "verdict: " << (all_pass ? "PASS" : "FAIL") << " (tolerance: rms ≤ "
            << Num(a.tolerance_mm) << " mm, max and tip ≤ " << Num(kMaxOverRms * a.tolerance_mm)
            << " mm)\nwrote " << report_path << ", " << png_path << ", " << material_path << "\n";
}

}  // namespace

void RegisterValidate(CLI::App& app) {
  auto a = std::make_shared<ValidateArgs>();
  CLI::App* sub = AddSubcommand(
      app, "validate",
      "Photos or profiles -> direct fit -> the same cantilevers simulated -> measured vs simulated "
      "(RMS, max, tip, verdict), report JSON + PNG",
      "textile validate samples/profiles/pabst-fig8_L0*.profile.csv --gsm 200 -o out/validate\n"
      "  textile validate strip_*.jpg --rig rig.json --gsm 200 -o out/validate");
  sub->add_option(
         "inputs", a->inputs,
         "Profile CSV files (s_mm,x_mm,y_mm) or photos (need --rig or --mm-per-px) of one strip")
      ->required();
  sub->add_option("--gsm", a->gsm, "Areal density of the fabric [g/m²]")->required();
  sub->add_option("-o,--out", a->out_dir, "Folder for validate.json, validate.png and fitted.json")
      ->required();
  sub->add_option("--tolerance-mm", a->tolerance_mm,
                  "RMS deviation allowed per profile [mm] (max and tip: 3x); default 0.5");
  sub->add_option(
         "--model", a->model,
         "Models to simulate: both (default), elastica (exact, ms) or shell (the 3D engine, "
         "~0.25 s per profile)")
      ->check(CLI::IsMember({"both", "elastica", "shell"}));
  sub->add_option("--width-mm", a->width_mm,
                  "Strip width for the shell model [mm], in [5, 200]; default 25");
  sub->add_flag("--strict", a->strict, "A failed validation is an error (exit 3, nothing written)");
  sub->add_flag("--json", a->json, "Print one JSON object instead of text");
  AddPhotoFlags(sub, &a->photo);
  CLI::Option* width = sub->get_option("--width-mm");
  std::vector<CLI::Option*> photo_flags;
  for (const char* name : {"--rig", "--mm-per-px", "--edge-px", "--level-deg", "--trace",
                           "--rig-type", "--step-mm", "--progress"})
    photo_flags.push_back(sub->get_option(name));
  sub->callback([a, width, photo_flags] {
    a->width_given = width->count() > 0;
    a->photo_flags_given.clear();
    for (const CLI::Option* o : photo_flags)
      if (o->count() > 0) a->photo_flags_given.push_back(o->get_name());
    Run(*a);
  });
}

namespace {
const bool kRegistered = AddCommand(70, RegisterValidate);
}  // namespace

}  // namespace textile::cli
