// The policy stages of SimulateDrape (libsim/src/scenes/drape_stages.h): the trust checks a drape
// result carries as notes, the figures over its seeds, and the rim a run is given.
#include "scenes/drape_stages.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "textile/sim/scenes/drape.h"
#include "textile/sim/core/error.h"

namespace textile {
namespace {

using drape_internal::DrapeNotes;
using drape_internal::SummariseSeeds;

// The Fig. 8 fabric's turn-down length at the default scene, rounded [m] (drape_test.cc has
// RimTurnDownLength's own test); the notes take it as given.
constexpr double kTurnDown = 0.0086;

std::vector<std::string> Codes(const std::vector<Note>& notes) {
  std::vector<std::string> codes;
  for (const Note& n : notes) codes.push_back(n.code);
  return codes;
}

// A clamped run with the rim extrapolation and nothing to say: one converged seed.
DrapeOptions QuietOptions() {
  DrapeOptions o;
  o.rim_element_size = 0.004;
  o.rim_extrapolation = true;
  return o;
}

DrapeResult QuietResult() {
  DrapeResult r;
  r.rim_turn_down = kTurnDown;
  r.support_area = std::numbers::pi * 0.09 * 0.09;
  DrapeSeedResult seed;
  seed.seed = 1;
  seed.converged = true;
  r.per_seed.push_back(seed);
  return r;
}

TEST(DrapeNotes, QuietRunHasNone) {
  EXPECT_TRUE(DrapeNotes(QuietOptions(), QuietResult(), false).empty());
}

// Every parameter's sensitivity with shifted seams leaves the scene's radii out, and says so;
// a list of parameters leaves them out by design, silently.
TEST(DrapeNotes, SceneRadiiSkippedWithShiftedSeams) {
  DrapeOptions o = QuietOptions();
  o.sensitivity = true;
  o.seams = DrapeSeams::kShifted;
  DrapeResult r = QuietResult();
  r.sensitivities.push_back(ParameterInfluence{});
  EXPECT_FALSE(drape_internal::TakesSceneRadii(o));
  EXPECT_TRUE(HasNote(DrapeNotes(o, r, false), "scene_radii_skipped"));
  o.sensitivity_parameters = {"b1"};
  EXPECT_FALSE(HasNote(DrapeNotes(o, r, false), "scene_radii_skipped"));
  o.sensitivity_parameters.clear();
  o.seams = DrapeSeams::kWeft;  // a diameter: the radial morph keeps it straight
  EXPECT_TRUE(drape_internal::TakesSceneRadii(o));
  EXPECT_FALSE(HasNote(DrapeNotes(o, r, false), "scene_radii_skipped"));
}

TEST(DrapeNotes, CoarseClampedRimWithoutExtrapolationIsAShortfall) {
  DrapeOptions o;  // 12 mm elements at the rim: 0.1 × 12 / 8.6 = 0.14 > 0.02
  const std::vector<Note> notes = DrapeNotes(o, QuietResult(), false);
  ASSERT_EQ(Codes(notes), std::vector<std::string>{"rim_shortfall"});
  EXPECT_EQ(notes[0].text.rfind("DC may be low by up to about 0.1: ", 0), 0u) << notes[0].text;
  // The extrapolated DC has no first-order shortfall, and the resting mount is not judged so.
  o.rim_extrapolation = true;
  EXPECT_FALSE(HasNote(DrapeNotes(o, QuietResult(), false), "rim_shortfall"));
  o.rim_extrapolation = false;
  o.mount = DrapeMount::kResting;
  EXPECT_FALSE(HasNote(DrapeNotes(o, QuietResult(), false), "rim_shortfall"));
  // A rim of ℓ/5 expects 0.02: not over the threshold.
  o.mount = DrapeMount::kClamped;
  o.rim_element_size = kTurnDown / 5.0;
  EXPECT_FALSE(HasNote(DrapeNotes(o, QuietResult(), false), "rim_shortfall"));
}

TEST(DrapeNotes, ShortfallPastAHalfSaysOnlyFarTooLow) {
  DrapeOptions o;
  DrapeResult r = QuietResult();
  r.rim_turn_down = 0.001;  // 0.1 × 12 / 1 = 1.2
  const std::vector<Note> notes = DrapeNotes(o, r, false);
  ASSERT_TRUE(HasNote(notes, "rim_shortfall"));
  EXPECT_EQ(notes[0].text.rfind("DC may be far too low: ", 0), 0u) << notes[0].text;
}

TEST(DrapeNotes, AutoRimCappedOnlyWhenAutoChoseIt) {
  DrapeOptions o = QuietOptions();
  EXPECT_FALSE(HasNote(DrapeNotes(o, QuietResult(), true), "rim_auto_capped"));  // explicit rim
  o.rim_auto = true;
  EXPECT_FALSE(HasNote(DrapeNotes(o, QuietResult(), false), "rim_auto_capped"));
  EXPECT_EQ(Codes(DrapeNotes(o, QuietResult(), true)), std::vector<std::string>{"rim_auto_capped"});
}

TEST(DrapeNotes, BareSupportPastTwoPercent) {
  DrapeResult r = QuietResult();
  r.per_seed[0].shadow.bare_support_area = 0.01 * r.support_area;  // slivers of a coarse rim
  EXPECT_TRUE(DrapeNotes(QuietOptions(), r, false).empty());
  r.per_seed[0].shadow.bare_support_area = 0.05 * r.support_area;
  const std::vector<Note> notes = DrapeNotes(QuietOptions(), r, false);
  ASSERT_EQ(Codes(notes), std::vector<std::string>{"bare_support"});
  EXPECT_EQ(notes[0].text.rfind("the fabric left 5 % of the support's top bare", 0), 0u);
}

TEST(DrapeNotes, SkirtSinkPastThreeTenthsOfAMillimetre) {
  DrapeOptions o = QuietOptions();
  DrapeResult r = QuietResult();
  r.per_seed[0].max_penetration = 2e-4;
  EXPECT_TRUE(DrapeNotes(o, r, false).empty());
  r.per_seed[0].max_penetration = 1e-3;
  EXPECT_EQ(Codes(DrapeNotes(o, r, false)), std::vector<std::string>{"skirt_sink"});
}

TEST(DrapeNotes, ReversedBracketNamesTheSeeds) {
  DrapeResult r = QuietResult();
  r.per_seed[0].extrapolation_reversed = true;
  std::vector<Note> notes = DrapeNotes(QuietOptions(), r, false);
  ASSERT_EQ(Codes(notes), std::vector<std::string>{"reversed_bracket"});
  EXPECT_EQ(notes[0].text.rfind("seed 1: ", 0), 0u) << notes[0].text;
  DrapeSeedResult third = r.per_seed[0];
  third.seed = 3;
  r.per_seed.push_back(third);
  notes = DrapeNotes(QuietOptions(), r, false);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].text.rfind("seeds 1, 3: ", 0), 0u) << notes[0].text;
}

