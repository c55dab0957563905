// The batch manifest (docs/guide/batch.md, "The manifest"): CSV, one specimen a row, columns
// named by the header in any order. Every error names the file, the line and the column.

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "csv_text.h"
#include "textile/photo/batch.h"
#include "textile/photo/profile_inputs.h"
#include "textile/sim/core/error.h"
#include "textile/sim/core/number_text.h"

namespace textile {

const std::vector<std::string> kManifestRequiredColumns = {"fabric",    "specimen", "direction",
                                                           "side",      "inputs",   "gsm"};
const std::vector<std::string> kManifestOptionalColumns = {"rig", "mm_per_px", "width_mm",
                                                           "notes", "validate"};

const char* DirectionName(StripDirection d) {
  switch (d) {
    case StripDirection::kWarp: return "warp";
    case StripDirection::kWeft: return "weft";
    case StripDirection::kBias: return "bias";
  }
  return "?";
}

const char* SideName(FabricSide s) { return s == FabricSide::kFace ? "face" : "back"; }

namespace {

namespace fs = std::filesystem;

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// Where a cell sits, for messages: "series.csv line 4, column gsm".
struct CellPlace {
  const std::string& source;
  int line;
  const std::string& column;
  std::string Text() const {
    return source + " line " + std::to_string(line) + ", column " + column;
  }
};

[[noreturn]] void Fail(const CellPlace& at, const std::string& what) {
  throw InputError(at.Text() + ": " + what);
}

// One CSV record's cells: commas split, "quoted" cells may hold commas, "" is a quote. Cells
// are trimmed. Throws InputError for an unterminated quote.
std::vector<std::string> SplitCsvRecord(const std::string& line, const std::string& where) {
  std::vector<std::string> cells;
  std::string cell;
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cell += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cell += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      cells.push_back(internal::Trim(cell));
      cell.clear();
    } else {
      cell += c;
    }
  }
  if (quoted) throw InputError(where + ": a quote is not closed");
  cells.push_back(internal::Trim(cell));
  return cells;
}

// The header's columns -> their index. Unknown, duplicate and missing columns are refused.
std::map<std::string, size_t> ColumnIndex(const std::vector<std::string>& header,
                                          const std::string& source, int line) {
  const std::string where = source + " line " + std::to_string(line);
  std::map<std::string, size_t> index;
  for (size_t i = 0; i < header.size(); ++i) {
    std::string name = header[i];
    std::transform(name.begin(), name.end(), name.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const auto known = [&name](const std::vector<std::string>& list) {
      return std::find(list.begin(), list.end(), name) != list.end();
    };
    if (header.size() == 1 && name.find(';') != std::string::npos)
      throw InputError(where + ": one column '" + header[i] +
                       "': the manifest is comma-separated (save it as CSV with ',')");
    if (!known(kManifestRequiredColumns) && !known(kManifestOptionalColumns))
      throw InputError(where + ": unknown column '" + header[i] +
                       "' (columns: fabric, specimen, direction, side, inputs, gsm, rig, "
                       "mm_per_px, width_mm, notes, validate)");
    if (!index.emplace(name, i).second)
      throw InputError(where + ": column '" + name + "' is given twice");
  }
  for (const std::string& c : kManifestRequiredColumns)
    if (!index.contains(c)) throw InputError(where + ": missing column '" + c + "'");
  return index;
}

// A name that can be a folder: [A-Za-z0-9._+-], not empty, not starting with '.', and none of
// `reserved` (the files batch writes beside the folder).
std::string PathSafeName(const std::string& cell, const CellPlace& at,
                         const std::vector<std::string>& reserved) {
  if (cell.empty()) Fail(at, "empty");
  const bool safe = std::all_of(cell.begin(), cell.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '.' || c == '_' || c == '-' || c == '+';
  });
  if (!safe || cell.front() == '.')
    Fail(at, "'" + cell + "' cannot name a folder (use letters, digits, '.', '_', '-', '+'; "
                          "not starting with '.')");
  if (std::find(reserved.begin(), reserved.end(), cell) != reserved.end())
    Fail(at, "'" + cell + "' is the name of a file batch writes there; choose another");
  return cell;
}

