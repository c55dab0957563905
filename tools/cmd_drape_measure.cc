// textile drape-measure: the drapemeter's measurement of a real drape, from a draped mesh (a 3D
// scan, another simulator's output, `textile drape --obj`) or a top-view shadow photo: drape
// coefficient, nodes, outline; MEASURED.json for `textile drape --compare`.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <optional>
#include <sstream>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "textile/photo/drape_photo.h"
#include "textile/photo/extract.h"
#include "textile/photo/image_codecs.h"
#include "textile/photo/rig.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/note.h"
#include "textile/sim/core/units.h"
#include "textile/sim/io/mesh_io.h"
#include "textile/sim/plot/measured_drape_picture.h"
#include "textile/sim/scenes/drape_measure.h"

namespace textile::cli {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

struct DrapeMeasureArgs {
  std::string input, out, png;
  double specimen_mm = 150.0, support_mm = 90.0;
  std::string units, up, centre_mm;  // meshes (empty: not given)
  std::string rig, centre_px;        // photos
  std::optional<double> mm_per_px;   // photos
  bool json = false;
};

enum class InputKind { kMesh, kPhoto };

InputKind KindOf(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".obj" || ext == ".ply") return InputKind::kMesh;
  for (const char* e : {".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp"})
    if (ext == e) return InputKind::kPhoto;
  throw InputError(path +
                   ": name the input .obj or .ply (a draped mesh) or .png, .jpg, .tif or "
                   ".bmp (a shadow photo)");
}

// "X,Y" as two finite numbers; throws InputError naming the flag.
Eigen::Vector2d ParsePair(const std::string& flag, const std::string& text, const char* unit) {
  const std::size_t comma = text.find(',');
  Eigen::Vector2d p;
  for (int k = 0; k < 2; ++k) {
    const std::string s =
        k == 0 ? text.substr(0, comma) : (comma == std::string::npos ? "" : text.substr(comma + 1));
    char* end = nullptr;
    p[k] = std::strtod(s.c_str(), &end);
    if (comma == std::string::npos || s.empty() || *end != '\0' || !std::isfinite(p[k]))
      throw InputError(flag + ": expected X,Y in " + unit + ", got '" + text + "'");
  }
  return p;
}

DrapeMeasureOptions MeasureOptions(const DrapeMeasureArgs& a) {
  if (!std::isfinite(a.specimen_mm) || !(a.specimen_mm > 0.0 && a.specimen_mm <= 2000.0))
    throw InputError("--specimen-mm: must be in (0, 2000] mm");
  if (!std::isfinite(a.support_mm) || !(a.support_mm > 0.0))
    throw InputError("--support-mm: must be > 0");
  if (a.specimen_mm <= a.support_mm)
    throw InputError("--specimen-mm: the specimen (" + Num(a.specimen_mm) +
                     " mm) must be larger than the support (" + Num(a.support_mm) + " mm)");
  DrapeMeasureOptions o;
  o.specimen_radius = units::MmToM(a.specimen_mm);
  o.support_radius = units::MmToM(a.support_mm);
  if (std::string why; !o.Check(&why)) throw InputError("drape-measure: " + why);
  return o;
}

// The flags of the other input kind are refused: they would be silently ignored.
void CheckFlagsFor(InputKind kind, const DrapeMeasureArgs& a) {
  const std::string what = kind == InputKind::kMesh ? "a mesh" : "a photo";
  auto refuse = [&](bool given, const std::string& flag, const std::string& for_kind) {
    if (given)
      throw InputError(flag + ": for " + for_kind + " only (" + a.input + " is " + what + ")");
  };
  if (kind == InputKind::kMesh) {
    refuse(a.mm_per_px.has_value(), "--mm-per-px", "photos");
    refuse(!a.rig.empty(), "--rig", "photos");
    refuse(!a.centre_px.empty(), "--centre-px", "photos");
    return;
  }
  refuse(!a.units.empty(), "--units", "meshes");
  refuse(!a.up.empty(), "--up", "meshes");
  refuse(!a.centre_mm.empty(), "--centre-mm", "meshes");
  if (a.mm_per_px && !a.rig.empty())
    throw InputError("--rig and --mm-per-px: give one of them, not both");
  if (!a.mm_per_px && a.rig.empty())
    throw InputError(a.input + ": a photo needs its scale: give --mm-per-px or --rig");
}

