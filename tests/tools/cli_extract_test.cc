// `textile extract` through the real executable: synthetic photos give profile CSVs that the
// rest of the tool chain reads and overlays that OpenCV reads; every kind of bad input exits 2
// and every detection failure exits 3, with one line on stderr, and neither leaves an output
// behind or replaces a good one (docs/spec/cli.md).

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>

#include "../fit/synthetic_photo.h"
#include "run_cli.h"
#include "textile/fit/profile.h"

namespace textile {
namespace {

namespace fs = std::filesystem;
using testing::CountLines;
using testing::PhotoScene;
using testing::ReadAll;
using testing::Scratch;

using testing::Textile;

std::string Quote(const fs::path& p) { return "'" + p.string() + "'"; }

std::set<std::string> Listing(const fs::path& dir) {
  std::set<std::string> names;
  if (!fs::exists(dir)) return names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

PhotoScene Strip() {
  PhotoScene s;
  s.width = 1000;
  s.height = 700;
  s.root_x = -0.5;
  s.root_y = 200;
  s.straight = 150;
  s.radius = 700;
  return s;
}

fs::path WritePhoto(const fs::path& dir, const std::string& name, const PhotoScene& scene) {
  fs::path p = dir / name;
  cv::imwrite(p.string(), testing::Render(scene).gray);
  return p;
}

void ExpectOneLineError(const testing::CliResult& r, int code, const std::string& words) {
  EXPECT_EQ(r.exit_code, code) << r.err;
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(words), std::string::npos) << r.err;
}

// The test strips are a straight run and an arc, no heavy cantilever: the physics check refuses
// them (exit 3, nothing written) unless told to take the guess, and then says so in the JSON's
// confidence report and warnings; the shipped rendered photo passes it.
TEST(CliExtract, PhysicsCheckRefusesAnArcAndAcceptGuessesTakesIt) {
  const fs::path dir = Scratch("cli_extract_shape");
  const fs::path png = WritePhoto(dir, "arc.png", Strip());
  ExpectOneLineError(Textile("extract " + Quote(png) + " --mm-per-px 0.1 -o " + Quote(dir / "a")),
                     3, "no heavy cantilever");
  EXPECT_FALSE(fs::exists(dir / "a"));
  const auto taken = Textile("extract " + Quote(png) + " --mm-per-px 0.1 --accept-guesses -o " +
                             Quote(dir / "b") + " --json");
  ASSERT_EQ(taken.exit_code, 0) << taken.err;
  const auto j = nlohmann::json::parse(taken.out)["photos"][0];
  EXPECT_EQ(j["confidence"]["held_end"], "found");
  EXPECT_EQ(j["confidence"]["shape_plausible"], false);
  ASSERT_EQ(j["confidence"]["guesses"].size(), 1u);
  EXPECT_NE(j["warnings"].dump().find("taken (--accept-guesses)"), std::string::npos) << j.dump();

  const auto shipped = Textile(
      "extract samples/photos/pabst-fig8_L060mm.jpg --rig samples/photos/pabst-fig8.rig-truth.json "
      "-o " + Quote(dir / "c") + " --json");
  ASSERT_EQ(shipped.exit_code, 0) << shipped.err;
  const auto c = nlohmann::json::parse(shipped.out)["photos"][0]["confidence"];
  EXPECT_EQ(c["held_end"], "found");
  EXPECT_EQ(c["tip"], "found");
  EXPECT_EQ(c["shape_plausible"], true);
  EXPECT_LT(c["shape_rms_mm"].get<double>(), 0.1);
  EXPECT_GT(c["sections_measured"].get<double>(), 0.9);
  EXPECT_TRUE(c["guesses"].empty());
}

TEST(CliExtract, WritesProfileAndOverlayAndAJsonSummary) {
  const fs::path dir = Scratch("cli_extract_ok");
  const testing::SyntheticPhoto photo = testing::Render(Strip());
  const fs::path png = dir / "strip_60mm.png";
  cv::imwrite(png.string(), photo.gray);
  const auto r = Textile("extract " + Quote(png) + " --mm-per-px 0.1 --no-shape-check -o " +
                         Quote(dir / "out") + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("photos").size(), 1u);
  const auto& p = j["photos"][0];
  EXPECT_EQ(p.at("rig_type"), "clamp");
  EXPECT_EQ(p.at("polarity"), "dark");
  EXPECT_EQ(p.at("direction"), "right");
  EXPECT_EQ(p.at("trace"), "mid");
  EXPECT_NEAR(p.at("mm_per_px").get<double>(), 0.1, 1e-12);
  // Length against the truth, to a pixel and a half.
  EXPECT_NEAR(p.at("length_mm").get<double>(), photo.free_length * 0.1, 0.15);
  EXPECT_TRUE(p.at("warnings").empty());
  for (const char* key :
       {"points", "tip_mm", "origin_px", "tip_px", "level_deg", "width_px", "seconds"}) {
    EXPECT_TRUE(p.contains(key)) << key;
  }
  EXPECT_EQ(Listing(dir / "out"),
            (std::set<std::string>{"strip_60mm.overlay.png", "strip_60mm.profile.csv"}));
  const Profile profile = ReadProfileCsv((dir / "out" / "strip_60mm.profile.csv").string());
  EXPECT_EQ(profile.size(), p.at("points").get<size_t>());
  EXPECT_NEAR(profile.s.back() * 1e3, p.at("length_mm").get<double>(), 1e-5);
  EXPECT_EQ(ReadAll(dir / "out" / "strip_60mm.profile.csv").rfind("s_mm,x_mm,y_mm\n", 0), 0u);
  const cv::Mat overlay = cv::imread((dir / "out" / "strip_60mm.overlay.png").string());
  EXPECT_EQ(overlay.cols, 1000);
  EXPECT_EQ(overlay.type(), CV_8UC3);
  // Text mode says the same in words.
  const auto text = Textile("extract " + Quote(png) + " --mm-per-px 0.1 --no-shape-check -o " +
                            Quote(dir / "out"));
  EXPECT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("clamp rig"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("wrote"), std::string::npos) << text.out;
}

TEST(CliExtract, RigFilesGiveTheSameProfileAsThePlainScale) {
  const fs::path dir = Scratch("cli_extract_rig");
  const fs::path png = WritePhoto(dir, "strip.png", Strip());
  std::ofstream(dir / "scale.json") << R"({"type": "scale", "mm_per_px": 0.1})";
  std::ofstream(dir / "homography.json")
      << R"({"type": "homography", "plane_from_image": [[0, -0.1, 50], [0.1, 0, -20], [0, 0, 1]]})";
  ASSERT_EQ(
      Textile("extract " + Quote(png) + " --mm-per-px 0.1 --no-shape-check -o " + Quote(dir / "a"))
          .exit_code,
      0);
  ASSERT_EQ(Textile("extract " + Quote(png) + " --rig " + Quote(dir / "scale.json") +
                    " --no-shape-check -o " + Quote(dir / "b"))
                .exit_code,
            0);
  const auto r = Textile("extract " + Quote(png) + " --no-shape-check --rig " +
                         Quote(dir / "homography.json") + " -o " + Quote(dir / "c"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Profile a = ReadProfileCsv((dir / "a" / "strip.profile.csv").string());
  for (const char* other : {"b", "c"}) {
    const Profile b = ReadProfileCsv((dir / other / "strip.profile.csv").string());
    ASSERT_EQ(a.size(), b.size()) << other;
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_NEAR(a.x[i], b.x[i], 2e-9) << other << " " << i;  // CSV: 6 decimals of mm
      EXPECT_NEAR(a.y[i], b.y[i], 2e-9) << other << " " << i;
    }
  }
}

TEST(CliExtract, OptionsReachTheExtractor) {
  const fs::path dir = Scratch("cli_extract_options");
  PhotoScene s = Strip();
  s.mirror = true;
  const fs::path png = WritePhoto(dir, "left.png", s);
  const auto r = Textile("extract " + Quote(png) + " --mm-per-px 0.1 --no-shape-check -o " +
                         Quote(dir) + " --trace upper --step-mm 1 --level-deg 0.5 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto p = nlohmann::json::parse(r.out)["photos"][0];
  EXPECT_EQ(p.at("direction"), "left");
  EXPECT_EQ(p.at("trace"), "upper");
  EXPECT_DOUBLE_EQ(p.at("level_deg").get<double>(), 0.5);
  const Profile profile = ReadProfileCsv((dir / "left.profile.csv").string());
  EXPECT_NEAR((profile.s[1] - profile.s[0]) * 1e3, 1.0, 2e-6);  // CSV: 6 decimals of mm
  // A manual edge: the profile starts where the line crosses the vertical through it.
  const auto e = Textile("extract " + Quote(png) + " --mm-per-px 0.1 --no-shape-check -o " +
                         Quote(dir) + " --edge-px 900,200 --json");
  ASSERT_EQ(e.exit_code, 0) << e.err;
  const auto q = nlohmann::json::parse(e.out)["photos"][0];
  EXPECT_DOUBLE_EQ(q.at("origin_px")[0].get<double>(), 900.0);
  EXPECT_NE(q.at("rig_detail").get<std::string>().find("--edge-px"), std::string::npos);
}

TEST(CliExtract, BadInputExitsTwoWithOneLineAndNoOutput) {
  const fs::path dir = Scratch("cli_extract_bad");
  const fs::path good = WritePhoto(dir, "good.png", Strip());
  const std::string whole = ReadAll(good);
  std::ofstream{dir / "empty.png"}.close();
  std::ofstream(dir / "text.jpg") << "not an image at all\n";
  std::ofstream(dir / "cut.png", std::ios::binary) << whole.substr(0, whole.size() / 3);
  cv::imwrite((dir / "tiny.png").string(), cv::Mat(1, 1, CV_8U, cv::Scalar(3)));
  {
    std::string huge = ReadAll(good);  // IHDR claims 100000 x 100000
    for (int k = 0; k < 2; ++k) {
      for (int b = 0; b < 4; ++b)
        huge[16 + 4 * k + b] = static_cast<char>((100000u >> (24 - 8 * b)) & 0xFF);
    }
    std::ofstream(dir / "huge.png", std::ios::binary) << huge;
  }
  std::ofstream(dir / "rig-not-json.json") << "{type: scale";
  std::ofstream(dir / "rig-missing.json") << R"({"type": "scale"})";
  std::ofstream(dir / "rig-nan.json") << R"({"type": "scale", "mm_per_px": NaN})";
  std::ofstream(dir / "rig-negative.json") << R"({"type": "scale", "mm_per_px": -0.1})";
  std::ofstream(dir / "rig-array.json") << "[0.1]";
  const std::string out = " -o " + Quote(dir / "out");
  const std::string scale = " --mm-per-px 0.1";
  struct Case {
    std::string args, words;
  };
  const std::vector<Case> cases = {
      {Quote(dir / "missing.png") + scale, "missing.png: cannot open"},
      {Quote(dir / "empty.png") + scale, "empty.png: empty file"},
      {Quote(dir / "text.jpg") + scale, "text.jpg: not a supported image"},
      {Quote(dir / "cut.png") + scale, "cut.png: truncated PNG"},
      {Quote(dir / "tiny.png") + scale, "tiny.png: 1x1 px is too small"},
      {Quote(dir / "huge.png") + scale, "huge.png: the header says 100000x100000 px"},
      {Quote(good) + " --rig " + Quote(dir / "missing.json"), "missing.json: cannot open rig file"},
      {Quote(good) + " --rig " + Quote(dir / "rig-not-json.json"),
       "rig-not-json.json: not valid JSON"},
      {Quote(good) + " --rig " + Quote(dir / "rig-missing.json"),
       "rig-missing.json: mm_per_px: missing"},
      {Quote(good) + " --rig " + Quote(dir / "rig-nan.json"), "rig-nan.json: not valid JSON"},
      {Quote(good) + " --rig " + Quote(dir / "rig-negative.json"),
       "rig-negative.json: mm_per_px: must be > 0"},
      {Quote(good) + " --rig " + Quote(dir / "rig-array.json"),
       "rig-array.json: (top level): must be a JSON object"},
      {Quote(good), "give exactly one of --rig"},
      {Quote(good) + scale + " --rig " + Quote(dir / "rig-missing.json"),
       "give exactly one of --rig"},
      {Quote(good) + " --mm-per-px 0", "--mm-per-px: the scale must be a number > 0"},
      {Quote(good) + " --mm-per-px -2", "--mm-per-px: the scale must be a number > 0"},
      {Quote(good) + " --mm-per-px nan", "--mm-per-px"},
      {Quote(good) + scale + " --edge-px 12", "--edge-px: expected X,Y"},
      {Quote(good) + scale + " --edge-px 12,abc", "--edge-px: 'abc' is not a number"},
      {Quote(good) + scale + " --edge-px 5000,10", "--edge-px 5000.0,10.0 lies outside"},
      {Quote(good) + scale + " --level-deg 60", "--level-deg"},
      {Quote(good) + scale + " --step-mm 0", "--step-mm"},
      {Quote(good) + scale + " --trace middle", "--trace"},
      {Quote(good) + scale + " --max-seconds -1", "--max-seconds must be a finite number >= 0"},
      {Quote(good) + scale + " --max-seconds inf", "--max-seconds must be a finite number >= 0"},
      {Quote(good) + " " + Quote(dir / "sub" / "good.png") + scale, "same file name"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    ExpectOneLineError(Textile("extract " + c.args + out), 2, c.words);
    EXPECT_FALSE(fs::exists(dir / "out"));  // the folder it made is gone again
  }
  // A folder that was there stays, empty; missing parents made for the run go with it.
  fs::create_directory(dir / "kept");
  ExpectOneLineError(Textile("extract " + Quote(dir / "text.jpg") + scale + " -o " +
                             Quote(dir / "kept" / "a" / "b")),
                     2, "not a supported image");
  EXPECT_TRUE(fs::is_directory(dir / "kept"));
  EXPECT_FALSE(fs::exists(dir / "kept" / "a"));
}

TEST(CliExtract, DetectionFailuresExitThreeAndKeepGoodOutputs) {
  const fs::path dir = Scratch("cli_extract_fail");
  PhotoScene blank = Strip();
  blank.strip = blank.background;
  PhotoScene cut = Strip();
  cut.root_y = 500;
  cut.radius = 500;
  cut.bend_deg = 60;  // leaves the photo at the bottom
  PhotoScene hook = Strip();
  hook.radius = 200;
  hook.bend_deg = 150;
  struct Case {
    std::string name;
    PhotoScene scene;
    std::string extra, words;
  };
  const std::vector<Case> cases = {
      {"blank.png", blank, "", "no strip found"},
      {"cut.png", cut, "", "the free tip is cut off by the image border"},
      {"forced.png", Strip(), " --rig-type platform", "platform not found"},
      {"hook.png", hook, "", "the extracted profile is not a hanging strip"},
      {"capped.png", Strip(), " --max-seconds 0", "time cap of 0 s reached after"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path png = WritePhoto(dir, c.name, c.scene);
    ExpectOneLineError(Textile("extract " + Quote(png) + " --mm-per-px 0.1 --no-shape-check -o " +
                               Quote(dir / "out") + c.extra),
                       3, c.name + ": " + c.words);
  }
  EXPECT_TRUE(Listing(dir / "out").empty());
  // A good run, then a failing photo under the same name: the good outputs stay as they were.
  const fs::path png = WritePhoto(dir, "strip.png", Strip());
  ASSERT_EQ(Textile("extract " + Quote(png) + " --mm-per-px 0.1 --no-shape-check -o " +
                    Quote(dir / "out"))
                .exit_code,
            0);
  const std::string csv = ReadAll(dir / "out" / "strip.profile.csv");
  const std::string overlay = ReadAll(dir / "out" / "strip.overlay.png");
  WritePhoto(dir, "strip.png", blank);
  EXPECT_EQ(Textile("extract " + Quote(png) + " --mm-per-px 0.1 --no-shape-check -o " +
                    Quote(dir / "out"))
                .exit_code,
            3);
  EXPECT_EQ(ReadAll(dir / "out" / "strip.profile.csv"), csv);
  EXPECT_EQ(ReadAll(dir / "out" / "strip.overlay.png"), overlay);
  EXPECT_EQ(Listing(dir / "out"),
            (std::set<std::string>{"strip.overlay.png", "strip.profile.csv"}));
}

TEST(CliExtract, SeveralPhotosAreAllOrNothing) {
  // Outputs appear only when every photo succeeded; progress lines go to stderr only on request
  // (or to a terminal), so a failed run's stderr is its one error line.
  const fs::path dir = Scratch("cli_extract_several");
  const fs::path a = WritePhoto(dir, "a.png", Strip());
  PhotoScene blank = Strip();
  blank.strip = blank.background;
  const fs::path b = WritePhoto(dir, "b.png", blank);
  const std::string out = " --mm-per-px 0.1 --no-shape-check -o " + Quote(dir / "out");
  ExpectOneLineError(Textile("extract " + Quote(a) + " " + Quote(b) + out), 3,
                     "b.png: no strip found");
  EXPECT_TRUE(Listing(dir / "out").empty());

  const fs::path c = WritePhoto(dir, "c.png", Strip());
  const auto quiet = Textile("extract " + Quote(a) + " " + Quote(c) + out);
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");
  EXPECT_EQ(Listing(dir / "out"), (std::set<std::string>{"a.overlay.png", "a.profile.csv",
                                                         "c.overlay.png", "c.profile.csv"}));
  const auto verbose = Textile("extract " + Quote(a) + " " + Quote(c) + out + " --progress");
  ASSERT_EQ(verbose.exit_code, 0) << verbose.err;
  EXPECT_EQ(CountLines(verbose.err), 2) << verbose.err;
  EXPECT_NE(verbose.err.find("extracting " + a.string() + " ..."), std::string::npos)
      << verbose.err;
}

// --edge-px at the platform corner that the automatic run reports, on the shipped photos: the
// same profile. The 4.7 px strip bends sharply over the corner; with --edge-px its measured
// stretch started 70 px down the bend, the straight continuation back missed the corner by
// 33 px and the edge was refused (exit 2, "lies 33 px from the strip"), and the 40 mm photo
// was refused as a tip cut off by the border (its tip lies nearer the corner than the end
// at the border).
TEST(CliExtract, EdgeAtTheCornerOfASharplyBentStripIsAccepted) {
  const fs::path dir = Scratch("cli_extract_edge_corner");
  // (The interlining's strip lies 62 mm on the platform before the corner: an edge there is
  // not "along the strip", which the first version of the warning said.)
  for (const std::string stem :
       {"pabst-fig8_L080mm", "pabst-fig8_L040mm", "pabst-interlining_L070mm"}) {
    SCOPED_TRACE(stem);
    const std::string photo = "samples/photos/" + stem + ".jpg";
    const auto automatic =
        Textile("extract " + photo + " --mm-per-px 0.12 -o " + Quote(dir / "auto") + " --json");
    ASSERT_EQ(automatic.exit_code, 0) << automatic.err;
    const auto a = nlohmann::json::parse(automatic.out).at("photos")[0];
    ASSERT_EQ(a.at("rig_type"), "platform");
    // The reviewer's exact case for the 80 mm photo; the reported corner for the others.
    char edge[64];
    std::snprintf(edge, sizeof edge, "%.1f,%.1f", a.at("origin_px")[0].get<double>(),
                  a.at("origin_px")[1].get<double>());
    if (stem == "pabst-fig8_L080mm") {
      EXPECT_STREQ(edge, "1030.3,218.1");
    }
    const auto given = Textile("extract " + photo + " --mm-per-px 0.12 --edge-px " + edge + " -o " +
                               Quote(dir / "edge") + " --json");
    ASSERT_EQ(given.exit_code, 0) << given.err;
    const auto g = nlohmann::json::parse(given.out).at("photos")[0];
    for (const auto& w : g.at("warnings"))
      EXPECT_EQ(w.get<std::string>().find("--edge-px"), std::string::npos) << w;
    if (stem.starts_with("pabst-fig8")) {
      EXPECT_TRUE(g.at("warnings").empty()) << g.at("warnings");
    }
    // Measured 0.03 mm (80 mm) and 0.02 mm (40 mm) apart; the first points within 0.015 mm.
    EXPECT_NEAR(g.at("length_mm").get<double>(), a.at("length_mm").get<double>(), 0.1);
    const Profile pa = ReadProfileCsv((dir / "auto" / (stem + ".profile.csv")).string());
    const Profile pg = ReadProfileCsv((dir / "edge" / (stem + ".profile.csv")).string());
    ASSERT_GT(pg.size(), 10u);
    for (size_t i = 0; i < 10; ++i) {
      EXPECT_NEAR(pg.x[i], pa.x[i], 5e-5) << i;  // [m]
      EXPECT_NEAR(pg.y[i], pa.y[i], 5e-5) << i;
    }
  }
}

TEST(CliExtract, RealPhotos) {
  const fs::path photos = fs::path(TEXTILE_SOURCE_DIR) / ".." / "shared" / "data" / "real-photos";
  if (!fs::exists(photos / "broberg-example.jpg") || !fs::exists(photos / "broberg-break.jpg")) {
    GTEST_SKIP() << photos << " is not available";
  }
  const fs::path dir = Scratch("cli_extract_real");
  const auto r = Textile("extract " + Quote(photos / "broberg-example.jpg") + " " +
                         Quote(photos / "broberg-break.jpg") +
                         " --mm-per-px 0.1101 --trace upper -o " + Quote(dir) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("photos").size(), 2u);
  for (const auto& p : j["photos"]) {
    EXPECT_EQ(p.at("rig_type"), "clamp");
    EXPECT_EQ(p.at("polarity"), "light");
    EXPECT_GT(p.at("length_mm").get<double>(), 230.0);
    EXPECT_LT(p.at("length_mm").get<double>(), 270.0);
    EXPECT_NO_THROW(ReadProfileCsv(p.at("profile_csv").get<std::string>()));
  }
}

}  // namespace
}  // namespace textile
