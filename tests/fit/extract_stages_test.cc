// The stages of ExtractProfile (libfit/src/photo/extract_internal.h), one by one on synthetic photos
// with a known truth (tests/fit/synthetic_photo.h): what each stage adds to the state, and the
// failure or warning it owns. ExtractProfile itself is tested whole in extract_test.cc.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "photo/extract_internal.h"
#include "synthetic_photo.h"
#include "textile/photo/extract.h"
#include "textile/photo/rig.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/note.h"

namespace textile {
namespace {

using extract_internal::ExtractState;
using extract_internal::StageFailure;
using testing::PhotoScene;
using testing::SyntheticPhoto;

constexpr double kScale = 0.1;  // [mm/px] of the synthetic photos
// Tolerances of the whole extraction (extract_test.cc), which the stages that place things must
// meet on their own: origin and tip [px], traced line's worst point [px].
constexpr double kOriginPx = 0.5;
constexpr double kTipPx = 1.5;
constexpr double kLineMaxPx = 1.0;

using testing::BorderScene;

PhotoScene PlatformScene() {
  PhotoScene s;
  s.holder = PhotoScene::Holder::kPlatform;
  s.root_x = 500.0;
  s.root_y = 300.0;
  return s;
}

// The stages in ExtractProfile's order, each stopping the run on failure.
const std::vector<std::pair<std::string, std::function<StageFailure(ExtractState*)>>>& Stages() {
  using namespace extract_internal;
  static const std::vector<std::pair<std::string, std::function<StageFailure(ExtractState*)>>>
      stages = {
          {"ReduceImages", [](ExtractState* s) { return ReduceImages(s), StageFailure(); }},
          {"FindStrip", FindStrip},
          {"FindStripBlocks", [](ExtractState* s) { return FindStripBlocks(s), StageFailure(); }},
          {"FindHeldEnd", FindHeldEnd},
          {"TraceCoarseLine", TraceCoarseLine},
          {"FindRig", FindRig},
          {"MeasureSections", MeasureSections},
          {"TraceMeasuredLine",
           [](ExtractState* s) { return TraceMeasuredLine(s), StageFailure(); }},
          {"FindTipEnd", FindTipEnd},
          {"CheckEdgeGiven",
           [](ExtractState* s) {
             return CheckEdgeGiven(*s, &s->summary.warnings), StageFailure();
           }},
          {"PlaceOrigin", PlaceOrigin},
          {"MapToMillimetres", MapToMillimetres},
          {"AssembleProfile", [](ExtractState* s) { return AssembleProfile(s), StageFailure(); }},
          {"DiagnoseSilhouette",
           [](ExtractState* s) { return DiagnoseSilhouette(s), StageFailure(); }},
          {"CheckResult", [](ExtractState* s) { return CheckResult(*s); }},
      };
  return stages;
}

// A state for one photo, with the options and rig it refers to kept alive beside it.
struct StagedRun {
  explicit StagedRun(const cv::Mat& photo, ExtractOptions opts = {})
      : gray(photo), options(std::move(opts)), state(gray, rig, options, "synthetic.png") {}
  // Runs the stages up to and including `last`; the failure of the first that fails.
  StageFailure Through(const std::string& last) {
    for (const auto& [name, stage] : Stages()) {
      if (done.count(name)) continue;
      done.insert(name);
      if (StageFailure why = stage(&state)) return why;
      if (name == last) return std::nullopt;
    }
    ADD_FAILURE() << "no stage " << last;
    return std::nullopt;
  }
  cv::Mat gray;
  Rig rig = Rig::FromScale(kScale);
  ExtractOptions options;
  ExtractState state;
  std::set<std::string> done;
};

TEST(ExtractStages, CheckExtractInputsRefusesWhatItCannotMeasure) {
  const Rig rig = Rig::FromScale(kScale);
  const cv::Mat colour(100, 100, CV_8UC3, cv::Scalar(0, 0, 0));
  EXPECT_THROW(extract_internal::CheckExtractInputs(colour, rig, {}, "a.png"), InputError);
  const cv::Mat grey(100, 120, CV_8UC1, cv::Scalar(128));
  EXPECT_NO_THROW(extract_internal::CheckExtractInputs(grey, rig, {}, "a.png"));
  ExtractOptions outside;
  outside.edge_px = Eigen::Vector2d(130.0, 50.0);
  try {
    extract_internal::CheckExtractInputs(grey, rig, outside, "a.png");
    ADD_FAILURE() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lies outside a.png (120x100 px)"), std::string::npos)
        << e.what();
  }
}

TEST(ExtractStages, ReduceImagesBoundsTheDetectionImageAndAddsAMidLevelForLargePhotos) {
  const cv::Mat large(300, 4100, CV_8UC1, cv::Scalar(100));
  StagedRun run(large);
  extract_internal::ReduceImages(&run.state);
  EXPECT_EQ(run.state.mid_factor, 2);
  EXPECT_EQ(run.state.mid.cols, 2050);
  EXPECT_EQ(run.state.small.cols, 1000);  // ExtractOptions::detect_side_px
  EXPECT_NEAR(run.state.scale, 1000.0 / 4100.0, 1e-12);
  const cv::Mat modest(300, 800, CV_8UC1, cv::Scalar(100));
  StagedRun small(modest);
  extract_internal::ReduceImages(&small.state);
  EXPECT_EQ(small.state.mid_factor, 1);
  EXPECT_TRUE(small.state.mid.empty());
  EXPECT_EQ(small.state.small.cols, 800);  // not enlarged
}

TEST(ExtractStages, FindStripTakesTheStripOfEitherPolarityOrFailsOnABlankPhoto) {
  StagedRun dark(testing::Render(BorderScene()).gray);
  ASSERT_FALSE(dark.Through("FindStrip"));
  EXPECT_EQ(dark.state.strip.polarity, -1);
  EXPECT_TRUE(dark.state.summary.warnings.empty());
  PhotoScene light_scene = BorderScene();
  light_scene.strip = 0.85;
  light_scene.background = 0.2;
  StagedRun light(testing::Render(light_scene).gray);
  ASSERT_FALSE(light.Through("FindStrip"));
  EXPECT_EQ(light.state.strip.polarity, +1);
  PhotoScene blank = BorderScene();
  blank.strip = blank.background;
  StagedRun none(testing::Render(blank).gray);
  const StageFailure why = none.Through("FindStrip");
  ASSERT_TRUE(why);
  EXPECT_EQ(why->rfind("no strip found", 0), 0u) << *why;
}

TEST(ExtractStages, FindStripBlocksMeasuresTheStripAndFindsAClampBlock) {
  PhotoScene s;
  s.holder = PhotoScene::Holder::kClampBlock;
  s.root_x = 300.0;
  s.block = 0.08;
  StagedRun run(testing::Render(s).gray);
  ASSERT_FALSE(run.Through("FindStripBlocks"));
  EXPECT_EQ(run.state.summary.polarity, "dark");
  // 10 px thick at full resolution, 1000/1400 of it on the detection image.
  EXPECT_NEAR(run.state.t_small, s.thickness * run.state.scale, 2.0);
  EXPECT_FALSE(run.state.blocks.empty());
  EXPECT_GT(run.state.sweep.length, 100.0);
}

TEST(ExtractStages, FindHeldEndTakesTheEndAtTheSideBorder) {
  StagedRun run(testing::Render(BorderScene()).gray);
  ASSERT_FALSE(run.Through("FindHeldEnd"));
  EXPECT_EQ(run.state.root_how, "border");
  EXPECT_EQ(run.state.root_borders, 1);  // the left border only
}

TEST(ExtractStages, FindHeldEndFailsWhenTheTipLeavesThePhoto) {
  PhotoScene s = BorderScene();
  s.root_y = 600;
  s.radius = 800;
  s.bend_deg = 60;  // ends 100 px below the photo
  StagedRun run(testing::Render(s).gray);
  const StageFailure why = run.Through("FindHeldEnd");
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("cut off by the image border (bottom)"), std::string::npos) << *why;
}

TEST(ExtractStages, FindHeldEndGuessesTheHigherEndWhenNothingHoldsTheStrip) {
  // The strip leaving the left border, with its first 150 columns painted over by background.
  cv::Mat gray = testing::Render(BorderScene()).gray.clone();
  gray(cv::Rect(0, 0, 150, gray.rows)).setTo(gray.at<uchar>(800, 5));
  StagedRun run(gray);
  ASSERT_FALSE(run.Through("FindHeldEnd"));
  EXPECT_EQ(run.state.root_how, "guess");
  EXPECT_TRUE(HasNote(run.state.summary.warnings, "held_end_guessed"));
}

TEST(ExtractStages, TraceCoarseLineRunsFromTheHeldEndTowardsTheOverhang) {
  for (const bool mirror : {false, true}) {
    PhotoScene s = BorderScene();
    s.mirror = mirror;
    const SyntheticPhoto photo = testing::Render(s);
    StagedRun run(photo.gray);
    ASSERT_FALSE(run.Through("TraceCoarseLine"));
    const ExtractState& st = run.state;
    EXPECT_EQ(st.direction, mirror ? -1 : +1);
    EXPECT_EQ(st.summary.direction, mirror ? "left" : "right");
    EXPECT_NEAR(st.t_full, s.thickness, 3.0);
    // It starts at the held end (within the reduction's few pixels) and runs every pixel.
    ASSERT_GT(st.coarse.size(), 100u);
    EXPECT_LT((st.coarse.front() - photo.origin).norm(), 3.0 * s.thickness);
    EXPECT_NEAR((st.coarse[1] - st.coarse[0]).norm(), 1.0, 1e-6);
  }
}

TEST(ExtractStages, FindRigFindsThePlatformOrFailsWhenAForcedOneIsMissing) {
  const SyntheticPhoto photo = testing::Render(PlatformScene());
  StagedRun run(photo.gray);
  ASSERT_FALSE(run.Through("FindRig"));
  ASSERT_TRUE(run.state.platform.found) << run.state.platform.why_not;
  EXPECT_LT((run.state.platform.corner - photo.origin).norm(), kOriginPx);
  EXPECT_FALSE(run.state.summary.blocks_px.empty());

  ExtractOptions forced;
  forced.rig = RigKind::kPlatform;
  StagedRun clamp(testing::Render(BorderScene()).gray, forced);
  const StageFailure why = clamp.Through("FindRig");
  ASSERT_TRUE(why);
  EXPECT_EQ(why->rfind("platform not found: ", 0), 0u) << *why;
}

TEST(ExtractStages, MeasureSectionsGivesTheSilhouetteWidth) {
  const PhotoScene s = BorderScene();
  StagedRun run(testing::Render(s).gray);
  ASSERT_FALSE(run.Through("MeasureSections"));
  EXPECT_NEAR(run.state.set.width, s.thickness, 0.5);
  EXPECT_EQ(run.state.summary.width_px, run.state.set.width);
  EXPECT_GT(run.state.last - run.state.first, 500);
  EXPECT_GT(run.state.summary.contrast, 10.0 * run.state.summary.noise);
}

TEST(ExtractStages, MeasureSectionsFailsOnALineMeasuredOnFewSections) {
  // A strip much thicker than its bend radius allows loses its upper edge in most sections
  // (as ExtractFailures.LineMeasuredOnFewSectionsFailsNamingIt).
  const PhotoScene s = testing::ThickBandRoundTheCornerScene();
  ExtractOptions upper;
  upper.trace = TraceLine::kUpper;
  StagedRun run(testing::Render(s).gray, upper);
  const StageFailure why = run.Through("MeasureSections");
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("upper edge is measured on only"), std::string::npos) << *why;
}

