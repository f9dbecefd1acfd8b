// The common spellings of option values that the commands accept beside their own, where the
// meaning is unambiguous: --green dx/gl for down/up, --size 4k for 4096. Header only: nmbake
// (cli/args.cpp) and nmview (viewer/main.cpp) read --green alike.
#pragma once

#include <cctype>
#include <string>

namespace nmbake {

// `text` in lower case (ASCII).
inline std::string lower_ascii(std::string text) {
  for (char& c : text) c = char(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// --green's value as "up" or "down" where `text` spells one of them, in any case: up, gl, opengl
// (OpenGL "Y+") or down, dx, directx (DirectX "Y-"); any other text unchanged, for the option's
// own check to refuse with its usual message.
inline std::string canonical_green(const std::string& text) {
  const std::string s = lower_ascii(text);
  if (s == "up" || s == "gl" || s == "opengl") return "up";
  if (s == "down" || s == "dx" || s == "directx") return "down";
  return text;
}

// One side of --size: a whole number of texels, or a whole number followed by k or K for that many
// times 1024 (1k = 1024, 4k = 4096). Sets `texels` and returns true, or returns false for any other
// text: an empty one, a sign, blanks, a fraction, another suffix, more than 12 digits.
inline bool parse_texel_count(const std::string& text, long long& texels) {
  std::string digits = text;
  long long unit = 1;
  if (!digits.empty() && (digits.back() == 'k' || digits.back() == 'K')) {
    digits.pop_back();
    unit = 1024;
  }
  if (digits.empty() || digits.size() > 12) return false;
  for (char c : digits)
    if (c < '0' || c > '9') return false;
  texels = std::stoll(digits) * unit;  // at most 1e12 x 1024: within long long
  return true;
}

}  // namespace nmbake
