#include "common/atomic_file.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "textile/sim/core/error.h"

namespace fs = std::filesystem;

namespace textile {

namespace {

// InstallSignalCleanup's records: a slot is free (0), being filled (1), or holds the path of a
// temporary file (2) or of a private folder (3), a folder with an open descriptor. Filled before
// they are marked, read by the handler only when marked; std::atomic<int> is lock-free, so the
// handler may read it. The handler runs on the main thread only (it forwards the signal there),
// the thread that records and forgets, so a slot cannot change under it.
constexpr int kCleanupSlots = 1024;
constexpr size_t kCleanupPathBytes = 1024;
constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
enum CleanupKind { kFree = 0, kFilling = 1, kTempFile = 2, kStageFolder = 3 };
struct CleanupSlot {
  std::atomic<int> kind{kFree};
  int folder_fd = -1;  // kStageFolder: the folder, opened, to empty it of unrecorded files too
  char path[kCleanupPathBytes];
};
CleanupSlot g_cleanup[kCleanupSlots];
static_assert(std::atomic<int>::is_always_lock_free);

// The slot now holding path, or -1 when there is no room (the normal paths still clean up).
int RecordForCleanup(const std::string& path, CleanupKind kind) {
  // The handler runs on the main thread only: a record from another thread could change under
  // it.
  if (path.size() >= kCleanupPathBytes || ::syscall(SYS_gettid) != ::getpid()) return -1;
  for (int i = 0; i < kCleanupSlots; ++i) {
    int expected = kFree;
    if (!g_cleanup[i].kind.compare_exchange_strong(expected, kFilling)) continue;
    std::memcpy(g_cleanup[i].path, path.c_str(), path.size() + 1);
    g_cleanup[i].folder_fd =
        kind == kStageFolder ? ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC) : -1;
    g_cleanup[i].kind.store(kind, std::memory_order_release);
    return i;
  }
  return -1;
}

void ForgetForCleanup(int slot) {
  if (slot < 0) return;
  CleanupSlot& s = g_cleanup[slot];
  s.kind.store(kFilling, std::memory_order_release);  // not the handler's any more
  if (s.folder_fd >= 0) ::close(s.folder_fd);
  s.folder_fd = -1;
  s.kind.store(kFree, std::memory_order_release);
}

// Unlinks every entry of the open folder (the private folders hold files only).
void EmptyFolder(int folder_fd) {
  ::lseek(folder_fd, 0, SEEK_SET);  // from the start, wherever the descriptor was read to
  alignas(8) char buffer[4096];
  for (;;) {
    const long n = ::syscall(SYS_getdents64, folder_fd, buffer, sizeof buffer);
    if (n <= 0) return;
    for (long at = 0; at < n;) {
      const auto* entry = reinterpret_cast<const struct dirent64*>(buffer + at);
      const char* name = entry->d_name;
      if (!(name[0] == '.' && (name[1] == '\0' || (name[1] == '.' && name[2] == '\0'))))
        ::unlinkat(folder_fd, name, 0);
      at += entry->d_reclen;
    }
  }
}

extern "C" void CleanUpAndResignal(int signal_number) {
  // Only the main thread records and forgets: a signal that reached another thread goes there.
  if (::syscall(SYS_gettid) != ::getpid()) {
    const int saved_errno = errno;
    const long forwarded = ::syscall(SYS_tgkill, ::getpid(), ::getpid(), signal_number);
    errno = saved_errno;
    if (forwarded == 0) return;  // else (no main thread) clean up here
  }
  // Files first: a private folder goes only once it is empty.
  for (CleanupSlot& slot : g_cleanup)
    if (slot.kind.load(std::memory_order_acquire) == kTempFile) ::unlink(slot.path);
  for (CleanupSlot& slot : g_cleanup) {
    if (slot.kind.load(std::memory_order_acquire) != kStageFolder) continue;
    if (slot.folder_fd >= 0) EmptyFolder(slot.folder_fd);
    ::rmdir(slot.path);
  }
  struct sigaction fallback {};
  fallback.sa_handler = SIG_DFL;
  sigemptyset(&fallback.sa_mask);
  ::sigaction(signal_number, &fallback, nullptr);
  ::raise(signal_number);
}

}  // namespace

void InstallSignalCleanup() {
  struct sigaction action {};
  action.sa_handler = CleanUpAndResignal;
  action.sa_flags = SA_RESTART;  // a thread that handed the signal on goes on where it was
  sigemptyset(&action.sa_mask);
  for (const int signal_number : kCleanupSignals) sigaddset(&action.sa_mask, signal_number);
  for (const int signal_number : kCleanupSignals) {
    // A signal the run was started with ignored stays ignored: nohup's SIGHUP, SIGINT in a
    // non-interactive shell's background jobs.
    struct sigaction before {};
    if (::sigaction(signal_number, nullptr, &before) == 0 && before.sa_handler == SIG_IGN) continue;
    ::sigaction(signal_number, &action, nullptr);
  }
}

AtomicFile::AtomicFile(std::string path, const std::string& stage_dir) : path_(std::move(path)) {
  if (path_.empty()) throw InputError("output path is empty");
  const fs::path target(path_);
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (fs::is_directory(target, ec)) throw InputError(path_ + ": is a directory, expected a file");
  if (!stage_dir.empty()) {
    dir = stage_dir;  // an OutputFolder's, checked there
  } else if (!fs::is_directory(dir, ec)) {
    throw InputError(path_ + ": output folder " + dir.string() + " does not exist");
  } else if (::access(dir.c_str(), W_OK) != 0) {
    throw InputError(path_ + ": output folder " + dir.string() + " is not writable");
  }
  std::random_device rd;
  const std::string tag = std::to_string(::getpid()) + "-" + std::to_string(rd() % 1000000);
  temp_ = (dir / ("." + target.stem().string() + ".tmp-" + tag + target.extension().string()))
              .string();
  cleanup_slot_ = RecordForCleanup(temp_, kTempFile);
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
  ForgetForCleanup(cleanup_slot_);
}

