// `textile export` through the real executable: the three formats, U3M against its schema,
// the same bytes twice, and every refusal a user can reach.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "run_cli.h"

namespace textile {
namespace {

using testing::ExpectRefused;
using testing::ReadAll;
using testing::Scratch;
using testing::Textile;
namespace fs = std::filesystem;

const std::string kFitted = "samples/expected/pabst-fig8.fitted.json";

TEST(CliExport, WritesEachFormatAndNamesWhatItCouldNotCarry) {
  const fs::path d = Scratch("cli_export_formats");
  const auto arcsim = Textile("export " + kFitted + " --to arcsim -o " + (d / "a.json").string());
  ASSERT_EQ(arcsim.exit_code, 0) << arcsim.err;
  EXPECT_NE(arcsim.out.find("note: stretching left out"), std::string::npos) << arcsim.out;
  const nlohmann::json a = nlohmann::json::parse(ReadAll(d / "a.json"));
  EXPECT_EQ(a["bending"].size(), 3u);
  EXPECT_EQ(a["density"], 0.2);

  const auto csv = Textile("export " + kFitted + " --to csv -o " + (d / "a.csv").string() + " --json");
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  const nlohmann::json j = nlohmann::json::parse(csv.out);
  EXPECT_EQ(j["format"], "csv");
  EXPECT_EQ(j["notes"][0]["code"], "membrane_not_measured");
  const std::string table = ReadAll(d / "a.csv");
  EXPECT_EQ(testing::CountLines(table), 4);
  EXPECT_NE(table.find("\nbias,45,pabst,0.10216231,"), std::string::npos) << table;

  // The measured-like KES membrane gives ARCSim its stretching.
  const auto kes = Textile("export samples/materials/pabst-fig8-kes.json --to arcsim --strict -o " +
                           (d / "kes.json").string());
  ASSERT_EQ(kes.exit_code, 0) << kes.err;
  EXPECT_EQ(nlohmann::json::parse(ReadAll(d / "kes.json"))["stretching"].size(), 6u);
}

// python3-jsonschema against U3M 1.1's published schema, where this machine has both: the
// schema is not shipped (TEXTILE_U3M_SCHEMA, else ../shared/formats/u3m-1.1 beside the source).
// MaterialExport.U3mIsPhysicsOnlyWithTheLawInItsCustomSection checks the structure everywhere.
TEST(CliExport, U3mValidatesAgainstTheU3mSchemaAndIsTheSameBytesTwice) {
  const fs::path d = Scratch("cli_export_u3m");
  const std::string env = "SOURCE_DATE_EPOCH=1796601600";
  const auto one = Textile("export " + kFitted + " --to u3m --thickness-mm 0.3 -o " +
                               (d / "one.u3m").string(), env);
  const auto two = Textile("export " + kFitted + " --to u3m --thickness-mm 0.3 -o " +
                               (d / "two.u3m").string(), env);
  ASSERT_EQ(one.exit_code, 0) << one.err;
  ASSERT_EQ(two.exit_code, 0) << two.err;
  EXPECT_EQ(ReadAll(d / "one.u3m"), ReadAll(d / "two.u3m"));
  EXPECT_EQ(nlohmann::json::parse(ReadAll(d / "one.u3m"))["material"]["created"],
            "2026-12-07T00:00:00Z");

  const char* given = std::getenv("TEXTILE_U3M_SCHEMA");
  const fs::path schema = given ? fs::path(given)
                                : fs::path(TEXTILE_SOURCE_DIR) / ".." / "shared" / "formats" /
                                      "u3m-1.1" / "u3m_schema.json";
  if (!fs::exists(schema)) GTEST_SKIP() << "no U3M schema at " << schema;
  if (std::system("python3 -c 'import jsonschema' 2>/dev/null") != 0)
    GTEST_SKIP() << "python3-jsonschema is not installed";
  const std::string check =
      "python3 -c 'import json, sys, jsonschema; "
      "jsonschema.Draft7Validator(json.load(open(sys.argv[1])), format_checker=jsonschema.FormatChecker()).validate(json.load(open(sys.argv[2])))' '" +
      schema.string() + "' '";
  EXPECT_EQ(std::system((check + (d / "one.u3m").string() + "'").c_str()), 0);
  // The check can fail: a weight below zero is refused.
  nlohmann::json bad = nlohmann::json::parse(ReadAll(d / "one.u3m"));
  bad["material"]["physics"]["weight"] = -1;
  std::ofstream(d / "bad.u3m") << bad.dump();
  EXPECT_NE(std::system((check + (d / "bad.u3m").string() + "' 2>/dev/null").c_str()), 0);
}

TEST(CliExport, RefusesBadInputWithOneLineAndWritesNothing) {
  const fs::path d = Scratch("cli_export_bad");
  const std::string out = (d / "out.json").string();
  ExpectRefused(Textile("export " + kFitted + " --to obj -o " + out), "arcsim, u3m or csv", "format");
  ExpectRefused(Textile("export samples/materials/none.json --to csv -o " + out), "none.json",
                "missing material");
  ExpectRefused(Textile("export " + kFitted + " --to arcsim --strict -o " + out),
                "stretch.warp, stretch.weft, stretch.shear", "--strict without a membrane");
  ExpectRefused(Textile("export " + kFitted + " --to u3m --thickness-mm 0 -o " + out), "thickness",
                "thickness 0");
  ExpectRefused(Textile("export " + kFitted + " --to csv -o " + kFitted), "overwrite", "output = input");
  std::ofstream(d / "noname.json") << R"({"areal_density_gsm": 200, "bending": {"units": "kes", "b1": 0.1, "b2": 0.09, "c1": -0.01}})";
  ExpectRefused(Textile("export " + (d / "noname.json").string() + " --to u3m -o " + out), "name",
                "U3M without a name");
  ExpectRefused(Textile("export " + kFitted + " --to u3m -o " + out, "SOURCE_DATE_EPOCH=x"),
                "SOURCE_DATE_EPOCH", "bad SOURCE_DATE_EPOCH");
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace textile
