// Objects and matching by name (issue 20, items 1-3): OBJ objects (o, g) are kept with their
// names; the report lists every object with its file, triangles and hits; --match names bakes each
// low-poly object only from the high-poly objects of its base name.
//
// The known answer: a plate pierced by a bolt, both boxes whose high-poly copies differ only in
// their normals (each object tilted its own way). With a ray distance that reaches the bolt's top
// from the plate, the plate's texels under the bolt take the bolt's normal unless the objects are
// matched; matched, every texel equals the bake of its object alone.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include "core/normals.h"
#include "core/object_match.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "nmdiff.h"
#include "pipeline/bake.h"
#include "procedural.h"
#include "test_support.h"

namespace nmbake {
namespace {

using test::contains;
using test::run_nmbake;

struct NamedBox {
  std::string name;
  glm::vec3 lo, hi;
  int first_cell;     // UV cells first_cell .. first_cell + 5 of a 4 x 4 grid, one per face
  glm::vec3 tilt{0};  // added to each face's normal (high-poly)
};

// Boxes as OBJ text: one `o` per box, hard edges (a normal per face), a UV cell per face.
std::string boxes_obj(const std::vector<NamedBox>& boxes) {
  static const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {3, 0, 4, 7}};
  static const float normals[6][3] = {{0, 0, -1}, {0, 0, 1}, {0, -1, 0}, {0, 1, 0}, {1, 0, 0}, {-1, 0, 0}};
  std::string text;
  char line[200];
  int base_v = 0, base_t = 0, base_n = 0;
  for (const NamedBox& b : boxes) {
    text += "o " + b.name + "\n";
    for (int k = 0; k < 8; ++k) {
      std::snprintf(line, sizeof line, "v %g %g %g\n", double((k == 1 || k == 2 || k == 5 || k == 6) ? b.hi.x : b.lo.x),
                    double((k == 2 || k == 3 || k == 6 || k == 7) ? b.hi.y : b.lo.y), double(k >= 4 ? b.hi.z : b.lo.z));
      text += line;
    }
    for (int f = 0; f < 6; ++f) {
      const int cell = b.first_cell + f;
      const double u0 = (cell % 4) / 4.0 + 0.02, v0 = (cell / 4) / 4.0 + 0.02, side = 0.25 - 0.04;
      for (const auto& [a, c] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{1, 1}, std::pair{0, 1}}) {
        std::snprintf(line, sizeof line, "vt %.9g %.9g\n", u0 + a * side, v0 + c * side);
        text += line;
      }
      const glm::vec3 n = glm::normalize(glm::vec3(normals[f][0], normals[f][1], normals[f][2]) + b.tilt);
      std::snprintf(line, sizeof line, "vn %.9g %.9g %.9g\nf", double(n.x), double(n.y), double(n.z));
      text += line;
      for (int c = 0; c < 4; ++c) {
        std::snprintf(line, sizeof line, " %d/%d/%d", base_v + faces[f][c] + 1, base_t + c + 1, base_n + 1);
        text += line;
      }
      text += "\n";
      base_t += 4;
      ++base_n;
    }
    base_v += 8;
  }
  return text;
}

const glm::vec3 kPlateLo(-1, -1, -0.1f), kPlateHi(1, 1, 0), kBoltLo(-0.2f, -0.2f, -0.5f), kBoltHi(0.2f, 0.2f, 0.5f);
const glm::vec3 kPlateTilt(0.3f, 0, 0), kBoltTilt(0, -0.3f, 0);

NamedBox plate(const std::string& name, bool high) { return {name, kPlateLo, kPlateHi, 0, high ? kPlateTilt : glm::vec3(0)}; }
NamedBox bolt(const std::string& name, bool high) { return {name, kBoltLo, kBoltHi, 8, high ? kBoltTilt : glm::vec3(0)}; }

