// The lab report (batch_report.h). Stages: ReadSummary, SummarySection (ASTM D1388 / FAST),
// StatisticsSection, CurvesSection (an SVG per fabric: each specimen's M(κ), the direction's
// mean ± sd band), SpecimensSection (table, verdicts, thumbnails), then the page around them.

#include "textile/photo/batch_report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <vector>

#include "textile/photo/image_codecs.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/core/units.h"
#include "textile/sim/law/bending_law.h"

namespace textile {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string ReadText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string Escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string Base64(const std::vector<unsigned char>& bytes) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const unsigned v = (unsigned{bytes[i]} << 16) |
                       (i + 1 < bytes.size() ? unsigned{bytes[i + 1]} << 8 : 0u) |
                       (i + 2 < bytes.size() ? unsigned{bytes[i + 2]} : 0u);
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? k[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? k[v & 63] : '=';
  }
  return out;
}

// A number cell: the rounded text shown, the full value in data-value under data-key.
std::string Cell(const json& v, const std::string& key, int digits = 4) {
  if (v.is_null()) return "<td data-key=\"" + key + "\" data-value=\"null\">–</td>";
  const double x = v.get<double>();
  std::ostringstream full;
  full.precision(17);
  full << x;
  return "<td data-key=\"" + key + "\" data-value=\"" + full.str() + "\">" +
         NumberText(x, digits) + "</td>";
}

std::string PercentCell(const json& v, const std::string& key) {
  if (v.is_null()) return "<td data-key=\"" + key + "\" data-value=\"null\">–</td>";
  std::ostringstream full;
  full.precision(17);
  full << v.get<double>();
  return "<td data-key=\"" + key + "\" data-value=\"" + full.str() + "\">" +
         NumberText(100.0 * v.get<double>(), 3) + " %</td>";
}

// The shape the page reads (batch.h, SummaryJson), checked before any of it is read: a field
// missing or of another type throws (std::runtime_error, made an InputError by ReadSummary).
void CheckSummaryShape(const json& s) {
  const auto need = [](const json& o, const char* key, bool (json::*is)() const, bool null_ok,
                       const std::string& where) {
    if (!o.is_object() || !o.contains(key) || !((o[key].*is)() || (null_ok && o[key].is_null())))
      throw std::runtime_error(where + ": '" + key + "' missing or of the wrong type");
  };
  const auto name = [](const json& o, const char* key, const std::string& where) {
    const std::string v = o[key].get<std::string>();
    if (v.empty() || v.front() == '.' || v.find('/') != std::string::npos ||
        v.find('\\') != std::string::npos)
      throw std::runtime_error(where + ": '" + key + "' is no folder name");
  };
  for (const char* k : {"directions", "fabrics", "specimens"})
    need(s, k, &json::is_array, false, "summary");
  for (const json& d : s["directions"]) {
    for (const char* k : {"fabric", "direction"}) need(d, k, &json::is_string, false, "direction");
    for (const char* k : {"n", "n_failed"}) need(d, k, &json::is_number, false, "direction");
    for (const char* q : {"b1_gfcm", "b2_gfcm", "c1_gfcm2", "bending_length_mm",
                          "flexural_rigidity_uNm", "flexural_rigidity_mgcm"}) {
      need(d, q, &json::is_object, false, "direction");
      need(d[q], "n", &json::is_number, false, q);
      for (const char* k : {"mean", "sd", "cv"}) need(d[q], k, &json::is_number, true, q);
    }
  }
  for (const json& f : s["fabrics"]) {
    need(f, "fabric", &json::is_string, false, "fabric");
    name(f, "fabric", "fabric");
    for (const char* k : {"overall_rigidity_uNm", "overall_rigidity_mgcm"})
      need(f, k, &json::is_number, true, "fabric");
  }
  for (const json& sp : s["specimens"]) {
    for (const char* k : {"fabric", "specimen", "direction", "side", "status"})
      need(sp, k, &json::is_string, false, "specimen");
    name(sp, "fabric", "specimen");
    name(sp, "specimen", "specimen");
    for (const char* k : {"b1_gfcm", "b2_gfcm", "c1_gfcm2", "bending_length_mm",
                          "flexural_rigidity_uNm", "rms_mm"})
      need(sp, k, &json::is_number, true, "specimen");
    need(sp, "error", &json::is_string, true, "specimen");
    need(sp, "validation", &json::is_object, true, "specimen");
    if (sp["validation"].is_object()) {
      for (const char* k : {"goodness_of_fit", "held_out"})
        need(sp["validation"], k, &json::is_string, false, "validation");
      need(sp["validation"], "pass", &json::is_boolean, false, "validation");
      need(sp["validation"], "reason", &json::is_string, true, "validation");
    }
  }
}

