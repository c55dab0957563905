#include "textile/sim/scenes/drape_what_if.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "scratch_dir.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/units.h"
#include "textile/sim/law/material_parameters.h"

namespace textile {
namespace {

namespace fs = std::filesystem;

Material Fig8() { return LawOnlyMaterial(BendingLaw::FromKes(0.1, 0.0892, -0.0092), 0.2); }

DrapeOptions Coarse() {
  DrapeOptions o;
  o.element_size = 0.015;
  o.raster_cell = 0.001;
  o.solver.tolerance = 1e-9;
  return o;
}

// A converged drape of `m` with DC `dc` and ∂DC/∂p = gradient[name] (0 for the others).
DrapeResult FakeDrape(const Material& m, double dc, const std::map<std::string, double>& gradient) {
  DrapeResult r;
  r.converged = true;
  r.drape_coefficient = dc;
  r.nodes = 6;
  for (const std::string& name : MaterialParameterNames(m)) {
    ParameterInfluence s;
    s.parameter = name;
    s.d_q_d_p = gradient.contains(name) ? gradient.at(name) : 0.0;
    r.sensitivities.push_back(s);
  }
  return r;
}

TEST(WhatIfEdits, TakeTheFilesNamesAndUnits) {
  const Material m = Fig8();
  const Material e = ApplyWhatIfEdits(m, "b1=0.11,areal_density_gsm=210,stretch.warp=3000");
  EXPECT_NEAR(e.bending.b1(), units::KesStiffnessToSi(0.11), 1e-15);
  EXPECT_NEAR(e.bending.b2(), m.bending.b2(), 1e-18);
  EXPECT_NEAR(e.areal_density, 0.21, 1e-15);
  EXPECT_NEAR(GetMaterialParameter(e, "stretch.warp").si, 3000.0, 1e-9);
  EXPECT_FALSE(e.IsDefaulted("stretch.warp"));
  const auto refused = [&](const std::string& edits, const std::string& fragment) {
    try {
      ApplyWhatIfEdits(m, edits);
      ADD_FAILURE() << edits << " was taken";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  refused("", "no edits");
  refused("b1", "is not NAME=VALUE");
  refused("b1=", "is not NAME=VALUE");
  refused("b1=0.1,,c1=-0.01", "is not NAME=VALUE");
  refused("b7=1", "'b7' is not a parameter of this material");
  refused("b1=0.11,b1=0.12", "b1 given twice");
  refused("b1=0.1x", "is not a number");
  refused("b1=nan", "is not a number");
  refused("b1=0.05", "outside the material's valid range");  // b1 < b2 with c1 < 0: κ0 < 0
  refused("stretch.compression_ratio=2", "outside the material's valid range");
  refused("b1= 0.11", "is not a number");
  refused("c1=0,b2=0.07", "the law is linear");  // b2 moves nothing once c1 = 0
  refused("b1=0x1p-3", "is not a number");
  // A law's constants move together: either order of a pair that is valid only together.
  const Material both = ApplyWhatIfEdits(m, "b2=0.105,b1=0.108");
  EXPECT_NEAR(both.bending.b1(), units::KesStiffnessToSi(0.108), 1e-15);
  EXPECT_NEAR(both.bending.b2(), units::KesStiffnessToSi(0.105), 1e-15);
  EXPECT_EQ(both.bending.b1(), ApplyWhatIfEdits(m, "b1=0.108,b2=0.105").bending.b1());
}

TEST(WhatIfScene, TheKeyFollowsWhatShapesTheDcOnly) {
  const DrapeOptions o = Coarse();
  DrapeOptions other = o;
  other.sensitivity = true;
  other.monte_carlo_samples = 10;
  other.progress = [](const std::string&) {};
  EXPECT_EQ(DrapeSceneKey(o), DrapeSceneKey(other));
  other.element_size = 0.012;
  EXPECT_NE(DrapeSceneKey(o), DrapeSceneKey(other));
  other = o;
  other.seeds = 2;
  EXPECT_NE(DrapeSceneKey(o), DrapeSceneKey(other));
  other = o;
  other.seams = DrapeSeams::kWeft;
  EXPECT_NE(DrapeSceneKey(o), DrapeSceneKey(other));
}

// One entry: GMLS with the linear basis is the entry's Taylor expansion; the estimate its
// second-order term; beyond the reach or above the error bound, no prediction.
TEST(WhatIfPrediction, OneEntryIsItsTaylorExpansion) {
  const Material m = Fig8();
  const double g_b1 = 2e4, g_rho = -1.5;  // ∂DC/∂b1 [per N·m], ∂DC/∂ρ [per kg/m²]
  const DrapeCacheEntry e = MakeDrapeCacheEntry(
      m, Coarse(), FakeDrape(m, 0.45, {{"b1", g_b1}, {"areal_density_gsm", g_rho}}));
  const Material t = ApplyWhatIfEdits(m, "b1=0.105,areal_density_gsm=196");
  const DrapeWhatIf w = PredictDrape(t, {e}, {});
  ASSERT_TRUE(w.predicted) << w.reason;
  const double db1 = t.bending.b1() - m.bending.b1(), drho = t.areal_density - m.areal_density;
  EXPECT_NEAR(w.drape_coefficient, 0.45 + g_b1 * db1 + g_rho * drho, 1e-12);
  // The largest of the second-order term, half the first-order change, and the jitter 0.002.
  const double second = 0.5 * (std::abs(g_b1 * t.bending.b1()) * std::pow(db1 / t.bending.b1(), 2) +
                               std::abs(g_rho * t.areal_density) * std::pow(drho / t.areal_density, 2));
  const double half_change = 0.5 * std::abs(g_b1 * db1 + g_rho * drho);
  EXPECT_NEAR(w.error_estimate, std::max({second, half_change, 0.002}), 1e-12);
  EXPECT_GT(half_change, 0.002);  // 0.0079: this term decides here
  EXPECT_EQ(w.entries_used, 1);
  // No change: the entry's own DC, exactly.
  const DrapeWhatIf same = PredictDrape(m, {e}, {});
  EXPECT_EQ(same.drape_coefficient, 0.45);
  EXPECT_EQ(same.error_estimate, 0.0);
  EXPECT_NEAR(w.distance, 0.005 / 0.105, 1e-9);  // b1's 4.8 % from the target
  const DrapeWhatIf far = PredictDrape(ApplyWhatIfEdits(m, "b1=0.13"), {e}, {});
  EXPECT_FALSE(far.predicted);
  EXPECT_NE(far.reason.find("beyond the reach"), std::string::npos) << far.reason;
  const DrapeWhatIf strict = PredictDrape(t, {e}, {.reach = 0.1, .max_error = 1e-9});
  EXPECT_FALSE(strict.predicted);
  EXPECT_NE(strict.reason.find("estimated error"), std::string::npos) << strict.reason;
}

// Two entries of one linear DC: GMLS gives it back exactly and their spread is zero; entries
// of another material form (a weft law) do not answer.
TEST(WhatIfPrediction, GmlsBlendsEntriesAndOnlyTheSameMaterialFormAnswers) {
  const Material m = Fig8();
  const double g = 3e4;  // DC = 0.4 + g (b1 − b1_0), exactly linear
  const Material up = ApplyWhatIfEdits(m, "b1=0.108");
  const std::vector<DrapeCacheEntry> cache = {
      MakeDrapeCacheEntry(m, Coarse(), FakeDrape(m, 0.4, {{"b1", g}})),
      MakeDrapeCacheEntry(up, Coarse(),
                          FakeDrape(up, 0.4 + g * (up.bending.b1() - m.bending.b1()), {{"b1", g}}))};
  const Material t = ApplyWhatIfEdits(m, "b1=0.104");
  const DrapeWhatIf w = PredictDrape(t, cache, {});
  ASSERT_TRUE(w.predicted) << w.reason;
  EXPECT_EQ(w.entries_used, 2);
  EXPECT_NEAR(w.drape_coefficient, 0.4 + g * (t.bending.b1() - m.bending.b1()), 1e-12);
  // A curved DC: the entries disagree. The target lies halfway, so the two weigh the same, the
  // fitted slope's terms cancel and GMLS gives the mean of their DCs; the estimate covers
  // each entry's own first-order value.
  std::vector<DrapeCacheEntry> curved = cache;
  curved[1] = MakeDrapeCacheEntry(up, Coarse(), FakeDrape(up, 0.43, {{"b1", 2 * g}}));
  const DrapeWhatIf c = PredictDrape(t, curved, {.reach = 0.1, .max_error = 1.0});
  EXPECT_NEAR(c.drape_coefficient, (0.4 + 0.43) / 2.0, 1e-9);
  const double from0 = 0.4 + g * (t.bending.b1() - m.bending.b1());
  const double from1 = 0.43 + 2 * g * (t.bending.b1() - up.bending.b1());
  EXPECT_GE(c.error_estimate, std::abs(c.drape_coefficient - from0) - 1e-12);
  EXPECT_GE(c.error_estimate, std::abs(c.drape_coefficient - from1) - 1e-12);
  Material weft = t;
  weft.bending_weft = BendingLaw::FromKes(0.05, 0.045, -0.005);
  const DrapeWhatIf other = PredictDrape(weft, cache, {});
  EXPECT_FALSE(other.predicted);
  EXPECT_EQ(other.entries_matching, 0);
  // ... nor the other way round: a cached weft law does not answer for a material without one.
  const DrapeWhatIf back = PredictDrape(
      t, {MakeDrapeCacheEntry(weft, Coarse(), FakeDrape(weft, 0.4, {{"b1", g}}))}, {});
  EXPECT_EQ(back.entries_matching, 0);
  // An entry with other parameters (a linear law, c1 = 0: no b2) does not answer for a law that
  // has them, and no parameter is taken for another.
  Material linear = m;
  linear.bending = BendingLaw::FromKes(0.1, 0.0892, 0.0);
  std::vector<DrapeCacheEntry> mixed = cache;
  mixed.push_back(MakeDrapeCacheEntry(linear, Coarse(), FakeDrape(linear, 0.9, {{"c1", 1e9}})));
  const DrapeWhatIf w2 = PredictDrape(t, mixed, {});
  EXPECT_EQ(w2.entries_matching, 2);
  EXPECT_EQ(w2.drape_coefficient, w.drape_coefficient);
}

TEST(WhatIfCache, EntriesRoundTripAndOtherScenesAreLeftOut) {
  const fs::path dir = ScratchDir("what_if_round_trip") / "cache";
  const Material m = Fig8();
  EXPECT_TRUE(ReadDrapeCache(dir.string(), Coarse()).empty());  // no folder yet: no entries
  WriteDrapeCacheEntry(dir.string(),
                       MakeDrapeCacheEntry(m, Coarse(), FakeDrape(m, 0.45, {{"b1", 2e4}})));
  DrapeOptions finer = Coarse();
  finer.element_size = 0.01;
  WriteDrapeCacheEntry(dir.string(), MakeDrapeCacheEntry(m, finer, FakeDrape(m, 0.47, {})));
  const std::vector<DrapeCacheEntry> read = ReadDrapeCache(dir.string(), Coarse());
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].drape_coefficient, 0.45);
  const DrapeWhatIf w = PredictDrape(ApplyWhatIfEdits(m, "b1=0.102"), read, {});
  EXPECT_TRUE(w.predicted) << w.reason;
  // A broken file and another version are left out, each with its reason.
  std::ofstream(dir / "junk.drape-cache.json") << "{\"textile_drape_cache\": 2}";
  std::ofstream(dir / "future.drape-cache.json") << "{\"textile_drape_cache\": 3}";
  std::vector<std::string> skipped;
  EXPECT_EQ(ReadDrapeCache(dir.string(), Coarse(), &skipped).size(), 1u);
  ASSERT_EQ(skipped.size(), 2u);
  EXPECT_NE(skipped[0].find("version 3"), std::string::npos) << skipped[0];  // future: sorted first
  EXPECT_NE(skipped[1].find("not a drape cache entry"), std::string::npos) << skipped[1];
  std::ofstream(dir.parent_path() / "plain-file") << "x";
  EXPECT_THROW(ReadDrapeCache((dir.parent_path() / "plain-file").string(), Coarse()), InputError);
  // A drape without sensitivities cannot be cached.
  DrapeResult bare = FakeDrape(m, 0.45, {});
  bare.sensitivities.clear();
  EXPECT_THROW(MakeDrapeCacheEntry(m, Coarse(), bare), InputError);
}

// The whole way: a drape solved into the cache, a 1 % edit predicted from it, against the
// edited drape solved (the same seed: the same folds). The 15 mm test mesh's raster DC
// jitters by about 0.003 between neighbouring solves (1 mm cells), so the bound is 0.004;
// the derivatives themselves are tested to 2 % in drape_sensitivity_test.cc.
TEST(WhatIfCache, APredictionFollowsTheSolvedDrape) {
  const fs::path dir = ScratchDir("what_if_solved") / "cache";
  const Material m = Fig8();
  const DrapeResult base = SimulateDrapeCached(m, Coarse(), dir.string());
  ASSERT_TRUE(base.converged) << base.message;
  // The cache needs the material's derivatives only: without sensitivity asked for, no radii.
  EXPECT_EQ(base.sensitivities.size(), MaterialParameterNames(m).size());
  EXPECT_TRUE(base.scene_sensitivities.empty());
  EXPECT_EQ(base.scene_sensitivity_seconds, 0.0);
  const DrapeWhatIfPrediction p =
      PredictDrapeWhatIf(m, "b1=0.101,areal_density_gsm=199", Coarse(), dir.string(), {});
  ASSERT_TRUE(p.what_if.predicted) << p.what_if.reason;
  const DrapeResult solved = SimulateDrape(p.material, Coarse());
  ASSERT_TRUE(solved.converged);
  EXPECT_NEAR(p.what_if.drape_coefficient, solved.drape_coefficient, 0.004);
  // The predicted material's membrane defaults are noted; a file that is no entry is too.
  EXPECT_TRUE(HasNote(p.what_if.notes, "membrane_default"));
  std::ofstream(dir / "old.drape-cache.json") << "{\"textile_drape_cache\": 1}";
  const DrapeWhatIfPrediction q = PredictDrapeWhatIf(m, "b1=0.101", Coarse(), dir.string(), {});
  EXPECT_TRUE(q.what_if.predicted);
  EXPECT_TRUE(HasNote(q.what_if.notes, "cache_entry_skipped"));
  DrapeOptions partial = Coarse();
  partial.sensitivity_parameters = {"b1"};
  EXPECT_THROW(SimulateDrapeCached(m, partial, dir.string()), InputError);
  DrapeOptions resting = Coarse();  // no sensitivities on the resting mount
  resting.mount = DrapeMount::kResting;
  try {
    SimulateDrapeCached(m, resting, dir.string());
    FAIL() << "cached a drape on the resting mount";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--cache: clamped mount only", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace textile
