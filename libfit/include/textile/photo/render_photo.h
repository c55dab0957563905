#ifndef TEXTILE_PHOTO_RENDER_PHOTO_H_
#define TEXTILE_PHOTO_RENDER_PHOTO_H_

// Synthetic cantilever photos with a known truth (docs/spec/cantilever.md, "Photo protocol"): the
// exact heavy elastica of a law, drawn as a band of the strip's thickness resting on a platform
// block, seen by a pinhole camera with a pose (perspective), over a background with a light
// gradient and a shadow, with the strip's texture, its frayed tip and hairy edges, optics blur,
// sensor noise and JPEG compression; plus the matching chessboard image held in the bending plane.
// For the extractor's tests, the calibration's tests, samples/photos and `textile bench
// extract-accuracy`.
//
//   textile::RenderPhotoOptions o = textile::RenderPhotoOptions::ForDifficulty(
//       textile::PhotoDifficulty::kMedium, /*seed=*/7);
//   o.overhang = 0.06;                                     // [m]
//   textile::RenderedPhoto r = textile::RenderPhoto(law, 0.2, o);   // law [SI], ρ [kg/m²]
//   textile::image_codecs::Write("strip.png", r.photo);     // or r.encoded (JPEG bytes)
//   // r.truth: the mid-line in the frame of docs/spec/cantilever.md [m]; r.rig: image -> plane
//   [mm];
//   // r.board: the chessboard photo; r.board_corners_px: its inner corners' true positions.
//
// Plane frame (mm): the frame of docs/spec/cantilever.md, origin at the platform's top/front
// corner, x towards the overhang, y up, z towards the camera; the strip's near side face lies in z
// = 0. Pixels are OpenCV's (x right, y down, pixel centres at integers). Deterministic per seed.

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "textile/fit/profile.h"
#include "textile/photo/rig.h"
#include "textile/sim/law/bending_law.h"

namespace textile {

enum class PhotoDifficulty { kEasy, kMedium, kHard };

// "easy", "medium", "hard"; throws InputError naming `flag` otherwise.
PhotoDifficulty ParsePhotoDifficulty(const std::string& text, const std::string& flag);
std::string ToString(PhotoDifficulty d);

struct RenderPhotoOptions {
  // --- the strip ---
  double overhang = 0.06;       // free length L beyond the platform edge [m]
  double thickness = 0.5e-3;    // t [m]: the band's height as seen side-on, at most
                                // kMaxRenderThickness (what extraction measures reliably)
  double strip_width = 0.0;     // depth of the strip away from the camera [m]; > 0 shows its top
                                // or bottom face as a band next to the side face (oblique view)
  double on_platform = 0.04;    // length lying on the platform, visible part [m]

  // --- camera (pinhole, square pixels, principal point at the image centre) ---
  int width_px = 2000, height_px = 1500;
  double mm_per_px = 0.1;       // scale at the aim point in the bending plane [mm/px]
  double distance = 0.8;        // camera centre to the aim point [m]; smaller = more perspective
  double yaw_deg = 0.0;         // turn about the vertical (positive: looks a bit to the right)
  double pitch_deg = 0.0;       // tilt about the horizontal (positive: looks down)
  double roll_deg = 0.0;        // about the optical axis (positive: the scene turns clockwise)
  // Aim point offset from the middle of the strip's bounding box, as fractions of the image.
  double aim_dx = 0.0, aim_dy = 0.0;
  // Fixed aim point in the plane [mm] instead of framing this strip: one camera for photos of
  // several overhangs (render the longest first and reuse its RenderedPhoto::aim_mm).
  std::optional<Eigen::Vector2d> aim_mm;

