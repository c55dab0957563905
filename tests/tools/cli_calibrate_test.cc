// `textile calibrate` through the real executable: a rendered board gives a rig file that
// `extract` reads and whose scale is the camera's; a board it cannot find exits 3, bad flags
// and unreadable files exit 2, with one line and no rig written.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "run_cli.h"
#include "textile/photo/rig.h"

namespace textile {
namespace {

namespace fs = std::filesystem;
using testing::CountLines;
using testing::Scratch;
using testing::Textile;

std::string Quote(const fs::path& p) { return "'" + p.string() + "'"; }

// A rendered strip photo and its board (medium level: a few degrees of pose) into dir; returns the
// board's square size [mm].
double Render(const fs::path& dir) {
  const auto r = Textile("render-photo --material samples/materials/pabst-fig8.json --overhang-mm 50 "
                         "--size 800x600 --mm-per-px 0.16 --difficulty medium --seed 2 -o " +
                         Quote(dir / "strip.png") + " --json");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return nlohmann::json::parse(r.out).at("board_square_mm").get<double>();
}

TEST(CliCalibrate, BoardGivesARigThatExtractReads) {
  const fs::path dir = Scratch("cli_calibrate_ok");
  const double square = Render(dir);
  const auto r = Textile("calibrate " + Quote(dir / "strip.board.png") + " --board 9x6 --square-mm " +
                         std::to_string(square) + " -o " + Quote(dir / "rig.json") + " --overlay " +
                         Quote(dir / "corners.png") + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  // Sub-pixel corners on a medium render (blur 1.2 px, noise 3): well under a quarter pixel.
  EXPECT_LT(j.at("reprojection_error_px").get<double>(), 0.25);
  EXPECT_NEAR(j.at("mm_per_px").get<double>(), 0.16, 0.016);
  EXPECT_TRUE(fs::exists(dir / "corners.png"));
  const Rig rig = ReadRigJson((dir / "rig.json").string());
  EXPECT_FALSE(rig.plain_scale);
  const auto x = Textile("extract " + Quote(dir / "strip.png") + " --rig " + Quote(dir / "rig.json") +
                         " -o " + Quote(dir / "out") + " --json");
  ASSERT_EQ(x.exit_code, 0) << x.err;
  // The medium level frays the tip: the extractor stops within a few pixels (0.16 mm each) of it.
  EXPECT_NEAR(nlohmann::json::parse(x.out)["photos"][0]["length_mm"].get<double>(), 50.0, 0.8);
}

// Several boards: the lens fit says which distortion terms the boards determine, with their
// 1-σ, and which were left out (text: a "lens:" line; JSON: lens_terms, lens_models).
TEST(CliCalibrate, SeveralBoardsReportTheLensTermsKept) {
  const fs::path dir = Scratch("cli_calibrate_lens");
  const double square = Render(dir);
  const auto second = Textile(
      "render-photo --material samples/materials/pabst-fig8.json --overhang-mm 50 --size 800x600 "
      "--mm-per-px 0.16 --difficulty medium --seed 5 -o " +
      Quote(dir / "other.png"));
  ASSERT_EQ(second.exit_code, 0) << second.err;
  const std::string args = "calibrate " + Quote(dir / "strip.board.png") + " " +
                           Quote(dir / "other.board.png") + " --board 9x6 --square-mm " +
                           std::to_string(square) + " -o " + Quote(dir / "rig.json");
  const auto text = Textile(args);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("\nlens: "), std::string::npos) << text.out;
  const auto r = Textile(args + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.at("lens_terms").is_string());
  ASSERT_FALSE(j.at("lens_models").empty());
  EXPECT_TRUE(j.at("lens_rms_px").is_number());
  EXPECT_EQ(j.at("lens_models").back().at("terms"), j.at("lens_terms"));
  // Each model tried with the p-values of the next model's and the full model's gain on it.
  for (const auto& m : j.at("lens_models")) {
    EXPECT_TRUE(m.at("p_next").is_number()) << m;
    EXPECT_TRUE(m.at("p_value").is_number()) << m;
    EXPECT_TRUE(m.at("significance").is_number()) << m;
  }
  EXPECT_EQ(j.at("lens_model").get<bool>(), j.at("lens_terms") != "none");
}

TEST(CliCalibrate, RefusesWhatItCannotUse) {
  const fs::path dir = Scratch("cli_calibrate_bad");
  Render(dir);
  { std::ofstream(dir / "text.png") << "not a png"; }
  const std::string board = Quote(dir / "strip.board.png");
  const std::string out = " -o " + Quote(dir / "rig.json");
  struct Case {
    std::string args;
    int code;
    std::string words;
  };
  const Case cases[] = {
      {Quote(dir / "strip.png") + " --board 9x6 --square-mm 10" + out, 3, "chessboard with 9x6 inner corners not found"},
      {board + " --board 10x7 --square-mm 10" + out, 3, "not found"},
      {board + " --board 9 --square-mm 10" + out, 2, "--board: expected COLSxROWS"},
      {board + " --board 6x6 --square-mm 10" + out, 2, "is square"},
      {board + " --board 9x6 --square-mm 0" + out, 2, "--square-mm"},
      {board + " --board 9x6 --square-mm 10 --max-error-px 0" + out, 2, "--max-error-px"},
      {board + " --board 9x6 --square-mm 10 --max-seconds -1" + out, 2, "--max-seconds: max_seconds"},
      {board + " --board 9x6 --square-mm 10 --max-seconds 0" + out, 3,
       "calibrate: time cap of 0 s reached after"},
      {Quote(dir / "missing.png") + " --board 9x6 --square-mm 10" + out, 2, "missing.png: cannot open"},
      {Quote(dir / "text.png") + " --board 9x6 --square-mm 10" + out, 2, "text.png: not a supported image"},
      {board + " --board 9x6 --square-mm 10 -o " + Quote(dir / "no" / "rig.json"), 2, "rig.json"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const auto r = Textile("calibrate " + c.args);
    EXPECT_EQ(r.exit_code, c.code) << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.words), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "rig.json"));
  }
}

}  // namespace
}  // namespace textile
