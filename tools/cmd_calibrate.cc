// textile calibrate: chessboard photos -> a rig file (image -> bending-plane homography, with
// several boards also the lens distortion), for `textile extract --rig` and `textile fit --rig`.

#include <filesystem>
#include <iostream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <system_error>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "textile/photo/calibrate.h"
#include "textile/photo/extract.h"
#include "textile/photo/image_codecs.h"
#include "textile/sim/core/error.h"

namespace textile::cli {
namespace {

struct CalibrateArgs {
  std::vector<std::string> boards;
  std::string board = "", out, overlay;
  double square_mm = 0.0, max_error_px = 1.0, max_seconds = 60.0;
  bool no_lens = false, json = false;
};

std::pair<int, int> ParseBoard(const std::string& text) {
  const auto x = text.find_first_of("xX");
  try {
    if (x == std::string::npos) throw std::invalid_argument("");
    size_t ea = 0, eb = 0;
    const int a = std::stoi(text.substr(0, x), &ea);
    const int b = std::stoi(text.substr(x + 1), &eb);
    if (ea != x || eb != text.size() - x - 1) throw std::invalid_argument("");
    return {a, b};
  } catch (const std::exception&) {
    throw InputError("--board: expected COLSxROWS inner corners (e.g. 9x6), got '" + text + "'");
  }
}

// The first board with its corners, the first one circled, scaled to at most 1600 px.
cv::Mat Overlay(const cv::Mat& gray, const BoardDetection& d, int cols, int rows) {
  cv::Mat colour;
  cv::cvtColor(gray, colour, cv::COLOR_GRAY2BGR);
  std::vector<cv::Point2f> corners;
  for (const auto& p : d.corners_px) corners.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  cv::drawChessboardCorners(colour, cv::Size(cols, rows), corners, d.found);
  if (!corners.empty()) {
    cv::circle(colour, corners[0], std::max(6, static_cast<int>(d.square_px / 3)), cv::Scalar(0, 0, 255), 2);
  }
  const double scale = std::min(1.0, 1600.0 / std::max(colour.cols, colour.rows));
  if (scale < 1.0) cv::resize(colour, colour, cv::Size(), scale, scale, cv::INTER_AREA);
  return colour;
}

void Run(const CalibrateArgs& a) {
  CalibrateOptions o;
  std::tie(o.cols, o.rows) = ParseBoard(a.board);
  o.square_mm = a.square_mm;
  o.max_error_px = a.max_error_px;
  o.lens = !a.no_lens;
  o.max_seconds = a.max_seconds;
  std::string why;
  if (!o.Check(&why)) {
    const std::string flag = why.rfind("square size", 0) == 0   ? "--square-mm"
                             : why.rfind("maximum", 0) == 0      ? "--max-error-px"
                             : why.rfind("max_seconds", 0) == 0  ? "--max-seconds"
                                                                 : "--board";
    throw InputError(flag + ": " + why);
  }
  // Outputs checked before the work; they appear together.
  std::vector<std::pair<std::string, std::string>> inputs;
  for (const std::string& board : a.boards) inputs.emplace_back("(a board photo)", board);
  CheckDistinctOutputs({{"-o", a.out}, {"--overlay", a.overlay}}, inputs);
  AtomicFileSet outputs;
  AtomicFile& rig_file = outputs.Add(a.out);
  AtomicFile* overlay_file = a.overlay.empty() ? nullptr : &outputs.Add(a.overlay);
  if (overlay_file)
    CheckOutputExtension("--overlay", a.overlay, {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff"});
  // One photo given twice adds no pose: the lens distortion would be fitted to one view.
  for (size_t j = 1; j < a.boards.size(); ++j) {
    for (size_t i = 0; i < j; ++i) {
      std::error_code ec;
      if (std::filesystem::is_regular_file(a.boards[j], ec) &&
          std::filesystem::equivalent(a.boards[i], a.boards[j], ec))
        throw InputError(a.boards[j] + ": the same photo as " + a.boards[i] +
                         " (more boards must show other poses)");
    }
  }
  std::vector<cv::Mat> images;
  for (const auto& path : a.boards) images.push_back(ReadPhotoGray(path));
  const CalibrationSummary c = CalibrateRig(images, a.boards, o);
  if (!c.success) throw ComputeError(c.message);
  rig_file.Write(RigToJson(c.rig));
  if (overlay_file) {
    if (!image_codecs::Write(overlay_file->temp_path(),
                             Overlay(images[0], c.detections[0], o.cols, o.rows))) {
      throw InputError(a.overlay + ": cannot write the overlay");
    }
  }
  outputs.Commit();
  if (a.json) {
    nlohmann::json boards = nlohmann::json::array();
    for (const auto& d : c.detections) {
      boards.push_back({{"photo", d.source}, {"found", d.found}, {"square_px", d.square_px},
                        {"image_size_px", {d.image_size.width, d.image_size.height}}});
    }
    nlohmann::json lens_models = nlohmann::json::array();
    for (const auto& m : c.lens_candidates) {
      lens_models.push_back({{"terms", m.terms},
                             {"rms_px", m.rms_px},
                             {"p_next", m.p_next},
                             {"p_value", m.p_value},
                             {"significance", m.significance}});
    }
    PrintJson(
        {{"rig_file", a.out},
         {"boards", boards},
         {"lens_model", c.lens_model},
         {"reprojection_error_px", c.rms_error_px},
         {"max_error_px", c.max_error_px},
         {"reprojection_error_mm", c.rms_error_mm},
         {"max_error_mm", c.max_error_mm},
         {"lens_rms_px", c.lens_terms.empty() ? nlohmann::json() : nlohmann::json(c.lens_rms_px)},
         {"lens_terms", c.lens_terms.empty() ? nlohmann::json() : nlohmann::json(c.lens_terms)},
         {"distortion", c.lens_model ? nlohmann::json(c.rig.lens->distortion) : nlohmann::json()},
         {"distortion_sigma", c.lens_model ? nlohmann::json(c.distortion_sigma) : nlohmann::json()},
         {"lens_models", lens_models},
         {"mm_per_px", c.mm_per_px},
         {"seconds", c.seconds}});
    return;
  }
  std::cout << c.BriefReport() << "\nwrote " << a.out << (a.overlay.empty() ? "" : " and " + a.overlay)
            << "\n";
}

}  // namespace

void RegisterCalibrate(CLI::App& app) {
  auto a = std::make_shared<CalibrateArgs>();
  CLI::App* sub = AddSubcommand(
      app, "calibrate",
      "Chessboard photo(s) in the bending plane -> rig file (homography, lens distortion)",
      "textile calibrate samples/photos/pabst-fig8.board.jpg --board 9x6 --square-mm 8.5 -o "
      "rig.json");
  sub->add_option("boards", a->boards,
                  "Board photos (PNG, JPEG, TIFF, BMP); the first lies in the bending plane, more "
                  "(other poses) also give the lens distortion")
      ->required();
  sub->add_option("--board", a->board, "Inner corners COLSxROWS (e.g. 9x6; not the squares)")->required();
  sub->add_option("--square-mm", a->square_mm, "Side of one square [mm]")->required();
  sub->add_option("-o,--out", a->out, "Rig JSON to write")->required();
  sub->add_option("--overlay", a->overlay, "Write the first board with its corners drawn (PNG)");
  sub->add_option("--max-error-px", a->max_error_px,
                  "Refuse a calibration whose RMS reprojection error is larger (default 1 px)");
  sub->add_option("--max-seconds", a->max_seconds,
                  "Wall-time cap [s] (default 60): past it, no rig is written and the exit is 3");
  sub->add_flag("--no-lens", a->no_lens, "Homography only, even with several boards");
  sub->add_flag("--json", a->json, "Print one JSON object instead of text");
  sub->callback([a] { Run(*a); });
}

namespace {
const bool kRegistered = AddCommand(25, RegisterCalibrate);
}  // namespace

}  // namespace textile::cli
