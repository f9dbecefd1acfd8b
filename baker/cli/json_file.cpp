#include "cli/json_file.h"

#include "core/errors.h"

namespace nmbake {

nlohmann::json parse_json_file_text(const std::string& path, const std::string& text) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    const std::string what = e.what();  // "[json.exception.parse_error.101] parse error at line 3, column 5: ..."
    const auto at = what.find("parse error");
    throw InputError(path + ": not valid JSON: " + (at == std::string::npos ? what : what.substr(at)));
  }
}

}  // namespace nmbake
