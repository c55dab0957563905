#include "common/atomic_file.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "textile/sim/core/error.h"

namespace fs = std::filesystem;

namespace textile {
namespace {

std::string Slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

fs::path ScratchDir(const std::string& name) {
  const fs::path d = fs::path(TEXTILE_BINARY_DIR) / "test_scratch" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(AtomicFile, WritesAndReplaces) {
  const fs::path d = ScratchDir("atomic_writes");
  const std::string p = (d / "a.json").string();
  WriteFileAtomically(p, "first");
  WriteFileAtomically(p, "second");
  EXPECT_EQ(Slurp(p), "second");
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator{}), 1);
}

TEST(AtomicFile, UncommittedLeavesOldFileAndNoTemp) {
  const fs::path d = ScratchDir("atomic_abort");
  const std::string p = (d / "a.json").string();
  WriteFileAtomically(p, "good");
  {
    AtomicFile out(p);
    std::ofstream(out.temp_path()) << "half";
    // destroyed without Commit: as if the computation threw
  }
  EXPECT_EQ(Slurp(p), "good");
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator{}), 1);
}

TEST(AtomicFile, TempKeepsExtensionForFormatWriters) {
  const fs::path d = ScratchDir("atomic_ext");
  AtomicFile out((d / "plot.png").string());
  EXPECT_EQ(fs::path(out.temp_path()).extension(), ".png");
  EXPECT_EQ(fs::path(out.temp_path()).parent_path(), d);
}

TEST(AtomicFile, RefusesMissingFolder) {
  try {
    AtomicFile out("/nonexistent-textile-dir/x.json");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
}

TEST(AtomicFile, CommitWithoutContentThrows) {
  const fs::path d = ScratchDir("atomic_empty");
  AtomicFile out((d / "x.json").string());
  EXPECT_THROW(out.Commit(), InputError);
  EXPECT_FALSE(fs::exists(d / "x.json"));
}

TEST(AtomicFile, WriteFillsTheTemporaryFileByteForByte) {
  const fs::path d = ScratchDir("atomic_write");
  const std::string p = (d / "a.csv").string();
  const std::string text("x,y\r\n\0\xff\n", 8);  // bytes as they are: CR, NUL, not UTF-8
  AtomicFile out(p);
  out.Write(text);
  EXPECT_FALSE(fs::exists(p));
  out.Commit();
  std::ifstream f(p, std::ios::binary);
  const std::string back((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  EXPECT_EQ(back, text);
  // A temporary file that cannot be written (its folder gone) is an InputError naming the file.
  const fs::path gone = d / "gone";
  fs::create_directories(gone);
  AtomicFile lost((gone / "b.json").string());
  fs::remove_all(gone);
  try {
    lost.Write("{}");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("b.json"), std::string::npos) << e.what();
  }
}

TEST(AtomicFileSet, AllOrNothing) {
  const fs::path d = ScratchDir("atomic_set");
  WriteFileAtomically((d / "a.csv").string(), "old a");
  const auto count = [&d] {
    return std::distance(fs::directory_iterator(d), fs::directory_iterator{});
  };
  {
    // One file of the set was never written: Commit moves none, the old file stays, and the
    // temporary files go with the set.
    AtomicFileSet set;
    std::ofstream(set.Add((d / "a.csv").string()).temp_path()) << "new a";
    set.Add((d / "b.png").string());
    EXPECT_THROW(set.Commit(), InputError);
  }
  EXPECT_EQ(Slurp(d / "a.csv"), "old a");
  EXPECT_EQ(count(), 1);
  {
    // A failure before Commit (an exception while staging) leaves nothing either.
    AtomicFileSet set;
    std::ofstream(set.Add((d / "c.csv").string()).temp_path()) << "c";
    EXPECT_THROW(set.Add((d / "missing" / "d.csv").string()), InputError);
  }
  EXPECT_EQ(count(), 1);
  AtomicFileSet set;
  std::ofstream(set.Add((d / "a.csv").string()).temp_path()) << "new a";
  std::ofstream(set.Add((d / "b.png").string()).temp_path()) << "b";
  set.Commit();
  EXPECT_EQ(Slurp(d / "a.csv"), "new a");
  EXPECT_EQ(Slurp(d / "b.png"), "b");
  EXPECT_EQ(count(), 2);
}

TEST(CheckDistinctOutputs, SameFileUnderAnyNameIsRefusedNamingBothFlags) {
  // Files that do not exist yet (the usual case), named relatively, with "./", "..", or
  // absolutely: all the same file. Empty paths are outputs not asked for.
  const fs::path d = ScratchDir("distinct_outputs");
  const fs::path cwd = fs::current_path();
  fs::current_path(d);
  const std::string abs = (d / "r.json").string();
  for (const auto& [a, b] : std::vector<std::pair<std::string, std::string>>{
           {"r.json", "./r.json"}, {"r.json", abs}, {"sub/../r.json", "r.json"}, {abs, "./r.json"}}) {
    SCOPED_TRACE(a + " / " + b);
    try {
      CheckDistinctOutputs({{"-o", a}, {"--png", ""}, {"--ply", b}});
      ADD_FAILURE() << "not refused";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), "-o and --ply name the same file " + b);
    }
  }
  EXPECT_NO_THROW(CheckDistinctOutputs({{"-o", "r.json"}, {"--png", ""}, {"--obj", ""}, {"--ply", "r.ply"}}));
  EXPECT_TRUE(fs::is_empty(d));
  fs::current_path(cwd);
}

}  // namespace
}  // namespace textile

