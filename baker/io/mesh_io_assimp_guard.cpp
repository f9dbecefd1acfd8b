#include "io/mesh_io_assimp_guard.h"

#include <pthread.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <exception>
#include <unordered_map>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/memory_budget.h"

namespace nmbake::mesh_io_detail {
namespace {

std::uint32_t u32(std::string_view bytes, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, bytes.data() + at, 4);  // little-endian hosts only, as the binary readers
  return v;
}

std::uint64_t u64(std::string_view bytes, std::size_t at) {
  std::uint64_t v = 0;
  std::memcpy(&v, bytes.data() + at, 8);
  return v;
}

std::string too_deep(std::size_t at) {
  return "nested more than " + std::to_string(kMaxNesting) + " deep (at byte " + std::to_string(at) + ")";
}

// From `at` (just after an opening quote) to just after the closing one; backslash escapes.
std::size_t skip_string(std::string_view t, std::size_t at) {
  for (; at < t.size(); ++at) {
    if (t[at] == '\\') ++at;
    else if (t[at] == '"') return at + 1;
  }
  return at;
}

std::string json_or_brace_nesting(std::string_view t, bool json) {
  std::size_t depth = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const char c = t[i];
    if (c == '"') {
      i = skip_string(t, i + 1) - 1;
    } else if (c == '{' || (json && c == '[')) {
      if (++depth > kMaxNesting) return too_deep(i);
    } else if ((c == '}' || (json && c == ']')) && depth > 0) {
      --depth;
    }
  }
  return "";
}

std::string xml_nesting(std::string_view t) {
  std::size_t depth = 0;
  for (std::size_t i = t.find('<'); i != std::string_view::npos; i = t.find('<', i + 1)) {
    const char next = i + 1 < t.size() ? t[i + 1] : '\0';
    std::string_view end = ">";
    if (t.substr(i, 4) == "<!--") end = "-->";
    else if (t.substr(i, 9) == "<![CDATA[") end = "]]>";
    const std::size_t close = t.find(end, i + 1);
    if (close == std::string_view::npos) return "";
    if (next == '/') {
      if (depth > 0) --depth;
    } else if (next != '?' && next != '!' && t[close - 1] != '/') {
      if (++depth > kMaxNesting) return too_deep(i);
    }
    i = close;
  }
  return "";
}

// Nodes and the nodes each holds or instantiates, as a file gives them.
struct NodeGraph {
  std::vector<std::vector<std::size_t>> children;
  std::vector<std::string> names;  // for messages
};

// A node in a cycle, nested more than kMaxNesting deep, or standing for more than kMaxNodeCopies
// nodes once every mention is a copy (as Assimp makes them: a chain of doubled children grows as
// 2^n); "" when none. Iterative depth first, every node once.
std::string node_graph_problem(const NodeGraph& g) {
  constexpr std::uint64_t kMaxNodeCopies = 1u << 20;
  const std::size_t n = g.children.size();
  auto name = [&](std::size_t i) { return "node " + g.names[i].substr(0, 64); };
  std::vector<char> state(n, 0);  // 1 on the path, 2 done
  std::vector<std::uint64_t> copies(n, 1);
  std::vector<std::pair<std::size_t, std::size_t>> path;  // (node, next child)
  for (std::size_t root = 0; root < n; ++root) {
    if (state[root]) continue;
    path.push_back({root, 0});
    state[root] = 1;
    while (!path.empty()) {
      auto& [node, next] = path.back();
      if (next == g.children[node].size()) {
        state[node] = 2;
        for (std::size_t c : g.children[node]) copies[node] = std::min(copies[node] + copies[c], kMaxNodeCopies + 1);
        if (copies[node] > kMaxNodeCopies)
          return name(node) + " stands for more than " + std::to_string(kMaxNodeCopies) + " copies of nodes";
        path.pop_back();
        continue;
      }
      const std::size_t child = g.children[node][next++];
      if (state[child] == 1) return name(child) + " is its own ancestor (a cycle)";
      if (state[child] == 2) continue;
      if (path.size() >= kMaxNesting) return name(child) + " is nested more than " + std::to_string(kMaxNesting) + " deep";
      state[child] = 1;
      path.push_back({child, 0});
    }
  }
  return "";
}

// The models of an FBX file (by id, or by name in FBX 6) and their "OO" connections.
struct FbxModels {
  std::vector<std::string> ids;
  std::vector<std::pair<std::string, std::string>> parent_child;
};

