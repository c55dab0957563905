#include <algorithm>
#include <cstdio>
#include <string>

#include "drape_stages.h"
#include "textile/sim/core/number_text.h"
#include "textile/sim/core/units.h"

namespace textile::drape_internal {

std::optional<Note> RimShortfallNote(const DrapeOptions& o, const DrapeResult& r) {
  // DC converges from below as the rim's element e shrinks, by about 0.1 e/ℓ at e = ℓ/3 for a
  // plain fabric (docs/methods/drapemeter.md, "Resolution at the rim"; less with seams and near
  // DC = 1, hence "up to"). An extrapolated DC has no first-order shortfall: no note.
  const double rim_size = o.rim_element_size > 0.0 ? o.rim_element_size : o.element_size;
  const double shortfall = 0.1 * rim_size / r.rim_turn_down;
  if (!(shortfall > 0.02) || o.rim_extrapolation || o.mount != DrapeMount::kClamped)
    return std::nullopt;
  // The estimate is first order in rim / turn-down; past about 0.5 it says only "a lot" (a
  // limp, heavy fabric printed 4e+03 for a DC that cannot exceed 1).
  return Note{"rim_shortfall",
              (shortfall > 0.5 ? std::string("DC may be far too low")
                               : "DC may be low by up to about " + NumberText(shortfall, 1)) +
                  ": the rim's elements (" + NumberText(units::MToMm(rim_size), 3) +
                  " mm) are coarse against this fabric's turn-down length there (" +
                  NumberText(units::MToMm(r.rim_turn_down), 2) + " mm); " +
                  (o.rim_element_size > 0.0 ? std::string("a smaller --rim-mm")
                                            : std::string("--rim-mm auto")) +
                  " meshes it finer (slower; docs/methods/drapemeter.md)"};
}

std::optional<Note> RimAutoCappedNote(const DrapeOptions& o, const DrapeResult& r,
                                      bool rim_capped) {
  // Decision (docs/methods/drapemeter.md): auto stays fast and says so; an explicit --rim-mm meshes
  // as finely as asked.
  if (!o.rim_auto || !rim_capped) return std::nullopt;
  const double wanted = std::max(r.rim_turn_down / (o.rim_extrapolation ? 2.0 : 3.0), 5e-4);
  return Note{"rim_auto_capped", "--rim-mm auto: the rim's elements (" +
                                     NumberText(units::MToMm(o.rim_element_size), 3) +
                                     " mm) are capped to keep the rim band under about " +
                                     NumberText(kAutoRimMaxVertices) +
                                     " vertices; this fabric's turn-down length (" +
                                     NumberText(units::MToMm(r.rim_turn_down), 2) +
                                     " mm) asks for " + NumberText(units::MToMm(wanted), 3) +
                                     " mm: give that as --rim-mm for the finer mesh (far slower)"};
}

std::optional<Note> BareSupportNote(const DrapeResult& r) {
  // A resting fabric that left part of the disk's top bare slid off it or, with contact on the
  // nodes only, passed through it (docs/methods/drapemeter.md, "Fabric through the support"): the
  // support's own shadow keeps the DC ≥ 0, but the drape needs a look.
  double bare = 0.0;
  for (const DrapeSeedResult& seed : r.per_seed)
    bare = std::max(bare, seed.shadow.bare_support_area);
  if (!(bare > 0.02 * r.support_area)) return std::nullopt;  // a coarse rim leaves up to ~1 %
  char percent[32];
  std::snprintf(percent, sizeof percent, "%.0f", 100.0 * bare / r.support_area);
  return Note{"bare_support",
              std::string("the fabric left ") + percent +
                  " % of the support's top bare: it slid off the disk or, as contact holds the "
                  "nodes only, passed through it (a coarse mesh); look at the mesh (--obj) before "
                  "trusting this DC"};
}

std::optional<Note> SkirtSinkNote(const DrapeOptions& o, const DrapeResult& r) {
  // The resting contact's penalty lets the skirt sink into the disk's side under the rim's load.
  // Past 0.3 mm (0.25 mm cost the Fig. 8 fabric's DC about 0.006, 1 mm about 0.03 on the default
  // mesh; docs/methods/drapemeter.md, "Contact stiffness") the run says so; which way the DC moves with a
  // stiffer contact is the mesh's affair (on a 12 mm mesh it went up, then down).
  double sink = 0.0;
  for (const DrapeSeedResult& seed : r.per_seed) sink = std::max(sink, seed.max_penetration);
  if (!(sink > 3e-4)) return std::nullopt;
  return Note{"skirt_sink", "the skirt sank up to " + NumberText(units::MToMm(sink), 2) +
                                " mm into the support under the rim's load (--contact-sink-mm " +
                                NumberText(units::MToMm(o.contact_sink)) +
                                "); on the default mesh 1 mm cost the Fig. 8 fabric's DC about "
                                "0.03 (docs/methods/drapemeter.md, \"Contact stiffness\")"};
}

std::optional<Note> ReversedBracketNote(const DrapeResult& r) {
  // The extrapolation assumes the DC converges from below as the rim is refined; a split rim
  // with a lower DC than the base's reverses the bracket (docs/methods/drapemeter.md, "Extrapolated DC").
  std::string reversed;
  for (const DrapeSeedResult& seed : r.per_seed)
    if (seed.extrapolation_reversed)
      reversed += (reversed.empty() ? "" : ", ") + std::to_string(seed.seed);
  if (reversed.empty()) return std::nullopt;
  return Note{"reversed_bracket",
              "seed" + std::string(reversed.find(',') == std::string::npos ? " " : "s ") +
                  reversed +
                  ": the split rim's DC is below the base's (a reversed bracket): the DC did not "
                  "converge from below as the extrapolation assumes; a finer --rim-mm or "
                  "--resolution-mm should agree before this DC is trusted"};
}

std::optional<Note> SceneRadiiSkippedNote(const DrapeOptions& o, const DrapeResult& r) {
  if (!o.sensitivity || !o.sensitivity_parameters.empty() || o.seams != DrapeSeams::kShifted ||
      r.sensitivities.empty())
    return std::nullopt;
  return Note{"scene_radii_skipped",
              "no sensitivities in the scene's radii with shifted seams: the radial morph they "
              "are taken through would bend the seams (docs/methods/sensitivity.md, \"Scene "
              "radii\")"};
}

std::vector<Note> DrapeNotes(const DrapeOptions& o, const DrapeResult& r, bool rim_capped) {
  std::vector<Note> notes;
  for (std::optional<Note> note : {RimShortfallNote(o, r), RimAutoCappedNote(o, r, rim_capped),
                                   BareSupportNote(r), SkirtSinkNote(o, r), ReversedBracketNote(r),
                                   SceneRadiiSkippedNote(o, r)})
    if (note) notes.push_back(std::move(*note));
  return notes;
}

}  // namespace textile::drape_internal
