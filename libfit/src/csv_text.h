#ifndef TEXTILE_FIT_SRC_CSV_TEXT_H_
#define TEXTILE_FIT_SRC_CSV_TEXT_H_

// The small text helpers the CSV readers of libfit share (profiles, moment-curvature pairs).

#include <sstream>
#include <string>
#include <vector>

namespace textile::internal {

// s without leading and trailing blanks (space, tab, CR, LF).
inline std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

// The comma-separated cells of a line, each trimmed; a trailing comma gives an empty last cell.
inline std::vector<std::string> SplitComma(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(Trim(cell));
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

}  // namespace textile::internal

#endif  // TEXTILE_FIT_SRC_CSV_TEXT_H_
