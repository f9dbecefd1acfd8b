// Stiff and extreme geometry (issue 5, test_stability.cpp): hard edges on the low-poly (case 9) and
// the high-poly's topology: non-manifold edges, isolated vertices, inconsistent winding, inverted
// normals (case 10).
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/mesh_topology.h"
#include "stability_test_helpers.h"

using namespace nmbake;
using namespace nmbake::stability_test;

// ---------------------------------------------------------------------------------------------
// 9. Hard edges: rays follow position-averaged normals, frames use the file's split normals.

TEST(Stability, HardEdgesOpenNoGapsAndNoCracks) {
  const Mesh high = load("cylinder_high.obj");
  for (const char* name : {"hard_edges_low.obj", "hard_edges_split_low.obj"}) {
    const Mesh low = load_low(name);
    BakeOptions o = options(128, 0.5f);
    o.height = 32;
    const BakeResult r = bake_normal_map(low, high, nullptr, o);
    EXPECT_EQ(r.stats.trace.misses, 0u) << name;
    EXPECT_EQ(r.stats.trace.texels_covered, 128u * 32u) << name;  // the strip covers the map: no cracks
    EXPECT_TRUE(all_finite(r.map)) << name;
    // Along a row, the azimuth of the decoded normal (the cylinder's radial normal where the ray
    // hit) must rise steadily through 360 degrees: split rays at an edge would jump back ~23 deg.
    test::for_each_decoded_texel(low, r.map, [](int, int, const glm::dvec3&, const glm::dvec3&, std::size_t) {});
    std::vector<double> az(128, 0.0);
    std::vector<double> z(128, 0.0);
    test::for_each_decoded_texel(low, r.map, [&](int x, int y, const glm::dvec3& w, const glm::dvec3&, std::size_t) {
      if (y != 16) return;
      az[std::size_t(x)] = std::atan2(w.y, w.x) * 180.0 / 3.14159265358979323846;
      z[std::size_t(x)] = w.z;
    });
    double worst_step = 0.0, min_step = 1e9, worst_z = 0.0;
    for (int x = 0; x < 128; ++x) {
      double step = az[std::size_t((x + 1) % 128)] - az[std::size_t(x)];
      if (step < -180) step += 360;
      if (step > 180) step -= 360;
      if (x != 127) {
        worst_step = std::max(worst_step, step);
        min_step = std::min(min_step, step);
      }
      worst_z = std::max(worst_z, std::abs(z[std::size_t(x)]));
    }
    measured(std::string(name) + ".largest_azimuth_step_deg", worst_step);
    measured(std::string(name) + ".smallest_azimuth_step_deg", min_step);
    measured(std::string(name) + ".worst_vertical_component", worst_z);
    EXPECT_GT(min_step, 0.0) << name;    // monotonic: no overlap, no jump back
    EXPECT_LT(worst_step, 6.0) << name;  // 360/128 = 2.8 on average: no gap
    EXPECT_LT(worst_z, 1e-3) << name;
  }
}

// ---------------------------------------------------------------------------------------------
// 10. Non-manifold edges, isolated vertices, inconsistent winding, inverted normals.

TEST(Stability, HighPolyTopologyIsInspected) {
  struct Expect {
    const char* file;
    std::size_t non_manifold, isolated, inconsistent, duplicates;
  };
  for (const Expect& e : {Expect{"nonmanifold_high.obj", 2, 0, 0, 0}, Expect{"isolated_vertices_high.obj", 0, 3, 0, 0},
                          Expect{"inconsistent_winding_high.obj", 0, 0, 264, 0}, Expect{"duplicates_high.obj", 0, 0, 0, 293},
                          Expect{"bumps_high.obj", 0, 0, 0, 0}}) {
    const MeshTopology t = inspect_topology(load(e.file));
    EXPECT_EQ(t.non_manifold_edges, e.non_manifold) << e.file;
    EXPECT_EQ(t.isolated_vertices, e.isolated) << e.file;
    EXPECT_EQ(t.inconsistent_winding_faces, e.inconsistent) << e.file;
    EXPECT_EQ(t.duplicate_faces, e.duplicates) << e.file;
  }
}

