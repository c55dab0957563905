#ifndef TEXTILE_SIM_IO_JSON_FIELDS_H_
#define TEXTILE_SIM_IO_JSON_FIELDS_H_

// Reading the fields of the JSON files users give (materials, seams, rigs), with one wording for
// each mistake. Every refusal is an InputError "<source>: <field>: <problem>", one line:
//
//   missing                                        Require (with an optional hint in brackets)
//   must be a number, got "0.1"                    Number: wrong type
//   must be finite, got ...                        Number: NaN or infinite
//   must be a string, got 3                        String
//   must be an array of numbers, got {...}         Numbers, FixedNumbers ("an array [lo, hi]")
//   must be a 3×3 array [[...], [...], [...]], got Matrix3
//   must be an object {"units", ...}, got [1, 2]   Object
//   must be > 0, got -1                            Must: any bound or shape, ", got <value>"
//   unknown law 'x' (use "pabst" or "spline")      Unknown: a string outside its choices
//   unknown field (known: a, b, c)                 CheckKeys
//   (top level): must be a JSON object, got [1]    RequireObject
//
// <value> is the JSON as written, cut to 40 characters.
//
//   const nlohmann::json root = textile::ParseJsonText(text, "rig.json");
//   const textile::JsonFields f("rig.json");
//   f.RequireObject(root);
//   const double s = f.Number(f.Require(root, "mm_per_px"), "mm_per_px");
//   if (s <= 0.0) f.Must("mm_per_px", "be > 0", root["mm_per_px"]);

#include <array>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "textile/sim/core/error.h"

namespace textile {

class JsonFields {
 public:
  explicit JsonFields(std::string source) : source_(std::move(source)) {}

  const std::string& source() const { return source_; }

  // Throws InputError "<source>: <field>: <problem>".
  [[noreturn]] void Fail(const std::string& field, const std::string& problem) const;
  // "<field>: must <requirement>, got <Brief(value)>" (requirement: "be > 0", "lie in [0, 1]").
  [[noreturn]] void Must(const std::string& field, const std::string& requirement,
                         const nlohmann::json& value) const;
  // "<field>: unknown <what> '<value>' (use <choices>)".
  [[noreturn]] void Unknown(const std::string& field, const std::string& what,
                            const std::string& value, const std::string& choices) const;

  // The JSON text of v, cut to 40 characters ("..." at the end when cut).
  static std::string Brief(const nlohmann::json& v);

  // "(top level): must be a JSON object" unless root is one.
  void RequireObject(const nlohmann::json& root) const;
  // obj[key], or "<field>: missing[ (<hint>)]"; field defaults to key.
  const nlohmann::json& Require(const nlohmann::json& obj, const std::string& key,
                                const std::string& hint = "", const std::string& field = "") const;
  // "unknown field (known: ...)" for a key of obj outside known; the field is where.key (key
  // alone when where is empty).
  void CheckKeys(const nlohmann::json& obj, const std::string& where,
                 const std::set<std::string>& known) const;

  // A finite number.
  double Number(const nlohmann::json& v, const std::string& field) const;
  // An array of finite numbers, any length; elements are named field[i].
  std::vector<double> Numbers(const nlohmann::json& v, const std::string& field) const;
  // An array of exactly N finite numbers; shape names it ("[lo, hi]").
  template <std::size_t N>
  std::array<double, N> FixedNumbers(const nlohmann::json& v, const std::string& field,
                                     const std::string& shape) const {
    if (!v.is_array() || v.size() != N) Must(field, "be an array " + shape, v);
    std::array<double, N> out{};
    for (std::size_t i = 0; i < N; ++i) out[i] = Number(v[i], Element(field, i));
    return out;
  }
  // 3 rows of 3 finite numbers, row-major.
  std::array<double, 9> Matrix3(const nlohmann::json& v, const std::string& field) const;
  // A string.
  std::string String(const nlohmann::json& v, const std::string& field) const;
  // An object; shape names its fields ("{\"units\", \"b1\"}"), may be empty.
  const nlohmann::json& Object(const nlohmann::json& v, const std::string& field,
                               const std::string& shape = "") const;

  // "field[i]".
  static std::string Element(const std::string& field, std::size_t i);

 private:
  std::string source_;
};

}  // namespace textile

#endif  // TEXTILE_SIM_IO_JSON_FIELDS_H_
