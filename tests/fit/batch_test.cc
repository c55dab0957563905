// textile batch's library (photo/batch.h): the manifest refused row by row and column by
// column, shards, statistics, the summary and fabric materials, and runs that are the same
// bytes fresh, resumed and merged from shards, with a failing specimen listed, not fatal.

#include "textile/photo/batch.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

namespace fs = std::filesystem;

const std::string kProfiles = std::string(TEXTILE_SOURCE_DIR) + "/samples/profiles/";
const std::string kHeader = "fabric,specimen,direction,side,inputs,gsm\n";

std::string Fig8(const std::string& l) { return kProfiles + "pabst-fig8_L0" + l + "mm.profile.csv"; }

// The InputError message of parsing `text`, or "" when it parses.
std::string ParseError(const std::string& text) {
  try {
    ParseManifest(text, "series.csv", "");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string ReadAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Every file under `dir` -> its bytes.
std::map<std::string, std::string> Tree(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out[fs::relative(e.path(), dir).string()] = ReadAll(e.path());
  return out;
}

fs::path Scratch(const std::string& name) {
  fs::path d = fs::path(TEXTILE_BINARY_DIR) / "test_scratch" / ("batch_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// Two warp and two weft specimens of the Fig. 8 fabric, and one of a second fabric that
// cannot be fitted (a profile file that is no profile).
Manifest SmallSeries(const fs::path& dir) {
  std::ofstream(dir / "broken.csv") << "s_mm,x_mm,y_mm\n0,0,0\n";
  const std::string text = kHeader +
                           "fig8,w1,warp,face," + Fig8("40") + ";" + Fig8("60") + ",200\n" +
                           "fig8,w2,warp,back," + Fig8("80") + ",200\n" +
                           "fig8,f1,weft,face," + Fig8("60") + ",200\n" +
                           "fig8,f2,weft,back," + Fig8("40") + ";" + Fig8("80") + ",200\n" +
                           "bad,x1,bias,face,broken.csv,120\n";
  return ParseManifest(text, "series.csv", dir.string());
}

TEST(BatchManifest, ColumnsComeInAnyOrderAndQuotedCellsKeepTheirCommas) {
  const Manifest m = ParseManifest(
      "gsm,inputs,side,direction,specimen,fabric,notes,width_mm\n"
      "180,a.csv;b.csv,back,bias,s-1,twill_2,\"wet, then dried\",25\n",
      "series.csv", "lab");
  ASSERT_EQ(m.rows.size(), 1u);
  const ManifestRow& r = m.rows[0];
  EXPECT_EQ(r.fabric, "twill_2");
  EXPECT_EQ(r.direction, StripDirection::kBias);
  EXPECT_EQ(r.side, FabricSide::kBack);
  EXPECT_EQ(r.inputs, (std::vector<std::string>{"a.csv", "b.csv"}));
  EXPECT_EQ(r.paths[1], (fs::path("lab") / "b.csv").string());
  EXPECT_EQ(r.notes, "wet, then dried");
  EXPECT_EQ(r.width_mm, 25.0);
  EXPECT_EQ(r.line, 2);
}

TEST(BatchManifest, EachMistakeNamesItsLineAndColumn) {
  EXPECT_NE(ParseError("fabric,specimen,direction,side,inputs\n").find("missing column 'gsm'"),
            std::string::npos);
  EXPECT_NE(ParseError("fabric,specimen,direction,side,inputs,gsm,colour\n").find("unknown column"),
            std::string::npos);
  EXPECT_NE(ParseError(kHeader + "f,s,warp,face,a.csv,200\nf,s,weft,face,b.csv,200\n")
                .find("line 3, column specimen: specimen 's' of fabric 'f' is listed twice"),
            std::string::npos);
  EXPECT_NE(ParseError(kHeader + "f,s,diagonal,face,a.csv,200\n")
                .find("line 2, column direction: unknown direction 'diagonal'"),
            std::string::npos);
  EXPECT_NE(ParseError(kHeader + "f,s,warp,top,a.csv,200\n").find("column side"),
            std::string::npos);
  EXPECT_NE(ParseError(kHeader + "f,s,warp,face,a.csv,200 g/m2\n")
                .find("line 2, column gsm: '200 g/m2' is not a number"),
            std::string::npos);
  EXPECT_NE(ParseError(kHeader + "f,s,warp,face,a.csv,0.2\n").find("column gsm"),
            std::string::npos);
  EXPECT_NE(ParseError(kHeader + "../up,s,warp,face,a.csv,200\n").find("cannot name a folder"),
            std::string::npos);
  EXPECT_NE(ParseError(kHeader + "f,s,warp,face,a.csv;a.csv,200\n").find("given twice"),
            std::string::npos);
  EXPECT_NE(ParseError(kHeader + "f,s,warp,face,a.csv\n").find("5 cells for 6 columns"),
            std::string::npos);
  EXPECT_NE(ParseError(kHeader).find("no specimens"), std::string::npos);
  EXPECT_NE(ParseError("").find("empty"), std::string::npos);
  EXPECT_NE(ParseError(kHeader + "f,\"s,warp,face,a.csv,200\n").find("quote"), std::string::npos);
  EXPECT_NE(ParseError("fabric,specimen,direction,side,inputs,gsm,rig,mm_per_px\n"
                       "f,s,warp,face,a.jpg,200,rig.json,0.1\n")
                .find("column mm_per_px: give a rig or a scale"),
            std::string::npos);
  EXPECT_NE(ParseError("fabric;specimen;direction;side;inputs;gsm\n").find("comma-separated"),
            std::string::npos);
  EXPECT_NE(ParseError(std::string("fab\0ric", 7)).find("not a text file"), std::string::npos);
  EXPECT_EQ(ParseError("\xEF\xBB\xBF" + kHeader + "f,s,warp,face,a.csv,200\n"), "")
      << "a spreadsheet's byte-order mark is no column name";
  EXPECT_NE(ParseError("fabric,specimen,direction,side,inputs,gsm,validate\n"
                       "f,s,warp,face,a.csv,200,maybe\n")
                .find("column validate: 'maybe'"),
            std::string::npos);
  EXPECT_NE(ParseError(kHeader + "f,material.json,warp,face,a.csv,200\n").find("a file batch writes"),
            std::string::npos);
  EXPECT_NE(ParseError(kHeader + "summary.csv,s,warp,face,a.csv,200\n").find("a file batch writes"),
            std::string::npos);
  EXPECT_EQ(ParseError(kHeader + "f,s,warp,face,a.csv,200\n"), "");
}

TEST(BatchManifest, SpreadsheetHabitsAreRead) {
  // Blank lines before the header, rows of empty cells, values in capitals, CRLF line ends.
  const Manifest m = ParseManifest("\r\n" + kHeader + ",,,,,\r\nf,s,Warp,FACE,a.csv,200\r\n\n",
                                   "series.csv", "");
  ASSERT_EQ(m.rows.size(), 1u);
  EXPECT_EQ(m.rows[0].direction, StripDirection::kWarp);
  EXPECT_EQ(m.rows[0].side, FabricSide::kFace);
  EXPECT_EQ(m.rows[0].inputs[0], "a.csv");
}

TEST(BatchManifest, ReadingChecksThatEveryInputExists) {
  const fs::path dir = Scratch("missing_input");
  std::ofstream(dir / "m.csv") << kHeader << "f,s,warp,face," << Fig8("40") << ";gone.csv,200\n";
  try {
    ReadManifest((dir / "m.csv").string());
    FAIL() << "a missing input was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2, column inputs: gone.csv does not exist"),
              std::string::npos)
        << e.what();
  }
}

TEST(BatchManifest, ReadingChecksThatAPhotoHasARigOrScaleAndInputsAreFiles) {
  const fs::path dir = Scratch("photo_without_rig");
  const std::string photo = std::string(TEXTILE_SOURCE_DIR) + "/samples/photos/pabst-fig8_L040mm.jpg";
  std::ofstream(dir / "m.csv") << kHeader << "f,s,warp,face," << photo << ",200\n";
  try {
    ReadManifest((dir / "m.csv").string());
    FAIL() << "a photo without a rig was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2, column rig"), std::string::npos) << e.what();
  }
  fs::create_directories(dir / "folder");
  std::ofstream(dir / "f.csv") << kHeader << "f,s,warp,face,folder,200\n";
  try {
    ReadManifest((dir / "f.csv").string());
    FAIL() << "a folder was taken as an input";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is a folder"), std::string::npos) << e.what();
  }
}

