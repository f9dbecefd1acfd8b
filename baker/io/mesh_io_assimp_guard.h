// Checks made before a file reaches Assimp, and the thread it reads on (mesh_io_assimp.cpp).
// Assimp recurses over what it reads (JSON, XML, FBX records, node trees: deep enough ones
// overflow the stack) and trusts lengths in headers (it allocates what a GLB chunk claims). Each check returns the problem, or ""
// when it finds none; what a check cannot see is left to Assimp, which reads on a thread whose stack grows with the file. Pure
// functions of the bytes: no Assimp here.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

namespace nmbake::mesh_io_detail {

// Deeper nesting than this (JSON, XML elements, braces, FBX records, glTF nodes) is refused.
constexpr std::size_t kMaxNesting = 1000;

// A GLB's 12-byte header (magic, version 1 or 2, total length within the file) and every chunk's
// length within the total. `json` receives the JSON chunk (version 1: the content).
std::string glb_problem(std::string_view bytes, std::string_view& json);

// Nesting deeper than kMaxNesting in a text file: of arrays and objects for `json`, else of XML
// elements where the text starts with '<' (after a BOM and blanks), else of { } outside "strings".
// Binary files (a zero byte in the first 4 KiB) are not looked at.
std::string nesting_problem(std::string_view bytes, bool json);

// A glTF's node tree (from its JSON) or a COLLADA file's (nodes, nested and by <instance_node>):
// a node nested more than kMaxNesting deep, in a cycle, or standing for more than 2^20 nodes once
// Assimp has copied it for every mention (a chain of doubled children grows as 2^n). What does
// not parse is left to Assimp.
std::string gltf_nodes_problem(std::string_view json);
std::string collada_nodes_problem(std::string_view xml);

// A glTF accessor without a buffer view (zeros, or sparse) of more than a quarter of `budget` bytes
// (counted at 4 bytes a component): Assimp allocates it, about three times over. The caller
// refuses it as a size (exit 4).
std::string gltf_accessor_problem(std::string_view json, std::uint64_t budget);

// An FBX file's records (binary) nested more than kMaxNesting deep, or its models' tree (by "OO"
// connections, binary or text) failing as gltf_nodes_problem's (a cycle made Assimp recurse for
// ever). Damaged records are left to Assimp.
std::string fbx_problem(std::string_view bytes);

// The longest line of Assimp's own error text an error message carries (one_line, errors.h).
constexpr std::size_t kAssimpMessageMax = 160;

// The stack for reading a file of `size` bytes: 256 times the size, at least 256 MiB, at most 4 GiB
// (reserved, not used: pages are touched only as deep as the reader goes).
std::size_t reader_stack_bytes(std::size_t size);

// Runs `read` on a thread with a stack of `stack_bytes`, or on this one when no such thread can
// start (ulimit -v); an exception of `read` is rethrown here.
void run_on_big_stack(std::size_t stack_bytes, const std::function<void()>& read);

}  // namespace nmbake::mesh_io_detail
