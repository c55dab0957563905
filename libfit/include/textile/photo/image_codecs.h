#ifndef TEXTILE_PHOTO_IMAGE_CODECS_H_
#define TEXTILE_PHOTO_IMAGE_CODECS_H_

// OpenCV's image codecs (libopencv_imgcodecs: imread, imwrite, imdecode, imencode), opened with
// dlopen on first use instead of linked, as Gmsh is (textile/sim/core/shared_library.h): the library
// brings about 100 others (GDAL, Poppler, HDF5, ...) whose relocation cost every `textile`
// command 0.07-0.11 s at start-up and made loading Gmsh 0.1 s slower, photos or not
// (docs/methods/meshing-and-membrane.md, "Start-up"). Only the commands that read or write images load
// it. Call these instead of cv::imread and friends; the flags are OpenCV's (opencv2/imgcodecs.hpp,
// a header only).
//
//   cv::Mat gray = textile::image_codecs::Decode(bytes, cv::IMREAD_GRAYSCALE);
//   if (!textile::image_codecs::Write("overlay.png", image)) ...

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

namespace textile::image_codecs {

// The functions, with opencv2/imgcodecs.hpp's signatures (checked at compile time).
struct Api {
  cv::Mat (*imread)(const std::string&, int) = nullptr;
  bool (*imwrite)(const std::string&, const cv::_InputArray&, const std::vector<int>&) = nullptr;
  cv::Mat (*imdecode)(const cv::_InputArray&, int) = nullptr;
  bool (*imencode)(const std::string&, const cv::_InputArray&, std::vector<uchar>&,
                   const std::vector<int>&) = nullptr;
};

// Opens the first of `files` that dlopen can load and resolves every function. Throws
// ComputeError naming what was tried and dlerror() when none loads, or the file when a function
// is missing or the file belongs to another OpenCV (its libopencv_core is not the linked one).
Api Open(const std::vector<std::string>& files);

// The library, loaded once (thread-safe): the file named by the environment variable
// TEXTILE_IMGCODECS when set, else the file found at build time, else its soname. Throws as
// Open; after a failure the next call tries again.
const Api& Load();

// The files Load tries without TEXTILE_IMGCODECS: the one found at build time, then its soname
// (found by the dynamic linker wherever OpenCV is installed).
std::vector<std::string> DefaultFiles();

// cv::imread, cv::imwrite, cv::imdecode and cv::imencode through Load().
cv::Mat Read(const std::string& path, int flags);
bool Write(const std::string& path, const cv::Mat& image, const std::vector<int>& params = {});
cv::Mat Decode(const cv::Mat& bytes, int flags);
bool Encode(const std::string& extension, const cv::Mat& image, std::vector<uchar>* bytes,
            const std::vector<int>& params = {});

}  // namespace textile::image_codecs

#endif  // TEXTILE_PHOTO_IMAGE_CODECS_H_
