// How nmdiff treats the conventions two maps' nmbake metadata state (pure; no file I/O).
//
// By default a convention the two maps state differently is a difference (exit 1): a golden test
// must catch a map baked with the wrong --green. --same-convention restores the normalising
// comparison: each map decoded in its own green, bitangents not compared.
#pragma once

#include <string>
#include <vector>

#include "nmdiff.h"

namespace nmbake::diff {

// What a map's metadata says: nmbake:green ("up", "down"), nmbake:space ("tangent", "object"),
// nmbake:bitangent ("pixel", "vertex"); "" where absent.
struct MapConventions {
  std::string green, space, bitangent;
};

struct ConventionVerdict {
  // "green", "space", "bitangent", in that order: stated by both maps, differently. A difference:
  // the maps are compared as they are (B decoded in A's green). Never with same_convention; green
  // not when the command line gives the greens (--green-a, --green-b).
  std::vector<std::string> differences;
  std::string described;  // "green up against down, space tangent against object"; "" when none
  // Both maps state their green (up or down) and the command line does not: decode with these.
  bool green_from_metadata = false;
  GreenAxis green_a = GreenAxis::up, green_b = GreenAxis::up;
  // same_convention with different spaces: normals in different frames cannot be compared.
  bool spaces_clash = false;
};

ConventionVerdict compare_conventions(const MapConventions& a, const MapConventions& b, bool greens_given, bool same_convention);

}  // namespace nmbake::diff
