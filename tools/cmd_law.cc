// textile law: inspect a material's bending law (κ0, M0 or a spline's knots, M and B at given
// curvatures) and plot M-κ and B-κ.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>

#include "common/atomic_file.h"
#include "common/chart_file.h"
#include "common/cli.h"
#include "textile/fit/moment_curve.h"
#include "textile/sim/core/error.h"
#include "textile/sim/law/material.h"
#include "textile/sim/core/units.h"

namespace textile::cli {
namespace {

struct LawArgs {
  std::string material;
  std::vector<double> kappa;     // as given, in kappa_unit
  std::string kappa_unit = "cm";  // "cm": 1/cm (KES); "m": 1/m
  std::string plot;
  std::vector<std::string> measured;  // (κ, M) CSVs drawn beside the law
  bool log_kappa = false;             // logarithmic κ axes on the chart
  bool json = false;
};

// Which part of the law κ falls in: the quadratic (a spline's cubic pieces) or the line.
const char* Branch(const BendingLaw& law, double k) {
  if (std::abs(k) > law.kappa0()) return "linear";
  return law.is_spline() ? "spline" : "quadratic";
}

nlohmann::json PointJson(const BendingLaw& law, double k) {
  return {{"kappa_per_m", k},         {"kappa_per_cm", units::SiCurvatureToKes(k)},
          {"M_N", law.Moment(k)},     {"M_gfcm_per_cm", units::SiMomentToKes(law.Moment(k))},
          {"B_Nm", law.Stiffness(k)}, {"B_gfcm", units::SiStiffnessToKes(law.Stiffness(k))},
          {"branch", Branch(law, k)}};
}

// A spline law: its knots, B(0), and the line past the last knot.
nlohmann::json SplineLawJson(const BendingLaw& law, const std::vector<double>& kappas) {
  nlohmann::json j = {{"law", "spline"},
                      {"B0_gfcm", law.b1_kes()},
                      {"B0_Nm", law.b1()},
                      {"kappa_end_per_cm", units::SiCurvatureToKes(law.kappa0())},
                      {"kappa_end_per_m", law.kappa0()},
                      {"M_end_gfcm_per_cm", units::SiMomentToKes(law.moment_at_kappa0())},
                      {"M_end_N", law.moment_at_kappa0()},
                      {"B_end_gfcm", law.b2_kes()},
                      {"B_end_Nm", law.b2()}};
  j["knots"] = nlohmann::json::array();
  for (double k : law.knot_kappa()) j["knots"].push_back(PointJson(law, k));
  j["points"] = nlohmann::json::array();
  for (double k : kappas) j["points"].push_back(PointJson(law, k));
  return j;
}

nlohmann::json LawJson(const BendingLaw& law, const std::vector<double>& kappas) {
  if (law.is_spline()) return SplineLawJson(law, kappas);
  nlohmann::json j = {
      {"b1_gfcm", law.b1_kes()}, {"b2_gfcm", law.b2_kes()}, {"c1_gfcm2", law.c1_kes()},
      {"b1_Nm", law.b1()}, {"b2_Nm", law.b2()}, {"c1_Nm2", law.c1()},
      // JSON has no infinity: κ0 = ∞ (c1 = 0) is written as null with a flag.
      {"kappa0_per_m", std::isfinite(law.kappa0()) ? nlohmann::json(law.kappa0()) : nlohmann::json()},
      {"kappa0_per_cm", std::isfinite(law.kappa0())
                            ? nlohmann::json(units::SiCurvatureToKes(law.kappa0()))
                            : nlohmann::json()},
      {"kappa0_infinite", std::isinf(law.kappa0())},
      {"M0_N", law.moment0()},
      {"M0_gfcm_per_cm", units::SiMomentToKes(law.moment0())}};
  j["points"] = nlohmann::json::array();
  for (double k : kappas) j["points"].push_back(PointJson(law, k));
  return j;
}

void PrintPoints(const BendingLaw& law, const std::vector<double>& kappas) {
  std::printf("  %10s %10s %14s %12s %12s %12s  %s\n", "κ [1/cm]", "κ [1/m]", "M [gf·cm/cm]",
              "M [N]", "B [gf·cm]", "B [N·m]", "branch");
  for (double k : kappas) {
    std::printf("  %10.4g %10.4g %14.6g %12.5g %12.6g %12.5g  %s\n", units::SiCurvatureToKes(k), k,
                units::SiMomentToKes(law.Moment(k)), law.Moment(k),
                units::SiStiffnessToKes(law.Stiffness(k)), law.Stiffness(k), Branch(law, k));
  }
}

void PrintSplineLawText(const std::string& title, const BendingLaw& law,
                        const std::vector<double>& kappas) {
  std::cout << title << ": monotone spline through " << law.knot_kappa().size()
            << " knots (Steffen), B(0) = " << Num(law.b1_kes()) << " gf·cm (" << Num(law.b1())
            << " N·m)\n  beyond the last knot, kappa = "
            << Num(units::SiCurvatureToKes(law.kappa0())) << " /cm (" << Num(law.kappa0())
            << " /m): linear, B = " << Num(law.b2_kes()) << " gf·cm (" << Num(law.b2())
            << " N·m)\n  knots:\n";
  PrintPoints(law, law.knot_kappa());
  std::cout << "  at the curvatures asked:\n";
  PrintPoints(law, kappas);
  std::cout.flush();
}

void PrintLawText(const std::string& title, const BendingLaw& law, const std::vector<double>& kappas) {
  if (law.is_spline()) return PrintSplineLawText(title, law, kappas);
  std::cout << title << ": b1 = " << Num(law.b1_kes()) << " gf·cm, b2 = " << Num(law.b2_kes())
            << " gf·cm, c1 = " << Num(law.c1_kes()) << " gf·cm²   (SI: " << Num(law.b1()) << ", "
            << Num(law.b2()) << " N·m, " << Num(law.c1()) << " N·m²)\n";
  if (law.kappa0() == 0.0) {
    std::cout << "  kappa0 = 0 (b1 = b2): linear law M = b2 kappa\n";
  } else if (std::isinf(law.kappa0())) {
    std::cout << "  kappa0 = inf (c1 = 0): linear law M = b1 kappa\n";
  } else {
    std::cout << "  kappa0 = " << Num(units::SiCurvatureToKes(law.kappa0())) << " /cm ("
              << Num(law.kappa0()) << " /m), M0 = " << Num(units::SiMomentToKes(law.moment0()))
              << " gf·cm/cm (" << Num(law.moment0()) << " N)\n";
  }
  PrintPoints(law, kappas);
  std::cout.flush();
}

// Curvature i of 0..n up to kappa_max [1/m]: even steps, or four decades in even ratios.
double SampleKappa(int i, int n, double kappa_max, bool log_kappa) {
  if (!log_kappa) return kappa_max * i / n;
  return kappa_max * std::pow(10.0, -4.0 * (1.0 - static_cast<double>(i) / n));
}

void Plot(const Material& m, const std::string& material_path, double kappa_max,
          const std::vector<MomentCurvePairs>& measured, bool log_kappa, const std::string& path) {
  namespace chart = textile::chart;
  chart::Panel mk{.title = "Moment-curvature", .x_label = "κ [1/cm]", .y_label = "M [gf·cm/cm]",
                  .log_x = log_kappa};
  chart::Panel bk{.title = "Bending stiffness", .x_label = "κ [1/cm]", .y_label = "B = dM/dκ [gf·cm]",
                  .log_x = log_kappa, .log_y = log_kappa};
  const bool directions = m.bending_weft || m.bending_bias;
  std::vector<std::pair<std::string, BendingLaw>> laws = {
      {directions ? "warp" : "law", m.EffectiveLaw()}};
  if (m.bending_weft) laws.emplace_back("weft", m.EffectiveWeftLaw());
  if (m.bending_bias) laws.emplace_back("bias (measured)", *m.EffectiveBiasLaw());
  constexpr int kSamples = 400;
  for (const auto& [label, law] : laws) {
    chart::Series sm{.label = label}, sb{.label = label};
    for (int i = 0; i <= kSamples; ++i) {
      const double k = SampleKappa(i, kSamples, kappa_max, log_kappa);
      sm.x.push_back(units::SiCurvatureToKes(k));
      sm.y.push_back(units::SiMomentToKes(law.Moment(k)));
      sb.x.push_back(units::SiCurvatureToKes(k));
      sb.y.push_back(units::SiStiffnessToKes(law.Stiffness(k)));
    }
    const auto color = chart::PaletteColor(static_cast<int>(mk.series.size() / 2));
    sm.color = sb.color = color;
    mk.series.push_back(sm);
    bk.series.push_back(sb);
    if (law.is_spline()) {
      chart::Series p{.label = "knots (" + label + ")",
                      .style = chart::Series::Style::kMarkers,
                      .color = color};
      chart::Series pb = p;
      for (double k : law.knot_kappa()) {
        if (k > kappa_max) break;
        p.x.push_back(units::SiCurvatureToKes(k));
        p.y.push_back(units::SiMomentToKes(law.Moment(k)));
        pb.x.push_back(units::SiCurvatureToKes(k));
        pb.y.push_back(units::SiStiffnessToKes(law.Stiffness(k)));
      }
      mk.series.push_back(p);
      bk.series.push_back(pb);
      mk.notes.push_back(label + ": spline, " + std::to_string(law.knot_kappa().size()) +
                         " knots, B(0) = " + Num(law.b1_kes(), 4) +
                         ", B past the last = " + Num(law.b2_kes(), 4) + " gf·cm");
      continue;
    }
    if (law.kappa0() > 0.0 && law.kappa0() <= kappa_max) {
      const double k0 = law.kappa0();
      chart::Series p{.label = "κ0 (" + label + ")",
                      .x = {units::SiCurvatureToKes(k0)},
                      .y = {units::SiMomentToKes(law.Moment(k0))},
                      .style = chart::Series::Style::kMarkers,
                      .color = color};
      mk.series.push_back(p);
      p.y = {units::SiStiffnessToKes(law.Stiffness(k0))};
      bk.series.push_back(p);
    }
    mk.notes.push_back(label + ": b1 = " + Num(law.b1_kes(), 4) + ", b2 = " + Num(law.b2_kes(), 4) +
                       " gf·cm, c1 = " + Num(law.c1_kes(), 4) + " gf·cm²");
  }
  // The fitted law's 1-σ band (linear propagation of its covariance), up to the curvatures
  // its data reached; measured pairs as markers.
  std::string no_band;
  if (!measured.empty() || m.fit.is_object()) {
    if (const auto cov = m.bending_weft || m.bending_bias
                             ? std::nullopt
                             : FitCovariance(m, material_path, &no_band)) {
      const BendingLaw law = m.EffectiveLaw();
      const double reach = std::min(kappa_max, FitCurvatureReach(m).value_or(kappa_max));
      chart::Series lo{.label = "±1σ of the fit", .dashed = true}, hi{.dashed = true};
      lo.color = hi.color = chart::PaletteColor(0);
      lo.line_width = hi.line_width = 1.0;
      constexpr int kBand = 200;
      for (int i = 0; i <= kBand; ++i) {
        const double k = SampleKappa(i, kBand, reach, log_kappa);
        const double sd = MomentSigma(law, *cov * m.beta * m.beta, k);
        lo.x.push_back(units::SiCurvatureToKes(k));
        hi.x.push_back(units::SiCurvatureToKes(k));
        lo.y.push_back(units::SiMomentToKes(law.Moment(k) - sd));
        hi.y.push_back(units::SiMomentToKes(law.Moment(k) + sd));
      }
      mk.series.push_back(lo);
      mk.series.push_back(hi);
    } else if (!measured.empty()) {
      mk.notes.push_back(no_band);
    }
  }
  for (const MomentCurvePairs& p : measured) {
    chart::Series s{.label = std::filesystem::path(p.source).filename().string(),
                    .style = chart::Series::Style::kMarkers};
    for (size_t i = 0; i < p.kappa.size(); ++i) {
      s.x.push_back(units::SiCurvatureToKes(p.kappa[i]));
      s.y.push_back(units::SiMomentToKes(p.moment[i]));
    }
    mk.series.push_back(s);
  }
  if (m.beta != 1.0) mk.notes.push_back("β = " + Num(m.beta) + " applied");
  if (!log_kappa) {  // B from 0 so that ratios read true
    double b_max = 0.0;
    for (const auto& s : bk.series)
      for (double v : s.y) b_max = std::max(b_max, v);
    bk.y_range = chart::Range{0.0, 1.15 * b_max};
  }
  chart::WritePng({.title = (m.name.empty() ? "Bending law" : m.name) + "  (" +
                            Num(units::SiToGsm(m.areal_density)) + " g/m²)",
                   .width_px = 1200,
                   .height_px = 560,
                   .columns = 2,
                   .panels = {mk, bk}},
                  path);
}

void Run(const LawArgs& a) {
  std::vector<std::pair<std::string, std::string>> inputs = {{"--material", a.material}};
  for (const std::string& f : a.measured) inputs.emplace_back("--measured", f);
  CheckDistinctOutputs({{"--plot", a.plot}}, inputs);
  if (!a.measured.empty() && a.plot.empty())
    throw InputError("--measured: drawn on the chart only; give --plot FILE.png");
  const Material m = ReadMaterial(a.material);
  std::vector<double> kappas;
  for (double k : a.kappa) {
    if (!std::isfinite(k)) throw InputError("--kappa: values must be finite numbers");
    if (std::abs(k) > 1e6) throw InputError("--kappa: " + Num(k) + " is beyond any textile curvature");
    kappas.push_back(a.kappa_unit == "cm" ? units::KesCurvatureToSi(k) : k);
  }
  const BendingLaw law = m.EffectiveLaw();
  if (kappas.empty()) {
    for (double k : {0.25, 0.5, 1.0, 2.0}) kappas.push_back(units::KesCurvatureToSi(k));
    // κ0 of a Pabst law; a spline's knots are listed apart.
    if (!law.is_spline() && law.kappa0() > 0.0 && std::isfinite(law.kappa0()))
      kappas.push_back(law.kappa0());
    std::sort(kappas.begin(), kappas.end());
  }
  double kappa_max = units::KesCurvatureToSi(2.0);
  for (double k : kappas) kappa_max = std::max(kappa_max, std::abs(k));
  if (std::isfinite(law.kappa0())) kappa_max = std::max(kappa_max, 1.5 * law.kappa0());

  std::vector<MomentCurvePairs> measured;
  if (!a.measured.empty()) {
    // The chart spans the measured pairs and the fit's data, not the default 2 /cm.
    double reach = 0.0;
    for (const std::string& f : a.measured) {
      measured.push_back(ReadMomentCurvatureCsv(f));
      for (double k : measured.back().kappa) reach = std::max(reach, k);
    }
    if (const auto fit_reach = FitCurvatureReach(m)) reach = std::max(reach, *fit_reach);
    if (reach > 0.0) kappa_max = 1.1 * reach;
  }
  if (!a.plot.empty()) Plot(m, a.material, kappa_max, measured, a.log_kappa, a.plot);

  if (a.json) {
    nlohmann::json j = {{"material", a.material},
                        {"name", m.name},
                        {"areal_density_gsm", units::SiToGsm(m.areal_density)},
                        {"beta", m.beta},
                        {"law", LawJson(law, kappas)}};
    if (m.bending_weft) j["law_weft"] = LawJson(m.EffectiveWeftLaw(), kappas);
    if (m.bending_bias) j["law_bias"] = LawJson(*m.EffectiveBiasLaw(), kappas);
    if (!a.plot.empty()) j["plot"] = a.plot;
    PrintJson(j);
    return;
  }
  std::cout << "material: " << (m.name.empty() ? a.material : m.name) << "  [" << a.material
            << "]\nareal density: " << Num(units::SiToGsm(m.areal_density)) << " g/m²"
            << (m.beta != 1.0 ? ", beta = " + Num(m.beta) + " (applied below)" : "") << "\n";
  PrintLawText(m.bending_weft || m.bending_bias ? "warp law" : "law", law, kappas);
  if (m.bending_weft) PrintLawText("weft law", m.EffectiveWeftLaw(), kappas);
  if (m.bending_bias) PrintLawText("bias law (measured)", *m.EffectiveBiasLaw(), kappas);
  if (!a.plot.empty()) std::cout << "plot: " << a.plot << "\n";
}

}  // namespace

void RegisterLaw(CLI::App& app) {
  auto args = std::make_shared<LawArgs>();
  CLI::App* sub = AddSubcommand(
      app, "law", "Inspect a material's moment-curvature law: kappa0, M0, M and B; plot M-κ and B-κ",
      "textile law --material samples/materials/pabst-fig8.json --kappa 0.5 1 2 --plot law.png");
  sub->add_option("-m,--material", args->material, "Material JSON file (docs/spec/cli.md format)")
      ->required();
  sub->add_option("-k,--kappa", args->kappa,
                  "Curvatures to evaluate (default 0.25 0.5 1 2 /cm and kappa0; a spline also "
                  "lists its knots)");
  sub->add_option("--kappa-unit", args->kappa_unit, "Unit of --kappa: cm (1/cm, KES; default) or m (1/m)")
      ->check(CLI::IsMember({"cm", "m"}));
  sub->add_option("--plot", args->plot, "Write an M-κ / B-κ chart to this PNG file");
  sub->add_flag("--log-kappa", args->log_kappa,
                "Logarithmic κ axes on the chart (and B): for laws with a knee at a small curvature");
  sub->add_option("--measured", args->measured,
                  "CSV(s) of measured (κ, M) pairs to draw beside the law (header kappa_per_m,M_N "
                  "or kappa_per_cm,M_gfcm_per_cm; other columns ignored); needs --plot");
  sub->add_flag("--json", args->json, "Print one JSON object instead of text");
  sub->callback([args] { Run(*args); });
}

namespace {
const bool kRegistered = AddCommand(10, RegisterLaw);
}  // namespace

}  // namespace textile::cli
