// The workflow recipes (workflow/Snakefile, workflow/parallel.sh) on the shipped series: one job
// a specimen, then the summary and the report, byte-identical to one `textile batch` run.
// Skipped where Debian's snakemake or parallel is not installed (cmake/debian-packages.txt
// installs both).

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "run_cli.h"

namespace textile {
namespace {

using testing::ReadAll;
using testing::Scratch;
using testing::Textile;
namespace fs = std::filesystem;

const std::string kSource = TEXTILE_SOURCE_DIR;
const std::string kManifest = kSource + "/samples/series/manifest.csv";

// The summary one plain `textile batch` writes for the shipped series.
std::string DirectSummary(const fs::path& dir) {
  const auto r = Textile("batch " + kManifest + " -o " + (dir / "direct").string());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return ReadAll(dir / "direct/summary.json");
}

int Shell(const std::string& cmd, const fs::path& log) {
  const int status = std::system((cmd + " > '" + log.string() + "' 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Workflow, SnakemakeRunsOneJobASpecimenThenTheSummaryAndReport) {
  if (!fs::exists("/usr/bin/snakemake")) GTEST_SKIP() << "no snakemake (Debian: snakemake)";
  const fs::path d = Scratch("workflow_snakemake");
  const std::string cmd = "snakemake -s '" + kSource + "/workflow/Snakefile' --cores 2 -q " +
                          "--directory '" + d.string() + "' --config manifest='" + kManifest +
                          "' out='" + (d / "out").string() + "' textile='" + TEXTILE_EXE + "'";
  ASSERT_EQ(Shell(cmd, d / "log"), 0) << ReadAll(d / "log");
  EXPECT_EQ(ReadAll(d / "out/summary.json"), DirectSummary(d));
  EXPECT_TRUE(fs::exists(d / "out/report.html"));
  // Every specimen was its own job: the summary job resumed them all.
  EXPECT_TRUE(fs::exists(d / "out/interlining/photo-1/specimen.json"));
}

TEST(Workflow, SnakemakeRefitsAChangedInputAndReadsHeadersAsTextileDoes) {
  if (!fs::exists("/usr/bin/snakemake")) GTEST_SKIP() << "no snakemake (Debian: snakemake)";
  const fs::path d = Scratch("workflow_snakemake_changed");
  const fs::path profiles = fs::path(kSource) / "samples/profiles";
  fs::copy_file(profiles / "pabst-fig8_L060mm.profile.csv", d / "a.csv");
  fs::copy_file(profiles / "pabst-fig8_L080mm.profile.csv", d / "b.csv");
  // Header names in capitals, as a spreadsheet may write them: textile takes them, so must the
  // workflow.
  std::ofstream(d / "m.csv") << "Fabric,Specimen,Direction,Side,Inputs,GSM\n"
                             << "f,a,warp,face,a.csv,200\nf,b,weft,face,b.csv,200\n";
  const std::string cmd = "snakemake -s '" + kSource + "/workflow/Snakefile' --cores 1 -q " +
                          "--directory '" + d.string() + "' --config manifest='" +
                          (d / "m.csv").string() + "' out='" + (d / "out").string() +
                          "' textile='" + TEXTILE_EXE + "'";
  ASSERT_EQ(Shell(cmd, d / "log"), 0) << ReadAll(d / "log");
  const std::string before = ReadAll(d / "out/summary.json");
  fs::copy_file(profiles / "pabst-fig8_L040mm.profile.csv", d / "a.csv",
                fs::copy_options::overwrite_existing);
  ASSERT_EQ(Shell(cmd, d / "log2"), 0) << ReadAll(d / "log2");
  EXPECT_NE(ReadAll(d / "out/summary.json"), before) << "the changed profile was not refitted";
}

TEST(Workflow, GnuParallelRecipeLogsItsJobsAndResumes) {
  if (!fs::exists("/usr/bin/parallel")) GTEST_SKIP() << "no GNU parallel (Debian: parallel)";
  const fs::path d = Scratch("workflow_parallel");
  const std::string cmd = "TEXTILE='" + std::string(TEXTILE_EXE) + "' bash '" + kSource +
                          "/workflow/parallel.sh' '" + kManifest + "' '" + (d / "out").string() +
                          "' 2";
  ASSERT_EQ(Shell(cmd, d / "log"), 0) << ReadAll(d / "log");
  EXPECT_EQ(ReadAll(d / "out/summary.json"), DirectSummary(d));
  EXPECT_EQ(testing::CountLines(ReadAll(d / "out/joblog")), 8);  // a header and 7 specimens
  // Again: parallel's --resume runs no job the log has as done.
  ASSERT_EQ(Shell(cmd, d / "log2"), 0) << ReadAll(d / "log2");
  EXPECT_EQ(testing::CountLines(ReadAll(d / "out/joblog")), 8);
  EXPECT_NE(ReadAll(d / "log2").find("7 resumed"), std::string::npos) << ReadAll(d / "log2");
}

}  // namespace
}  // namespace textile
