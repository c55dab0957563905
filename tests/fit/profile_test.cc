#include "textile/fit/profile.h"

#include <gtest/gtest.h>

#include <string>

#include "textile/sim/core/error.h"

namespace textile {
namespace {

const std::string kDir = std::string(TEXTILE_SOURCE_DIR) + "/tests/data/profiles/";

TEST(Profile, ReadsGoodFileInMetres) {
  const Profile p = ReadProfileCsv(kDir + "good.csv");
  ASSERT_EQ(p.size(), 30u);
  EXPECT_DOUBLE_EQ(p.s.front(), 0.0);
  EXPECT_NEAR(p.s.back(), 0.05, 1e-15);  // 50 mm
  EXPECT_LT(p.y.back(), 0.0);
}

TEST(Profile, CsvRoundTrip) {
  const Profile p = ReadProfileCsv(kDir + "good.csv");
  const Profile q = ParseProfileCsv(ProfileToCsv(p), "round trip");
  ASSERT_EQ(q.size(), p.size());
  for (size_t i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(q.x[i], p.x[i], 1e-9);  // 6 decimals in mm = 1 nm
    EXPECT_NEAR(q.y[i], p.y[i], 1e-9);
  }
}

TEST(Profile, AcceptsCommentsBlankLinesCrlfAndSpaces) {
  std::string text = "# from extract\r\n s_mm , x_mm , y_mm \r\n\r\n";
  for (int i = 0; i < 12; ++i) text += std::to_string(i) + ", " + std::to_string(i) + ", -0.5\r\n";
  EXPECT_EQ(ParseProfileCsv(text, "crlf").size(), 12u);
}

struct BadCase {
  const char* file;
  const char* fragment;
};

// A mid-line starts half a thickness above the platform: a strip thicker than the rise check
// allows (6 mm) is named as the likelier cause near the edge; a rise further out is not.
TEST(Profile, RiseNearTheEdgeNamesTheThickness) {
  Profile p;
  p.source = "thick.csv";
  for (int i = 0; i < 20; ++i) {
    p.s.push_back(i * 1e-3);
    p.x.push_back(i * 1e-3);
    p.y.push_back(4e-3 - i * 1e-4);  // starts 4 mm up, a 8 mm strip
  }
  try {
    CheckProfile(p);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("point 1 lies 4.000000 mm above the platform, more than 3 mm"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("a strip thicker than 6 mm"), std::string::npos) << m;
  }
  for (double& y : p.y) y = -1e-3;
  p.y[15] = 5e-3;  // far from the edge: a rising tip, not a thick strip
  try {
    CheckProfile(p);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("point 16 lies"), std::string::npos) << m;
    EXPECT_EQ(m.find("thicker"), std::string::npos) << m;
  }
}

class BadProfile : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadProfile, IsRejectedNamingTheFile) {
  const std::string path = kDir + GetParam().file;
  try {
    ReadProfileCsv(path);
    FAIL() << path << " was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path, 0), 0u) << what;
    EXPECT_NE(what.find(GetParam().fragment), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Profile, BadProfile,
    ::testing::Values(BadCase{"empty.csv", "empty profile"},
                      BadCase{"binary.csv", "expected the header"},
                      BadCase{"wrong-header.csv", "expected the header 's_mm,x_mm,y_mm'"},
                      BadCase{"no-header.csv", "expected the header"},
                      BadCase{"too-few.csv", "5 points, at least 10"},
                      BadCase{"non-increasing-s.csv", "must increase strictly"},
                      BadCase{"nan.csv", "NaN or infinite"},
                      BadCase{"rises-above.csv", "above the platform"},
                      BadCase{"folds-back.csv", "folds back"},
                      BadCase{"not-a-number.csv", "'abc' is not a number"},
                      BadCase{"two-columns.csv", "expected 3 values"},
                      BadCase{"missing.csv", "cannot open"}),
    [](const auto& info) {
      std::string n = info.param.file;
      n = n.substr(0, n.find('.'));
      for (char& c : n) if (c == '-') c = '_';
      return n;
    });

}  // namespace
}  // namespace textile