DrapeMeshOptions MeshOptions(const DrapeMeasureArgs& a) {
  DrapeMeshOptions o;
  o.measure = MeasureOptions(a);
  if (a.units == "mm")
    o.metres_per_unit = 0.001;
  else if (!a.units.empty() && a.units != "m")
    throw InputError("--units: '" + a.units + "' is not m or mm");
  if (!a.up.empty()) {
    if (a.up != "z" && a.up != "y") throw InputError("--up: '" + a.up + "' is not z or y");
    o.up = ParseMeshUpAxis(a.up);
  }
  if (!a.centre_mm.empty()) {
    const Eigen::Vector2d c = ParsePair("--centre-mm", a.centre_mm, "mm");
    o.centre = Eigen::Vector2d(units::MmToM(c.x()), units::MmToM(c.y()));
  }
  return o;
}

std::string CentreText(const MeasuredDrape& m) {
  const std::string at =
      "(" + Num(units::MToMm(m.centre.x()), 4) + ", " + Num(units::MToMm(m.centre.y()), 4) + ") mm";
  if (m.centre_from == "origin") return at + ", the mesh's origin (its flat top is centred there)";
  if (m.centre_from == "plateau") return at + ", the centroid of the mesh's flat top";
  if (m.centre_from == "given") return at + ", given";
  if (m.centre_from == "shadow") return at + ", the shadow's centre";
  return at + (m.centre_from.empty() ? "" : ", " + m.centre_from);
}

void PrintText(const MeasuredDrape& m, const std::string& input_facts, const DrapeMeasureArgs& a,
               const std::string& outline_path) {
  std::cout << "input: " << a.input << " (" << input_facts << ")\n"
            << "drape coefficient: " << Num(m.drape_coefficient, 4) << " (specimen "
            << Num(units::MToMm(m.specimen_radius)) << " mm, support "
            << Num(units::MToMm(m.support_radius)) << " mm; A_specimen = pi R^2)\n"
            << "nodes: " << m.nodes.angles.size() << "\n";
  for (size_t k = 0; k < m.nodes.angles.size(); ++k)
    std::cout << "  " << Num(m.nodes.angles[k] / kDegree, 4) << " deg: r "
              << Num(units::MToMm(m.nodes.radii[k]), 4) << " mm, prominence "
              << Num(units::MToMm(m.nodes.prominences[k]), 3) << " mm\n";
  std::cout << "outline radius [mm]: min " << Num(units::MToMm(m.min_radius), 4) << ", mean "
            << Num(units::MToMm(m.mean_radius), 4) << ", max " << Num(units::MToMm(m.max_radius), 4)
            << "\n"
            << "centre: " << CentreText(m) << "\n";
  if (!m.notes.empty()) std::cout << "note: " << JoinNoteTexts(m.notes, "; ") << "\n";
  std::cout << "result: " << a.out << "\noutline: " << outline_path << "\n";
  if (!a.png.empty()) std::cout << "overlay: " << a.png << "\n";
}

std::string OutlinePath(const std::string& result) {
  std::filesystem::path p(result);
  if (p.extension() == ".json") p.replace_extension();
  return p.string() + ".outline.csv";
}

// The mesh's measurement; the overlay drawn by textile::plot into png (or none).
MeasuredDrape MeasureMesh(const DrapeMeasureArgs& a, AtomicFile* png, std::string* facts) {
  const DrapeMeshOptions o = MeshOptions(a);
  const TriangleMesh mesh = ReadDrapedMesh(a.input);
  *facts = "mesh, " + std::to_string(mesh.num_vertices()) + " vertices, " +
           std::to_string(mesh.num_triangles()) + " triangles";
  MeasuredDrape m = MeasureDrapeMesh(mesh, o, a.input);
  if (png && !WriteMeasuredDrapePng(m, png->temp_path()))
    throw InputError("--png: cannot write " + a.png);
  return m;
}