Mesh load_obj(const std::string& name, const std::string& text) {
  LoadOptions o;
  o.require_uvs = name.find("low") != std::string::npos;
  return load_mesh_from_memory(name, text, o);
}

// A bake of the known-answer scene's size with one ray distance for the scene that reaches from the
// plate to the bolt's top (as a user's --front would).
BakeOptions scene_options() {
  BakeOptions o;
  o.width = o.height = 128;
  o.padding = 0;
  o.front = 0.6f;
  o.rear = 0.2f;
  return o;
}

// Largest angle (degrees) between two maps over the texels covered in `coverage`.
double largest_angle(const BakeResult& a, const BakeResult& b, const std::vector<std::uint8_t>& coverage) {
  double worst = 0.0;
  for (std::size_t i = 0; i < coverage.size(); ++i)
    if (coverage[i])
      worst = std::max(worst, test::angle_deg(test::decode_rgb(&a.map.pixels[3 * i]), test::decode_rgb(&b.map.pixels[3 * i])));
  return worst;
}

TEST(ObjectMatch, BasesSuffixesAndGroups) {
  const MatchSuffixes d = default_match_suffixes();
  EXPECT_EQ(match_base("arm_low", d, false), "arm");
  EXPECT_EQ(match_base("Arm_HIGH", d, true), "Arm");
  EXPECT_EQ(match_base("arm_high", d, false), "arm_high");  // a high suffix on the low side is part of the name
  EXPECT_EQ(match_base("head_lp", d, false), "head");
  EXPECT_EQ(match_base("_low", d, false), "_low");  // nothing would be left
  EXPECT_EQ(match_base("bolt", d, true), "bolt");
  const ObjectMatch m =
      match_objects({"arm_low", "leg_lp", "tail_low", "head"}, {"leg_hp", "arm_high", "head", "wing_high", "arm_high"}, d);
  EXPECT_EQ(m.bases, (std::vector<std::string>{"arm", "leg", "head"}));
  EXPECT_EQ(m.low_group, (std::vector<std::uint32_t>{0, 1, kNoMatch, 2}));
  EXPECT_EQ(m.high_group, (std::vector<std::uint32_t>{1, 0, 2, kNoMatch, 0}));
  EXPECT_EQ(m.unmatched_low, (std::vector<std::size_t>{2}));
  EXPECT_EQ(m.unmatched_high, (std::vector<std::size_t>{3}));
  EXPECT_EQ(parse_match_suffixes("_lo:_hi,_L:_H"), (MatchSuffixes{{"_lo", "_hi"}, {"_L", "_H"}}));
  for (const char* bad : {"", "_lo", "_lo:", ":_hi", "_lo:_hi,", "a:b:c"})
    EXPECT_THROW(parse_match_suffixes(bad), UsageError) << bad;
  const auto unused = unused_match_suffixes({"arm_lo"}, {"arm_high"}, {{"_lo", "_hi"}});
  ASSERT_EQ(unused.size(), 1u);
  EXPECT_EQ(unused[0], (std::pair<std::string, bool>{"_hi", true}));
}

