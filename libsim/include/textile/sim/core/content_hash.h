#ifndef TEXTILE_SIM_CORE_CONTENT_HASH_H_
#define TEXTILE_SIM_CORE_CONTENT_HASH_H_

// A 128-bit fingerprint of bytes: two FNV-1a 64 passes, the second seeded by the first. For
// telling content apart (an export's id, a batch's "did this specimen's input change"), not for
// security: anyone can make two inputs that collide on purpose.
//
//   const textile::ContentHash h = textile::HashContent(text);
//   h.Hex();   // 32 lower-case hex digits, the same on every machine

#include <cstdint>
#include <string>
#include <string_view>

namespace textile {

struct ContentHash {
  std::uint64_t hi = 0, lo = 0;
  std::string Hex() const;  // hi then lo, 32 lower-case hex digits
  bool operator==(const ContentHash&) const = default;
};

ContentHash HashContent(std::string_view content);

}  // namespace textile

#endif  // TEXTILE_SIM_CORE_CONTENT_HASH_H_
