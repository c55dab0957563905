#include "textile/sim/core/note.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "textile/sim/core/number_text.h"

namespace textile {
namespace {

TEST(Note, HasNoteComparesCodesNotTexts) {
  const std::vector<Note> notes = {{"rim_shortfall", "short of the rim"},
                                   {"bare_support", "the support shows"}};
  EXPECT_TRUE(HasNote(notes, "bare_support"));
  EXPECT_FALSE(HasNote(notes, "short of the rim"));
  EXPECT_FALSE(HasNote({}, "rim_shortfall"));
}

TEST(Note, JoinNoteTextsKeepsOrder) {
  const std::vector<Note> notes = {{"a", "first"}, {"b", "second"}};
  EXPECT_EQ(JoinNoteTexts(notes, "; "), "first; second");
  EXPECT_EQ(JoinNoteTexts({}, "; "), "");
}

TEST(NumberText, SignificantDigitsAndNonFinite) {
  EXPECT_EQ(NumberText(0.123456789), "0.123457");
  EXPECT_EQ(NumberText(1234.5, 3), "1.23e+03");
  EXPECT_EQ(NumberText(std::nan("")), "nan");
  EXPECT_EQ(NumberText(-std::numeric_limits<double>::infinity()), "-inf");
}

}  // namespace
}  // namespace textile
