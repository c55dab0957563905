#ifndef TEXTILE_PHOTO_BATCH_REPORT_H_
#define TEXTILE_PHOTO_BATCH_REPORT_H_

// The lab report of a `textile batch` folder (docs/guide/report.md): one self-contained HTML
// page, no external assets (charts are inline SVG, thumbnails data: URIs), with an ASTM D1388 /
// FAST-style summary, the per-direction statistics, the M-κ curves with their ±1 sd bands, the
// specimen table with validation verdicts and the photos' overlays as thumbnails.
//
//   const std::string html = textile::BatchReportHtml("out/series");   // throws InputError
//
// Every number of summary.json the page shows carries its full value in data-key/data-value
// attributes (key "<fabric>/<direction>/<quantity>/<mean|sd|cv|n>", "<fabric>/overall/<unit>"),
// so that a reader can check the page against the file. A small script checks on load that
// every thumbnail decoded and every chart drew, logs console.error otherwise, and sets
// data-selfcheck="ok" on <body>.

#include <string>

namespace textile {

// Long side of a report thumbnail [px]; thumbnails are JPEG (quality 85).
inline constexpr int kReportThumbnailSidePx = 320;

// The report of the batch folder `dir` (its summary.json, and each specimen's folder for the
// curves' ranges and the overlays). Throws InputError when dir has no summary.json ("run
// textile batch first") or it is not one.
std::string BatchReportHtml(const std::string& dir);

}  // namespace textile

#endif  // TEXTILE_PHOTO_BATCH_REPORT_H_