std::string fbx_models_problem(const FbxModels& models) {
  NodeGraph graph;
  std::unordered_map<std::string, std::size_t> index;
  for (const std::string& id : models.ids)
    if (index.emplace(id, graph.children.size()).second) {
      graph.children.emplace_back();
      graph.names.push_back("'" + id + "'");
    }
  for (const auto& [parent, child] : models.parent_child) {
    const auto p = index.find(parent), c = index.find(child);
    if (p != index.end() && c != index.end()) graph.children[p->second].push_back(c->second);
  }
  return node_graph_problem(graph);
}

// The first `n` properties of a binary record that are ids (L) or text (S), as text.
std::vector<std::string> fbx_ids(std::string_view p, std::size_t n) {
  std::vector<std::string> out;
  for (std::size_t at = 0; out.size() < n && at < p.size();) {
    const char type = p[at++];
    if (type == 'L' && p.size() - at >= 8) {
      out.push_back(std::to_string(static_cast<long long>(u64(p, at))));
      at += 8;
    } else if (type == 'S' && p.size() - at >= 4 && u32(p, at) <= p.size() - at - 4) {
      out.emplace_back(p.substr(at + 4, u32(p, at)));
      at += 4 + std::size_t(u32(p, at));
    } else {
      break;
    }
  }
  return out;
}

void fbx_connection(const std::vector<std::string>& v, FbxModels& models) {
  if (v.size() == 3 && v[0] == "OO") models.parent_child.push_back({v[2], v[1]});
}

void fbx_record(std::string_view name, std::string_view properties, FbxModels& models) {
  if (name == "Model")
    if (const auto ids = fbx_ids(properties, 1); !ids.empty()) models.ids.push_back(ids[0]);
  if (name == "C" || name == "Connect") fbx_connection(fbx_ids(properties, 3), models);
}

// Text FBX: "Model: 1000, "Model::a", "Mesh" {" and "C: "OO",1001,1000" (FBX 6: names, "Connect:").
void fbx_text_models(std::string_view t, FbxModels& models) {
  auto fields = [](std::string_view rest) {
    std::vector<std::string> out;
    for (std::size_t at = 0; at <= rest.size() && out.size() < 3;) {
      std::size_t end = std::min(rest.find_first_of(",{", at), rest.size());
      std::string_view f = rest.substr(at, end - at);
      while (!f.empty() && std::strchr(" \t\r\"", f.front())) f.remove_prefix(1);
      while (!f.empty() && std::strchr(" \t\r\"", f.back())) f.remove_suffix(1);
      out.emplace_back(f);
      if (end == rest.size() || rest[end] == '{') break;
      at = end + 1;
    }
    return out;
  };
  for (std::size_t at = 0; at < t.size();) {
    std::size_t end = std::min(t.find('\n', at), t.size());
    std::string_view line = t.substr(at, end - at);
    at = end + 1;
    while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
    if (line.substr(0, 6) == "Model:") {
      if (const auto f = fields(line.substr(6)); !f.empty()) models.ids.push_back(f[0]);
    } else if (line.substr(0, 2) == "C:" || line.substr(0, 8) == "Connect:") {
      fbx_connection(fields(line.substr(line[1] == ':' ? 2 : 8)), models);
    }
  }
}

}  // namespace

std::string glb_problem(std::string_view bytes, std::string_view& json) {
  if (bytes.size() < 12 || bytes.substr(0, 4) != "glTF") return "GLB header shorter than 12 bytes";
  const std::uint32_t version = u32(bytes, 4), length = u32(bytes, 8);
  const std::string claims = "the GLB header claims ";
  if (version != 1 && version != 2) return "GLB version " + std::to_string(version) + " (1 or 2 expected)";
  if (length > bytes.size() || length < 12)
    return claims + std::to_string(length) + " bytes, the file has " + std::to_string(bytes.size());
  if (version == 1) {
    if (length < 20) return claims + std::to_string(length) + " bytes: no room for the content header";
    const std::uint32_t content = u32(bytes, 12);
    if (content > length - 20)
      return "its content length " + std::to_string(content) + " runs past the file's " + std::to_string(length);
    json = bytes.substr(20, content);
    return "";
  }
  for (std::size_t at = 12, k = 0; at < length; ++k) {
    if (length - at < 8) return "GLB chunk " + std::to_string(k) + " at byte " + std::to_string(at) + " is cut short";
    const std::uint32_t chunk = u32(bytes, at);
    if (chunk > length - at - 8)
      return "GLB chunk " + std::to_string(k) + " claims " + std::to_string(chunk) + " bytes, " +
             std::to_string(length - at - 8) + " are left";
    if (k == 0) json = bytes.substr(at + 8, chunk);
    at += 8 + std::size_t(chunk);
  }
  return "";
}

