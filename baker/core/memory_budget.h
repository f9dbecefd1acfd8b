// How much memory a bake or an image read may take on this machine, checked before the big
// buffers exist.
#pragma once

#include <cstdint>
#include <string>

namespace nmbake {

// The smallest of: MemAvailable (/proc/meminfo), the cgroup's limit minus its usage (containers,
// cgroup v2 memory.max or v1 memory.limit_in_bytes), and the address-space limit (ulimit -v) minus
// what the process already maps. UINT64_MAX when none is known.
std::uint64_t memory_budget_bytes();

// "4.8 GB", "812 bytes": a byte count for a message (decimal units).
std::string format_bytes(double bytes);

}  // namespace nmbake