TEST(ExtractStages, TraceMeasuredLineFollowsTheTruthMidline) {
  const SyntheticPhoto photo = testing::Render(BorderScene());
  StagedRun run(photo.gray);
  ASSERT_FALSE(run.Through("TraceMeasuredLine"));
  ASSERT_GT(run.state.trace.size(), 100u);
  double worst = 0.0;
  for (const Eigen::Vector2d& p : run.state.trace)
    worst = std::max(worst, photo.DistanceToLine(p, 0.0));
  EXPECT_LT(worst, kLineMaxPx);
  EXPECT_FALSE(run.state.summary.upper_px.empty());
  EXPECT_FALSE(run.state.summary.lower_px.empty());
}

TEST(ExtractStages, FindTipEndPlacesTheTip) {
  const SyntheticPhoto photo = testing::Render(BorderScene());
  StagedRun run(photo.gray);
  ASSERT_FALSE(run.Through("FindTipEnd"));
  EXPECT_LT((run.state.summary.tip_px - photo.tip).norm(), kTipPx);
  EXPECT_EQ(run.state.trace.back(), run.state.summary.tip_px);
  EXPECT_FALSE(HasNote(run.state.summary.warnings, "tip_end_unclear"));
}

TEST(ExtractStages, AGivenTipCutsTheLineOrContinuesItAndAFarOneIsRefused) {
  const SyntheticPhoto photo = testing::Render(BorderScene());
  StagedRun found(photo.gray);
  ASSERT_FALSE(found.Through("FindTipEnd"));
  const std::vector<Eigen::Vector2d> line = found.state.trace;
  ASSERT_GT(line.size(), 40u);

  // A tip back along the line: the line ends there, the points beyond it are gone.
  ExtractOptions back;
  back.tip_px = line[line.size() - 30];
  StagedRun cut(photo.gray, back);
  ASSERT_FALSE(cut.Through("FindTipEnd"));
  EXPECT_EQ(cut.state.trace.back(), *back.tip_px);
  EXPECT_EQ(cut.state.summary.tip_px, *back.tip_px);
  EXPECT_LT(cut.state.trace.size(), line.size() - 20);
  EXPECT_FALSE(HasNote(cut.state.summary.warnings, "tip_end_unclear"));

  // A tip beyond the end, on the line's continuation: the line is continued to it.
  const Eigen::Vector2d& end = line.back();
  const Eigen::Vector2d along = (end - line[line.size() - 10]).normalized();
  ExtractOptions ahead;
  ahead.tip_px = end + 15.0 * along;
  StagedRun longer(photo.gray, ahead);
  ASSERT_FALSE(longer.Through("FindTipEnd"));
  EXPECT_EQ(longer.state.trace.back(), *ahead.tip_px);

  // A tip well off the line is a mistake, named.
  ExtractOptions off;
  off.tip_px = end + 40.0 * Eigen::Vector2d(along.y(), -along.x());
  StagedRun refused(photo.gray, off);
  try {
    refused.Through("FindTipEnd");
    ADD_FAILURE() << "a tip 40 px off the line was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--tip-px"), std::string::npos) << e.what();
  }
}

