// Stage 2b of the bake, distances: how far rays reach and which way the high-poly's faces point,
// measured by probes from the low-poly along its ray normals (after a first BVH, stage 4).
//
// Three modes (README "Choosing the hit"): a cage read from a file (its rear measured per vertex
// unless --rear is given); one fixed distance for the whole scene where --front or --rear is given
// (the other measured for the whole scene); else the automatic cage, front and rear measured per
// vertex (trace/auto_cage.h).
#pragma once

#include "core/mesh.h"
#include "pipeline/bake.h"
#include "pipeline/bvh.h"
#include "pipeline/prepare.h"

namespace nmbake {

struct ReachMode {
  bool auto_cage = false;       // no --cage, --front or --rear: the automatic cage
  bool auto_distances = false;  // one of --front and --rear given: the other measured for the scene
  bool local_rear = false;      // rear measured per vertex (automatic cage, or a file's without --rear)
  bool probing = false;         // distances measured at all
  bool file_cage = false;       // rays start on a cage read from a file
  bool any_cage = false;        // rays start on a cage (file or automatic)
  double reach = 0.0;           // how far probes look: farther is another part of the model
  double floor = 0.0;           // the least distance measured (coincident meshes)

  static ReachMode of(const BakeOptions& opt, const Mesh* cage, const Prepared& s);
};

// Measures what `mode` leaves to measure and decides the high-poly's facing (unless back faces are
// kept), over the BVH `h`. Fills in `result.stats.distances`: front, rear, scene_front, scene_rear,
// auto_distances, auto_probe_beyond, backface_probe_share, high_facing, backfaces_skipped, cage,
// vertex_front, vertex_rear, cage_front_limited, cage_rear_limited; in `result`: cage_positions
// (automatic cage), vertex_rear and vertex_search (per-vertex rear). Turns an inverted high-poly
// (turn_inverted_high), attaches the automatic cage to `s` and sets every cage triangle's reach.
void measure_reach(const ReachMode& mode, const Mesh& low, const BakeOptions& opt, int threads, Prepared& s, HighScene& h,
                   BakeResult& result);

}  // namespace nmbake
