#include "textile/sim/io/json_text.h"

#include <set>
#include <vector>

#include "textile/sim/core/error.h"

namespace textile {

nlohmann::json ParseJsonText(const std::string& text, const std::string& source) {
  using json = nlohmann::json;
  // The keys seen so far in each open object (innermost last), and the key that opened each
  // nested value, for the message. nlohmann keeps the last of duplicate keys without a word;
  // in a material or seam file a repeated key is an editing mistake that silently wins.
  std::vector<std::set<std::string>> keys;
  std::vector<std::string> path;
  std::string last_key;
  const json::parser_callback_t refuse_duplicates = [&](int /*depth*/, json::parse_event_t event,
                                                        json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
        keys.emplace_back();
        path.push_back(last_key);
        last_key.clear();  // an object in an array has no key of its own
        break;
      case json::parse_event_t::object_end:
        keys.pop_back();
        path.pop_back();
        break;
      case json::parse_event_t::array_start:
        path.push_back(last_key);
        last_key.clear();
        break;
      case json::parse_event_t::array_end:
        path.pop_back();
        break;
      case json::parse_event_t::key: {
        last_key = parsed.get<std::string>();
        if (!keys.back().insert(last_key).second) {
          std::string where;
          for (const std::string& k : path)
            if (!k.empty()) where += (where.empty() ? "" : ".") + k;
          throw InputError(
              source + ": duplicate key \"" + last_key + "\"" +
              (where.empty() ? std::string(" at the top level") : " in \"" + where + "\"") +
              " (a JSON parser would silently keep the last one)");
        }
        break;
      }
      case json::parse_event_t::value:
        break;
    }
    return true;
  };
  try {
    return json::parse(text, refuse_duplicates);
  } catch (const json::exception& e) {  // parse_error, or out_of_range for 1e999
    // Drop nlohmann's "[json.exception.parse_error.101] " tag; keep what and where.
    std::string what = e.what();
    if (const auto p = what.find("] "); p != std::string::npos) what = what.substr(p + 2);
    throw InputError(source + ": not valid JSON: " + what);
  }
}

nlohmann::json NotesJson(const std::vector<Note>& notes) {
  nlohmann::json list = nlohmann::json::array();
  for (const Note& n : notes) list.push_back({{"code", n.code}, {"text", n.text}});
  return list;
}

}  // namespace textile
