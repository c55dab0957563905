// LoadProfileInputs: profile CSVs and photos mixed in one list, photos told apart by their
// bytes (not their names), extracted with the given rig exactly as `textile extract` does, and
// every way of getting it wrong refused in one line naming the file or flag.

#include "common/profile_inputs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "../fit/synthetic_photo.h"
#include "run_cli.h"
#include "textile/sim/core/error.h"

namespace textile {
namespace {

namespace fs = std::filesystem;
using testing::Scratch;

// A dark strip leaving the left border, bending down: extractable at any scale.
testing::SyntheticPhoto Photo() {
  testing::PhotoScene s;
  s.width = 800;
  s.height = 560;
  s.root_x = -0.5;
  s.root_y = 150;
  s.straight = 120;
  s.radius = 500;
  return testing::Render(s);
}

void WriteCsv(const fs::path& p) {
  std::ofstream f(p);
  f << "s_mm,x_mm,y_mm\n";
  for (int i = 0; i < 20; ++i) f << i << "," << i << "," << -0.01 * i * i << "\n";
}

template <typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(ProfileInputs, MixesCsvsAndPhotosInOrder) {
  const fs::path dir = Scratch("profile_inputs_mix");
  const testing::SyntheticPhoto photo = Photo();
  // The photo's name says nothing: the PNG signature decides.
  cv::imwrite((dir / "strip.png").string(), photo.gray);
  fs::rename(dir / "strip.png", dir / "strip.dat");
  WriteCsv(dir / "a.profile.csv");
  PhotoInputOptions o;
  o.mm_per_px = 0.1;
  o.extract.check_shape = false;  // the synthetic strip is an arc, no cantilever
  const auto in =
      LoadProfileInputs({(dir / "a.profile.csv").string(), (dir / "strip.dat").string()}, o);
  ASSERT_EQ(in.size(), 2u);
  EXPECT_FALSE(in[0].from_photo);
  EXPECT_FALSE(in[0].extraction.has_value());
  EXPECT_EQ(in[0].profile.size(), 20u);
  EXPECT_TRUE(in[1].from_photo);
  ASSERT_TRUE(in[1].extraction.has_value());
  EXPECT_EQ(in[1].profile.source, (dir / "strip.dat").string());
  EXPECT_TRUE(in[1].photo.empty());  // not kept unless asked
  // The strip's length at 0.1 mm/px, to a pixel and a half (the extractor's own tests).
  EXPECT_NEAR(in[1].profile.s.back() * 1e3, photo.free_length * 0.1, 0.15);
  // Same result as the extractor called directly.
  const ExtractionSummary direct =
      ExtractProfile(photo.gray, Rig::FromScale(0.1), o.extract, "direct");
  ASSERT_TRUE(direct.success);
  ASSERT_EQ(direct.profile.size(), in[1].profile.size());
  EXPECT_EQ(direct.profile.y.back(), in[1].profile.y.back());
}

TEST(ProfileInputs, KeepsThePhotoWhenAsked) {
  const fs::path dir = Scratch("profile_inputs_keep");
  cv::imwrite((dir / "strip.png").string(), Photo().gray);
  PhotoInputOptions o;
  o.mm_per_px = 0.1;
  o.extract.check_shape = false;  // the synthetic strip is an arc, no cantilever
  o.keep_photos = true;
  const auto in = LoadProfileInputs({(dir / "strip.png").string()}, o);
  ASSERT_EQ(in.size(), 1u);
  EXPECT_EQ(in[0].photo.cols, 800);
  EXPECT_EQ(in[0].photo.type(), CV_8UC1);
}

TEST(ProfileInputs, CsvsNeedNoRig) {
  const fs::path dir = Scratch("profile_inputs_csv");
  WriteCsv(dir / "a.csv");
  const auto in = LoadProfileInputs({(dir / "a.csv").string()}, PhotoInputOptions{});
  ASSERT_EQ(in.size(), 1u);
  EXPECT_FALSE(in[0].from_photo);
}

TEST(ProfileInputs, BadInputIsRefusedNamingTheFileOrFlag) {
  const fs::path dir = Scratch("profile_inputs_bad");
  cv::imwrite((dir / "strip.png").string(), Photo().gray);
  { std::ofstream(dir / "text.jpg") << "not a jpeg"; }
  { std::ofstream(dir / "rig.json") << "[1, 2]"; }
  const std::string png = (dir / "strip.png").string();
  PhotoInputOptions none, both, scale, bad_rig, bad_step;
  both.mm_per_px = 0.1;
  both.rig_path = (dir / "rig.json").string();
  scale.mm_per_px = 0.1;
  bad_rig.rig_path = (dir / "rig.json").string();
  bad_step.mm_per_px = 0.1;
  bad_step.extract.step_mm = -1;
  struct Case {
    std::vector<std::string> paths;
    PhotoInputOptions options;
    std::string words;
  };
  const Case cases[] = {
      {{png}, none, "strip.png is a photo: give exactly one of --rig"},
      {{png}, both, "give exactly one of --rig RIG.json and --mm-per-px S (both given)"},
      {{png}, bad_rig, "rig.json: (top level): must be a JSON object"},
      {{png}, bad_step, "step_mm must lie in"},
      {{(dir / "text.jpg").string()}, scale, "text.jpg: not a supported image"},
      {{(dir / "missing.png").string()}, scale, "missing.png: cannot open photo"},
      {{(dir / "missing.csv").string()}, scale, "missing.csv"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.words);
    const std::string what = ErrorOf([&] { LoadProfileInputs(c.paths, c.options); });
    EXPECT_NE(what.find(c.words), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_THROW(LoadProfileInputs(c.paths, c.options), InputError);
  }
}

TEST(ProfileInputs, APhotoWithoutAStripIsAComputeError) {
  const fs::path dir = Scratch("profile_inputs_blank");
  testing::PhotoScene s;
  s.width = 600;
  s.height = 400;
  s.strip = s.background;
  cv::imwrite((dir / "blank.png").string(), testing::Render(s).gray);
  PhotoInputOptions o;
  o.mm_per_px = 0.1;
  o.extract.check_shape = false;  // the synthetic strip is an arc, no cantilever
  const std::string path = (dir / "blank.png").string();
  EXPECT_THROW(LoadProfileInputs({path}, o), ComputeError);
  EXPECT_EQ(ErrorOf([&] { LoadProfileInputs({path}, o); }).rfind(path + ": ", 0), 0u);
}

TEST(ProfileInputs, ParseEdgePxReadsTwoNumbers) {
  EXPECT_EQ(cli::ParseEdgePx("12.5,-3"), Eigen::Vector2d(12.5, -3));
  EXPECT_THROW(cli::ParseEdgePx("12"), InputError);
  EXPECT_THROW(cli::ParseEdgePx("1,2,3"), InputError);
  EXPECT_THROW(cli::ParseEdgePx("1,x"), InputError);
}

}  // namespace
}  // namespace textile
