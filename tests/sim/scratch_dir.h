#ifndef TEXTILE_TESTS_SIM_SCRATCH_DIR_H_
#define TEXTILE_TESTS_SIM_SCRATCH_DIR_H_

// A test helper: an empty folder of the build tree for a test's files.

#include <filesystem>
#include <string>

namespace textile {

// <build>/test_scratch/<name>, emptied and created.
inline std::filesystem::path ScratchDir(const std::string& name) {
  const std::filesystem::path d = std::filesystem::path(TEXTILE_BINARY_DIR) / "test_scratch" / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace textile

#endif  // TEXTILE_TESTS_SIM_SCRATCH_DIR_H_
