// FNV-1a, 64 bits: a fast, fixed hash of bytes (the same on every machine and run), for names and
// files that need a stable number, not for security.
#pragma once

#include <cstdint>
#include <string_view>

namespace nmbake {

inline std::uint64_t fnv1a64(std::string_view bytes) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : bytes) h = (h ^ c) * 0x100000001b3ull;
  return h;
}

}  // namespace nmbake