std::string nesting_problem(std::string_view bytes, bool json) {
  if (std::memchr(bytes.data(), '\0', std::min<std::size_t>(bytes.size(), 4096))) return "";
  std::size_t first = bytes.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
  while (first < bytes.size() && std::strchr(" \t\r\n", bytes[first]) && bytes[first]) ++first;
  if (!json && first < bytes.size() && bytes[first] == '<') return xml_nesting(bytes);
  return json_or_brace_nesting(bytes, json);
}

std::string gltf_nodes_problem(std::string_view json) {
  const nlohmann::json doc = nlohmann::json::parse(json.begin(), json.end(), nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("nodes")) return "";
  // glTF 2.0 lists nodes and children by index; glTF 1.0 names them ({"id": {...}}, children by id).
  const nlohmann::json& nodes = doc["nodes"];
  if (!nodes.is_array() && !nodes.is_object()) return "";
  NodeGraph graph;
  std::unordered_map<std::string, std::size_t> by_id;
  for (auto it = nodes.begin(); it != nodes.end(); ++it) {
    const auto name = it->is_object() ? it->find("name") : it->end();
    const std::string id = nodes.is_array() ? std::to_string(graph.names.size()) : it.key();
    by_id.emplace(id, graph.names.size());
    graph.names.push_back(id + (name != it->end() && name->is_string() ? " '" + name->get<std::string>() + "'" : ""));
  }
  graph.children.resize(graph.names.size());
  std::size_t i = 0;
  for (auto it = nodes.begin(); it != nodes.end(); ++it, ++i) {
    if (!it->is_object() || !it->contains("children") || !(*it)["children"].is_array()) continue;
    for (const nlohmann::json& c : (*it)["children"]) {
      const auto k = c.is_number_unsigned() ? by_id.find(std::to_string(c.get<std::uint64_t>()))
                     : c.is_string()        ? by_id.find(c.get<std::string>())
                                            : by_id.end();
      if (k != by_id.end() && (nodes.is_array() == c.is_number_unsigned())) graph.children[i].push_back(k->second);
    }
  }
  return node_graph_problem(graph);
}

