// The JSON documents nmbake reads (a batch's jobs file, the parts' reports it merges).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace nmbake {

// `text`, the content of the file `path`, parsed. Throws InputError "<path>: not valid JSON: parse
// error at line L, column C: ..." (the parser's message without its exception tag).
nlohmann::json parse_json_file_text(const std::string& path, const std::string& text);

}  // namespace nmbake
