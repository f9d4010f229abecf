// Surface repair by refinement (surface_repair.h) and `run_mesh` with repair_surface.
#include "hexpeel/surface_repair.h"

#include "hexpeel/chords.h"
#include "hexpeel/pipeline.h"
#include "hexpeel/tet_fill.h"
#include "soups.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace hexpeel {
namespace {

/// Square pyramid, radial mesh: 8 quads, one chord (length 16) that crosses itself at all 8.
PolygonSoup square_pyramid_radial() {
  return test::radial_soup({{1, 1, 0}, {-1, 1, 0}, {-1, -1, 0}, {1, -1, 0}, {0, 0, 1}},
                           {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}});
}

ChordStats stats_of(const QuadSurface& s) { return chord_stats(find_chords(s, build_adjacency(s))); }

/// Distance from p to the bilinear patch of quad q, sampled (the patches here are planar
/// pieces or gently bent, a fine grid is enough to tell on from off).
double distance_to_patch(const QuadSurface& s, const Quad& q, const Vec3& p) {
  double best = 1e300;
  for (int i = 0; i <= 60; ++i)
    for (int j = 0; j <= 60; ++j) {
      const double u = i / 60.0, v = j / 60.0;
      const Vec3 x = (1 - u) * (1 - v) * s.points[q[0]] + u * (1 - v) * s.points[q[1]] +
                     u * v * s.points[q[2]] + (1 - u) * v * s.points[q[3]];
      best = std::min(best, (x - p).norm());
    }
  return best;
}

void expect_closed_manifold(const QuadSurface& s) {
  const QuadAdjacency adj = build_adjacency(s);
  for (size_t he = 0; he < adj.opposite.size(); ++he) ASSERT_GE(adj.opposite[he], 0) << he;
  // V - E + F = 2
  EXPECT_EQ(s.num_points() - 2 * s.num_quads() + s.num_quads(), 2);
}

TEST(SurfaceRepair, RefinementKeepsVerticesAndMakesEvenClosedSurfaces) {
  const QuadSurface cube = test::to_surface(test::cube_soup());
  for (char six : {0, 1}) {
    SCOPED_TRACE(six ? "six" : "four");
    std::vector<int32_t> parent;
    const QuadSurface r = refine_surface(cube, std::vector<char>(6, six), parent);
    EXPECT_EQ(r.num_quads(), six ? 36 : 24);
    ASSERT_EQ(parent.size(), static_cast<size_t>(r.num_quads()));
    for (int32_t v = 0; v < cube.num_points(); ++v) EXPECT_EQ(r.points[v], cube.points[v]);
    expect_closed_manifold(r);
    // new vertices lie on their parent quad; refined quads keep the parent's orientation
    for (int32_t q = 0; q < r.num_quads(); ++q) {
      const Quad& parent_quad = cube.quads[parent[q]];
      for (int32_t v : r.quads[q])
        EXPECT_LT(distance_to_patch(cube, parent_quad, r.points[v]), 1e-2) << "quad " << q;
      EXPECT_GT(quad_normal(r, q).dot(quad_normal(cube, parent[q])), 0.99) << "quad " << q;
    }
    // four: the cube's 3 chords doubled; six: one chord around each of the 8 corners
    const ChordStats st = stats_of(r);
    EXPECT_EQ(st.count, six ? 8 : 6);
    EXPECT_EQ(st.self_intersecting, 0);
  }
}