TEST(ExtractStages, AnInferredTipNamesTipPxWithWhereItWasTaken) {
  const SyntheticPhoto photo = testing::Render(BorderScene());
  ExtractOptions unchecked;  // the physics check needs the profile, which comes later
  unchecked.check_shape = false;
  StagedRun run(photo.gray, unchecked);
  ASSERT_FALSE(run.Through("FindTipEnd"));
  run.state.summary.warnings.push_back({"tip_end_unclear", "as FindTipEnd writes it"});
  run.state.summary.tip_px = Eigen::Vector2d(812.25, 640.5);
  const ExtractionConfidence c = extract_internal::AssessConfidence(run.state);
  EXPECT_EQ(c.tip, "inferred");
  ASSERT_FALSE(c.guesses.empty());
  EXPECT_NE(c.guesses.back().find("at 812.25,640.5 px"), std::string::npos) << c.guesses.back();
  EXPECT_NE(c.guesses.back().find("--tip-px X,Y"), std::string::npos) << c.guesses.back();

  ExtractOptions given = unchecked;
  given.tip_px = run.state.trace.back();
  StagedRun told(photo.gray, given);
  ASSERT_FALSE(told.Through("FindTipEnd"));
  EXPECT_EQ(extract_internal::AssessConfidence(told.state).tip, "given");
}

