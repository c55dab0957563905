#ifndef TEXTILE_BENCH_BENCH_H_
#define TEXTILE_BENCH_BENCH_H_

// The benchmarks of docs/spec/benchmarks.md behind `textile bench NAME`. Each one runs its
// study, returns rows (one JSON object per CSV row, columns as docs/spec/benchmarks.md names them,
// more welcome), writes a PNG to the output folder and prints a short table on stdout (unless
// --json). Timings are medians of repeats measured in the same run; never used by tests.

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace textile::bench {

struct Context {
  std::string out_dir;  // CSV + PNG go here
  bool quick = false;   // CI-sized run
  bool print = true;    // human-readable table on stdout
  bool progress = false;  // a line on stderr per case (a terminal, or bench --progress)
};

struct Result {
  std::vector<std::string> columns;  // CSV column order
  std::vector<nlohmann::json> rows;
  std::string summary;  // a few lines for people (also stored in the JSON)
};

struct Benchmark {
  std::string name;
  std::string description;
  std::function<Result(const Context&)> run;
};

// Benchmarks register themselves, one file each (bench/<name>.cc), with a namespace-scope
//   const bool kRegistered = AddBenchmark(40, FitAccuracyBenchmark);
// `order` follows docs/spec/benchmarks.md: bend-force 10, hinge-curve 15, stability 20,
// acpm-accuracy 30, fit-accuracy 40, elastica 45, extract-accuracy 50, drape-convergence 60,
// drape-measure-mesh 62, drape-sensitivity 64, drape-measure-photo 65, what-if 66, stress 70.
bool AddBenchmark(int order, Benchmark (*make)());
// All registered benchmarks, in order.
const std::vector<Benchmark>& Registry();

// Writes rows as CSV (columns in order; strings quoted if needed) atomically.
void WriteCsv(const std::string& path, const Result& result);
// Machine, build and thread facts recorded with every result.
nlohmann::json MachineInfo();
// Median of a sample (copy); NaN for an empty one.
double Median(std::vector<double> v);
// Seconds of wall time for one call of f, as the median of `repeats` calls.
double MedianSeconds(const std::function<void()>& f, int repeats);
// CPU time of the calling thread [s] (POSIX CLOCK_THREAD_CPUTIME_ID).
double ThreadCpuSeconds();

}  // namespace textile::bench

#endif  // TEXTILE_BENCH_BENCH_H_
