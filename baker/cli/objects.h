// The objects of a bake's meshes for the report, and matching them by name (--match names).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/mesh.h"
#include "core/object_match.h"
#include "pipeline/bake.h"

namespace nmbake {

// A mesh's objects (Mesh::objects) with their triangle counts.
struct ObjectList {
  std::vector<Mesh::Object> objects;
  std::vector<std::size_t> triangles;
  std::vector<std::string> names() const;
};
ObjectList object_list(const Mesh& mesh);

struct MatchInfo {
  bool on = false;  // --match names
  MatchSuffixes suffixes;
  ObjectMatch match;
};

// --match names: groups the objects of `low` and `high` by base name (object_match.h) into the
// options' low_object_group and high_object_group. `suffix_text` is --match-suffixes ("" for the
// defaults); a suffix given there that ends no object name of its side is a UsageError.
MatchInfo match_by_names(const ObjectList& low, const ObjectList& high, const std::string& suffix_text, BakeOptions& options);

// One warning per side with objects left unmatched, naming them.
std::vector<std::string> match_warnings(const MatchInfo& match, const ObjectList& low, const ObjectList& high,
                                        const std::string& low_path, const std::string& high_path);

// The report's "objects" (each object with its file, triangles, samples and hits, and its match
// group) and "match" sections.
void add_objects_report(nlohmann::json& report, const ObjectList& low, const ObjectList& high, const MatchInfo& match,
                        const BakeStats& stats);

}  // namespace nmbake
