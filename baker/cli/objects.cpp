#include "cli/objects.h"

#include <algorithm>

#include "core/errors.h"

namespace nmbake {

std::vector<std::string> ObjectList::names() const {
  std::vector<std::string> out;
  for (const Mesh::Object& o : objects) out.push_back(o.name);
  return out;
}

ObjectList object_list(const Mesh& mesh) {
  ObjectList list;
  list.objects = mesh.objects.empty() ? std::vector<Mesh::Object>{{mesh.source, mesh.source}} : mesh.objects;
  list.triangles.assign(list.objects.size(), 0);
  if (mesh.triangle_object.empty()) list.triangles[0] = mesh.triangle_count();
  for (std::uint32_t k : mesh.triangle_object) ++list.triangles[k];
  return list;
}

MatchInfo match_by_names(const ObjectList& low, const ObjectList& high, const std::string& suffix_text, BakeOptions& o) {
  MatchInfo info;
  info.on = true;
  info.suffixes = suffix_text.empty() ? default_match_suffixes() : parse_match_suffixes(suffix_text);
  const std::vector<std::string> low_names = low.names(), high_names = high.names();
  if (!suffix_text.empty())
    if (const auto unused = unused_match_suffixes(low_names, high_names, info.suffixes); !unused.empty()) {
      const auto& [suffix, is_high] = unused.front();
      const ObjectList& side = is_high ? high : low;
      throw UsageError("--match-suffixes: '" + suffix + "' ends no " + (is_high ? "high" : "low") + "-poly object's name (" +
                       std::to_string(side.objects.size()) + " object(s) in " + side.objects.front().file + ", the first '" +
                       side.objects.front().name + "')");
    }
  info.match = match_objects(low_names, high_names, info.suffixes);
  o.low_object_group = info.match.low_group;
  o.high_object_group = info.match.high_group;
  return info;
}

namespace {

std::string name_list(const ObjectList& list, const std::vector<std::size_t>& which) {
  std::string out;
  const std::size_t shown = std::min<std::size_t>(which.size(), 8);
  for (std::size_t i = 0; i < shown; ++i) out += (i ? ", '" : "'") + list.objects[which[i]].name + "'";
  if (which.size() > shown) out += " and " + std::to_string(which.size() - shown) + " more";
  return out;
}

}  // namespace

std::vector<std::string> match_warnings(const MatchInfo& m, const ObjectList& low, const ObjectList& high,
                                        const std::string& low_path, const std::string& high_path) {
  std::vector<std::string> out;
  if (!m.on) return out;
  const ObjectMatch& match = m.match;
  if (!match.unmatched_low.empty())
    out.push_back("warning: " + low_path + ": --match names: " + std::to_string(match.unmatched_low.size()) +
                  " low-poly object(s) match no high-poly object and are left flat: " + name_list(low, match.unmatched_low));
  if (!match.unmatched_high.empty())
    out.push_back(
        "warning: " + high_path + ": --match names: " + std::to_string(match.unmatched_high.size()) +
        " high-poly object(s) match no low-poly object and are not baked from: " + name_list(high, match.unmatched_high));
  return out;
}

void add_objects_report(nlohmann::json& report, const ObjectList& low, const ObjectList& high, const MatchInfo& m,
                        const BakeStats& s) {
  using nlohmann::json;
  auto group = [&](const std::vector<std::uint32_t>& groups, std::size_t k) {
    return m.on && k < groups.size() && groups[k] < m.match.bases.size() ? json(m.match.bases[groups[k]]) : json(nullptr);
  };
  auto at = [](const std::vector<std::uint64_t>& v, std::size_t k) { return k < v.size() ? v[k] : 0; };
  json lows = json::array(), highs = json::array();
  for (std::size_t k = 0; k < low.objects.size(); ++k)
    lows.push_back({{"name", low.objects[k].name},
                    {"file", low.objects[k].file},
                    {"triangles", low.triangles[k]},
                    {"samples", at(s.trace.low_object_samples, k)},
                    {"hits", at(s.trace.low_object_hits, k)},
                    {"match", group(m.match.low_group, k)}});
  for (std::size_t k = 0; k < high.objects.size(); ++k)
    highs.push_back({{"name", high.objects[k].name},
                     {"file", high.objects[k].file},
                     {"triangles", high.triangles[k]},
                     {"hits", at(s.trace.high_object_hits, k)},
                     {"match", group(m.match.high_group, k)}});
  report["objects"] = {{"low", lows}, {"high", highs}};
  json unmatched_low = json::array(), unmatched_high = json::array(), suffixes = json::array();
  for (std::size_t k : m.match.unmatched_low) unmatched_low.push_back(low.objects[k].name);
  for (std::size_t k : m.match.unmatched_high) unmatched_high.push_back(high.objects[k].name);
  for (const auto& [l, h] : m.suffixes) suffixes.push_back({l, h});
  report["match"] = {{"mode", m.on ? "names" : "none"},
                     {"suffixes", suffixes},
                     {"groups", m.match.bases},
                     {"unmatched_low", unmatched_low},
                     {"unmatched_high", unmatched_high}};
  report["samples_unmatched"] = s.trace.samples_unmatched;
}

}  // namespace nmbake
