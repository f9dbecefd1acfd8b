#include "cli/numbers.h"

#include <charconv>
#include <string>
#include <CLI/CLI.hpp>

namespace nmbake {

// What CLI11 alone would take: '' as 0, leading blanks, octal (010 as 8) and hex (0x10).
bool is_number(const std::string& word, bool integer) {
  std::size_t first = word.size() > 1 && word[0] == '+' && word[1] != '-' ? 1 : 0;
  if (word.empty() || word.find_first_of(" \t\n\r\f\v") != std::string::npos) return false;
  if (integer) {
    if (word[first] == '-') ++first;
    return first < word.size() && word.find_first_not_of("0123456789", first) == std::string::npos;
  }
  double value = 0.0;
  const auto [end, ec] = std::from_chars(word.data() + first, word.data() + word.size(), value);
  return end == word.data() + word.size() && (ec == std::errc() || ec == std::errc::result_out_of_range);
}

std::string printable(const std::string& word) {
  std::string s = word.substr(0, 40);
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 32 || c == 127) c = '?';
  return word.size() > 40 ? s + "..." : s;
}

namespace {

// Decimal integers with leading zeros lose them: CLI11 reads "010" as octal.
std::string without_leading_zeros(const std::string& word) {
  std::size_t sign = word[0] == '+' || word[0] == '-' ? 1 : 0;
  std::size_t digits = sign;
  while (digits + 1 < word.size() && word[digits] == '0') ++digits;
  return (word[0] == '-' ? "-" : "") + word.substr(digits);
}

}  // namespace

void require_numbers(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    const bool integer = type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0;
    if (option->get_type_size() == 0 || (!integer && type.rfind("FLOAT", 0) != 0)) continue;  // flags, text
    option->transform(CLI::Validator(
        [integer](std::string& word) {
          if (!is_number(word, integer))
            return std::string("expected ") + (integer ? "a whole number" : "a number") + ", got '" + printable(word) + "'";
          if (integer) word = without_leading_zeros(word);
          return std::string();
        },
        "", "number"));
  }
}

}  // namespace nmbake
