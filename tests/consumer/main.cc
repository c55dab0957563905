// Uses the installed headers and libraries: prints the paper's Fig. 8 law at 1/cm, and round-trips
// a small image through the image codecs libfit opens at run time (textile/photo/image_codecs.h),
// and asks textile::plot for an axis's ticks (textile/sim/plot/chart.h).
#include <cstdio>
#include <vector>

#include "textile/photo/image_codecs.h"
#include "textile/sim/law/bending_law.h"
#include "textile/sim/plot/chart.h"
#include "textile/sim/core/units.h"

int main() {
  const auto law = textile::BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  const double m = law.Moment(textile::units::KesCurvatureToSi(1.0));
  std::printf("M(1/cm) = %.6f gf·cm/cm\n", textile::units::SiMomentToKes(m));
  const cv::Mat image(8, 8, CV_8U, cv::Scalar(77));
  std::vector<uchar> png;
  if (!textile::image_codecs::Encode(".png", image, &png)) return 1;
  const cv::Mat back = textile::image_codecs::Decode(cv::Mat(png), cv::IMREAD_GRAYSCALE);
  if (back.size() != image.size() || cv::norm(back, image, cv::NORM_INF) != 0.0) return 1;
  if (textile::chart::NiceTicks(0.0, 1.0, 6).values.empty()) return 1;
  return m > 0.0 ? 0 : 1;
}
