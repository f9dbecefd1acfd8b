#include "cli/warnings.h"

#include <cstdio>
#include <string>

#include "cli/format_line.h"

namespace nmbake {

std::vector<std::string> load_warnings(const MeshLoadInfo& info, const std::string& path) {
  std::vector<std::string> out;
  const char* lost = "all the file's normals were dropped and smooth normals computed (hard edges lost)";
  if (info.normals_dropped && info.faces_without_normals)
    out.push_back(format_line("warning: %s: %zu of %zu faces %s no normals: %s", path.c_str(), info.faces_without_normals,
                              info.file_faces, info.faces_without_normals == 1 ? "has" : "have", lost));
  else if (info.normals_dropped)
    out.push_back(format_line("warning: %s: %zu %s length 0: %s", path.c_str(), info.zero_normals,
                              info.zero_normals == 1 ? "normal has" : "normals have", lost));
  if (info.uvs_dropped)
    out.push_back(format_line("warning: %s: %zu of %zu faces %s no UVs: all the file's UVs were dropped", path.c_str(),
                              info.faces_without_uvs, info.file_faces, info.faces_without_uvs == 1 ? "has" : "have"));
  return out;
}

void WarningLog::add(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) {
    all_.push_back(w);
    if (print_) std::fprintf(stderr, "nmbake: %s\n", w.c_str());
  }
}

void WarningLog::check_strict() const {
  if (!strict_ || all_.empty()) return;
  std::string first = all_.front();
  if (first.rfind("warning: ", 0) == 0) first.erase(0, 9);
  throw StrictError("--strict: " + std::to_string(all_.size()) + (all_.size() == 1 ? " warning" : " warnings") +
                    ", the first: " + first + "; nothing written");
}

