#ifndef TEXTILE_TOOLS_COMMON_CHART_FILE_H_
#define TEXTILE_TOOLS_COMMON_CHART_FILE_H_

// The CLI's charts as files: textile::chart's drawing (textile/sim/plot/chart.h) written through an
// AtomicFile, so that a failed run leaves no chart and never half of one.
//
//   chart::WritePng({.title = "Sample 3", .panels = {mk}}, "fit.png");    // on its own
//   chart::WritePng(figure, outputs.Add("fit.png"));                        // with the run's set

#include <string>

#include "textile/sim/plot/chart.h"

namespace textile {
class AtomicFile;
}  // namespace textile

namespace textile::chart {

// Renders the figure to a PNG file at path (extension .png), atomically: on failure no
// file is left and an existing one is untouched. Throws InputError naming the path if it
// cannot be written or the figure fails Check().
void WritePng(const Figure& figure, const std::string& path);
// The same into an output staged in an AtomicFileSet (or an AtomicFile the caller commits):
// the picture goes to out.temp_path(); out.path() must end in .png.
void WritePng(const Figure& figure, AtomicFile& out);

}  // namespace textile::chart

#endif  // TEXTILE_TOOLS_COMMON_CHART_FILE_H_
