// Numeric command-line options taken strictly, for nmbake, nmdiff and nmview.
#pragma once

#include <string>

// CLI11's App, declared: CLI/CLI.hpp costs seconds of compile time in every translation unit that
// includes it, so only the .cpp files that parse do.
namespace CLI {
class App;
}  // namespace CLI

namespace nmbake {

// Every numeric option of `app` (CLI11's INT, UINT, FLOAT) refuses, as a usage error naming it, an
// empty value, white space, trailing characters, octal and hex; decimal leading zeros are dropped.
// Call after the options are added, before parsing.
void require_numbers(CLI::App& app);

// Whether `word` is a whole number (decimal digits with an optional sign) or, not `integer`, a
// number as std::from_chars reads it (decimal, inf, nan); a leading '+' is allowed.
bool is_number(const std::string& word, bool integer);

// A value for a one-line message: control characters as '?', at most 40 characters.
std::string printable(const std::string& word);

}  // namespace nmbake
