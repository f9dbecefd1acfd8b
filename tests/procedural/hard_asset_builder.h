// Internal to the hard assets: building their meshes (rings of corners stitched into walls, discs
// and annuli, flat faces with hard edges) and packing their UV islands.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/mesh.h"
#include "hard_assets.h"

namespace nmbake::procedural::detail {

struct Corner {
  std::uint32_t p = 0, n = 0, t = 0;  // position, normal, uv index
};
using Ring = std::vector<Corner>;  // a closed loop: the last corner repeats the first's position

class Builder {
 public:
  Builder(Mesh& mesh, std::vector<int>& parts, bool uvs) : m_(mesh), parts_(parts), uvs_(uvs) {}
  std::uint32_t position(const glm::dvec3& p) {
    m_.positions.push_back(glm::vec3(p));
    return std::uint32_t(m_.positions.size() - 1);
  }
  std::uint32_t normal(const glm::dvec3& n) {
    m_.normals.push_back(glm::vec3(n));
    return std::uint32_t(m_.normals.size() - 1);
  }
  std::uint32_t uv(const glm::dvec2& t) {
    if (!uvs_) return 0;
    m_.uvs.push_back(glm::vec2(t));
    return std::uint32_t(m_.uvs.size() - 1);
  }
  Corner corner(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec2& t = glm::dvec2(0.0)) {
    return {position(p), normal(n), uv(t)};
  }
  void triangle(Corner a, Corner b, Corner c, int part) {
    add(a, b, c, part);
    ++face_;
  }
  void quad(Corner a, Corner b, Corner c, Corner d, int part) {  // a b c d counter-clockwise
    add(a, b, c, part);
    add(a, c, d, part);
    ++face_;
  }

 private:
  void add(Corner a, Corner b, Corner c, int part) {
    for (const Corner& k : {a, b, c}) {
      m_.position_index.push_back(k.p);
      m_.normal_index.push_back(k.n);
      if (uvs_) m_.uv_index.push_back(k.t);
    }
    m_.source_face.push_back(face_);
    parts_.push_back(part);
  }
  Mesh& m_;
  std::vector<int>& parts_;
  bool uvs_;
  std::uint32_t face_ = 0;
};

// A placed UV island: object units (u, v) from its corner to UV.
struct Island {
  glm::dvec2 origin{0.0};
  double scale = 1.0;
  glm::dvec2 operator()(double u, double v) const { return origin + scale * glm::dvec2(u, v); }
};

// count corners at theta = 2 pi k / count, then the first again; seam_uv, when given, is the last
// corner's own UV (an island's seam; the position and normal stay the first's).
Ring make_ring(Builder& out, int count, const std::function<Corner(double theta)>& corner,
               const std::function<glm::dvec2()>& seam_uv = nullptr);

// The band between closed rings a and b (corner counts may differ), wound like the quads
// (a_i, a_i+1, b_i+1, b_i): counter-clockwise seen from outside when a is the lower ring of an
// outward cylinder wall or the outer ring of an upward disc.
void stitch(Builder& out, const Ring& a, const Ring& b, int part);

// The disc inside `outer` (angles increasing counter-clockwise seen from +z): rings - 1 inner rings
// at radius * j / rings with about (outer count) * j / rings corners, and a fan to the centre;
// vertex(rho, theta) makes the inner corners. `up`: the disc faces +z.
void fill_disc(Builder& out, const Ring& outer, int rings, double radius,
               const std::function<Corner(double rho, double theta)>& vertex, bool up, int part);

// A wall of along + 1 rings from z0 to z1, of `around` corners made by corner(theta, z); seam_uv(z),
// when given, is the seam corner's own UV. `bore`: the wall faces the axis.
std::vector<Ring> add_wall(Builder& out, int around, int along, double z0, double z1,
                           const std::function<Corner(double theta, double z)>& corner,
                           const std::function<glm::dvec2(double z)>& seam_uv, bool bore, int part);

// A ring's positions with normal n and UVs uv(theta): the edge of a flat face (a hard edge).
Ring edge_ring(Builder& out, Ring ring, std::uint32_t n, const std::function<glm::dvec2(double theta)>& uv);

// The flat annulus at height z around `axis` between `outer` (radius r_outer) and `inner` (radius
// r_inner, same corner count), in `segments` bands; vertex(rho, theta) makes the corners between.
void add_annulus(Builder& out, const Ring& outer, const Ring& inner, int segments, double r_outer, double r_inner,
                 const std::function<Corner(double rho, double theta)>& vertex, bool up, int part);

// The corners of a flat face at height z around `axis` with normal n and UVs uv(x, y) (relative to
// the axis) for fill_disc and add_annulus.
std::function<Corner(double, double)> flat_vertex(Builder& out, glm::dvec2 axis, double z, std::uint32_t n,
                                                  std::function<glm::dvec2(double x, double y)> uv);

// A closed cylinder around `axis` from z0 to z1 whose wall, made by side(theta, z), ends in circles
// of `radius`; flat caps of cap_rings rings with their own normals. cap_uv(top, x, y) gives a cap
// corner's UV from its position relative to the axis (nullptr: no UVs).
void add_capped_cylinder(Builder& out, glm::dvec2 axis, double radius, double z0, double z1, int around, int along, int cap_rings,
                         const std::function<Corner(double theta, double z)>& side,
                         const std::function<glm::dvec2(double z)>& seam_uv,
                         const std::function<glm::dvec2(bool top, double x, double y)>& cap_uv, int part);

// UV islands side by side at one common scale (object units to UV), 0.02 apart and from the
// border: shelves of islands sorted by height, the largest scale that fits.
std::vector<Island> pack_islands(const std::vector<glm::dvec2>& sizes);

// The UV in a disc island (of a disc of `radius`) of the point (x, y) from the disc's centre; seen
// from below (a face with normal -z), x runs the other way.
glm::dvec2 disc_uv(const Island& island, double radius, bool up, double x, double y);

// printf `format` with one or two numbers: an asset's name.
std::string format_name(const char* format, double a, double b = 0);

// Mesh::source of both meshes = the asset's name.
void name_meshes(HardAsset& asset);

// The chord error of a regular polygon with `count` corners on a circle of radius r.
double sagitta(double r, int count);

}  // namespace nmbake::procedural::detail
