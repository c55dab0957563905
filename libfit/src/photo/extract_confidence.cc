// The confidence report of an extracted profile and the refusal of guesses
// (docs/methods/extraction.md, "Confidence"): an exit-0 profile is within 1 mm RMS of the strip,
// or the run says why it may not be.

#include <algorithm>
#include <string>
#include <vector>

#include "extract_internal.h"
#include "textile/photo/extract.h"
#include "textile/sim/core/number_text.h"

namespace textile::extract_internal {
namespace {

std::string HeldEnd(const ExtractState& s) {
  if (s.options.edge_px) return "given";
  return HasNote(s.summary.warnings, "held_end_guessed") ? "guessed" : "found";
}

double SectionsMeasured(const ExtractState& s) {
  const int n = s.last - s.first + 1;
  if (n <= 0) return 0.0;
  return std::clamp(1.0 - static_cast<double>(s.summary.rejected_sections) / n, 0.0, 1.0);
}

// The guesses of a report, each with what settles it.
std::vector<std::string> Guesses(const ExtractionConfidence& c, const Eigen::Vector2d& tip_px) {
  std::vector<std::string> guesses;
  if (c.held_end == "guessed")
    guesses.push_back(
        "the held end was guessed (no platform, clamp or image border holds the strip in view; "
        "--edge-px X,Y at the edge or --rig-type settles it)");
  if (c.tip == "inferred")
    guesses.push_back(
        "the tip was inferred (the strip's contrast does not fall off at its end: the last "
        "measured section was taken, at " +
        NumberText(tip_px.x(), 5) + "," + NumberText(tip_px.y(), 5) +
        " px; check the overlay, and --tip-px X,Y at the tip's end settles it)");
  if (c.shape && !c.shape->plausible)
    guesses.push_back(c.shape->message + " (--edge-px or --rig-type settles a wrong held end)");
  return guesses;
}

}  // namespace

ExtractionConfidence AssessConfidence(const ExtractState& s) {
  ExtractionConfidence c;
  c.held_end = HeldEnd(s);
  c.held_end_how = s.summary.rig_detail;
  c.tip = s.options.tip_px ? "given"
          : HasNote(s.summary.warnings, "tip_end_unclear") ? "inferred"
                                                            : "found";
  c.sections_measured = SectionsMeasured(s);
  if (s.options.check_shape) c.shape = CheckCantileverShape(s.summary.profile);
  c.guesses = Guesses(c, s.summary.tip_px);
  return c;
}

StageFailure RefuseGuesses(const ExtractionConfidence& confidence, const ExtractOptions& options,
                           std::vector<Note>* warnings) {
  if (confidence.guesses.empty()) return std::nullopt;
  if (options.accept_guesses) {
    for (const std::string& g : confidence.guesses)
      warnings->push_back({"guess_accepted", g + "; taken (--accept-guesses)"});
    return std::nullopt;
  }
  std::string why = "had to guess: ";
  for (size_t k = 0; k < confidence.guesses.size(); ++k)
    why += (k ? "; " : "") + confidence.guesses[k];
  return why + " (--accept-guesses takes the guesses)";
}

}  // namespace textile::extract_internal