std::vector<std::string> bake_warnings(const BakeStats& s, const MeshTopology& t, const std::string& low, const std::string& high,
                                       const UvTilesNote& uv_tiles, const PairNote& pair) {
  std::vector<std::string> out;
  if (s.prepare.degenerate_uv_triangles)
    out.push_back(format_line("warning: %s: %zu triangles have zero UV area (they cover no texels and give no tangent)",
                              low.c_str(), s.prepare.degenerate_uv_triangles));
  if (s.prepare.degenerate_3d_triangles)
    out.push_back(
        format_line("warning: %s: %zu triangles have zero area (their texels take the normal found from a point or a line)",
                    low.c_str(), s.prepare.degenerate_3d_triangles));
  if (uv_tiles.udim) {  // udim.h: uv_outside_* count the triangles cut at their tile's edge and those in no tile
    if (s.prepare.uv_outside_triangles)
      out.push_back(
          format_line("warning: %s: %zu triangles reach beyond their UDIM tile (by their UV centroid) and are cut at its edge",
                      low.c_str(), s.prepare.uv_outside_triangles));
    if (s.prepare.uv_outside_entirely_triangles)
      out.push_back(format_line("warning: %s: %zu triangles lie in no UDIM tile (u below 0 or from 10 on, v below 0): not baked",
                                low.c_str(), s.prepare.uv_outside_entirely_triangles));
  } else if (s.prepare.uv_outside_triangles) {
    std::string tiles;
    if (uv_tiles.beyond_triangles)
      tiles = format_line(
          "; %zu triangles (%zu texels) lie in UDIM tiles %s: -o with <UDIM> (normal.<UDIM>.png) bakes them, one "
          "map per tile",
          uv_tiles.beyond_triangles, uv_tiles.beyond_texels, uv_tiles.beyond_tiles.c_str());
    out.push_back(
        format_line("warning: %s: %zu triangles have UVs outside [0,1] (%zu entirely outside, not baked); only the part inside "
                    "the map is baked, UVs are not wrapped%s",
                    low.c_str(), s.prepare.uv_outside_triangles, s.prepare.uv_outside_entirely_triangles, tiles.c_str()));
  }
  if (pair.overlap && pair.overlap->overlapped)
    out.push_back("warning: " + overlap_text(*pair.overlap, s.trace.overlapping_samples, low, true));
  else if (s.trace.overlapping_samples)  // too little to show on the overlap check's grid
    out.push_back(format_line("warning: %s: UV islands overlap slightly (%llu samples covered twice; the lower face number wins)",
                              low.c_str(), (unsigned long long)s.trace.overlapping_samples));
  if (s.trace.samples_covered && double(s.trace.misses) > kMissShareWarn * double(s.trace.samples_covered))
    out.push_back(format_line("warning: %.1f%% of samples missed %s and were written flat; %s",
                              100.0 * double(s.trace.misses) / double(s.trace.samples_covered), high.c_str(),
                              pair.boxes_mismatch ? "LOW and HIGH do not lie in one place or differ in size (above)"
                                                  : "check --front/--rear (or --cage)"));
  if (s.trace.texels_covered && double(s.pad.texels_facing_away) > kFacingAwayShareWarn * double(s.trace.texels_covered))
    out.push_back(
        format_line("warning: %.1f%% of covered texels point into the low-poly: are the normals or the winding of %s inverted?",
                    100.0 * double(s.pad.texels_facing_away) / double(s.trace.texels_covered), high.c_str()));
  if (s.distances.high_facing == BakeStats::HighFacing::inverted)
    out.push_back(format_line(
        "warning: %s: its faces look inverted (%.0f%% of the surfaces nearest the low-poly face into it): their fronts "
        "were taken the other way round%s%s",
        high.c_str(), 100.0 * s.distances.backface_probe_share,
        s.prepare.high_normals_computed() ? " and the computed normals turned outwards"
                                          : "; the file's normals are kept, so the map points into the surface",
        pair.boxes_mismatch ? " (judged from the few probes that met it: LOW and HIGH do not match, above)" : ""));
  else if (s.distances.high_facing == BakeStats::HighFacing::mixed)
    out.push_back(
        format_line("warning: %s: some of its parts look inverted (%.0f%% of the surfaces nearest the low-poly face into it): "
                    "back faces are kept for this bake, as with --keep-backfaces",
                    high.c_str(), 100.0 * s.distances.backface_probe_share));
  if (s.pad.suspect_share > kSuspectShareWarn)
    out.push_back(
        format_line("warning: %.2f%% of covered texels are suspect (normal tilted over %.0f degrees from the low-poly's, or "
                    "samples disagreeing), %.0f%% of them in UV u %.3g-%.3g, v %.3g-%.3g; see --suspect-mask",
                    100.0 * s.pad.suspect_share, kSuspectTiltDeg, 100.0 * s.pad.suspect_region_share, s.pad.suspect_region[0],
                    s.pad.suspect_region[2], s.pad.suspect_region[1], s.pad.suspect_region[3]));
  if (s.prepare.coordinate_spacing > kCoordinateSpacingWarn)
    out.push_back(
        format_line("warning: coordinates reach %.3g, far from the origin for a scene this size: float precision there is "
                    "%.2g of the scene diagonal (above %.0e the map degrades measurably); move the meshes near the origin",
                    s.prepare.largest_coordinate, s.prepare.coordinate_spacing, kCoordinateSpacingWarn));
  std::string topo;
  auto add = [&](std::size_t n, const char* what) {
    if (!n) return;
    topo += (topo.empty() ? "" : ", ") + std::to_string(n) + " " + what;
  };
  add(t.non_manifold_edges, "non-manifold edges");
  add(t.isolated_vertices, "isolated vertices (ignored)");
  add(t.inconsistent_winding_faces, s.prepare.high_normals_computed()
                                        ? "faces wound against their neighbours (turned before computing normals)"
                                        : "faces wound against their neighbours (the file's normals are used)");
  add(t.duplicate_faces, "duplicate faces (counted once in computed normals)");
  if (!topo.empty()) out.push_back("warning: " + high + ": " + topo);
  return out;
}

}  // namespace nmbake