json ReadSummary(const std::string& dir) {
  const fs::path p = fs::path(dir) / "summary.json";
  std::error_code ec;
  if (!fs::is_regular_file(p, ec))
    throw InputError(dir + ": no summary.json (run textile batch into it first)");
  try {
    json s = json::parse(ReadText(p));
    CheckSummaryShape(s);
    return s;
  } catch (const std::exception& e) {  // JSON syntax, a missing field, a wrong type
    throw InputError(p.string() + ": not a batch summary (" + e.what() + ")");
  }
}

// ---- ASTM D1388 / FAST summary ----------------------------------------------------------

std::string SummarySection(const json& s) {
  std::ostringstream h;
  h << "<h2>Summary (ASTM D1388 / FAST)</h2>\n"
       "<p>Bending length c and flexural rigidity G = ρ g c³ per direction, as the classic 41.5° "
       "cantilever reports them, computed from each specimen's fitted law; mean ± sample sd, "
       "CV. Overall rigidity √(G<sub>warp</sub> G<sub>weft</sub>).</p>\n";
  for (const json& f : s["fabrics"]) {
    const std::string fabric = f["fabric"];
    h << "<h3>" << Escape(fabric) << "</h3>\n<table>\n<tr><th>direction</th><th>n</th>"
      << "<th>c mean [mm]</th><th>c sd [mm]</th><th>c CV</th><th>G mean [µN·m]</th>"
      << "<th>G sd [µN·m]</th><th>G CV</th><th>G mean [mg·cm]</th></tr>\n";
    for (const json& d : s["directions"]) {
      if (d["fabric"] != fabric) continue;
      const std::string k = fabric + "/" + d["direction"].get<std::string>() + "/";
      const json& c = d["bending_length_mm"];
      const json& g = d["flexural_rigidity_uNm"];
      h << "<tr><td>" << Escape(d["direction"]) << "</td><td>" << d["n"] << "</td>"
        << Cell(c["mean"], k + "bending_length_mm/mean") << Cell(c["sd"], k + "bending_length_mm/sd")
        << PercentCell(c["cv"], k + "bending_length_mm/cv")
        << Cell(g["mean"], k + "flexural_rigidity_uNm/mean")
        << Cell(g["sd"], k + "flexural_rigidity_uNm/sd")
        << PercentCell(g["cv"], k + "flexural_rigidity_uNm/cv")
        << Cell(d["flexural_rigidity_mgcm"]["mean"], k + "flexural_rigidity_mgcm/mean") << "</tr>\n";
    }
    h << "<tr class=\"overall\"><td colspan=\"5\">overall rigidity</td>"
      << Cell(f["overall_rigidity_uNm"], fabric + "/overall/uNm") << "<td colspan=\"2\"></td>"
      << Cell(f["overall_rigidity_mgcm"], fabric + "/overall/mgcm") << "</tr>\n</table>\n";
  }
  return h.str();
}

// ---- Per-direction statistics of the law --------------------------------------------------

std::string StatisticsSection(const json& s) {
  std::ostringstream h;
  h << "<h2>The bending law per direction</h2>\n"
       "<p>The constants of Pabst et al.'s moment-curvature law in KES units (b1, b2 gf·cm/cm, "
       "c1 gf·cm²/cm). n counts the specimens whose fit determined the "
       "constant; the others are left out of its mean.</p>\n<table>\n<tr><th>fabric</th>"
       "<th>direction</th><th>specimens</th><th>failed</th>";
  for (const char* q : {"b1", "b2", "c1"})
    h << "<th>" << q << " n</th><th>" << q << " mean</th><th>" << q << " sd</th><th>" << q
      << " CV</th>";
  h << "</tr>\n";
  for (const json& d : s["directions"]) {
    const std::string k =
        d["fabric"].get<std::string>() + "/" + d["direction"].get<std::string>() + "/";
    h << "<tr><td>" << Escape(d["fabric"]) << "</td><td>" << Escape(d["direction"]) << "</td><td>"
      << d["n"] << "</td><td>" << d["n_failed"] << "</td>";
    for (const char* q : {"b1_gfcm", "b2_gfcm", "c1_gfcm2"}) {
      const json& x = d[q];
      h << "<td data-key=\"" << k << q << "/n\" data-value=\"" << x["n"] << "\">" << x["n"]
        << "</td>" << Cell(x["mean"], k + q + "/mean") << Cell(x["sd"], k + q + "/sd")
        << PercentCell(x["cv"], k + q + "/cv");
    }
    h << "</tr>\n";
  }
  h << "</table>\n";
  return h.str();
}

