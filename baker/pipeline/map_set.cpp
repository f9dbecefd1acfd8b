#include "pipeline/map_set.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/curvature.h"
#include "core/fnv.h"
#include "core/padding.h"
#include "core/parallel.h"

namespace nmbake {

namespace {

constexpr std::size_t kTexelChunk = 1 << 16;  // texels a thread takes at once in finish_maps

std::string number(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

std::uint64_t name_hash(const std::string& name) {
  std::uint64_t h = fnv1a64(name);
  h ^= h >> 29;  // spread the last characters into the high bits
  h *= 0xbf58476d1ce4e5b9ull;
  return h ^ (h >> 32);
}

// Hue, saturation and value to RGB, each in [0, 1].
glm::dvec3 hsv(double h, double s, double v) {
  const double k[3] = {5.0, 3.0, 1.0};
  glm::dvec3 out;
  for (int c = 0; c < 3; ++c) {
    const double x = std::fmod(k[c] + h * 6.0, 6.0);
    out[c] = v - v * s * std::max(0.0, std::min({x, 4.0 - x, 1.0}));
  }
  return out;
}

// The covered texels' values of a one-channel image.
std::vector<double> covered_values(const Image& img, const std::vector<std::uint8_t>& coverage) {
  std::vector<double> v;
  for (std::size_t i = 0; i < coverage.size(); ++i)
    if (coverage[i]) v.push_back(img.pixels[i]);
  return v;
}

// Mean and 95th percentile of the covered texels of a standard-error image.
void error_summary(const Image& err, const std::vector<std::uint8_t>& coverage, BakedMap& out) {
  std::vector<double> v = covered_values(err, coverage);
  if (v.empty()) {
    out.error_mean = out.error_p95 = 0.0;
    return;
  }
  double sum = 0.0;
  for (double e : v) sum += e;
  out.error_mean = sum / double(v.size());
  const std::size_t k = std::min(v.size() - 1, std::size_t(std::ceil(0.95 * double(v.size()))) - 1);
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  out.error_p95 = v[k];
}

// Mean and most of the covered texels of a rays-per-texel image (--ao-rays auto); none: -1.
void rays_summary(const Image& rays, const std::vector<std::uint8_t>& coverage, BakedMap& out) {
  if (rays.pixels.empty()) return;
  const std::vector<double> v = covered_values(rays, coverage);
  double sum = 0.0, most = 0.0;
  for (double n : v) sum += n, most = std::max(most, n);
  out.rays_mean = v.empty() ? 0.0 : sum / double(v.size());
  out.rays_max = most;
}

// The names of the high-poly's objects (one: the file's name) and materials (none: one, "").
std::vector<std::string> object_names(const Mesh& high) {
  std::vector<std::string> names;
  for (const Mesh::Object& o : high.objects) names.push_back(o.name);
  if (names.empty()) names.push_back(high.source);
  return names;
}
std::vector<std::string> material_names(const Mesh& high) {
  std::vector<std::string> names = high.materials;
  if (names.empty()) names.push_back("");
  return names;
}

}  // namespace

glm::vec3 id_color(const std::string& name) {
  const std::uint64_t h = name_hash(name);
  const double hue = double(h & 0xffffu) / 65536.0;
  const double sat = 0.55 + 0.45 * double((h >> 16) & 0xffu) / 255.0;
  const double val = 0.65 + 0.35 * double((h >> 24) & 0xffu) / 255.0;
  const glm::dvec3 c = hsv(hue, sat, val);
  return glm::vec3(glm::round(c * 255.0) / 255.0);
}

std::vector<glm::vec3> id_colors(const std::vector<std::string>& names) {
  std::vector<std::size_t> order(names.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return names[a] < names[b]; });
  std::vector<glm::vec3> out(names.size()), taken;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t i = order[k];
    if (k > 0 && names[i] == names[order[k - 1]]) {  // one name, one colour
      out[i] = out[order[k - 1]];
      continue;
    }
    glm::vec3 c = id_color(names[i]);
    for (int salt = 1; std::find(taken.begin(), taken.end(), c) != taken.end(); ++salt)
      c = id_color(names[i] + "#" + std::to_string(salt));
    taken.push_back(c);
    out[i] = c;
  }
  return out;
}

