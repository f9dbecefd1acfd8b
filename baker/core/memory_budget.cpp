#include "core/memory_budget.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>

namespace nmbake {

namespace {

constexpr std::uint64_t kUnknown = std::numeric_limits<std::uint64_t>::max();

// The first number in a file, or kUnknown ("max", missing, unreadable).
std::uint64_t read_number(const char* path) {
  std::ifstream in(path);
  std::uint64_t v = 0;
  if (!(in >> v)) return kUnknown;
  return v;
}

std::uint64_t mem_available() {
  std::ifstream in("/proc/meminfo");
  std::string key, unit;
  std::uint64_t value = 0;
  while (in >> key >> value >> unit)
    if (key == "MemAvailable:") return value * 1024;
  const long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page) : kUnknown;
}

std::uint64_t cgroup_headroom() {
  std::uint64_t limit = read_number("/sys/fs/cgroup/memory.max");
  std::uint64_t usage = read_number("/sys/fs/cgroup/memory.current");
  if (limit == kUnknown) {  // cgroup v1
    limit = read_number("/sys/fs/cgroup/memory/memory.limit_in_bytes");
    usage = read_number("/sys/fs/cgroup/memory/memory.usage_in_bytes");
    if (limit >= (std::uint64_t(1) << 60)) return kUnknown;  // v1 reports "no limit" as a huge number
  }
  if (limit == kUnknown) return kUnknown;
  if (usage == kUnknown) usage = 0;
  return limit > usage ? limit - usage : 0;
}

// What the address-space limit (ulimit -v) leaves beyond what the process maps now.
std::uint64_t address_space_headroom() {
  rlimit rl{};
  if (getrlimit(RLIMIT_AS, &rl) != 0 || rl.rlim_cur == RLIM_INFINITY) return kUnknown;
  std::ifstream in("/proc/self/statm");
  std::uint64_t pages = 0;
  in >> pages;  // total program size in pages
  const std::uint64_t mapped = pages * std::uint64_t(sysconf(_SC_PAGESIZE));
  return rl.rlim_cur > mapped ? rl.rlim_cur - mapped : 0;
}

}  // namespace

std::uint64_t memory_budget_bytes() { return std::min({mem_available(), cgroup_headroom(), address_space_headroom()}); }

std::string format_bytes(double bytes) {
  char text[32];
  if (bytes >= 1e9) std::snprintf(text, sizeof text, "%.1f GB", bytes / 1e9);
  else if (bytes >= 1e6) std::snprintf(text, sizeof text, "%.1f MB", bytes / 1e6);
  else if (bytes >= 1e4) std::snprintf(text, sizeof text, "%.1f kB", bytes / 1e3);
  else std::snprintf(text, sizeof text, "%.0f bytes", bytes);
  return text;
}

}  // namespace nmbake