// A bake that computes the high-poly's normals hands back the checks it found on the way (the
// command reports them instead of inspecting the mesh again): the same counts as inspect_topology.
// A high-poly with normals leaves them to the command.
TEST(Stability, TheBakeComputingNormalsFindsTheSameTopology) {
  const Mesh low = load_low("flat_grid_low.obj");
  std::size_t computed = 0;
  for (const char* file : {"isolated_vertices_high.obj", "inconsistent_winding_high.obj", "duplicates_high.obj",
                           "nonmanifold_high.obj", "bumps_high.obj"}) {
    const Mesh high = load(file);
    const BakeResult r = bake_normal_map(low, high, nullptr, options(32, 0.1f));
    if (high.has_normals()) {
      EXPECT_FALSE(r.stats.prepare.high_topology) << file;
      continue;
    }
    ++computed;
    ASSERT_TRUE(r.stats.prepare.high_topology) << file;
    const auto counts = [](const MeshTopology& t) {
      return std::array<std::size_t, 6>{t.welded_vertices, t.isolated_vertices,  t.duplicate_faces,
                                        t.boundary_edges,  t.non_manifold_edges, t.inconsistent_winding_faces};
    };
    const MeshTopology want = inspect_topology(high);
    EXPECT_EQ(counts(*r.stats.prepare.high_topology), counts(want)) << file;
    EXPECT_EQ(r.stats.prepare.high_faces_reoriented(), want.inconsistent_winding_faces) << file;
  }
  EXPECT_EQ(computed, 3u);
}

TEST(Stability, NonManifoldFinsGiveTheFirstHit) {
  // 0 < x < 0.2: the slanted fin lies above the plane; elsewhere the plane (+Z). The fin's normal
  // points down, into the low-poly: by default the plane beneath it is taken (a hit whose normal
  // points away is taken only for want of another); with back faces kept, the first hit, the fin.
  const Mesh low = load_low("flat_grid_low.obj");
  const glm::dvec3 fin = glm::normalize(glm::dvec3(0.9, 0, -0.6));
  for (bool keep : {false, true}) {
    BakeOptions o = options(64, 0.6f);
    o.keep_backfaces = keep;
    const BakeResult r = bake_normal_map(low, load("nonmanifold_high.obj"), nullptr, o);
    EXPECT_EQ(r.stats.trace.misses, 0u);
    EXPECT_TRUE(all_finite(r.map));
    std::size_t wrong = 0, on_fin = 0;
    test::for_each_decoded_texel(low, r.map, [&](int, int, const glm::dvec3& w, const glm::dvec3& p, std::size_t) {
      const bool under_fin = p.x > 0.0 && p.x < 0.2;
      on_fin += under_fin;
      const glm::dvec3 expect = under_fin && keep ? fin : glm::dvec3(0, 0, 1);
      wrong += angle_deg(w, expect) > 1e-3;
    });
    EXPECT_GT(on_fin, 100u);
    EXPECT_EQ(wrong, 0u) << "keep_backfaces " << keep;
    EXPECT_EQ(r.stats.trace.hits_facing_away, 0u);
  }
}

TEST(Stability, IsolatedVerticesChangeNothing) {
  // Auto distances and the re-centring must ignore vertices no face uses (one is 1e6 away).
  const Mesh low = load_low("flat_grid_low.obj");
  const BakeResult ref = bake_normal_map(low, load("bumps_nonormals_high.obj"), nullptr, options(128, -1.0f));
  const BakeResult r = bake_normal_map(low, load("isolated_vertices_high.obj"), nullptr, options(128, -1.0f));
  double mean = 0.0;
  const double worst = max_texel_angle(r, ref, &mean);
  measured("isolated_vertices.max_deg_vs_clean", worst);
  measured("isolated_vertices.front", r.stats.distances.front);
  EXPECT_EQ(r.stats.distances.front, ref.stats.distances.front);
  EXPECT_EQ(r.stats.distances.rear, ref.stats.distances.rear);
  EXPECT_TRUE(r.map.pixels == ref.map.pixels);
}

