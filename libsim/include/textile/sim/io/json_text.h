#ifndef TEXTILE_SIM_IO_JSON_TEXT_H_
#define TEXTILE_SIM_IO_JSON_TEXT_H_

// Parsing the JSON files users give (materials, seams, rigs) with one kind of error message.
//
//   nlohmann::json j = textile::ParseJsonText(text, "rig.json");
//   // throws InputError "rig.json: not valid JSON: syntax error while parsing ... at line 3"

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "textile/sim/core/note.h"

namespace textile {

// Parses text as JSON. Throws InputError "<source>: not valid JSON: <what and where>", one
// line, for a syntax error or a number out of range (1e999), and "<source>: duplicate key
// \"k\" in \"a.b\" ..." for an object that repeats a key (JSON leaves it open; the last would
// win silently).
nlohmann::json ParseJsonText(const std::string& text, const std::string& source);

// Notes as JSON results list them: [{"code": ..., "text": ...}, ...] ([] for none).
nlohmann::json NotesJson(const std::vector<Note>& notes);

}  // namespace textile

#endif  // TEXTILE_SIM_IO_JSON_TEXT_H_