TEST(SurfaceRepair, SelfCrossingChordIsResolved) {
  const QuadSurface in = test::to_surface(square_pyramid_radial());
  ASSERT_GT(stats_of(in).self_intersecting, 0);
  const SurfaceRepair rep = repair_surface(in);
  ASSERT_TRUE(rep.status.ok()) << to_string(rep.status);
  EXPECT_TRUE(rep.stats.applied);
  EXPECT_EQ(rep.stats.input_quads, 8);
  EXPECT_EQ(rep.stats.input_self_crossings, 8);
  EXPECT_FALSE(rep.stats.six_split.empty());
  EXPECT_EQ(rep.stats.output_quads, rep.surface.num_quads());
  EXPECT_EQ(rep.surface.num_quads() % 2, 0);
  EXPECT_EQ(stats_of(rep.surface).self_intersecting, 0);
  for (int32_t v = 0; v < in.num_points(); ++v) EXPECT_EQ(rep.surface.points[v], in.points[v]);
  expect_closed_manifold(rep.surface);
  // split into six everywhere: the fallback the pipeline tries when the first does not mesh
  const SurfaceRepair all = repair_surface(in, true);
  ASSERT_TRUE(all.status.ok());
  EXPECT_EQ(all.stats.six_split.size(), 8u);
  EXPECT_EQ(all.surface.num_quads(), 48);
  EXPECT_EQ(stats_of(all.surface).self_intersecting, 0);
  EXPECT_EQ(stats_of(all.surface).count, in.num_points());  // one chord around each vertex
  // deterministic
  const SurfaceRepair again = repair_surface(in);
  EXPECT_EQ(again.surface.quads, rep.surface.quads);
  EXPECT_EQ(again.surface.points, rep.surface.points);
}

TEST(SurfaceRepair, OddSurfaceBecomesEven) {
  const QuadSurface in = test::to_surface(test::prism_radial_soup());
  ASSERT_EQ(in.num_quads(), 9);
  const SurfaceRepair rep = repair_surface(in);
  ASSERT_TRUE(rep.status.ok()) << to_string(rep.status);
  EXPECT_TRUE(rep.stats.input_odd);
  EXPECT_EQ(rep.surface.num_quads() % 2, 0);
  EXPECT_EQ(stats_of(rep.surface).self_intersecting, 0);
}

void expect_meshes_repaired(const PolygonSoup& soup) {
  // refused without the repair ...
  const MeshResult refused = run_mesh(soup);
  EXPECT_FALSE(refused.status.ok());
  // ... and meshed with it: a ball, every hex positive, boundary = the repaired surface
  MeshParams p;
  p.repair_surface = true;
  p.repair_fill = MeshParams::RepairFill::elimination;
  const MeshResult r = run_mesh(soup, p);
  ASSERT_TRUE(r.status.ok()) << to_string(r.status);
  EXPECT_TRUE(r.repair.applied);
  EXPECT_EQ(r.repaired_surface.num_quads(), r.repair.output_quads);
  const QualityReport q = run_quality(r.mesh, {}, &r.repaired_surface);
  EXPECT_TRUE(q.is_ball) << q.topology_message;
  EXPECT_EQ(q.boundary_matches_surface, true) << q.boundary_message;
  EXPECT_EQ(q.sj_count_nonpositive, 0);
  EXPECT_GT(q.sj_min, 0.0);
  for (size_t v = 0; v < soup.points.size(); ++v) EXPECT_EQ(r.mesh.points[v], soup.points[v]);
  const nlohmann::json j = to_json(r);
  ASSERT_TRUE(j.contains("repair"));
  EXPECT_EQ(j["repair"]["quads_changed"], static_cast<int>(soup.num_faces()));
}

TEST(SurfaceRepair, PipelineMeshesSelfCrossingSurface) { expect_meshes_repaired(square_pyramid_radial()); }
TEST(SurfaceRepair, PipelineMeshesOddSurface) { expect_meshes_repaired(test::prism_radial_soup()); }

