#include "core/curvature.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/image.h"
#include "core/mesh_topology.h"
#include "core/parallel.h"

namespace nmbake {

namespace {

enum FaceState : std::uint8_t { kGood, kZeroArea, kCollapsed, kDuplicate };

// The welded mesh: corners as welded ids, each face's state, and the faces around each vertex.
struct Welded {
  std::size_t vertices = 0;
  std::vector<std::uint32_t> weld;        // per position
  const std::uint32_t* corner = nullptr;  // 3 per triangle: the mesh's position_index when welding changed nothing, else own
  std::vector<std::uint32_t> own_corner;
  std::vector<std::uint8_t> state;   // per triangle, FaceState
  std::vector<std::uint32_t> first;  // vertices + 1 offsets into `faces`
  std::vector<std::uint32_t> faces;  // the non-collapsed faces around each vertex, in face order
};

constexpr std::size_t kFaceChunk = 1 << 14;    // faces a thread takes at once
constexpr std::size_t kVertexChunk = 1 << 13;  // vertices a thread takes at once

bool finite(const glm::vec3& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

Welded weld_mesh(const Mesh& m, int threads) {
  Welded w;
  w.weld = weld_positions(m.positions, &w.vertices);
  const std::size_t tris = m.triangle_count();
  // A mesh whose positions are all distinct (an indexed PLY) welds to itself: its own indices serve.
  bool same = w.vertices == m.positions.size();
  for (std::size_t i = 0; same && i < w.weld.size(); ++i) same = w.weld[i] == i;
  if (!same) w.own_corner.resize(3 * tris);
  w.corner = same ? m.position_index.data() : w.own_corner.data();
  w.state.resize(tris);
  parallel_chunks(threads, tris, kFaceChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t) {
      if (!same)
        for (int k = 0; k < 3; ++k) w.own_corner[3 * t + k] = w.weld[m.position_index[3 * t + k]];
      const std::uint32_t* c = &w.corner[3 * t];
      const bool ok = c[0] != c[1] && c[1] != c[2] && c[0] != c[2] && finite(m.corner_position(t, 0)) &&
                      finite(m.corner_position(t, 1)) && finite(m.corner_position(t, 2));
      w.state[t] = ok ? kGood : kCollapsed;
    }
  });
  w.first.assign(w.vertices + 1, 0);
  for (std::size_t t = 0; t < tris; ++t)
    if (w.state[t] != kCollapsed)
      for (int k = 0; k < 3; ++k) ++w.first[w.corner[3 * t + k] + 1];
  for (std::size_t v = 0; v < w.vertices; ++v) w.first[v + 1] += w.first[v];
  w.faces.resize(w.first[w.vertices]);
  std::vector<std::uint32_t> fill(w.first.begin(), w.first.end() - 1);
  for (std::size_t t = 0; t < tris; ++t) {
    if (w.state[t] == kCollapsed) continue;
    for (int k = 0; k < 3; ++k) w.faces[fill[w.corner[3 * t + k]]++] = std::uint32_t(t);
  }
  // A repeated face is found at its lowest vertex, among the earlier faces listed there. A face is
  // a repeat when any earlier face has its three vertices (the first of them is not itself a
  // repeat, and it is listed there too): each face is decided on its own, on every thread.
  // The faces listed at the lowest vertex all have it, and three distinct corners: such a face
  // repeats this one when it also has the other two.
  parallel_chunks(threads, tris, kFaceChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t) {
      if (w.state[t] == kCollapsed) continue;
      const std::uint32_t* c = &w.corner[3 * t];
      const std::uint32_t low = std::min({c[0], c[1], c[2]});
      const std::uint32_t a = c[0] == low ? c[1] : c[0], b = c[2] == low ? c[1] : c[2];
      for (std::uint32_t i = w.first[low]; i < w.first[low + 1] && w.faces[i] < t; ++i) {
        const std::uint32_t* o = &w.corner[3 * std::size_t(w.faces[i])];
        const bool has_a = o[0] == a || o[1] == a || o[2] == a, has_b = o[0] == b || o[1] == b || o[2] == b;
        if (has_a && has_b) {
          w.state[t] = kDuplicate;
          break;
        }
      }
    }
  });
  return w;
}

// In `out`, sorted, the other corners of every kept face at `v` (a neighbour once per face).
void sorted_neighbours(const Welded& w, std::uint32_t v, std::vector<std::uint32_t>& out) {
  out.clear();
  for (std::uint32_t i = w.first[v]; i < w.first[v + 1]; ++i) {
    const std::uint32_t t = w.faces[i];
    if (w.state[t] == kDuplicate) continue;
    for (int k = 0; k < 3; ++k)
      if (w.corner[3 * t + k] != v) out.push_back(w.corner[3 * t + k]);
  }
  std::sort(out.begin(), out.end());
}

