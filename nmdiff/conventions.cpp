#include "conventions.h"

namespace nmbake::diff {

namespace {

bool stated_differently(const std::string& a, const std::string& b) { return !a.empty() && !b.empty() && a != b; }

bool known_green(const std::string& g) { return g == "up" || g == "down"; }

GreenAxis green_axis(const std::string& g) { return g == "down" ? GreenAxis::down : GreenAxis::up; }

}  // namespace

ConventionVerdict compare_conventions(const MapConventions& a, const MapConventions& b, bool greens_given, bool same_convention) {
  ConventionVerdict v;
  auto differ = [&](const char* name, const std::string& x, const std::string& y) {
    v.differences.push_back(name);
    v.described += (v.described.empty() ? "" : ", ") + std::string(name) + " " + x + " against " + y;
  };
  if (!greens_given && known_green(a.green) && known_green(b.green)) {
    v.green_from_metadata = true;
    v.green_a = green_axis(a.green);
    // Compared as they are (B in A's green) unless the maps are to be brought into one convention.
    v.green_b = same_convention ? green_axis(b.green) : v.green_a;
    if (!same_convention && a.green != b.green) differ("green", a.green, b.green);
  }
  if (stated_differently(a.space, b.space)) {
    if (same_convention) v.spaces_clash = true;
    else differ("space", a.space, b.space);
  }
  if (!same_convention && stated_differently(a.bitangent, b.bitangent)) differ("bitangent", a.bitangent, b.bitangent);
  return v;
}

}  // namespace nmbake::diff
