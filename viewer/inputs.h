// nmview's input files: which one is the low-poly, which the map, which the high-poly. Two orders
// are accepted, nmview's own `nmview LOW MAP HIGH` and nmbake's `nmview LOW HIGH -m MAP`; with three
// files the map may stand anywhere, since meshes and images are told apart by their content (magic
// bytes, a text mesh's first statement, else OpenImageIO's header probe), the extension deciding
// only where the content says nothing.
#pragma once

#include <string>
#include <vector>

namespace nmview {

enum class FileKind {
  mesh,     // a mesh format nmbake reads (OBJ, PLY, OFF, STL, glTF/GLB, FBX, DAE, 3DS, ...)
  image,    // a map: an image format OpenImageIO reads, or a path with <MAP> (a texture set)
  neither,  // a regular file that is neither
  unknown,  // not looked into: missing, not a regular file (FIFO, device), unreadable; its loader says why
};

// What `path` holds. Reads at most its first 4 KiB (and an image's header) of a regular file only:
// a FIFO or device is never opened. Throws nothing.
FileKind classify_file(const std::string& path);

struct InputFiles {
  std::string low, map, high;
};

// The three inputs from the positional `files` (2 or 3 of them, as given) and -m/--map's
// `map_option` (empty when absent):
// - with -m: `files` are LOW HIGH, neither may be an image, and the map may not be a mesh;
// - without: of three files the one image is the map and the two meshes are LOW then HIGH; where
//   one file cannot be looked into (missing, a FIFO) and the two others are meshes, it is the map;
//   otherwise (none or several undecided) the order LOW MAP HIGH stands and the loaders report.
// Throws nmbake::UsageError (exit 1) for a form that names no map, no high-poly, two maps or a map
// in place of a mesh, and nmbake::InputError (exit 2) for a file that is neither a mesh nor an image; each one
// line naming the file.
InputFiles resolve_inputs(const std::vector<std::string>& files, const std::string& map_option);

}  // namespace nmview