TEST(DrapeNotes, ComeInTheDocumentedOrder) {
  DrapeOptions o;  // coarse clamped rim: a shortfall
  o.rim_auto = true;
  DrapeResult r = QuietResult();
  r.per_seed[0].shadow.bare_support_area = r.support_area;
  r.per_seed[0].max_penetration = 1e-3;
  r.per_seed[0].extrapolation_reversed = true;
  EXPECT_EQ(Codes(DrapeNotes(o, r, true)),
            (std::vector<std::string>{"rim_shortfall", "rim_auto_capped", "bare_support",
                                      "skirt_sink", "reversed_bracket"}));
}

TEST(DrapeSummary, MeansAndSampleSdOverTheSeeds) {
  DrapeResult r;
  for (double dc : {0.6, 0.8}) {
    DrapeSeedResult s;
    s.converged = true;
    s.drape_coefficient = dc;
    s.nodes.angles = std::vector<double>(dc < 0.7 ? 6 : 8, 0.0);
    r.per_seed.push_back(s);
  }
  SummariseSeeds(&r);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.message, "converged");
  constexpr double kTolerance = 1e-12;  // a mean and an sd of two numbers: round-off only
  EXPECT_NEAR(r.drape_coefficient, 0.7, kTolerance);
  EXPECT_NEAR(r.drape_coefficient_sd, 0.1 * std::sqrt(2.0), kTolerance);
  EXPECT_EQ(r.nodes, 7.0);
}

