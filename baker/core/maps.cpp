#include "core/maps.h"

namespace nmbake {

namespace {
constexpr const char* kNames[kMapKinds] = {"normal",    "object-normal", "ao",        "bent-normal", "height",      "thickness",
                                           "curvature", "position",      "object-id", "material-id", "vertex-color"};
}

const char* map_name(MapKind kind) { return kNames[int(kind)]; }

bool parse_map_name(const std::string& name, MapKind& kind) {
  for (int k = 0; k < kMapKinds; ++k)
    if (name == kNames[k]) {
      kind = MapKind(k);
      return true;
    }
  return false;
}

std::string map_name_list() {
  std::string out;
  for (int k = 0; k < kMapKinds; ++k) out += (k ? ", " : "") + std::string(kNames[k]);
  return out;
}

int map_channels(MapKind kind) {
  switch (kind) {
    case MapKind::ao:
    case MapKind::height:
    case MapKind::thickness:
    case MapKind::curvature: return 1;
    default: return 3;
  }
}

int map_image_channels(MapKind kind) { return map_is_flat(kind) ? 1 : map_channels(kind); }

bool map_is_flat(MapKind kind) { return kind == MapKind::object_id || kind == MapKind::material_id; }

bool map_casts_rays(MapKind kind) { return kind == MapKind::ao || kind == MapKind::bent_normal || kind == MapKind::thickness; }

}  // namespace nmbake