// The distinct vertices sharing a kept face with `v`, each with how many kept faces share the edge.
void edge_neighbours(const Welded& w, std::uint32_t v, std::vector<std::uint32_t>& scratch,
                     std::vector<std::pair<std::uint32_t, int>>& out) {
  sorted_neighbours(w, v, scratch);
  out.clear();
  for (std::size_t i = 0; i < scratch.size();) {
    std::size_t j = i;
    while (j < scratch.size() && scratch[j] == scratch[i]) ++j;
    out.emplace_back(scratch[i], int(j - i));
    i = j;
  }
}

// Whether some edge at `v` is not shared by exactly two kept faces (edge_neighbours' counts, not
// all 2): its neighbours, sorted, must come in pairs of one vertex each.
bool on_border(const Welded& w, std::uint32_t v, std::vector<std::uint32_t>& scratch) {
  sorted_neighbours(w, v, scratch);
  const std::size_t n = scratch.size();
  if (n % 2) return true;
  for (std::size_t i = 0; i < n; i += 2)
    if (scratch[i] != scratch[i + 1] || (i + 2 < n && scratch[i + 2] == scratch[i])) return true;
  return false;
}

// Sums per vertex over the non-degenerate faces: twice the area gradient (the cotangent terms),
// the area-weighted normal (twice the area), and the mixed area.
struct Sums {
  std::vector<glm::dvec3> laplace, normal;
  std::vector<double> area;
};

// One pass over the faces in order, each adding its terms to its three vertices (a gather per
// vertex would give the same sums but compute each face three times: this pass is the cheaper one,
// and runs beside the trace's preparation). A zero-area face has no normal and no area gradient: it
// is marked and contributes nothing.
Sums accumulate(const Mesh& m, Welded& w) {
  Sums s;
  s.laplace.assign(w.vertices, glm::dvec3(0.0));
  s.normal.assign(w.vertices, glm::dvec3(0.0));
  s.area.assign(w.vertices, 0.0);
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    if (w.state[t] != kGood) continue;
    const glm::dvec3 p[3] = {glm::dvec3(m.corner_position(t, 0)), glm::dvec3(m.corner_position(t, 1)),
                             glm::dvec3(m.corner_position(t, 2))};
    const glm::dvec3 e[3] = {p[2] - p[1], p[0] - p[2], p[1] - p[0]};  // e[k]: the edge opposite corner k
    const glm::dvec3 cross = glm::cross(e[2], -e[1]);
    const double len = glm::length(cross);
    if (!(len > 0.0) || !std::isfinite(len)) {
      w.state[t] = kZeroArea;
      continue;
    }
    const glm::dvec3 n = cross / len;
    const double area = 0.5 * len;
    // Corner k's dot product of its two edges: negative at an obtuse corner; cot = dot / len.
    const double dot[3] = {-glm::dot(e[2], e[1]), -glm::dot(e[0], e[2]), -glm::dot(e[1], e[0])};
    const int obtuse = dot[0] < 0.0 ? 0 : dot[1] < 0.0 ? 1 : dot[2] < 0.0 ? 2 : -1;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = w.corner[3 * t + std::size_t(k)];
      // (cot a + cot b)-weighted edges of this face at corner k, in closed form: n x (opposite edge),
      // whose length is the opposite edge's however thin the face.
      s.laplace[v] += glm::cross(n, e[k]);
      s.normal[v] += cross;
      double mixed;
      if (obtuse < 0) {
        // Voronoi area: |edge to corner k+1|^2 cot(corner k+2) + |edge to corner k+2|^2 cot(corner k+1), over 8.
        const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
        mixed = (glm::dot(e[k2], e[k2]) * dot[k2] + glm::dot(e[k1], e[k1]) * dot[k1]) / (8.0 * len);
        mixed = std::clamp(mixed, 0.0, area);
      } else {
        mixed = obtuse == k ? 0.5 * area : 0.25 * area;
      }
      s.area[v] += mixed;
    }
  }
  return s;
}

// The area-weighted mean over each vertex's faces of the faces' mean corner value, `passes` times;
// each vertex's sums gathered over its faces in face order (the same sums on any number of threads).
// A face's weighted value is worked out once per pass, not once per corner.
void smooth(const Welded& w, const double* face_area, int passes, int threads, std::vector<double>& h) {
  std::vector<double> next(w.vertices);
  std::vector<double, DefaultInitAllocator<double>> face_value(w.state.size());  // written for every kept face
  for (int pass = 0; pass < passes; ++pass) {
    parallel_chunks(threads, w.state.size(), kFaceChunk, [&](std::size_t begin, std::size_t end) {
      for (std::size_t t = begin; t < end; ++t) {
        if (w.state[t] != kGood) continue;
        const std::uint32_t* c = &w.corner[3 * t];
        face_value[t] = face_area[t] * (h[c[0]] + h[c[1]] + h[c[2]]) / 3.0;
      }
    });
    parallel_chunks(threads, w.vertices, kVertexChunk, [&](std::size_t begin, std::size_t end) {
      for (std::size_t v = begin; v < end; ++v) {
        double sum = 0.0, weight = 0.0;
        for (std::uint32_t i = w.first[v]; i < w.first[v + 1]; ++i) {
          const std::uint32_t t = w.faces[i];
          if (w.state[t] != kGood) continue;
          sum += face_value[t];
          weight += face_area[t];
        }
        next[v] = weight > 0.0 ? sum / weight : h[v];
      }
    });
    h.swap(next);
  }
}

}  // namespace