TEST(Objects, ObjObjectsKeepTheirNames) {
  // Triangles before any name belong to an object named after the file; `g` names objects only
  // in a file without `o`; a name met again continues its object; objects without faces are gone.
  const std::string quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
  const Mesh m = load_obj("dir/parts.obj", quad + "f 1 2 3\no a\nf 1 3 4\no empty\no b\ng ignored\nf 1 2 4\no a\nf 2 3 4\n");
  ASSERT_EQ(m.objects.size(), 3u);
  EXPECT_EQ(m.objects[0].name, "parts");
  EXPECT_EQ(m.objects[1].name, "a");
  EXPECT_EQ(m.objects[2].name, "b");
  EXPECT_EQ(m.objects[2].file, "dir/parts.obj");
  EXPECT_EQ(m.triangle_object, (std::vector<std::uint32_t>{0, 1, 2, 1}));
  const Mesh groups = load_obj("g.obj", quad + "g default\ng left\nf 1 2 3\ng right\nf 1 3 4\n");
  ASSERT_EQ(groups.objects.size(), 2u);
  EXPECT_EQ(groups.objects[0].name, "left");
  EXPECT_EQ(groups.objects[1].name, "right");
  const Mesh one = load_obj("one.obj", quad + "o only\nf 1 2 3 4\n");
  ASSERT_EQ(one.objects.size(), 1u);
  EXPECT_EQ(one.objects[0].name, "only");
  EXPECT_TRUE(one.triangle_object.empty());
  // Merged files keep each object with its file.
  const Mesh merged = merge_meshes({load_obj("x.obj", quad + "f 1 2 3\n"), groups});
  ASSERT_EQ(merged.objects.size(), 3u);
  EXPECT_EQ(merged.objects[0].name, "x");
  EXPECT_EQ(merged.objects[2].file, "g.obj");
  EXPECT_EQ(merged.triangle_object, (std::vector<std::uint32_t>{0, 1, 2}));
}

TEST(MatchNames, IntersectingPartsNeverImprintOnEachOther) {
  const Mesh low = load_obj("low.obj", boxes_obj({plate("plate_low", false), bolt("bolt_low", false)}));
  const Mesh high = load_obj("high.obj", boxes_obj({plate("plate_high", true), bolt("bolt_high", true)}));
  ASSERT_EQ(low.objects.size(), 2u);
  BakeOptions o = scene_options();
  const BakeResult together = bake_normal_map(low, high, nullptr, o);
  const ObjectMatch m = match_objects({"plate_low", "bolt_low"}, {"plate_high", "bolt_high"}, default_match_suffixes());
  o.low_object_group = m.low_group;
  o.high_object_group = m.high_group;
  o.keep_trace = true;
  const BakeResult matched = bake_normal_map(low, high, nullptr, o);
  // Each object alone: the known answer for its texels.
  const BakeOptions alone_options = scene_options();
  const BakeResult plate_alone =
      bake_normal_map(load_obj("p_low.obj", boxes_obj({plate("plate_low", false)})),
                      load_obj("p.obj", boxes_obj({plate("plate_high", true)})), nullptr, alone_options);
  const BakeResult bolt_alone = bake_normal_map(load_obj("b_low.obj", boxes_obj({bolt("bolt_low", false)})),
                                                load_obj("b.obj", boxes_obj({bolt("bolt_high", true)})), nullptr, alone_options);
  std::size_t plate_texels = 0, bolt_texels = 0;
  for (std::uint8_t c : plate_alone.coverage) plate_texels += c;
  for (std::uint8_t c : bolt_alone.coverage) bolt_texels += c;
  ASSERT_GT(plate_texels, 1000u);
  ASSERT_GT(bolt_texels, 1000u);
  EXPECT_LT(largest_angle(matched, plate_alone, plate_alone.coverage), 0.05);
  EXPECT_LT(largest_angle(matched, bolt_alone, bolt_alone.coverage), 0.05);
  // Unmatched, the plate under the bolt takes the bolt's normal: this scene tells them apart.
  std::size_t imprinted = 0;
  for (std::size_t i = 0; i < plate_alone.coverage.size(); ++i)
    imprinted += plate_alone.coverage[i] && test::angle_deg(test::decode_rgb(&together.map.pixels[3 * i]),
                                                            test::decode_rgb(&plate_alone.map.pixels[3 * i])) > 5.0;
  // The bolt's cross-section is 4% of the plate's top and bottom faces: about 2 x 29 texels.
  EXPECT_GT(imprinted, 40u) << "the unmatched bake should show the bolt on the plate";
  // Hits counted per object.
  ASSERT_EQ(matched.stats.trace.low_object_samples.size(), 2u);
  EXPECT_EQ(matched.stats.trace.low_object_samples[0], plate_texels);
  EXPECT_EQ(matched.stats.trace.low_object_hits[0], plate_texels);
  EXPECT_EQ(matched.stats.trace.high_object_hits[1], bolt_texels);
  EXPECT_EQ(matched.stats.trace.high_object_hits[0], plate_texels);
  EXPECT_NE(together.stats.trace.high_object_hits[0], plate_texels) << "unmatched, rays cross from one object to the other";
  // The error estimate re-bakes with the same matching: it sees no error the matching removed.
  EXPECT_EQ(test::texels_traced_otherwise(low, *matched.trace_inputs, o, matched), 0u);
}

