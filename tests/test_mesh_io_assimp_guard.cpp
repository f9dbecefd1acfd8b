// What is checked before a file reaches Assimp (io/mesh_io_assimp_guard.h), and the files of
// issue 34, item 8 (deep trees, lying GLB lengths, a FIFO as a glTF's buffer) and item 13 (long
// Assimp messages) through load_mesh.
#include <sys/stat.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "io/mesh_io.h"
#include "io/mesh_io_assimp_guard.h"
#include "test_support.h"

namespace nmbake {
namespace {

using namespace mesh_io_detail;

std::string le32(std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); }

std::string glb(std::uint32_t version, std::uint32_t length, const std::string& chunks) {
  return "glTF" + le32(version) + le32(length) + chunks;
}

std::string repeat(const std::string& s, std::size_t n) {
  std::string out;
  for (std::size_t i = 0; i < n; ++i) out += s;
  return out;
}

// A chain of `n` glTF nodes (each the only child of the one before), or with `twice` each listing
// the next two times.
std::string gltf_chain(std::size_t n, bool twice = false) {
  std::string nodes;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const std::string next = std::to_string(i + 1);
    nodes += "{\"children\":[" + next + (twice ? "," + next : "") + "]},";
  }
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[)" + nodes + "{}]}";
}

// A COLLADA file whose library holds `n` nodes, each instantiating the next (`copies` times).
std::string collada_chain(std::size_t n, int copies = 1) {
  std::string nodes;
  for (std::size_t i = 0; i < n; ++i)
    nodes += "<node id=\"n" + std::to_string(i) + "\">" +
             (i + 1 < n ? repeat("<instance_node url=\"#n" + std::to_string(i + 1) + "\"/>", copies) : "") + "</node>";
  return "<?xml version=\"1.0\"?><COLLADA><library_nodes>" + nodes + "</library_nodes></COLLADA>";
}

// A binary FBX 7.4 whose records are nested `n` deep.
std::string fbx_nested(std::size_t n) {
  std::string out = std::string("Kaydara FBX Binary  \0\x1a\0", 23) + le32(7400);
  const std::size_t leaf = 14, closing = 13;  // a record's header with a 1-letter name; a null record
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t inside = n - i - 1;  // records inside this one
    const std::size_t end = out.size() + leaf * (inside + 1) + closing * inside;
    out += le32(std::uint32_t(end)) + le32(0) + le32(0) +
           "\x01"
           "A";
  }
  out += std::string(closing * n, '\0');
  return out;
}

TEST(AssimpGuard, GlbLengthsAreCheckedAgainstTheFile) {
  const std::string json = R"({"asset":{"version":"2.0"}})";
  const std::string chunk = le32(std::uint32_t(json.size())) + "JSON" + json;
  std::string_view found;  // views into the file's bytes: they must outlive it
  const std::string file = glb(2, std::uint32_t(12 + chunk.size()), chunk);
  EXPECT_EQ(glb_problem(file, found), "");
  EXPECT_EQ(found, json);
  // The case of the issue: a chunk claiming 0xF0000000 bytes was allocated before Assimp failed.
  const std::string liar = le32(0xF0000000u) + "JSON" + json;
  EXPECT_EQ(glb_problem(glb(2, std::uint32_t(12 + liar.size()), liar), found),
            "GLB chunk 0 claims 4026531840 bytes, 27 are left");
  EXPECT_EQ(glb_problem(glb(2, 4000000000u, chunk), found), "the GLB header claims 4000000000 bytes, the file has 47");
  EXPECT_EQ(glb_problem(glb(3, 12, ""), found), "GLB version 3 (1 or 2 expected)");
  EXPECT_EQ(glb_problem("glTF\x02", found), "GLB header shorter than 12 bytes");
  EXPECT_EQ(glb_problem(glb(2, std::uint32_t(12 + chunk.size() + 4), chunk + "abcd"), found),
            "GLB chunk 1 at byte 47 is cut short");
  // Version 1: a 20-byte header, then the content.
  EXPECT_EQ(glb_problem(glb(1, 20, le32(4000) + le32(0)), found), "its content length 4000 runs past the file's 20");
  const std::string v1 = glb(1, std::uint32_t(20 + json.size()), le32(std::uint32_t(json.size())) + le32(0) + json);
  EXPECT_EQ(glb_problem(v1, found), "");
  EXPECT_EQ(found, json);
}

