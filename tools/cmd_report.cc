// textile report: the lab report of a `textile batch` folder, one self-contained HTML file;
// textile::BatchReportHtml writes it (libfit photo/batch_report.h, docs/guide/report.md).

#include <iostream>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "textile/photo/batch_report.h"

namespace textile::cli {
namespace {

struct ReportArgs {
  std::string dir, output;
};

void Run(const ReportArgs& a) {
  const std::string html = BatchReportHtml(a.dir);
  WriteFileAtomically(a.output, html);
  std::cout << "wrote " << a.output << " (" << html.size() / 1024 << " KiB)\n";
}

}  // namespace

void RegisterReport(CLI::App& app) {
  auto a = std::make_shared<ReportArgs>();
  CLI::App* sub = AddSubcommand(
      app, "report", "Write the lab report of a batch folder: one self-contained HTML file",
      "textile report out/series -o out/series/report.html");
  sub->add_option("DIR", a->dir, "Folder of a `textile batch` run (its summary.json)")->required();
  sub->add_option("-o,--output", a->output, "HTML file to write")->required();
  sub->callback([a] { Run(*a); });
}

namespace {
const bool kRegistered = AddCommand(46, RegisterReport);
}  // namespace

}  // namespace textile::cli
