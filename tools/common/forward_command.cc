#include "common/forward_command.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <system_error>
#include <vector>

namespace textile::cli {
namespace {

namespace fs = std::filesystem;

// command -> executable's file name
std::map<std::string, std::string>& Forwarded() {
  static std::map<std::string, std::string> forwarded;
  return forwarded;
}

// The folder of the running executable (not argv[0], which a shell's PATH lookup leaves bare).
fs::path OwnFolder() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : self.parent_path();
}

}  // namespace

bool ForwardCommand(const std::string& command, const std::string& executable) {
  Forwarded()[command] = executable;
  return true;
}

bool RunForwardedCommand(int argc, char** argv) {
  // `textile --help bench` is CLI11's way to ask for the subcommand's help, as `bench --help`.
  const bool help_first =
      argc > 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0);
  const int at = help_first ? 2 : 1;
  if (argc <= at) return false;
  const auto it = Forwarded().find(argv[at]);
  if (it == Forwarded().end()) return false;
  const std::string path = (OwnFolder() / it->second).string();
  std::vector<char*> args = {const_cast<char*>(path.c_str())};
  if (help_first) args.push_back(argv[1]);
  args.insert(args.end(), argv + at + 1, argv + argc);
  args.push_back(nullptr);
  ::execv(path.c_str(), args.data());
  // Only reached when the executable could not be started.
  std::fprintf(stderr, "error: textile %s needs %s beside textile: %s: %s\n", it->first.c_str(),
               it->second.c_str(), path.c_str(), std::strerror(errno));
  return true;
}

}  // namespace textile::cli