// ---- M-κ curves --------------------------------------------------------------------------

struct Curve {
  std::string direction;
  BendingLaw law;
  bool determined = true;  // its fit determined every constant (else drawn dashed)
};

const char* DirectionColour(const std::string& d) {
  return d == "warp" ? "#1f77b4" : d == "weft" ? "#d62728" : "#2ca02c";
}

// The curvature range of a fabric's chart [1/cm]: the largest its specimens' data reached.
double KappaRange(const std::string& dir, const json& s, const std::string& fabric) {
  double kmax = 0.0;
  for (const json& sp : s["specimens"]) {
    if (sp["fabric"] != fabric || sp["status"] != "fitted") continue;
    const fs::path m = fs::path(dir) / fabric / sp["specimen"].get<std::string>() / "material.json";
    try {
      const json j = json::parse(ReadText(m));
      kmax = std::max(kmax, j["fit"].value("kappa_max_per_cm", 0.0));
    } catch (const std::exception&) {
      // a specimen folder removed after the batch: its range is unknown, the others decide
    }
  }
  return kmax > 0.0 ? kmax : 1.0;
}

std::string CurvesSvg(const std::string& fabric, const std::vector<Curve>& curves, double kmax) {
  constexpr int kW = 560, kH = 340, kL = 60, kR = 20, kT = 20, kB = 45, kSamples = 60;
  std::map<std::string, std::vector<std::vector<double>>> by;  // direction -> curves' M
  std::map<std::string, std::vector<bool>> determined;          // direction -> each curve's
  double mmax = 0.0;
  for (const Curve& c : curves) {
    determined[c.direction].push_back(c.determined);
    std::vector<double> m;
    for (int i = 0; i <= kSamples; ++i) {
      const double k = kmax * i / kSamples;
      m.push_back(units::SiMomentToKes(c.law.Moment(units::KesCurvatureToSi(k))));
      mmax = std::max(mmax, m.back());
    }
    by[c.direction].push_back(m);
  }
  if (!(mmax > 0.0)) mmax = 1.0;
  const auto X = [&](double k) { return kL + (kW - kL - kR) * k / kmax; };
  const auto Y = [&](double m) { return kH - kB - (kH - kT - kB) * std::max(0.0, m) / (1.05 * mmax); };
  std::ostringstream svg;
  svg << "<svg class=\"chart\" data-fabric=\"" << Escape(fabric) << "\" width=\"" << kW
      << "\" height=\"" << kH << "\" viewBox=\"0 0 " << kW << " " << kH
      << "\" xmlns=\"http://www.w3.org/2000/svg\" font-size=\"11\">\n"
      << "<rect x=\"" << kL << "\" y=\"" << kT << "\" width=\"" << kW - kL - kR << "\" height=\""
      << kH - kT - kB << "\" fill=\"none\" stroke=\"#888\"/>\n";
  for (int i = 0; i <= 4; ++i) {
    svg << "<text x=\"" << X(kmax * i / 4) << "\" y=\"" << kH - kB + 15 << "\" text-anchor=\"middle\">"
        << NumberText(kmax * i / 4, 3) << "</text>\n"
        << "<text x=\"" << kL - 5 << "\" y=\"" << Y(1.05 * mmax * i / 4) + 4
        << "\" text-anchor=\"end\">" << NumberText(1.05 * mmax * i / 4, 3) << "</text>\n";
  }
  svg << "<text x=\"" << (kW + kL) / 2 << "\" y=\"" << kH - 8
      << "\" text-anchor=\"middle\">κ [1/cm]</text>\n<text x=\"14\" y=\"" << (kH - kB) / 2
      << "\" transform=\"rotate(-90 14 " << (kH - kB) / 2
      << ")\" text-anchor=\"middle\">M [gf·cm/cm]</text>\n";
  int legend = 0;
  for (const auto& [direction, ms] : by) {
    const char* colour = DirectionColour(direction);
    // The band: mean ± sample sd of M over the specimens, at each κ (with two or more).
    std::vector<double> mean(kSamples + 1, 0.0), sd(kSamples + 1, 0.0);
    for (int i = 0; i <= kSamples; ++i) {
      for (const auto& m : ms) mean[i] += m[i] / ms.size();
      if (ms.size() > 1) {
        for (const auto& m : ms) sd[i] += (m[i] - mean[i]) * (m[i] - mean[i]);
        sd[i] = std::sqrt(sd[i] / (ms.size() - 1));
      }
    }
    if (ms.size() > 1) {
      svg << "<polygon class=\"band\" fill=\"" << colour << "\" fill-opacity=\"0.18\" points=\"";
      for (int i = 0; i <= kSamples; ++i)
        svg << X(kmax * i / kSamples) << "," << Y(mean[i] + sd[i]) << " ";
      for (int i = kSamples; i >= 0; --i)
        svg << X(kmax * i / kSamples) << "," << Y(mean[i] - sd[i]) << " ";
      svg << "\"/>\n";
    }
    for (size_t c = 0; c < ms.size(); ++c) {
      const std::vector<double>& m = ms[c];
      svg << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"0.8\" "
          << (determined[direction][c] ? "" : "stroke-dasharray=\"4 3\" ")
          << "stroke-opacity=\"0.6\" points=\"";
      for (int i = 0; i <= kSamples; ++i) svg << X(kmax * i / kSamples) << "," << Y(m[i]) << " ";
      svg << "\"/>\n";
    }
    svg << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"2.2\" points=\"";
    for (int i = 0; i <= kSamples; ++i) svg << X(kmax * i / kSamples) << "," << Y(mean[i]) << " ";
    svg << "\"/>\n<text x=\"" << kL + 10 << "\" y=\"" << kT + 15 + 14 * legend++ << "\" fill=\""
        << colour << "\">" << Escape(direction) << " (" << ms.size() << ")</text>\n";
  }
  svg << "</svg>\n";
  return svg.str();
}