  // --- look ---
  bool light_strip = false;     // a light strip on a dark background (else dark on light)
  bool overhang_left = false;   // the photo mirrored: the overhang points left
  double strip_reflectance = 0.16, background_reflectance = 0.78, platform_reflectance = 0.45;
  double face_reflectance = 0.30;   // the top/bottom face (strip_width > 0)
  double gradient = 0.0;        // light falling off across the photo (0 = even, 0.4 = 40 %)
  double shadow = 0.0;          // depth of the strip's soft shadow on the background (0..1)
  double texture = 0.0;         // strip reflectance modulation, relative σ (weave, stains)
  int tip_fibres = 0;           // loose fibres at the frayed tip
  int edge_fibres = 0;          // short hairs along the strip's edges
  double blur_px = 1.0;         // optics, Gaussian σ [px]
  double noise = 2.0;           // sensor noise σ at mid grey [grey levels] (with shot noise)
  int jpeg_quality = 0;         // 0: none; else JPEG round trip at this quality (1..100)
  int supersample = 4;          // anti-aliasing samples per pixel side (1..8)

  // --- the chessboard image (same camera, board in the bending plane) ---
  int board_cols = 9, board_rows = 6;  // inner corners
  double board_square_mm = 0.0;        // 0: chosen to fill about half the image

  std::uint64_t seed = 1;

  // Defaults of a difficulty level with its random pose, polarity, direction and defects drawn
  // from `seed`: easy (side-on, clean), medium (a few degrees of pose, gradient, shadow, texture,
  // frayed tip, blur 1.2 px, noise 3, JPEG 92), hard (more of everything, an oblique face,
  // JPEG 75). The size and scale fields keep their defaults.
  static RenderPhotoOptions ForDifficulty(PhotoDifficulty difficulty, std::uint64_t seed);

  // True if every field is usable; otherwise *why says which and why.
  bool Check(std::string* why) const;
};

// Thickest strip rendered [m]: its mid-line starts t/2 above the platform, and extraction
// refuses mid-lines more than 3 mm up (CheckProfile); 4 mm leaves a millimetre for the noise of
// the first points (4 mm strips extract to about 0.05 mm RMS, 5 mm ones were refused or worse).
inline constexpr double kMaxRenderThickness = 4e-3;

struct RenderedPhoto {
  cv::Mat photo;                    // CV_8UC1, width_px × height_px (after JPEG if asked)
  std::vector<unsigned char> encoded;  // the JPEG bytes when jpeg_quality > 0, else empty
  cv::Mat board;                    // CV_8UC1 chessboard photo by the same camera
  int board_cols = 0, board_rows = 0;
  double board_square_mm = 0.0;
  std::vector<Eigen::Vector2d> board_corners_px;  // #cols·rows inner corners, row-major [px]
  std::vector<Eigen::Vector2d> board_corners_mm;  // the same in the board's own frame [mm]
                                                  // (x along a row, y down the rows)

  Profile truth;  // strip mid-line, frame of docs/spec/cantilever.md [m]; s from the edge
  Profile truth_upper, truth_lower; // the silhouette's boundaries in the plane z = 0 [m]
  std::vector<Eigen::Vector2d> truth_px;  // #N the truth mid-line in the photo [px]
  Eigen::Vector2d origin_px{0, 0};  // the platform edge in the photo [px]
  Rig rig;                          // the true image -> plane map (plane frame above) [mm]
  Eigen::Matrix3d image_from_plane = Eigen::Matrix3d::Identity();  // its inverse [px/mm]
  Eigen::Matrix3d camera_matrix = Eigen::Matrix3d::Identity();     // K [px]
  double tip_x_mm = 0.0, tip_y_mm = 0.0;  // mid-line tip, cantilever frame [mm]
  Eigen::Vector2d aim_mm{0, 0};     // where the camera looks in the plane [mm]
  std::string description;          // one line: difficulty-relevant settings, for CSV/JSON
};

// Renders the strip of law `law` [SI] and areal density [kg/m²] as options say. Throws
// InputError for options that fail Check, ComputeError when the elastica fails or the strip
// does not fit in the photo (then the message says which way).
RenderedPhoto RenderPhoto(const BendingLaw& law, double areal_density,
                          const RenderPhotoOptions& options);

// Distance of a point in the cantilever frame [m] from a polyline profile [m] (nearest segment).
double DistanceToProfile(const Profile& truth, double x, double y);

}  // namespace textile

#endif  // TEXTILE_PHOTO_RENDER_PHOTO_H_