TEST(MatchNames, AnUnmatchedObjectIsLeftFlat) {
  const Mesh low = load_obj("low.obj", boxes_obj({plate("plate_low", false), bolt("bolt_low", false)}));
  const Mesh high = load_obj("high.obj", boxes_obj({plate("plate_high", true), bolt("screw_high", true)}));
  BakeOptions o = scene_options();
  const ObjectMatch m = match_objects({"plate_low", "bolt_low"}, {"plate_high", "screw_high"}, default_match_suffixes());
  ASSERT_EQ(m.unmatched_low, (std::vector<std::size_t>{1}));
  o.low_object_group = m.low_group;
  o.high_object_group = m.high_group;
  const BakeResult r = bake_normal_map(low, high, nullptr, o);
  std::size_t bolt_texels = 0;
  for (std::size_t i = 0; i < r.coverage.size(); ++i) {
    const std::size_t y = i / 128;
    if (!r.coverage[i] || y >= 64) continue;  // the bolt's cells: the top half of the image (v >= 0.5)
    ++bolt_texels;
    const glm::dvec3 n = test::decode_rgb(&r.map.pixels[3 * i]);
    EXPECT_TRUE(n == glm::dvec3(0, 0, 1)) << "texel " << i << ": " << n.x << " " << n.y << " " << n.z;
    if (n != glm::dvec3(0, 0, 1)) break;
  }
  EXPECT_GT(bolt_texels, 1000u);
  EXPECT_EQ(r.stats.trace.samples_unmatched, bolt_texels);
  EXPECT_EQ(r.stats.trace.misses, 0u);
  EXPECT_EQ(r.stats.trace.high_object_hits[1], 0u);
}

