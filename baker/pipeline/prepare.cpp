#include "pipeline/prepare.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/bounds.h"
#include "core/mesh_topology.h"
#include "core/parallel.h"
#include "raycast.h"

namespace nmbake {

namespace {

// `spare` more elements of capacity than of size: room that Embree's 16-byte loads past the last
// vertex may read when it takes the positions in place (build_high_scene's `share`).
std::vector<glm::vec3> recentre(const std::vector<glm::vec3>& pts, const glm::dvec3& c, std::size_t spare = 0) {
  std::vector<glm::vec3> out;
  touch_storage(0, storage_for(out, pts.size() + spare));  // its pages first touched on every core
  out.resize(pts.size());
  parallel_chunks(0, pts.size(), std::size_t(1) << 16, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) out[i] = glm::vec3(glm::dvec3(pts[i]) - c);
  });
  return out;
}

std::vector<glm::vec3> position_averaged_normals(const Mesh& low, const TangentFrames& frames,
                                                 const std::vector<std::uint32_t>& weld, std::size_t np) {
  // A position whose corners all use one normal keeps it bit for bit; one with several gets the
  // normalized mean over its corners (a normal shared by more faces weighs more).
  std::vector<glm::vec3> out(np, glm::vec3(0, 0, 1));
  std::vector<std::uint8_t> state(np, 0);  // 0 unseen, 1 one normal so far, 2 several
  for (std::size_t c = 0; c < low.position_index.size(); ++c) {
    const std::uint32_t p = weld[low.position_index[c]];
    if (state[p] == 0) {
      state[p] = 1;
      out[p] = frames.normal[c];
    } else if (frames.normal[c] != out[p]) {
      state[p] = 2;
    }
  }
  std::vector<glm::dvec3> sum(np, glm::dvec3(0.0));
  for (std::size_t c = 0; c < low.position_index.size(); ++c)
    if (state[weld[low.position_index[c]]] == 2) sum[weld[low.position_index[c]]] += glm::dvec3(frames.normal[c]);
  for (std::size_t p = 0; p < np; ++p) {
    const double len = glm::length(sum[p]);
    if (state[p] == 2 && len > 1e-12) out[p] = glm::vec3(sum[p] / len);
  }
  return out;
}

// Ray normals: one per position, the normalized mean of its corners' normals (a normal shared by
// more corners weighs more), so split normals (hard edges) open no gaps between the rays of
// neighbouring faces. Positions are welded by value first: glTF-style files split hard edges into
// separate vertices.
std::vector<glm::vec3> position_averaged_normals(const Mesh& low, const TangentFrames& frames) {
  std::size_t np = 0;
  const std::vector<std::uint32_t> weld = weld_positions(low.positions, &np);
  const std::vector<glm::vec3> welded = position_averaged_normals(low, frames, weld, np);
  std::vector<glm::vec3> out(low.positions.size());
  for (std::size_t p = 0; p < out.size(); ++p) out[p] = welded[weld[p]];
  return out;
}

// Triangle t's raycast::HitRule::facing code: the side its corner normals `c` (3) point to, + that of
// cross(p1 - p0, p2 - p0) (also where that cannot be told: no area, normals that cancel), and how far
// they lean from the face.
std::int8_t facing_of(const std::vector<glm::vec3>& pos, const std::uint32_t* corners, const glm::vec3* c) {
  const glm::vec3 p0 = pos[corners[0]], p1 = pos[corners[1]], p2 = pos[corners[2]];
  glm::vec3 f = glm::cross(p1 - p0, p2 - p0);
  const int sign = glm::dot(f, c[0] + c[1] + c[2]) < 0.0f ? -1 : 1;
  const float f2 = glm::dot(f, f);
  double lean = 2.0;  // unknown
  if (f2 > 0.0f) {
    f *= float(sign) / std::sqrt(f2);
    lean = 0.0;
    for (int k = 0; k < 3 && lean < 1.0; ++k) {
      const float n2 = glm::dot(c[k], c[k]);
      // The sine of the angle from the face, rounded up by a little for the float arithmetic;
      // a normal past 90 degrees (or of no length) leaves it unknown.
      if (!(n2 > 0.0f) || !(glm::dot(c[k], f) > 0.0f)) lean = 2.0;
      else lean = std::max(lean, double(glm::length(glm::cross(c[k], f)) / std::sqrt(n2)) + 1e-4);
    }
  }
  return raycast::facing_code(sign, lean);
}

