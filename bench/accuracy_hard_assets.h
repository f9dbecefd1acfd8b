// The accuracy bench's "hard assets" section: the known-answer models of
// tests/procedural/hard_assets.h (close tubes, a thin shell, a rod in a bore, a bevelled box, a
// high-poly with flipped winding) baked with four settings and measured against the exact normal
// of the analytic surface the low-poly part's rays should land on, as tests/test_robust_hits.cpp
// measures them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace nmbake::bench {

struct HardAssetRow {
  std::string asset, setting;        // setting: default, closest, cage, old-rule
  int size = 0;                      // map side in texels (1 sample per texel)
  std::size_t texels = 0;            // covered texel centres measured
  double facing_away = 0.0;          // BakeStats::Pad::texels_facing_away / texels_covered
  double mean_deg = 0.0;             // mean angular error against the analytic normal, degrees
  double over1 = 0.0, over60 = 0.0;  // share of the texels more than 1 (60) degrees off
  double worst_deg = 0.0;
  std::uint64_t misses = 0, backface_skips = 0;
  double front = 0.0, rear = 0.0;  // BakeStats::Distances::front / rear: largest distances used (cage: its push), scene units
  double seconds = 0.0;            // bake_normal_map wall time (in-process; no files)
};

// Bakes every case of procedural::hard_asset_set() at each size with the settings
//  - default:  default BakeOptions (automatic cage, back faces skipped);
//  - closest:  RayPolicy::closest, otherwise default;
//  - cage:     an explicit cage: the low-poly moved along its per-position ray normals by
//              1.25 x the default bake's BakeStats::Distances::vertex_front.max (an artist's uniform push);
//  - old-rule: keep_backfaces with front and rear pinned to the global distances a bake with
//              back faces kept measures (rear given as the default bake's vertex_rear.max),
//              i.e. the rule the baker had before the automatic cage and the back-face filter.
// Prints a line per row to stderr. `notes` receives one line per case (its meshes).
std::vector<HardAssetRow> run_hard_assets(const std::vector<int>& sizes, std::vector<std::string>& notes);

// docs/accuracy/hard_assets.csv. Throws OutputError when it cannot be written.
void write_hard_assets_csv(const std::string& path, const std::vector<HardAssetRow>& rows);

// The Markdown section of accuracy.md: heading, what was measured, the notes and the table.
std::string hard_assets_markdown(const std::vector<HardAssetRow>& rows, const std::vector<std::string>& notes, double seconds);

}  // namespace nmbake::bench
