// Writes the seed corpus of fuzz_photo (small synthetic cantilever photos in the four formats
// extract reads, plus damaged variants) and the photos of tests/bad_inputs/files/.
//   make_photo_seeds OUT_DIR
// Run by hand when the seeds need renewing (the outputs are committed); built with the fuzz
// targets. The photos come from the extractor tests' renderer (tests/fit/synthetic_photo.h).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "../fit/synthetic_photo.h"

namespace {

std::vector<uchar> Encode(const cv::Mat& gray, const std::string& ext) {
  std::vector<uchar> bytes;
  if (!cv::imencode(ext, gray, bytes)) {
    std::fprintf(stderr, "cannot encode %s\n", ext.c_str());
    std::exit(1);
  }
  return bytes;
}

void Write(const std::filesystem::path& path, const std::vector<uchar>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_photo_seeds OUT_DIR\n");
    return 2;
  }
  const std::filesystem::path out = argv[1];
  std::filesystem::create_directories(out);
  using textile::testing::PhotoScene;
  // A 200×130 px clamp-at-the-border photo: a dark strip 5 px wide bending down to the right.
  PhotoScene clamp;
  clamp.width = 200;
  clamp.height = 130;
  clamp.root_y = 35;
  clamp.straight = 40;
  clamp.radius = 120;
  clamp.bend_deg = 50;
  clamp.thickness = 5;
  clamp.noise_sigma = 1.0;
  const cv::Mat a = textile::testing::Render(clamp).gray;
  // The same strip on a platform, light on dark, overhang to the left.
  PhotoScene platform = clamp;
  platform.holder = PhotoScene::Holder::kPlatform;
  platform.root_x = 60;
  platform.root_y = 40;
  platform.strip = 0.85;
  platform.background = 0.15;
  platform.mirror = true;
  const cv::Mat b = textile::testing::Render(platform).gray;

  Write(out / "clamp.png", Encode(a, ".png"));
  Write(out / "clamp.jpg", Encode(a, ".jpg"));
  Write(out / "clamp.bmp", Encode(a, ".bmp"));
  Write(out / "clamp.tif", Encode(a, ".tif"));
  Write(out / "platform.png", Encode(b, ".png"));
  Write(out / "platform.jpg", Encode(b, ".jpg"));
  // Damaged: cut in half (image data missing), and a PNG whose header claims 40000×40000 px.
  std::vector<uchar> png = Encode(a, ".png");
  Write(out / "truncated.png", std::vector<uchar>(png.begin(), png.begin() + png.size() / 2));
  std::vector<uchar> jpg = Encode(a, ".jpg");
  Write(out / "truncated.jpg", std::vector<uchar>(jpg.begin(), jpg.begin() + jpg.size() / 2));
  std::vector<uchar> huge = png;  // IHDR width and height: bytes 16..23, big-endian
  for (int k : {16, 20}) {
    huge[k] = 0x00, huge[k + 1] = 0x00, huge[k + 2] = 0x9C, huge[k + 3] = 0x40;  // 40000
  }
  Write(out / "huge-header.png", huge);
  // Tiny: 20×20 px, below the smallest photo extract accepts.
  Write(out / "tiny.png", Encode(cv::Mat(20, 20, CV_8UC1, cv::Scalar(200)), ".png"));
  // Blank: a uniform grey photo (nothing to find).
  Write(out / "blank.png", Encode(cv::Mat(130, 200, CV_8UC1, cv::Scalar(128)), ".png"));
  // Photos that show no usable cantilever (exit 3): two strips side by side (from the left
  // and the right border) and one above the other, a tip cut off by the bottom border, and a
  // strip hanging off both ends of a platform standing in the photo, lying on it in view
  // (light platform) or unseen (dark platform).
  PhotoScene left = clamp;
  left.straight = 20;
  left.radius = 80;
  left.bend_deg = 40;
  PhotoScene right = left;
  right.mirror = true;
  right.root_y = 50;
  right.seed = 2;
  Write(out / "two-strips-side.png",
        Encode(textile::testing::RenderTwoStrips(left, right), ".png"));
  PhotoScene upper = clamp;
  upper.root_y = 30;
  upper.straight = 30;
  upper.radius = 100;
  upper.bend_deg = 40;
  PhotoScene lower = upper;
  lower.root_y = 75;
  lower.radius = 150;
  lower.bend_deg = 30;
  lower.seed = 3;
  Write(out / "two-strips-stacked.png",
        Encode(textile::testing::RenderTwoStrips(upper, lower), ".png"));
  PhotoScene cut = clamp;
  cut.root_y = 60;
  cut.radius = 110;
  cut.bend_deg = 80;  // ends 30 px below the photo
  Write(out / "tip-cut.png", Encode(textile::testing::Render(cut).gray, ".png"));
  textile::testing::DrapedScene draped;
  draped.platform = 240;
  Write(out / "draped.png", Encode(textile::testing::RenderDraped(draped), ".png"));
  draped.platform = 100;
  Write(out / "draped-dark.png", Encode(textile::testing::RenderDraped(draped), ".png"));
  return 0;
}