// A plain number with no units in the cell; `what` says its unit for the message.
double NumberCell(const std::string& cell, const CellPlace& at, const std::string& unit) {
  if (cell.empty()) Fail(at, "empty (expected a number in " + unit + ")");
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(cell.c_str(), &end);
  if (end == cell.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    Fail(at, "'" + cell + "' is not a number (" + unit + ", without units in the cell)");
  return v;
}

double PositiveInRange(const std::string& cell, const CellPlace& at, const std::string& unit,
                       double lo, double hi) {
  const double v = NumberCell(cell, at, unit);
  if (!(v >= lo && v <= hi))
    Fail(at, NumberText(v) + " " + unit + " is outside " + NumberText(lo) + " .. " +
                 NumberText(hi));
  return v;
}

StripDirection DirectionCell(const std::string& cell, const CellPlace& at) {
  if (cell == "warp") return StripDirection::kWarp;
  if (cell == "weft") return StripDirection::kWeft;
  if (cell == "bias") return StripDirection::kBias;
  Fail(at, "unknown direction '" + cell + "' (warp, weft or bias)");
}

FabricSide SideCell(const std::string& cell, const CellPlace& at) {
  if (cell == "face") return FabricSide::kFace;
  if (cell == "back") return FabricSide::kBack;
  Fail(at, "unknown side '" + cell + "' (face or back)");
}

SpecimenValidation ValidateCell(const std::string& cell, const CellPlace& at) {
  if (cell.empty() || cell == "no") return SpecimenValidation::kNone;
  if (cell == "yes") return SpecimenValidation::kElastica;
  if (cell == "shell") return SpecimenValidation::kShell;
  Fail(at, "'" + cell + "' (no, yes for the elastica, or shell for the elastica and the shell)");
}

std::string Resolve(const std::string& path, const std::string& base_dir) {
  const fs::path p(path);
  return p.is_absolute() || base_dir.empty() ? p.string() : (fs::path(base_dir) / p).string();
}

std::vector<std::string> InputsCell(const std::string& cell, const CellPlace& at) {
  std::vector<std::string> out;
  std::stringstream ss(cell);
  std::string part;
  while (std::getline(ss, part, ';')) {
    part = internal::Trim(part);
    if (part.empty()) Fail(at, "an empty input between ';'");
    if (std::find(out.begin(), out.end(), part) != out.end())
      Fail(at, part + " is given twice (its points would weigh double in the fit)");
    out.push_back(part);
  }
  if (out.empty()) Fail(at, "empty (expected photos or profiles, ';'-separated)");
  return out;
}

ManifestRow ParseRow(const std::vector<std::string>& cells,
                     const std::map<std::string, size_t>& index, int line,
                     const std::string& source, const std::string& base_dir) {
  const auto cell = [&](const std::string& column) -> std::string {
    const auto it = index.find(column);
    return it == index.end() ? std::string() : cells[it->second];
  };
  const auto at = [&](const std::string& column) { return CellPlace{source, line, column}; };
  const std::string fabric = "fabric", specimen = "specimen", direction = "direction",
                    side = "side", inputs = "inputs", gsm = "gsm", rig = "rig",
                    scale = "mm_per_px", width = "width_mm";
  ManifestRow r;
  r.line = line;
  r.fabric = PathSafeName(cell(fabric), at(fabric), {"summary.json", "summary.csv", "report.html"});
  r.specimen = PathSafeName(cell(specimen), at(specimen), {"material.json"});
  r.direction = DirectionCell(Lower(cell(direction)), at(direction));
  r.side = SideCell(Lower(cell(side)), at(side));
  r.inputs = InputsCell(cell(inputs), at(inputs));
  for (const std::string& in : r.inputs) r.paths.push_back(Resolve(in, base_dir));
  r.gsm = PositiveInRange(cell(gsm), at(gsm), "g/m²", 1.0, 1e4);
  r.rig = cell(rig);
  if (!r.rig.empty()) r.rig_path = Resolve(r.rig, base_dir);
  if (!cell(scale).empty()) r.mm_per_px = PositiveInRange(cell(scale), at(scale), "mm/px", 1e-4, 10.0);
  if (!r.rig.empty() && r.mm_per_px)
    Fail(at(scale), "give a rig or a scale, not both (the rig already maps pixels to mm)");
  if (!cell(width).empty()) r.width_mm = PositiveInRange(cell(width), at(width), "mm", 1.0, 1000.0);
  r.notes = cell("notes");
  r.validate = ValidateCell(Lower(cell("validate")), at("validate"));
  return r;
}

}  // namespace

