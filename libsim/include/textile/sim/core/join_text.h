#ifndef TEXTILE_SIM_CORE_JOIN_TEXT_H_
#define TEXTILE_SIM_CORE_JOIN_TEXT_H_

// Items joined by a separator, for messages and notes: the one way every module joins them.
//
//   JoinText({"stretch.warp", "stretch.shear"}, ", ")   -> "stretch.warp, stretch.shear"
//   JoinText({}, "; ")                                   -> ""

#include <string>
#include <string_view>
#include <vector>

namespace textile {

inline std::string JoinText(const std::vector<std::string>& items, std::string_view separator) {
  std::string joined;
  for (const std::string& item : items) {
    if (!joined.empty()) joined += separator;
    joined += item;
  }
  return joined;
}

}  // namespace textile

#endif  // TEXTILE_SIM_CORE_JOIN_TEXT_H_
