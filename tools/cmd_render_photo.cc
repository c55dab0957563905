// textile render-photo: synthetic cantilever photos of a material with a known truth (profile
// CSV and the true rig), plus the matching chessboard image for `textile calibrate`.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "textile/photo/image_codecs.h"
#include "textile/photo/render_photo.h"
#include "textile/sim/core/error.h"
#include "textile/sim/law/material.h"

namespace textile::cli {
namespace {

struct RenderArgs {
  std::string material, out, difficulty = "medium", size = "2000x1500", board = "9x6";
  std::string polarity = "auto", direction = "auto";
  std::vector<double> overhangs_mm;
  double mm_per_px = 0.1, thickness_mm = 0.5;
  int jpeg = -1;  // -1: the difficulty's default
  unsigned seed = 1;
  bool json = false;
};

// "AxB" with positive integers; throws InputError naming the flag.
std::pair<int, int> ParsePair(const std::string& text, const std::string& flag) {
  const auto x = text.find_first_of("xX");
  int a = 0, b = 0;
  try {
    size_t ea = 0, eb = 0;
    if (x == std::string::npos) throw std::invalid_argument("");
    a = std::stoi(text.substr(0, x), &ea);
    b = std::stoi(text.substr(x + 1), &eb);
    if (ea != x || eb != text.size() - x - 1) throw std::invalid_argument("");
  } catch (const std::exception&) {
    throw InputError(flag + ": expected AxB with whole numbers, got '" + text + "'");
  }
  if (a <= 0 || b <= 0) throw InputError(flag + ": both numbers must be > 0, got '" + text + "'");
  return {a, b};
}

bool IsJpegPath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".jpg" || ext == ".jpeg") return true;
  if (ext == ".png") return false;
  throw InputError("-o: " + path + ": the photo must be .png, .jpg or .jpeg");
}

std::string WithSuffix(const std::string& path, const std::string& suffix, const std::string& ext) {
  const std::filesystem::path p(path);
  return (p.parent_path() / (p.stem().string() + suffix + ext)).string();
}

// The truth at about `spacing` [m] of arc (the renderer samples every quarter pixel), ends kept.
Profile Thinned(const Profile& p, double spacing) {
  if (p.size() < 3) return p;
  const double ds = p.s.back() / static_cast<double>(p.size() - 1);
  const size_t k = std::max<size_t>(1, static_cast<size_t>(spacing / ds));
  Profile out;
  out.source = p.source;
  for (size_t i = 0; i < p.size(); i += k) {
    if (i + 1 == p.size()) break;
    out.s.push_back(p.s[i]);
    out.x.push_back(p.x[i]);
    out.y.push_back(p.y[i]);
  }
  out.s.push_back(p.s.back());
  out.x.push_back(p.x.back());
  out.y.push_back(p.y.back());
  return out;
}

void WriteImage(const AtomicFile& f, const cv::Mat& image, const std::vector<unsigned char>& jpeg,
                bool as_jpeg) {
  if (as_jpeg && !jpeg.empty()) {
    std::ofstream(f.temp_path(), std::ios::binary)
        .write(reinterpret_cast<const char*>(jpeg.data()), static_cast<std::streamsize>(jpeg.size()));
    return;
  }
  std::vector<int> params;
  if (as_jpeg) params = {cv::IMWRITE_JPEG_QUALITY, 95};
  if (!image_codecs::Write(f.temp_path(), image, params))
    throw InputError(f.path() + ": cannot write the image");
}

// The suffix of an overhang's photo when several are rendered: "_L040mm".
std::string LengthTag(double length_mm) {
  char tag[32];
  std::snprintf(tag, sizeof tag, "_L%03.0fmm", length_mm);
  return tag;
}