Manifest ParseManifest(const std::string& raw, const std::string& source,
                       const std::string& base_dir) {
  const std::string text = raw.rfind("\xEF\xBB\xBF", 0) == 0 ? raw.substr(3) : raw;  // Excel's BOM
  if (std::any_of(text.begin(), text.end(), [](unsigned char c) {
        return (c < 0x20 && c != '\t' && c != '\r' && c != '\n') || c == 0x7f;
      }))
    throw InputError(source + ": not a text file (expected a CSV manifest)");
  Manifest m;
  m.source = source;
  std::stringstream in(text);
  std::string line;
  int number = 0;
  std::map<std::string, size_t> index;
  size_t columns = 0;
  std::set<std::pair<std::string, std::string>> seen;
  while (std::getline(in, line)) {
    ++number;
    if (internal::Trim(line).empty()) continue;
    const std::string where = source + " line " + std::to_string(number);
    const std::vector<std::string> cells = SplitCsvRecord(line, where);
    if (index.empty()) {
      index = ColumnIndex(cells, source, number);
      columns = cells.size();
      continue;
    }
    if (std::all_of(cells.begin(), cells.end(), [](const std::string& c) { return c.empty(); }))
      continue;  // a spreadsheet's empty row, all commas
    if (cells.size() != columns)
      throw InputError(where + ": " + std::to_string(cells.size()) + " cells for " +
                       std::to_string(columns) + " columns");
    ManifestRow row = ParseRow(cells, index, number, source, base_dir);
    if (!seen.emplace(row.fabric, row.specimen).second)
      throw InputError(where + ", column specimen: specimen '" + row.specimen + "' of fabric '" +
                       row.fabric + "' is listed twice");
    m.rows.push_back(std::move(row));
  }
  if (index.empty()) throw InputError(source + ": empty (expected a header and one row a specimen)");
  if (m.rows.empty()) throw InputError(source + ": a header and no specimens");
  return m;
}

Manifest ReadManifest(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot read the manifest");
  std::stringstream text;
  text << in.rdbuf();
  Manifest m = ParseManifest(text.str(), path, fs::path(path).parent_path().string());
  for (const ManifestRow& r : m.rows) {
    const std::string at = path + " line " + std::to_string(r.line) + ", column ";
    for (size_t i = 0; i < r.paths.size(); ++i) {
      std::error_code ec;
      if (fs::is_directory(r.paths[i], ec))
        throw InputError(at + "inputs: " + r.inputs[i] + " is a folder, not a photo or profile");
      if (!fs::is_regular_file(r.paths[i], ec))
        throw InputError(at + "inputs: " + r.inputs[i] +
                         " does not exist (inputs are relative to the manifest)");
      if (r.rig.empty() && !r.mm_per_px && IsPhotoPath(r.paths[i]))
        throw InputError(at + "rig: " + r.inputs[i] +
                         " is a photo: give its rig file (column rig) or its scale (column "
                         "mm_per_px)");
    }
    std::error_code ec;
    if (!r.rig_path.empty() && !fs::is_regular_file(r.rig_path, ec))
      throw InputError(path + " line " + std::to_string(r.line) + ", column rig: " + r.rig +
                       " does not exist");
  }
  return m;
}

Shard ParseShard(const std::string& text) {
  const auto slash = text.find('/');
  const auto whole = [](const std::string& s, int* v) {
    if (s.empty() || s.size() > 6 || !std::all_of(s.begin(), s.end(), ::isdigit)) return false;
    *v = std::stoi(s);
    return true;
  };
  Shard s;
  if (slash == std::string::npos || !whole(text.substr(0, slash), &s.index) ||
      !whole(text.substr(slash + 1), &s.count))
    throw InputError("--shard " + text + ": expected K/N, e.g. 2/4 (part K of N)");
  if (s.count < 1 || s.index < 1 || s.index > s.count)
    throw InputError("--shard " + text + ": K must lie in 1..N and N >= 1");
  return s;
}

}  // namespace textile
