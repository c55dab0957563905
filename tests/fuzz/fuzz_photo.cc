// libFuzzer target: the image path of `textile extract` on arbitrary bytes. The bytes go to a
// file on tmpfs (ReadPhotoGray takes a path: the header checks, the completeness checks and the
// decode are exactly what the CLI runs), and whatever decodes small enough goes through
// ExtractProfile and, when a strip is found, DrawExtractionOverlay. Anything but a result or an
// InputError is a bug; a failed extraction must say why and a successful one must hand out a
// profile that `textile fit` can read back.
//
// Size limits, so that a run is fast: OpenCV refuses to decode more than kMaxDecodePixels
// (OPENCV_IO_MAX_IMAGE_PIXELS, read by OpenCV when it is loaded, hence the re-exec below; the
// refusal is a cv::Exception that ReadPhotoGray must turn into an InputError), extraction runs
// on photos of at most kMaxExtractPixels, and tests/fuzz/run.sh caps inputs at 64 kB.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "textile/photo/extract.h"
#include "textile/fit/profile.h"
#include "textile/photo/rig.h"
#include "textile/sim/core/error.h"

namespace {

constexpr const char* kMaxDecodePixels = "1000000";
constexpr double kMaxExtractPixels = 400e3;

std::string& PhotoPath() {
  static std::string path;
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  (void)argc;
  if (!std::getenv("OPENCV_IO_MAX_IMAGE_PIXELS")) {
    setenv("OPENCV_IO_MAX_IMAGE_PIXELS", kMaxDecodePixels, 1);
    execv("/proc/self/exe", *argv);  // only returns on failure: then run without the limit
  }
  const std::filesystem::path shm = "/dev/shm";
  const std::filesystem::path dir = std::filesystem::is_directory(shm)
                                        ? shm
                                        : std::filesystem::temp_directory_path();
  PhotoPath() = (dir / ("textile-fuzz-photo-" + std::to_string(getpid()) + ".img")).string();
  std::atexit([] { std::filesystem::remove(PhotoPath()); });
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  {
    std::ofstream out(PhotoPath(), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) __builtin_trap();  // the scratch file must be writable, else nothing is tested
  }
  cv::Mat gray;
  try {
    gray = textile::ReadPhotoGray(PhotoPath());
  } catch (const textile::InputError& e) {
    // The message names the photo (docs/spec/cli.md: errors name the file).
    if (std::string(e.what()).rfind(PhotoPath(), 0) != 0) __builtin_trap();
    return 0;
  }
  // ReadPhotoGray's promises: 8-bit grey, within the size limits.
  if (gray.type() != CV_8UC1 || gray.cols < textile::kMinPhotoSidePx ||
      gray.rows < textile::kMinPhotoSidePx) {
    __builtin_trap();
  }
  if (static_cast<double>(gray.total()) > kMaxExtractPixels) return 0;
  try {
    const textile::Rig rig = textile::Rig::FromScale(0.1);
    const textile::ExtractionSummary r =
        textile::ExtractProfile(gray, rig, textile::ExtractOptions{}, "fuzz.png");
    if (!r.success) {
      if (r.message.empty()) __builtin_trap();
    } else {
      // What extract writes, fit must be able to read.
      try {
        textile::ParseProfileCsv(textile::ProfileToCsv(r.profile), "fuzz profile");
      } catch (const textile::InputError&) {
        __builtin_trap();
      }
    }
    const cv::Mat overlay = textile::DrawExtractionOverlay(gray, r, 400);
    if (overlay.empty()) __builtin_trap();
  } catch (const textile::InputError&) {
  }
  return 0;
}