void AtomicFile::CheckWritten() const {
  std::error_code ec;
  if (!fs::exists(temp_, ec) || fs::file_size(temp_, ec) == 0) {
    throw InputError(path_ + ": writing failed (nothing was written)");
  }
}

void AtomicFile::Commit() {
  CheckWritten();
  std::error_code ec;
  const fs::path dir = fs::path(path_).parent_path();
  if (!dir.empty() && !fs::is_directory(dir, ec)) {  // an OutputFolder's, made now
    fs::create_directories(dir, ec);
    if (ec) throw InputError(dir.string() + ": cannot create output folder: " + ec.message());
  }
  fs::rename(temp_, path_, ec);
  if (ec) throw InputError(path_ + ": cannot move output into place: " + ec.message());
  committed_ = true;
  ForgetForCleanup(cleanup_slot_);
  cleanup_slot_ = -1;
}

AtomicFile& AtomicFileSet::Add(std::string path, const std::string& stage_dir) {
  files_.push_back(std::make_unique<AtomicFile>(std::move(path), stage_dir));
  return *files_.back();
}

void AtomicFileSet::Commit() {
  for (const auto& f : files_) f->CheckWritten();
  for (const auto& f : files_) f->Commit();
}

void CheckDistinctOutputs(const std::vector<std::pair<std::string, std::string>>& outputs,
                          const std::vector<std::pair<std::string, std::string>>& inputs) {
  for (const auto& [flag, path] : outputs) {
    if (path.empty()) continue;
    for (const auto& [input_flag, input] : inputs) {
      std::error_code ec;  // a missing file is no input to lose
      if (!input.empty() && fs::equivalent(path, input, ec) && !ec)
        throw InputError(flag + " " + path + " is the input " + input_flag +
                         ": the run would overwrite it");
    }
  }
  std::vector<std::pair<std::string, fs::path>> seen;  // {flag, canonical path}
  for (const auto& [flag, path] : outputs) {
    if (path.empty()) continue;
    // Absolute first: weakly_canonical leaves a relative path relative when its first part does
    // not exist yet, so "d.json" would not meet "./d.json" before the file is there.
    std::error_code ec;
    const fs::path absolute = fs::absolute(fs::path(path), ec).lexically_normal();
    fs::path canonical = fs::weakly_canonical(absolute, ec);
    if (ec) canonical = absolute;
    for (const auto& [other_flag, other] : seen)
      if (other == canonical)
        throw InputError(other_flag + " and " + flag + " name the same file " + path);
    seen.emplace_back(flag, canonical);
  }
}

void AtomicFile::Write(std::string_view text) const {
  std::ofstream f(temp_, std::ios::binary);
  f.write(text.data(), static_cast<std::streamsize>(text.size()));
  f.close();  // some write errors only show when the file is closed
  if (!f) throw InputError(path_ + ": write failed");
}

void CheckOutputExtension(const std::string& flag, const std::string& path,
                          const std::vector<std::string>& extensions) {
  std::string extension = fs::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (std::find(extensions.begin(), extensions.end(), extension) != extensions.end()) return;
  std::string names;
  for (size_t i = 0; i < extensions.size(); ++i)
    names += (i == 0 ? "" : i + 1 == extensions.size() ? " or " : ", ") + extensions[i];
  throw InputError(flag + ": " + path + ": name it " + names);
}

void WriteFileAtomically(const std::string& path, std::string_view text) {
  AtomicFile out(path);
  out.Write(text);
  out.Commit();
}

void EnsureDirectory(const std::string& dir) {
  std::error_code ec;
  if (dir.empty()) throw InputError("output folder is empty");
  if (fs::is_directory(dir, ec)) {
    if (::access(dir.c_str(), W_OK) != 0) throw InputError(dir + ": output folder is not writable");
    return;
  }
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create output folder: " + ec.message());
}

OutputFolder::OutputFolder(const std::string& dir) {
  if (dir.empty()) throw InputError("output folder is empty");
  std::error_code ec;
  // Resolved as the kernel will make it (links and "..", then the missing rest), so that the
  // staging folder sits on the final folder's filesystem.
  fs::path stage = fs::weakly_canonical(fs::absolute(dir, ec), ec);
  if (ec) stage = fs::absolute(dir, ec);
  const fs::path target = stage;
  while (!fs::exists(stage, ec) && stage.has_parent_path() && stage != stage.parent_path()) {
    if (fs::is_symlink(fs::symlink_status(stage, ec)))
      throw InputError(dir + ": cannot create output folder: " + stage.string() +
                       " is a broken link");
    stage = stage.parent_path();
  }
  if (!fs::is_directory(stage, ec)) {
    throw InputError(dir + ": cannot create output folder: " + stage.string() +
                     (fs::exists(stage, ec) ? " is not a folder" : " does not exist"));
  }
  std::string pattern = (stage / ".textile-stage-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    throw InputError(dir + (stage == target ? ": output folder is not writable"
                                            : ": cannot create output folder: " + stage.string() +
                                                  " is not writable"));
  }
  stage_dir_ = pattern;
  cleanup_slot_ = RecordForCleanup(stage_dir_, kStageFolder);
}

OutputFolder::~OutputFolder() {
  std::error_code ec;
  fs::remove_all(stage_dir_, ec);  // empty after a commit; a failed run's temporary files
  ForgetForCleanup(cleanup_slot_);
}

}  // namespace textile
