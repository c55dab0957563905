// `textile synth-profile` through the real executable: the files it writes, determinism, and
// how it refuses bad flags and bad materials (docs/spec/cli.md: exit 2, one line naming the flag or
// file, nothing written).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "run_cli.h"

namespace textile {
namespace {

using testing::CountLines;
using testing::ReadAll;
using testing::Scratch;
namespace fs = std::filesystem;

const std::string kFig8 = "samples/materials/pabst-fig8.json";

using testing::Textile;

std::string Quote(const fs::path& p) { return "'" + p.string() + "'"; }

// Names of the entries of a folder (files and hidden temp files alike).
std::set<std::string> Listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

// Non-comment lines of a CSV file.
std::vector<std::string> DataLines(const fs::path& file) {
  std::istringstream in(ReadAll(file));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] != '#') lines.push_back(line);
  }
  return lines;
}


TEST(CliSynth, WritesOneCsvPerOverhangWithHeaderAndPointCount) {
  const auto dir = Scratch("cli_synth_files") / "profiles";  // created by the command
  const auto r = Textile("synth-profile --material " + kFig8 +
                         " --overhang-mm 40 60 80 --points 37 -o " + Quote(dir));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Exactly three files, no temporary leftovers.
  EXPECT_EQ(Listing(dir),
            (std::set<std::string>{"pabst-fig8_L040mm.profile.csv", "pabst-fig8_L060mm.profile.csv",
                                   "pabst-fig8_L080mm.profile.csv"}));
  EXPECT_EQ(CountLines(r.out), 3) << r.out;  // one line per file
  for (double L : {40.0, 60.0, 80.0}) {
    char name[64];
    std::snprintf(name, sizeof name, "pabst-fig8_L%03.0fmm.profile.csv", L);
    const fs::path file = dir / name;
    EXPECT_NE(r.out.find(file.string()), std::string::npos) << r.out;
    const auto lines = DataLines(file);
    ASSERT_EQ(lines.size(), 1u + 37u) << file;
    EXPECT_EQ(lines.front(), "s_mm,x_mm,y_mm");
    double s_last = 0.0, s_prev = -1.0;
    for (size_t i = 1; i < lines.size(); ++i) {
      double s, x, y;
      char c1, c2;
      std::istringstream row(lines[i]);
      ASSERT_TRUE(row >> s >> c1 >> x >> c2 >> y) << file << ": " << lines[i];
      EXPECT_EQ(c1, ',');
      EXPECT_EQ(c2, ',');
      EXPECT_GT(s, s_prev) << file << ": " << lines[i];
      EXPECT_LE(y, 1e-9) << file << ": a hanging strip has y <= 0";
      s_prev = s_last = s;
    }
    // Noise-free: s is the sum of the chords between samples, which undershoots the overhang
    // by Σ κ² h³ / 24 (h = L/36, κ ≤ 1.9 /cm): at most 0.1 mm here, never more than L.
    EXPECT_LE(s_last, L + 1e-6) << file;
    EXPECT_GT(s_last, L - 0.1) << file;
  }
}

TEST(CliSynth, DistinctOverhangsGiveDistinctFiles) {
  // Overhangs a fraction of a millimetre apart are different experiments: neither may
  // overwrite the other.
  const auto dir = Scratch("cli_synth_distinct");
  const auto r = Textile("synth-profile --material " + kFig8 + " --overhang-mm 40 40.4 -o " +
                         Quote(dir) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("profiles").size(), 2u);
  EXPECT_NE(j["profiles"][0]["path"], j["profiles"][1]["path"]) << r.out;
  EXPECT_EQ(Listing(dir).size(), 2u);
}

TEST(CliSynth, SameSeedIsByteIdenticalOtherSeedDiffers) {
  const auto root = Scratch("cli_synth_seed");
  const auto run = [&](const std::string& sub, int seed) {
    const auto r = Textile("synth-profile --material " + kFig8 +
                           " --overhang-mm 50 70 --noise-mm 0.1 --seed " + std::to_string(seed) +
                           " -o " + Quote(root / sub));
    EXPECT_EQ(r.exit_code, 0) << r.err;
  };
  run("a", 7);
  run("b", 7);
  run("c", 8);
  for (const char* name : {"pabst-fig8_L050mm.profile.csv", "pabst-fig8_L070mm.profile.csv"}) {
    const std::string a = ReadAll(root / "a" / name);
    ASSERT_GT(a.size(), 1000u) << name;
    EXPECT_EQ(a, ReadAll(root / "b" / name)) << name << ": same seed, different bytes";
    EXPECT_NE(a, ReadAll(root / "c" / name)) << name << ": another seed, same noise";
  }
}

