// OpenCV's image codecs are opened at run time (textile/photo/image_codecs.h): what the loader says
// when the library is missing or is not the codecs, and that the installed one round-trips images
// through the functions it resolved.

#include "textile/photo/image_codecs.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

std::string OpenError(const std::vector<std::string>& files) {
  try {
    image_codecs::Open(files);
  } catch (const ComputeError& e) {
    return e.what();
  }
  return "";
}

cv::Mat Gradient() {
  cv::Mat image(48, 64, CV_8U);
  for (int r = 0; r < image.rows; ++r)
    for (int c = 0; c < image.cols; ++c) image.at<uchar>(r, c) = static_cast<uchar>(3 * c + r);
  return image;
}

TEST(ImageCodecs, APngRoundTripsBitForBit) {
  const cv::Mat image = Gradient();
  std::vector<uchar> bytes;
  ASSERT_TRUE(image_codecs::Encode(".png", image, &bytes));
  ASSERT_GT(bytes.size(), 8u);
  EXPECT_EQ(std::string(bytes.begin() + 1, bytes.begin() + 4), "PNG");
  const cv::Mat back = image_codecs::Decode(cv::Mat(bytes), cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(back.size(), image.size());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0);
}

TEST(ImageCodecs, WriteAndReadUseTheFileNamesExtension) {
  const std::string path = ::testing::TempDir() + "image_codecs_test.jpg";
  const cv::Mat image = Gradient();
  ASSERT_TRUE(image_codecs::Write(path, image, {cv::IMWRITE_JPEG_QUALITY, 95}));
  const cv::Mat back = image_codecs::Read(path, cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(back.size(), image.size());
  EXPECT_LT(cv::norm(back, image, cv::NORM_L1) / image.total(), 2.0);
  std::ifstream file(path, std::ios::binary);
  unsigned char magic[2] = {0, 0};
  file.read(reinterpret_cast<char*>(magic), 2);
  EXPECT_EQ(magic[0], 0xFF);  // a JPEG's start-of-image marker, as the name asks
  EXPECT_EQ(magic[1], 0xD8);
  EXPECT_TRUE(image_codecs::Read(path + ".missing", cv::IMREAD_GRAYSCALE).empty());
}

TEST(ImageCodecs, AMissingLibraryIsAClearError) {
  const std::string why = OpenError({"/nonexistent/libopencv_imgcodecs.so.9", "libnot-there.so"});
  EXPECT_NE(why.find("cannot load OpenCV's image codecs (tried "
                     "/nonexistent/libopencv_imgcodecs.so.9, libnot-there.so)"),
            std::string::npos)
      << why;
  EXPECT_NE(why.find("TEXTILE_IMGCODECS"), std::string::npos) << why;
  EXPECT_NE(OpenError({}).find("no file to try"), std::string::npos);
}

TEST(ImageCodecs, ALibraryThatIsNotTheCodecsIsRefusedByName) {
  const std::string why = OpenError({"libm.so.6"});
  EXPECT_NE(why.find("libm.so.6 is not OpenCV's image codecs library (no cv::imread)"),
            std::string::npos)
      << why;
}

TEST(ImageCodecs, CodecsOfAnotherOpenCvAreRefused) {
  const std::string why = OpenError({TEXTILE_FAKE_IMGCODECS});
  EXPECT_NE(why.find(std::string(TEXTILE_FAKE_IMGCODECS) +
                     " belongs to another OpenCV than the one textile was built with (" +
                     CV_VERSION + ")"),
            std::string::npos)
      << why;
}

TEST(ImageCodecs, TheLoadedFunctionsAreTheLinkedOnes) {
  // This test links the codecs (for its own images elsewhere): dlopen hands back that library.
  const image_codecs::Api& api = image_codecs::Load();
  EXPECT_EQ(api.imread, static_cast<decltype(api.imread)>(&cv::imread));
  EXPECT_EQ(api.imwrite, static_cast<decltype(api.imwrite)>(&cv::imwrite));
  EXPECT_EQ(api.imdecode, static_cast<decltype(api.imdecode)>(&cv::imdecode));
  EXPECT_EQ(api.imencode, static_cast<decltype(api.imencode)>(&cv::imencode));
}

TEST(ImageCodecs, EachDefaultFileLoadsOnItsOwn) {
  // The build-time path and the soname: the second is what remains when OpenCV is updated in
  // place or textile runs on another machine, so it must be a name the dynamic linker finds.
  const std::vector<std::string> files = image_codecs::DefaultFiles();
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(files[0].front(), '/') << files[0];
  EXPECT_EQ(files[1].find('/'), std::string::npos) << files[1];
  for (const std::string& file : files) {
    SCOPED_TRACE(file);
    EXPECT_EQ(OpenError({file}), "");
  }
}

}  // namespace
}  // namespace textile
