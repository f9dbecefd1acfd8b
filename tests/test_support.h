// Helpers shared by the test programs: data paths, scratch folders, procedural meshes, running the
// nmbake binary.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "core/image.h"

#include "core/mesh.h"

namespace nmbake {
struct BakeOptions;
struct BakeResult;
struct TraceInputs;
struct UvTileFilter;
}  // namespace nmbake

namespace nmbake::test {

constexpr double kPi = 3.14159265358979323846;

std::string data_path(const std::string& relative);         // <repo>/data/<relative>
std::string shared_data_path(const std::string& relative);  // <repo>/../shared/data/<relative>
// The bundled sample pair (data/sample): the torus low-poly (OBJ, with UVs) and its sculpt (PLY).
const std::string& sample_low();
const std::string& sample_high();

// A low-poly (UVs required) and a high-poly loaded as nmbake loads them: the high-poly on the
// low-poly's origin. `low_info` receives what loading the low-poly found, when not null.
struct MeshPair {
  Mesh low, high;
};
MeshPair load_pair(const std::string& low_path, const std::string& high_path, MeshLoadInfo* low_info = nullptr);
bool exists(const std::string& path);
std::string read_file(const std::string& path);                      // the whole file ("" when unreadable)
void write_file(const std::string& path, const std::string& bytes);  // created or replaced; throws when it cannot

// A fresh empty folder under the build tree, named after the running test.
std::string scratch_dir();

// One run of the nmbake command: its exit code (-1 when it did not exit normally), stdout, stderr,
// the folder it ran in, and the report it wrote to r.json there (null when it wrote none).
struct CliRun {
  int code = -1;
  std::string out, err, dir;
  nlohmann::json report;
};

// Runs the nmbake command with `args` (shell words; relative paths are relative to the folder) in
// `dir`, or in a fresh scratch_dir() when `dir` is empty. stdout and stderr go to out.txt and
// err.txt in the folder, stdin reads /dev/null; an r.json left there by an earlier run is removed
// first. Prints the command and what it printed.
// Without a `prefix` the command runs in this process (cli/command.h: the code of the binary's
// main(), without a process start's ~0.4 s of loading OpenImageIO's libraries); with one (a shell
// command such as "ulimit -v 3000000 &&"), or with NMBAKE_TEST_PROCESS=1 in the environment, the
// binary <build>/baker/nmbake runs in a shell. The cli.nmbake.* tests run the binary too.
CliRun run_nmbake(const std::string& args, const std::string& prefix = "", const std::string& dir = "");

// Runs the nmbake command (cli/command.h) in this process with the arguments `words` (without the
// program's name), in folder `dir`: stdin reads /dev/null, stdout and stderr go to the files
// `out_name` and `err_name` there; the working directory and the three descriptors are restored
// after. Returns the exit status.
int run_nmbake_in(const std::vector<std::string>& words, const std::string& dir, const std::string& out_name = "out.txt",
                  const std::string& err_name = "err.txt");

// The same for any command with a main()'s signature (nmdiff_command of nmdiff/command.h, say):
// runs `command` with the program name `name` and the arguments `words` in folder `dir`.
int run_command_in(int (*command)(int, char**), const std::string& name, const std::vector<std::string>& words,
                   const std::string& dir, const std::string& out_name = "out.txt", const std::string& err_name = "err.txt");

// The words of a command line as bash splits them: single and double quotes and backslashes; an
// unquoted shell operator, glob or $ throws std::invalid_argument (nothing here runs a shell).
std::vector<std::string> shell_words(const std::string& line);

// Whether `what` occurs in `s`.
bool contains(const std::string& s, const std::string& what);

// A size x size bake of the normal map with `samples` per texel and `padding` texels of padding.
BakeOptions bake_options(int size, int samples = 1, int padding = 0);

// A planar grid of nx x ny quads (two triangles each) covering [x0,x1] x [y0,y1] at z = 0,
// normals +Z, UVs mapping the grid onto [0,1]^2 (u along x, v along y).
Mesh make_grid(int nx, int ny, float x0 = -1, float x1 = 1, float y0 = -1, float y1 = 1);

// A torus around +Z (major radius R, minor r) with nu x nv quads, analytic normals and UVs
// u = around the major circle, v = around the tube; seam vertices are bit-identical in position
// and normal but carry their own UVs.
Mesh make_torus(int nu, int nv, float R = 1.0f, float r = 0.35f);

// A grid of nx x ny quads over [-1,1]^2 with z = height(x, y) and the given per-vertex normals
// (normal(x, y) must return a unit vector); UVs map [-1,1]^2 onto [0,1]^2.
template <typename H, typename N>
Mesh make_height_field(int nx, int ny, H height, N normal) {
  Mesh m = make_grid(nx, ny);
  m.normals.clear();
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    glm::vec3& p = m.positions[i];
    const double x = p.x, y = p.y;
    p.z = float(height(x, y));
    m.normals.push_back(glm::vec3(normal(x, y)));
  }
  m.normal_index = m.position_index;
  return m;
}

// Angle in degrees between two directions (0 when either is zero).
double angle_deg(const glm::dvec3& a, const glm::dvec3& b);

// a and b hold the same bits (+0 and -0 differ; a NaN equals itself).
bool same_bits(double a, double b);
bool same_bits(float a, float b);

// Decodes an encoded map value c in [0,1]^3 to a unit tangent-space vector.
glm::dvec3 decode_rgb(const float* c);

// For every texel centre covered by `low` (the lowest triangle index wins, as in the bake), the
// tangent-space `map` decoded to a world normal with the covering triangle's frame: calls
// fn(x, y, world, P, triangle) with P the low-poly point under the texel centre.
void for_each_decoded_texel(
    const Mesh& low, const Image& map,
    const std::function<void(int x, int y, const glm::dvec3& world, const glm::dvec3& point, std::size_t triangle)>& fn);

// The covered texels of `r` (a bake from `low` with options `o`, or a UDIM tile's with `tile`) whose
// map bits the bake's tracer, given the same samples, does not give again over `traced` (the bake's
// kept trace inputs): trace_texels, as the error estimate calls it, snapped and encoded as the map
// (write_texel_row). 0 when the estimate's re-bake is the bake, bit for bit; `covered` receives how
// many texels were compared.
std::size_t texels_traced_otherwise(const Mesh& low, const TraceInputs& traced, const BakeOptions& o, const BakeResult& r,
                                    std::size_t* covered = nullptr, const UvTileFilter* tile = nullptr);

}  // namespace nmbake::test
