// textile synth-profile: synthetic cantilever profiles of a known material (elastica + seeded
// noise + resampling), for trying the fits and for the samples.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "textile/fit/synthetic_profile.h"
#include "textile/sim/core/error.h"
#include "textile/sim/law/material.h"
#include "textile/sim/core/units.h"

namespace textile::cli {
namespace {

struct SynthArgs {
  std::string material, out_dir;
  std::vector<double> overhang_mm;
  double noise_mm = 0.0, offset_mm = 0.0, rotation_deg = 0.0;
  int points = 100;
  int64_t seed = 1;
  bool exact_arc_length = false, json = false;
};

void Run(const SynthArgs& a) {
  const Material m = ReadMaterial(a.material);
  SyntheticOptions o;
  o.num_points = a.points;
  o.noise_sigma = units::MmToM(a.noise_mm);
  o.vertical_offset = units::MmToM(a.offset_mm);
  o.rotation = a.rotation_deg * M_PI / 180.0;
  o.chord_arc_length = !a.exact_arc_length;
  std::string why;
  if (!std::isfinite(a.noise_mm) || a.noise_mm < 0.0 || a.noise_mm > 5.0)
    throw InputError("--noise-mm must lie in [0, 5] mm");
  if (!std::isfinite(a.offset_mm) || std::abs(a.offset_mm) > 5.0)
    throw InputError("--offset-mm must lie in [-5, 5] mm");
  if (a.points < kMinProfilePoints || a.points > 100000)
    throw InputError("--points must lie in [" + std::to_string(kMinProfilePoints) + ", 100000], got " +
                     std::to_string(a.points));
  if (!std::isfinite(a.rotation_deg) || std::abs(a.rotation_deg) > 10.0)
    throw InputError("--rotation-deg must lie in [-10, 10] degrees, got " + Num(a.rotation_deg));
  if (a.seed < 0) throw InputError("--seed must be >= 0");
  if (!o.Check(&why)) throw InputError("synth-profile: " + why);
  // File names carry the overhang to 0.1 mm; two overhangs that share a name are refused.
  std::vector<std::string> names;
  for (double L : a.overhang_mm) {
    // Below 1 mm the points crowd the CSV's 1 nm digits (0.0001 mm wrote 899 repeated arc
    // lengths that fit then refused) and every name reads L000mm.
    if (!std::isfinite(L) || L < 1.0 || L > 1000.0) {
      throw InputError("--overhang-mm: " + Num(L) + " is not a length in [1, 1000] mm");
    }
    char name[64];
    if (std::abs(L - std::round(L)) < 0.05) std::snprintf(name, sizeof name, "_L%03.0fmm.profile.csv", L);
    else std::snprintf(name, sizeof name, "_L%05.1fmm.profile.csv", L);
    if (std::find(names.begin(), names.end(), name) != names.end()) {
      throw InputError("--overhang-mm: " + Num(L) + " mm repeats an overhang (same file " +
                       std::string(name + 1) + ")");
    }
    names.push_back(name);
  }
  const OutputFolder folder(a.out_dir);  // made when the files are committed
  const std::string stem = std::filesystem::path(a.material).stem().string();
  nlohmann::json files = nlohmann::json::array();
  // All or nothing: the profiles and the report wait until the last one is made.
  AtomicFileSet outputs;
  std::ostringstream report;
  int k = 0;
  for (double L : a.overhang_mm) {
    o.seed = static_cast<uint64_t>(a.seed) + static_cast<uint64_t>(k);  // independent noise per profile
    const Profile p = SyntheticProfile(m.EffectiveLaw(), m.areal_density, units::MmToM(L), o);
    const std::string path = (std::filesystem::path(a.out_dir) / (stem + names[k++])).string();
    outputs.Add(path, folder.stage_dir()).Write("# " + p.source + "\n" + ProfileToCsv(p));
    files.push_back({{"path", path}, {"overhang_mm", L}, {"points", p.size()}});
    report << path << "  (" << Num(L) << " mm overhang, " << p.size() << " points)\n";
  }
  outputs.Commit();
  if (!a.json) std::cout << report.str();
  if (a.json) {
    PrintJson({{"material", a.material}, {"noise_mm", a.noise_mm}, {"offset_mm", a.offset_mm},
               {"seed", a.seed}, {"profiles", files}});
  }
}

}  // namespace

void RegisterSynth(CLI::App& app) {
  auto a = std::make_shared<SynthArgs>();
  CLI::App* sub = AddSubcommand(
      app, "synth-profile",
      "Synthetic cantilever profiles of a known material: exact elastica, seeded noise, resampling",
      "textile synth-profile --material samples/materials/pabst-fig8.json --overhang-mm 40 60 80 "
      "--noise-mm 0.1 -o out/profiles");
  sub->add_option("-m,--material", a->material, "Material JSON file")->required();
  sub->add_option("-L,--overhang-mm", a->overhang_mm, "Overhang lengths [mm], one profile each")
      ->required();
  sub->add_option("-o,--out", a->out_dir, "Output folder for <material>_L<mm>mm.profile.csv")->required();
  sub->add_option("--noise-mm", a->noise_mm, "Gaussian noise on x and y [mm] (default 0)");
  sub->add_option("--offset-mm", a->offset_mm, "Mid-line height at the edge, t/2 [mm] (default 0)");
  sub->add_option("--rotation-deg", a->rotation_deg, "Rig rotation [deg] (default 0)");
  sub->add_option("--points", a->points, "Points per profile (default 100)");
  sub->add_option("--seed", a->seed, "Random seed (default 1; profile i uses seed + i)");
  sub->add_flag("--exact-arc-length", a->exact_arc_length,
                "Keep the exact arc lengths (default: recompute s from the noisy points, as an "
                "extractor does)");
  sub->add_flag("--json", a->json, "Print one JSON object instead of text");
  sub->callback([a] { Run(*a); });
}

namespace {
const bool kRegistered = AddCommand(20, RegisterSynth);
}  // namespace

}  // namespace textile::cli
