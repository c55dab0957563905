#include "textile/sim/core/error.h"

#include <array>
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

std::string ReadInputFile(const std::string& path, const std::string& what, std::size_t max_bytes) {
  std::ifstream f = OpenInputFile(path, what);
  std::string text;
  std::array<char, 1 << 16> chunk;
  while (f) {
    f.read(chunk.data(), chunk.size());
    text.append(chunk.data(), static_cast<std::size_t>(f.gcount()));
    if (text.size() > max_bytes) {
      throw InputError(path + ": more than " + std::to_string(max_bytes >> 20) +
                       " MB, too large for a " + what);
    }
  }
  if (f.bad()) throw InputError(path + ": cannot read " + what);
  return text;
}

}  // namespace textile