TEST(ExtractStages, CheckEdgeGivenRefusesAnEdgeFarFromTheStrip) {
  const SyntheticPhoto photo = testing::Render(BorderScene());
  ExtractOptions far;
  far.edge_px = Eigen::Vector2d(700.0, 850.0);  // far below the strip
  StagedRun run(photo.gray, far);
  ASSERT_FALSE(run.Through("FindTipEnd"));
  std::vector<Note> warnings;
  EXPECT_THROW(extract_internal::CheckEdgeGiven(run.state, &warnings), InputError);
  // Without --edge-px there is nothing to check.
  StagedRun plain(photo.gray);
  ASSERT_FALSE(plain.Through("FindTipEnd"));
  EXPECT_NO_THROW(extract_internal::CheckEdgeGiven(plain.state, &warnings));
  EXPECT_TRUE(warnings.empty());
}

TEST(ExtractStages, PlaceOriginPutsItWhereTheStripLeavesTheBorderOrAtTheCorner) {
  const SyntheticPhoto border = testing::Render(BorderScene());
  StagedRun run(border.gray);
  ASSERT_FALSE(run.Through("PlaceOrigin"));
  EXPECT_EQ(run.state.summary.rig_type, "clamp");
  EXPECT_LT((run.state.summary.origin_px - border.origin).norm(), kOriginPx);
  EXPECT_EQ(run.state.level, 0.0);  // rows

  const SyntheticPhoto platform = testing::Render(PlatformScene());
  StagedRun on(platform.gray);
  ASSERT_FALSE(on.Through("PlaceOrigin"));
  EXPECT_EQ(on.state.summary.rig_type, "platform");
  EXPECT_EQ(on.state.summary.origin_px, on.state.platform.corner);
  EXPECT_EQ(on.state.summary.platform_px.size(), 3u);
  EXPECT_NEAR(on.state.summary.level_deg, 0.0, 0.05);
}

