// The `textile` shell, `textile law` and two quick benchmarks (`textile bench`), through the
// real executable.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "run_cli.h"

namespace textile {
namespace {

using testing::CountLines;
using testing::RunTextile;
using testing::Scratch;
namespace fs = std::filesystem;

TEST(Cli, VersionAndHelp) {
  const auto v = RunTextile("--version", "version");
  EXPECT_EQ(v.exit_code, 0);
  EXPECT_NE(v.out.find("textile 0."), std::string::npos) << v.out;
  const auto h = RunTextile("--help", "help");
  EXPECT_EQ(h.exit_code, 0);
  EXPECT_NE(h.out.find("law"), std::string::npos);
}

// The BLAS kernels (tools/common/blas_kernels.h): on an x86-64 CPU with AVX2 + FMA, OpenBLAS
// does not run its SSE3 "Prescott" kernels (0.3.21 picks them for this machine's CPU model);
// a user's OPENBLAS_CORETYPE wins.
TEST(Cli, VersionNamesTheBlasKernelsAndTheyUseTheCpusVectorUnits) {
  const auto v = RunTextile("--version", "version_blas", "-u OPENBLAS_CORETYPE");
  ASSERT_EQ(v.exit_code, 0);
  const size_t at = v.out.find("(BLAS: ");
  ASSERT_NE(at, std::string::npos) << v.out;
  const std::string blas = v.out.substr(at + 7, v.out.find(')', at) - at - 7);
  if (blas.rfind("OpenBLAS ", 0) != 0 || blas.find("(fixed") != std::string::npos)
    GTEST_SKIP() << "not OpenBLAS's dynamic-architecture build: " << blas;
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
    EXPECT_NE(blas, "OpenBLAS Prescott");
  }
  const auto chosen = RunTextile("--version", "version_blas_user", "OPENBLAS_CORETYPE=Prescott");
  EXPECT_NE(chosen.out.find("(BLAS: OpenBLAS Prescott)"), std::string::npos) << chosen.out;
#endif
}

TEST(Cli, EverySubcommandHelpHasAnExample) {
  const auto h = RunTextile("--help", "help_list");
  for (const char* sub : {"law", "fit", "synth-profile", "bench"}) {
    if (h.out.find(std::string("  ") + sub) == std::string::npos) continue;  // not built yet
    const auto r = RunTextile(std::string(sub) + " --help", std::string("help_") + sub);
    EXPECT_EQ(r.exit_code, 0) << sub;
    EXPECT_NE(r.out.find("Example:\n  textile " + std::string(sub)), std::string::npos)
        << sub << ": " << r.out;
  }
}

TEST(Cli, UsageErrorsExit2WithOneLine) {
  for (const char* args : {"", "no-such-command", "law", "law --material", "law --nonsense 3",
                           "law --material samples/materials/pabst-fig8.json --kappa-unit km"}) {
    const auto r = RunTextile(args, "usage");
    EXPECT_EQ(r.exit_code, 2) << "'" << args << "'";
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

TEST(CliLaw, PrintsKappa0AndTable) {
  const auto r = RunTextile("law --material samples/materials/pabst-fig8.json --kappa 1", "law_text");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("kappa0 = 0.586957 /cm"), std::string::npos) << r.out;
  // M(1/cm) = M0 + b2·1 with M0 = -(b2-b1)²/(4 c1) = -0.0108²/0.0368 gf·cm/cm.
  EXPECT_NE(r.out.find("0.0923"), std::string::npos) << r.out;
}

TEST(CliLaw, JsonHasBothUnitsAndMatchesTheLaw) {
  const auto r = RunTextile(
      "law --material samples/materials/pabst-interlining.json --kappa 0.1 1 --json", "law_json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto& law = j.at("law");
  EXPECT_NEAR(law.at("kappa0_per_cm").get<double>(), (1.8856 - 0.5168) / (2 * 2.2683), 1e-12);
  ASSERT_EQ(law.at("points").size(), 2u);
  const auto& p0 = law.at("points")[0];
  EXPECT_NEAR(p0.at("kappa_per_m").get<double>(), 10.0, 1e-12);
  // Below κ0: M = b1 κ + c1 κ² in KES.
  EXPECT_NEAR(p0.at("M_gfcm_per_cm").get<double>(), 0.5168 * 0.1 + 2.2683 * 0.01, 1e-12);
  EXPECT_EQ(p0.at("branch"), "quadratic");
  EXPECT_EQ(law.at("points")[1].at("branch"), "linear");
  EXPECT_NEAR(law.at("points")[1].at("B_gfcm").get<double>(), 1.8856, 1e-12);
}

TEST(CliLaw, KappaInPerMetre) {
  const auto r = RunTextile(
      "law --material samples/materials/pabst-dress.json --kappa 100 --kappa-unit m --json", "law_m");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["law"]["points"][0]["kappa_per_cm"].get<double>(), 1.0, 1e-15);
  EXPECT_NEAR(j["law"]["points"][0]["M_gfcm_per_cm"].get<double>(), 0.0973, 1e-12);
}

TEST(CliLaw, WritesPlot) {
  const auto d = Scratch("law_plot");
  const auto png = d / "law.png";
  const auto r = RunTextile("law --material samples/materials/pabst-fig8.json --plot '" +
                                png.string() + "'", "law_plot");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(png));
  EXPECT_GT(fs::file_size(png), 10000u);  // a real chart, not an empty image
  EXPECT_EQ(testing::ReadAll(png).substr(1, 3), "PNG");
}

TEST(CliLaw, PlotsMeasuredPairsAndTheFitsBand) {
  // A fitted material carries its covariance (fit.covariance_kes, sds on its diagonal); the
  // chart draws its band and measured pairs in either unit; without a fit report the chart
  // says there is no band.
  const auto d = Scratch("law_measured");
  const auto profiles = d / "profiles";
  ASSERT_EQ(RunTextile("synth-profile --material samples/materials/pabst-fig8.json "
                       "--overhang-mm 40 60 80 --noise-mm 0.1 -o '" + profiles.string() + "'",
                       "law_measured_synth").exit_code, 0);
  const auto fitted = d / "fitted.json";
  std::string inputs;
  for (const char* L : {"40", "60", "80"})
    inputs += " '" + (profiles / (std::string("pabst-fig8_L0") + L + "mm.profile.csv")).string() + "'";
  const auto f = RunTextile("fit" + inputs + " --gsm 200 -o '" + fitted.string() + "'", "law_measured_fit");
  ASSERT_EQ(f.exit_code, 0) << f.err;
  const auto report = nlohmann::json::parse(testing::ReadAll(fitted))["fit"];
  ASSERT_TRUE(report.contains("covariance_kes"));
  EXPECT_NEAR(std::sqrt(report["covariance_kes"][0][0].get<double>()), report["b1_sd"].get<double>(),
              1e-9 * report["b1_sd"].get<double>());
  EXPECT_EQ(report["start"], "Peirce");
  { std::ofstream(d / "si.csv") << "kappa_per_m,M_N\n0,0\n50,0.05\n100,0.09\n"; }
  { std::ofstream(d / "lab.csv") << "kappa_per_cm,M_gfcm_per_cm\n0.5,5\n1,9\n"; }
  const auto png = d / "law.png";
  const auto r = RunTextile("law --material '" + fitted.string() + "' --plot '" + png.string() +
                                "' --log-kappa --measured '" + (d / "si.csv").string() + "' '" +
                                (d / "lab.csv").string() + "'", "law_measured");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(fs::file_size(png), 10000u);
  const auto plain = RunTextile("law --material samples/materials/pabst-fig8.json --plot '" +
                                    (d / "plain.png").string() + "' --measured '" +
                                    (d / "si.csv").string() + "'", "law_measured_plain");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_TRUE(fs::exists(d / "plain.png"));
}

TEST(CliLaw, UnwritablePlotExits2AndWritesNothing) {
  const auto r = RunTextile(
      "law --material samples/materials/pabst-fig8.json --plot /nonexistent-dir/law.png", "law_bad_plot");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("/nonexistent-dir/law.png"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST(CliLaw, BadMaterialsExit2NamingFileAndField) {
  struct Case {
    const char* file;
    const char* fragment;
  };
  for (const Case& c : {Case{"kappa0-negative.json", "bending: kappa0"},
                        Case{"spline-not-monotone.json", "bending.moment[3]: 0.03 is not above"},
                        Case{"gsm-zero.json", "areal_density_gsm: must be > 0"},
                        Case{"unknown-units.json", "bending.units: unknown units"},
                        Case{"not-json.json", "not valid JSON"},
                        Case{"does-not-exist.json", "cannot open material file"}}) {
    const std::string path = std::string("tests/data/materials/") + c.file;
    const auto r = RunTextile("law --material " + path, "law_bad");
    EXPECT_EQ(r.exit_code, 2) << c.file;
    EXPECT_EQ(r.err.rfind("error: " + path + ": ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(c.fragment), std::string::npos) << r.err;
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

TEST(CliLaw, SplineMaterialPrintsItsKnotsAndTheLineBeyond) {
  const std::string knee = "law --material samples/materials/knee-spline.json --kappa 0.02 3";
  const auto t = RunTextile(knee, "law_spline_text");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_NE(t.out.find("monotone spline through 8 knots"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("B(0) = 11.6 gf·cm"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("beyond the last knot, kappa = 2 /cm"), std::string::npos) << t.out;
  const auto r =
      RunTextile(knee + " --json --plot '" + (Scratch("law_spline") / "k.png").string() + "'",
                 "law_spline_json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto law = nlohmann::json::parse(r.out).at("law");
  EXPECT_EQ(law.at("law"), "spline");
  ASSERT_EQ(law.at("knots").size(), 8u);
  EXPECT_NEAR(law.at("knots")[7].at("M_gfcm_per_cm").get<double>(), 0.72, 1e-14);
  // At a knot the spline is the knot; past the last one, the line with the last slope.
  const auto& at_knot = law.at("points")[0];
  EXPECT_NEAR(at_knot.at("M_gfcm_per_cm").get<double>(), 0.2, 1e-14);
  EXPECT_EQ(at_knot.at("branch"), "spline");
  const auto& beyond = law.at("points")[1];
  const double b_end = law.at("B_end_gfcm").get<double>();
  EXPECT_EQ(beyond.at("branch"), "linear");
  EXPECT_NEAR(beyond.at("M_gfcm_per_cm").get<double>(), 0.72 + b_end * (3.0 - 2.0), 1e-13);
  EXPECT_NEAR(beyond.at("B_gfcm").get<double>(), b_end, 1e-14);
  EXPECT_GT(law.at("B0_gfcm").get<double>() / b_end, 100.0);  // the knee
}

TEST(CliLaw, RejectsNonFiniteKappa) {
  const auto r = RunTextile("law --material samples/materials/pabst-fig8.json --kappa nan", "law_nan");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--kappa"), std::string::npos) << r.err;
}

// A benchmark's CSV (bench/bench_common.cc WriteCsv): a header line, then one line per row;
// strings are in double quotes and may hold commas (never a quote), numbers are bare.
struct Csv {
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
};

std::vector<std::string> CsvFields(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (char c : line) {
    if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

Csv ReadCsv(const fs::path& path) {
  Csv csv;
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line)) return csv;
  csv.header = CsvFields(line);
  while (std::getline(in, line)) {
    const std::vector<std::string> fields = CsvFields(line);
    EXPECT_EQ(fields.size(), csv.header.size()) << path << ": " << line;
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < std::min(fields.size(), csv.header.size()); ++i)
      row[csv.header[i]] = fields[i];
    csv.rows.push_back(row);
  }
  return csv;
}

// The number in a field; NaN for an empty or malformed one, so that a finiteness check fails.
double Number(const std::map<std::string, std::string>& row, const std::string& column) {
  const auto it = row.find(column);
  if (it == row.end() || it->second.empty()) return std::nan("");
  char* end = nullptr;
  const double v = std::strtod(it->second.c_str(), &end);
  return *end == '\0' ? v : std::nan("");
}

void ExpectPng(const fs::path& png) {
  ASSERT_TRUE(fs::exists(png)) << png;
  EXPECT_GT(fs::file_size(png), 10000u) << png;  // a real chart, not an empty image
  EXPECT_EQ(testing::ReadAll(png).substr(1, 3), "PNG") << png;
}

// Runs `textile bench <name> --quick` into a scratch folder, checks it wrote <name>.csv and a
// real <name>.png chart, and reads the CSV into *csv.
void RunQuickBench(const std::string& name, Csv* csv) {
  const auto d = Scratch("CliBench." + name);
  const auto r = RunTextile("bench " + name + " --quick -o '" + d.string() + "'", "bench_" + name);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;  // progress lines only on a terminal or with --progress
  ASSERT_TRUE(fs::exists(d / (name + ".csv"))) << r.out;
  ExpectPng(d / (name + ".png"));
  *csv = ReadCsv(d / (name + ".csv"));
}

const std::set<std::string> kBendingModels = {"volino", "bridson", "isometric", "pabst"};

TEST(CliBench, ProgressLinesWithTheFlag) {
  const auto d = Scratch("CliBench.Progress");
  const auto r =
      RunTextile("bench hinge-curve --quick --progress -o '" + d.string() + "'", "bench_progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.rfind("bench: running hinge-curve (quick)\n", 0), 0u) << r.err;
}

// The quick photo benchmark's summary table: a column without values (the easy photos are
// PNGs, whose decode time is not measured) printed "nan" on stdout; docs/spec/cli.md allows no NaN.
TEST(CliBench, ExtractAccuracySummaryPrintsNoNan) {
  const auto d = Scratch("CliBench.ExtractAccuracy");
  const auto r = RunTextile("bench extract-accuracy --quick -o '" + d.string() + "'",
                            "bench_extract_accuracy");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_NE(r.out.find("decode_ms"), std::string::npos) << r.out;
  std::string lower = r.out;
  std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
  EXPECT_EQ(lower.find("nan"), std::string::npos) << r.out;
}

// Sensitive Couture Fig. 6 (docs/methods/benchmarks.md, "stability"): every start converges to one
// energy, and the run-time-against-error rows carry their errors against the reference (a
// reference solve that stalled above its tolerance used to leave them empty after 60 s).
TEST(CliBench, StabilityQuickConvergesAndMeasuresItsErrors) {
  Csv csv;
  ASSERT_NO_FATAL_FAILURE(RunQuickBench("stability", &csv));
  int tolerance_rows = 0;
  for (const auto& row : csv.rows) {
    EXPECT_EQ(row.at("converged"), "true") << row.at("case") << " " << row.at("solver");
    if (row.at("case").find("tolerance") == std::string::npos) continue;
    ++tolerance_rows;
    EXPECT_TRUE(std::isfinite(Number(row, "position_error_mm"))) << row.at("tolerance");
    // The loosest tolerance (1e-2 of the weight) is within 0.1 mm of the reference.
    EXPECT_LT(Number(row, "position_error_mm"), 0.1) << row.at("tolerance");
  }
  EXPECT_EQ(tolerance_rows, 3);
}

// Pabst Fig. 10 (docs/methods/bending.md, "hinge-curve"): one curve per fabric and model, and the shapes
// the paper describes. Physics only: no timing.
TEST(CliBench, HingeCurveQuickWritesPabstFig10Curves) {
  Csv csv;
  ASSERT_NO_FATAL_FAILURE(RunQuickBench("hinge-curve", &csv));
  EXPECT_EQ(csv.header,
            (std::vector<std::string>{"fabric", "model", "opening_deg", "bend_deg", "kappa_per_m",
                                      "normal_force_mn", "tangential_force_mn"}));

  // (fabric, model) -> (opening angle, normal force), in file order.
  std::map<std::pair<std::string, std::string>, std::vector<std::pair<double, double>>> curves;
  for (const auto& row : csv.rows) {
    const double opening = Number(row, "opening_deg"), fn = Number(row, "normal_force_mn");
    for (const char* c : {"opening_deg", "bend_deg", "kappa_per_m", "normal_force_mn",
                          "tangential_force_mn"})
      EXPECT_TRUE(std::isfinite(Number(row, c))) << c << " in " << row.at("model");
    EXPECT_EQ(opening + Number(row, "bend_deg"), 180.0);
    EXPECT_GE(Number(row, "kappa_per_m"), 0.0);
    curves[{row.at("fabric"), row.at("model")}].emplace_back(opening, fn);
  }
  std::map<std::string, std::set<std::string>> models_of;
  for (const auto& [key, curve] : curves) models_of[key.first].insert(key.second);
  ASSERT_EQ(models_of.size(), 2u) << "two fabrics (Fig. 8 fabric, interlining)";
  for (const auto& [fabric, models] : models_of) EXPECT_EQ(models, kBendingModels) << fabric;

  const auto& first = curves.begin()->second;
  for (const auto& [key, curve] : curves) {
    SCOPED_TRACE(key.first + " / " + key.second);
    ASSERT_GE(curve.size(), 10u);
    // The same angles for every curve, from flat (180°) closing towards 0°, 90° among them.
    std::vector<double> angles, first_angles;
    for (const auto& p : curve) angles.push_back(p.first);
    for (const auto& p : first) first_angles.push_back(p.first);
    EXPECT_EQ(angles, first_angles);
    EXPECT_EQ(curve.front().first, 180.0);
    EXPECT_TRUE(std::is_sorted(angles.rbegin(), angles.rend())) << "opening angles not closing";
    EXPECT_LE(curve.back().first, 20.0);
    EXPECT_NEAR(curve.front().second, 0.0, 1e-9) << "a flat hinge bends nothing";
    const auto peak = *std::max_element(
        curve.begin(), curve.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    if (key.second == "volino" || key.second == "isometric") {
      // ∝ sin θ: rises to 90° and falls back as the hinge closes.
      EXPECT_NEAR(peak.first, 90.0, 10.0);
      EXPECT_LT(curve.back().second, 0.5 * peak.second) << "no fall after the peak";
      EXPECT_LT(curve[1].second, 0.5 * peak.second);
    } else {
      // Bridson (∝ sin θ/2) and Pabst: rise monotonically all the way as the hinge closes.
      for (size_t i = 1; i < curve.size(); ++i)
        EXPECT_GT(curve[i].second, curve[i - 1].second)
            << "at " << curve[i].first << "° after " << curve[i - 1].first << "°";
      EXPECT_EQ(peak.first, curve.back().first);
    }
  }
  // "The isometric curve lies on Volino's" for one hinge.
  for (const auto& [fabric, models] : models_of) {
    const auto& volino = curves[{fabric, "volino"}];
    const auto& isometric = curves[{fabric, "isometric"}];
    ASSERT_EQ(volino.size(), isometric.size());
    for (size_t i = 0; i < volino.size(); ++i)
      EXPECT_NEAR(isometric[i].second, volino[i].second, 1e-5 * std::abs(volino[i].second) + 1e-9)
          << fabric << " at " << volino[i].first << "°";
  }
}

// The bend-force CSV: the columns docs/methods/benchmarks.md reads, one row per model and thread count
// (1, and all hardware threads when there are more), every time positive and finite. No
// thresholds on the times: they belong to the benchmark.
TEST(CliBench, BendForceQuickWritesOneRowPerModelAndThreadCount) {
  Csv csv;
  ASSERT_NO_FATAL_FAILURE(RunQuickBench("bend-force", &csv));
  for (const char* c : {"model", "threads", "triangles", "force_ms", "force_jacobian_ms"})
    EXPECT_NE(std::find(csv.header.begin(), csv.header.end(), c), csv.header.end())
        << "no column " << c;

  const unsigned hardware = std::thread::hardware_concurrency();
  std::set<int> thread_counts = {1};
  if (hardware > 1) thread_counts.insert(static_cast<int>(hardware));
  std::map<std::string, std::multiset<int>> threads_of;
  for (const auto& row : csv.rows) {
    const std::string model = row.count("model") ? row.at("model") : "";
    SCOPED_TRACE(model + ", " + (row.count("threads") ? row.at("threads") : "?") + " threads");
    threads_of[model].insert(static_cast<int>(Number(row, "threads")));
    EXPECT_EQ(Number(row, "triangles"), 3600.0) << "Pabst's Table 3 sheet";
    int times = 0;
    for (const std::string& c : csv.header) {
      if (c.size() < 3 || c.compare(c.size() - 3, 3, "_ms") != 0) continue;
      ++times;
      const double ms = Number(row, c);
      EXPECT_TRUE(std::isfinite(ms) && ms > 0) << c << " = " << ms;
    }
    EXPECT_GE(times, 2);
  }
  EXPECT_EQ(csv.rows.size(), kBendingModels.size() * thread_counts.size());
  for (const std::string& model : kBendingModels) {
    EXPECT_EQ(threads_of[model], std::multiset<int>(thread_counts.begin(), thread_counts.end()))
        << model;
  }
  EXPECT_EQ(threads_of.size(), kBendingModels.size());
}

}  // namespace
}  // namespace textile
