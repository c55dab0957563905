// `textile render-photo` through the real executable: a photo, its truth profile, the true rig
// and the board image, all readable by the rest of the tool chain; several overhangs share one
// camera; bad input exits 2, a strip that does not fit exits 3, and neither writes anything.

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>

#include "run_cli.h"
#include "textile/fit/profile.h"
#include "textile/photo/rig.h"

namespace textile {
namespace {

namespace fs = std::filesystem;
using testing::CountLines;
using testing::Scratch;
using testing::Textile;

const std::string kFig8 = "samples/materials/pabst-fig8.json";
const std::string kSmall = " --size 800x600 --mm-per-px 0.15";

std::string Quote(const fs::path& p) { return "'" + p.string() + "'"; }

std::set<std::string> Listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

TEST(CliRenderPhoto, WritesPhotoTruthRigAndBoard) {
  const fs::path dir = Scratch("cli_render_photo_ok");
  const auto r = Textile("render-photo --material " + kFig8 + " --overhang-mm 50 -o " +
                         Quote(dir / "strip.jpg") + kSmall + " --difficulty medium --seed 3 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(Listing(dir), (std::set<std::string>{"strip.jpg", "strip.truth.csv", "strip.board.jpg",
                                                 "strip.rig-truth.json"}));
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("photos").size(), 1u);
  // The truth is a profile of the requested overhang; the rig reads; the images decode.
  const Profile truth = ReadProfileCsv((dir / "strip.truth.csv").string());
  EXPECT_NEAR(truth.s.back(), 0.05, 1e-6);
  const Rig rig = ReadRigJson((dir / "strip.rig-truth.json").string());
  EXPECT_NEAR(rig.MmPerPxAt({400, 300}), 0.15, 0.02);
  const cv::Mat photo = cv::imread((dir / "strip.jpg").string(), cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(photo.cols, 800);
  EXPECT_EQ(cv::imread((dir / "strip.board.jpg").string(), cv::IMREAD_GRAYSCALE).rows, 600);
}

TEST(CliRenderPhoto, SeveralOverhangsShareOneCamera) {
  const fs::path dir = Scratch("cli_render_photo_several");
  const auto r = Textile("render-photo --material " + kFig8 + " --overhang-mm 40 60 -o " +
                         Quote(dir / "fig8.png") + kSmall + " --difficulty easy");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(Listing(dir),
            (std::set<std::string>{"fig8_L040mm.png", "fig8_L040mm.truth.csv", "fig8_L060mm.png",
                                   "fig8_L060mm.truth.csv", "fig8.board.png",
                                   "fig8.rig-truth.json"}));
  // One rig for both: the photos extract with it to their own lengths.
  const auto x = Textile("extract " + Quote(dir / "fig8_L040mm.png") + " " +
                         Quote(dir / "fig8_L060mm.png") + " --rig " +
                         Quote(dir / "fig8.rig-truth.json") + " -o " + Quote(dir / "out") + " --json");
  ASSERT_EQ(x.exit_code, 0) << x.err;
  const auto j = nlohmann::json::parse(x.out);
  // Within a pixel and a half of the truth at 0.15 mm/px (blurred tip).
  EXPECT_NEAR(j["photos"][0]["length_mm"].get<double>(), 40.0, 0.25);
  EXPECT_NEAR(j["photos"][1]["length_mm"].get<double>(), 60.0, 0.25);
}

TEST(CliRenderPhoto, BadInputExits2AndAStripThatDoesNotFitExits3) {
  const fs::path dir = Scratch("cli_render_photo_bad");
  const std::string out = " -o " + Quote(dir / "p.png");
  struct Case {
    std::string args;
    int code;
    std::string words;
  };
  const Case cases[] = {
      {"--material missing.json --overhang-mm 50" + out, 2, "missing.json"},
      {"--material " + kFig8 + " --overhang-mm 0" + out, 2, "--overhang-mm"},
      {"--material " + kFig8 + " --overhang-mm 50 --size 10" + out, 2, "--size"},
      {"--material " + kFig8 + " --overhang-mm 50 --size 20x20" + out, 2, "photo size"},
      {"--material " + kFig8 + " --overhang-mm 50 --board 6x6" + out, 2, "board"},
      {"--material " + kFig8 + " --overhang-mm 50 --difficulty tricky" + out, 2, "--difficulty"},
      {"--material " + kFig8 + " --overhang-mm 50 --jpeg 101" + out, 2, "--jpeg"},
      {"--material " + kFig8 + " --overhang-mm 50 -o " + Quote(dir / "p.gif"), 2, ".png, .jpg"},
      {"--material " + kFig8 + " --overhang-mm 500" + kSmall + out, 3, "does not fit"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const auto r = Textile("render-photo " + c.args);
    EXPECT_EQ(r.exit_code, c.code) << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.words), std::string::npos) << r.err;
    EXPECT_TRUE(Listing(dir).empty());
  }
}

}  // namespace
}  // namespace textile