// The last point's s: the exact arc length ends at the overhang; recomputed from noisy points (the
// default, as an extractor measures it) the polyline is longer.
TEST(CliSynth, ExactArcLengthKeepsTheTrueS) {
  const auto root = Scratch("cli_synth_exact");
  const auto last_s = [&](const std::string& sub, const std::string& flag) {
    const auto r = Textile("synth-profile --material " + kFig8 +
                           " --overhang-mm 40 --noise-mm 0.1 -o " + Quote(root / sub) + flag);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    const std::string csv = ReadAll(root / sub / "pabst-fig8_L040mm.profile.csv");
    const size_t line = csv.rfind('\n', csv.size() - 2);
    return std::stod(csv.substr(line + 1));
  };
  EXPECT_DOUBLE_EQ(last_s("exact", " --exact-arc-length"), 40.0);
  EXPECT_GT(last_s("chord", ""), 40.5);
}

TEST(CliSynth, JsonListsTheFiles) {
  const auto dir = Scratch("cli_synth_json");
  const auto r = Textile("synth-profile --material " + kFig8 +
                         " --overhang-mm 45 65 --noise-mm 0.05 --seed 3 --points 50 -o " +
                         Quote(dir) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json j;
  ASSERT_NO_THROW(j = nlohmann::json::parse(r.out)) << "stdout is not one JSON object:\n" << r.out;
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j.at("material"), kFig8);
  EXPECT_EQ(j.at("noise_mm").get<double>(), 0.05);
  EXPECT_EQ(j.at("seed").get<int>(), 3);
  const auto& profiles = j.at("profiles");
  ASSERT_EQ(profiles.size(), 2u);
  std::set<std::string> listed;
  const double overhangs[] = {45.0, 65.0};
  for (size_t i = 0; i < profiles.size(); ++i) {
    const std::string path = profiles[i].at("path");
    listed.insert(fs::path(path).filename().string());
    EXPECT_EQ(profiles[i].at("overhang_mm").get<double>(), overhangs[i]);
    EXPECT_EQ(profiles[i].at("points").get<int>(), 50);
    // The listed path is the written file (relative paths resolve from the source root).
    const fs::path on_disk =
        fs::path(path).is_absolute() ? fs::path(path) : fs::path(TEXTILE_SOURCE_DIR) / path;
    ASSERT_TRUE(fs::exists(on_disk)) << path;
    EXPECT_EQ(DataLines(on_disk).size(), 51u) << path;
  }
  EXPECT_EQ(listed, Listing(dir));
}

TEST(CliSynth, BadFlagsExit2NamingTheFlag) {
  struct Case {
    std::string args, fragment;
  };
  const std::vector<Case> cases = {
      {"--overhang-mm -10", "--overhang-mm"},
      {"--overhang-mm 0", "--overhang-mm"},
      {"--overhang-mm nan", "--overhang-mm"},
      {"--overhang-mm inf", "--overhang-mm"},
      {"--overhang-mm 1e9", "--overhang-mm"},
      {"--overhang-mm 40 60 -5", "--overhang-mm"},  // a bad one after good ones
      {"--overhang-mm 40 --noise-mm -0.1", "--noise-mm"},
      {"--overhang-mm 40 --noise-mm nan", "--noise-mm"},
      {"--overhang-mm 40 --offset-mm 99", "--offset-mm"},
      {"--overhang-mm", "--overhang-mm"},  // no value
      {"--overhang-mm forty", "--overhang-mm"},
      {"--overhang-mm 40 --points many", "--points"},
  };
  const auto root = Scratch("cli_synth_bad_flags");
  for (const Case& c : cases) {
    const auto dir = root / "never-created";
    const auto r =
        Textile("synth-profile --material " + kFig8 + " " + c.args + " -o " + Quote(dir));
    testing::ExpectRefused(r, c.fragment, c.args);
    EXPECT_FALSE(fs::exists(dir)) << c.args << ": the output folder was created by a refused run";
  }
}

