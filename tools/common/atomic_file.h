#ifndef TEXTILE_TOOLS_COMMON_ATOMIC_FILE_H_
#define TEXTILE_TOOLS_COMMON_ATOMIC_FILE_H_

// Every file the CLI writes goes through here: the content lands in a temporary file next to
// the target and is renamed over it only when complete, so a failed run leaves no
// half-written file and never replaces a good one with garbage (docs/spec/cli.md).
//
//   textile::AtomicFile out("fit.json");        // throws InputError if the folder is unusable
//   std::ofstream(out.temp_path()) << text;      // or let a library write to temp_path()
//   out.Commit();                                // rename; without it the temp file is removed

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace textile {

class AtomicFile {
 public:
  // path: the final file. Checks that its folder exists and is writable; with a stage_dir (an
  // OutputFolder's) the folder may be missing: the temporary file goes there, and Commit makes
  // the folder.
  explicit AtomicFile(std::string path, const std::string& stage_dir = "");
  ~AtomicFile();  // removes the temporary file unless committed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& path() const { return path_; }
  // Where to write; same folder and extension as path() so writers that go by the
  // extension (OpenCV, Cairo) pick the right format.
  const std::string& temp_path() const { return temp_; }
  // Writes text (bytes as they are) to temp_path(); throws InputError naming path() on failure.
  void Write(std::string_view text) const;
  // Moves the finished temporary file into place. Throws InputError if it is missing/empty.
  void Commit();
  // Throws InputError, as Commit would, if the temporary file is missing or empty.
  void CheckWritten() const;

 private:
  std::string path_, temp_;
  bool committed_ = false;
  int cleanup_slot_ = -1;  // InstallSignalCleanup's record of temp_
};

// Outputs of one run that appear together or not at all (extract: a profile and an overlay per
// photo). Files not committed are removed with the set.
//
//   textile::AtomicFileSet outputs;
//   for (...) std::ofstream(outputs.Add(path).temp_path()) << text;  // throws: nothing appears
//   outputs.Commit();
//
// Commit checks every temporary file before moving any into place; the renames themselves
// (same folder) are not one atomic step, so only a rename failing midway could leave a part.
class AtomicFileSet {
 public:
  // Stages one more output; throws InputError like AtomicFile.
  AtomicFile& Add(std::string path, const std::string& stage_dir = "");
  void Commit();

 private:
  std::vector<std::unique_ptr<AtomicFile>> files_;
};

// Refuses outputs of one run that name the same file (one would silently replace the other):
// throws InputError "<flag> and <flag> name the same file <path>". Each entry is {flag, path};
// empty paths (outputs not asked for) are skipped; paths are compared after
// std::filesystem::weakly_canonical, so "a.json" and "./a.json" are the same file.
// Also refuses an output that is one of the run's existing input files, {flag, path} each (the
// same file by std::filesystem::equivalent: links and "./" spellings too): throws InputError
// "<flag> <path> is the input <flag>: the run would overwrite it".
void CheckDistinctOutputs(const std::vector<std::pair<std::string, std::string>>& outputs,
                          const std::vector<std::pair<std::string, std::string>>& inputs = {});

// Refuses an output whose extension (any case) is none of `extensions` (".png", ".jpg", ...):
// throws InputError "<flag>: <path>: name it .png or .jpg". Image writers go by the name, and
// one they cannot serve would fail only after the work (OpenCV: with an exception, exit 3).
void CheckOutputExtension(const std::string& flag, const std::string& path,
                          const std::vector<std::string>& extensions);

// Writes text to path atomically. Throws InputError naming the path on failure.
void WriteFileAtomically(const std::string& path, std::string_view text);

// Creates a directory (and parents) for outputs; throws InputError naming it on failure.
void EnsureDirectory(const std::string& dir);

// The output folder of a command whose outputs are files in it (extract, synth-profile,
// validate), made only when its files are committed: until then they wait in a private folder
// (mkdtemp, mode 0700) made in its nearest existing ancestor, on the same filesystem, so a failed
// run leaves no folder behind and never takes one away from another run writing there. The
// private folder goes with the OutputFolder: declare it before the outputs' AtomicFileSet.
// Throws InputError naming the folder when it exists and is not one, when a broken link is in
// its way, or when its nearest existing ancestor is not a folder one can write in.
class OutputFolder {
 public:
  explicit OutputFolder(const std::string& dir);
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;
  const std::string& stage_dir() const { return stage_dir_; }

 private:
  std::string stage_dir_;
  int cleanup_slot_ = -1;  // InstallSignalCleanup's record of stage_dir_
};

// A run stopped by SIGINT, SIGTERM, SIGHUP or SIGQUIT (Ctrl-C, kill, a closed terminal, Ctrl-\)
// removes its AtomicFiles' temporary files and its OutputFolders' private folders, with
// whatever is in them, before the signal ends it as it would have (the exit status still says
// which signal). The handler makes async-signal-safe calls only (unlink, unlinkat, getdents64,
// lseek, rmdir, then sigaction and raise; tgkill to hand a signal on) on paths and folders
// recorded when they were made, by the main thread, up to 1024 at once, of up to 1023 bytes
// each: a temporary file past that stays, a private folder past that stays with its files. It
// runs on the main thread (the one that makes and commits outputs; a signal sent to another goes
// there, so the main thread must not block these signals). A signal ignored when the run started
// (nohup's SIGHUP, SIGINT in a shell's background job) stays ignored. Not covered: a signal between
// mkdtemp and its record, or in the middle of an AtomicFileSet's renames (some outputs in place,
// the rest gone), and SIGKILL, which cannot be caught. Call once, from main.
void InstallSignalCleanup();

}  // namespace textile

#endif  // TEXTILE_TOOLS_COMMON_ATOMIC_FILE_H_
