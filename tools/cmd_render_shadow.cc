// textile render-shadow: a synthetic top-view photo of a Cusick drape test (the shadow of a
// draped mesh, e.g. `textile drape --obj`) with a known truth, and the chessboard photo by the
// same camera for `textile calibrate` (docs/guide/render-shadow.md).

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "textile/photo/image_codecs.h"
#include "textile/photo/render_shadow.h"
#include "textile/sim/core/error.h"
#include "textile/sim/io/mesh_io.h"

namespace textile::cli {
namespace {

struct RenderShadowArgs {
  std::string mesh, out, board, truth, style = "shadow", size = "1600x1200", units = "m";
  double mm_per_px = 0.25, tilt_deg = 0.0, azimuth_deg = 30.0, k1 = 0.0, gradient = 0.0;
  double vignetting = 0.0, blur_px = 1.0, noise = 2.0, texture = 0.05;
  double specimen_mm = 150.0, support_mm = 90.0;
  int jpeg = 0;
  unsigned seed = 1;
  bool json = false;
};

std::pair<int, int> ParseSize(const std::string& text) {
  const auto x = text.find_first_of("xX");
  try {
    size_t ea = 0, eb = 0;
    if (x == std::string::npos) throw std::invalid_argument("");
    const int a = std::stoi(text.substr(0, x), &ea);
    const int b = std::stoi(text.substr(x + 1), &eb);
    if (ea != x || eb != text.size() - x - 1) throw std::invalid_argument("");
    return {a, b};
  } catch (const std::exception&) {
    throw InputError("--size: expected WxH with whole numbers, got '" + text + "'");
  }
}

void WriteImage(AtomicFile& f, const cv::Mat& image, const std::vector<unsigned char>& jpeg) {
  std::string ext = std::filesystem::path(f.path()).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool as_jpeg = ext == ".jpg" || ext == ".jpeg";
  if (as_jpeg && !jpeg.empty()) {
    // The rendered JPEG's own bytes (the photo was decoded from them), checked as written.
    f.Write(std::string_view(reinterpret_cast<const char*>(jpeg.data()), jpeg.size()));
    return;
  }
  std::vector<int> params;
  if (as_jpeg) params = {cv::IMWRITE_JPEG_QUALITY, 95};
  if (!image_codecs::Write(f.temp_path(), image, params))
    throw InputError(f.path() + ": cannot write the image");
}

void Run(const RenderShadowArgs& a) {
  CheckDistinctOutputs({{"-o", a.out}, {"--board", a.board}, {"--truth", a.truth}},
                       {{"DRAPED.obj", a.mesh}});
  CheckOutputExtension("-o", a.out, {".png", ".jpg", ".jpeg"});
  if (!a.board.empty()) CheckOutputExtension("--board", a.board, {".png", ".jpg", ".jpeg"});
  RenderShadowOptions o;
  const auto [w, h] = ParseSize(a.size);
  o.width_px = w;
  o.height_px = h;
  o.style = ParseShadowStyle(a.style, "--style");
  o.mm_per_px = a.mm_per_px;
  o.tilt_deg = a.tilt_deg;
  o.tilt_azimuth_deg = a.azimuth_deg;
  o.k1 = a.k1;
  o.gradient = a.gradient;
  o.vignetting = a.vignetting;
  o.blur_px = a.blur_px;
  o.noise = a.noise;
  o.jpeg_quality = a.jpeg;
  o.texture = o.style == ShadowStyle::kTop ? a.texture : 0.0;
  o.seed = a.seed;
  o.measure.specimen_radius = a.specimen_mm * 1e-3;
  o.measure.support_radius = a.support_mm * 1e-3;
  if (std::string why; !o.Check(&why)) throw InputError("render-shadow: " + why);
  if (a.units != "m" && a.units != "mm")
    throw InputError("--units: m or mm, got '" + a.units + "'");

  const TriangleMesh mesh = ReadDrapedMesh(a.mesh);
  AtomicFileSet outputs;
  AtomicFile& photo_file = outputs.Add(a.out);
  AtomicFile* board_file = a.board.empty() ? nullptr : &outputs.Add(a.board);
  AtomicFile* truth_file = a.truth.empty() ? nullptr : &outputs.Add(a.truth);
  image_codecs::Load();  // a missing codec library fails before the rendering
  const RenderedShadow r = RenderShadowPhoto(mesh, a.units == "mm" ? 1e-3 : 1.0, o, a.mesh);
  WriteImage(photo_file, r.photo, r.encoded);
  if (board_file) WriteImage(*board_file, r.board, {});
  const std::string truth = RenderedShadowTruthJson(r, o);
  if (truth_file) truth_file->Write(truth);
  outputs.Commit();

  if (a.json) {
    nlohmann::json j = nlohmann::json::parse(truth);
    j["photo"] = a.out;
    if (!a.board.empty()) j["board_photo"] = a.board;
    if (!a.truth.empty()) j["truth"] = a.truth;
    PrintJson(j);
    return;
  }
  std::cout << a.out << "  (" << r.description << ")\n"
            << "truth: DC " << Num(r.truth.drape_coefficient, 4) << ", "
            << r.truth.nodes.angles.size() << " nodes, support centre at ("
            << Num(r.centre_px.x(), 6) << ", " << Num(r.centre_px.y(), 6) << ") px, "
            << Num(r.centre_mm_per_px, 4) << " mm/px there\n";
  if (board_file)
    std::cout << "board: " << a.board << " (textile calibrate " << a.board << " --board "
              << r.board_cols << "x" << r.board_rows << " --square-mm " << Num(r.board_square_mm)
              << ")\n";
}

}  // namespace

void RegisterRenderShadow(CLI::App& app) {
  auto a = std::make_shared<RenderShadowArgs>();
  CLI::App* sub = AddSubcommand(
      app, "render-shadow",
      "Render a top-view shadow photo of a draped mesh with a known truth, and a chessboard photo",
      "textile render-shadow out/drape.obj -o out/shadow.png --board out/board.png --truth "
      "out/truth.json --tilt-deg 8 --gradient 0.3 --noise 3 --jpeg 90");
  sub->add_option("mesh", a->mesh,
                  "Draped mesh (OBJ or PLY; `textile drape --obj`), z up, support centre at the origin")
      ->required();
  sub->add_option("-o,--out", a->out, "Photo to write (.png or .jpg)")->required();
  sub->add_option("--board", a->board, "Also write the chessboard photo by the same camera");
  sub->add_option("--truth", a->truth, "Also write the truth JSON (DC, nodes, centre, true rig)");
  sub->add_option("--style", a->style,
                  "shadow (dark shadow on lit paper, default) or top "
                  "(the specimen from above, textured)");
  sub->add_option("--size", a->size, "Photo size WxH [px] (default 1600x1200)");
  sub->add_option("--mm-per-px", a->mm_per_px,
                  "Scale at the support's centre on the paper (default 0.25)");
  sub->add_option("--tilt-deg", a->tilt_deg, "Camera axis off vertical [°], 0..20 (default 0)");
  sub->add_option("--azimuth-deg", a->azimuth_deg, "Direction of the tilt [°] (default 30)");
  sub->add_option("--k1", a->k1, "Radial lens distortion, OpenCV's k1 (default 0)");
  sub->add_option("--gradient", a->gradient,
                  "Light falling off across the photo, 0..0.8 (default 0)");
  sub->add_option("--vignetting", a->vignetting,
                  "Light fall-off at the corners, 0..0.6 (default 0)");
  sub->add_option("--blur-px", a->blur_px, "Soft edge, Gaussian σ [px] (default 1)");
  sub->add_option("--noise", a->noise, "Sensor noise σ at mid grey [grey levels] (default 2)");
  sub->add_option("--texture", a->texture,
                  "Top style: the weave's and stains' relative σ (default 0.05)");
  sub->add_option("--jpeg", a->jpeg, "JPEG round trip at this quality, 0 = none (default 0)");
  sub->add_option("--specimen-mm", a->specimen_mm,
                  "Specimen radius for the truth [mm] (default 150)");
  sub->add_option("--support-mm", a->support_mm, "Support radius for the truth [mm] (default 90)");
  sub->add_option("--units", a->units, "Units of the mesh: m (default) or mm");
  sub->add_option("--seed", a->seed, "Random seed of the noise and texture (default 1)");
  sub->add_flag("--json", a->json, "Print one JSON object (the truth) instead of text");
  sub->callback([a] { Run(*a); });
}

namespace {
const bool kRegistered = AddCommand(62, RegisterRenderShadow);
}  // namespace

}  // namespace textile::cli
