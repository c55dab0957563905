#include "textile/sim/json_text.h"

#include "textile/sim/error.h"

namespace textile {

nlohmann::json ParseJsonText(const std::string& text, const std::string& source) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {  // parse_error, or out_of_range for 1e999
    // Drop nlohmann's "[json.exception.parse_error.101] " tag; keep what and where.
    std::string what = e.what();
    if (const auto p = what.find("] "); p != std::string::npos) what = what.substr(p + 2);
    throw InputError(source + ": not valid JSON: " + what);
  }
}

}  // namespace textile
