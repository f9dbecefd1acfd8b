// Matching low-poly objects to high-poly objects by name (--match names), so that each low-poly
// part is baked only from its own high-poly part: the parts of an exploded or intersecting model
// never imprint on each other.
//
// A name's base is the name without a suffix of its side (case-insensitive, at the end): by default
// "_low"/"_high" and "_lp"/"_hp" ("arm_low" and "arm_high" are both "arm"); a name without one is
// its own base. Objects of one base form a group: a low-poly object's rays see the high-poly
// objects of its group (BakeOptions::low_object_group, high_object_group).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace nmbake {

// Pairs of (low-poly suffix, high-poly suffix).
using MatchSuffixes = std::vector<std::pair<std::string, std::string>>;

inline MatchSuffixes default_match_suffixes() { return {{"_low", "_high"}, {"_lp", "_hp"}}; }

// "_lo:_hi,_LP:_HP" as pairs; throws UsageError on a malformed list (an empty suffix, a pair
// without ':').
MatchSuffixes parse_match_suffixes(const std::string& text);

struct ObjectMatch {
  // Per object, its group (an index into `bases`), or kNoMatch (bake.h's value) when the other side
  // has no object of its base.
  std::vector<std::uint32_t> low_group, high_group;
  std::vector<std::string> bases;                          // per group, its base name
  std::vector<std::size_t> unmatched_low, unmatched_high;  // object indices, in order
};

// The base of `name` with the suffixes of one side (low: first of each pair, high: second).
std::string match_base(const std::string& name, const MatchSuffixes& suffixes, bool high);

ObjectMatch match_objects(const std::vector<std::string>& low_names, const std::vector<std::string>& high_names,
                          const MatchSuffixes& suffixes);

// The suffixes (of `suffixes`, either side) that end no object name of their side, each with its
// side (true: high-poly): empty when each matches some object.
std::vector<std::pair<std::string, bool>> unused_match_suffixes(const std::vector<std::string>& low_names,
                                                                const std::vector<std::string>& high_names,
                                                                const MatchSuffixes& suffixes);

}  // namespace nmbake
