// Untangling, quality optimization, forced configurations and pillowing (src/geometry).
#include "hexpeel/embedding.h"
#include "hexpeel/pillow.h"
#include "hexpeel/pipeline.h"
#include "hexpeel/quality.h"
#include "hexpeel/untangle.h"
#include "support/generators.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>

namespace hexpeel {
namespace {

using testing::Generated;

std::vector<uint8_t> surface_fixed(const Generated& g) {
  std::vector<uint8_t> fixed(g.known_mesh.points.size(), 0);
  for (int32_t v = 0; v < g.surface.num_points(); ++v) fixed[v] = 1;
  return fixed;
}

HexComplex complex_of(const Generated& g) {
  HexComplex c;
  c.num_vertices = g.known_mesh.num_points();
  c.hexes = g.known_mesh.hexes;
  for (int32_t v = 0; v < c.num_vertices; ++v) {
    c.input_vertex.push_back(v < g.surface.num_points() ? v : -1);
    c.created_at.push_back(0);
  }
  return c;
}

TEST(GeometryUntangle, JitteredGridBecomesPositiveAndBoundaryStays) {
  for (uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // The whole interior scrambled far beyond its cells; the surface untouched.
    Generated g = testing::jittered(testing::cube(4, 4, 4, 0.25), seed, 0.0);
    for (int32_t v = g.surface.num_points(); v < g.known_mesh.num_points(); ++v)
      g.known_mesh.points[v] += Vec3(0.2 * std::sin(3.0 * v + seed), 0.2 * std::cos(5.0 * v),
                                     0.2 * std::sin(7.0 * v * seed));
    QualityReport before = run_quality(g.known_mesh);
    ASSERT_GT(before.sj_count_nonpositive, 0) << "the scrambled start should be tangled";
    UntangleResult r = run_untangle(g.known_mesh, surface_fixed(g));
    ASSERT_TRUE(r.status.ok()) << to_string(r.status);
    for (int32_t v = 0; v < g.surface.num_points(); ++v)
      ASSERT_EQ(std::memcmp(r.mesh.points[v].data(), g.known_mesh.points[v].data(), sizeof(Vec3)), 0)
          << "boundary vertex " << v << " moved";
    QualityReport q = run_quality(r.mesh, {}, &g.surface);
    EXPECT_EQ(q.sj_count_nonpositive, 0);
    EXPECT_GT(q.sj_min, 0.9);  // the grid is the optimum
    EXPECT_EQ(q.boundary_matches_surface, true);
    EXPECT_EQ(r.stats.forced_nonpositive, 0);
    EXPECT_EQ(r.stats.untangle.nonpositive_after, 0);
  }
}

TEST(GeometryUntangle, SameBytesForAnyThreadCount) {
  Generated g = testing::jittered(testing::cubed_sphere_equiangular(5), 11, 0.3);
  auto run = [&](int threads) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    return run_untangle(g.known_mesh, surface_fixed(g)).mesh;
  };
  HexMesh a = run(1), b = run(2);
  ASSERT_EQ(a.points.size(), b.points.size());
  EXPECT_EQ(std::memcmp(a.points.data(), b.points.data(), a.points.size() * sizeof(Vec3)), 0);
}

TEST(GeometryUntangle, OptimizeNeverLowersTheMinimum) {
  Generated g = testing::jittered(testing::cubed_sphere_equiangular(4), 5, 0.2);
  UntangleParams p;
  p.optimize = false;
  UntangleResult a = run_untangle(g.known_mesh, surface_fixed(g), p);
  UntangleResult b = run_untangle(g.known_mesh, surface_fixed(g));
  EXPECT_GE(run_quality(b.mesh).sj_min, run_quality(a.mesh).sj_min - 1e-12);
  EXPECT_EQ(run_quality(b.mesh).sj_count_nonpositive, 0);
}

/// A 2x2x3 grid whose hex at [0,1]^2 x [1,2] has its front (y=0) and left (x=0) boundary faces
/// made coplanar (the shared edge moved to x = y = 0.5): a flat doublet.
Generated flat_doublet() {
  Generated g = testing::cube(2, 2, 3);
  for (int32_t v = 0; v < g.surface.num_points(); ++v) {
    Vec3& p = g.surface.points[v];
    if (p.x() == 0.0 && p.y() == 0.0 && (p.z() == 1.0 || p.z() == 2.0)) {
      p.x() = p.y() = 0.5;
      g.known_mesh.points[v] = p;
    }
  }
  return g;
}

TEST(GeometryPillow, FlatDoubletIsDetected) {
  Generated g = flat_doublet();
  std::vector<ForcedConfiguration> f = find_forced_configurations(g.surface, complex_of(g));
  ASSERT_FALSE(f.empty());
  bool doublet = false;
  for (const ForcedConfiguration& c : f) {
    doublet |= c.kind == ForcedKind::flat_doublet;
    EXPECT_LE(c.scaled_jacobian, 1e-12);
  }
  EXPECT_TRUE(doublet);
  // The plain grid has none.
  Generated plain = testing::cube(2, 2, 3);
  EXPECT_TRUE(find_forced_configurations(plain.surface, complex_of(plain)).empty());
}

TEST(GeometryPillow, KeepsBoundaryAndBallAndFixesTheDoublet) {
  Generated g = flat_doublet();
  for (PillowMode mode : {PillowMode::automatic, PillowMode::all}) {
    SCOPED_TRACE(std::string(to_string(mode)));
    PillowParams pp;
    pp.mode = mode;
    pp.whole_fraction = 1.0;  // a 12-hex grid: keep auto local so both paths are tested
    pp.grow = 0;
    PillowResult pr = run_pillow(g.surface, complex_of(g), pp);
    ASSERT_TRUE(pr.status.ok());
    EXPECT_GT(pr.stats.new_hexes, 0);
    EXPECT_EQ(pr.stats.forced_after, 0);
    EXPECT_EQ(pr.stats.whole_boundary, mode == PillowMode::all);
    for (int32_t v = 0; v < g.surface.num_points(); ++v) EXPECT_EQ(pr.complex.input_vertex[v], v);
    PlacementResult placed = run_placement(g.surface, pr.complex);
    ASSERT_TRUE(placed.status.ok());
    std::vector<uint8_t> fixed(placed.mesh.points.size(), 0);
    for (int32_t v = 0; v < g.surface.num_points(); ++v) fixed[v] = 1;
    UntangleResult u = run_untangle(placed.mesh, fixed);
    QualityReport q = run_quality(u.mesh, {}, &g.surface);
    EXPECT_TRUE(q.is_ball) << q.topology_message;
    EXPECT_EQ(q.boundary_matches_surface, true) << q.boundary_message;
    EXPECT_EQ(q.sj_count_nonpositive, 0);
  }
  // none: nothing changes, the doublet is still reported.
  PillowParams none;
  none.mode = PillowMode::none;
  PillowResult pr = run_pillow(g.surface, complex_of(g), none);
  EXPECT_EQ(pr.complex.hexes, g.known_mesh.hexes);
  EXPECT_GT(pr.stats.forced, 0);
}

TEST(GeometryPipeline, GeneratedSurfacesMeshAllPositive) {
  std::vector<Generated> gs;
  gs.push_back(testing::cube(3, 3, 3));
  gs.push_back(testing::named_solid("L", 2));
  gs.push_back(testing::named_solid("stairs", 1));
  gs.push_back(testing::cubed_sphere_equiangular(4));
  gs.push_back(testing::random_voxel_solid(3, 4, 8));
  gs.push_back(testing::pillowed(testing::cube(2, 2, 2), 1, 0.3));
  int meshed = 0;
  for (const Generated& g : gs) {
    SCOPED_TRACE(g.name);
    MeshResult r = run_mesh(to_polygon_soup(g.surface));
    if (r.status.code == StatusCode::stuck) continue;  // elimination's business, not geometry's
    ++meshed;
    ASSERT_TRUE(r.status.ok()) << to_string(r.status);
    EXPECT_TRUE(r.quality.is_ball);
    EXPECT_EQ(r.quality.boundary_matches_surface, true);
    EXPECT_EQ(r.quality.sj_count_nonpositive, 0);
    for (int32_t v = 0; v < g.surface.num_points(); ++v)
      ASSERT_EQ(r.mesh.points[v], g.surface.points[v]) << "vertex " << v;
    EXPECT_FALSE(to_json(r)["untangle"].is_null());
    EXPECT_FALSE(to_json(r)["pillow"].is_null());
  }
  EXPECT_GE(meshed, 4);
}

TEST(GeometryPipeline, CubeGridStaysPerfect) {
  MeshResult r = run_mesh(to_polygon_soup(testing::cube(3, 3, 3).surface));
  ASSERT_TRUE(r.status.ok()) << to_string(r.status);
  EXPECT_GE(r.quality.sj_min, 0.99);
}

}  // namespace
}  // namespace hexpeel
