#include "textile/sim/io/json_fields.h"

#include <gtest/gtest.h>

#include <string>

namespace textile {
namespace {

using nlohmann::json;

// The message of the InputError that f throws.
template <typename F>
std::string Refusal(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(JsonFields, EachMistakeHasOneWording) {
  const JsonFields f("a.json");
  const json root = json::parse(R"({"x": "1", "s": 2, "o": [], "a": [1, "2"], "e": "q"})");
  EXPECT_EQ(Refusal([&] { f.RequireObject(json::array({1})); }),
            "a.json: (top level): must be a JSON object, got [1]");
  EXPECT_EQ(Refusal([&] { f.Require(root, "y"); }), "a.json: y: missing");
  EXPECT_EQ(Refusal([&] { f.Require(root, "y", "g/m²", "top.y"); }),
            "a.json: top.y: missing (g/m²)");
  EXPECT_EQ(Refusal([&] { f.Number(root["x"], "x"); }), "a.json: x: must be a number, got \"1\"");
  EXPECT_EQ(Refusal([&] { f.String(root["s"], "s"); }), "a.json: s: must be a string, got 2");
  EXPECT_EQ(Refusal([&] { f.Object(root["o"], "o", "{\"k\"}"); }),
            "a.json: o: must be an object {\"k\"}, got []");
  EXPECT_EQ(Refusal([&] { f.Numbers(root["s"], "s"); }),
            "a.json: s: must be an array of numbers, got 2");
  EXPECT_EQ(Refusal([&] { f.Numbers(root["a"], "a"); }),
            "a.json: a[1]: must be a number, got \"2\"");
  EXPECT_EQ(Refusal([&] { f.FixedNumbers<3>(root["a"], "a", "[x, y, z]"); }),
            "a.json: a: must be an array [x, y, z], got [1,\"2\"]");
  EXPECT_EQ(Refusal([&] { f.Matrix3(root["a"], "m"); }),
            "a.json: m: must be a 3×3 array [[...], [...], [...]], got [1,\"2\"]");
  EXPECT_EQ(Refusal([&] { f.Must("s", "be > 3", root["s"]); }), "a.json: s: must be > 3, got 2");
  EXPECT_EQ(Refusal([&] { f.Unknown("e", "reading", "q", "\"p\" or \"r\""); }),
            "a.json: e: unknown reading 'q' (use \"p\" or \"r\")");
  EXPECT_EQ(Refusal([&] {
              f.CheckKeys(root, "top", {"x", "s"});
            }),
            "a.json: top.a: unknown field (known: s, x)");
}

TEST(JsonFields, BriefIsTheStartOfTheCompactText) {
  const json small = json::parse(R"({"b": [1, 2.5, "x"], "a": null})");
  EXPECT_EQ(JsonFields::Brief(small), small.dump());
  const json long_array = json::array({std::string(60, 'x'), 1, 2});
  EXPECT_EQ(JsonFields::Brief(long_array), long_array.dump().substr(0, 37) + "...");
}

TEST(JsonFields, BriefOfADeeplyNestedValueIsBounded) {
  // dump() recurses once per level; this depth overflows its stack under ASan (and near the
  // default 8 MiB stack without), while the parser takes it.
  constexpr int kDepth = 200000;
  const json deep = json::parse(std::string(kDepth, '[') + std::string(kDepth, ']'));
  EXPECT_EQ(JsonFields::Brief(deep), std::string(37, '[') + "...");
}

TEST(JsonFields, NonFiniteNumbersAreRefused) {
  // JSON text cannot hold them (ParseJsonText refuses 1e999), but a json built in code can.
  const JsonFields f("a.json");
  EXPECT_EQ(Refusal([&] { f.Number(json(std::numeric_limits<double>::infinity()), "x"); }),
            "a.json: x: must be finite, got null");
}

TEST(JsonFields, ReadsWellFormedValues) {
  const JsonFields f("a.json");
  const json m = json::parse("[[1, 2, 3], [4, 5, 6], [7, 8, 9.5]]");
  const std::array<double, 9> v = f.Matrix3(m, "m");
  EXPECT_EQ(v[1], 2.0);
  EXPECT_EQ(v[3], 4.0);  // row-major
  EXPECT_EQ(v[8], 9.5);
  EXPECT_EQ(f.FixedNumbers<2>(json::parse("[0, 80]"), "r", "[lo, hi]")[1], 80.0);
  EXPECT_EQ(JsonFields::Brief(json(std::string(50, 'x'))).size(), 40u);
}

}  // namespace
}  // namespace textile
