// What `textile` loads at start-up: neither Gmsh nor OpenCV's image codecs, each of which brings
// dozens of libraries of its own (textile/sim/core/shared_library.h); a command opens them when it
// needs them, and without them fails with one line and no files while the rest still run.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "run_cli.h"

namespace textile {
namespace {

namespace fs = std::filesystem;
using testing::Scratch;
using testing::Textile;

const std::string kNoCodecs = "TEXTILE_IMGCODECS=/nonexistent/libopencv_imgcodecs.so.406";
const std::string kFig8 = "--material samples/materials/pabst-fig8.json";
const std::string kCoarse = " --resolution-mm 15 --no-coarse-to-fine --rim-mm 0";

void ExpectNoCodecsError(const testing::CliResult& r) {
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(r.err.rfind("error: cannot load OpenCV's image codecs (tried "
                        "/nonexistent/libopencv_imgcodecs.so.406)",
                        0),
            0u)
      << r.err;
  EXPECT_EQ(testing::CountLines(r.err), 1) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(CliStartup, TheExecutableLinksNeitherGmshNorTheImageCodecs) {
  const fs::path listing = Scratch("CliStartup.Ldd") / "ldd.txt";
  const std::string cmd =
      std::string("ldd '") + TEXTILE_EXE + "' > '" + listing.string() + "' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const std::string libraries = testing::ReadAll(listing);
  ASSERT_NE(libraries.find("libopencv_core"), std::string::npos) << libraries;  // ldd worked
  EXPECT_EQ(libraries.find("imgcodecs"), std::string::npos) << libraries;
  EXPECT_EQ(libraries.find("gmsh"), std::string::npos) << libraries;
  EXPECT_EQ(libraries.find("gdal"), std::string::npos) << libraries;
}

TEST(CliStartup, WithoutTheImageCodecsPhotoCommandsFailWithOneLineAndNoFiles) {
  const fs::path dir = Scratch("CliStartup.NoCodecs");
  const std::string photo = "samples/photos/pabst-fig8_L040mm.jpg";
  const std::string rig = " --rig samples/photos/pabst-fig8.rig-truth.json";
  ExpectNoCodecsError(
      Textile("extract " + photo + rig + " -o " + (dir / "extract").string(), kNoCodecs));
  ExpectNoCodecsError(
      Textile("fit " + photo + rig + " --gsm 200 -o " + (dir / "fit.json").string(), kNoCodecs));
  ExpectNoCodecsError(
      Textile("calibrate samples/photos/pabst-fig8.board.jpg --board 9x6 "
              "--square-mm 8.5 -o " +
                  (dir / "rig.json").string(),
              kNoCodecs));
  ExpectNoCodecsError(Textile(
      "render-photo " + kFig8 + " --overhang-mm 40 -o " + (dir / "strip.jpg").string(), kNoCodecs));
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    EXPECT_TRUE(entry.is_directory()) << entry.path();  // no file written
}

TEST(CliStartup, WithoutTheImageCodecsTheOtherCommandsRun) {
  const fs::path dir = Scratch("CliStartup.OthersRun");
  const auto law = Textile("law " + kFig8, kNoCodecs);
  EXPECT_EQ(law.exit_code, 0) << law.err;
  const auto fit = Textile(
      "fit samples/profiles/pabst-fig8_L0*.profile.csv --gsm 200 -o " + (dir / "fit.json").string(),
      kNoCodecs);
  EXPECT_EQ(fit.exit_code, 0) << fit.err;
  // The drape's picture is Cairo's (textile/sim/plot/drape_picture.h), not OpenCV's.
  const auto drape = Textile("drape " + kFig8 + kCoarse + " -o " + (dir / "d.json").string() +
                                 " --png " + (dir / "d.png").string(),
                             kNoCodecs);
  EXPECT_EQ(drape.exit_code, 0) << drape.err;
  EXPECT_TRUE(fs::exists(dir / "d.json"));
  EXPECT_GT(fs::file_size(dir / "d.png"), 5000u);
}

// A report that cannot reach stdout (here a full disk) fails the run instead of passing for a
// success; its files were committed before it was printed.
TEST(CliStartup, AReportThatCannotBeWrittenIsAFailure) {
  const fs::path err = Scratch("CliStartup.Full") / "err.txt";
  const std::string cmd = std::string("cd '") + TEXTILE_SOURCE_DIR + "' && '" + TEXTILE_EXE +
                          "' law " + kFig8 + " > /dev/full 2> '" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_EQ(testing::ReadAll(err), "error: cannot write the report to stdout\n");
}

// The executable installs the signal cleanup (tools/common/app_main.cc): an `extract` stopped
// with SIGTERM once its private folder exists dies of the signal and leaves nothing
// (SignalCleanup.* test the handler itself).
TEST(CliStartup, AStoppedRunDiesOfTheSignalAndLeavesNothing) {
  const fs::path d = Scratch("CliStartup.Stopped");
  const std::string photos =
      "samples/photos/pabst-fig8_L040mm.jpg samples/photos/pabst-fig8_L060mm.jpg "
      "samples/photos/pabst-fig8_L080mm.jpg";
  // Waits (up to 5 s) for the staging folder, then stops the run; writes its exit status.
  const std::string cmd =
      std::string("cd '") + TEXTILE_SOURCE_DIR + "' && ('" + TEXTILE_EXE + "' extract " + photos +
      " --mm-per-px 0.11 -o '" + (d / "out" / "sub").string() +
      "' > /dev/null 2>&1 & pid=$!; for i in $(seq 500); do ls -d '" + d.string() +
      "'/.textile-stage-* > /dev/null 2>&1 && break; sleep 0.01; done; "
      "kill -TERM $pid; wait $pid 2> /dev/null; echo $? > '" +
      (d / "status").string() + "')";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  // 143 = 128 + SIGTERM: it died of the signal (not exit 0: it had not finished).
  EXPECT_EQ(testing::ReadAll(d / "status"), "143\n");
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(d)) left.push_back(e.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"status"});
}

TEST(CliStartup, NoCommandIsOneLineNamingTheCommands) {
  const auto r = Textile("");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err.rfind("error: no command given (the commands: law, synth-profile, ", 0), 0u)
      << r.err;
  EXPECT_NE(r.err.find(", bench)"), std::string::npos) << r.err;
  EXPECT_EQ(testing::CountLines(r.err), 1) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

}  // namespace
}  // namespace textile
