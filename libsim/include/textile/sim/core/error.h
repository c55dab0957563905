#ifndef TEXTILE_SIM_CORE_ERROR_H_
#define TEXTILE_SIM_CORE_ERROR_H_

#include <fstream>
#include <stdexcept>
#include <string>

namespace textile {

// Bad user input (a file, a flag, a value out of range). The message is one line that names
// the source and the problem; the CLI prints it as "error: <message>" and exits with 2.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

// A computation that could not produce a trustworthy result (no convergence, nothing detected).
// The CLI prints it as "error: <message>" and exits with 3.
class ComputeError : public std::runtime_error {
 public:
  explicit ComputeError(const std::string& message) : std::runtime_error(message) {}
};

// Opens an input file for binary reading. Throws InputError "<path>: is a folder, not a <what>"
// or "<path>: cannot open <what>" (what: "material file", "profile", ...): a folder opens as an
// empty stream on Linux and would otherwise be reported as an empty file.
std::ifstream OpenInputFile(const std::string& path, const std::string& what);

// The whole of an input file (OpenInputFile's errors), refused with InputError "<path>: more
// than N MB, too large for a <what>" once it passes max_bytes: a material, seam or rig file is
// kilobytes, and a stray gigabyte file (or /dev/zero) would otherwise be read into memory until
// the machine runs out of it.
std::string ReadInputFile(const std::string& path, const std::string& what, std::size_t max_bytes);

}  // namespace textile

#endif  // TEXTILE_SIM_CORE_ERROR_H_