TEST(AssimpGuard, NestingIsCountedUpTo1000) {
  EXPECT_EQ(nesting_problem(repeat("[", 1000) + repeat("]", 1000), true), "");
  EXPECT_EQ(nesting_problem(repeat("[", 1001) + repeat("]", 1001), true), "nested more than 1000 deep (at byte 1000)");
  EXPECT_EQ(nesting_problem("{\"a\":\"" + repeat("[{", 2000) + "\"}", true), "") << "brackets in a string";
  EXPECT_EQ(nesting_problem(repeat("{", 1001), false), "nested more than 1000 deep (at byte 1000)") << "braces of FBX text";
  EXPECT_EQ(nesting_problem(repeat("[", 2000), false), "") << "brackets count in JSON only";
  // XML: elements count, not declarations, comments, empty elements or closed ones.
  const std::string xml = "<?xml version=\"1.0\"?><!-- <a> --><a>" + repeat("<b/><c></c>", 2000) + "</a>";
  EXPECT_EQ(nesting_problem(xml, false), "");
  EXPECT_EQ(nesting_problem("\xEF\xBB\xBF  " + repeat("<node>", 1000) + repeat("</node>", 1000), false), "");
  EXPECT_EQ(nesting_problem(repeat("<node>", 1001), false), "nested more than 1000 deep (at byte 6000)");
  EXPECT_EQ(nesting_problem(std::string("\0", 1) + repeat("{", 2000), false), "") << "binary files are not looked at";
}

TEST(AssimpGuard, GltfNodeTrees) {
  EXPECT_EQ(gltf_nodes_problem(gltf_chain(1000)), "");
  EXPECT_EQ(gltf_nodes_problem(gltf_chain(1001)), "node 1000 is nested more than 1000 deep");
  EXPECT_EQ(gltf_nodes_problem(R"({"nodes":[{"children":[1]},{"name":"loop","children":[0]}]})"),
            "node 0 is its own ancestor (a cycle)");
  EXPECT_EQ(gltf_nodes_problem(R"({"nodes":[{"children":[0]}]})"), "node 0 is its own ancestor (a cycle)");
  // Each node listing the next twice: 2^21 - 1 nodes once copied.
  EXPECT_EQ(gltf_nodes_problem(gltf_chain(20, true)), "");
  EXPECT_EQ(gltf_nodes_problem(gltf_chain(21, true)), "node 0 stands for more than 1048576 copies of nodes");
  // glTF 1.0: nodes by name, children by name.
  EXPECT_EQ(gltf_nodes_problem(R"({"nodes":{"a":{"children":["b"]},"b":{"children":["a"]}}})"),
            "node a is its own ancestor (a cycle)");
  EXPECT_EQ(gltf_nodes_problem(R"({"nodes":{"a":{"children":["b"]},"b":{"children":[]}}})"), "");
  EXPECT_EQ(gltf_nodes_problem("not json"), "");
  EXPECT_EQ(gltf_nodes_problem(R"({"nodes":[{"children":[7, -1, "x"]}]})"), "") << "left to Assimp";
}