TEST(BatchShard, KOfNPartitionsTheRows) {
  const Shard s = ParseShard("2/3");
  EXPECT_FALSE(s.Contains(0));
  EXPECT_TRUE(s.Contains(1));
  EXPECT_TRUE(s.Contains(4));
  for (const char* bad : {"3/2", "0/2", "2", "a/b", "1/0", "-1/2", "1/2/3", ""})
    EXPECT_THROW(ParseShard(bad), InputError) << bad;
}

TEST(BatchStats, SampleSdAndCv) {
  const SeriesStats s = Stats({2.0, 4.0, 6.0});
  EXPECT_EQ(s.n, 3u);
  EXPECT_DOUBLE_EQ(s.mean, 4.0);
  EXPECT_DOUBLE_EQ(*s.sd, 2.0);  // n - 1 in the denominator, as ASTM D1388 and FAST report it
  EXPECT_DOUBLE_EQ(*s.cv, 0.5);
  const SeriesStats one = Stats({3.0});
  EXPECT_FALSE(one.sd.has_value());
  EXPECT_EQ(Stats({}).n, 0u);
}

TEST(Batch, AFailingSpecimenIsListedAndTheOthersAreSummarised) {
  const fs::path dir = Scratch("run");
  const Manifest m = SmallSeries(dir);
  BatchOptions o;
  o.out_dir = (dir / "out").string();
  o.jobs = 2;
  const BatchResult r = RunBatch(m, o);
  EXPECT_EQ(r.failed, 1);
  ASSERT_TRUE(r.summary_written);
  const SpecimenOutcome& bad = r.specimens[4];
  EXPECT_EQ(bad.status, SpecimenStatus::kFailed);
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_EQ(bad.error.find(dir.string()), std::string::npos) << "paths as the manifest spells them";
  EXPECT_NE(bad.error.find("broken.csv"), std::string::npos) << bad.error;
  EXPECT_FALSE(fs::exists(dir / "out/bad/x1/material.json"));
  EXPECT_TRUE(fs::exists(dir / "out/bad/x1/specimen.json"));
  EXPECT_FALSE(fs::exists(dir / "out/bad/material.json"));

  // The statistics are those of the specimens' own laws.
  const nlohmann::json& warp = r.summary["directions"][0];
  EXPECT_EQ(warp["direction"], "warp");
  EXPECT_EQ(warp["n"], 2);
  const double w1 = r.specimens[0].material->bending.b1_kes();
  const double w2 = r.specimens[1].material->bending.b1_kes();
  EXPECT_NEAR(warp["b1_gfcm"]["mean"].get<double>(), 0.5 * (w1 + w2), 1e-12);
  EXPECT_NEAR(warp["b1_gfcm"]["sd"].get<double>(), std::abs(w1 - w2) / std::sqrt(2.0), 1e-12);
  // The Fig. 8 law is b1 = 0.1 gf·cm; each specimen's fit lands within a few per cent.
  EXPECT_NEAR(warp["b1_gfcm"]["mean"].get<double>(), 0.1, 0.005);
  const nlohmann::json& fabric = r.summary["fabrics"][0];
  const double g_warp = warp["flexural_rigidity_uNm"]["mean"].get<double>();
  const double g_weft = r.summary["directions"][1]["flexural_rigidity_uNm"]["mean"].get<double>();
  EXPECT_NEAR(fabric["overall_rigidity_uNm"].get<double>(), std::sqrt(g_warp * g_weft), 1e-12);
  EXPECT_TRUE(r.summary["fabrics"][1]["overall_rigidity_uNm"].is_null());
  EXPECT_EQ(r.summary["specimens"][4]["status"], "failed");
  EXPECT_EQ(r.summary["fabrics"][1]["material_note"], "no specimen of it was fitted");
  EXPECT_TRUE(r.summary["fabrics"][0]["material_note"].is_null());

  // The fabric's material: warp and weft means, readable as any material file.
  const Material fig8 = ReadMaterial((dir / "out/fig8/material.json").string());
  EXPECT_NEAR(fig8.bending.b1_kes(), warp["b1_gfcm"]["mean"].get<double>(), 1e-9);
  ASSERT_TRUE(fig8.bending_weft.has_value());
  EXPECT_NEAR(fig8.areal_density, 0.2, 1e-12);

  // The CSV carries the same numbers, one row a fabric and direction.
  const std::string csv = ReadAll(dir / "out/summary.csv");
  EXPECT_EQ(csv.rfind("fabric,direction,n,n_failed,b1_mean_gfcm,b1_sd_gfcm,b1_cv,b1_n,", 0), 0u);
  EXPECT_NE(csv.find("\nbad,bias,0,1,"), std::string::npos) << csv;
  // No column name twice (a spreadsheet or pandas would rename or drop one).
  std::vector<std::string> columns;
  std::stringstream header(csv.substr(0, csv.find('\n')));
  for (std::string c; std::getline(header, c, ',');) columns.push_back(c);
  std::sort(columns.begin(), columns.end());
  EXPECT_EQ(std::adjacent_find(columns.begin(), columns.end()), columns.end());
}

