#ifndef TEXTILE_TESTS_FIT_SYNTHETIC_PHOTO_H_
#define TEXTILE_TESTS_FIT_SYNTHETIC_PHOTO_H_

// Synthetic cantilever photos with a known truth, for the extractor's tests: a band of known
// width along a known curve (a straight run, then a circular arc bending down), held by a
// platform block, a clamp block or the image border, over a background with optional uneven
// light and a shadow; anti-aliased by supersampling, then blurred, then noisy.
//
//   textile::testing::PhotoScene scene;             // dark strip, clamp at the left border
//   textile::testing::SyntheticPhoto photo = textile::testing::Render(scene);
//   double d = photo.DistanceToMidline({x, y});     // [px], to the truth
//
// Coordinates are OpenCV's (x right, y down, pixel centres at integers); the band's truth is in
// those coordinates after mirroring and rotation, so tests compare like with like.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

namespace textile::testing {

struct PhotoScene {
  enum class Holder { kBorder, kClampBlock, kPlatform };
  int width = 1400, height = 900;  // [px]
  Holder holder = Holder::kBorder;
  double root_x = 0.0;      // where the free part starts: platform corner / clamp face [px]
  double root_y = 250.0;    // the band's mid-line there (platform: its top face) [px]
  double straight = 200.0;  // horizontal run before the bend [px]
  double radius = 900.0;    // bend radius of the mid-line [px]
  double bend_deg = 45.0;   // angle turned by the arc [deg]
  double thickness = 10.0;  // band width [px]
  double strip = 0.20, background = 0.75, block = 0.40;  // reflectances (0..1)
  bool uneven_light = false;  // light falling off across the photo, plus a soft shadow
  double blur_sigma = 1.0;    // optics [px]
  double noise_sigma = 2.0;   // sensor noise [grey levels]
  bool mirror = false;        // overhang to the left
  double rotate_deg = 0.0;    // camera roll: the scene turned counter-clockwise as seen [deg]
  int fibres = 0;             // loose fibres at the tip and along the edges
  unsigned seed = 1;
};

struct SyntheticPhoto {
  cv::Mat gray;  // CV_8UC1
  PhotoScene scene;
  Eigen::Vector2d origin{0, 0};  // the truth origin: platform corner or where the mid-line
                                 // leaves the clamp/border [px]
  Eigen::Vector2d tip{0, 0};     // end of the mid-line [px]
  double free_length = 0.0;      // mid-line arc length from x = root_x to the tip [px]

  // Scene frame (before mirror/rotation) <-> image.
  Eigen::Vector2d ToImage(const Eigen::Vector2d& p) const {
    const double c = scene.width / 2.0, r = scene.height / 2.0;
    Eigen::Vector2d q = p;
    const double a = scene.rotate_deg * M_PI / 180.0;
    // Counter-clockwise as seen: with y down this is (x, y) -> (x cos a + y sin a, -x sin a + y cos
    // a).
    const Eigen::Vector2d d(q.x() - c, q.y() - r);
    q = Eigen::Vector2d(c + d.x() * std::cos(a) + d.y() * std::sin(a),
                        r - d.x() * std::sin(a) + d.y() * std::cos(a));
    if (scene.mirror) q.x() = scene.width - 1 - q.x();
    return q;
  }
  Eigen::Vector2d ToScene(const Eigen::Vector2d& p) const {
    Eigen::Vector2d q = p;
    if (scene.mirror) q.x() = scene.width - 1 - q.x();
    const double c = scene.width / 2.0, r = scene.height / 2.0;
    const double a = scene.rotate_deg * M_PI / 180.0;
    const Eigen::Vector2d d(q.x() - c, q.y() - r);
    return Eigen::Vector2d(c + d.x() * std::cos(a) - d.y() * std::sin(a),
                           r + d.x() * std::sin(a) + d.y() * std::cos(a));
  }