TEST(Stability, InconsistentWindingDoesNotFlipComputedNormals) {
  const Mesh low = load_low("flat_grid_low.obj");
  const BakeResult ref = bake_normal_map(low, load("bumps_nonormals_high.obj"), nullptr, options(128, 0.1f));
  const BakeResult r = bake_normal_map(low, load("inconsistent_winding_high.obj"), nullptr, options(128, 0.1f));
  double mean = 0.0;
  const double worst = max_texel_angle(r, ref, &mean);
  measured("inconsistent_winding.max_deg_vs_clean", worst);
  measured("inconsistent_winding.faces_reoriented", double(r.stats.prepare.high_faces_reoriented()));
  EXPECT_EQ(r.stats.prepare.high_faces_reoriented(), 264u);
  EXPECT_LT(worst, 1e-3);
}

TEST(Stability, InvertedNormalsAreBakedAsGivenAndReported) {
  // A file's inverted normals are baked as given (the faces' fronts follow them, so the hit rule
  // changes nothing); normals computed from an inverted winding are turned outwards. Both are
  // reported as an inverted high-poly.
  const Mesh low = load_low("flat_grid_low.obj");
  for (bool keep : {false, true}) {
    BakeOptions o = options(64, 0.1f);
    o.keep_backfaces = keep;
    const BakeResult r = bake_normal_map(low, load("inverted_normals_high.obj"), nullptr, o);
    measured(std::string("inverted_normals.texels_facing_away.keep") + (keep ? "1" : "0"),
             double(r.stats.pad.texels_facing_away));
    EXPECT_EQ(r.stats.pad.texels_facing_away, r.stats.trace.texels_covered);
    EXPECT_EQ(r.stats.distances.high_facing, keep ? BakeStats::HighFacing::sound : BakeStats::HighFacing::inverted);
    EXPECT_TRUE(all_finite(r.map));
    const BakeResult w = bake_normal_map(low, load("inverted_winding_high.obj"), nullptr, o);
    EXPECT_TRUE(all_finite(w.map));
    if (keep) {
      EXPECT_EQ(w.stats.pad.texels_facing_away, w.stats.trace.texels_covered);
    } else {
      EXPECT_EQ(w.stats.distances.high_facing, BakeStats::HighFacing::inverted);
      EXPECT_GT(w.stats.distances.backface_probe_share, 0.99);
      EXPECT_EQ(w.stats.pad.texels_facing_away, 0u);
      // The same map as the correctly wound field's.
      const BakeResult ref = bake_normal_map(low, load("bumps_nonormals_high.obj"), nullptr, o);
      double mean = 0.0;
      EXPECT_LT(max_texel_angle(w, ref, &mean), 1e-3);
      EXPECT_EQ(ref.stats.distances.high_facing, BakeStats::HighFacing::sound);
    }
  }
  const BakeResult ok = bake_normal_map(low, load("bumps_high.obj"), nullptr, options(64, 0.1f));
  EXPECT_EQ(ok.stats.pad.texels_facing_away, 0u);
  EXPECT_EQ(ok.stats.distances.backface_probe_share, 0.0);
}