TEST(DrapeSummary, OneFailedSeedLeavesNoFigures) {
  DrapeResult r;
  DrapeSeedResult good, bad;
  good.converged = true;
  good.drape_coefficient = 0.7;
  r.per_seed = {good, bad};
  SummariseSeeds(&r);
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(r.message.empty());
  EXPECT_TRUE(std::isnan(r.drape_coefficient));
  EXPECT_TRUE(std::isnan(r.nodes));
}

Material Fig8() {
  Material m;
  m.areal_density = 0.2;
  m.bending = BendingLaw::FromKes(0.1, 0.0892, -0.0092);
  return m;
}

TEST(ChooseDrapeRim, ExtrapolatesByDefaultWhereItApplies) {
  DrapeOptions o;
  ChooseDrapeRim(Fig8(), true, DrapeExtrapolation::kDefault, &o);
  EXPECT_TRUE(o.rim_extrapolation);
  EXPECT_TRUE(o.rim_auto);
  EXPECT_EQ(o.rim_element_size, AutoRimElementSize(Fig8(), o, true));
  std::string why;
  EXPECT_TRUE(o.Check(&why)) << why;
}

TEST(ChooseDrapeRim, OffOrRestingMeshesTheRimForOneSolve) {
  DrapeOptions off;
  ChooseDrapeRim(Fig8(), true, DrapeExtrapolation::kOff, &off);
  EXPECT_FALSE(off.rim_extrapolation);
  EXPECT_EQ(off.rim_element_size, AutoRimElementSize(Fig8(), off, false));
  DrapeOptions resting;
  resting.mount = DrapeMount::kResting;
  ChooseDrapeRim(Fig8(), true, DrapeExtrapolation::kDefault, &resting);
  EXPECT_FALSE(resting.rim_extrapolation);
  // No rim band (an explicit 0): nothing to extrapolate, and the rim is left as given.
  DrapeOptions plain;
  ChooseDrapeRim(Fig8(), false, DrapeExtrapolation::kDefault, &plain);
  EXPECT_FALSE(plain.rim_extrapolation);
  EXPECT_FALSE(plain.rim_auto);
  EXPECT_EQ(plain.rim_element_size, 0.0);
}

TEST(ChooseDrapeRim, NeedsADensity) {
  Material none = Fig8();
  none.areal_density = 0.0;
  DrapeOptions o;
  EXPECT_THROW(ChooseDrapeRim(none, true, DrapeExtrapolation::kDefault, &o), InputError);
}

}  // namespace
}  // namespace textile

namespace textile {
namespace {

// The start's harmonics from "MIN-MAX"; anything else is refused naming the text, and the
// options are left as they were.
TEST(DrapeStartModes, ParseMinMaxAndRefuseTheRest) {
  DrapeOptions o;
  ParseStartModes("2-12", &o);
  EXPECT_EQ(o.min_harmonic, 2);
  EXPECT_EQ(o.max_harmonic, 12);
  ParseStartModes("5-5", &o);
  EXPECT_EQ(o.min_harmonic, 5);
  EXPECT_EQ(o.max_harmonic, 5);
  for (const char* bad : {"", "3", "-3", "3-", "9-3", "0-8", "3-65", "3-8-9", "a-b", "3 - 8",
                          "99999-99999", "1e1-20"}) {
    DrapeOptions p;
    try {
      ParseStartModes(bad, &p);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(std::string("start_modes: '") + bad + "'", 0), 0u)
          << e.what();
    }
    EXPECT_EQ(p.min_harmonic, DrapeOptions{}.min_harmonic) << bad;
    EXPECT_EQ(p.max_harmonic, DrapeOptions{}.max_harmonic) << bad;
    std::string why;
    EXPECT_TRUE(p.Check(&why)) << why;
  }
}

}  // namespace
}  // namespace textile
