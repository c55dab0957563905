// `textile fit-seam` through the real executable.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "run_cli.h"

namespace textile {
namespace {

using testing::ExpectRefused;
using testing::ReadAll;
using testing::Scratch;
using testing::Textile;
namespace fs = std::filesystem;

// C-plain (Table 2) at the 17 centre-seam ray distances, exact.
std::string CPlainCsv() {
  std::string csv = "d_mm,factor\n";
  for (int i = 0; i < 17; ++i) {
    const double d = std::abs(5.0 + 190.0 * i / 16.0 - 100.0);
    csv += std::to_string(d) + "," + std::to_string(2e-4 * d * d - 0.0702 * d + 9.07) + "\n";
  }
  return csv;
}

void Write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

TEST(CliFitSeam, CsvToSeamFileThatReadsBack) {
  const auto dir = Scratch("CliFitSeam.Csv");
  Write(dir / "f.csv", CPlainCsv());
  const auto r = Textile("fit-seam " + (dir / "f.csv").string() + " --layers 4 -o " +
                         (dir / "seam.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("B_f(d) = 0.0002 d² + -0.0702 d + 9.07"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(ReadAll(dir / "seam.json"));
  EXPECT_EQ(j["type"], "fitted");
  EXPECT_EQ(j["layers"], 4);
  // std::to_string keeps 6 decimals: the coefficients come back to ~1e-6 of the factor.
  EXPECT_NEAR(j["coefficients_mm"][0].get<double>(), 2e-4, 1e-8);
  EXPECT_NEAR(j["coefficients_mm"][1].get<double>(), -0.0702, 1e-6);
  EXPECT_NEAR(j["coefficients_mm"][2].get<double>(), 9.07, 1e-5);
  EXPECT_EQ(j["range_mm"][1].get<double>(), 95.0);
  EXPECT_EQ(j["fit"]["dof"], 14);
  EXPECT_TRUE(j.contains("covariance"));
}

TEST(CliFitSeam, RefusesBadInputWithExit2) {
  const auto dir = Scratch("CliFitSeam.Bad");
  Write(dir / "two.csv", "d_mm,factor\n0,3\n10,2\n");
  Write(dir / "neg.csv", "d_mm,factor\n0,3\n-10,2\n20,1.5\n");
  Write(dir / "sd0.csv", "d_mm,factor,sd\n0,3,0.1\n10,2,0\n20,1.5,0.1\n");
  Write(dir / "nan.csv", "d_mm,factor\n0,3\n10,nan\n20,1.5\n");
  Write(dir / "plain.json", R"({"model": "elastica", "rays": [{"z_mm": 5, "d_mm": null, "factor": 1}]})");
  const std::string out = " -o " + (dir / "s.json").string();
  ExpectRefused(Textile("fit-seam " + (dir / "two.csv").string() + " --layers 2" + out),
                "at least 3 points", "two points");
  ExpectRefused(Textile("fit-seam " + (dir / "neg.csv").string() + " --layers 2" + out),
                "neg.csv:3: d_mm = -10 is negative", "negative d");
  ExpectRefused(Textile("fit-seam " + (dir / "sd0.csv").string() + " --layers 2" + out),
                "sd0.csv:3: sd = 0", "sd 0");
  ExpectRefused(Textile("fit-seam " + (dir / "nan.csv").string() + " --layers 2" + out),
                "nan.csv:3", "nan");
  ExpectRefused(Textile("fit-seam " + (dir / "plain.json").string() + out), "no seam distance",
                "plain ACPM result");
  ExpectRefused(Textile("fit-seam " + (dir / "two.csv").string() + out), "--layers", "no layers");
  ExpectRefused(Textile("fit-seam " + (dir / "missing.csv").string() + " --layers 2" + out),
                "cannot open", "missing file");
  EXPECT_FALSE(fs::exists(dir / "s.json"));
}

TEST(CliFitSeam, PoorFitWarnsOrFailsWithStrict) {
  const auto dir = Scratch("CliFitSeam.Poor");
  std::string csv = "d_mm,factor\n";
  for (int i = 0; i < 17; ++i) {
    const double d = 6.0 * i;
    csv += std::to_string(d) + "," + (d < 20 ? "4" : std::to_string(1.5 + 0.3 * std::sin(d))) + "\n";
  }
  Write(dir / "step.csv", csv);
  const auto warn = Textile("fit-seam " + (dir / "step.csv").string() + " --layers 3 -o " +
                            (dir / "w.json").string());
  EXPECT_EQ(warn.exit_code, 0) << warn.err;
  EXPECT_NE(warn.err.find("warning:"), std::string::npos) << warn.err;
  EXPECT_TRUE(nlohmann::json::parse(ReadAll(dir / "w.json"))["fit"]["poor"].get<bool>());
  const auto strict = Textile("fit-seam " + (dir / "step.csv").string() + " --layers 3 --strict -o " +
                              (dir / "s.json").string());
  EXPECT_EQ(strict.exit_code, 3) << strict.err;
  EXPECT_NE(strict.err.find("poor fit"), std::string::npos) << strict.err;
  EXPECT_FALSE(fs::exists(dir / "s.json"));
}

TEST(CliFitSeam, JsonOutput) {
  const auto dir = Scratch("CliFitSeam.Json");
  Write(dir / "f.csv", CPlainCsv());
  const auto r = Textile("fit-seam " + (dir / "f.csv").string() + " --layers 4 --json -o " +
                         (dir / "seam.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["seam"]["layers"], 4);
  EXPECT_FALSE(j["seam"]["fit"]["poor"].get<bool>());
}

// seam-ok.csv covers d = 0-30 mm (3 -> 1.8); its quadratic turns up beyond 42 mm.
TEST(CliFitSeam, InfluenceRangeFollowsTheDataUnlessGiven) {
  const auto dir = Scratch("CliFitSeam.Influence");
  const std::string ok = "tests/bad_inputs/files/seam-ok.csv --layers 2";
  const auto r = Textile("fit-seam " + ok + " -o " + (dir / "s.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");  // nothing extrapolated, nothing to note
  const auto j = nlohmann::json::parse(ReadAll(dir / "s.json"));
  EXPECT_EQ(j["influence_mm"].get<double>(), 30.0);
  EXPECT_EQ(j["fit"]["influence_from"], "data");
  EXPECT_NE(r.out.find("influence range 30 mm (the data's)"), std::string::npos) << r.out;
  // The old default of 100 mm wrote S(100) = 4.17: refused, naming where the rise starts.
  ExpectRefused(Textile("fit-seam " + ok + " --influence-mm 100 -o " + (dir / "x.json").string()),
                "rises from 1.671 at 42.33 mm to 4.165 at 100 mm", "rising extrapolation");
  EXPECT_FALSE(fs::exists(dir / "x.json"));
  // A range inside the data is the user's call, with a note on what it cuts off.
  Write(dir / "to40.csv", "d_mm,factor\n0,3\n10,2.5\n20,2\n30,1.8\n40,1.6\n");
  const auto cut = Textile("fit-seam " + (dir / "to40.csv").string() +
                           " --layers 2 --influence-mm 10 -o " + (dir / "c.json").string());
  ASSERT_EQ(cut.exit_code, 0) << cut.err;
  EXPECT_NE(cut.err.find("note: "), std::string::npos) << cut.err;
  EXPECT_NE(cut.err.find("ends inside the data (d up to 40 mm)"), std::string::npos) << cut.err;
  EXPECT_EQ(nlohmann::json::parse(ReadAll(dir / "c.json"))["fit"]["notes"].size(), 1u);
}

TEST(CliFitSeam, AFlatExcellentFitPassesStrict) {
  const auto dir = Scratch("CliFitSeam.Flat");
  std::string csv = "d_mm,factor\n";
  for (int i = 0; i <= 12; ++i) csv += std::to_string(5 * i) + (i % 2 ? ",1.999\n" : ",2.001\n");
  Write(dir / "flat.csv", csv);
  const auto r = Textile("fit-seam " + (dir / "flat.csv").string() + " --layers 2 --strict -o " +
                         (dir / "s.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(nlohmann::json::parse(ReadAll(dir / "s.json"))["fit"]["poor"].get<bool>());
}

TEST(CliFitSeam, AcceptsAUtf8ByteOrderMark) {
  const auto dir = Scratch("CliFitSeam.Bom");
  const std::string bom = "\xEF\xBB\xBF";  // Excel's "CSV UTF-8" starts with it
  Write(dir / "excel.csv", bom + "d_mm,factor\r\n0,3\r\n10,2.5\r\n20,2\r\n30,1.8\r\n");
  const auto csv = Textile("fit-seam " + (dir / "excel.csv").string() + " --layers 2 -o " +
                           (dir / "a.json").string());
  EXPECT_EQ(csv.exit_code, 0) << csv.err;
  const std::string acpm_json =
      R"({"model": "shell", "seam": {"direction": "along", "profile": {"layers": 3}}, "rays": )"
      R"([{"d_mm": 0, "factor": 4}, {"d_mm": 20, "factor": 3}, {"d_mm": 40, "factor": 2.5}]})";
  Write(dir / "acpm.json", bom + acpm_json);
  const auto acpm =
      Textile("fit-seam " + (dir / "acpm.json").string() + " -o " + (dir / "b.json").string());
  ASSERT_EQ(acpm.exit_code, 0) << acpm.err;
  EXPECT_EQ(nlohmann::json::parse(ReadAll(dir / "b.json"))["layers"], 3);
}

TEST(CliFitSeam, LayersMustAgreeWithTheAcpmResult) {
  const auto dir = Scratch("CliFitSeam.Layers");
  const std::string rays =
      R"("rays": [{"d_mm": 0, "factor": 4}, {"d_mm": 20, "factor": 3}, {"d_mm": 40, "factor": 2.5}])";
  Write(dir / "two.json",
        R"({"seam": {"direction": "along", "profile": {"layers": 2}}, )" + rays + "}");
  Write(dir / "frac.json",
        R"({"seam": {"direction": "along", "profile": {"layers": 3.5}}, )" + rays + "}");
  const std::string out = " -o " + (dir / "s.json").string();
  ExpectRefused(Textile("fit-seam " + (dir / "two.json").string() + " --layers 4" + out),
                "--layers 4: " + (dir / "two.json").string() + " records seam.profile.layers 2",
                "contradicting --layers");
  ExpectRefused(Textile("fit-seam " + (dir / "frac.json").string() + out),
                "seam.profile.layers must be a whole number in [1, 20], got 3.5", "layers 3.5");
  EXPECT_FALSE(fs::exists(dir / "s.json"));
  // Saying the same as the result is fine.
  EXPECT_EQ(Textile("fit-seam " + (dir / "two.json").string() + " --layers 2" + out).exit_code, 0);
}

}  // namespace
}  // namespace textile
