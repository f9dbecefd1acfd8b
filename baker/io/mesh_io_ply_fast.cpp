// The PLY reader's fast path (mesh_io_ply_types.h, parse_fast): a binary triangle mesh as sculpting
// and scanning tools write it (fixed-size vertices, then faces of three int32 or uint32 indices),
// read on every core in chunks that each write their own vertices and triangles. Everything the
// general reader checks is checked; anything it would refuse, or any layout this path does not
// take, sends the file back to it, so its messages stay the only ones.
#include <atomic>
#include <cmath>
#include <functional>
#include <iterator>

#include "core/parallel.h"
#include "io/mesh_io_ply_types.h"

namespace nmbake::mesh_io_detail::ply {

namespace {

constexpr std::size_t kChunk = std::size_t(1) << 16;  // vertices or faces per chunk

// Where each vertex value is: offset in the vertex's bytes and type; offset -1: absent.
struct VertexLayout {
  std::size_t stride = 0;
  long offset[kAlpha + 1] = {};  // by Role kX .. kAlpha; -1 for every role (vertex_layout)
  Scalar type[kAlpha + 1] = {};
};

bool vertex_layout(const Element& e, VertexLayout& v) {
  for (long& offset : v.offset) offset = -1;
  for (const Property& p : e.properties) {
    if (p.is_list) return false;
    if (p.role >= kX && p.role <= kAlpha) {
      v.offset[p.role] = long(v.stride);
      v.type[p.role] = p.type;
    }
    v.stride += scalar_size(p.type);
  }
  return v.stride > 0;
}

// The first two elements that take bytes: `vertex` and `face`, in that order.
bool elements_in_order(const Header& header, const Layout& layout) {
  const Element* order[2] = {nullptr, nullptr};
  int found = 0;
  for (const Element& e : header.elements) {
    if (e.properties.empty() || e.count == 0) continue;
    order[found++] = &e;
    if (found == 2) break;
  }
  return found == 2 && order[0] == layout.vertex && order[1] == layout.face;
}

}  // namespace

bool parse_fast(const Header& header, const Layout& layout, std::string_view data, ParsedMesh& out) {
  if (header.encoding != Encoding::binary_little_endian || !kHostLittleEndian || layout.face_texcoords ||
      !elements_in_order(header, layout))
    return false;
  const Element& vertex = *layout.vertex;
  const Element& face = *layout.face;
  VertexLayout vl;
  if (!vertex_layout(vertex, vl)) return false;
  if (face.properties.size() != 1) return false;
  const Property& list = face.properties[0];
  if (list.type != Scalar::int32 && list.type != Scalar::uint32) return false;
  const std::size_t count_bytes = scalar_size(list.count_type), face_stride = count_bytes + 12;
  const std::uint64_t vc = vertex.count, fc = face.count;
  if (vc > data.size() / vl.stride) return false;
  const std::size_t vertex_bytes = std::size_t(vc) * vl.stride;
  if (fc > (data.size() - vertex_bytes) / face_stride) return false;

  Mesh& m = out.mesh;
  out.corner_uvs = layout.vertex_uvs;
  out.corner_normals = layout.normals;
  // The arrays sized on every core: each is zeroed as it grows, and the system zeroes its fresh
  // pages first; one thread doing all of it was a fifth of the load of a 1M-triangle sculpt. The
  // pages are touched first on every core, so that the largest array, sized on one thread, only
  // writes its zeros (the fresh pages cost several times that on a virtual machine).
  touch_storage(0, storage_for(m.position_index, 3 * fc), storage_for(out.exact_positions, vc),
                storage_for(m.normal_index, out.corner_normals ? 3 * fc : 0),
                storage_for(m.uv_index, out.corner_uvs ? 3 * fc : 0), storage_for(m.positions, vc),
                storage_for(m.normals, layout.normals ? vc : 0), storage_for(m.uvs, layout.vertex_uvs ? vc : 0),
                storage_for(m.colors, layout.colors ? vc : 0), storage_for(m.source_face, fc));
  const std::function<void()> sizing[] = {
      [&] { m.position_index.resize(3 * fc); },
      [&] { out.exact_positions.resize(vc); },
      [&] {
        if (out.corner_normals) m.normal_index.resize(3 * fc);
      },
      [&] {
        if (out.corner_uvs) m.uv_index.resize(3 * fc);
      },
      [&] {
        m.positions.resize(vc);
        if (layout.normals) m.normals.resize(vc);
        if (layout.vertex_uvs) m.uvs.resize(vc);
        if (layout.colors) m.colors.resize(vc);
        m.source_face.resize(fc);
      },
  };
  parallel_chunks(0, std::size(sizing), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) sizing[i]();
  });

  std::atomic<bool> bad{false};
  const char* vbytes = data.data();
  parallel_chunks(0, std::size_t(vc), kChunk, [&](std::size_t begin, std::size_t end) {
    double value[kAlpha + 1] = {};
    if (vl.offset[kAlpha] < 0) value[kAlpha] = 1.0;  // opaque
    double scale[kAlpha + 1];
    for (int r = kX; r <= kAlpha; ++r) scale[r] = vl.offset[r] >= 0 ? color_scale(vl.type[r]) : 1.0;
    const int last = layout.colors ? kAlpha : kV;  // the colour roles cost a plain file nothing
    for (std::size_t i = begin; i < end && !bad.load(std::memory_order_relaxed); ++i) {
      const char* at = vbytes + i * vl.stride;
      for (int r = kX; r <= last; ++r)
        if (vl.offset[r] >= 0) value[r] = load_scalar(at + vl.offset[r], vl.type[r], false);
      const glm::dvec3 exact(value[kX], value[kY], value[kZ]);
      const glm::vec3 p(exact);
      const glm::vec3 n{float(value[kNx]), float(value[kNy]), float(value[kNz])};
      const glm::vec2 uv{float(value[kU]), float(value[kV])};
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(n.x) || !std::isfinite(n.y) ||
          !std::isfinite(n.z) || !std::isfinite(uv.x) || !std::isfinite(uv.y)) {
        bad = true;
        return;
      }
      m.positions[i] = p;
      out.exact_positions[i] = exact;
      if (layout.normals) m.normals[i] = n;
      if (layout.vertex_uvs) m.uvs[i] = uv;
      if (layout.colors) {
        glm::vec4 color;
        for (int k = 0; k < 4; ++k) {
          if (!std::isfinite(value[kRed + k])) {
            bad = true;
            return;
          }
          color[k] = unit_color(value[kRed + k], scale[kRed + k]);
        }
        m.colors[i] = color;
      }
    }
  });
  const char* fbytes = vbytes + vertex_bytes;
  const bool signed_index = list.type == Scalar::int32;
  parallel_chunks(0, std::size_t(fc), kChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end && !bad.load(std::memory_order_relaxed); ++f) {
      const char* at = fbytes + f * face_stride;
      if (load_scalar(at, list.count_type, false) != 3.0) {
        bad = true;
        return;
      }
      for (int k = 0; k < 3; ++k) {
        std::uint32_t u;
        std::memcpy(&u, at + count_bytes + 4 * k, 4);
        if ((signed_index && std::int32_t(u) < 0) || u >= vc) {
          bad = true;
          return;
        }
        m.position_index[3 * f + std::size_t(k)] = u;
        if (out.corner_uvs) m.uv_index[3 * f + std::size_t(k)] = u;
        if (out.corner_normals) m.normal_index[3 * f + std::size_t(k)] = u;
      }
      m.source_face[f] = std::uint32_t(f);
    }
  });
  if (bad) return false;
  out.file_faces = out.faces = std::size_t(fc);
  if (layout.vertex_uvs) out.faces_with_uvs = std::size_t(fc);
  else if (fc) out.first_face_without_uvs = "face 0";
  if (layout.normals) out.faces_with_normals = std::size_t(fc);
  out.fast_path = true;
  return true;
}

}  // namespace nmbake::mesh_io_detail::ply