/// The tet split itself: a ball whose boundary is the surface split into six everywhere, vertex
/// for vertex; on planar parallelogram quads (`positive`) every hex positive where it puts them.
void expect_tet_fill(const PolygonSoup& soup, bool positive) {
  if (!tet_fill_available()) GTEST_SKIP() << "built without gmsh's library";
  const QuadSurface in = test::to_surface(soup);
  std::vector<int32_t> parent;
  const QuadSurface six = refine_surface(in, std::vector<char>(in.num_quads(), 1), parent);
  const TetFill tf = tet_fill(in, six);
  ASSERT_TRUE(tf.status.ok()) << to_string(tf.status);
  EXPECT_GT(tf.stats.tetrahedra, 0);
  EXPECT_EQ(tf.complex.hexes.size(), 4u * tf.stats.tetrahedra);
  ASSERT_EQ(tf.points.size(), static_cast<size_t>(tf.complex.num_vertices));
  for (int32_t v = 0; v < six.num_points(); ++v) {
    EXPECT_EQ(tf.complex.input_vertex[v], v);
    EXPECT_EQ(tf.points[v], six.points[v]);
  }
  for (size_t v = six.num_points(); v < tf.points.size(); ++v) EXPECT_EQ(tf.complex.input_vertex[v], -1);
  const HexMesh m{tf.points, tf.complex.hexes};
  const QualityReport q = run_quality(m, {}, &six);
  EXPECT_TRUE(q.is_ball) << q.topology_message;
  EXPECT_EQ(q.boundary_matches_surface, true) << q.boundary_message;
  if (positive) {
    EXPECT_EQ(q.sj_count_nonpositive, 0);
    EXPECT_GT(q.sj_min, 0.0);
  }
}

TEST(SurfaceRepair, TetFillOfSelfCrossingSurface) { expect_tet_fill(square_pyramid_radial(), false); }
TEST(SurfaceRepair, TetFillOfOddSurface) { expect_tet_fill(test::prism_radial_soup(), false); }
TEST(SurfaceRepair, TetFillOfCube) { expect_tet_fill(test::cube_soup(), true); }

TEST(SurfaceRepair, PipelineMeshesThroughTetrahedra) {
  if (!tet_fill_available()) GTEST_SKIP() << "built without gmsh's library";
  MeshParams p;
  p.repair_surface = true;
  p.repair_fill = MeshParams::RepairFill::tets;
  const PolygonSoup soup = square_pyramid_radial();
  const MeshResult r = run_mesh(soup, p);
  ASSERT_TRUE(r.status.ok()) << to_string(r.status);
  EXPECT_TRUE(r.tet_fill_kept);
  EXPECT_EQ(r.repaired_surface.num_quads(), 6 * soup.num_faces());
  const QualityReport q = run_quality(r.mesh, {}, &r.repaired_surface);
  EXPECT_TRUE(q.is_ball) << q.topology_message;
  EXPECT_EQ(q.boundary_matches_surface, true) << q.boundary_message;
  EXPECT_EQ(q.sj_count_nonpositive, 0);
  for (size_t v = 0; v < soup.points.size(); ++v) EXPECT_EQ(r.mesh.points[v], soup.points[v]);
  const nlohmann::json j = to_json(r);
  EXPECT_EQ(j["repair"]["tet_fill"]["kept"], true);
  EXPECT_GT(j["repair"]["tet_fill"]["tetrahedra"], 0);
  // elimination: the elimination's mesh, no tet section
  p.repair_fill = MeshParams::RepairFill::elimination;
  const MeshResult e = run_mesh(soup, p);
  ASSERT_TRUE(e.status.ok());
  EXPECT_FALSE(e.tet_fill_kept);
  EXPECT_FALSE(to_json(e)["repair"].contains("tet_fill"));
}

TEST(SurfaceRepair, SurfaceThatNeedsNoneIsMeshedAsIs) {
  // the option changes nothing on a surface the mesher takes: same mesh, no repair section
  MeshParams p;
  p.repair_surface = true;
  const MeshResult a = run_mesh(test::cube_soup());
  const MeshResult b = run_mesh(test::cube_soup(), p);
  ASSERT_TRUE(a.status.ok() && b.status.ok());
  EXPECT_FALSE(b.repair.applied);
  EXPECT_EQ(a.mesh.points, b.mesh.points);
  EXPECT_EQ(a.mesh.hexes, b.mesh.hexes);
  EXPECT_FALSE(to_json(b).contains("repair"));
}

}  // namespace
}  // namespace hexpeel
