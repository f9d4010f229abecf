// Property test of the meshing core: over generated surfaces, elimination + reconstruction either
// gives a complex that is a topological ball whose boundary equals the input exactly, or reports
// `stuck` cleanly. Any invalid complex fails the test; the success rate and failing seeds print.
#include "hexpeel/chords.h"
#include "hexpeel/elimination.h"
#include "hexpeel/embedding.h"
#include "hexpeel/pipeline.h"
#include "hexpeel/quality.h"
#include "hexpeel/reconstruction.h"
#include "support/generators.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

using namespace hexpeel;
namespace ht = hexpeel::testing;

namespace {

struct Outcome {
  bool meshed = false, stuck = false;
  std::string failure;  // non-empty: an invalid result (test failure)
  int32_t hexes = 0;
};

Outcome mesh_and_check(const QuadSurface& surface) {
  Outcome o;
  MeshParams params;
  params.reconstruction.verify_each_step = true;
  MeshResult r = run_mesh(to_polygon_soup(surface), params);
  if (r.status.code == StatusCode::stuck) {
    o.stuck = true;
    if (!r.mesh.hexes.empty()) o.failure = "stuck but a mesh was produced";
    return o;
  }
  if (!r.status.ok()) {
    o.failure = to_string(r.status);
    return o;
  }
  // Independent re-check of the written mesh's topology and boundary.
  QualityReport q = run_quality(r.mesh, {}, &surface);
  if (!q.is_ball) o.failure = "not a ball: " + q.topology_message;
  else if (q.boundary_matches_surface != true) o.failure = "boundary differs: " + q.boundary_message;
  else if (q.euler_characteristic != 1) o.failure = "Euler characteristic " + std::to_string(q.euler_characteristic);
  // Boundary vertices are exactly the input positions, by id.
  for (int32_t v = 0; v < surface.num_points() && o.failure.empty(); ++v)
    if (r.mesh.points[v] != surface.points[v]) o.failure = "boundary vertex " + std::to_string(v) + " moved";
  o.meshed = o.failure.empty();
  o.hexes = q.hexes;
  return o;
}

void run_family(const std::string& family, const std::vector<ht::Generated>& surfaces) {
  int meshed = 0, stuck = 0;
  std::string failing;
  for (const auto& g : surfaces) {
    ASSERT_GT(g.surface.num_quads(), 0) << g.name;
    Outcome o = mesh_and_check(g.surface);
    meshed += o.meshed;
    stuck += o.stuck;
    if (!o.failure.empty()) {
      ADD_FAILURE() << g.name << ": " << o.failure;
      failing += " " + g.name;
    }
    if (o.stuck) failing += " " + g.name + "(stuck)";
  }
  std::printf("%-22s %3zu surfaces: %3d meshed, %3d stuck, %3zu invalid; success %.0f%%;%s%s\n",
              family.c_str(), surfaces.size(), meshed, stuck, surfaces.size() - meshed - stuck,
              100.0 * meshed / surfaces.size(), failing.empty() ? "" : " not meshed:", failing.c_str());
}

}  // namespace

TEST(Reconstruction, CubeGridsGiveKCubedHexes) {
  for (int k = 1; k <= 6; ++k) {
    ht::Generated g = ht::cube(k, k, k);
    Outcome o = mesh_and_check(g.surface);
    ASSERT_TRUE(o.meshed) << "cube_n" << k << ": " << o.failure;
    EXPECT_EQ(o.hexes, k * k * k) << "cube_n" << k;
  }
}

TEST(Reconstruction, PropertyCubesAndSpheres) {
  std::vector<ht::Generated> s;
  for (int nx = 1; nx <= 4; ++nx)
    for (int ny = nx; ny <= 4; ++ny) s.push_back(ht::cube(nx, ny, 1 + (nx + ny) % 3));
  for (int n = 2; n <= 8; ++n) s.push_back(ht::cubed_sphere(n));
  run_family("cubes+spheres", s);
}

TEST(Reconstruction, PropertyNamedAndRefinedSolids) {
  std::vector<ht::Generated> s;
  for (const char* shape : {"L", "U", "T", "pocket", "notch", "stairs", "steps"})
    for (int m = 1; m <= 2; ++m) s.push_back(ht::named_solid(shape, m));
  s.push_back(ht::refined(ht::named_solid("L", 1)));
  s.push_back(ht::refined(ht::cubed_sphere(3)));
  run_family("named+refined solids", s);
}

TEST(Reconstruction, PropertyRandomVoxelSolids) {
  std::vector<ht::Generated> s;
  for (uint64_t seed = 1; seed <= 40; ++seed)
    s.push_back(ht::random_voxel_solid(seed, 4, 4 + static_cast<int>(seed % 12), 1 + (seed % 5 == 0)));
  run_family("random voxel solids", s);
}

TEST(Reconstruction, PropertyPerturbed) {
  std::vector<ht::Generated> s;
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    s.push_back(ht::perturbed(ht::random_voxel_solid(100 + seed, 4, 8), seed, 0.2));
    s.push_back(ht::perturbed(ht::cubed_sphere(4), seed, 0.2));
  }
  run_family("perturbed", s);
}