  // Mid-line in the scene frame: arc-length parameter u from the root (u < 0 lies on the
  // platform / in the clamp), position and the unit normal pointing to the top face.
  double MidlineY0() const {
    return scene.holder == PhotoScene::Holder::kPlatform ? scene.root_y - scene.thickness / 2
                                                         : scene.root_y;
  }
  Eigen::Vector2d ArcCentre() const {
    return {scene.root_x + scene.straight, MidlineY0() + scene.radius};
  }
  double EndU() const { return scene.straight + scene.radius * scene.bend_deg * M_PI / 180.0; }

  // Signed offset of a scene point from the mid-line (positive towards the top face) and its
  // arc parameter u, for points whose nearest mid-line point is interior; returns false when
  // the nearest point is beyond the tip.
  bool Offset(const Eigen::Vector2d& p, double* offset, double* u) const {
    const double y0 = MidlineY0();
    if (p.x() <= scene.root_x + scene.straight) {
      *u = p.x() - scene.root_x;
      *offset = y0 - p.y();
      return true;
    }
    const Eigen::Vector2d c = ArcCentre();
    const Eigen::Vector2d d = p - c;
    // Angle from "straight up" turning clockwise as seen (towards +x, then down).
    const double phi = std::atan2(d.x(), -d.y());
    if (phi < 0.0) {
      *u = scene.straight;
      *offset = y0 - p.y();
      return true;
    }
    *u = scene.straight + scene.radius * phi;
    *offset = d.norm() - scene.radius;
    return *u <= EndU();
  }