std::vector<float> map_curvature(const BakeOptions& opt, const Mesh& high) {
  return opt.maps.wants(MapKind::curvature)
             ? vertex_mean_curvature(high, CurvatureOptions{opt.maps.curvature_smoothing, opt.threads})
             : std::vector<float>();
}

MapInputs make_map_inputs(const BakeOptions& opt, const Prepared& s, const HighScene& scene, const HighSelection& selection,
                          const Mesh& high, std::vector<float> curvature) {
  MapInputs in;
  in.curvature = std::move(curvature);
  in.maps = &opt.maps;
  in.s = &s;
  in.scene = &scene;
  in.high = &high;
  in.source = selection.kept.empty() ? nullptr : selection.kept.data();
  in.object = scene.object;
  if (opt.maps.wants(MapKind::material_id) && !high.triangle_material.empty()) {  // per BVH triangle, as `object`
    in.material.resize(scene.triangles);
    for (std::size_t t = 0; t < scene.triangles; ++t) in.material[t] = high.triangle_material[in.source ? in.source[t] : t];
  }
  if (opt.maps.wants(MapKind::position)) {
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const glm::vec3& p : s.high_pos) lo = glm::min(lo, glm::dvec3(p)), hi = glm::max(hi, glm::dvec3(p));
    in.position_lo = lo, in.position_hi = hi;
  }
  if (opt.maps.wants(MapKind::object_id)) in.object_colors = id_colors(object_names(high));
  if (opt.maps.wants(MapKind::material_id)) in.material_colors = id_colors(material_names(high));
  in.ao_distance = opt.maps.ao_distance > 0.0 ? opt.maps.ao_distance : kAutoAoDistance * s.diagonal;
  in.thickness_distance = opt.maps.thickness_distance > 0.0 ? opt.maps.thickness_distance : kAutoThickness * s.diagonal;
  in.epsilon = 1e-5 * s.diagonal;
  in.space = opt.space;
  in.bitangent = opt.bitangent;
  in.green_down = opt.green_down;
  return in;
}

MapRanges map_ranges(const BakeOptions& opt, const Prepared& s, const std::vector<const MapTargets*>& raw,
                     const std::vector<const std::vector<std::uint8_t>*>& coverage) {
  MapRanges out;
  out.height_min = opt.maps.height_min, out.height_max = opt.maps.height_max;
  out.curvature_scale = opt.maps.curvature_scale;
  double r = 0.0, sum = 0.0, sq = 0.0, n = 0.0;
  for (std::size_t k = 0; k < opt.maps.maps.size(); ++k) {
    const MapKind kind = opt.maps.maps[k];
    if (kind != MapKind::height && kind != MapKind::curvature) continue;
    for (std::size_t t = 0; t < raw.size(); ++t) {
      const Image& img = raw[t]->raw[k];
      const std::vector<std::uint8_t>& cov = *coverage[t];
      for (std::size_t i = 0; i < cov.size(); ++i) {
        if (!cov[i]) continue;
        const double a = std::fabs(double(img.pixels[i]));
        if (kind == MapKind::height) r = std::max(r, a);
        else sum += a, sq += a * a, n += 1.0;
      }
    }
  }
  if (!opt.maps.height_range_given) {
    if (!(r > 0.0)) r = 1e-6 * s.diagonal;  // a flat bake: everything at 0.5
    out.height_min = -r, out.height_max = r;
  }
  if (!(out.curvature_scale > 0.0)) {
    const double mean = n > 0.0 ? sum / n : 0.0;
    out.curvature_scale = mean + std::sqrt(std::max(0.0, n > 0.0 ? sq / n - mean * mean : 0.0));
    if (!(out.curvature_scale > 0.0)) out.curvature_scale = 1.0 / std::max(s.diagonal, 1e-30);  // flat: everything at 0.5
  }
  return out;
}

