#include "textile/sim/core/note.h"

#include <algorithm>

namespace textile {

bool HasNote(const std::vector<Note>& notes, std::string_view code) {
  return std::any_of(notes.begin(), notes.end(),
                     [code](const Note& note) { return note.code == code; });
}

std::string JoinNoteTexts(const std::vector<Note>& notes, std::string_view separator) {
  std::string joined;
  for (const Note& note : notes) {
    if (!joined.empty()) joined += separator;
    joined += note.text;
  }
  return joined;
}

}  // namespace textile
