#include "controls.h"

#include <algorithm>
#include <cmath>

#include "angle_metrics.h"

namespace nmview {
void keep_light_in_range(Light& light) {
  light.azimuth = std::remainder(light.azimuth, 360.0f);
  light.elevation = std::clamp(light.elevation, -89.0f, 89.0f);
}

void cycle_display(Toggles& toggles, const std::vector<nmbake::MapKind>& maps) {
  if (!toggles.show_map) {
    toggles.show_map = !maps.empty();
    if (toggles.show_map) toggles.shown = maps.front();
    return;
  }
  const auto at = std::find(maps.begin(), maps.end(), toggles.shown);
  if (at == maps.end() || at + 1 == maps.end()) toggles.show_map = false;
  else toggles.shown = *(at + 1);
}

KeyAction apply_key(ViewerState& s, int key, const KeyContext& c, std::ostream& log) {
  Toggles& t = s.toggles;
  switch (key) {
    case kKeyEscape:
      // Esc first drops the selection; with none it closes the window, as Q does.
      if (!s.selection) return KeyAction::quit;
      s.selection.reset();
      break;
    case 'Q': return KeyAction::quit;
    case 'R':
      s.view = c.initial_view;
      s.light = c.initial_light;
      break;
    case 'F': s.view = s.selection ? frame_point(s.view, *s.selection) : frame_view(s.view); break;
    case 'V': return KeyAction::print_view;
    case 'P': return KeyAction::screenshot;
    case 'N': t.map = !t.map; break;
    case 'W': t.wireframe = !t.wireframe; break;
    case 'T': t.tangent_colours = !t.tangent_colours; break;
    case 'A':
      t.ao = !t.ao;
      if (!c.has_ao) log << "nmview: A: the set has no ao map\n";
      break;
    case 'M': cycle_display(t, c.maps); break;
    case 'K':
      t.masks = !t.masks;
      if (!c.has_masks) log << "nmview: K: no mask given (--miss-mask, --suspect-mask, or --report)\n";
      break;
    case 'C':
      t.cage = !t.cage;
      if (!c.has_cage) log << "nmview: C: no cage given (--cage, or --report of a bake with --cage)\n";
      break;
    case 'U':
      t.uv_layout = !t.uv_layout;
      if (!t.uv_layout) {
        s.uv_cursor.reset();
        s.uv_point.reset();
      }
      break;
    case 'D': t.difference = !t.difference; break;
    case '[':
    case ']':
      t.diff_scale = next_diff_scale(t.diff_scale, key == ']');
      log << "nmview: difference scale 0.." << t.diff_scale << " degrees\n";
      break;
    case 'S': t.specular = t.specular > 0.0f ? 0.0f : 0.3f; break;
    case 'L': s.orbit_light = !s.orbit_light; break;
    case 'H': s.help = !s.help; break;
    case kKeyLeft: s.light.azimuth -= 5.0f; break;
    case kKeyRight: s.light.azimuth += 5.0f; break;
    case kKeyUp: s.light.elevation += 5.0f; break;
    case kKeyDown: s.light.elevation -= 5.0f; break;
    default: return KeyAction::ignored;
  }
  keep_light_in_range(s.light);
  return KeyAction::redraw;
}

Marks marks_of(const ViewerState& s) {
  Marks m;
  if (s.toggles.uv_layout && s.uv_cursor) {
    m.uv = s.uv_cursor;
    if (s.uv_point) m.points.push_back(s.uv_point->position);
    m.label = describe_uv_point(*s.uv_cursor, s.uv_point);
  }
  if (s.selection) m.points.push_back(*s.selection);
  return m;
}

void set_uv_cursor(ViewerState& s, const std::optional<glm::vec2>& uv, const LowVertices& low) {
  s.uv_cursor = uv;
  s.uv_point = uv ? find_uv_point(low, *uv) : std::nullopt;
}

}  // namespace nmview
