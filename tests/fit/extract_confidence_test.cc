// The confidence report of an extraction and the refusal of guesses (extract_confidence.cc).

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <string>

#include "photo/extract_internal.h"
#include "synthetic_photo.h"
#include "textile/photo/extract.h"
#include "textile/photo/render_photo.h"
#include "textile/sim/law/bending_law.h"

namespace textile {
namespace {

bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A rendered heavy elastica on a platform: everything found, the physics check within the
// extraction's own error, nothing guessed.
TEST(ExtractConfidence, RenderedCantileverIsFoundEverywhere) {
  const RenderedPhoto photo =
      RenderPhoto(BendingLaw::FromKes(0.1, 0.0892, -0.0092), 0.2,
                  RenderPhotoOptions::ForDifficulty(PhotoDifficulty::kMedium, 11));
  const ExtractionSummary r = ExtractProfile(photo.photo, photo.rig, {}, "rendered");
  ASSERT_TRUE(r.success) << r.message;
  const ExtractionConfidence& c = r.confidence;
  EXPECT_EQ(c.held_end, "found");
  EXPECT_EQ(c.held_end_how, r.rig_detail);
  EXPECT_EQ(c.tip, "found");
  EXPECT_GT(c.sections_measured, 0.8);
  EXPECT_LE(c.sections_measured, 1.0);
  ASSERT_TRUE(c.shape.has_value());
  EXPECT_TRUE(c.shape->plausible) << c.shape->message;
  EXPECT_LT(c.shape->rms, 0.1e-3);
  EXPECT_TRUE(c.guesses.empty());
  EXPECT_TRUE(Has(r.BriefReport(), "confidence: held end found, tip found")) << r.BriefReport();
}

// A strip that is a straight run and a circular arc is no heavy cantilever: refused by the
// physics check naming the flags, taken with accept_guesses (a warning), unchecked without it.
TEST(ExtractConfidence, ArcThatIsNoCantileverFailsThePhysicsCheck) {
  const cv::Mat gray = testing::Render(testing::BorderScene()).gray;
  const Rig rig = Rig::FromScale(0.1);
  const ExtractionSummary refused = ExtractProfile(gray, rig, {}, "arc.png");
  ASSERT_FALSE(refused.success);
  EXPECT_TRUE(Has(refused.message, "had to guess: ")) << refused.message;
  EXPECT_TRUE(Has(refused.message, "no heavy cantilever")) << refused.message;
  EXPECT_TRUE(Has(refused.message, "--accept-guesses")) << refused.message;

  ExtractOptions accept;
  accept.accept_guesses = true;
  const ExtractionSummary taken = ExtractProfile(gray, rig, accept, "arc.png");
  ASSERT_TRUE(taken.success) << taken.message;
  ASSERT_TRUE(taken.confidence.shape.has_value());
  EXPECT_FALSE(taken.confidence.shape->plausible);
  // Either no heavy cantilever fits at all, or the best one lies over 1 mm away.
  EXPECT_TRUE(!taken.confidence.shape->converged || taken.confidence.shape->rms > 1e-3);
  ASSERT_EQ(taken.confidence.guesses.size(), 1u);
  EXPECT_TRUE(HasNote(taken.warnings, "guess_accepted"));
  EXPECT_TRUE(Has(taken.BriefReport(), "FAILS the")) << taken.BriefReport();

  ExtractOptions unchecked;
  unchecked.check_shape = false;
  const ExtractionSummary plain = ExtractProfile(gray, rig, unchecked, "arc.png");
  ASSERT_TRUE(plain.success) << plain.message;
  EXPECT_FALSE(plain.confidence.shape.has_value());
  EXPECT_TRUE(plain.confidence.guesses.empty());
  EXPECT_FALSE(HasNote(plain.warnings, "guess_accepted"));
}

// Nothing holds the strip in view (its first 150 columns painted over): the held end is a
// guess, and the run fails naming --edge-px unless the guess is accepted.
TEST(ExtractConfidence, GuessedHeldEndFailsNamingTheFlag) {
  cv::Mat gray = testing::Render(testing::BorderScene()).gray.clone();
  gray(cv::Rect(0, 0, 150, gray.rows)).setTo(gray.at<uchar>(800, 5));
  ExtractOptions o;
  o.check_shape = false;
  const ExtractionSummary refused = ExtractProfile(gray, Rig::FromScale(0.1), o, "loose.png");
  ASSERT_FALSE(refused.success);
  EXPECT_TRUE(Has(refused.message, "the held end was guessed")) << refused.message;
  EXPECT_TRUE(Has(refused.message, "--edge-px")) << refused.message;
  o.accept_guesses = true;
  const ExtractionSummary taken = ExtractProfile(gray, Rig::FromScale(0.1), o, "loose.png");
  ASSERT_TRUE(taken.success) << taken.message;
  EXPECT_EQ(taken.confidence.held_end, "guessed");
  EXPECT_TRUE(HasNote(taken.warnings, "held_end_guessed"));
  EXPECT_TRUE(HasNote(taken.warnings, "guess_accepted"));
}

// The refusal itself: every guess listed in order, nothing without guesses.
TEST(ExtractConfidence, RefuseGuessesListsEveryGuess) {
  ExtractionConfidence c;
  std::vector<Note> warnings;
  EXPECT_FALSE(extract_internal::RefuseGuesses(c, {}, &warnings));
  c.guesses = {"first guess", "second guess"};
  const auto why = extract_internal::RefuseGuesses(c, {}, &warnings);
  ASSERT_TRUE(why);
  EXPECT_EQ(*why, "had to guess: first guess; second guess (--accept-guesses takes the guesses)");
  EXPECT_TRUE(warnings.empty());
  ExtractOptions accept;
  accept.accept_guesses = true;
  EXPECT_FALSE(extract_internal::RefuseGuesses(c, accept, &warnings));
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_EQ(warnings[1].text, "second guess; taken (--accept-guesses)");
}

}  // namespace
}  // namespace textile