TEST(AssimpGuard, GltfAccessorsWithoutBufferViews) {
  const std::string zeros = R"({"accessors":[{"bufferView":0,"count":4000000000,"type":"VEC3"},
                                             {"count":1000,"type":"VEC3","sparse":{}},{"count":1001,"type":"VEC3"}]})";
  EXPECT_EQ(gltf_accessor_problem(zeros, 4 * 12012), "");  // a buffer view: Assimp checks it against the view
  EXPECT_EQ(gltf_accessor_problem(zeros, 4 * 12011),
            "accessor 2 holds 12.0 kB of zeros (no buffer view); Assimp needs about 3 times that, the memory budget is 48.0 kB");
  EXPECT_EQ(
      gltf_accessor_problem(R"({"accessors":[{"count":100,"type":"MAT4"}]})", 4 * 6399),
      "accessor 0 holds 6400 bytes of zeros (no buffer view); Assimp needs about 3 times that, the memory budget is 25.6 kB");
}

TEST(AssimpGuard, ColladaNodeTrees) {
  EXPECT_EQ(collada_nodes_problem(collada_chain(1000)), "");
  EXPECT_EQ(collada_nodes_problem(collada_chain(1001)), "node 'n1000' is nested more than 1000 deep");
  EXPECT_EQ(collada_nodes_problem(collada_chain(20, 2)), "");
  EXPECT_EQ(collada_nodes_problem(collada_chain(21, 2)), "node 'n0' stands for more than 1048576 copies of nodes");
  const std::string cycle =
      "<COLLADA><library_nodes><node id='a'><node id=\"b\"><instance_node url=\"#a\"/></node></node></library_nodes></COLLADA>";
  EXPECT_EQ(collada_nodes_problem(cycle), "node 'a' is its own ancestor (a cycle)");
  EXPECT_EQ(collada_nodes_problem("<COLLADA><node id=\"a\"><instance_node url=\"#nowhere\"/></node></COLLADA>"), "");
}

// A binary FBX 7.4 of top-level records (NAME, properties already encoded) without children.
std::string fbx_flat(const std::vector<std::pair<std::string, std::string>>& records) {
  std::string out = std::string("Kaydara FBX Binary  \0\x1a\0", 23) + le32(7400);
  for (const auto& [name, properties] : records) {
    const std::size_t end = out.size() + 13 + name.size() + properties.size();
    out += le32(std::uint32_t(end)) + le32(1) + le32(std::uint32_t(properties.size())) + char(name.size()) + name + properties;
  }
  return out + std::string(13, '\0');
}

std::string fbx_id(std::uint64_t id) { return "L" + std::string(reinterpret_cast<const char*>(&id), 8); }
std::string fbx_text(const std::string& s) { return "S" + le32(std::uint32_t(s.size())) + s; }

// A text FBX whose models 1000.. are connected child to parent by `links` (child, parent).
std::string fbx_text_file(std::size_t models, const std::vector<std::pair<std::size_t, std::size_t>>& links) {
  std::string s = "; FBX 7.4.0 project file\nObjects:  {\n";
  for (std::size_t i = 0; i < models; ++i)
    s += "\tModel: " + std::to_string(1000 + i) + ", \"Model::m" + std::to_string(i) + "\", \"Null\" {\n\t}\n";
  s += "}\nConnections:  {\n\tC: \"OO\",1000,0\n";
  for (const auto& [child, parent] : links)
    s += "\tC: \"OO\"," + std::to_string(1000 + child) + "," + std::to_string(1000 + parent) + "\n";
  return s + "}\n";
}

