// A stand-in for another OpenCV's image codecs (ImageCodecs.CodecsOfAnotherOpenCvAreRefused): it
// exports the four functions textile calls and a cv::getBuildInformation of its own, as a
// libopencv_imgcodecs built against another libopencv_core would.

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

namespace cv {

Mat imread(const String&, int) { return Mat(); }
bool imwrite(const String&, InputArray, const std::vector<int>&) { return false; }
Mat imdecode(InputArray, int) { return Mat(); }
bool imencode(const String&, InputArray, std::vector<uchar>&, const std::vector<int>&) {
  return false;
}
const String& getBuildInformation() {
  static const String kInformation = "another OpenCV";
  return kInformation;
}

}  // namespace cv
