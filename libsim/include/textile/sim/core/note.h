#ifndef TEXTILE_SIM_CORE_NOTE_H_
#define TEXTILE_SIM_CORE_NOTE_H_

// Typed status: what a computation wants its caller to know, as a code a program (or a test)
// can compare and a sentence a person reads.
//
//   result.notes.push_back({"rim_shortfall", "the skirt stops 3.1 mm short of the rim"});
//   if (HasNote(result.notes, "rim_shortfall")) ...
//   std::cerr << JoinNoteTexts(result.notes, "; ");
//
// Codes are lower_snake_case, stable across versions (they go into JSON results as "code");
// the text may change.

#include <string>
#include <string_view>
#include <vector>

namespace textile {

struct Note {
  std::string code;  // e.g. "rim_shortfall"
  std::string text;  // one sentence for people, no trailing newline
};

// True when a note with this code is in `notes`.
bool HasNote(const std::vector<Note>& notes, std::string_view code);

// The texts joined by `separator`, in order ("" for none).
std::string JoinNoteTexts(const std::vector<Note>& notes, std::string_view separator);

}  // namespace textile

#endif  // TEXTILE_SIM_CORE_NOTE_H_
