// `textile batch` through the real executable: the shipped series (profiles and a photo) with
// two jobs, its summary and materials, and a series with a failing specimen, which is listed
// while the others are fitted, the run exiting 3 at the end.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "run_cli.h"

namespace textile {
namespace {

using testing::ReadAll;
using testing::Scratch;
using testing::Textile;
namespace fs = std::filesystem;

TEST(CliBatch, TheShippedSeriesGivesASummaryAndAMaterialPerFabric) {
  const fs::path d = Scratch("cli_batch_series");
  const auto r = Textile("batch samples/series/manifest.csv -o " + (d / "out").string() +
                         " --jobs 2 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["fitted"], 7);
  EXPECT_TRUE(j["failed"].empty());
  EXPECT_EQ(testing::CountLines(r.err), 7) << "a progress line a specimen when not on a terminal";
  const nlohmann::json s = nlohmann::json::parse(ReadAll(d / "out/summary.json"));
  EXPECT_EQ(s["directions"].size(), 4u);  // fig8 warp, weft; interlining warp, weft
  const std::string csv = ReadAll(d / "out/summary.csv");
  EXPECT_EQ(testing::CountLines(csv), 5);
  // The photo specimen was extracted with its row's rig and fitted: the interlining's law,
  // b1 = 0.517 gf·cm, within the extraction's accuracy.
  const nlohmann::json photo =
      nlohmann::json::parse(ReadAll(d / "out/interlining/photo-1/material.json"));
  EXPECT_EQ(photo["fit"]["photos"][0]["photo"], "../photos/pabst-interlining_L100mm.jpg");
  EXPECT_NEAR(photo["bending"]["b1"].get<double>(), 0.517, 0.05);
  EXPECT_TRUE(fs::exists(d / "out/interlining/photo-1/pabst-interlining_L100mm.overlay.png"));
  // The rows that ask for validation carry its verdicts; the others none.
  EXPECT_EQ(s["specimens"][0]["validation"]["held_out"], "pass");
  EXPECT_EQ(s["specimens"][6]["validation"]["goodness_of_fit"], "pass");
  EXPECT_TRUE(s["specimens"][1]["validation"].is_null());
  EXPECT_TRUE(fs::exists(d / "out/fig8/material.json"));
  EXPECT_TRUE(fs::exists(d / "out/interlining/material.json"));
}

TEST(CliBatch, AFailingSpecimenIsListedAndTheRunExits3AtTheEnd) {
  const fs::path d = Scratch("cli_batch_failing");
  std::ofstream(d / "straight.csv") << "s_mm,x_mm,y_mm\n0,0,0\n10,10,0\n20,20,0\n30,30,0\n";
  fs::copy_file(fs::path(TEXTILE_SOURCE_DIR) / "samples/profiles/pabst-fig8_L060mm.profile.csv",
                d / "good.csv");
  std::ofstream(d / "m.csv") << "fabric,specimen,direction,side,inputs,gsm\n"
                             << "a,1,warp,face,good.csv,200\n"
                             << "a,2,warp,face,straight.csv,200\n";
  const auto r = Textile("batch " + (d / "m.csv").string() + " -o " + (d / "out").string());
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.out.find("failed: a/2 (line 3): "), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("error: batch: 1 of 2 specimens failed"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(d / "out/a/1/material.json"));
  const nlohmann::json s = nlohmann::json::parse(ReadAll(d / "out/summary.json"));
  EXPECT_EQ(s["specimens"][1]["status"], "failed");
  EXPECT_FALSE(s["specimens"][1]["error"].get<std::string>().empty());
}

}  // namespace
}  // namespace textile