TEST(Batch, FreshResumedAndMergedShardsAreTheSameBytes) {
  const fs::path dir = Scratch("same_bytes");
  const Manifest m = SmallSeries(dir);
  BatchOptions fresh;
  fresh.out_dir = (dir / "fresh").string();
  RunBatch(m, fresh);
  const auto fresh_tree = Tree(dir / "fresh");

  BatchOptions resumed = fresh;
  resumed.resume = true;
  resumed.jobs = 2;
  const BatchResult again = RunBatch(m, resumed);
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ(again.specimens[i].status, SpecimenStatus::kResumed);
  EXPECT_EQ(again.specimens[4].status, SpecimenStatus::kFailed) << "failures are tried again";
  EXPECT_EQ(Tree(dir / "fresh"), fresh_tree);

  BatchOptions shard;
  shard.out_dir = (dir / "sharded").string();
  for (const char* k : {"1/2", "2/2"}) {
    shard.shard = ParseShard(k);
    const BatchResult part = RunBatch(m, shard);
    EXPECT_FALSE(part.summary_written);
  }
  EXPECT_FALSE(fs::exists(dir / "sharded/summary.json"));
  shard.shard = Shard{};
  shard.resume = true;
  RunBatch(m, shard);
  EXPECT_EQ(Tree(dir / "sharded"), Tree(dir / "fresh"));
}

