#include "common/chart_file.h"

#include "common/atomic_file.h"

namespace textile::chart {

void WritePng(const Figure& figure, AtomicFile& out) {
  RenderPng(figure, out.temp_path(), out.path());
  out.CheckWritten();
}

void WritePng(const Figure& figure, const std::string& path) {
  CheckPngPath(path);
  AtomicFile out(path);  // checks the folder before any drawing work
  WritePng(figure, out);
  out.Commit();
}

}  // namespace textile::chart