  // Distance from an image point to the truth line at `offset` from the mid-line (0: mid-line,
  // +w/2: upper boundary, -w/2: lower boundary) [px].
  double DistanceToLine(const Eigen::Vector2d& image_point, double offset = 0.0) const {
    double o, u;
    const Eigen::Vector2d p = ToScene(image_point);
    if (!Offset(p, &o, &u)) {
      const Eigen::Vector2d c = ArcCentre();
      const double phi = scene.bend_deg * M_PI / 180.0;
      const double r = scene.radius + offset;
      return (p - (c + r * Eigen::Vector2d(std::sin(phi), -std::cos(phi)))).norm();
    }
    return std::abs(o - offset);
  }
};

inline SyntheticPhoto Render(const PhotoScene& s) {
  SyntheticPhoto photo;
  photo.scene = s;
  const double half = s.thickness / 2.0;
  const double clamp_half = 60.0;
  // Reflectance of a scene point.
  const auto reflectance = [&](const Eigen::Vector2d& p) {
    double o, u;
    const bool interior = photo.Offset(p, &o, &u);
    const bool on_strip = interior && std::abs(o) <= half &&
                          (s.holder != PhotoScene::Holder::kClampBlock || u >= -1e9);
    if (s.holder == PhotoScene::Holder::kClampBlock && p.x() <= s.root_x &&
        std::abs(p.y() - s.root_y) <= clamp_half) {
      return s.block;
    }
    if (on_strip) return s.strip;
    if (s.holder == PhotoScene::Holder::kPlatform && p.x() <= s.root_x && p.y() >= s.root_y) {
      return s.block;
    }
    return s.background;
  };
  cv::Mat light(s.height, s.width, CV_64F);
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      double l = 1.0;
      if (s.uneven_light) {
        // Falls off by 45 % across the photo, plus a soft shadow under the strip's middle.
        l = 1.1 - 0.45 * x / s.width - 0.15 * y / s.height;
        const double dx = x - 0.55 * s.width, dy = y - 0.7 * s.height;
        l -= 0.3 * std::exp(-(dx * dx + dy * dy) / (2.0 * 140.0 * 140.0));
      }
      light.at<double>(y, x) = l;
    }
  }
  cv::Mat img(s.height, s.width, CV_64F);
  constexpr int kSub = 4;
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      // Far from any boundary one sample is enough; near one, 4x4 samples.
      const Eigen::Vector2d centre = photo.ToScene({double(x), double(y)});
      double o, u;
      photo.Offset(centre, &o, &u);
      const bool near_strip =
          std::abs(std::abs(o) - half) < 1.5 || std::abs(u - photo.EndU()) < 2.0 + half;
      const bool near_block = std::abs(centre.x() - s.root_x) < 1.5 ||
                              std::abs(centre.y() - s.root_y) < 1.5 ||
                              std::abs(std::abs(centre.y() - s.root_y) - clamp_half) < 1.5;
      double sum = 0.0;
      if (!near_strip && !near_block) {
        sum = reflectance(centre);
      } else {
        for (int j = 0; j < kSub; ++j) {
          for (int i = 0; i < kSub; ++i) {
            const Eigen::Vector2d q(x - 0.5 + (i + 0.5) / kSub, y - 0.5 + (j + 0.5) / kSub);
            sum += reflectance(photo.ToScene(q));
          }
        }
        sum /= kSub * kSub;
      }
      img.at<double>(y, x) = sum;
    }
  }
  // Loose fibres: thin, strip-coloured lines sticking out of the edges and the tip.
  std::mt19937 rng(s.seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (int k = 0; k < s.fibres; ++k) {
    const bool at_tip = k % 3 == 0;
    const double u = at_tip ? photo.EndU() - uni(rng) * s.thickness
                            : 0.2 * photo.EndU() + 0.7 * photo.EndU() * uni(rng);
    // Point on the mid-line at u and the local frame.
    Eigen::Vector2d p, t;
    if (u <= s.straight) {
      p = {s.root_x + u, photo.MidlineY0()};
      t = {1, 0};
    } else {
      const double phi = (u - s.straight) / s.radius;
      p = photo.ArcCentre() + s.radius * Eigen::Vector2d(std::sin(phi), -std::cos(phi));
      t = {std::cos(phi), std::sin(phi)};
    }
    const Eigen::Vector2d n(t.y(), -t.x());  // top side
    const double side = uni(rng) < 0.5 ? -1.0 : 1.0;
    const Eigen::Vector2d start =
        at_tip ? p + (uni(rng) - 0.5) * s.thickness * n : p + side * half * n;
    const double ang = (uni(rng) - 0.5) * 1.2;
    const Eigen::Vector2d dir = at_tip
                                    ? Eigen::Vector2d(t * std::cos(ang) + n * std::sin(ang))
                                    : Eigen::Vector2d(side * n * std::cos(ang) + t * std::sin(ang));
    const double len = (at_tip ? 1.0 : 0.6) * s.thickness * (1.0 + 2.0 * uni(rng));
    const Eigen::Vector2d a = photo.ToImage(start), b = photo.ToImage(start + len * dir);
    cv::line(img, cv::Point(int(std::lround(a.x() * 16)), int(std::lround(a.y() * 16))),
             cv::Point(int(std::lround(b.x() * 16)), int(std::lround(b.y() * 16))),
             cv::Scalar(s.strip), 1, cv::LINE_8, 4);
  }
  img = img.mul(light) * 255.0;
  if (s.blur_sigma > 0) cv::GaussianBlur(img, img, cv::Size(0, 0), s.blur_sigma);
  cv::Mat noise(img.size(), CV_64F);
  cv::RNG cv_rng(s.seed);
  cv_rng.fill(noise, cv::RNG::NORMAL, 0.0, s.noise_sigma);
  img += noise;
  img.convertTo(photo.gray, CV_8U);  // saturates to 0..255 (ToScene already mirrored/rotated)

  photo.origin = photo.ToImage({s.root_x, s.root_y});
  const double phi = s.bend_deg * M_PI / 180.0;
  photo.tip =
      photo.ToImage(photo.ArcCentre() + s.radius * Eigen::Vector2d(std::sin(phi), -std::cos(phi)));
  photo.free_length = photo.EndU();
  return photo;
}