TEST(ExtractStages, MapToMillimetresStartsTheCurveAtTheVerticalThroughTheOrigin) {
  const SyntheticPhoto photo = testing::Render(BorderScene());
  StagedRun run(photo.gray);
  ASSERT_FALSE(run.Through("MapToMillimetres"));
  const std::vector<Eigen::Vector2d>& curve = run.state.curve;
  ASSERT_GT(curve.size(), 10u);
  EXPECT_NEAR(curve.front().x(), 0.0, 1e-9);
  EXPECT_NEAR(curve.front().y(), 0.0, 1e-9);  // a clamp at the border: the origin itself
  EXPECT_GT(curve.back().x(), 0.0);           // towards the overhang
  EXPECT_LT(curve.back().y(), 0.0);           // y up: the tip hangs below
  EXPECT_NEAR(run.state.summary.mm_per_px, kScale, 1e-12);
}

TEST(ExtractStages, AssembleProfileResamplesAtTheStepAndEndsAtTheTip) {
  ExtractOptions options;
  options.step_mm = 1.0;
  StagedRun run(testing::Render(BorderScene()).gray, options);
  ASSERT_FALSE(run.Through("AssembleProfile"));
  const ExtractionSummary& r = run.state.summary;
  ASSERT_GT(r.profile.size(), 10u);
  EXPECT_NEAR(r.profile.s[1] - r.profile.s[0], 1e-3, 1e-12);  // 1 mm [m]
  EXPECT_NEAR(r.profile.s.back() * 1e3, r.length_mm, 1e-9);
  EXPECT_NEAR(r.profile.x.back() * 1e3, r.tip_mm.x(), 1e-9);
  EXPECT_EQ(r.trace_px.back(), r.tip_px);
}

TEST(ExtractStages, AssembleProfileRefusesAStepGivingTooFewPoints) {
  ExtractOptions coarse;
  coarse.step_mm = 10.0;  // enough points on the 91 mm strip
  StagedRun run(testing::Render(BorderScene()).gray, coarse);
  ASSERT_FALSE(run.Through("MapToMillimetres"));
  // Shrink the curve to 60 mm: 7 points at 10 mm, 121 at the default step.
  std::vector<Eigen::Vector2d>& curve = run.state.curve;
  curve = {curve.front(), curve.front() + Eigen::Vector2d(60.0, 0.0)};
  try {
    extract_internal::AssembleProfile(&run.state);
    ADD_FAILURE() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--step-mm 10.00: the 60.0 mm strip"), std::string::npos)
        << e.what();
  }
}

TEST(ExtractStages, DiagnoseSilhouetteWarnsOfLowContrastWithItsCode) {
  StagedRun run(testing::Render(BorderScene()).gray);
  ASSERT_FALSE(run.Through("DiagnoseSilhouette"));
  EXPECT_TRUE(run.state.summary.warnings.empty()) << run.state.summary.warnings.front().text;
  EXPECT_NEAR(run.state.summary.widening, 1.0, 0.2);
  EXPECT_GT(run.state.summary.core_width_px, 0.0);
  // The same sections with a noise near the contrast.
  ExtractState& s = run.state;
  s.summary.rejected_sections = 0;
  s.summary.noise = s.summary.contrast / 5.0;
  extract_internal::DiagnoseSilhouette(&s);
  ASSERT_EQ(s.summary.warnings.size(), 1u);
  EXPECT_EQ(s.summary.warnings[0].code, "low_contrast");
  EXPECT_EQ(s.summary.warnings[0].text.rfind("low contrast: strip ", 0), 0u);
}

TEST(ExtractStages, CheckResultFailsOnTooFewPointsAndPassesAGoodProfile) {
  StagedRun run(testing::Render(BorderScene()).gray);
  ASSERT_FALSE(run.Through("CheckResult"));
  Profile& p = run.state.summary.profile;
  p.s.resize(5);
  p.x.resize(5);
  p.y.resize(5);
  const StageFailure why = extract_internal::CheckResult(run.state);
  ASSERT_TRUE(why);
  EXPECT_EQ(why->rfind("the profile has only 5 points", 0), 0u) << *why;
}

}  // namespace
}  // namespace textile