void Run(const RenderArgs& a) {
  const Material m = ReadMaterial(a.material);
  const auto [w, h] = ParsePair(a.size, "--size");
  const auto [cols, rows] = ParsePair(a.board, "--board");
  const PhotoDifficulty difficulty = ParsePhotoDifficulty(a.difficulty, "--difficulty");
  if (a.overhangs_mm.empty()) throw InputError("--overhang-mm: give at least one length");
  for (double L : a.overhangs_mm) {
    if (!(std::isfinite(L) && L >= 1.0 && L <= 2000.0))
      throw InputError("--overhang-mm: " + Num(L) + " mm is outside [1, 2000] mm");
  }
  // Several lengths name their photos by the whole millimetre (_L040mm): two that round alike
  // would write the same files.
  for (size_t i = 0; i < a.overhangs_mm.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      if (LengthTag(a.overhangs_mm[i]) == LengthTag(a.overhangs_mm[j]))
        throw InputError("--overhang-mm: " + Num(a.overhangs_mm[j]) + " and " +
                         Num(a.overhangs_mm[i]) + " mm would name the same photo (" +
                         LengthTag(a.overhangs_mm[i]) + ")");
    }
  }
  if (!(std::isfinite(a.thickness_mm) && a.thickness_mm >= 0.01 &&
        a.thickness_mm <= kMaxRenderThickness * 1e3)) {
    throw InputError("--thickness-mm must lie in [0.01, " + Num(kMaxRenderThickness * 1e3) +
                     "] mm (thicker strips rise too far above the platform for extract)");
  }
  if (!(std::isfinite(a.mm_per_px) && a.mm_per_px >= 0.001 && a.mm_per_px <= 10))
    throw InputError("--mm-per-px must lie in [0.001, 10]");
  if (a.jpeg > 100 || a.jpeg < -1) throw InputError("--jpeg must lie in [0, 100]");
  const bool as_jpeg = IsJpegPath(a.out);

  RenderPhotoOptions o = RenderPhotoOptions::ForDifficulty(difficulty, a.seed);
  o.width_px = w;
  o.height_px = h;
  o.mm_per_px = a.mm_per_px;
  o.thickness = a.thickness_mm * 1e-3;
  o.board_cols = cols;
  o.board_rows = rows;
  if (a.jpeg >= 0) o.jpeg_quality = a.jpeg;
  if (a.polarity != "auto") {
    const bool light = a.polarity == "light";
    if (light != o.light_strip) {
      // Keep the contrast of the level, swap who is light.
      std::swap(o.strip_reflectance, o.background_reflectance);
      o.light_strip = light;
      o.face_reflectance = light ? 0.6 : 0.3;
    }
  }
  if (a.direction != "auto") o.overhang_left = a.direction == "left";
  std::string why;
  if (!o.Check(&why)) {
    // Name the flag where one set the field.
    const std::string flag = why.rfind("photo size", 0) == 0  ? "--size"
                             : why.rfind("board", 0) == 0     ? "--board"
                             : why.rfind("thickness", 0) == 0 ? "--thickness-mm"
                                                              : "render-photo";
    throw InputError(flag + ": " + why);
  }

  // One camera for every overhang: framed on the longest strip.
  std::vector<double> lengths = a.overhangs_mm;
  const bool several = lengths.size() > 1;
  std::vector<size_t> order(lengths.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t i, size_t j) { return lengths[i] > lengths[j]; });

  const std::string ext = std::filesystem::path(a.out).extension().string();
  // The board in the photo's format (JPEG boards keep samples small; corners stay sub-pixel).
  const std::string board_path = WithSuffix(a.out, ".board", as_jpeg ? ".jpg" : ".png");
  const std::string rig_path = WithSuffix(a.out, ".rig-truth", ".json");
  std::vector<std::unique_ptr<AtomicFile>> files;
  files.push_back(std::make_unique<AtomicFile>(board_path));
  files.push_back(std::make_unique<AtomicFile>(rig_path));
  image_codecs::Load();  // opened now: a missing library fails before any rendering
  nlohmann::json photos = nlohmann::json::array();
  std::vector<nlohmann::json> by_input(lengths.size());
  std::string text;
  for (size_t k = 0; k < order.size(); ++k) {
    const size_t i = order[k];
    o.overhang = lengths[i] * 1e-3;
    const std::string photo_path = several ? WithSuffix(a.out, LengthTag(lengths[i]), ext) : a.out;
    const std::string truth_path = WithSuffix(photo_path, ".truth", ".csv");
    if (several) Progress("rendering " + photo_path + " ...");  // on a terminal only
    const RenderedPhoto r = RenderPhoto(m.EffectiveLaw(), m.areal_density, o);
    if (k == 0) {
      o.aim_mm = r.aim_mm;
      std::vector<int> params;
      if (as_jpeg) params = {cv::IMWRITE_JPEG_QUALITY, 95};
      if (!image_codecs::Write(files[0]->temp_path(), r.board, params))
        throw InputError(board_path + ": cannot write");
      std::ofstream(files[1]->temp_path()) << RigToJson(r.rig);
    }
    files.push_back(std::make_unique<AtomicFile>(photo_path));
    WriteImage(*files.back(), r.photo, r.encoded, as_jpeg);
    files.push_back(std::make_unique<AtomicFile>(truth_path));
    std::ofstream(files.back()->temp_path(), std::ios::binary) << ProfileToCsv(Thinned(r.truth, 1e-4));
    by_input[i] = {{"photo", photo_path},
                   {"truth_csv", truth_path},
                   {"overhang_mm", lengths[i]},
                   {"tip_mm", {r.tip_x_mm, r.tip_y_mm}},
                   {"origin_px", {r.origin_px.x(), r.origin_px.y()}},
                   {"description", r.description}};
    if (k == 0) {
      by_input[i]["board_square_mm"] = r.board_square_mm;
    }
    std::ostringstream line;
    line << photo_path << "  (L = " << Num(lengths[i]) << " mm, tip (" << Num(r.tip_x_mm, 5) << ", "
         << Num(r.tip_y_mm, 5) << ") mm; " << r.description << ")\n";
    by_input[i]["text"] = line.str();
  }
  double square = 0;
  for (auto& j : by_input) {
    if (j.contains("board_square_mm")) {
      square = j["board_square_mm"];
      j.erase("board_square_mm");
    }
    text += j["text"].get<std::string>();
    j.erase("text");
    photos.push_back(j);
  }
  for (auto& f : files) f->Commit();
  if (a.json) {
    PrintJson({{"material", a.material}, {"difficulty", a.difficulty}, {"seed", a.seed},
               {"photos", photos}, {"board", board_path}, {"board_size", {cols, rows}},
               {"board_square_mm", square}, {"rig_truth", rig_path}, {"mm_per_px", a.mm_per_px},
               {"image_size_px", {w, h}}});
    return;
  }
  std::cout << text << "board: " << board_path << " (" << cols << "x" << rows
            << " inner corners, squares " << Num(square) << " mm: textile calibrate " << board_path
            << " --board " << cols << "x" << rows << " --square-mm " << Num(square) << ")\n"
            << "true rig: " << rig_path << "\n";
}

}  // namespace

