#include "textile/sim/io/json_fields.h"

#include <cmath>

namespace textile {

using nlohmann::json;

void JsonFields::Fail(const std::string& field, const std::string& problem) const {
  throw InputError(source_ + ": " + field + ": " + problem);
}

void JsonFields::Must(const std::string& field, const std::string& requirement,
                      const json& value) const {
  Fail(field, "must " + requirement + ", got " + Brief(value));
}

void JsonFields::Unknown(const std::string& field, const std::string& what,
                         const std::string& value, const std::string& choices) const {
  Fail(field, "unknown " + what + " '" + value + "' (use " + choices + ")");
}

namespace {

// Appends v's compact JSON text (as json::dump() writes it) to *out until *out is longer than
// `limit`; false once it stopped there. Bounded, unlike dump(): a file nested 20 000 arrays
// deep overflowed dump()'s recursion (under ASan), and only the first `limit` characters are
// shown anyway. Each level writes a bracket, so the recursion is at most `limit` deep.
bool AppendBrief(const json& v, size_t limit, std::string* out) {
  if (out->size() > limit) return false;
  if (v.is_array() || v.is_object()) {
    *out += v.is_array() ? '[' : '{';
    bool first = true;
    for (auto it = v.begin(); it != v.end(); ++it) {
      if (!first) *out += ',';
      first = false;
      if (v.is_object()) *out += json(it.key()).dump() + ':';
      if (!AppendBrief(it.value(), limit, out)) return false;
    }
    *out += v.is_array() ? ']' : '}';
  } else {
    *out += v.dump();
  }
  return out->size() <= limit;
}

}  // namespace

std::string JsonFields::Brief(const json& v) {
  constexpr size_t kShown = 40;
  std::string s;
  AppendBrief(v, kShown, &s);
  return s.size() > kShown ? s.substr(0, kShown - 3) + "..." : s;
}

void JsonFields::RequireObject(const json& root) const {
  if (!root.is_object()) Must("(top level)", "be a JSON object", root);
}

const json& JsonFields::Require(const json& obj, const std::string& key, const std::string& hint,
                                const std::string& field) const {
  if (!obj.contains(key))
    Fail(field.empty() ? key : field, hint.empty() ? "missing" : "missing (" + hint + ")");
  return obj.at(key);
}

void JsonFields::CheckKeys(const json& obj, const std::string& where,
                           const std::set<std::string>& known) const {
  for (const auto& [key, value] : obj.items()) {
    if (known.count(key)) continue;
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    Fail(where.empty() ? key : where + "." + key, "unknown field (known: " + list + ")");
  }
}

double JsonFields::Number(const json& v, const std::string& field) const {
  if (!v.is_number()) Must(field, "be a number", v);
  const double d = v.get<double>();
  if (!std::isfinite(d)) Must(field, "be finite", v);
  return d;
}

std::vector<double> JsonFields::Numbers(const json& v, const std::string& field) const {
  if (!v.is_array()) Must(field, "be an array of numbers", v);
  std::vector<double> out;
  for (std::size_t i = 0; i < v.size(); ++i) out.push_back(Number(v[i], Element(field, i)));
  return out;
}

std::array<double, 9> JsonFields::Matrix3(const json& v, const std::string& field) const {
  const auto is_row = [](const json& r) { return r.is_array() && r.size() == 3; };
  if (!v.is_array() || v.size() != 3 || !is_row(v[0]) || !is_row(v[1]) || !is_row(v[2]))
    Must(field, "be a 3×3 array [[...], [...], [...]]", v);
  std::array<double, 9> out{};
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c)
      out[3 * r + c] = Number(v[r][c], Element(Element(field, r), c));
  return out;
}

std::string JsonFields::String(const json& v, const std::string& field) const {
  if (!v.is_string()) Must(field, "be a string", v);
  return v.get<std::string>();
}

const json& JsonFields::Object(const json& v, const std::string& field,
                               const std::string& shape) const {
  if (!v.is_object()) Must(field, shape.empty() ? "be an object" : "be an object " + shape, v);
  return v;
}

std::string JsonFields::Element(const std::string& field, std::size_t i) {
  return field + "[" + std::to_string(i) + "]";
}

}  // namespace textile
