// textile-bench (and `textile bench`, which runs it): the named benchmarks of
// docs/spec/benchmarks.md (CSV + PNG per benchmark, a table, or with --json one object per
// benchmark {"benchmark": NAME, "rows": [...]}).

#include <iostream>

#include "bench/bench.h"
#include "common/atomic_file.h"
#include "common/cli.h"
#include "textile/sim/core/error.h"

namespace textile::cli {
namespace {

struct BenchArgs {
  std::vector<std::string> names;
  std::string out = "out/bench";
  bool quick = false, json = false, list = false, progress = false;
};

void Run(const BenchArgs& a) {
  const auto& all = bench::Registry();
  if (a.list) {
    for (const auto& b : all) std::cout << b.name << "\t" << b.description << "\n";
    return;
  }
  std::vector<const bench::Benchmark*> chosen;
  for (const auto& n : a.names) {
    const bench::Benchmark* found = nullptr;
    for (const auto& b : all) if (b.name == n) found = &b;
    if (!found) {
      std::string known;
      for (const auto& b : all) known += (known.empty() ? "" : ", ") + b.name;
      throw InputError("bench: unknown benchmark '" + n + "' (known: " + known + ")");
    }
    chosen.push_back(found);
  }
  if (chosen.empty()) for (const auto& b : all) chosen.push_back(&b);
  EnsureDirectory(a.out);
  const nlohmann::json machine = bench::MachineInfo();
  for (const auto* b : chosen) {
    bench::Context ctx{
        .out_dir = a.out, .quick = a.quick, .print = !a.json, .progress = ShowProgress(a.progress)};
    Progress("bench: running " + b->name + (a.quick ? " (quick)" : ""), a.progress);
    const bench::Result r = b->run(ctx);
    bench::WriteCsv(a.out + "/" + b->name + ".csv", r);
    if (a.json) {
      PrintJson({{"benchmark", b->name}, {"quick", a.quick}, {"machine", machine},
                 {"rows", r.rows}, {"summary", r.summary}});
    } else {
      std::cout << "== " << b->name << (a.quick ? " (quick)" : "") << ": " << b->description << "\n"
                << r.summary << "csv: " << a.out << "/" << b->name << ".csv, png: " << a.out << "/"
                << b->name << ".png\n\n";
    }
  }
  if (!a.json) {
    std::cout << "machine: " << machine["cpu"].get<std::string>() << ", "
              << machine["hardware_threads"] << " hardware threads, 1 used, "
              << machine["build"].get<std::string>() << ", BLAS: "
              << machine["blas_kernels"].get<std::string>() << "\n";
  }
}

}  // namespace

void RegisterBench(CLI::App& app) {
  auto a = std::make_shared<BenchArgs>();
  CLI::App* sub = AddSubcommand(app, "bench", "Run the named benchmarks (all by default): CSV + PNG each",
                                "textile bench fit-accuracy --quick -o out/bench");
  sub->add_option("names", a->names, "Benchmarks to run (see --list)");
  sub->add_option("-o,--out", a->out, "Output folder (default out/bench)");
  sub->add_flag("--quick", a->quick, "CI-sized run (minutes become seconds)");
  sub->add_flag("--list", a->list, "List the benchmarks and exit");
  sub->add_flag("--json", a->json, "One JSON object per benchmark on stdout");
  sub->add_flag("--progress", a->progress,
                "Print a progress line per case on stderr even when it is not a terminal");
  sub->callback([a] { Run(*a); });
}

namespace {
const bool kRegistered = AddCommand(90, RegisterBench);
}  // namespace

}  // namespace textile::cli