// Per triangle, facing_of its corner normals (3 per triangle).
std::vector<std::int8_t> triangle_facing(const std::vector<glm::vec3>& pos, const std::vector<std::uint32_t>& index,
                                         const CornerNormals& corner_normals) {
  std::vector<std::int8_t> out(index.size() / 3);
  parallel_chunks(0, out.size(), 65536, [&](std::size_t t0, std::size_t t1) {
    for (std::size_t t = t0; t < t1; ++t) out[t] = facing_of(pos, &index[3 * t], &corner_normals[3 * t]);
  });
  return out;
}

// A cage must enclose the low-poly: one whose vertices mostly lie inside it (moved against the ray
// normals) is refused.
void check_cage_encloses(const Prepared& s, const Mesh& cage) {
  std::vector<std::uint8_t> used(s.low_pos.size(), 0);
  for (std::uint32_t i : cage.position_index) used[i] = 1;
  std::size_t inside = 0, outside = 0;
  const double tiny = 1e-6 * s.diagonal;
  for (std::size_t i = 0; i < used.size(); ++i) {
    if (!used[i]) continue;
    const double off = glm::dot(glm::dvec3(s.cage_pos[i]) - glm::dvec3(s.low_pos[i]), glm::dvec3(s.ray_normal[i]));
    inside += off < -tiny;
    outside += off > tiny;
  }
  if (inside > outside)
    throw InputError(cage.source + ": the cage lies inside the low-poly (" + std::to_string(inside) + " of " +
                     std::to_string(inside + outside) +
                     " moved vertices are moved inwards along the normals); a cage must enclose it");
}

}  // namespace

// The cage's corners, re-centred, 3 per low-poly triangle (its topology is the low-poly's: 3
// position indices per triangle).
void attach_cage(Prepared& s, const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& index) {
  s.cage_pos = recentre(positions, s.centre);
  s.cage_tris.resize(index.size() / 3);
  for (std::size_t t = 0; t < s.cage_tris.size(); ++t)
    for (int c = 0; c < 3; ++c) s.cage_tris[t].corner[c] = glm::dvec3(s.cage_pos[index[3 * t + c]]);
}

// The cage triangles' rear and search distances: per vertex (LocalDistances) when measured, else
// the one rear distance and no search beyond the cage.
void set_cage_reach(Prepared& s, const Mesh& low, double rear, const std::vector<float>& vertex_rear,
                    const std::vector<float>& vertex_search) {
  for (std::size_t t = 0; t < s.cage_tris.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t v = low.position_index[3 * t + c];
      s.cage_tris[t].rear[c] = vertex_rear.empty() ? rear : double(vertex_rear[v]);
      s.cage_tris[t].search[c] = vertex_search.empty() ? 0.0 : double(vertex_search[v]);
    }
}