void RegisterRenderPhoto(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* sub = AddSubcommand(
      app, "render-photo",
      "Render synthetic cantilever photos of a material with a known truth, and a chessboard image",
      "textile render-photo --material samples/materials/pabst-fig8.json --overhang-mm 40 60 "
      "--difficulty medium -o out/fig8.png");
  sub->add_option("--material", a->material, "Material JSON (law and areal density)")->required();
  sub->add_option("--overhang-mm", a->overhangs_mm,
                  "Overhang length(s) [mm]; several give <stem>_L060mm.png etc., one camera")
      ->required();
  sub->add_option("-o,--out", a->out,
                  "Photo to write (.png or .jpg); also <stem>.truth.csv, <stem>.board.png|jpg and "
                  "<stem>.rig-truth.json")
      ->required();
  sub->add_option("--difficulty", a->difficulty, "easy, medium (default) or hard");
  sub->add_option("--seed", a->seed, "Random seed: pose, polarity, direction, defects, noise (default 1)");
  sub->add_option("--size", a->size, "Photo size WxH [px] (default 2000x1500)");
  sub->add_option("--mm-per-px", a->mm_per_px, "Scale at the aim point in the bending plane (default 0.1)");
  sub->add_option("--thickness-mm", a->thickness_mm,
                  "Strip thickness [mm], 0.01 to 4 (default 0.5)");
  sub->add_option("--polarity", a->polarity, "auto (from the seed), dark or light strip")
      ->check(CLI::IsMember({"auto", "dark", "light"}));
  sub->add_option("--direction", a->direction, "auto (from the seed), right or left overhang")
      ->check(CLI::IsMember({"auto", "right", "left"}));
  sub->add_option("--jpeg", a->jpeg, "JPEG quality of the round trip, 0 = none (default: the level's)");
  sub->add_option("--board", a->board, "Chessboard inner corners COLSxROWS (default 9x6)");
  sub->add_flag("--json", a->json, "Print one JSON object instead of text");
  sub->callback([a] { Run(*a); });
}

namespace {
const bool kRegistered = AddCommand(35, RegisterRenderPhoto);
}  // namespace

}  // namespace textile::cli