TEST(Batch, AChangedInputIsFittedAgainOnResume) {
  const fs::path dir = Scratch("changed_input");
  fs::copy_file(Fig8("60"), dir / "a.csv");
  const Manifest m = ParseManifest(kHeader + "f,s,warp,face,a.csv,200\n", "m.csv", dir.string());
  BatchOptions o;
  o.out_dir = (dir / "out").string();
  o.resume = true;
  EXPECT_EQ(RunBatch(m, o).specimens[0].status, SpecimenStatus::kFitted);
  EXPECT_EQ(RunBatch(m, o).specimens[0].status, SpecimenStatus::kResumed);
  fs::copy_file(Fig8("80"), dir / "a.csv", fs::copy_options::overwrite_existing);
  EXPECT_EQ(RunBatch(m, o).specimens[0].status, SpecimenStatus::kFitted);
  // A row that changes (here its gsm) is a changed input too.
  const Manifest heavier =
      ParseManifest(kHeader + "f,s,warp,face,a.csv,210\n", "m.csv", dir.string());
  EXPECT_EQ(RunBatch(heavier, o).specimens[0].status, SpecimenStatus::kFitted);
}

TEST(Batch, ARerunLeavesNoStaleOverlayAndAShardRemovesTheOldSummary) {
  const fs::path dir = Scratch("stale");
  const std::string photos = std::string(TEXTILE_SOURCE_DIR) + "/samples/photos/";
  const std::string header = "fabric,specimen,direction,side,inputs,gsm,rig\n";
  const Manifest by_photo = ParseManifest(
      header + "f,a," + "warp,face," + photos + "pabst-fig8_L060mm.jpg,200," + photos +
          "pabst-fig8.rig-truth.json\n",
      "m.csv", "");
  BatchOptions o;
  o.out_dir = (dir / "out").string();
  ASSERT_EQ(RunBatch(by_photo, o).failed, 0);
  ASSERT_TRUE(fs::exists(dir / "out/f/a/pabst-fig8_L060mm.overlay.png"));
  // The same specimen now from a profile: the photo's overlay goes with the photo.
  const Manifest by_profile =
      ParseManifest(header + "f,a,warp,face," + Fig8("60") + ",200,\n", "m.csv", "");
  ASSERT_EQ(RunBatch(by_profile, o).failed, 0);
  EXPECT_FALSE(fs::exists(dir / "out/f/a/pabst-fig8_L060mm.overlay.png"));
  ASSERT_TRUE(fs::exists(dir / "out/summary.json"));
  // A shard's run: the whole run's summary and fabric material no longer describe the folder.
  o.shard = ParseShard("1/2");
  RunBatch(by_profile, o);
  EXPECT_FALSE(fs::exists(dir / "out/summary.json"));
  EXPECT_FALSE(fs::exists(dir / "out/summary.csv"));
  EXPECT_FALSE(fs::exists(dir / "out/f/material.json"));
}