std::string CurvesSection(const std::string& dir, const json& s) {
  std::ostringstream h;
  h << "<h2>Moment-curvature curves</h2>\n<p>Thin lines: each fitted specimen's M(κ), dashed "
       "where its fit left a constant undetermined (such a constant stays out of the statistics "
       "above); thick: their mean; band: ± 1 sample sd of M. Up to the largest curvature any "
       "specimen's data of the fabric reached.</p>\n";
  for (const json& f : s["fabrics"]) {
    const std::string fabric = f["fabric"];
    std::vector<Curve> curves;
    for (const json& sp : s["specimens"]) {
      if (sp["fabric"] != fabric || sp["status"] != "fitted" || sp["b1_gfcm"].is_null()) continue;
      const bool determined = !sp.contains("unobserved") || sp["unobserved"].empty();
      curves.push_back({sp["direction"],
                        BendingLaw::FromKes(sp["b1_gfcm"], sp["b2_gfcm"], sp["c1_gfcm2"]),
                        determined});
    }
    h << "<h3>" << Escape(fabric) << "</h3>\n";
    if (curves.empty()) {
      h << "<p>No specimen of this fabric was fitted.</p>\n";
      continue;
    }
    h << CurvesSvg(fabric, curves, KappaRange(dir, s, fabric));
  }
  return h.str();
}

// ---- Specimens ---------------------------------------------------------------------------

// The thumbnails of a specimen's overlays, as <img> with data: URIs (JPEG, kReportThumbnailSidePx).
std::string Thumbnails(const fs::path& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return "";
  std::vector<fs::path> overlays;
  for (const auto& e : fs::directory_iterator(folder, ec))
    if (e.path().string().ends_with(".overlay.png")) overlays.push_back(e.path());
  std::sort(overlays.begin(), overlays.end());
  std::string out;
  for (const fs::path& p : overlays) {
    const cv::Mat image = image_codecs::Read(p.string(), 1 /* IMREAD_COLOR */);
    if (image.empty()) continue;
    const double scale =
        std::min(1.0, double{kReportThumbnailSidePx} / std::max(image.cols, image.rows));
    cv::Mat small;
    cv::resize(image, small, cv::Size(), scale, scale, cv::INTER_AREA);
    std::vector<unsigned char> jpeg;
    if (!image_codecs::Encode(".jpg", small, &jpeg, {1 /* IMWRITE_JPEG_QUALITY */, 85})) continue;
    out += "<img class=\"thumb\" alt=\"" + Escape(p.filename().string()) +
           "\" src=\"data:image/jpeg;base64," + Base64(jpeg) + "\">";
  }
  return out;
}

