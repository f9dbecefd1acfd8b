// How the left pane decodes the normal map: the convention it was baked with.
//
// nmbake stores its convention in the map's metadata (image_io.h read_image_metadata):
// "nmbake:space" tangent|object, "nmbake:green" up|down, "nmbake:bitangent" pixel|vertex. Maps
// from other bakers carry none of these, so each can be overridden on the command line; what is
// neither stored nor given is the baker's default (tangent space, green up = OpenGL, per-pixel
// bitangent, MikkTSpace frames).
#pragma once

#include <map>
#include <string>

#include "core/tangent_frames.h"

namespace nmview {

// Where a setting came from: the command line, the map's nmbake:* metadata, or the default.
enum class DecodingSource { default_value, metadata, option };

struct MapDecoding {
  bool object_space = false;  // the map holds object-space normals (n = texel * 2 - 1)
  bool green_down = false;    // DirectX "Y-": the bitangent component is negated (tangent space only)
  nmbake::BitangentMode bitangent = nmbake::BitangentMode::per_pixel;  // as in tangent_frames.h
  DecodingSource space_source = DecodingSource::default_value;
  DecodingSource green_source = DecodingSource::default_value;  // default_value for object-space maps
};

// The convention in a pane label's words (upper case, the viewer's font): "GREEN UP (OPENGL) FROM
// METADATA", "GREEN DOWN (DIRECTX) FROM --GREEN", "GREEN UP (OPENGL) BY DEFAULT", or for an
// object-space map "OBJECT SPACE FROM METADATA" / "FROM --SPACE".
std::string convention_label(const MapDecoding& decoding);

// Command-line overrides: empty = take the map's metadata, else "tangent"/"object", "up"/"down",
// "pixel"/"vertex".
struct DecodingOverrides {
  std::string space, green, bitangent;
};

// Metadata first, then overrides. Throws nmbake::InputError ("<map>: nmbake:green is 'sideways'")
// for a stored value it does not know and nmbake::UsageError for a bad override. `note` receives
// one line saying what was chosen and where each part came from.
MapDecoding resolve_decoding(const std::map<std::string, std::string>& metadata, const DecodingOverrides& overrides,
                             const std::string& map_name, std::string* note = nullptr);

}  // namespace nmview
