#include "map_diff.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "core/errors.h"
#include "texel_selection.h"

namespace nmbake::diff {
namespace {

// Parses exactly `count` finite numbers separated by `sep` (surrounding spaces allowed).
bool parse_numbers(const std::string& text, char sep, int count, double* out) {
  const char* p = text.c_str();
  for (int i = 0; i < count; ++i) {
    char* end = nullptr;
    out[i] = std::strtod(p, &end);
    if (end == p || !std::isfinite(out[i])) return false;
    while (*end == ' ') ++end;
    if (i + 1 < count) {
      if (*end != sep) return false;
      ++end;
    }
    p = end;
  }
  return *p == '\0';
}

std::string metadata_value(const std::map<std::string, std::string>& metadata, const char* key) {
  const auto it = metadata.find(key);
  return it == metadata.end() ? std::string() : it->second;
}

// "a height", "an ao".
std::string with_article(const std::string& kind) {
  return (kind.empty() || std::string("aeiou").find(kind[0]) == std::string::npos ? "a " : "an ") + kind;
}

int channels_needed(MapKind kind) { return map_channels(kind) == 1 ? 1 : 3; }

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

MapFamily map_family(MapKind kind) {
  switch (kind) {
    case MapKind::normal:
    case MapKind::object_normal:
    case MapKind::bent_normal: return MapFamily::normal;
    case MapKind::object_id:
    case MapKind::material_id: return MapFamily::id;
    default: return MapFamily::grey;
  }
}

MapKind resolve_map_kind(const std::string& given, const std::string& kind_a, const std::string& kind_b,
                         const std::string& name_a, const std::string& name_b) {
  MapKind kind = MapKind::normal;
  if (!given.empty()) {
    if (!parse_map_name(given, kind)) throw InputError("--map " + given + ": not a map kind (" + map_name_list() + ")");
    return kind;
  }
  MapKind a = MapKind::normal, b = MapKind::normal;
  if (!kind_a.empty() && !parse_map_name(kind_a, a))
    throw InputError(name_a + ": nmbake:map '" + kind_a + "' is not a map kind nmdiff knows (--map KIND to choose one)");
  if (!kind_b.empty() && !parse_map_name(kind_b, b))
    throw InputError(name_b + ": nmbake:map '" + kind_b + "' is not a map kind nmdiff knows (--map KIND to choose one)");
  if (!kind_a.empty() && !kind_b.empty() && a != b)
    throw InputError(name_a + " is " + with_article(kind_a) + " map, " + name_b + " " + with_article(kind_b) +
                     " map (nmbake:map metadata): different kinds cannot be compared (--map KIND compares both as one)");
  return kind_a.empty() ? b : a;
}

MapDecoding map_decoding(MapKind kind, const std::map<std::string, std::string>& metadata, const std::string& name) {
  MapDecoding d;
  d.kind = kind;
  const auto malformed = [&](const char* key, const std::string& text, const char* form) {
    return InputError(name + ": " + key + " '" + text + "' is not " + form);
  };
  if (kind == MapKind::height) {
    const std::string text = metadata_value(metadata, "nmbake:height_range");
    if (text.empty()) return d;
    double v[2];
    if (!parse_numbers(text, ':', 2, v)) throw malformed("nmbake:height_range", text, "A:B (two finite numbers)");
    d.offset[0] = v[0];
    d.scale[0] = v[1] - v[0];
    d.from_metadata = true;
    d.range_text = text;
  } else if (kind == MapKind::curvature) {
    const std::string text = metadata_value(metadata, "nmbake:curvature_scale");
    if (text.empty()) return d;
    double s;
    if (!parse_numbers(text, ' ', 1, &s)) throw malformed("nmbake:curvature_scale", text, "a finite number");
    // (2v - 1) S = -S + v (2S).
    d.offset[0] = -s;
    d.scale[0] = 2.0 * s;
    d.from_metadata = true;
    d.range_text = text;
  } else if (kind == MapKind::position) {
    const std::string text = metadata_value(metadata, "nmbake:position_box");
    if (text.empty()) return d;
    const std::size_t colon = text.find(':');
    double lo[3], hi[3];
    if (colon == std::string::npos || !parse_numbers(text.substr(0, colon), ',', 3, lo) ||
        !parse_numbers(text.substr(colon + 1), ',', 3, hi))
      throw malformed("nmbake:position_box", text, "x0,y0,z0:x1,y1,z1 (six finite numbers)");
    for (int c = 0; c < 3; ++c) {
      d.offset[c] = lo[c];
      d.scale[c] = hi[c] - lo[c];
    }
    d.from_metadata = true;
    d.range_text = text;
  }
  return d;
}

std::string map_units(const MapDecoding& d) {
  switch (d.kind) {
    case MapKind::height:
    case MapKind::position: return d.from_metadata ? "scene units" : "value";
    case MapKind::curvature: return d.from_metadata ? "1/scene units" : "value";
    case MapKind::ao:
    case MapKind::thickness: return "share";
    case MapKind::vertex_color: return "rgb";
    case MapKind::object_id:
    case MapKind::material_id: return "texels";
    default: return "deg";
  }
}

MapTolerances default_map_tolerances(const MapDecoding& a) {
  double range = 1.0;
  if (a.from_metadata)
    range = std::max({std::abs(a.scale[0]), a.kind == MapKind::position ? std::abs(a.scale[1]) : 0.0,
                      a.kind == MapKind::position ? std::abs(a.scale[2]) : 0.0});
  MapTolerances t;
  t.max_mean = 0.005 * range;
  t.max_p99 = 0.01 * range;
  t.max_abs = 0.02 * range;
  t.max_share = 0.0;
  return t;
}

MapDiffStats compare_maps(const Image& a, const Image& b_in, const MapDiffOptions& options, AngleField* field) {
  const MapKind kind = options.decoding_a.kind;
  assert(options.decoding_b.kind == kind);
  const MapFamily family = map_family(kind);
  assert(family != MapFamily::normal);
  const int needed = channels_needed(kind);
  for (const auto& [m, name] : {std::pair<const Image*, const char*>{&a, "map A"}, {&b_in, "map B"}}) {
    if (m->width <= 0 || m->height <= 0 || m->pixels.empty()) throw InputError(std::string(name) + ": empty image");
    if (m->channels < needed)
      throw InputError(std::string(name) + ": has " + std::to_string(m->channels) + " channel(s); " +
                       with_article(map_name(kind)) + " map needs " + (needed == 1 ? "one" : "RGB"));
  }
  const bool resized = a.width != b_in.width || a.height != b_in.height;
  // An ID colour is never blended: the nearest texel whatever mode was asked.
  const Resample mode = family == MapFamily::id ? Resample::nearest : options.resample;
  Image resampled;
  const Image& b = comparable_b(a, b_in, options.resample, mode, options.mask, resampled);
  const std::size_t texels = static_cast<std::size_t>(a.width) * a.height;

  // A map without its range (e.g. re-saved by an editor) is taken to share the other's.
  const MapDecoding& given_a = options.decoding_a;
  const MapDecoding& given_b = options.decoding_b;
  const MapDecoding& da = !given_a.from_metadata && given_b.from_metadata ? given_b : given_a;
  const MapDecoding& db = !given_b.from_metadata && given_a.from_metadata ? given_a : given_b;

  MapDiffStats s;
  s.kind = kind;
  s.units = map_units(da);
  s.width = a.width;
  s.height = a.height;
  if (field) {
    field->width = a.width;
    field->height = a.height;
    field->degrees.assign(texels, -1.0f);
  }
  if (resized && family == MapFamily::id && options.resample != Resample::nearest)
    s.warnings.push_back("ID colours are never blended: B resampled by the nearest texel");

  // Select, decode and measure each texel.
  DiffTally tally;  // in the map's units, or 0/1 per ID texel
  tally.values.reserve(texels);
  for (std::size_t i = 0; i < texels; ++i) {
    const float* pa = &a.pixels[i * a.channels];
    const float* pb = &b.pixels[i * b.channels];
    const TexelSelection sel = select_texel(a, b, i, options.mask, options.use_alpha, options.include_padding);
    if (count_skipped(sel, s)) continue;
    bool finite = true;
    for (int c = 0; c < needed; ++c) finite = finite && std::isfinite(pa[c]) && std::isfinite(pb[c]);
    if (sel == TexelSelection::padding) ++s.padding_compared;
    if (!finite) {
      ++s.nonfinite_texels;
      if (field) field->degrees[i] = std::numeric_limits<float>::max();  // shown as the worst
      continue;
    }
    double d = 0.0;
    if (family == MapFamily::id) {
      // ID colours are in 8-bit steps: equal when every channel rounds to the same step, so an
      // 8-bit PNG and a 16-bit or float copy of it agree.
      for (int c = 0; c < 3; ++c)
        if (std::lround(double(pa[c]) * 255.0) != std::lround(double(pb[c]) * 255.0)) d = 1.0;
      s.texels_differing += d > 0.0;
    } else {
      for (int c = 0; c < needed; ++c) {
        const double va = da.offset[c] + double(pa[c]) * da.scale[c];
        const double vb = db.offset[c] + double(pb[c]) * db.scale[c];
        d = std::max(d, std::abs(va - vb));
      }
    }
    if (field) field->degrees[i] = static_cast<float>(d);
    tally.add(i, a.width, d);
  }

  // Statistics.
  s.texels_compared = tally.values.size() + s.nonfinite_texels;
  s.max = tally.max;
  s.worst_x = tally.worst_x, s.worst_y = tally.worst_y;
  if (!tally.values.empty()) {
    const DiffTally::Summary m = tally.summary();
    s.mean = m.mean, s.rms = m.rms, s.p95 = m.p95, s.p99 = m.p99;
  }
  if (s.texels_compared > 0) s.share_differing = double(s.texels_differing) / double(s.texels_compared);
  const MapTolerances& t = options.tolerances;
  const bool met = family == MapFamily::id ? s.share_differing <= t.max_share
                                           : s.mean <= t.max_mean && s.p99 <= t.max_p99 && s.max <= t.max_abs;
  s.within = s.texels_compared > 0 && s.nonfinite_texels == 0 && met;
  if (s.texels_compared == 0) s.warnings.push_back("no texels compared: nothing is within tolerance");
  if (s.nonfinite_texels > 0)
    s.warnings.push_back(std::to_string(s.nonfinite_texels) +
                         " texel(s) hold a value that is not a number (NaN or infinity) in A or B: not in the statistics, "
                         "and the maps differ");
  if (family == MapFamily::grey && (kind == MapKind::height || kind == MapKind::position || kind == MapKind::curvature)) {
    const char* key = kind == MapKind::height     ? "nmbake:height_range"
                      : kind == MapKind::position ? "nmbake:position_box"
                                                  : "nmbake:curvature_scale";
    if (given_a.from_metadata != given_b.from_metadata)
      s.warnings.push_back(std::string("map ") + (given_a.from_metadata ? "B" : "A") + " has no " + key +
                           ": decoded with the other map's (" + da.range_text + ")");
    else if (!given_a.from_metadata)
      s.warnings.push_back(std::string("neither map has ") + key + ": compared as stored values in [0,1], not in " +
                           (kind == MapKind::curvature ? "1/scene units" : "scene units"));
  }
  return s;
}

std::string map_summary_line(const MapDiffStats& s) {
  std::string units = s.units;
  std::replace(units.begin(), units.end(), ' ', '-');
  std::string line = std::string("map=") + map_name(s.kind) + " units=" + units;
  if (map_family(s.kind) == MapFamily::id)
    line += " differing=" + std::to_string(s.texels_differing) + " share=" + number_text(s.share_differing);
  else line += " mean=" + number_text(s.mean) + " p99=" + number_text(s.p99) + " max=" + number_text(s.max);
  return line + " texels=" + std::to_string(s.texels_compared) + " within=" + (s.within ? "1" : "0");
}

}  // namespace nmbake::diff
