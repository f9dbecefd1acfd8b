#include "decoding.h"

#include "core/errors.h"

namespace nmview {
namespace {

// The value of one setting: the override, else the stored value, else the default; returns
// whether `first` of the two allowed values was chosen and appends "name first|second (source)".
bool choose(const std::map<std::string, std::string>& metadata, const std::string& key, const std::string& given,
            const std::string& flag, const char* first, const char* second, bool first_is_default, const std::string& map_name,
            std::string& note, DecodingSource* where = nullptr) {
  std::string value, source;
  if (!given.empty()) {
    if (given != first && given != second)
      throw nmbake::UsageError(flag + ": expected " + first + " or " + second + ", got '" + given + "'");
    value = given;
    source = flag;
  } else if (auto it = metadata.find(key); it != metadata.end()) {
    if (it->second != first && it->second != second)
      throw nmbake::InputError(map_name + ": " + key + " is '" + it->second + "', expected " + first + " or " + second);
    value = it->second;
    source = "metadata";
  } else {
    value = first_is_default ? first : second;
    source = "default";
  }
  note += (note.empty() ? "" : ", ") + flag.substr(2) + " " + value + " (" + source + ")";
  if (where)
    *where = source == "metadata"  ? DecodingSource::metadata
             : source == "default" ? DecodingSource::default_value
                                   : DecodingSource::option;
  return value == first;
}

}  // namespace

MapDecoding resolve_decoding(const std::map<std::string, std::string>& metadata, const DecodingOverrides& overrides,
                             const std::string& map_name, std::string* note) {
  std::string text;
  MapDecoding d;
  d.object_space =
      choose(metadata, "nmbake:space", overrides.space, "--space", "object", "tangent", false, map_name, text, &d.space_source);
  if (!d.object_space) {
    d.green_down =
        choose(metadata, "nmbake:green", overrides.green, "--green", "down", "up", false, map_name, text, &d.green_source);
    d.bitangent =
        choose(metadata, "nmbake:bitangent", overrides.bitangent, "--bitangent", "vertex", "pixel", false, map_name, text)
            ? nmbake::BitangentMode::per_vertex
            : nmbake::BitangentMode::per_pixel;
  } else if (!overrides.green.empty() || !overrides.bitangent.empty()) {
    throw nmbake::UsageError("--green and --bitangent apply to tangent-space maps only");
  }
  if (note) *note = text;
  return d;
}

std::string convention_label(const MapDecoding& decoding) {
  const auto from = [](DecodingSource s, const char* flag) {
    return s == DecodingSource::option     ? std::string("FROM ") + flag
           : s == DecodingSource::metadata ? std::string("FROM METADATA")
                                           : std::string("BY DEFAULT");
  };
  if (decoding.object_space) return "OBJECT SPACE " + from(decoding.space_source, "--SPACE");
  return std::string(decoding.green_down ? "GREEN DOWN (DIRECTX) " : "GREEN UP (OPENGL) ") +
         from(decoding.green_source, "--GREEN");
}

}  // namespace nmview