namespace textile {
namespace {

// An output folder is made only when its files are committed; until then they wait in its
// nearest existing ancestor, so a failed run leaves nothing and removes nothing.
TEST(OutputFolder, IsMadeOnlyWhenItsFilesAreCommitted) {
  const fs::path d = ScratchDir("output_folder");
  const fs::path dir = d / "a" / "b";
  {
    const OutputFolder folder(dir.string());
    // A private folder in the nearest existing ancestor.
    EXPECT_EQ(fs::path(folder.stage_dir()).parent_path(), fs::canonical(d));
    EXPECT_EQ(fs::status(folder.stage_dir()).permissions(), fs::perms::owner_all);
    AtomicFileSet failed;
    failed.Add((dir / "x.csv").string(), folder.stage_dir()).Write("abandoned");
    EXPECT_FALSE(fs::exists(d / "a"));  // staged beside it, not in it
  }
  EXPECT_TRUE(fs::is_empty(d));  // the failed run's files and private folder are gone
  {
    const OutputFolder folder(dir.string() + "/");
    AtomicFileSet outputs;
    outputs.Add((dir / "x.csv").string(), folder.stage_dir()).Write("kept");
    outputs.Commit();
  }
  EXPECT_EQ(Slurp(dir / "x.csv"), "kept");
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator{}), 1);  // just a/
  // An existing folder stages in itself; a broken link in the way is refused before any work.
  EXPECT_EQ(fs::path(OutputFolder(dir.string()).stage_dir()).parent_path(), fs::canonical(dir));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 1);  // x.csv
  fs::create_symlink(d / "nowhere", d / "broken");
  EXPECT_THROW(OutputFolder((d / "broken" / "new").string()), InputError);
}

// A run stopped by a signal: the handler removes the temporary files (next to their targets
// and in a private folder) and the private folder, then the signal ends the process as before.
// The child dies inside the handler, so no destructor can have done it.
// A file in the private folder that no AtomicFile recorded goes too (the folder is emptied); a
// signal raised on another thread ends the run the same way (handed to the main thread: this
// checks that nothing is lost on the way, not which thread cleaned up). SIGQUIT would dump core:
// the child's core size is set to 0.
TEST(SignalCleanup, ASignalledRunLeavesNoTemporaryFilesOrFolders) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  for (const bool from_another_thread : {false, true}) {
    for (const int signal_number : {SIGTERM, SIGINT, SIGHUP, SIGQUIT}) {
      const fs::path d = ScratchDir("signal_cleanup");
      std::ofstream(d / "old.json") << "keep me";
      const auto run = [&] {
        const rlimit no_core{0, 0};
        ::setrlimit(RLIMIT_CORE, &no_core);
        InstallSignalCleanup();
        AtomicFile next_to_target((d / "old.json").string());
        next_to_target.Write("half");
        const OutputFolder folder((d / "out").string());
        AtomicFileSet staged;
        staged.Add((d / "out" / "a.csv").string(), folder.stage_dir()).Write("a");
        staged.Add((d / "out" / "b.png").string(), folder.stage_dir()).Write("b");
        std::ofstream(fs::path(folder.stage_dir()) / "unrecorded.png") << "c";
        if (from_another_thread) {
          std::thread([signal_number] { std::raise(signal_number); }).join();
          for (;;) ::pause();  // the main thread takes it over
        }
        std::raise(signal_number);
        std::_Exit(0);  // not reached
      };
      EXPECT_EXIT(run(), ::testing::KilledBySignal(signal_number), "");
      // Only what was there before: no .tmp- file, no .textile-stage- folder, no out/.
      std::vector<std::string> left;
      for (const auto& e : fs::directory_iterator(d)) left.push_back(e.path().filename().string());
      EXPECT_EQ(left, std::vector<std::string>{"old.json"})
          << "signal " << signal_number << (from_another_thread ? " from another thread" : "");
      EXPECT_EQ(Slurp(d / "old.json"), "keep me");
    }
  }
}

// A signal ignored when the run started (nohup's SIGHUP) stays ignored: the run goes on.
TEST(SignalCleanup, AnIgnoredSignalStaysIgnored) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        std::signal(SIGHUP, SIG_IGN);
        InstallSignalCleanup();
        std::raise(SIGHUP);
        std::_Exit(7);
      },
      ::testing::ExitedWithCode(7), "");
}

// Without the handler the same run leaves its temporary files behind: the test above can fail.
TEST(SignalCleanup, WithoutTheHandlerTheFilesStay) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const fs::path d = ScratchDir("signal_no_cleanup");
  EXPECT_EXIT(
      {
        std::signal(SIGTERM, SIG_DFL);
        AtomicFile next_to_target((d / "new.json").string());
        next_to_target.Write("half");
        std::raise(SIGTERM);
        std::_Exit(0);
      },
      ::testing::KilledBySignal(SIGTERM), "");
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator{}), 1);
}

TEST(OutputFolder, RefusesAFileInTheWay) {
  const fs::path d = ScratchDir("output_folder_file");
  std::ofstream(d / "plain") << "keep me";
  for (const fs::path& dir : {d / "plain", d / "plain" / "sub"}) {
    try {
      OutputFolder folder(dir.string());
      ADD_FAILURE() << dir << " was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(dir.string() + ": cannot create output folder: ", 0),
                0u)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("plain is not a folder"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(Slurp(d / "plain"), "keep me");
}

}  // namespace
}  // namespace textile