TEST(Stability, TopologyAndInversionAreReportedByTheCli) {
  const std::string low = data("flat_grid_low.obj");
  CliRun r = run_nmbake(low + " " + data("nonmanifold_high.obj") + " -o out.png --size 32 --report r.json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["high_mesh"]["non_manifold_edges"], 2);
  EXPECT_TRUE(contains(r.err, "2 non-manifold edges")) << r.err;
  r = run_nmbake(low + " " + data("isolated_vertices_high.obj") + " -o out.png --size 32 --report r.json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["high_mesh"]["isolated_vertices"], 3);
  EXPECT_TRUE(contains(r.err, "3 isolated vertices")) << r.err;
  r = run_nmbake(low + " " + data("inconsistent_winding_high.obj") + " -o out.png --size 32 --report r.json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["high_mesh"]["inconsistent_winding_faces"], 264);
  EXPECT_EQ(r.report["high_faces_reoriented"], 264);
  EXPECT_TRUE(contains(r.err, "264 faces wound against their neighbours")) << r.err;
  r = run_nmbake(low + " " + data("inverted_normals_high.obj") + " -o out.png --size 32 --report r.json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["texels_facing_away"], 32 * 32);
  EXPECT_EQ(r.report["high_facing"], "inverted");
  EXPECT_TRUE(contains(r.err, "warning: 100.0% of covered texels point into the low-poly")) << r.err;
  EXPECT_TRUE(contains(r.err,
                       "inverted_normals_high.obj: its faces look inverted (100% of the surfaces nearest the low-poly face "
                       "into it): their fronts were taken the other way round; the file's normals are kept"))
      << r.err;
  r = run_nmbake(low + " " + data("inverted_winding_high.obj") + " -o out.png --size 32 --report r.json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["texels_facing_away"], 0);
  EXPECT_EQ(r.report["high_facing"], "inverted");
  EXPECT_TRUE(contains(r.err,
                       "inverted_winding_high.obj: its faces look inverted (100% of the surfaces nearest the low-poly face "
                       "into it): their fronts were taken the other way round and the computed normals turned outwards"))
      << r.err;
  // --keep-backfaces: the first hit, as it lies.
  r = run_nmbake(low + " " + data("inverted_winding_high.obj") + " -o out.png --size 32 --report r.json --keep-backfaces");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["texels_facing_away"], 32 * 32);
  EXPECT_EQ(r.report["options"]["keep_backfaces"], true);
  EXPECT_EQ(r.report["backfaces_skipped"], false);
}

// A high-poly with normals in its file is checked after the bake: on one thread before the write,
// on several beside it. The same counts either way, and the report's seconds say what the check
// took ("topology"); a high-poly whose normals the bake computed (no normals in its file) was
// checked on the way (0).
TEST(Stability, TopologyCheckedBesideTheWriteCountsTheSame) {
  const std::string sample =
      " '" + test::data_path("sample/torus_low.obj") + "' '" + test::data_path("sample/torus_high.ply") + "'";
  const CliRun one = run_nmbake(sample + " -o one.png --size 64 --threads 1 --report r.json");
  const CliRun two = run_nmbake(sample + " -o two.png --size 64 --threads 2 --report r.json");
  ASSERT_EQ(one.code, 0);
  ASSERT_EQ(two.code, 0);
  for (const char* key : {"boundary_edges", "non_manifold_edges", "duplicate_faces", "isolated_vertices", "welded_vertices",
                          "inconsistent_winding_faces"})
    EXPECT_EQ(one.report["high_mesh"][key], two.report["high_mesh"][key]) << key;
  EXPECT_GT(one.report["high_mesh"]["welded_vertices"].get<double>(), 0.0);
  EXPECT_GT(one.report["seconds"]["topology"].get<double>(), 0.0);
  EXPECT_GE(two.report["seconds"]["topology"].get<double>(), 0.0);
  const CliRun computed = run_nmbake("'" + data("flat_grid_low.obj") + "' '" + data("isolated_vertices_high.obj") +
                                     "' -o out.png --size 32 --report r.json");
  ASSERT_EQ(computed.code, 0);
  EXPECT_EQ(computed.report["high_normals_computed"], true);
  EXPECT_EQ(computed.report["seconds"]["topology"].get<double>(), 0.0);
}
