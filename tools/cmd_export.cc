// textile export: a material file in another tool's format (ARCSim, U3M 1.1, CSV);
// the conversions are textile::ExportMaterial's (libsim/exchange, docs/guide/export.md).

#include <iostream>
#include <optional>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "textile/sim/exchange/material_export.h"
#include "textile/sim/io/json_text.h"

namespace textile::cli {
namespace {

struct ExportArgs {
  std::string material, to, output;
  std::optional<double> thickness_mm;
  bool strict = false;
  bool json = false;
};

void Run(const ExportArgs& a) {
  const ExportFormat format = ParseExportFormat(a.to);
  CheckDistinctOutputs({{"-o", a.output}}, {{"MATERIAL", a.material}});
  const Material m = ReadMaterial(a.material);
  const ExportedMaterial e = ExportMaterial(
      m, format,
      {.thickness_mm = a.thickness_mm, .strict = a.strict, .producer = "textile " TEXTILE_VERSION});
  WriteFileAtomically(a.output, e.text);
  if (a.json) {
    PrintJson({{"material", a.material}, {"format", a.to}, {"output", a.output},
               {"notes", NotesJson(e.notes)}});
    return;
  }
  std::cout << a.to << ": " << a.output << "\n";
  for (const Note& n : e.notes) std::cout << "note: " << n.text << "\n";
}

}  // namespace

void RegisterExport(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* sub = AddSubcommand(
      app, "export", "Write a material for another tool: ARCSim JSON, U3M 1.1 or CSV",
      "textile export samples/expected/pabst-fig8.fitted.json --to u3m -o fig8.u3m");
  sub->add_option("MATERIAL", args->material, "Material JSON file (docs/spec/cli.md format)")
      ->required();
  sub->add_option("--to", args->to, "Format: arcsim, u3m or csv")->required();
  sub->add_option("-o,--output", args->output, "Output file")->required();
  sub->add_option("--thickness-mm", args->thickness_mm,
                  "U3M physics.thickness [mm] (a cantilever does not measure it; default null)");
  sub->add_flag("--strict", args->strict,
                "Fail instead of leaving out a block the material cannot fill (ARCSim's "
                "stretching of an unmeasured membrane)");
  sub->add_flag("--json", args->json, "Print one JSON object instead of text");
  sub->callback([args] { Run(*args); });
}

namespace {
const bool kRegistered = AddCommand(80, RegisterExport);
}  // namespace

}  // namespace textile::cli
