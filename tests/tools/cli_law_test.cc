// The `textile` shell and `textile law`, through the real executable.

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

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

TEST(CliLaw, RejectsNonFiniteKappa) {
  const auto r = RunTextile("law --material samples/materials/pabst-fig8.json --kappa nan", "law_nan");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--kappa"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace textile
