// textile validate: photos or profiles -> direct fit -> the same cantilevers simulated with the
// fitted law at the photographed overhangs, by the elastica and by the shell model -> measured vs
// simulated (docs/guide/validate.md): the goodness of fit, and with two or more profiles each one
// predicted by the law fitted to the others (leave-one-out). RMS and maximum deviation, tip
// difference, verdicts against a stated tolerance, a report JSON and a picture with all curves.
// The work is libfit's ValidateFit (validate.h); this file parses, prints and writes.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "common/atomic_file.h"
#include "common/chart_file.h"
#include "common/cli.h"
#include "common/profile_inputs.h"
#include "textile/fit/direct_fit.h"
#include "textile/fit/fit_report.h"
#include "textile/fit/profile_compare.h"
#include "textile/fit/validate.h"
#include "textile/sim/core/error.h"
#include "textile/sim/io/json_text.h"
#include "textile/sim/law/material.h"
#include "textile/sim/core/note.h"
#include "textile/sim/core/units.h"

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

nlohmann::json ModelJson(const ModelComparison& k) {
  if (!k.run) return nullptr;
  const ProfileComparison& c = k.comparison;
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

// The material with the fit report `textile fit` writes (fit_report.h), for the direct fit with
// default options that validate runs, and the verdicts.
Material FittedMaterial(const ValidationSummary& v, const std::vector<LoadedProfile>& loaded,
                        double gsm, const std::string& report_path) {
  Material fitted = v.material;
  fitted.fit = FitReportJson(v.fit, v.fit_options, units::GsmToSi(gsm),
                             v.NoteTexts(validation_note::kFit), {.diagnostics = false});
  nlohmann::json photos = nlohmann::json::array();
  std::vector<std::string> inputs;
  for (const auto& in : loaded) {
    if (in.extraction) photos.push_back(ExtractionJson(in));
    inputs.push_back(in.source);
  }
  fitted.fit["inputs"] = inputs;
  if (!photos.empty()) fitted.fit["photos"] = photos;
  fitted.fit["areal_density_gsm"] = gsm;
  fitted.fit["validate"] = report_path;
  fitted.fit["verdict"] = v.pass ? "pass" : "fail";
  fitted.fit["holdout_verdict"] = HoldoutVerdictName(v.holdout_verdict);
  return fitted;
}

// The held-out predictions: for each left-out profile, each point's distance from the curve the
// law of the other profiles predicts for it (the first model run; the elastica unless only the
// shell ran) along the strip, against the tolerance and its kMaxOverRms multiple.
textile::chart::Panel HeldOutPanel(const ValidationSummary& v, const std::vector<Profile>& profiles,
                                   const std::vector<std::string>& stems, size_t common) {
  namespace chart = textile::chart;
  const double tol_mm = units::MToMm(v.options.tolerance);
  chart::Panel p{
      .title = "Held out: distance of each profile from the law fitted to the others",
      .x_label = "arc length s [mm]",
      .y_label = "distance from the prediction [mm]"};
  double s_max = 0.0;
  for (const HeldOutProfile& h : v.holdout) {
    const Profile& measured = profiles[h.index];
    const std::string name = stems[h.index].substr(common);
    if (!h.predicted) {
      p.notes.push_back(name + ": not predicted");
      continue;
    }
    const HeldOutModel& m = h.elastica.check.run ? h.elastica : h.shell;
    const ProfileComparison& c = m.check.comparison;
    chart::Series d{.label = name + ": rms " + Num(units::MToMm(c.rms), 2) + " ± " +
                             Num(units::MToMm(m.sigma.rms), 2) + " mm" + (h.ok ? " ok" : " FAIL"),
                    .style = chart::Series::Style::kLineAndMarkers,
                    .color = chart::PaletteColor(static_cast<int>(h.index))};
    // The distances the rms and max were taken over, one per measured point.
    for (size_t j = 0; j < measured.size() && j < c.distances.size(); ++j) {
      d.x.push_back(units::MToMm(measured.s[j]));
      d.y.push_back(units::MToMm(c.distances[j]));
    }
    s_max = std::max(s_max, d.x.empty() ? 0.0 : d.x.back());
    p.series.push_back(std::move(d));
  }
  for (const double level : {tol_mm, kMaxOverRms * tol_mm})
    p.series.push_back({.label = level == tol_mm ? "rms tolerance" : "max and tip tolerance",
                        .x = {0.0, s_max},
                        .y = {level, level},
                        .color = chart::Rgb{0.4, 0.4, 0.4},
                        .line_width = 1.0,
                        .dashed = true});
  // Headroom above the largest distance and the max tolerance for the legend and the notes.
  double top = kMaxOverRms * tol_mm;
  for (const chart::Series& d : p.series)
    for (const double y : d.y) top = std::max(top, y);
  p.y_range = chart::Range{0.0, 1.6 * top};
  p.notes.push_back(std::string(v.holdout.front().elastica.check.run ? "elastica" : "shell") +
                    "'s predictions; held out: " +
                    (v.holdout_verdict == HoldoutVerdict::kPass ? "PASS" : "FAIL"));
  return p;
}

void Plot(const ValidationSummary& v, const std::vector<Profile>& profiles, AtomicFile& out) {
  namespace chart = textile::chart;
  const double tol_mm = units::MToMm(v.options.tolerance);
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
  for (const ProfileValidation& k : v.profiles)
    stems.push_back(std::filesystem::path(k.source).stem().string());
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
  for (size_t i = 0; i < v.profiles.size(); ++i) {
    const ProfileValidation& k = v.profiles[i];
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
    for (const ModelComparison* m : {&k.elastica, &k.shell}) {
      if (!m->run) continue;
      rms += (rms.empty() ? "" : "/") + Num(units::MToMm(m->comparison.rms), 2);
      max += (max.empty() ? "" : "/") + Num(units::MToMm(m->comparison.max), 2);
    }
    if (k.elastica.run)
      lines.push_back(
          curve(k.elastica.comparison, i == 0 ? "elastica" : "", false, {0.1, 0.1, 0.1}));
    if (k.shell.run)
      lines.push_back(curve(k.shell.comparison, i == 0 ? "shell" : "", true, {0.85, 0.1, 0.1}));
    const std::string note = stems[i].substr(common) + ": rms " + rms + ", max " + max + " mm";
    p.notes.push_back(note + (k.pass ? " ok" : " FAIL"));
  }
  for (auto& l : lines) p.series.push_back(std::move(l));
  if (!v.profiles.empty() && v.profiles[0].elastica.run && v.profiles[0].shell.run)
    p.notes.push_back("(elastica/shell)");
  const BendingLaw& law = v.material.bending;
  p.notes.push_back("law b1 = " + Num(law.b1_kes(), 4) + ", b2 = " + Num(law.b2_kes(), 4) +
                    " gf·cm, c1 = " + Num(law.c1_kes(), 4) + " gf·cm²");
  p.notes.push_back(std::string("goodness of fit: ") + (v.pass ? "PASS" : "FAIL") + " (rms ≤ " +
                    Num(tol_mm) + " mm, max and tip ≤ " + Num(kMaxOverRms * tol_mm) + " mm)");
  // The held-out predictions in one line: each profile's rms by the first model run.
  std::string held;
  for (const HeldOutProfile& h : v.holdout) {
    const ModelComparison& m = h.elastica.check.run ? h.elastica.check : h.shell.check;
    held += (held.empty() ? "" : ", ") +
            (h.predicted ? Num(units::MToMm(m.comparison.rms), 2) : std::string("-"));
  }
  p.notes.push_back(v.holdout.empty()
                        ? std::string("held out: nothing (one profile)")
                        : "held out: rms " + held + " mm " +
                              (v.holdout_verdict == HoldoutVerdict::kPass ? "PASS" : "FAIL"));
  std::vector<chart::Panel> panels = {p};
  if (!v.holdout.empty()) panels.push_back(HeldOutPanel(v, profiles, stems, common));
  chart::WritePng({.title = "textile validate",
                   .width_px = 1100,
                   .height_px = panels.size() == 1 ? 800 : 1400,
                   .panels = panels},
                  out);
}

nlohmann::json MmOrNull(double m) { return OrNull(units::MToMm(m)); }

// validate.json's `holdout`: one entry per held-out profile and model run.
nlohmann::json HoldoutJson(const ValidationSummary& v) {
  nlohmann::json list = nlohmann::json::array();
  for (const HeldOutProfile& h : v.holdout) {
    for (const auto& [name, m] :
         {std::pair{"elastica", &h.elastica}, std::pair{"shell", &h.shell}}) {
      // A profile not predicted gets an entry for each model asked for, with null figures.
      const bool asked = name == std::string("elastica")
                             ? v.options.run_elastica
                             : v.options.run_shell && v.options.hold_out_shell;
      if (!asked) continue;
      const ProfileComparison& c = m->check.comparison;
      const bool ran = h.predicted && m->check.run;
      const auto fig = [&](double value) { return ran ? MmOrNull(value) : nlohmann::json(); };
      nlohmann::json e = {
          {"input", h.source},
          {"model", name},
          {"overhang_mm", units::MToMm(h.overhang)},
          {"rms_mm", fig(c.rms)},
          {"max_mm", fig(c.max)},
          {"tip_mm", fig(std::hypot(c.tip_dx, c.tip_dy))},
          {"tip_dx_mm", fig(c.tip_dx)},
          {"tip_dy_mm", fig(c.tip_dy)},
          {"rms_sigma_mm", fig(m->sigma.rms)},
          {"max_sigma_mm", fig(m->sigma.max)},
          {"tip_sigma_mm", fig(m->sigma.tip)},
          {"sigma_complete", h.predicted ? nlohmann::json(h.sigma_complete) : nlohmann::json()},
          {"law_kes", h.law ? nlohmann::json{{"b1", h.law->b1_kes()},
                                             {"b2", h.law->b2_kes()},
                                             {"c1", h.law->c1_kes()}}
                            : nlohmann::json()},
          {"fit_rms_mm", h.predicted ? nlohmann::json(units::MToMm(h.fit_rms)) : nlohmann::json()},
          {"ok", ran && m->check.pass},
          {"why", ran ? m->check.why : h.why}};
      list.push_back(e);
    }
  }
  return list;
}

// Flags out of range, before any work (the library would refuse some only after the inputs
// are read, in its own words).
void CheckFlags(const ValidateArgs& a) {
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
}

struct OutputPaths {
  std::string report, png, material;  // validate.json, validate.png, fitted.json
};

OutputPaths OutputPathsIn(const std::string& dir) {
  const std::filesystem::path d(dir);
  return {(d / "validate.json").string(), (d / "validate.png").string(),
          (d / "fitted.json").string()};
}

// validate.json: the run's figures, verdicts and notes; `note`: the one-line note.
nlohmann::json ReportJson(const ValidateArgs& a, const ValidationSummary& v,
                          const std::vector<LoadedProfile>& loaded, const std::vector<Note>& notes,
                          const std::string& note, const OutputPaths& out) {
  const DirectFitSummary& fit = v.fit;
  const bool run_elastica = v.options.run_elastica, run_shell = v.options.run_shell;
  nlohmann::json per = nlohmann::json::array();
  for (size_t i = 0; i < v.profiles.size(); ++i) {
    const ProfileValidation& k = v.profiles[i];
    per.push_back({{"source", k.source},
                   {"from_photo", loaded[i].from_photo},
                   {"data_length_mm", units::MToMm(k.data_length)},
                   {"overhang_mm", units::MToMm(k.overhang)},
                   {"elastica", ModelJson(k.elastica)},
                   {"shell", ModelJson(k.shell)},
                   {"shell_vs_elastica_max_mm", MmOrNull(k.model_gap)},
                   {"pass", k.pass},
                   {"why", k.why}});
  }
  const std::string shell_notes = v.shell_notes;
  return {{"inputs", a.inputs},
          {"areal_density_gsm", a.gsm},
          {"law_kes", LawToJson(v.material.bending, false)},
          {"fit",
           {{"rms_mm", units::MToMm(fit.rms)},
            {"offset_mm", units::MToMm(fit.offset)},
            {"b1_sd_kes", OrNull(units::SiStiffnessToKes(fit.b1_sd))},
            {"b2_sd_kes", OrNull(units::SiStiffnessToKes(fit.b2_sd))},
            {"c1_sd_kes", OrNull(units::SiQuadraticToKes(fit.c1_sd))},
            {"observability", fit.observability}}},
          {"models",
           {{"elastica", run_elastica ? "simulated" : "not run (--model shell)"},
            {"shell", run_shell ? "simulated: 3D shell, tensor bending, " + shell_notes +
                                      ", strip " + Num(a.width_mm) + " mm wide"
                                : "not run (--model elastica)"}}},
          {"tolerance",
           {{"rms_mm", a.tolerance_mm},
            {"max_mm", kMaxOverRms * a.tolerance_mm},
            {"tip_mm", kMaxOverRms * a.tolerance_mm}}},
          {"profiles", per},
          {"verdict", v.pass ? "pass" : "fail"},
          {"holdout_method",
           "leave-one-out: each profile predicted at its fitted overhang by the law, offset and "
           "rotation fitted to the other profiles, graded by the tolerance; sigma: that fit's "
           "covariance through the elastica's sensitivities (docs/guide/validate.md)"},
          {"holdout", HoldoutJson(v)},
          {"holdout_verdict", HoldoutVerdictName(v.holdout_verdict)},
          {"note", note.empty() ? nlohmann::json() : nlohmann::json(note)},
          {"notes", NotesJson(notes)},
          {"png", out.png},
          {"material", out.material}};
}

// The text report: the law, each profile's figures, the held-out predictions, the verdicts.
void PrintText(const ValidateArgs& a, const ValidationSummary& v, const std::string& note,
               const OutputPaths& out) {
  const DirectFitSummary& fit = v.fit;
  const BendingLaw& law = v.material.bending;
  const bool run_elastica = v.options.run_elastica, run_shell = v.options.run_shell;
  const bool holdout_pass = v.holdout_verdict != HoldoutVerdict::kFail;
  const std::string& shell_notes = v.shell_notes;
  const double tol_mm = a.tolerance_mm;
  std::cout << "fitted law: b1 = " << Num(law.b1_kes(), 5)
            << " gf·cm, b2 = " << Num(law.b2_kes(), 5) << " gf·cm, c1 = " << Num(law.c1_kes(), 5)
            << " gf·cm² (fit rms " << Num(units::MToMm(fit.rms), 3) << " mm, offset "
            << Num(units::MToMm(fit.offset), 3) << " mm)\n"
            << "goodness of fit: simulated at each fitted overhang with "
            << (run_elastica ? "the elastica" : "") << (run_elastica && run_shell ? " and " : "")
            << (run_shell ? "the shell (" + shell_notes + "; " + std::to_string(v.shell_solves) +
                                " static solves in all)"
                          : "")
            << "\n";
  const auto figures = [](const ModelComparison& m) {
    const ProfileComparison& c = m.comparison;
    return "rms " + Num(units::MToMm(c.rms), 3) + " mm, max " + Num(units::MToMm(c.max), 3) +
           " mm, tip (" + Num(units::MToMm(c.tip_dx), 3) + ", " + Num(units::MToMm(c.tip_dy), 3) +
           ") mm  " + (m.pass ? "ok" : "FAIL: " + m.why);
  };
  for (const auto& k : v.profiles) {
    std::cout << "  " << k.source << ": L = " << Num(units::MToMm(k.overhang), 5) << " mm";
    if (std::isfinite(k.model_gap))
      std::cout << ", shell within " << Num(units::MToMm(k.model_gap), 3) << " mm of the elastica";
    std::cout << "\n";
    if (k.elastica.run) std::cout << "    elastica: " << figures(k.elastica) << "\n";
    if (k.shell.run) std::cout << "    shell   : " << figures(k.shell) << "\n";
  }
  if (!v.holdout.empty()) {
    std::cout << "held out: each profile predicted by the law fitted to the others, at its "
                 "fitted overhang (± 1σ of the prediction)\n";
    const auto pm = [](double value, double sigma) {
      return Num(units::MToMm(value), 3) + " ± " + Num(units::MToMm(sigma), 2);
    };
    for (const HeldOutProfile& h : v.holdout) {
      std::cout << "  " << h.source << ": L = " << Num(units::MToMm(h.overhang), 5) << " mm";
      if (!h.predicted) {
        std::cout << ", not predicted: " << h.why << "\n";
        continue;
      }
      std::cout << ", law without it b1 = " << Num(h.law->b1_kes(), 4)
                << ", b2 = " << Num(h.law->b2_kes(), 4) << ", c1 = " << Num(h.law->c1_kes(), 4)
                << "\n";
      for (const auto& [name, m] :
           {std::pair{"elastica", &h.elastica}, std::pair{"shell   ", &h.shell}}) {
        if (!m->check.run) continue;
        const ProfileComparison& c = m->check.comparison;
        std::cout << "    " << name << ": rms " << pm(c.rms, m->sigma.rms) << " mm, max "
                  << pm(c.max, m->sigma.max) << " mm, tip "
                  << pm(std::hypot(c.tip_dx, c.tip_dy), m->sigma.tip) << " mm  "
                  << (m->check.pass ? "ok" : "FAIL: " + m->check.why) << "\n";
      }
    }
  }
  if (!note.empty()) std::cout << "note: " << note << "\n";
  // The held-out notes, each on its line; a held-out fit that failed is said by its own line.
  for (const Note& n : v.notes)
    if (n.code != validation_note::kFit && n.code != validation_note::kHeldOutFitFailed)
      std::cout << "note: " << n.text << "\n";
  std::cout << "goodness of fit: " << (v.pass ? "PASS" : "FAIL") << " (tolerance: rms ≤ "
            << Num(tol_mm) << " mm, max and tip ≤ " << Num(kMaxOverRms * tol_mm) << " mm)\n"
            << "held out: "
            << (v.holdout_verdict == HoldoutVerdict::kNone ? "nothing (one profile)"
                : holdout_pass                             ? "PASS (the same tolerance)"
                                                           : "FAIL (the same tolerance)")
            << "\nwrote " << out.report << ", " << out.png << ", " << out.material << "\n";
}

// Valid photo flags with profiles only are not an error (textile fit takes them too, and a
// glob may or may not match photos), but the run does not use them: say so.
std::vector<Note> UnusedPhotoFlags(const ValidateArgs& a,
                                   const std::vector<LoadedProfile>& loaded) {
  const bool any_photo =
      std::any_of(loaded.begin(), loaded.end(), [](const auto& in) { return in.from_photo; });
  if (any_photo || a.photo_flags_given.empty()) return {};
  std::string text = "no input is a photo: ";
  for (size_t f = 0; f < a.photo_flags_given.size(); ++f)
    text += (f ? ", " : "") + a.photo_flags_given[f];
  return {{"photo_flags_unused", text + " not used"}};
}

// validate.json's `note` and the text's first note line: the photo flags and the fit's own
// notes (as textile fit's report has them); the held-out notes print apart.
std::string OneLineNote(const std::vector<Note>& notes) {
  std::string note;
  for (const Note& n : notes)
    if (n.code == "photo_flags_unused" || n.code == validation_note::kFit)
      note += (note.empty() ? "" : "; ") + n.text;
  return note;
}

void Run(const ValidateArgs& a) {
  CheckFlags(a);
  ValidationOptions options;
  options.tolerance = units::MmToM(a.tolerance_mm);
  options.run_elastica = a.model != "shell";
  options.run_shell = a.model != "elastica";
  options.strip_width = units::MmToM(a.width_mm);
  const PhotoInputOptions photo = a.photo.Options();
  const OutputPaths out = OutputPathsIn(a.out_dir);
  // Before any work: an input in the folder under an output's name would be replaced by it
  // (the photo by the chart, the rig by the fitted material). (A profile given twice is refused
  // by LoadProfileInputs, as in textile fit.)
  std::vector<std::pair<std::string, std::string>> inputs{{"--rig", a.photo.rig_file}};
  for (const std::string& in : a.inputs) inputs.emplace_back(in, in);
  CheckDistinctOutputs({{"-o", out.report}, {"-o", out.png}, {"-o", out.material}}, inputs);
  const std::vector<LoadedProfile> loaded = LoadProfileInputs(a.inputs, photo);
  std::vector<Note> notes = UnusedPhotoFlags(a, loaded);
  const OutputFolder folder(a.out_dir);  // made when the files are committed
  // Fail fast on an unusable folder; the three files appear together or not at all.
  AtomicFileSet outputs;
  AtomicFile& report_file = outputs.Add(out.report, folder.stage_dir());
  AtomicFile& png_file = outputs.Add(out.png, folder.stage_dir());
  AtomicFile& material_file = outputs.Add(out.material, folder.stage_dir());

  std::vector<Profile> profiles;
  for (const auto& in : loaded) profiles.push_back(in.profile);
  // The fit textile fit runs (a tilted rig is found and fitted with its rotation), the same
  // cantilevers simulated, and each profile predicted by the law fitted to the others.
  const ValidationSummary v = ValidateFit(profiles, units::GsmToSi(a.gsm), options);
  if (!v.completed) throw ComputeError(v.message);
  notes.insert(notes.end(), v.notes.begin(), v.notes.end());
  const std::string note = OneLineNote(notes);
  const nlohmann::json report = ReportJson(a, v, loaded, notes, note, out);
  if (v.AllPass() || !a.strict) {
    material_file.Write(MaterialToJson(FittedMaterial(v, loaded, a.gsm, out.report)).dump(2) +
                        "\n");
    Plot(v, profiles, png_file);
    report_file.Write(report.dump(2) + "\n");
    outputs.Commit();
  } else {
    throw ComputeError("validation failed (--strict): " + v.FailureReason());
  }

  if (a.json) {
    PrintJson(report);
    return;
  }
  PrintText(a, v, note, out);
}

}  // namespace

void RegisterValidate(CLI::App& app) {
  auto a = std::make_shared<ValidateArgs>();
  CLI::App* sub = AddSubcommand(
      app, "validate",
      "Photos or profiles -> direct fit -> the same cantilevers simulated -> measured vs simulated "
      "(RMS, max, tip: goodness of fit), and each profile predicted by the law fitted to the "
      "others (held out); verdicts, report JSON + PNG",
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
  sub->add_flag("--strict", a->strict,
                "A failed verdict, goodness of fit or held out, is an error (exit 3, nothing "
                "written)");
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