std::string VerdictCell(const json& v) {
  if (v.is_null()) return "<td class=\"muted\">not asked</td>";
  const bool pass = v.value("pass", false);
  std::string text = "fit " + v.value("goodness_of_fit", std::string("?")) + ", held out " +
                     v.value("held_out", std::string("?"));
  if (!pass && v["reason"].is_string()) text += ": " + v["reason"].get<std::string>();
  return std::string("<td class=\"") + (pass ? "pass" : "fail") + "\">" + Escape(text) + "</td>";
}

std::string SpecimensSection(const std::string& dir, const json& s) {
  std::ostringstream h;
  size_t asked = 0, passed = 0, failed = 0;
  for (const json& sp : s["specimens"]) {
    failed += sp["status"] == "failed";
    if (sp["validation"].is_null()) continue;
    ++asked;
    passed += sp["validation"].value("pass", false);
  }
  h << "<h2>Specimens</h2>\n<p>" << s["specimens"].size() << " specimens, " << failed
    << " failed to fit; validation asked of " << asked << ", passed by " << passed
    << ".</p>\n<table>\n<tr><th>fabric</th><th>specimen</th><th>direction</th><th>side</th>"
       "<th>status</th><th>b1</th><th>b2</th><th>c1</th><th>c [mm]</th><th>G [µN·m]</th>"
       "<th>rms [mm]</th><th>validation</th><th>overlays</th></tr>\n";
  for (const json& sp : s["specimens"]) {
    const std::string fabric = sp["fabric"], specimen = sp["specimen"];
    const std::string k = fabric + "/" + specimen + "/";
    const bool ok = sp["status"] == "fitted";
    h << "<tr><td>" << Escape(fabric) << "</td><td>" << Escape(specimen) << "</td><td>"
      << Escape(sp["direction"]) << "</td><td>" << Escape(sp["side"]) << "</td>";
    if (!ok) {
      h << "<td class=\"fail\" colspan=\"9\">failed: " << Escape(sp.value("error", std::string()))
        << "</td>";
    } else {
      h << "<td>fitted</td>" << Cell(sp["b1_gfcm"], k + "b1_gfcm")
        << Cell(sp["b2_gfcm"], k + "b2_gfcm") << Cell(sp["c1_gfcm2"], k + "c1_gfcm2")
        << Cell(sp["bending_length_mm"], k + "bending_length_mm")
        << Cell(sp["flexural_rigidity_uNm"], k + "flexural_rigidity_uNm")
        << Cell(sp["rms_mm"], k + "rms_mm", 3) << VerdictCell(sp["validation"]);
    }
    h << "<td>" << Thumbnails(fs::path(dir) / fabric / specimen) << "</td></tr>\n";
  }
  h << "</table>\n";
  return h.str();
}

constexpr const char* kStyle = R"(body{font-family:sans-serif;margin:2em;color:#222}
table{border-collapse:collapse;margin:0.5em 0 1.5em}td,th{border:1px solid #ccc;padding:3px 7px;
text-align:right}th{background:#f2f2f2}td:first-child,th:first-child{text-align:left}
.pass{color:#176917}.fail{color:#b00020;text-align:left}.muted{color:#888}
.overall td{font-weight:bold}img.thumb{max-width:160px;margin:2px;vertical-align:middle})";

// Checks on load that every thumbnail decoded and every chart drew; a failure is a console error.
constexpr const char* kSelfCheck = R"(window.addEventListener('load', function () {
  var bad = 0;
  document.querySelectorAll('img.thumb').forEach(function (img) {
    if (!img.complete || img.naturalWidth === 0) { bad++; console.error('thumbnail did not decode: ' + img.alt); }
  });
  document.querySelectorAll('svg.chart').forEach(function (svg) {
    if (svg.getBBox().width === 0) { bad++; console.error('chart did not draw: ' + svg.dataset.fabric); }
  });
  document.body.dataset.selfcheck = bad === 0 ? 'ok' : 'failed';
});)";

}  // namespace

std::string BatchReportHtml(const std::string& dir) {
  const json s = ReadSummary(dir);
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
    << "<title>Bending report: " << Escape(fs::path(dir).filename().string()) << "</title>\n"
    << "<style>" << kStyle << "</style>\n</head>\n<body>\n<h1>Cantilever bending report</h1>\n"
    << "<p>" << s["specimens"].size() << " specimens of " << s["fabrics"].size()
    << " fabrics, fitted by textile batch (the direct elastica fit of Pabst et al.'s law). "
       "Every number below is in summary.json.</p>\n"
    << SummarySection(s) << StatisticsSection(s) << CurvesSection(dir, s)
    << SpecimensSection(dir, s) << "<script>" << kSelfCheck << "</script>\n</body>\n</html>\n";
  return h.str();
}

}  // namespace textile