TEST(AssimpGuard, FbxModelTrees) {
  // Text: a cycle of two models made Assimp recurse until the stack ran out.
  EXPECT_EQ(fbx_problem(fbx_text_file(2, {{1, 0}, {0, 1}})), "node '1000' is its own ancestor (a cycle)");
  std::vector<std::pair<std::size_t, std::size_t>> chain;
  for (std::size_t i = 1; i < 1001; ++i) chain.push_back({i, i - 1});
  EXPECT_EQ(fbx_problem(fbx_text_file(1001, chain)), "node '2000' is nested more than 1000 deep");
  chain.pop_back();
  EXPECT_EQ(fbx_problem(fbx_text_file(1000, chain)), "");
  // FBX 6 text names models and connects them by name.
  EXPECT_EQ(fbx_problem("Model: \"Model::a\", \"Mesh\" {\n}\nModel: \"Model::b\", \"Mesh\" {\n}\n"
                        "Connect: \"OO\", \"Model::a\", \"Model::b\"\nConnect: \"OO\", \"Model::b\", \"Model::a\"\n"),
            "node 'Model::a' is its own ancestor (a cycle)");
  // Binary: Model records with their ids, C records with "OO", child, parent.
  const std::string a = fbx_id(7), b = fbx_id(8);
  const std::pair<std::string, std::string> model_a{"Model", a + fbx_text("a")}, model_b{"Model", b + fbx_text("b")};
  EXPECT_EQ(fbx_problem(fbx_flat({model_a, model_b, {"C", fbx_text("OO") + b + a}})), "");
  EXPECT_EQ(fbx_problem(fbx_flat({model_a, model_b, {"C", fbx_text("OO") + b + a}, {"C", fbx_text("OO") + a + b}})),
            "node '7' is its own ancestor (a cycle)");
}

TEST(AssimpGuard, FbxRecordsNestedTooDeep) {
  EXPECT_EQ(fbx_problem(fbx_nested(1000)), "");
  EXPECT_EQ(fbx_problem(fbx_nested(1001)), "FBX records nested more than 1000 deep (at byte 14027)");
  EXPECT_EQ(fbx_problem("; FBX 7.4.0 project file"), "");
}

TEST(AssimpGuard, LibraryTextIsCutTo160Characters) {
  const std::string cut = one_line(repeat("word ", 100), kAssimpMessageMax);
  EXPECT_EQ(cut.size(), 160u);
  EXPECT_EQ(cut.substr(cut.size() - 10), "word wo...");
  EXPECT_EQ(one_line(repeat("x", 160), kAssimpMessageMax), repeat("x", 160));
}

TEST(AssimpGuard, StackGrowsWithTheFile) {
  const std::size_t mib = std::size_t(1) << 20;
  EXPECT_EQ(reader_stack_bytes(0), 256 * mib);
  EXPECT_EQ(reader_stack_bytes(2 * mib), 512 * mib);
  EXPECT_EQ(reader_stack_bytes(std::size_t(1) << 40), 4096 * mib);
  int ran = 0;
  run_on_big_stack(256 * mib, [&] { ran = 1; });
  EXPECT_EQ(ran, 1);
  EXPECT_THROW(run_on_big_stack(256 * mib, [] { throw InputError("x"); }), InputError);
}

