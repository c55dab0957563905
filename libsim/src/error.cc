#include "textile/sim/error.h"

#include <filesystem>
#include <system_error>

namespace textile {

std::ifstream OpenInputFile(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path + ": is a folder, not a " + what);
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(path + ": cannot open " + what);
  return f;
}

}  // namespace textile
