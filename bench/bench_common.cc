#include <unistd.h>

#include <algorithm>
#include <utility>
#include <chrono>
#include <cmath>
#include <ctime>
#include <fstream>
#include <sstream>
#include <thread>

#include "bench/bench.h"
#include "common/atomic_file.h"
#include "common/blas_kernels.h"

namespace textile::bench {

namespace {
std::vector<std::pair<int, Benchmark (*)()>>& Makers() {
  static std::vector<std::pair<int, Benchmark (*)()>> makers;
  return makers;
}
}  // namespace

bool AddBenchmark(int order, Benchmark (*make)()) {
  Makers().emplace_back(order, make);
  return true;
}

const std::vector<Benchmark>& Registry() {
  static const std::vector<Benchmark> all = [] {
    auto makers = Makers();
    std::stable_sort(makers.begin(), makers.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<Benchmark> list;
    for (const auto& entry : makers) list.push_back(entry.second());
    return list;
  }();
  return all;
}

void WriteCsv(const std::string& path, const Result& result) {
  std::ostringstream out;
  for (size_t i = 0; i < result.columns.size(); ++i) out << (i ? "," : "") << result.columns[i];
  out << "\n";
  for (const auto& row : result.rows) {
    for (size_t i = 0; i < result.columns.size(); ++i) {
      if (i) out << ",";
      const auto it = row.find(result.columns[i]);
      if (it == row.end() || it->is_null()) continue;
      if (it->is_string()) {
        out << '"' << it->get<std::string>() << '"';
      } else if (it->is_number_float()) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.6g", it->get<double>());
        out << buf;
      } else {
        out << it->dump();
      }
    }
    out << "\n";
  }
  WriteFileAtomically(path, out.str());
}

nlohmann::json MachineInfo() {
  std::string cpu = "unknown";
  std::ifstream info("/proc/cpuinfo");
  for (std::string line; std::getline(info, line);) {
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  }
#ifdef NDEBUG
  const char* build = "Release (-O2, asserts off)";
#else
  const char* build = "Debug (asserts on)";
#endif
  return {{"cpu", cpu},
          {"hardware_threads", std::thread::hardware_concurrency()},
          {"threads_used", 1},
          {"blas_kernels", cli::BlasKernels()},
          {"build", build}};
}

double Median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double ThreadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double MedianSeconds(const std::function<void()>& f, int repeats) {
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return Median(t);
}

}  // namespace textile::bench
