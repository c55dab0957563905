#include "textile/sim/core/content_hash.h"

#include <cstdio>

namespace textile {
namespace {

// FNV-1a, 64 bits, from a seed.
std::uint64_t Fnv1a(std::string_view s, std::uint64_t seed) {
  std::uint64_t h = seed;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return h;
}

}  // namespace

std::string ContentHash::Hex() const {
  char s[33];
  std::snprintf(s, sizeof s, "%016llx%016llx", static_cast<unsigned long long>(hi),
                static_cast<unsigned long long>(lo));
  return s;
}

ContentHash HashContent(std::string_view content) {
  ContentHash h;
  h.hi = Fnv1a(content, 14695981039346656037ULL);
  h.lo = Fnv1a(content, h.hi ^ 0x9e3779b97f4a7c15ULL);
  return h;
}

}  // namespace textile
