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
#include "textile/fit/fit_material.h"
#include "textile/fit/fit_report.h"
#include "textile/fit/profile.h"
#include "textile/fit/profile_compare.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/join_text.h"
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

void Plot(const FitArgs& a, const std::vector<Profile>& profiles, const FittedMaterial& o,
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
  prof.notes = {"rms " + Num(o.material.fit["rms_mm"].get<double>(), 3) + " mm"};

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
  mk.series.push_back(curve(o.material.bending, a.method == "direct" ? "direct fit" : "Clapp fit", false));
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
  const BendingLaw& law = o.material.bending;
  mk.notes = {"b1 = " + Num(law.b1_kes(), 4) + " gf·cm",
              "b2 = " + Num(law.b2_kes(), 4) + " gf·cm",
              "c1 = " + Num(law.c1_kes(), 4) + " gf·cm²",
              "κ0 = " + Num(units::SiCurvatureToKes(law.kappa0()), 4) + " /cm"};
  chart::WritePng({.title = "textile fit (" + a.method + "), " + Num(a.gsm) + " g/m²",
                   .width_px = 1300,
                   .height_px = 600,
                   .columns = 2,
                   .panels = {prof, mk}},
                  out);
}

FitMaterialOptions Options(const FitArgs& a) {
  FitMaterialOptions o;
  if (!std::isfinite(a.gsm) || a.gsm <= 0.0) throw InputError("--gsm must be a number > 0 (g/m²)");
  o.areal_density = units::GsmToSi(a.gsm);
  o.method = a.method == "clapp" ? FitMethod::kClapp : FitMethod::kDirect;
  if (a.thickness_given) o.thickness = units::MmToM(a.thickness_mm);
  o.no_offset = a.no_offset;
  o.fit_rotation = a.fit_rotation;
  o.robust_scale_mm = a.robust_mm;
  o.robust_given = a.robust_given;
  o.name = a.name;
  CheckFitMaterialOptions(o);
  return o;
}

void Run(const FitArgs& a) {
  const FitMaterialOptions options = Options(a);
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
  FittedMaterial o;
  try {
    o = FitMaterial(profiles, options);
  } catch (const ComputeError& e) {
    if (photo_warnings.empty()) throw;
    throw ComputeError(e.what() + std::string(" (extraction warnings") + photo_warnings + ")");
  }

  Material& m = o.material;
  m.fit["inputs"] = a.inputs;
  if (!photos.empty()) m.fit["photos"] = photos;
  m.fit["areal_density_gsm"] = a.gsm;

  std::optional<ClappResult> clapp;
  if (!a.plot.empty()) {
    try {
      clapp = FitClapp(profiles, options.areal_density);
    } catch (const InputError&) {
      // Clapp's points are only decoration here; a profile it cannot use is not an error.
    }
    Plot(a, profiles, o, clapp, *plot_file);
  }

  material_file.Write(MaterialToJson(m).dump(2) + "\n");
  outputs.Commit();

  if (a.json) {
    PrintJson({{"material_file", a.out}, {"material", MaterialToJson(m)}});
    return;
  }
  std::cout << extracted.str() << o.brief << "\n";
  const BendingLaw& law = m.bending;
  const nlohmann::json& report = m.fit;
  std::cout << "law: b1 = " << Num(law.b1_kes(), 5) << " gf·cm, b2 = " << Num(law.b2_kes(), 5)
            << " gf·cm, c1 = " << Num(law.c1_kes(), 5)
            << " gf·cm²  (kappa0 = " << Num(units::SiCurvatureToKes(law.kappa0()), 4)
            << " /cm)\n";
  std::cout << "profile rms: " << Num(report["rms_mm"].get<double>(), 3) << " mm\n";
  if (report.contains("bending_length_mm")) {
    std::cout << "classic 41.5° test of this law: c = "
              << Num(report["bending_length_mm"].get<double>(), 4)
              << " mm, G = " << Num(report["flexural_rigidity_uNm"].get<double>(), 4)
              << " µN·m = " << Num(report["flexural_rigidity_mgcm"].get<double>(), 4)
              << " mg·cm (G/b1 = " << Num(report["G_over_b1"].get<double>(), 3) << ")\n";
  }
  if (!o.notes.empty()) std::cout << "note: " << JoinText(o.notes, "; ") << "\n";
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
