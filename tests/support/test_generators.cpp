// Tests of the surface generators: every output is a closed oriented genus-0 quad surface, the
// known hex mesh's boundary is exactly the surface, chords match values known by hand, and the
// output is deterministic. The checks here are written independently of generators_check.cpp.
#include "support/generators.h"

#include <Eigen/LU>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace hexpeel::testing {
namespace {

using ::testing::AssertionFailure;
using ::testing::AssertionResult;
using ::testing::AssertionSuccess;

/// Every directed edge once and its reverse once, every vertex used, V - E + F = 2.
AssertionResult closed_sphere(const QuadSurface& s) {
  if (s.quads.empty()) return AssertionFailure() << "empty surface";
  std::map<std::pair<int32_t, int32_t>, int> directed;
  std::vector<int> used(s.points.size(), 0);
  for (const Quad& q : s.quads)
    for (int k = 0; k < 4; ++k) {
      if (q[k] < 0 || q[k] >= s.num_points()) return AssertionFailure() << "bad id " << q[k];
      ++directed[{q[k], q[(k + 1) % 4]}];
      used[q[k]] = 1;
    }
  for (const auto& [e, count] : directed) {
    if (count != 1)
      return AssertionFailure() << "half-edge " << e.first << "->" << e.second << " used "
                                << count << " times";
    if (!directed.count({e.second, e.first}))
      return AssertionFailure() << "edge " << e.first << "-" << e.second << " has one quad";
  }
  for (size_t v = 0; v < used.size(); ++v)
    if (!used[v]) return AssertionFailure() << "vertex " << v << " unused";
  const long chi = static_cast<long>(s.points.size()) - static_cast<long>(directed.size() / 2) +
                   static_cast<long>(s.quads.size());
  if (chi != 2) return AssertionFailure() << "V - E + F = " << chi;
  return AssertionSuccess();
}

Quad rotated_min_first(const Quad& q) {
  const int r = static_cast<int>(std::min_element(q.begin(), q.end()) - q.begin());
  return {q[r], q[(r + 1) % 4], q[(r + 2) % 4], q[(r + 3) % 4]};
}

/// The faces used by one hex (kHexFaces orientation) are exactly the surface quads, by vertex id,
/// and the mesh's first points are the surface's points.
AssertionResult boundary_is_surface(const Generated& g) {
  const HexMesh& m = g.known_mesh;
  if (m.hexes.empty()) return AssertionFailure() << "no known mesh";
  if (m.points.size() < g.surface.points.size()) return AssertionFailure() << "too few points";
  for (size_t v = 0; v < g.surface.points.size(); ++v)
    if (m.points[v] != g.surface.points[v])
      return AssertionFailure() << "point " << v << " differs";
  std::map<Quad, std::vector<Quad>> by_key;  // sorted ids -> oriented faces
  for (const Hex& h : m.hexes)
    for (const auto& lf : kHexFaces) {
      Quad f{h[lf[0]], h[lf[1]], h[lf[2]], h[lf[3]]}, key = f;
      std::sort(key.begin(), key.end());
      by_key[key].push_back(f);
    }
  std::set<Quad> boundary, surface;
  for (const auto& [key, faces] : by_key) {
    if (faces.size() > 2) return AssertionFailure() << "face used by " << faces.size() << " hexes";
    if (faces.size() == 1) boundary.insert(rotated_min_first(faces[0]));
  }
  for (const Quad& q : g.surface.quads) surface.insert(rotated_min_first(q));
  if (surface.size() != g.surface.quads.size()) return AssertionFailure() << "duplicate quads";
  if (boundary != surface)
    return AssertionFailure() << "boundary has " << boundary.size() << " faces, surface "
                              << surface.size() << " quads, not the same";
  return AssertionSuccess();
}

/// Hexes whose 8 corner determinants are all > 0.
int positive_hexes(const HexMesh& m) {
  int n = 0;
  for (const Hex& h : m.hexes) {
    bool ok = true;
    for (int c = 0; c < 8; ++c) {
      const auto& f = kHexCornerFrames[c];
      Eigen::Matrix3d J;
      for (int i = 0; i < 3; ++i) J.col(i) = m.points[h[f[i]]] - m.points[h[c]];
      ok = ok && J.determinant() > 0;
    }
    n += ok;
  }
  return n;
}

/// The full contract of a generator with a known mesh whose hexes should all be positive.
void expect_valid(const Generated& g, bool all_positive = true) {
  SCOPED_TRACE(g.name);
  ASSERT_TRUE(closed_sphere(g.surface));
  EXPECT_GT(signed_volume(g.surface), 0.0);
  EXPECT_TRUE(boundary_is_surface(g));
  EXPECT_EQ(check_known_mesh(g), "");
  EXPECT_EQ(g.chords, static_cast<int32_t>(g.chord_lengths.size()));
  EXPECT_TRUE(std::is_sorted(g.chord_lengths.begin(), g.chord_lengths.end()));
  int sum = 0;
  for (int32_t len : g.chord_lengths) sum += len;
  EXPECT_EQ(sum, 2 * g.surface.num_quads()) << "each quad is crossed by two chord passages";
  EXPECT_EQ(count_positive_hexes(g.known_mesh), positive_hexes(g.known_mesh));
  if (all_positive) EXPECT_EQ(positive_hexes(g.known_mesh), g.known_mesh.num_hexes());
}

bool same(const Generated& a, const Generated& b) {
  return a.name == b.name && a.surface.points == b.surface.points &&
         a.surface.quads == b.surface.quads && a.known_mesh.points == b.known_mesh.points &&
         a.known_mesh.hexes == b.known_mesh.hexes && a.chords == b.chords &&
         a.chord_lengths == b.chord_lengths;
}

/// Every chord of length L replaced by k chords of length k*L (a k x k split of every quad).
std::vector<int32_t> split_chords(const std::vector<int32_t>& lengths, int k) {
  std::vector<int32_t> out;
  for (int32_t len : lengths)
    for (int i = 0; i < k; ++i) out.push_back(k * len);
  std::sort(out.begin(), out.end());
  return out;
}

TEST(Cube, GridBoundaryAndChords) {
  for (int n = 1; n <= 6; ++n) {
    const Generated g = cube(n, n, n);
    expect_valid(g);
    EXPECT_EQ(g.surface.num_quads(), 6 * n * n);
    EXPECT_EQ(g.surface.num_points(), 6 * n * n + 2);
    EXPECT_EQ(g.known_mesh.num_hexes(), n * n * n);
    EXPECT_EQ(g.known_mesh.num_points(), (n + 1) * (n + 1) * (n + 1));
    EXPECT_NEAR(signed_volume(g.surface), n * n * n, 1e-9);
    EXPECT_EQ(g.chords, 3 * n);
    EXPECT_EQ(g.chord_lengths, std::vector<int32_t>(3 * n, 4 * n));
  }
}

TEST(Cube, Box234ChordsByHand) {
  // Rings around x: 2 of length 2*(3+4); around y: 3 of 2*(2+4); around z: 4 of 2*(2+3).
  const Generated g = cube(2, 3, 4, 0.5);
  expect_valid(g);
  EXPECT_EQ(g.chords, 9);
  EXPECT_EQ(g.chord_lengths, (std::vector<int32_t>{10, 10, 10, 10, 12, 12, 12, 14, 14}));
  EXPECT_NEAR(signed_volume(g.surface), 24 * 0.125, 1e-12);
}

TEST(Cube, UnitCubeFamily) {
  // cube(3,3,3, 1/3) is the shared cube_n3: the unit cube, 54 quads, 56 vertices.
  const Generated g = cube(3, 3, 3, 1.0 / 3.0);
  expect_valid(g);
  EXPECT_EQ(g.surface.num_quads(), 54);
  EXPECT_EQ(g.surface.num_points(), 56);
  EXPECT_NEAR(signed_volume(g.surface), 1.0, 1e-12);
}

TEST(CubedSphere, OnUnitSphereWithPositiveInterior) {
  for (bool equiangular : {false, true})
    for (int n = 1; n <= 7; ++n) {
      const Generated g = equiangular ? cubed_sphere_equiangular(n) : cubed_sphere(n);
      expect_valid(g);
      EXPECT_EQ(g.surface.num_quads(), 6 * n * n);
      for (const Vec3& p : g.surface.points) EXPECT_NEAR(p.norm(), 1.0, 1e-12);
      for (size_t v = g.surface.points.size(); v < g.known_mesh.points.size(); ++v)
        EXPECT_LT(g.known_mesh.points[v].norm(), 1.0 - 1e-9);
      EXPECT_EQ(g.chord_lengths, std::vector<int32_t>(3 * n, 4 * n));
      EXPECT_LT(signed_volume(g.surface), 4.0 / 3.0 * std::numbers::pi);
      EXPECT_TRUE(same(g, equiangular ? cubed_sphere_equiangular(n) : cubed_sphere(n)));
    }
}

TEST(VoxelSolid, NamedShapes) {
  // Voxel counts, and quad counts at m = 1 (those of the shared vox_*_m1 files where one exists).
  const std::vector<std::tuple<std::string, int, int>> shapes{
      {"L", 3, 14},       {"Lblock", 10, 34}, {"U", 7, 30},      {"T", 4, 18},
      {"pocket", 17, 46}, {"notch", 24, 52},  {"stairs", 6, 24}, {"steps", 14, 42}};
  for (const auto& [shape, voxels, quads] : shapes) {
    const Generated g1 = named_solid(shape, 1);
    SCOPED_TRACE(shape);
    expect_valid(g1);
    EXPECT_NEAR(signed_volume(g1.surface), voxels, 1e-9);
    EXPECT_EQ(g1.known_mesh.num_hexes(), voxels);
    EXPECT_EQ(g1.surface.num_quads(), quads);
    for (int m = 2; m <= 3; ++m) {
      const Generated g = named_solid(shape, m);
      expect_valid(g);
      EXPECT_EQ(g.surface.num_quads(), m * m * quads);
      EXPECT_EQ(g.known_mesh.num_hexes(), m * m * m * voxels);
      EXPECT_NEAR(signed_volume(g.surface), voxels, 1e-9);
      EXPECT_EQ(g.chord_lengths, split_chords(g1.chord_lengths, m));
      EXPECT_TRUE(same(g, named_solid(shape, m)));
    }
  }
  EXPECT_EQ(named_solid("L", 2).name, "vox_L3_m2");
  EXPECT_TRUE(named_solid("no such shape").surface.quads.empty());
}

TEST(VoxelSolid, L3ChordsByHand) {
  // Around z: the L's perimeter (8); around x: cross-sections 2x1 (6) and 1x1 (4); same around y.
  const Generated g = named_solid("L", 1);
  EXPECT_EQ(g.chord_lengths, (std::vector<int32_t>{4, 4, 6, 6, 8}));
}

TEST(VoxelSolid, RejectsNonSpheres) {
  auto rejected = [](int nx, int ny, int nz, std::vector<uint8_t> filled) {
    return voxel_solid(nx, ny, nz, filled).surface.quads.empty();
  };
  EXPECT_TRUE(rejected(2, 2, 1, {1, 0, 0, 1}));                    // edge-only contact
  EXPECT_TRUE(rejected(2, 2, 2, {1, 0, 0, 0, 0, 0, 0, 1}));        // vertex-only contact
  EXPECT_TRUE(rejected(2, 2, 2, {1, 1, 0, 1, 0, 0, 1, 1}));        // edge contact, else connected
  EXPECT_TRUE(rejected(3, 1, 1, {1, 0, 1}));                       // two components
  EXPECT_TRUE(rejected(3, 3, 1, {1, 1, 1, 1, 0, 1, 1, 1, 1}));     // tunnel (torus)
  std::vector<uint8_t> hollow(27, 1);
  hollow[13] = 0;
  EXPECT_TRUE(rejected(3, 3, 3, hollow));                          // cavity
  EXPECT_TRUE(rejected(2, 1, 1, {0, 0}));                          // empty
  EXPECT_TRUE(rejected(2, 1, 1, {1}));                             // wrong size
  EXPECT_FALSE(rejected(3, 3, 1, {1, 1, 1, 1, 0, 0, 1, 1, 1}));    // a C: fine
}

TEST(RandomVoxelSolid, FiftySeedsAreValidAndDeterministic) {
  std::set<std::vector<Quad>> distinct;
  for (uint64_t seed = 0; seed < 50; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const int m = seed % 5 == 0 ? 2 : 1;
    const Generated g = random_voxel_solid(seed, 4, 14, m);
    expect_valid(g);
    EXPECT_NEAR(signed_volume(g.surface), g.known_mesh.num_hexes() / double(m * m * m), 1e-9);
    EXPECT_LE(g.known_mesh.num_hexes(), 14 * m * m * m);
    EXPECT_GE(g.known_mesh.num_hexes(), 8 * m * m * m) << "growth stalled early";
    EXPECT_TRUE(same(g, random_voxel_solid(seed, 4, 14, m)));
    if (m == 1) distinct.insert(g.surface.quads);
  }
  EXPECT_GT(distinct.size(), 20u);
}

TEST(Perturbed, MovesInTangentPlaneKeepingTheMesh) {
  const Generated g = cube(3, 3, 3);
  const Generated p = perturbed(g, 7, 0.2);
  expect_valid(p, false);
  EXPECT_EQ(p.surface.quads, g.surface.quads);
  EXPECT_EQ(p.chord_lengths, g.chord_lengths);
  EXPECT_EQ(p.known_mesh.hexes, g.known_mesh.hexes);
  int moved = 0;
  for (int32_t v = 0; v < g.surface.num_points(); ++v) {
    const Vec3 a = g.surface.points[v], d = p.surface.points[v] - a;
    EXPECT_LE(d.norm(), 0.2 + 1e-12);  // every edge of cube(3,3,3) has length 1
    moved += d.norm() > 0;
    // A vertex inside a cube face (exactly one coordinate at 0 or 3) stays in the face's plane.
    int on = 0, axis = -1;
    for (int i = 0; i < 3; ++i)
      if (a[i] == 0.0 || a[i] == 3.0) ++on, axis = i;
    if (on == 1) EXPECT_NEAR(d[axis], 0.0, 1e-12) << "vertex " << v;
  }
  EXPECT_EQ(moved, g.surface.num_points());
  for (size_t v = g.surface.points.size(); v < g.known_mesh.points.size(); ++v)
    EXPECT_EQ(p.known_mesh.points[v], g.known_mesh.points[v]);
  EXPECT_EQ(positive_hexes(perturbed(g, 7, 0.1).known_mesh), g.known_mesh.num_hexes());
  EXPECT_TRUE(same(p, perturbed(g, 7, 0.2)));
  EXPECT_NE(p.surface.points, perturbed(g, 8, 0.2).surface.points);
  for (const Generated& base : {cubed_sphere(4), named_solid("notch", 2)}) {
    const Generated q = perturbed(base, 3, 0.1);
    expect_valid(q, false);
    std::cout << "[ info ] " << q.name << ": " << positive_hexes(q.known_mesh) << "/"
              << q.known_mesh.num_hexes() << " hexes positive\n";
  }
}

TEST(Jittered, SurfaceAsPerturbedInteriorMoved) {
  const Generated g = named_solid("pocket", 2);
  const Generated j = jittered(g, 5, 0.1), p = perturbed(g, 5, 0.1);
  expect_valid(j, false);
  EXPECT_EQ(j.surface.points, p.surface.points);
  EXPECT_EQ(j.surface.quads, p.surface.quads);
  int moved = 0;
  for (size_t v = g.surface.points.size(); v < g.known_mesh.points.size(); ++v)
    moved += j.known_mesh.points[v] != g.known_mesh.points[v];
  EXPECT_EQ(moved, g.known_mesh.num_points() - g.surface.num_points());
  EXPECT_EQ(positive_hexes(j.known_mesh), j.known_mesh.num_hexes());
  EXPECT_TRUE(same(j, jittered(g, 5, 0.1)));
}

TEST(Refined, SplitsQuadsAndHexesAndDoublesChords) {
  for (const Generated& g : {cube(2, 3, 4), cubed_sphere(3), named_solid("pocket", 1),
                             named_solid("steps", 1), random_voxel_solid(11, 4, 12)}) {
    const Generated r = refined(g);
    SCOPED_TRACE(r.name);
    expect_valid(r);
    EXPECT_EQ(r.surface.num_quads(), 4 * g.surface.num_quads());
    EXPECT_EQ(r.known_mesh.num_hexes(), 8 * g.known_mesh.num_hexes());
    EXPECT_EQ(r.chord_lengths, split_chords(g.chord_lengths, 2));
    EXPECT_NEAR(signed_volume(r.surface), signed_volume(g.surface), 1e-9);
    const Generated rr = refined(r);
    expect_valid(rr);
    EXPECT_EQ(rr.chord_lengths, split_chords(g.chord_lengths, 4));
    EXPECT_TRUE(same(r, refined(g)));
  }
  // refined(cube(n)) is cube(2n) combinatorially.
  EXPECT_EQ(refined(cube(2, 2, 2)).chord_lengths, cube(4, 4, 4).chord_lengths);
  const Generated rp = refined(perturbed(cube(3, 3, 3), 1, 0.1));
  expect_valid(rp, false);
}

TEST(Pillowed, ValidComplexWithKnownHexCount) {
  int surface_changed = 0, total = 0;
  for (const Generated& g : {cube(4, 4, 4), named_solid("pocket", 2), cubed_sphere(4),
                             random_voxel_solid(3, 4, 12, 2), refined(named_solid("L", 1))}) {
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      SCOPED_TRACE("seed " + std::to_string(seed));
      const Generated p = pillowed(g, seed, 0.3);
      expect_valid(p, false);
      EXPECT_GT(p.known_mesh.num_hexes(), g.known_mesh.num_hexes());
      EXPECT_TRUE(same(p, pillowed(g, seed, 0.3)));
      const int positive = positive_hexes(p.known_mesh);
      std::cout << "[ info ] " << p.name << ": " << p.surface.num_quads() << " quads (was "
                << g.surface.num_quads() << "), " << p.chords << " chords (was " << g.chords
                << "), " << p.known_mesh.num_hexes() << " hexes (was "
                << g.known_mesh.num_hexes() << "), " << positive << " positive\n";
      EXPECT_EQ(positive, p.known_mesh.num_hexes()) << "pillowed keeps an all-positive input so";
      surface_changed += p.surface.num_quads() != g.surface.num_quads();
      ++total;
      // Pillowing again works on the result too.
      if (seed == 1) expect_valid(pillowed(p, 99, 0.2), false);
    }
  }
  EXPECT_GT(surface_changed, total / 2) << "most random shrink sets reach the boundary";
}

TEST(Pillowed, WithoutKnownMeshReturnsInput) {
  Generated g = cube(2, 2, 2);
  g.known_mesh = {};
  EXPECT_EQ(pillowed(g, 1).surface.quads, g.surface.quads);
}

}  // namespace
}  // namespace hexpeel::testing