// The message of a load that fails ("loaded" when it does not).
std::string load_error(const std::string& path) {
  try {
    load_mesh(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "loaded";
}

// A load through Assimp that must fail: one line starting with the path, holding `text`.
void expect_refused(const std::string& path, const std::string& text) {
  const std::string what = load_error(path);
  EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
  EXPECT_NE(what.find(text), std::string::npos) << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  EXPECT_LE(what.size(), path.size() + 220) << what;
}

// Each of these crashed (SIGSEGV), allocated 4 GB or hung before the guards.
TEST(AssimpGuard, HostileFilesAreRefused) {
  const std::string dir = test::scratch_dir();
  test::write_file(dir + "/deep_nodes.gltf", gltf_chain(200000));
  expect_refused(dir + "/deep_nodes.gltf", "malformed: node 1000 is nested more than 1000 deep");
  test::write_file(dir + "/deep_json.gltf",
                   "{\"asset\":{\"version\":\"2.0\"},\"extras\":" + repeat("[", 200000) + repeat("]", 200000) + "}");
  expect_refused(dir + "/deep_json.gltf", "malformed: nested more than 1000 deep");
  test::write_file(dir + "/deep.dae", "<?xml version=\"1.0\"?><COLLADA><library_visual_scenes><visual_scene id=\"s\">" +
                                          repeat("<node>", 200000) + repeat("</node>", 200000) +
                                          "</visual_scene></library_visual_scenes></COLLADA>");
  expect_refused(dir + "/deep.dae", "malformed: nested more than 1000 deep");
  test::write_file(dir + "/deep_text.fbx", "; FBX 7.4.0 project file\nFBXHeaderExtension: {\n}\n" + repeat("A: {\n", 200000));
  expect_refused(dir + "/deep_text.fbx", "malformed: nested more than 1000 deep");
  test::write_file(dir + "/deep_binary.fbx", fbx_nested(100000));
  expect_refused(dir + "/deep_binary.fbx", "malformed: FBX records nested more than 1000 deep");
  // 2^60 zeros (a sparse accessor): refused as a size whatever the machine (500M took 19.5 GB, 55 s).
  test::write_file(dir + "/zeros.gltf", R"({"asset":{"version":"2.0"},"accessors":[{"count":1152921504606846976,"type":"VEC3",
    "componentType":5126,"sparse":{"count":1,"indices":{"bufferView":0,"componentType":5125},"values":{"bufferView":0}}}]})");
  try {
    load_mesh(dir + "/zeros.gltf");
    ADD_FAILURE() << "zeros.gltf loaded";
  } catch (const ResourceError& e) {
    EXPECT_NE(std::string(e.what()).find("zeros.gltf: accessor 0 holds"), std::string::npos) << e.what();
  }
  test::write_file(dir + "/cycle.fbx", fbx_text_file(2, {{1, 0}, {0, 1}}));
  expect_refused(dir + "/cycle.fbx", "malformed: node '1000' is its own ancestor (a cycle)");
  const std::string liar = le32(0xF0000000u) + "JSON" + R"({"asset":{"version":"2.0"}} )";
  test::write_file(dir + "/liar.glb", glb(2, std::uint32_t(12 + liar.size()), liar));
  expect_refused(dir + "/liar.glb", "malformed: GLB chunk 0 claims 4026531840 bytes");
  // A buffer that is a FIFO (opening it for reading blocked for ever), and one that is a folder.
  const std::string fifo = dir + "/fifo.bin";
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  ::mkdir((dir + "/folder.bin").c_str(), 0700);
  for (const std::string bin : {"fifo.bin", "folder.bin"}) {
    test::write_file(dir + "/buffer.gltf", R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"buffers":[{"byteLength":36,"uri":")" +
                                               bin + R"("}],
      "bufferViews":[{"buffer":0,"byteLength":36}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}]})");
    expect_refused(dir + "/buffer.gltf", "refers to " + dir + "/" + bin + ", which is not a regular file");
  }
}

// Assimp's messages run over 300 characters on some files: one line, the library's part cut.
TEST(AssimpGuard, LongLibraryMessagesAreCut) {
  const std::string dir = test::scratch_dir();
  // glTF: a TEXCOORD_1 without TEXCOORD_0 (Assimp's message: 227 characters).
  test::write_file(dir + "/texcoord.gltf", R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
    "meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_1":0}}]}],
    "buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
    "bufferViews":[{"buffer":0,"byteLength":36}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}]})");
  expect_refused(dir + "/texcoord.gltf", "cannot read as .gltf: GLTF: Invalid attribute");
  // COLLADA: a number Assimp cannot read, in a long <float_array> (its message quotes the text).
  test::write_file(dir + "/long.dae",
                   "<?xml version=\"1.0\"?><COLLADA><library_geometries><geometry id=\"g\"><mesh><source id=\"p\">"
                   "<float_array id=\"a\" count=\"3\">" +
                       repeat("\n  x   \t ", 60) +
                       "</float_array></source></mesh>"
                       "</geometry></library_geometries></COLLADA>");
  expect_refused(dir + "/long.dae", "cannot read as .dae");
}

}  // namespace
}  // namespace nmbake
