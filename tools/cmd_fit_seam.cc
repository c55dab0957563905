// textile fit-seam: ACPM rays or a (d, factor[, sd]) CSV -> the seam influence factor
// B_f(d) = a2 d² + a1 d + a0 (Pabst et al. section 4.2, Table 2) with covariance and range,
// written as a seam file (libsim seam.h) of type "fitted" with a `fit` report.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <vector>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "textile/fit/seam_fit.h"
#include "textile/sim/core/error.h"

namespace textile::cli {
namespace {

struct FitSeamArgs {
  std::string input, out, name;
  std::optional<int> layers;  // not given: from the ACPM result's seam, else required
  std::optional<double> influence_mm;  // not given: the data's range
  bool strict = false, json = false;
};

void Run(const FitSeamArgs& a) {
  CheckDistinctOutputs({{"-o", a.out}}, {{"(the input)", a.input}});
  const SeamMeasurement m = ReadSeamMeasurement(a.input);
  SeamFitOptions o;
  o.name = a.name;
  if (a.influence_mm) o.influence_mm = *a.influence_mm;
  // The ACPM result's factors were simulated with its seam's layers (the band's extra plies
  // load the strip): a seam file with other layers would not describe what was measured.
  if (a.layers && m.layers != 0 && *a.layers != m.layers)
    throw InputError("--layers " + std::to_string(*a.layers) + ": " + a.input +
                     " records seam.profile.layers " + std::to_string(m.layers) +
                     " (its factors were simulated with that seam); leave --layers out");
  o.layers = a.layers ? *a.layers : m.layers;
  if (!a.layers && o.layers == 0)
    throw InputError("--layers: required for " + a.input +
                     " (the seam's fabric layers, Table 1: A 2, B 3, C 4)");
  if (std::string why; !o.Check(&why)) throw InputError("--layers/--influence-mm: " + why);
  SeamFitSummary fit;
  try {
    fit = FitSeamFactor(m.samples, o);
  } catch (const InputError& e) {
    throw InputError(a.input + ": " + e.what());
  }
  if (fit.poor && a.strict) throw ComputeError(a.input + ": poor fit (--strict): " + fit.poor_reason);
  nlohmann::json seam = SeamProfileToJson(fit.profile);
  seam["source"] = a.input;
  WriteFileAtomically(a.out, seam.dump(2) + "\n");
  if (fit.poor) Info("warning: " + a.input + ": poor fit: " + fit.poor_reason);
  for (const Note& note : fit.notes) Info("note: " + a.input + ": " + note.text);

  if (a.json) {
    PrintJson({{"input", a.input}, {"output", a.out}, {"seam", seam}});
    return;
  }
  const SeamProfile& p = fit.profile;
  std::cout << "fit-seam: " << fit.num_points << " points from " << a.input << "\n"
            << fit.BriefReport() << "\n"
            << "influence range " << Num(p.influence_mm) << " mm ("
            << (fit.influence_from_data ? "the data's" : "--influence-mm") << "), fade "
            << Num(p.fade_mm) << " mm: S = max(1, B_f) up to there, then to 1 by "
            << Num(p.influence_mm + p.fade_mm) << " mm\n"
            << "  d [mm]   B_f(d)        S(d)\n";
  std::vector<double> ds{0.0, 10.0, 25.0, 50.0, 75.0, 100.0};
  ds.push_back(p.influence_mm);
  ds.push_back(p.influence_mm + p.fade_mm);
  std::sort(ds.begin(), ds.end());
  ds.erase(std::unique(ds.begin(), ds.end()), ds.end());
  for (double d : ds) {
    if (d > p.influence_mm + p.fade_mm) break;
    // Beyond d_max the polynomial is not used (the fade is): no B_f shown there.
    if (d <= p.influence_mm)
      std::printf("  %6.1f   %-10.4f    %.4f\n", d, p.StiffnessFactor(d), p.Multiplier(d));
    else
      std::printf("  %6.1f   %-10s    %.4f\n", d, "-", p.Multiplier(d));
  }
  std::cout << "wrote " << a.out << "\n";
}

}  // namespace

void RegisterFitSeam(CLI::App& app) {
  auto a = std::make_shared<FitSeamArgs>();
  CLI::App* sub = AddSubcommand(
      app, "fit-seam",
      "ACPM rays or a d_mm,factor[,sd] CSV -> seam factor B_f(d) = a2 d² + a1 d + a0 (GSL weighted "
      "least squares, covariance, range) as a seam file",
      "textile fit-seam acpm-result.json -o seam.json\n"
      "  textile fit-seam factors.csv --layers 4 --name 'denim double lap' -o seam.json");
  sub->add_option("input", a->input, "ACPM result JSON (rays with d_mm, factor) or CSV d_mm,factor[,sd]")
      ->required();
  sub->add_option("-o,--out", a->out, "Seam JSON to write (type \"fitted\", with a fit report)")->required();
  sub->add_option("--layers", a->layers,
                  "Fabric layers in the seam (A 2, B 3, C 4); default: the ACPM result's seam");
  sub->add_option("--name", a->name, "Name to store in the seam file");
  sub->add_option("--influence-mm", a->influence_mm,
                  "Influence range d_max of the written profile [mm] (default: the largest d "
                  "fitted; beyond it S fades to 1 without extrapolating the fit)");
  sub->add_flag("--strict", a->strict, "A poor fit is an error (exit 3, nothing written)");
  sub->add_flag("--json", a->json, "Print one JSON object instead of text");
  sub->callback([a] { Run(*a); });
}

namespace {
const bool kRegistered = AddCommand(45, RegisterFitSeam);
}  // namespace

}  // namespace textile::cli
