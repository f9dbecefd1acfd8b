#include "core/object_match.h"

#include <algorithm>
#include <cctype>
#include <unordered_map>

#include "core/errors.h"

namespace nmbake {

namespace {

constexpr std::uint32_t kNone = 0xffffffffu;  // bake.h's kNoMatch (core does not include pipeline)

bool ends_with_nocase(const std::string& name, const std::string& suffix) {
  if (suffix.empty() || suffix.size() > name.size()) return false;
  const std::size_t at = name.size() - suffix.size();
  for (std::size_t i = 0; i < suffix.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(name[at + i])) != std::tolower(static_cast<unsigned char>(suffix[i])))
      return false;
  return true;
}

}  // namespace

MatchSuffixes parse_match_suffixes(const std::string& text) {
  MatchSuffixes out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string pair = text.substr(start, comma - start);
    const std::size_t colon = pair.find(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == pair.size() || pair.find(':', colon + 1) != std::string::npos)
      throw UsageError("--match-suffixes: expected LOW:HIGH pairs separated by commas (e.g. _low:_high,_lp:_hp), got '" + text +
                       "'");
    out.emplace_back(pair.substr(0, colon), pair.substr(colon + 1));
    start = comma + 1;
  }
  return out;
}

std::string match_base(const std::string& name, const MatchSuffixes& suffixes, bool high) {
  // The longest suffix that ends the name ("_high" before "_h").
  std::size_t cut = 0;
  for (const auto& [low_suffix, high_suffix] : suffixes) {
    const std::string& suffix = high ? high_suffix : low_suffix;
    if (ends_with_nocase(name, suffix) && suffix.size() < name.size()) cut = std::max(cut, suffix.size());
  }
  return name.substr(0, name.size() - cut);
}

ObjectMatch match_objects(const std::vector<std::string>& low_names, const std::vector<std::string>& high_names,
                          const MatchSuffixes& suffixes) {
  ObjectMatch m;
  std::unordered_map<std::string, std::uint32_t> high_base;  // base -> group
  std::vector<std::string> high_bases(high_names.size());
  for (std::size_t k = 0; k < high_names.size(); ++k) high_bases[k] = match_base(high_names[k], suffixes, true);
  std::unordered_map<std::string, bool> high_has;
  for (const std::string& b : high_bases) high_has[b] = true;
  // Groups in the order of the low-poly's objects.
  m.low_group.assign(low_names.size(), kNone);
  for (std::size_t k = 0; k < low_names.size(); ++k) {
    const std::string base = match_base(low_names[k], suffixes, false);
    if (!high_has.count(base)) {
      m.unmatched_low.push_back(k);
      continue;
    }
    const auto [it, added] = high_base.try_emplace(base, std::uint32_t(m.bases.size()));
    if (added) m.bases.push_back(base);
    m.low_group[k] = it->second;
  }
  m.high_group.assign(high_names.size(), kNone);
  for (std::size_t k = 0; k < high_names.size(); ++k) {
    const auto it = high_base.find(high_bases[k]);
    if (it == high_base.end()) {
      m.unmatched_high.push_back(k);
      continue;
    }
    m.high_group[k] = it->second;
  }
  return m;
}

std::vector<std::pair<std::string, bool>> unused_match_suffixes(const std::vector<std::string>& low_names,
                                                                const std::vector<std::string>& high_names,
                                                                const MatchSuffixes& suffixes) {
  std::vector<std::pair<std::string, bool>> unused;
  for (const auto& [low_suffix, high_suffix] : suffixes) {
    bool low_used = false, high_used = false;
    for (const std::string& n : low_names) low_used = low_used || ends_with_nocase(n, low_suffix);
    for (const std::string& n : high_names) high_used = high_used || ends_with_nocase(n, high_suffix);
    if (!low_used) unused.emplace_back(low_suffix, false);
    if (!high_used) unused.emplace_back(high_suffix, true);
  }
  return unused;
}

}  // namespace nmbake