TEST(CliSynth, PointsAndRotationErrorsNameTheirFlag) {
  // docs/spec/cli.md: the error names the flag the user typed (not an internal option name or
  // unit).
  const auto dir = Scratch("cli_synth_bad_points") / "never-created";
  for (const char* args : {"--points 2", "--points -5"}) {
    const auto r = Textile("synth-profile --material " + kFig8 + " --overhang-mm 40 " + args +
                           " -o " + Quote(dir));
    testing::ExpectRefused(r, "--points", args);
  }
  for (const char* args : {"--rotation-deg 90", "--rotation-deg nan"}) {
    const auto r = Textile("synth-profile --material " + kFig8 + " --overhang-mm 40 " + args +
                           " -o " + Quote(dir));
    testing::ExpectRefused(r, "--rotation-deg", args);
  }
  EXPECT_FALSE(fs::exists(dir));
}

TEST(CliSynth, MissingOrBadMaterialExit2NamingTheFile) {
  const auto dir = Scratch("cli_synth_bad_material") / "never-created";
  {
    const auto r = Textile("synth-profile --overhang-mm 40 -o " + Quote(dir));
    testing::ExpectRefused(r, "--material", "no --material");
  }
  std::vector<std::string> files = {"tests/data/materials/does-not-exist.json"};
  for (const auto& e :
       fs::directory_iterator(fs::path(TEXTILE_SOURCE_DIR) / "tests/data/materials")) {
    files.push_back("tests/data/materials/" + e.path().filename().string());
  }
  ASSERT_GE(files.size(), 10u);
  for (const std::string& f : files) {
    const auto r = Textile("synth-profile --material " + f + " --overhang-mm 40 -o " + Quote(dir));
    testing::ExpectRefused(r, "error: " + f + ": ", f);
  }
  EXPECT_FALSE(fs::exists(dir));
}

TEST(CliSynth, UnwritableOutputFolderExit2) {
  const auto root = Scratch("cli_synth_unwritable");
  const fs::path regular = root / "regular-file";
  std::ofstream(regular) << "keep me\n";
  for (const fs::path& out : {fs::path("/proc/forbidden"), regular / "sub", regular}) {
    const auto r =
        Textile("synth-profile --material " + kFig8 + " --overhang-mm 40 -o " + Quote(out));
    testing::ExpectRefused(r, out.string(), out.string());
  }
  EXPECT_EQ(ReadAll(regular), "keep me\n");
  EXPECT_EQ(Listing(root), std::set<std::string>{"regular-file"});
  EXPECT_FALSE(fs::exists("/proc/forbidden"));
}

// All or nothing: a profile that cannot be written (a folder has its name) stops the run before
// any other profile or the folder appears, and stdout stays empty.
TEST(CliSynth, AProfileThatCannotBeWrittenLeavesNothing) {
  const auto root = Scratch("cli_synth_nothing");
  fs::create_directories(root / "out" / "pabst-fig8_L060mm.profile.csv");
  const auto r = Textile("synth-profile --material " + kFig8 + " --overhang-mm 40 60 -o " +
                         Quote(root / "out"));
  testing::ExpectRefused(r, "pabst-fig8_L060mm.profile.csv", "a folder in the way");
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_EQ(Listing(root / "out"), std::set<std::string>{"pabst-fig8_L060mm.profile.csv"});
}

TEST(CliSynth, RefusedRunLeavesAnExistingFolderAlone) {
  const auto dir = Scratch("cli_synth_keep");
  const auto good =
      Textile("synth-profile --material " + kFig8 + " --overhang-mm 40 -o " + Quote(dir));
  ASSERT_EQ(good.exit_code, 0) << good.err;
  const auto before = Listing(dir);
  ASSERT_EQ(before.size(), 1u);
  const std::string bytes = ReadAll(dir / *before.begin());
  // Same overhang and folder, but a bad second overhang and a different noise: refused before
  // anything is written, so the old 40 mm profile is untouched.
  const auto bad = Textile("synth-profile --material " + kFig8 +
                           " --overhang-mm 40 2000 --noise-mm 0.3 -o " + Quote(dir));
  testing::ExpectRefused(bad, "--overhang-mm", "overhang 2000");
  EXPECT_EQ(Listing(dir), before);
  EXPECT_EQ(ReadAll(dir / *before.begin()), bytes);
}

}  // namespace
}  // namespace textile