std::vector<BakedMap> finish_maps(const BakeOptions& opt, const Prepared& s, const Mesh& high, const MapInputs& in,
                                  const MapRanges& ranges, MapTargets& raw, const std::vector<std::uint8_t>& coverage,
                                  int threads) {
  std::vector<BakedMap> out;
  const glm::dvec3 file_origin = high.origin + s.centre;  // re-centred + this = file coordinates
  for (std::size_t k = 0; k < opt.maps.maps.size(); ++k) {
    const MapKind kind = opt.maps.maps[k];
    if (kind == MapKind::normal) continue;
    BakedMap m;
    m.kind = kind;
    m.metadata.push_back({"nmbake:map", map_name(kind)});
    Image img = std::move(raw.raw[k]);
    const auto each = [&](auto&& f) {  // every covered texel, on every thread (each texel on its own)
      parallel_chunks(threads, coverage.size(), kTexelChunk, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
          if (coverage[i]) f(&img.pixels[i * std::size_t(img.channels)]);
      });
    };
    switch (kind) {
      case MapKind::object_normal:
      case MapKind::bent_normal:
        each([](float* p) {
          for (int c = 0; c < 3; ++c) p[c] = p[c] * 0.5f + 0.5f;
        });
        if (kind == MapKind::bent_normal) {
          rays_summary(raw.ao_rays, coverage, m);
          m.distance = in.ao_distance;
          m.metadata.push_back({"nmbake:ao_distance", number(in.ao_distance)});
        }
        break;
      case MapKind::ao:
        m.distance = in.ao_distance;
        m.metadata.push_back({"nmbake:ao_distance", number(in.ao_distance)});
        error_summary(raw.ao_error, coverage, m);
        rays_summary(raw.ao_rays, coverage, m);
        m.error = std::move(raw.ao_error);
        break;
      case MapKind::thickness:
        m.distance = in.thickness_distance;
        m.metadata.push_back({"nmbake:thickness_distance", number(in.thickness_distance)});
        error_summary(raw.thickness_error, coverage, m);
        rays_summary(raw.thickness_rays, coverage, m);
        m.error = std::move(raw.thickness_error);
        break;
      case MapKind::height: {
        const double lo = ranges.height_min, hi = ranges.height_max;
        each([&](float* p) { p[0] = float(std::clamp((double(p[0]) - lo) / (hi - lo), 0.0, 1.0)); });
        m.range_min = lo, m.range_max = hi;
        m.metadata.push_back({"nmbake:height_range", number(lo) + ":" + number(hi)});
        break;
      }
      case MapKind::curvature: {
        const double scale = ranges.curvature_scale;
        each([&](float* p) { p[0] = float(0.5 + 0.5 * std::clamp(double(p[0]) / scale, -1.0, 1.0)); });
        m.range_min = -scale, m.range_max = scale;
        m.metadata.push_back({"nmbake:curvature_scale", number(scale)});
        break;
      }
      case MapKind::position:  // encoded by the trace (TexelMaps::write)
        m.box_min = in.position_lo + file_origin, m.box_max = in.position_hi + file_origin;
        m.metadata.push_back({"nmbake:position_box", number(m.box_min.x) + "," + number(m.box_min.y) + "," + number(m.box_min.z) +
                                                         ":" + number(m.box_max.x) + "," + number(m.box_max.y) + "," +
                                                         number(m.box_max.z)});
        break;
      case MapKind::object_id:
      case MapKind::material_id: {  // coloured by the trace (TexelMaps::write)
        const std::vector<std::string> names = kind == MapKind::object_id ? object_names(high) : material_names(high);
        const std::vector<glm::vec3>& colors = kind == MapKind::object_id ? in.object_colors : in.material_colors;
        for (std::size_t i = 0; i < names.size(); ++i) m.colors.push_back({names[i], colors[i]});
        break;
      }
      case MapKind::vertex_color:
        if (!high.has_colors()) {
          m.skipped = high.source + " has no vertex colours";
          img = Image();
        }
        break;
      default: break;
    }
    m.image = std::move(img);
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace nmbake