TEST(MatchNames, CommandLineReportAndWarnings) {
  const std::string dir = test::scratch_dir();
  test::write_file(dir + "/low.obj", boxes_obj({plate("plate_low", false), bolt("bolt_low", false)}));
  test::write_file(dir + "/high.obj", boxes_obj({plate("plate_high", true), bolt("screw_hp", true)}));
  const test::CliRun r = run_nmbake("low.obj high.obj -o m.png --size 64 --match names --report r.json", "", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(
      contains(r.err, "low.obj: --match names: 1 low-poly object(s) match no high-poly object and are left flat: 'bolt_low'"))
      << r.err;
  EXPECT_TRUE(contains(r.err, "high.obj: --match names: 1 high-poly object(s) match no low-poly object")) << r.err;
  const nlohmann::json& objects = r.report["objects"];
  ASSERT_EQ(objects["low"].size(), 2u);
  EXPECT_EQ(objects["low"][0]["name"], "plate_low");
  EXPECT_EQ(objects["low"][0]["file"], "low.obj");
  EXPECT_EQ(objects["low"][0]["triangles"], 12);
  EXPECT_EQ(objects["low"][0]["match"], "plate");
  EXPECT_GT(objects["low"][0]["hits"].get<long>(), 0);
  EXPECT_TRUE(objects["low"][1]["match"].is_null());
  EXPECT_EQ(objects["high"][1]["name"], "screw_hp");
  EXPECT_EQ(objects["high"][1]["hits"], 0);
  EXPECT_EQ(r.report["match"]["unmatched_low"], nlohmann::json::array({"bolt_low"}));
  EXPECT_EQ(r.report["match"]["unmatched_high"], nlohmann::json::array({"screw_hp"}));
  EXPECT_EQ(r.report["options"]["match"], "names");
  EXPECT_GT(r.report["samples_unmatched"].get<long>(), 0);
  // --strict: the unmatched objects are warnings, so nothing is written.
  const test::CliRun strict = run_nmbake("low.obj high.obj -o s.png --size 64 --match names --strict", "", dir);
  EXPECT_EQ(strict.code, 5) << strict.err;
  EXPECT_FALSE(test::exists(dir + "/s.png"));
}

TEST(MatchNames, BadSuffixesAreRefused) {
  const std::string dir = test::scratch_dir();
  test::write_file(dir + "/low.obj", boxes_obj({plate("plate_low", false)}));
  test::write_file(dir + "/high.obj", boxes_obj({plate("plate_high", true)}));
  struct Case {
    const char* args;
    const char* message;
  };
  for (const Case& c :
       {Case{"--match names --match-suffixes _lo:_high", "'_lo' ends no low-poly object's name"},
        Case{"--match names --match-suffixes _low:_hi", "'_hi' ends no high-poly object's name"},
        Case{"--match names --match-suffixes _low", "expected LOW:HIGH pairs"},
        Case{"--match-suffixes _low:_high", "applies with --match names"}, Case{"--match everything", "--match"}}) {
    const test::CliRun r = run_nmbake(std::string("low.obj high.obj -o x.png --size 32 ") + c.args, "", dir);
    EXPECT_EQ(r.code, 1) << c.args;
    EXPECT_TRUE(contains(r.err, c.message)) << c.args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(test::exists(dir + "/x.png"));
  }
  // Given suffixes that match: baked.
  const test::CliRun ok = run_nmbake("low.obj high.obj -o ok.png --size 32 --match names --match-suffixes _LOW:_HIGH", "", dir);
  EXPECT_EQ(ok.code, 0) << ok.err;
}

// The objects of an asset format are its nodes with meshes, by name: the scene of two named objects
// re-saved by Assimp's exporter as GLB, ASCII FBX (in centimetres, as FBX files usually are) and
// DAE keeps both names, and --match names bakes the map of the OBJ files from each.
TEST(MatchNames, NodesOfAssetFormatsAreObjects) {
  const std::string dir = test::scratch_dir();
  test::write_file(dir + "/low.obj", boxes_obj({plate("plate_low", false), bolt("bolt_low", false)}));
  test::write_file(dir + "/high.obj", boxes_obj({plate("plate_high", true), bolt("bolt_high", true)}));
  for (const auto& [format, ext] : {std::pair{"glb2", "glb"}, std::pair{"fbxa", "fbx"}, std::pair{"collada", "dae"}}) {
    for (const char* side : {"low", "high"}) {
      Assimp::Importer importer;
      const aiScene* scene = importer.ReadFile(dir + "/" + side + ".obj", aiProcess_ValidateDataStructure);
      ASSERT_NE(scene, nullptr) << importer.GetErrorString();
      if (std::string(ext) == "fbx")  // the exporter writes a unit of 1 cm
        for (unsigned i = 0; i < scene->mNumMeshes; ++i)
          for (unsigned v = 0; v < scene->mMeshes[i]->mNumVertices; ++v) scene->mMeshes[i]->mVertices[v] *= 100.0f;
      Assimp::Exporter exporter;
      ASSERT_EQ(exporter.Export(scene, format, dir + "/" + side + "." + ext), AI_SUCCESS) << exporter.GetErrorString();
    }
    const Mesh low = load_mesh(dir + "/low." + ext);
    std::vector<std::string> names;
    for (const Mesh::Object& o : low.objects) names.push_back(o.name);
    EXPECT_EQ(names, (std::vector<std::string>{"plate_low", "bolt_low"})) << ext;
  }
  const std::string options = " --size 64 --front 0.6 --rear 0.2 --padding 0 --match names";
  const test::CliRun obj = run_nmbake("low.obj high.obj -o obj.exr" + options, "", dir);
  ASSERT_EQ(obj.code, 0) << obj.err;
  const Image expected = read_image(dir + "/obj.exr");
  for (const char* pair : {"low.glb high.glb", "low.fbx high.glb", "low.dae high.fbx"}) {
    const test::CliRun r = run_nmbake(std::string(pair) + " -o m.exr --report r.json" + options, "", dir);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.report["match"]["groups"], nlohmann::json::array({"plate", "bolt"})) << pair;
    const diff::DiffStats d = diff::compare_normal_maps(read_image(dir + "/m.exr"), expected);
    EXPECT_LT(d.max_deg, 0.05) << pair;
  }
}