// The photo's measurement (textile::photo); its overlay is the photo with the outline drawn.
MeasuredDrape MeasurePhoto(const DrapeMeasureArgs& a, AtomicFile* png, std::string* facts) {
  DrapePhotoOptions o;
  o.measure = MeasureOptions(a);
  if (!a.centre_px.empty()) o.centre_px = ParsePair("--centre-px", a.centre_px, "pixels");
  const Rig rig = a.rig.empty() ? Rig::FromScale(*a.mm_per_px) : ReadRigJson(a.rig);
  const cv::Mat photo = ReadPhotoGray(a.input);
  *facts = "photo, " + std::to_string(photo.cols) + " x " + std::to_string(photo.rows) + " px";
  cv::Mat overlay;
  MeasuredDrape m = MeasureDrapePhoto(photo, rig, o, a.input, png ? &overlay : nullptr);
  if (png && (overlay.empty() || !image_codecs::Write(png->temp_path(), overlay)))
    throw InputError("--png: cannot write " + a.png);
  return m;
}

void Run(const DrapeMeasureArgs& a) {
  const InputKind kind = KindOf(a.input);
  CheckFlagsFor(kind, a);
  const std::string outline_path = OutlinePath(a.out);
  CheckDistinctOutputs(
      {{"-o", a.out}, {"the outline (next to -o)", outline_path}, {"--png", a.png}},
      {{"INPUT", a.input}, {"--rig", a.rig}});
  if (!a.png.empty()) CheckOutputExtension("--png", a.png, {".png"});
  AtomicFileSet outputs;
  AtomicFile& result_file = outputs.Add(a.out);
  AtomicFile& outline_file = outputs.Add(outline_path);
  AtomicFile* png_file = a.png.empty() ? nullptr : &outputs.Add(a.png);

  std::string facts;
  const MeasuredDrape m = kind == InputKind::kMesh ? MeasureMesh(a, png_file, &facts)
                                                   : MeasurePhoto(a, png_file, &facts);
  nlohmann::json j = nlohmann::json::parse(MeasuredDrapeJson(m));
  j["outline_csv"] = outline_file.path();
  if (png_file) j["png"] = a.png;
  outline_file.Write(OutlineCsv(m.shadow));
  result_file.Write(j.dump(2) + "\n");
  outputs.Commit();

  if (a.json) {
    j["output"] = a.out;
    PrintJson(j);
    return;
  }
  PrintText(m, facts, a, outline_file.path());
}

}  // namespace

void RegisterDrapeMeasure(CLI::App& app) {
  auto a = std::make_shared<DrapeMeasureArgs>();
  CLI::App* sub = AddSubcommand(
      app, "drape-measure",
      "Measured drape: drape coefficient, nodes and outline of a draped mesh (OBJ, PLY) or a "
      "top-view shadow photo, as the drapemeter measures a simulated one",
      "textile drape-measure scan.ply --units mm -o measured.json --png measured.png");
  sub->add_option("input", a->input,
                  "Draped mesh (.obj, .ply: vertical projection) or shadow photo (.png, .jpg, "
                  ".tif, .bmp)")
      ->required();
  sub->add_option("-o,--output", a->out,
                  "Result JSON (MEASURED.json, read by drape --compare); the outline CSV goes "
                  "next to it")
      ->required();
  sub->add_option("--png", a->png,
                  "Overlay picture (PNG): the outline, circles, centre and nodes (photos: drawn "
                  "on the photo)");
  sub->add_option("--specimen-mm", a->specimen_mm, "Specimen radius [mm] (default 150)");
  sub->add_option("--support-mm", a->support_mm, "Support radius [mm] (default 90)");
  sub->add_option("--units", a->units, "Mesh: the file's unit, m (default) or mm");
  sub->add_option("--up", a->up, "Mesh: the vertical axis, z (default) or y");
  sub->add_option("--centre-mm", a->centre_mm,
                  "Mesh: the support's centre X,Y in the horizontal plane [mm] (default: found "
                  "from the mesh's flat top)");
  sub->add_option("--mm-per-px", a->mm_per_px,
                  "Photo: the scale of a photo taken square on [mm/px]");
  sub->add_option("--rig", a->rig, "Photo: a rig JSON (from calibrate) instead of --mm-per-px");
  sub->add_option("--centre-px", a->centre_px,
                  "Photo: the support's centre X,Y in the photo [px] (default: found)");
  sub->add_flag("--json", a->json, "Print one JSON object instead of text");
  sub->callback([a] { Run(*a); });
}

namespace {
const bool kRegistered = AddCommand(65, RegisterDrapeMeasure);
}  // namespace

}  // namespace textile::cli