// The strip leaving the photo's left edge (no holder in the frame): the plainest scene.
inline PhotoScene BorderScene() {
  PhotoScene s;
  s.root_x = -0.5;
  return s;
}

// A band bent round the platform's corner at a radius not much larger than its thickness (70 px
// at 120 px): its upper edge is measured on 6 of 168 cross-sections.
inline PhotoScene ThickBandRoundTheCornerScene() {
  PhotoScene s;
  s.holder = PhotoScene::Holder::kPlatform;
  s.root_x = 900.0;
  s.root_y = 300.0;
  s.mirror = true;
  s.thickness = 70.0;
  s.radius = 120.0;
  s.straight = 0.0;
  s.bend_deg = 80.0;
  return s;
}

// Two cantilevers in one photo (two strips side by side or one above the other): both scenes
// rendered and the darker of the two kept at each pixel, so both must show dark strips on the
// same background.
inline cv::Mat RenderTwoStrips(const PhotoScene& a, const PhotoScene& b) {
  return cv::min(Render(a).gray, Render(b).gray);
}

// A strip lying over the whole top of a platform block that stands in the photo (it reaches in
// from the bottom border only) and hanging off both of its ends: not a cantilever from one
// edge. Grey levels, not reflectances; x right, y down [px].
struct DrapedScene {
  int width = 400, height = 260;                                        // [px]
  double platform_left = 120, platform_right = 250, platform_top = 90;  // [px]
  double radius = 100;                                  // bend radius of both overhangs [px]
  double left_deg = 70, right_deg = 50;                 // angle turned by each overhang [deg]
  double thickness = 10;                                // [px]
  double strip = 50, background = 190, platform = 100;  // grey levels
  double blur_sigma = 1.0, noise_sigma = 1.0;           // [px], [grey levels]
  unsigned seed = 1;
};

inline cv::Mat RenderDraped(const DrapedScene& s) {
  constexpr int kSub = 4;  // drawn at 4x and reduced: anti-aliased
  cv::Mat big(s.height * kSub, s.width * kSub, CV_8U, cv::Scalar(s.background));
  cv::rectangle(big, cv::Point(int(s.platform_left * kSub), int(s.platform_top * kSub)),
                cv::Point(int(s.platform_right * kSub), s.height * kSub), cv::Scalar(s.platform),
                cv::FILLED);
  // The mid-line: down the left overhang to the platform's left corner, over the top, and down
  // the right overhang.
  const double y = s.platform_top - s.thickness / 2;
  std::vector<cv::Point> line;
  for (double a = s.left_deg; a >= 0; a -= 1) {
    const double r = a * M_PI / 180;
    line.emplace_back(int(kSub * (s.platform_left - s.radius * std::sin(r))),
                      int(kSub * (y + s.radius * (1 - std::cos(r)))));
  }
  for (double a = 0; a <= s.right_deg; a += 1) {
    const double r = a * M_PI / 180;
    line.emplace_back(int(kSub * (s.platform_right + s.radius * std::sin(r))),
                      int(kSub * (y + s.radius * (1 - std::cos(r)))));
  }
  cv::polylines(big, line, false, cv::Scalar(s.strip), int(s.thickness * kSub), cv::LINE_AA);
  cv::Mat img;
  cv::resize(big, img, cv::Size(s.width, s.height), 0, 0, cv::INTER_AREA);
  img.convertTo(img, CV_64F);
  if (s.blur_sigma > 0) cv::GaussianBlur(img, img, cv::Size(0, 0), s.blur_sigma);
  cv::Mat noise(img.size(), CV_64F);
  cv::RNG rng(s.seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, s.noise_sigma);
  img += noise;
  cv::Mat gray;
  img.convertTo(gray, CV_8U);
  return gray;
}

}  // namespace textile::testing

#endif  // TEXTILE_TESTS_FIT_SYNTHETIC_PHOTO_H_
