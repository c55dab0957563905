#ifndef TEXTILE_PHOTO_RENDER_SHADOW_H_
#define TEXTILE_PHOTO_RENDER_SHADOW_H_

// Synthetic top-view photos of a Cusick drape test with a known truth (issue 33, point 4): the
// vertical projection of a draped mesh, seen by a pinhole camera above the paper with a known
// scale, a tilt off vertical (perspective), optional lens distortion, uneven light (a gradient
// and vignetting), the shadow's soft edge, sensor noise and JPEG; plus the chessboard photo by
// the same camera lying on the paper, so that `textile calibrate` finds the rig. For
// MeasureDrapePhoto's tests, `textile render-shadow` and `textile bench drape-measure-photo`.
//
//   textile::RenderShadowOptions o;                 // 1600 x 1200 px, 0.25 mm/px, vertical
//   o.tilt_deg = 8.0;  o.gradient = 0.3;  o.noise = 3.0;  o.jpeg_quality = 90;
//   textile::RenderedShadow r = textile::RenderShadowPhoto(draped, o);   // draped: #V×3 [m]
//   // r.photo: CV_8UC1; r.rig: image -> paper [mm]; r.centre_px: the support's centre;
//   // r.truth: MeasureDrapeShadow of the mesh's own raster (o.measure): the DC to recover.
//
// Paper frame (mm): the drape's own (x, y), origin at the support's centre, z up towards the
// camera. Pixels are OpenCV's (x right, y down, pixel centres at integers). Deterministic per
// seed.

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "textile/photo/rig.h"
#include "textile/sim/mesh/mesh.h"
#include "textile/sim/scenes/drape_measure.h"

namespace textile {

// What the photo shows.
//   kShadow  the drapemeter's dark shadow on lit paper (dark on light, uniform)
//   kTop     the specimen seen from above on a contrasting ground, with a woven texture and
//            stains (lighter or darker than the ground: specimen_reflectance)
enum class ShadowStyle { kShadow, kTop };

// "shadow", "top"; throws InputError naming `flag` otherwise.
ShadowStyle ParseShadowStyle(const std::string& text, const std::string& flag);
std::string ToString(ShadowStyle style);

struct RenderShadowOptions {
  ShadowStyle style = ShadowStyle::kShadow;

  // --- camera: pinhole, square pixels, principal point at the image centre ---
  int width_px = 1600, height_px = 1200;
  double mm_per_px = 0.25;        // scale at the aim point on the paper [mm/px]
  double distance = 1.2;          // camera centre to the aim point [m]; smaller = more perspective
  double tilt_deg = 0.0;          // optical axis off vertical [°], 0..20
  double tilt_azimuth_deg = 0.0;  // the direction the camera leans towards, in the paper [°]
  double roll_deg = 0.0;          // about the optical axis [°]
  Eigen::Vector2d aim_mm{0.0, 0.0};  // where the camera looks on the paper [mm]
  double k1 = 0.0;                   // radial lens distortion (OpenCV's k1; 0: none), |k1| ≤ 0.3

  // --- look ---
  double paper = 0.85;         // lit paper's level (shadow style) or the ground's (top) [0..1]
  double shadow_level = 0.12;  // the shadow's level (shadow style) [0..1]
  double specimen_reflectance = 0.55;  // the specimen's level (top style) [0..1]
  double texture = 0.0;                // top style: relative σ of the weave and stains
  double gradient = 0.0;               // light falling off across the photo (0 = even, 0.4 = 40 %)
  double gradient_azimuth_deg = 30.0;  // the direction it falls off towards, in the image [°]
  double vignetting = 0.0;             // relative fall-off at the photo's corners (0..0.6)
  double blur_px = 1.0;                // the shadow's soft edge and the optics, Gaussian σ [px]
  double noise = 2.0;            // sensor noise σ at mid grey [grey levels] (with shot noise)
  int jpeg_quality = 0;          // 0: none; else a JPEG round trip at this quality (1..100)
  int supersample = 3;           // anti-aliasing samples per pixel side (1..6)
  double raster_cell = 0.00025;  // the projection's raster drawn from [m] (finer than the
                                 // measurement's 0.5 mm)

  // --- the chessboard photo: same camera, board on the paper centred on the aim point ---
  int board_cols = 9, board_rows = 6;  // inner corners
  double board_square_mm = 0.0;        // 0: about 60 % of the photo's short side across
  bool render_board = true;            // false: RenderedShadow::board stays empty

  // The truth's measurement (MeasureDrapeShadow of the mesh's raster at measure.raster_cell).
  DrapeMeasureOptions measure;

  std::uint64_t seed = 1;

  // True if every field is usable; otherwise *why says which and why.
  bool Check(std::string* why) const;
};

struct RenderedShadow {
  cv::Mat photo;                       // CV_8UC1, width_px × height_px (after JPEG if asked)
  std::vector<unsigned char> encoded;  // the JPEG bytes when jpeg_quality > 0, else empty
  cv::Mat board;                       // CV_8UC1 chessboard photo by the same camera
  int board_cols = 0, board_rows = 0;
  double board_square_mm = 0.0;
  Rig rig;  // the true image -> paper map [mm] (lens when k1 ≠ 0)
  Eigen::Matrix3d image_from_plane = Eigen::Matrix3d::Identity();  // ideal px from paper mm
  Eigen::Vector2d centre_px{0.0, 0.0};  // the support's centre in the photo [px]
  double centre_mm_per_px = 0.0;        // local scale there [mm/px]
  MeasuredDrape truth;                  // the mesh's own measurement (centre_from "origin")
  std::string description;              // one line: the settings, for CSV/JSON
};

// Renders the draped mesh (vertices #V×3 [m] in the drape's frame, the support's centre at the
// origin; triangles #F×3) as options say. Throws InputError for options that fail Check or a
// mesh that MeasureShadow refuses, ComputeError when the mesh's own measurement fails or the
// shadow does not fit in the photo.
RenderedShadow RenderShadowPhoto(const Vertices& x, const Triangles& triangles,
                                 const RenderShadowOptions& options);

// The same for a draped mesh as a file gives it (ReadDrapedMesh: OBJ, PLY), in `metres_per_unit`
// (1: m, 0.001: mm), z up: its scale is checked as drape-measure checks it (CheckMeshScale:
// InputError "<source>: ... --units mm?") before it is rendered; messages name `source`.
RenderedShadow RenderShadowPhoto(const TriangleMesh& draped, double metres_per_unit,
                                 const RenderShadowOptions& options, const std::string& source);

// The rendered truth as JSON (drape coefficient, nodes, centre_px, scale, the true rig, the
// board), for `textile render-shadow --truth`.
std::string RenderedShadowTruthJson(const RenderedShadow& r, const RenderShadowOptions& o);

}  // namespace textile

#endif  // TEXTILE_PHOTO_RENDER_SHADOW_H_