std::string gltf_accessor_problem(std::string_view json, std::uint64_t budget) {
  const nlohmann::json doc = nlohmann::json::parse(json.begin(), json.end(), nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("accessors") || !doc["accessors"].is_array()) return "";
  const std::unordered_map<std::string, std::uint64_t> components{{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
                                                                  {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
  const nlohmann::json& accessors = doc["accessors"];
  for (std::size_t i = 0; i < accessors.size(); ++i) {
    const nlohmann::json& a = accessors[i];
    if (!a.is_object() || a.contains("bufferView") || !a.contains("count") || !a["count"].is_number_unsigned()) continue;
    const auto type =
        a.contains("type") && a["type"].is_string() ? components.find(a["type"].get<std::string>()) : components.end();
    const double bytes = double(a["count"].get<std::uint64_t>()) * double(type == components.end() ? 1 : type->second) * 4.0;
    if (bytes > double(budget) / 4.0)
      return "accessor " + std::to_string(i) + " holds " + format_bytes(bytes) +
             " of zeros (no buffer view); Assimp needs about 3 times that, the memory budget is " + format_bytes(double(budget));
  }
  return "";
}

std::string collada_nodes_problem(std::string_view xml) {
  NodeGraph graph;
  std::unordered_map<std::string, std::size_t> by_id;
  std::vector<std::pair<std::size_t, std::string>> instances;  // (node, id it instantiates)
  std::vector<std::size_t> open;
  auto attribute = [](std::string_view tag, std::string_view name) {
    for (std::size_t at = tag.find(name); at != std::string_view::npos; at = tag.find(name, at + 1)) {
      const std::size_t quote = at + name.size() + 1;
      if (at == 0 || !std::isspace(static_cast<unsigned char>(tag[at - 1])) || quote >= tag.size() || tag[quote - 1] != '=' ||
          (tag[quote] != '"' && tag[quote] != '\''))
        continue;
      const std::size_t end = tag.find(tag[quote], quote + 1);
      return std::string(tag.substr(quote + 1, end == std::string_view::npos ? std::string_view::npos : end - quote - 1));
    }
    return std::string();
  };
  for (std::size_t at = xml.find('<'); at != std::string_view::npos; at = xml.find('<', at + 1)) {
    const std::size_t close = xml.find('>', at);
    if (close == std::string_view::npos) break;
    const std::string_view tag = xml.substr(at, close - at + 1);
    const bool empty = tag.size() > 1 && tag[tag.size() - 2] == '/';
    if (tag.substr(0, 7) == "</node>" || tag.substr(0, 7) == "</node ") {
      if (!open.empty()) open.pop_back();
    } else if (tag.substr(0, 6) == "<node " || tag.substr(0, 6) == "<node>" || tag.substr(0, 6) == "<node/") {
      const std::size_t k = graph.children.size();
      graph.children.emplace_back();
      const std::string id = attribute(tag, "id");
      graph.names.push_back("'" + id + "'");
      if (!id.empty()) by_id.emplace(id, k);
      if (!open.empty()) graph.children[open.back()].push_back(k);
      if (!empty) open.push_back(k);
    } else if (tag.substr(0, 15) == "<instance_node " && !open.empty()) {
      const std::string url = attribute(tag, "url");
      if (!url.empty() && url[0] == '#') instances.push_back({open.back(), url.substr(1)});
    }
  }
  for (const auto& [node, id] : instances)
    if (const auto it = by_id.find(id); it != by_id.end()) graph.children[node].push_back(it->second);
  return node_graph_problem(graph);
}

std::string fbx_problem(std::string_view bytes) {
  FbxModels models;
  if (bytes.size() < 27 || bytes.substr(0, 18) != "Kaydara FBX Binary") {
    fbx_text_models(bytes, models);
    return fbx_models_problem(models);
  }
  const bool wide = u32(bytes, 23) >= 7500;  // 64-bit record offsets from FBX 7.5
  const std::size_t header = wide ? 25 : 13;
  std::vector<std::uint64_t> ends;  // of the records the walk is inside
  std::size_t at = 27;
  while (at + header <= bytes.size()) {
    while (!ends.empty() && at >= ends.back()) ends.pop_back();
    const std::uint64_t end = wide ? u64(bytes, at) : u32(bytes, at);
    const std::uint64_t properties = wide ? u64(bytes, at + 16) : u32(bytes, at + 8);
    const std::size_t name = std::uint8_t(bytes[at + header - 1]);
    const std::uint64_t body = at + header + name + properties;
    if (end == 0) {  // the null record closing a list of children
      if (ends.empty()) break;
      at = std::size_t(ends.back());
      ends.pop_back();
      continue;
    }
    if (end <= at || end > bytes.size() || body > end || (!ends.empty() && end > ends.back())) return "";  // for Assimp
    if (ends.size() >= kMaxNesting) return "FBX records " + too_deep(at);
    fbx_record(bytes.substr(at + header, name), bytes.substr(at + header + name, std::size_t(properties)), models);
    if (body < end) ends.push_back(end);
    at = std::size_t(body < end ? body : end);
  }
  return fbx_models_problem(models);
}

std::size_t reader_stack_bytes(std::size_t size) {
  const std::size_t mib = std::size_t(1) << 20;
  return std::clamp<std::size_t>(size > (std::size_t(4096) * mib) / 256 ? 4096 * mib : size * 256, 256 * mib, 4096 * mib);
}

void run_on_big_stack(std::size_t stack_bytes, const std::function<void()>& read) {
  struct Call {
    const std::function<void()>* read;
    std::exception_ptr error;
  } call{&read, nullptr};
  auto body = [](void* p) -> void* {
    auto* c = static_cast<Call*>(p);
    try {
      (*c->read)();
    } catch (...) {
      c->error = std::current_exception();
    }
    return nullptr;
  };
  pthread_attr_t attr;
  pthread_t thread;
  if (pthread_attr_init(&attr) != 0) return read();
  const bool started = pthread_attr_setstacksize(&attr, stack_bytes) == 0 && pthread_create(&thread, &attr, body, &call) == 0;
  pthread_attr_destroy(&attr);
  if (!started) return read();
  pthread_join(thread, nullptr);
  if (call.error) std::rethrow_exception(call.error);
}

}  // namespace nmbake::mesh_io_detail
