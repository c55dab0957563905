// textile fit: cantilever profiles -> the bending law {b1, b2, c1}, by the direct elastica fit
// (default) or by Clapp et al.'s method; writes a material file with a `fit` report.

#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>

#include "common/atomic_file.h"
#include "common/chart_file.h"
#include "common/cli.h"
#include "common/profile_inputs.h"
#include "textile/fit/clapp.h"
#include "textile/fit/direct_fit.h"
#include "textile/fit/fit_report.h"
#include "textile/fit/profile.h"
#include "textile/fit/profile_compare.h"
#include "textile/sim/core/error.h"
#include "textile/sim/law/material.h"
#include "textile/sim/core/units.h"

namespace textile::cli {
namespace {

struct FitArgs {
  std::vector<std::string> inputs;
  double gsm = 0.0;
  std::string method = "direct";
  std::string out, plot, name;
  double thickness_mm = 0.0;
  bool thickness_given = false;  // else the offset is fitted
  bool no_offset = false, fit_rotation = false, json = false;
  double robust_mm = 0.5;
  bool robust_given = false;
  PhotoFlags photo;  // photos among the inputs are extracted first
};

// "pabst-fig8_L040mm" for .../pabst-fig8_L040mm.profile.csv (extract's and synth-profile's
// names) and for a photo .../pabst-fig8_L040mm.jpg.
std::string InputStem(const std::string& path) {
  std::string stem = std::filesystem::path(path).stem().string();
  const std::string suffix = ".profile";
  if (stem.size() > suffix.size() && stem.ends_with(suffix))
    stem.resize(stem.size() - suffix.size());
  return stem;
}

struct Outcome {
  BendingLaw law = BendingLaw::FromKes(1, 1, 0);
  nlohmann::json report;
  std::vector<ProfileComparison> comparisons;  // per profile, for the plot
  double kappa_max = 0.0;
  std::string brief;
  std::string notes;  // what the user should know about a fit that succeeded ("; "-joined)
};

// A fit can only hand out a law that a material file accepts: Clapp's regression, for one,
// can wander to constants no fabric has when the polynomial is poor.
void CheckFittedLaw(const BendingLaw& law, double rho, const std::string& method) {
  if (std::string why; !FittedLawMaterial(law, rho, &why))
    throw ComputeError("fit (" + method + ") gave an implausible law: " + why);
}

Outcome RunDirect(const FitArgs& a, const std::vector<Profile>& profiles, double rho) {
  DirectFitOptions o;
  o.fit_offset = !a.thickness_given && !a.no_offset;
  o.offset = a.thickness_given ? units::MmToM(a.thickness_mm) / 2.0 : 0.0;
  o.fit_rotation = a.fit_rotation;
  o.robust_scale = units::MmToM(a.robust_mm);
  std::vector<std::string> notes;
  const DirectFitSummary fit = FitDirectCheckingTilt(profiles, rho, o, &notes, &o);
  if (!fit.converged) throw ComputeError("fit: " + fit.message);
  Outcome out;
  for (const std::string& n : notes) out.notes += (out.notes.empty() ? "" : "; ") + n;
  out.law = *fit.law;
  out.kappa_max = fit.kappa_max;
  out.brief = fit.BriefReport();
  for (size_t i = 0; i < profiles.size(); ++i) {
    out.comparisons.push_back(CompareWithElastica(
        out.law, rho, profiles[i], fit.profiles[i].overhang, fit.offset, fit.rotation));
  }
  CheckFittedLaw(out.law, rho, "direct");
  out.report = FitReportJson(fit, o, rho, notes, {.robust_scale_mm = a.robust_mm});
  return out;
}

Outcome RunClapp(const std::vector<Profile>& profiles, double rho) {
  const ClappResult fit = FitClapp(profiles, rho);
  if (!fit.success || !fit.law) throw ComputeError("fit (clapp): " + fit.message);
  Outcome out;
  out.law = *fit.law;
  out.kappa_max = fit.kappa_max;
  out.brief = fit.BriefReport();
  out.comparisons = GradeClappFit(fit, profiles, rho);
  CheckFittedLaw(out.law, rho, "clapp");
  out.report = FitReportJson(fit, profiles, out.comparisons, rho);
  return out;
}

void Plot(const FitArgs& a, const std::vector<Profile>& profiles, const Outcome& o, double rho,
          const std::optional<ClappResult>& clapp, AtomicFile& out) {
  namespace chart = textile::chart;
  chart::Panel prof{.title = "Profiles: measured and fitted",
                    .x_label = "x [mm]",
                    .y_label = "y [mm]",
                    .equal_aspect = true};
  std::vector<chart::Series> models;
  for (size_t i = 0; i < profiles.size(); ++i) {
    const auto color = chart::PaletteColor(static_cast<int>(i));
    chart::Series data{.label = std::filesystem::path(profiles[i].source).filename().string(),
                       .style = chart::Series::Style::kMarkers,
                       .color = color};
    for (size_t j = 0; j < profiles[i].size(); ++j) {
      data.x.push_back(profiles[i].x[j] * 1e3);
      data.y.push_back(profiles[i].y[j] * 1e3);
    }
    // Thin dark lines on top of the dots, so that the fit is visible through the data.
    chart::Series model{.label = i == 0 ? "fitted elastica" : "",
                        .color = chart::Rgb{0.1, 0.1, 0.1},
                        .line_width = 1.2};
    for (size_t j = 0; j < o.comparisons[i].model_x.size(); ++j) {
      model.x.push_back(o.comparisons[i].model_x[j] * 1e3);
      model.y.push_back(o.comparisons[i].model_y[j] * 1e3);
    }
    prof.series.push_back(data);
    models.push_back(model);
  }
  for (auto& m : models) prof.series.push_back(std::move(m));
  prof.notes = {"rms " + Num(o.report["rms_mm"].get<double>(), 3) + " mm"};

  chart::Panel mk{.title = "Moment-curvature", .x_label = "κ [1/cm]", .y_label = "M [gf·cm/cm]"};
  const double kmax = o.kappa_max;
  const auto curve = [&](const BendingLaw& law, const std::string& label, bool dashed) {
    chart::Series s{.label = label, .dashed = dashed};
    for (int i = 0; i <= 200; ++i) {
      const double k = kmax * i / 200.0;
      s.x.push_back(units::SiCurvatureToKes(k));
      s.y.push_back(units::SiMomentToKes(law.Moment(k)));
    }
    return s;
  };
  mk.series.push_back(curve(o.law, a.method == "direct" ? "direct fit" : "Clapp fit", false));
  if (clapp && clapp->law) {
    chart::Series pts{.label = "Clapp (κ, M) points",
                      .style = chart::Series::Style::kMarkers,
                      .color = chart::Rgb{0.6, 0.6, 0.6}};
    for (const auto& p : clapp->points) {
      pts.x.push_back(units::SiCurvatureToKes(p.kappa));
      pts.y.push_back(units::SiMomentToKes(p.moment));
    }
    mk.series.push_back(pts);
    if (a.method == "direct") mk.series.push_back(curve(*clapp->law, "Clapp's law", true));
  }
  mk.notes = {"b1 = " + Num(o.law.b1_kes(), 4) + " gf·cm",
              "b2 = " + Num(o.law.b2_kes(), 4) + " gf·cm",
              "c1 = " + Num(o.law.c1_kes(), 4) + " gf·cm²",
              "κ0 = " + Num(units::SiCurvatureToKes(o.law.kappa0()), 4) + " /cm"};
  chart::WritePng({.title = "textile fit (" + a.method + "), " + Num(a.gsm) + " g/m²",
                   .width_px = 1300,
                   .height_px = 600,
                   .columns = 2,
                   .panels = {prof, mk}},
                  out);
  (void)rho;
}

void Run(const FitArgs& a) {
  if (!std::isfinite(a.gsm) || a.gsm <= 0.0) throw InputError("--gsm must be a number > 0 (g/m²)");
  if (a.gsm < 1.0 || a.gsm > 1e4)
    throw InputError("--gsm " + Num(a.gsm) + " g/m² is implausible (1 .. 10000)");
  if (!(a.robust_mm == 0.0 || (a.robust_mm >= 0.001 && a.robust_mm <= 100.0)))
    throw InputError("--robust-mm must be 0 (off) or in [0.001, 100] mm");
  if (a.thickness_given && !(a.thickness_mm > 0.0 && a.thickness_mm <= 6.0))
    throw InputError(
        "--thickness-mm must lie in (0, 6] mm (a thicker strip's mid-line starts above what a "
        "profile may rise), got " +
        Num(a.thickness_mm));
  if (a.thickness_given && a.no_offset)
    throw InputError("--thickness-mm and --no-offset contradict each other (offset t/2 vs 0)");
  // Clapp's polynomial takes the profiles as they are: no offset, rotation or robust loss.
  if (a.method == "clapp") {
    for (const auto& [given, flag] :
         {std::pair{a.thickness_given, "--thickness-mm"}, std::pair{a.no_offset, "--no-offset"},
          std::pair{a.fit_rotation, "--fit-rotation"}, std::pair{a.robust_given, "--robust-mm"}})
      if (given)
        throw InputError(
            std::string(flag) +
            ": an option of the direct fit; --method clapp fits the profiles as they are");
  }
  const double rho = units::GsmToSi(a.gsm);
  // Check the outputs before the work (photos included), so that a bad path fails fast; they appear
  // together.
  std::vector<std::pair<std::string, std::string>> inputs{{"--rig", a.photo.rig_file}};
  for (const std::string& in : a.inputs) inputs.emplace_back("(a profile or photo)", in);
  CheckDistinctOutputs({{"-o", a.out}, {"--plot", a.plot}}, inputs);
  if (!a.plot.empty()) textile::chart::CheckPngPath(a.plot);
  AtomicFileSet outputs;
  AtomicFile& material_file = outputs.Add(a.out);
  AtomicFile* plot_file = a.plot.empty() ? nullptr : &outputs.Add(a.plot);

  const std::vector<LoadedProfile> loaded = LoadProfileInputs(a.inputs, a.photo.Options());
  std::vector<Profile> profiles;
  std::ostringstream
      extracted;  // printed once the fit has succeeded: a failed run's stdout stays empty
  std::string photo_warnings;  // what may explain a failed fit, for its one error line
  nlohmann::json photos = nlohmann::json::array();
  for (const auto& in : loaded) {
    profiles.push_back(in.profile);
    if (!in.extraction) continue;
    const ExtractionSummary& r = *in.extraction;
    photos.push_back(ExtractionJson(in));
    if (!a.json) {
      extracted << "extracted " << in.source << ": " << r.rig_type << " rig, " << r.polarity
                << " strip, L = " << Num(r.length_mm, 4) << " mm, tip (" << Num(r.tip_mm.x(), 4)
                << ", " << Num(r.tip_mm.y(), 4) << ") mm, " << r.profile.size() << " points\n";
      for (const auto& w : r.warnings) extracted << "  warning: " << w.text << "\n";
    }
    for (const auto& w : r.warnings) photo_warnings += "; " + in.source + ": " + w.text;
  }
  Outcome o;
  try {
    o = a.method == "direct" ? RunDirect(a, profiles, rho) : RunClapp(profiles, rho);
  } catch (const ComputeError& e) {
    if (photo_warnings.empty()) throw;
    throw ComputeError(e.what() + std::string(" (extraction warnings") + photo_warnings + ")");
  }

  o.report["inputs"] = a.inputs;
  if (!photos.empty()) o.report["photos"] = photos;
  o.report["areal_density_gsm"] = a.gsm;

  std::optional<ClappResult> clapp;
  if (!a.plot.empty()) {
    try {
      clapp = FitClapp(profiles, rho);
    } catch (const InputError&) {
      // Clapp's points are only decoration here; a profile it cannot use is not an error.
    }
    Plot(a, profiles, o, rho, clapp, *plot_file);
  }

  Material m = LawOnlyMaterial(o.law, rho);
  m.name = a.name.empty() ? "fitted from " + InputStem(a.inputs.front()) : a.name;
  m.fit = o.report;
  material_file.Write(MaterialToJson(m).dump(2) + "\n");
  outputs.Commit();

  if (a.json) {
    PrintJson({{"material_file", a.out}, {"material", MaterialToJson(m)}});
    return;
  }
  std::cout << extracted.str() << o.brief << "\n";
  std::cout << "law: b1 = " << Num(o.law.b1_kes(), 5) << " gf·cm, b2 = " << Num(o.law.b2_kes(), 5)
            << " gf·cm, c1 = " << Num(o.law.c1_kes(), 5)
            << " gf·cm²  (kappa0 = " << Num(units::SiCurvatureToKes(o.law.kappa0()), 4)
            << " /cm)\n";
  std::cout << "profile rms: " << Num(o.report["rms_mm"].get<double>(), 3) << " mm\n";
  if (o.report.contains("bending_length_mm")) {
    std::cout << "classic 41.5° test of this law: c = "
              << Num(o.report["bending_length_mm"].get<double>(), 4)
              << " mm, G = " << Num(o.report["flexural_rigidity_uNm"].get<double>(), 4)
              << " µN·m = " << Num(o.report["flexural_rigidity_mgcm"].get<double>(), 4)
              << " mg·cm (G/b1 = " << Num(o.report["G_over_b1"].get<double>(), 3) << ")\n";
  }
  if (!o.notes.empty()) std::cout << "note: " << o.notes << "\n";
  std::cout << "wrote " << a.out << (a.plot.empty() ? "" : " and " + a.plot) << "\n";
}

}  // namespace

void RegisterFit(CLI::App& app) {
  auto a = std::make_shared<FitArgs>();
  CLI::App* sub = AddSubcommand(
      app, "fit", "Fit the bending law {b1, b2, c1} to cantilever profiles or photos of one strip",
      "textile fit samples/profiles/pabst-fig8_L0*.profile.csv --gsm 200 -o fitted.json --plot "
      "fit.png\n"
      "  textile fit samples/photos/pabst-fig8_L0*.jpg --rig "
      "samples/photos/pabst-fig8.rig-truth.json --gsm 200 -o fitted.json");
  sub->add_option(
         "inputs", a->inputs,
         "Profile CSV files (s_mm,x_mm,y_mm) or photos (PNG, JPEG, TIFF, BMP; need --rig or "
         "--mm-per-px) of the same strip")
      ->required();
  sub->add_option("--gsm", a->gsm, "Areal density of the fabric [g/m²]")->required();
  sub->add_option("--method", a->method,
                  "direct (elastica fit, default) or clapp (Clapp et al. 1990)")
      ->check(CLI::IsMember({"direct", "clapp"}));
  sub->add_option("-o,--out", a->out, "Material JSON to write (with the fit report)")->required();
  sub->add_option("--plot", a->plot,
                  "Write measured vs fitted profiles and the M-κ curve to a PNG");
  sub->add_option("--name", a->name, "Material name to store");
  sub->add_option(
      "--thickness-mm", a->thickness_mm,
      "Measured strip thickness [mm]: fixes the mid-line offset to t/2 (default: fitted)");
  sub->add_flag("--no-offset", a->no_offset, "Force the curve through the edge (offset 0)");
  sub->add_flag(
      "--fit-rotation", a->fit_rotation,
      "Always fit a small rig rotation (without it, one is fitted when the data show a tilt)");
  sub->add_option("--robust-mm", a->robust_mm,
                  "Cauchy loss scale per point [mm]; 0 = plain least squares (default 0.5)");
  sub->add_flag("--json", a->json, "Print one JSON object instead of text");
  AddPhotoFlags(sub, &a->photo);
  CLI::Option* thickness = sub->get_option("--thickness-mm");
  CLI::Option* robust = sub->get_option("--robust-mm");
  sub->callback([a, thickness, robust] {
    a->thickness_given = thickness->count() > 0;
    a->robust_given = robust->count() > 0;
    Run(*a);
  });
}

namespace {
const bool kRegistered = AddCommand(40, RegisterFit);
}  // namespace

}  // namespace textile::cli