TEST(Batch, OptionsAndAnUnusableFolderAreRefusedBeforeAnySpecimen) {
  const fs::path dir = Scratch("options");
  const Manifest m = SmallSeries(dir);
  BatchOptions o;
  o.out_dir = (dir / "out").string();
  o.jobs = 0;
  EXPECT_THROW(RunBatch(m, o), InputError);
  o.jobs = 1;
  std::ofstream(dir / "file") << "x";
  o.out_dir = (dir / "file").string();
  EXPECT_THROW(RunBatch(m, o), InputError);
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(BatchSummary, AFabricWithOneOfWarpAndWeftTakesItsLawForBothAndSaysSo) {
  const fs::path dir = Scratch("one_direction");
  const Manifest m = ParseManifest(kHeader + "f,s,weft,face," + Fig8("60") + ",200\n" +
                                       "f,t,bias,face," + Fig8("80") + ",220\n",
                                   "m.csv", "");
  std::vector<SpecimenOutcome> outcomes;
  for (const ManifestRow& r : m.rows) outcomes.push_back(FitSpecimen(r));
  const std::optional<Material> mat = FabricMaterial("f", outcomes);
  ASSERT_TRUE(mat.has_value());
  EXPECT_FALSE(mat->bending_weft.has_value());
  EXPECT_NEAR(mat->bending.b1_kes(), outcomes[0].material->bending.b1_kes(), 1e-12);
  const std::string notes = mat->extra["notes"].dump();
  EXPECT_NE(notes.find("only the weft direction"), std::string::npos) << notes;
  // The bias specimen's law is carried as the measured bias, with a note saying so.
  ASSERT_TRUE(mat->bending_bias.has_value());
  EXPECT_NEAR(mat->bending_bias->b1_kes(), outcomes[1].material->bending.b1_kes(), 1e-12);
  EXPECT_NE(notes.find("bending_bias is the bias mean"), std::string::npos) << notes;
  EXPECT_NE(notes.find("200 .. 220"), std::string::npos) << notes;
  std::string why;
  EXPECT_FALSE(FabricMaterial("other", outcomes, &why).has_value());
  EXPECT_EQ(why, "no specimen of it was fitted");
}

TEST(BatchSummary, AConstantItsFitDidNotDetermineStaysOutOfTheMean) {
  const Manifest m = ParseManifest(kHeader + "f,a,warp,face,x.csv,200\nf,b,warp,face,y.csv,200\n" +
                                       "f,c,warp,face,z.csv,200\n",
                                   "m.csv", "");
  std::vector<SpecimenOutcome> outcomes(3);
  const double b1[] = {0.10, 0.11, 0.9};  // the third: one short noisy profile, b1 unresolved
  for (size_t i = 0; i < 3; ++i) {
    outcomes[i].row = &m.rows[i];
    outcomes[i].status = SpecimenStatus::kFitted;
    outcomes[i].material = LawOnlyMaterial(BendingLaw::FromKes(b1[i], 0.09, -0.01), 0.2);
    outcomes[i].material->fit = {{"b1_observed", i < 2}, {"b2_observed", true},
                                 {"c1_observed", false}};
  }
  const nlohmann::json s = SummaryJson(outcomes);
  const nlohmann::json& warp = s["directions"][0];
  EXPECT_EQ(warp["n"], 3);
  EXPECT_EQ(warp["b1_gfcm"]["n"], 2);
  EXPECT_EQ(warp["b1_gfcm"]["n_unobserved"], 1);
  EXPECT_NEAR(warp["b1_gfcm"]["mean"].get<double>(), 0.105, 1e-12);
  EXPECT_EQ(warp["c1_gfcm2"]["n"], 0);
  EXPECT_TRUE(warp["c1_gfcm2"]["mean"].is_null());
  // The material takes the observed mean, and for c1, which no fit determined, the median
  // with a note.
  const std::optional<Material> mat = FabricMaterial("f", outcomes);
  ASSERT_TRUE(mat.has_value());
  EXPECT_NEAR(mat->bending.b1_kes(), 0.105, 1e-9);
  EXPECT_NE(mat->extra["notes"].dump().find("c1 (warp): no specimen's curvatures determine it"),
            std::string::npos)
      << mat->extra["notes"].dump();
}

}  // namespace
}  // namespace textile