// Two intersecting balls (issue 34, item 2), each a coarse low-poly sphere inside a fine bumped
// high-poly one, named a_low/a_high and b_low/b_high, a UV half each. Ball b lies inside a's high
// surface where they cross: probes from a that saw b's surfaces limited a's cage there.
constexpr float kBallOffset = 0.6f;

Mesh ball(bool high, float x) {
  Mesh m =
      high
          ? procedural::make_sphere(
                64, 32, [](double t, double f) { return procedural::displaced_sphere_radius(0.04, 5, t, f); },
                [](double t, double f) { return procedural::displaced_sphere_normal(0.04, 5, t, f); })
          : procedural::make_sphere(
                10, 6, [](double, double) { return 1.06; },
                [](double t, double f) { return glm::dvec3(std::sin(t) * std::cos(f), std::sin(t) * std::sin(f), std::cos(t)); });
  for (glm::vec3& p : m.positions) p.x += x;
  for (glm::vec2& uv : m.uvs) uv.x = 0.5f * uv.x + (x > 0.0f ? 0.5f : 0.0f);
  return m;
}

// Meshes as one OBJ file, one `o` per mesh (positions, UVs when present, normals when present).
std::string objects_obj(const std::vector<std::pair<std::string, Mesh>>& parts) {
  std::string text;
  char line[200];
  std::size_t base_v = 0, base_t = 0, base_n = 0;
  for (const auto& [name, m] : parts) {
    text += "o " + name + "\n";
    for (const glm::vec3& p : m.positions) {
      std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", double(p.x), double(p.y), double(p.z));
      text += line;
    }
    for (const glm::vec2& t : m.uvs) {
      std::snprintf(line, sizeof line, "vt %.9g %.9g\n", double(t.x), double(t.y));
      text += line;
    }
    for (const glm::vec3& n : m.normals) {
      std::snprintf(line, sizeof line, "vn %.9g %.9g %.9g\n", double(n.x), double(n.y), double(n.z));
      text += line;
    }
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      text += "f";
      for (int c = 0; c < 3; ++c) {
        text += " " + std::to_string(base_v + m.position_index[3 * t + c] + 1) + "/";
        if (m.has_uvs()) text += std::to_string(base_t + m.uv_index[3 * t + c] + 1);
        if (m.has_normals()) text += "/" + std::to_string(base_n + m.normal_index[3 * t + c] + 1);
      }
      text += "\n";
    }
    base_v += m.positions.size();
    base_t += m.uvs.size();
    base_n += m.normals.size();
  }
  return text;
}

std::string balls_obj(bool high, bool a, bool b) {
  std::vector<std::pair<std::string, Mesh>> parts;
  if (a) parts.push_back({high ? "a_high" : "a_low", ball(high, -kBallOffset)});
  if (b) parts.push_back({high ? "b_high" : "b_low", ball(high, kBallOffset)});
  return objects_obj(parts);
}

