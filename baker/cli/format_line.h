// printf-style formatting into a std::string, for the command's one-line messages and warnings.
#pragma once

#include <cstdio>
#include <string>

namespace nmbake {

// At most 1023 characters (a longer text is cut there).
template <typename... Args>
std::string format_line(const char* fmt, Args... args) {
  char buf[1024];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

}  // namespace nmbake