// Everything the rays and the shading read, from the meshes (prepare.h).
Prepared prepare(const Mesh& low, const Mesh& high, const Mesh* cage, BakeStats& st) {
  Prepared s;
  s.low_object = low.triangle_object.empty() ? nullptr : low.triangle_object.data();
  s.low_objects = low.object_count();
  s.high_objects = high.object_count();
  s.frames = compute_tangent_frames(low);
  st.prepare.degenerate_uv_triangles = s.frames.degenerate_uv_triangles;
  st.prepare.degenerate_3d_triangles = s.frames.degenerate_3d_triangles;
  st.prepare.corners_without_tangent = s.frames.corners_without_tangent;
  {
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    grow_box(lo, hi, low.positions, low.position_index);
    grow_box(lo, hi, high.positions, high.position_index);
    // Not the cage's: an automatic cage is made after this, and the same cage read from a file
    // must give the same centre, so the same rays to the bit.
    s.centre = 0.5 * (lo + hi);
    st.prepare.centre = s.centre;
    s.diagonal = glm::length(hi - lo);
    if (!(s.diagonal > 0.0)) s.diagonal = 1.0;
    // Float spacing at the largest coordinate: the precision the inputs carry (float positions).
    const glm::dvec3 far = glm::max(glm::abs(lo), glm::abs(hi));
    const float largest = float(std::max({far.x, far.y, far.z}));
    st.prepare.largest_coordinate = largest;
    st.prepare.coordinate_spacing =
        double(std::nextafter(largest, std::numeric_limits<float>::infinity()) - largest) / s.diagonal;
  }
  s.low_pos = recentre(low.positions, s.centre);
  s.high_pos = recentre(high.positions, s.centre, 1);
  s.ray_normal = position_averaged_normals(low, s.frames);
  if (high.has_normals()) {
    // The file's normals per corner and, from them while they are at hand, the facing codes: one
    // pass over the triangles (two read the corner normals twice, a memory-bound 0.14 s at 4M
    // triangles that a second thread did not shorten here).
    touch_storage(0, storage_for(s.high_facing, high.triangle_count()));  // as recentre's
    s.high_corner_normals.resize(high.normal_index.size());
    s.high_facing.resize(high.triangle_count());
    parallel_chunks(0, high.triangle_count(), std::size_t(1) << 15, [&](std::size_t begin, std::size_t end) {
      for (std::size_t t = begin; t < end; ++t) {
        glm::vec3* n = &s.high_corner_normals[3 * t];
        for (int c = 0; c < 3; ++c) n[c] = high.normals[high.normal_index[3 * t + std::size_t(c)]];
        s.high_facing[t] = facing_of(s.high_pos, &high.position_index[3 * t], n);
      }
    });
  } else {
    // Welded by value, duplicate faces once, one winding per piece (mesh_topology.h).
    s.high_corner_normals.resize(3 * high.triangle_count());
    compute_high_corner_normals(high, s.high_corner_normals.data(), &st.prepare.high_topology.emplace());
    s.high_facing = triangle_facing(s.high_pos, high.position_index, s.high_corner_normals);
  }
  s.low_tris.resize(low.triangle_count());
  for (std::size_t t = 0; t < low.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t pi = low.position_index[3 * t + c];
      s.low_tris[t].p[c] = glm::dvec3(s.low_pos[pi]);
      s.low_tris[t].ray_n[c] = glm::dvec3(s.ray_normal[pi]);
      s.low_tris[t].n[c] = glm::dvec3(s.frames.normal[3 * t + c]);
      s.low_tris[t].t[c] = glm::dvec4(s.frames.tangent[3 * t + c]);
    }
  if (cage) {
    attach_cage(s, cage->positions, cage->position_index);
    check_cage_encloses(s, *cage);
  }
  for (std::size_t t = 0; t < low.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) {
      const glm::vec2 uv = low.corner_uv(t, c);
      if (uv.x < 0.0f || uv.x > 1.0f || uv.y < 0.0f || uv.y > 1.0f) {
        ++st.prepare.uv_outside_triangles;
        glm::vec2 lo = uv, hi = uv;
        for (int k = 0; k < 3; ++k) lo = glm::min(lo, low.corner_uv(t, k)), hi = glm::max(hi, low.corner_uv(t, k));
        st.prepare.uv_outside_entirely_triangles += hi.x < 0.0f || lo.x > 1.0f || hi.y < 0.0f || lo.y > 1.0f;
        break;
      }
    }
  return s;
}

std::vector<glm::vec3> low_ray_normals(const Mesh& low) { return position_averaged_normals(low, compute_tangent_frames(low)); }

}  // namespace nmbake