BakeOptions ball_options(const Mesh& low, const Mesh& high) {
  BakeOptions o;
  o.width = o.height = 128;
  o.padding = 0;
  std::vector<std::string> lows, highs;
  for (const Mesh::Object& x : low.objects) lows.push_back(x.name);
  for (const Mesh::Object& x : high.objects) highs.push_back(x.name);
  const ObjectMatch m = match_objects(lows, highs, default_match_suffixes());
  o.low_object_group = m.low_group;
  o.high_object_group = m.high_group;
  return o;
}

// With --match names the automatic cage of each ball is sized from its own group only: no
// misses, and each ball's texels are those of the ball baked alone (the known answer).
TEST(MatchNames, IntersectingBallsBakeAsIfAlone) {
  const Mesh low = load_obj("low.obj", balls_obj(false, true, true));
  const Mesh high = load_obj("high.obj", balls_obj(true, true, true));
  ASSERT_EQ(low.objects.size(), 2u);
  const BakeResult both = bake_normal_map(low, high, nullptr, ball_options(low, high));
  EXPECT_EQ(both.stats.trace.misses, 0u) << "of " << both.stats.trace.samples_covered;
  for (const bool a : {true, false}) {
    const Mesh low1 = load_obj("low1.obj", balls_obj(false, a, !a)), high1 = load_obj("high1.obj", balls_obj(true, a, !a));
    const BakeResult alone = bake_normal_map(low1, high1, nullptr, ball_options(low1, high1));
    std::size_t texels = 0, over_rounding = 0;
    for (std::size_t i = 0; i < alone.coverage.size(); ++i) {
      if (!alone.coverage[i]) continue;
      ++texels;
      for (int c = 0; c < 3; ++c)
        over_rounding += std::abs(int(both.map.pixels[3 * i + c]) - int(alone.map.pixels[3 * i + c])) > 1;
    }
    ASSERT_GT(texels, 3000u);
    EXPECT_EQ(over_rounding, 0u) << (a ? "ball a" : "ball b");
    EXPECT_LT(largest_angle(both, alone, alone.coverage), 1.0) << (a ? "ball a" : "ball b");
  }
}

// The same scene as GLB and as DAE (Assimp's exporter) gives the same cages, so the same maps.
TEST(MatchNames, IntersectingBallsAgreeAcrossFormats) {
  const std::string dir = test::scratch_dir();
  test::write_file(dir + "/low.obj", balls_obj(false, true, true));
  test::write_file(dir + "/high.obj", balls_obj(true, true, true));
  for (const auto& [format, ext] : {std::pair{"glb2", "glb"}, std::pair{"collada", "dae"}})
    for (const char* side : {"low", "high"}) {
      Assimp::Importer importer;
      const aiScene* scene = importer.ReadFile(dir + "/" + side + ".obj", aiProcess_ValidateDataStructure);
      ASSERT_NE(scene, nullptr) << importer.GetErrorString();
      Assimp::Exporter exporter;
      ASSERT_EQ(exporter.Export(scene, format, dir + "/" + side + "." + ext), AI_SUCCESS) << exporter.GetErrorString();
    }
  const std::string options = " --size 128 --padding 0 --match names --report r.json";
  const test::CliRun glb = run_nmbake("low.glb high.glb -o glb.png" + options, "", dir);
  ASSERT_EQ(glb.code, 0) << glb.err;
  EXPECT_EQ(glb.report["misses"], 0);
  const test::CliRun dae = run_nmbake("low.dae high.dae -o dae.png" + options, "", dir);
  ASSERT_EQ(dae.code, 0) << dae.err;
  EXPECT_EQ(dae.report["misses"], 0);
  const diff::DiffStats d = diff::compare_normal_maps(read_image(dir + "/dae.png"), read_image(dir + "/glb.png"));
  EXPECT_TRUE(d.within) << "mean " << d.mean_deg << ", p99 " << d.p99_deg << ", max " << d.max_deg << ", over 1 degree "
                        << d.over_1deg;
  EXPECT_LT(d.over_1deg, 0.001);
}

}  // namespace
}  // namespace nmbake
