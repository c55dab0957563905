#include "textile/photo/image_codecs.h"

#include <string>
#include <vector>

#include "textile/sim/core/error.h"
#include "textile/sim/core/shared_library.h"

#ifndef TEXTILE_IMGCODECS_LIBRARY
#define TEXTILE_IMGCODECS_LIBRARY ""
#endif
#ifndef TEXTILE_IMGCODECS_SONAME
#define TEXTILE_IMGCODECS_SONAME "libopencv_imgcodecs.so"
#endif

namespace textile::image_codecs {
namespace {

// Each cast compiles only if the OpenCV headers declare the function with exactly the pointer's
// type (an unevaluated operand: nothing is linked). The symbol names below are written by hand
// as the Itanium C++ ABI mangles those declarations (std::string being
// std::__cxx11::basic_string); ImageCodecs.TheLoadedFunctionsAreTheLinkedOnes checks them
// against the linked functions.
using CheckImread = decltype(static_cast<decltype(Api::imread)>(&cv::imread));
using CheckImwrite = decltype(static_cast<decltype(Api::imwrite)>(&cv::imwrite));
using CheckImdecode = decltype(static_cast<decltype(Api::imdecode)>(&cv::imdecode));
using CheckImencode = decltype(static_cast<decltype(Api::imencode)>(&cv::imencode));
using BuildInformation = const std::string& (*)();
using CheckBuildInformation = decltype(static_cast<BuildInformation>(&cv::getBuildInformation));

constexpr const char* kImread =
    "_ZN2cv6imreadERKNSt7__cxx1112basic_stringIcSt11char_traitsIcESaIcEEEi";
constexpr const char* kImwrite =
    "_ZN2cv7imwriteERKNSt7__cxx1112basic_stringIcSt11char_traitsIcESaIcEEERKNS_11_InputArrayERKSt6"
    "vectorIiSaIiEE";
constexpr const char* kImdecode = "_ZN2cv8imdecodeERKNS_11_InputArrayEi";
constexpr const char* kImencode =
    "_ZN2cv8imencodeERKNSt7__cxx1112basic_stringIcSt11char_traitsIcESaIcEEERKNS_11_InputArrayERSt6"
    "vectorIhSaIhEERKSB_IiSaIiEE";
constexpr const char* kGetBuildInformation = "_ZN2cv19getBuildInformationB5cxx11Ev";

template <class F>
void Resolve(void* handle, const std::string& file, const char* name, const char* what, F* f) {
  *f = reinterpret_cast<F>(FindSymbol(handle, name));
  if (!*f) {
    throw ComputeError(file + " is not OpenCV's image codecs library (no " + what + ")");
  }
}

}  // namespace

Api Open(const std::vector<std::string>& files) {
  std::string file;
  void* handle =
      OpenFirstLibrary(files, "OpenCV's image codecs",
                       "install OpenCV's imgcodecs library (Debian: libopencv-imgcodecs406) or set "
                       "TEXTILE_IMGCODECS to its library file",
                       &file);
  Api api;
  try {
    Resolve(handle, file, kImread, "cv::imread", &api.imread);
    Resolve(handle, file, kImwrite, "cv::imwrite", &api.imwrite);
    Resolve(handle, file, kImdecode, "cv::imdecode", &api.imdecode);
    Resolve(handle, file, kImencode, "cv::imencode", &api.imencode);
    // Codecs of another OpenCV would bring their own libopencv_core next to the linked one, and
    // the cv::Mat passed between them would meet two allocators and two sets of state.
    BuildInformation its_core = nullptr;
    Resolve(handle, file, kGetBuildInformation, "cv::getBuildInformation", &its_core);
    if (its_core != static_cast<BuildInformation>(&cv::getBuildInformation)) {
      throw ComputeError(file + " belongs to another OpenCV than the one textile was built with " +
                         "(" + CV_VERSION + ")");
    }
  } catch (...) {
    CloseLibrary(handle);
    throw;
  }
  return api;  // the handle stays open for the life of the process
}

std::vector<std::string> DefaultFiles() {
  return {TEXTILE_IMGCODECS_LIBRARY, TEXTILE_IMGCODECS_SONAME};
}

const Api& Load() { return LoadOnce<Api>("TEXTILE_IMGCODECS", DefaultFiles(), &Open); }

cv::Mat Read(const std::string& path, int flags) { return Load().imread(path, flags); }

bool Write(const std::string& path, const cv::Mat& image, const std::vector<int>& params) {
  return Load().imwrite(path, image, params);
}

cv::Mat Decode(const cv::Mat& bytes, int flags) { return Load().imdecode(bytes, flags); }

bool Encode(const std::string& extension, const cv::Mat& image, std::vector<uchar>* bytes,
            const std::vector<int>& params) {
  return Load().imencode(extension, image, *bytes, params);
}

}  // namespace textile::image_codecs
