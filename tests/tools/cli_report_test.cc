// `textile report` through the real executable: the report of the shipped series is one
// self-contained page whose numbers are summary.json's, and which headless Chromium renders with
// every chart and thumbnail and no console message.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "run_cli.h"

namespace textile {
namespace {

using testing::ReadAll;
using testing::Scratch;
using testing::Textile;
namespace fs = std::filesystem;

// data-key -> data-value of every number cell of the page.
std::map<std::string, std::string> NumberCells(const std::string& html) {
  // By hand: std::regex recurses per character and overflows the stack on a page of thumbnails.
  std::map<std::string, std::string> cells;
  const std::string key = "data-key=\"", value = "\" data-value=\"";
  for (size_t at = html.find(key); at != std::string::npos; at = html.find(key, at + 1)) {
    const size_t k0 = at + key.size(), k1 = html.find(value, k0);
    if (k1 == std::string::npos) break;
    const size_t v0 = k1 + value.size(), v1 = html.find('"', v0);
    if (v1 == std::string::npos) break;
    cells[html.substr(k0, k1 - k0)] = html.substr(v0, v1 - v0);
  }
  return cells;
}

void ExpectCell(const std::map<std::string, std::string>& cells, const std::string& key,
                const nlohmann::json& value) {
  const auto it = cells.find(key);
  ASSERT_NE(it, cells.end()) << key << " is not on the page";
  if (value.is_null()) {
    EXPECT_EQ(it->second, "null") << key;
    return;
  }
  const double shown = std::stod(it->second), want = value.get<double>();
  EXPECT_NEAR(shown, want, 1e-14 * std::max(1.0, std::abs(want))) << key;
}

// The headless browser Debian ships (chromium-headless-shell), or chromium; "" when neither.
std::string Browser() {
  for (const char* b : {"/usr/bin/chromium-headless-shell", "/usr/bin/chromium"})
    if (fs::exists(b)) return b;
  return "";
}

// Renders `page` in `browser` headless: the DOM after load into dom, the console into log; the
// browser's exit code.
int Render(const std::string& browser, const fs::path& page, const fs::path& dom,
           const fs::path& log) {
  const std::string cmd = "timeout 120 '" + browser +
                          "' --no-sandbox --disable-gpu --enable-logging=stderr --v=0 "
                          "--virtual-time-budget=5000 --dump-dom 'file://" + page.string() +
                          "' > '" + dom.string() + "' 2> '" + log.string() + "'";
  return std::system(cmd.c_str());
}

// The shipped series batched and reported into a scratch folder of the test's own (ctest runs
// tests in parallel processes).
fs::path BatchAndReport(const std::string& name) {
  fs::path dir = Scratch(name);
  const auto batch = Textile("batch samples/series/manifest.csv -o " + (dir / "out").string());
  EXPECT_EQ(batch.exit_code, 0) << batch.err;
  const auto report =
      Textile("report " + (dir / "out").string() + " -o " + (dir / "report.html").string());
  EXPECT_EQ(report.exit_code, 0) << report.err;
  return dir;
}

TEST(CliReport, EveryNumberIsSummaryJsons) {
  const fs::path dir = BatchAndReport("cli_report_numbers");
  const std::string html = ReadAll(dir / "report.html");
  const nlohmann::json s = nlohmann::json::parse(ReadAll(dir / "out/summary.json"));
  const auto cells = NumberCells(html);
  for (const auto& d : s["directions"]) {
    const std::string k = d["fabric"].get<std::string>() + "/" + d["direction"].get<std::string>();
    for (const char* q : {"b1_gfcm", "b2_gfcm", "c1_gfcm2"})
      for (const char* stat : {"mean", "sd", "cv"}) ExpectCell(cells, k + "/" + q + "/" + stat, d[q][stat]);
    for (const char* stat : {"mean", "sd", "cv"}) {
      ExpectCell(cells, k + "/bending_length_mm/" + stat, d["bending_length_mm"][stat]);
      ExpectCell(cells, k + "/flexural_rigidity_uNm/" + stat, d["flexural_rigidity_uNm"][stat]);
    }
  }
  for (const auto& f : s["fabrics"]) {
    ExpectCell(cells, f["fabric"].get<std::string>() + "/overall/uNm", f["overall_rigidity_uNm"]);
    ExpectCell(cells, f["fabric"].get<std::string>() + "/overall/mgcm", f["overall_rigidity_mgcm"]);
  }
  for (const auto& sp : s["specimens"])
    ExpectCell(cells, sp["fabric"].get<std::string>() + "/" + sp["specimen"].get<std::string>() +
                          "/b1_gfcm",
               sp["b1_gfcm"]);
  // Self-contained: nothing is fetched.
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);
  EXPECT_EQ(html.find("href=\"http"), std::string::npos);
  EXPECT_NE(html.find("data:image/jpeg;base64,"), std::string::npos) << "the photo's overlay";
  EXPECT_NE(html.find("held out pass"), std::string::npos) << "the validation verdict";
}

TEST(CliReport, HeadlessChromiumRendersItWithoutAConsoleMessage) {
  const std::string browser = Browser();
  if (browser.empty()) GTEST_SKIP() << "no headless Chromium (Debian: chromium-headless-shell)";
  const fs::path dir = BatchAndReport("cli_report_browser");
  const fs::path dom = dir / "dom.html", log = dir / "browser.log";
  ASSERT_EQ(Render(browser, dir / "report.html", dom, log), 0) << ReadAll(log);
  const std::string rendered = ReadAll(dom);
  EXPECT_NE(rendered.find("data-selfcheck=\"ok\""), std::string::npos)
      << "a thumbnail or chart failed: " << ReadAll(log);
  EXPECT_EQ(ReadAll(log).find(":CONSOLE"), std::string::npos) << ReadAll(log);
  // The rendered page carries the same numbers as the file.
  EXPECT_EQ(NumberCells(rendered), NumberCells(ReadAll(dir / "report.html")));
}

TEST(CliReport, HeadlessChromiumCatchesABrokenThumbnail) {
  // The check above could pass by never looking: a page with one thumbnail broken must fail it.
  const std::string browser = Browser();
  if (browser.empty()) GTEST_SKIP() << "no headless Chromium (Debian: chromium-headless-shell)";
  const fs::path dir = BatchAndReport("cli_report_tampered");
  std::string html = ReadAll(dir / "report.html");
  const std::string jpeg = "data:image/jpeg;base64,";
  const size_t at = html.find(jpeg);
  ASSERT_NE(at, std::string::npos);
  html.replace(at + jpeg.size(), 8, "AAAAAAAA");
  std::ofstream(dir / "tampered.html") << html;
  const fs::path dom = dir / "dom.html", log = dir / "browser.log";
  ASSERT_EQ(Render(browser, dir / "tampered.html", dom, log), 0) << ReadAll(log);
  EXPECT_NE(ReadAll(dom).find("data-selfcheck=\"failed\""), std::string::npos);
  EXPECT_NE(ReadAll(log).find("thumbnail did not decode"), std::string::npos) << ReadAll(log);
}

TEST(CliReportRefusals, AFolderWithoutABatchSummaryIsRefused) {
  const fs::path d = Scratch("cli_report_refused");
  const auto r = Textile("report " + d.string() + " -o " + (d / "r.html").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no summary.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "r.html"));
}

}  // namespace
}  // namespace textile
