// `textile render-shadow` through the real executable: a shadow photo, its board and truth,
// readable by the rest of the tool chain (calibrate; MeasureDrapePhoto measures the photo to the
// truth's DC); bad input is in tests/bad_inputs/render-shadow.cases.

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "run_cli.h"
#include "textile/photo/drape_photo.h"
#include "textile/photo/image_codecs.h"
#include "textile/photo/rig.h"

namespace textile {
namespace {

namespace fs = std::filesystem;
using testing::Scratch;
using testing::Textile;

const std::string kMesh = "tests/data/meshes/lobed-drape.obj";

std::string Quote(const fs::path& p) { return "'" + p.string() + "'"; }

TEST(CliRenderShadow, WritesAPhotoTheDrapeMeasurementRecovers) {
  const fs::path dir = Scratch("cli_render_shadow_ok");
  const auto r =
      Textile("render-shadow " + kMesh + " -o " + Quote(dir / "shadow.jpg") + " --board " +
              Quote(dir / "board.png") + " --truth " + Quote(dir / "truth.json") +
              " --tilt-deg 8 --gradient 0.3 --noise 3 --jpeg 90 --seed 2 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["nodes"], 6);
  EXPECT_EQ(j["photo"], (dir / "shadow.jpg").string());
  const nlohmann::json truth = nlohmann::json::parse(testing::ReadAll(dir / "truth.json"));
  EXPECT_DOUBLE_EQ(truth["drape_coefficient"].get<double>(), j["drape_coefficient"].get<double>());
  const Rig rig = ParseRigJson(truth["rig"].dump(), "truth.json");
  const cv::Mat photo = image_codecs::Read((dir / "shadow.jpg").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(photo.cols, 1600);
  const MeasuredDrape m = MeasureDrapePhoto(photo, rig, DrapePhotoOptions{}, "shadow.jpg");
  EXPECT_NEAR(m.drape_coefficient, truth["drape_coefficient"].get<double>(), 0.005);
  EXPECT_TRUE(fs::exists(dir / "board.png"));
}

TEST(CliRenderShadow, PrintsTheTruthAndTheCalibrateLine) {
  const fs::path dir = Scratch("cli_render_shadow_text");
  const auto r = Textile("render-shadow " + kMesh + " -o " + Quote(dir / "s.png") + " --board " +
                         Quote(dir / "b.png") + " --style top --size 1200x1000 --mm-per-px 0.3");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("truth: DC "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("textile calibrate"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace textile