std::vector<float> vertex_mean_curvature(const Mesh& mesh, const CurvatureOptions& opt, CurvatureStats* stats) {
  CurvatureStats st;
  const int threads = opt.threads;
  Welded w = weld_mesh(mesh, threads);
  st.welded_vertices = w.vertices;
  Sums s = accumulate(mesh, w);

  // Interior vertices: every edge shared by exactly two kept faces. H = K.n / 2 with
  // K = laplace / (2 area): the normal part of the mean-curvature normal, whose tangential part on
  // an irregular mesh is discretisation error. 0 where it has no meaning yet.
  std::vector<std::uint8_t, DefaultInitAllocator<std::uint8_t>> border(w.vertices);  // written for every vertex
  std::vector<double> h(w.vertices, 0.0);
  std::vector<std::uint8_t> valued(w.vertices, 0);
  parallel_chunks(threads, w.vertices, kVertexChunk, [&](std::size_t begin, std::size_t end) {
    std::vector<std::uint32_t> scratch;
    for (std::size_t v = begin; v < end; ++v) {
      border[v] = on_border(w, std::uint32_t(v), scratch);
      const double nlen = glm::length(s.normal[v]);
      if (border[v] || !(s.area[v] > 0.0) || !(nlen > 0.0) || !std::isfinite(nlen)) continue;
      const double value = glm::dot(s.laplace[v], s.normal[v] / nlen) / (4.0 * s.area[v]);
      if (!std::isfinite(value)) continue;
      h[v] = value;
      valued[v] = 1;
    }
  });
  for (std::size_t v = 0; v < w.vertices; ++v) st.border_vertices += border[v];
  s = Sums();  // freed now: the smoothing's buffers reuse the memory (no fresh pages to zero)

  // The others from their neighbours: first those next to a valued vertex, then those next to one
  // of these (a grid's corner), each the plain mean of the distinct neighbours valued before it.
  std::vector<double, DefaultInitAllocator<double>> fill(w.vertices);  // read only where `filled`, written each round
  std::vector<std::uint8_t> filled(w.vertices);
  for (std::uint8_t round = 2; round <= 3; ++round) {
    parallel_chunks(threads, w.vertices, kVertexChunk, [&](std::size_t begin, std::size_t end) {
      std::vector<std::uint32_t> scratch;
      std::vector<std::pair<std::uint32_t, int>> nb;
      for (std::size_t v = begin; v < end; ++v) {
        filled[v] = 0;
        if (valued[v] || w.first[v] == w.first[v + 1]) continue;
        edge_neighbours(w, std::uint32_t(v), scratch, nb);
        double sum = 0.0;
        int count = 0;
        for (const auto& e : nb) {
          if (valued[e.first] == 0 || valued[e.first] >= round) continue;
          sum += h[e.first];
          ++count;
        }
        if (count == 0) continue;
        filled[v] = 1;
        fill[v] = sum / count;
      }
    });
    for (std::size_t v = 0; v < w.vertices; ++v)
      if (filled[v]) h[v] = fill[v], valued[v] = round;
  }
  for (std::size_t v = 0; v < w.vertices; ++v) st.unvalued_vertices += valued[v] == 0;

  if (opt.smoothing > 0) {
    std::vector<double, DefaultInitAllocator<double>> face_area(mesh.triangle_count());  // read for kept faces only
    parallel_chunks(threads, mesh.triangle_count(), kFaceChunk, [&](std::size_t begin, std::size_t end) {
      for (std::size_t t = begin; t < end; ++t) {
        if (w.state[t] != kGood) continue;
        const glm::dvec3 p0(mesh.corner_position(t, 0));
        face_area[t] = 0.5 * glm::length(glm::cross(glm::dvec3(mesh.corner_position(t, 1)) - p0,
                                                    glm::dvec3(mesh.corner_position(t, 2)) - p0));
      }
    });
    smooth(w, face_area.data(), opt.smoothing, threads, h);
  }

  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    st.degenerate_faces += w.state[t] == kZeroArea || w.state[t] == kCollapsed;
    st.duplicate_faces += w.state[t] == kDuplicate;
  }
  std::vector<float> out(mesh.positions.size());
  parallel_chunks(threads, out.size(), kVertexChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const double value = h[w.weld[i]];
      out[i] = std::isfinite(value) ? float(std::clamp(value, double(-FLT_MAX), double(FLT_MAX))) : 0.0f;
    }
  });
  if (stats) *stats = st;
  return out;
}

}  // namespace nmbake
