// Tests of find_chords, chord_stats, classify_edges and diagnose_surface on hand-made surfaces
// whose chords and sharp edges are known.
#include "hexpeel/chords.h"
#include "hexpeel/diagnosis.h"

#include "support/generators.h"
#include "topology/soups.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace hexpeel {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// Every passage belongs to exactly the chord that lists it, consecutive steps are neighbours
/// across the leaving edge, and the walk closes.
void expect_consistent(const QuadSurface& s, const QuadAdjacency& adj, const ChordSet& set) {
  ASSERT_EQ(set.chord_of.size(), 2 * static_cast<size_t>(s.num_quads()));
  size_t passages = 0;
  for (size_t c = 0; c < set.chords.size(); ++c) {
    const auto& steps = set.chords[c].steps;
    ASSERT_FALSE(steps.empty());
    EXPECT_TRUE(steps[0].edge == 0 || steps[0].edge == 1);
    if (c > 0) {
      const auto& prev = set.chords[c - 1].steps[0];
      EXPECT_LT(std::make_pair(prev.quad, prev.edge), std::make_pair(steps[0].quad, steps[0].edge));
    }
    for (size_t i = 0; i < steps.size(); ++i) {
      EXPECT_EQ(set.chord_of[2 * steps[i].quad + (steps[i].edge & 1)], static_cast<int32_t>(c));
      const ChordStep& next = steps[(i + 1) % steps.size()];
      EXPECT_EQ(adj.opposite[4 * steps[i].quad + ((steps[i].edge + 2) & 3)],
                4 * next.quad + next.edge);
    }
    passages += steps.size();
  }
  EXPECT_EQ(passages, 2 * static_cast<size_t>(s.num_quads()));
  for (int32_t id : set.chord_of) EXPECT_GE(id, 0);
}

struct Found {
  QuadSurface surface;
  QuadAdjacency adj;
  ChordSet chords;
};

Found chords_of(const PolygonSoup& soup) {
  Found f;
  f.surface = test::to_surface(soup);
  f.adj = build_adjacency(f.surface);
  f.chords = find_chords(f.surface, f.adj);
  return f;
}

std::vector<int32_t> sorted_lengths(const ChordSet& set) {
  std::vector<int32_t> len;
  for (const auto& c : set.chords) len.push_back(static_cast<int32_t>(c.steps.size()));
  std::sort(len.begin(), len.end());
  return len;
}

TEST(Chords, UnitCubeHasThreeChordsOfLengthFour) {
  const Found f = chords_of(test::cube_soup());
  expect_consistent(f.surface, f.adj, f.chords);
  EXPECT_EQ(sorted_lengths(f.chords), (std::vector<int32_t>{4, 4, 4}));
  for (int32_t q = 0; q < 6; ++q) EXPECT_NE(f.chords.chord_of[2 * q], f.chords.chord_of[2 * q + 1]);
  const ChordStats st = chord_stats(f.chords);
  EXPECT_EQ(st.count, 3);
  EXPECT_EQ(st.min_length, 4);
  EXPECT_EQ(st.max_length, 4);
  EXPECT_DOUBLE_EQ(st.mean_length, 4.0);
  EXPECT_EQ(st.self_intersecting, 0);
}

TEST(Chords, GridBoundaries) {
  for (int n = 2; n <= 4; ++n) {
    const Found f = chords_of(test::grid_soup(n));
    expect_consistent(f.surface, f.adj, f.chords);
    EXPECT_EQ(sorted_lengths(f.chords), std::vector<int32_t>(3 * n, 4 * n)) << n;
  }
}

TEST(Chords, LShape) {
  const Found f = chords_of(test::voxel_soup({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  expect_consistent(f.surface, f.adj, f.chords);
  // Around z: one chord of length 8; in x and y two each (one through 1 voxel, one through 2).
  EXPECT_EQ(sorted_lengths(f.chords), (std::vector<int32_t>{4, 4, 6, 6, 8}));
}

TEST(Chords, Deterministic) {
  const Found a = chords_of(test::grid_soup(3)), b = chords_of(test::grid_soup(3));
  ASSERT_EQ(a.chords.chords.size(), b.chords.chords.size());
  for (size_t c = 0; c < a.chords.chords.size(); ++c)
    for (size_t i = 0; i < a.chords.chords[c].steps.size(); ++i) {
      EXPECT_EQ(a.chords.chords[c].steps[i].quad, b.chords.chords[c].steps[i].quad);
      EXPECT_EQ(a.chords.chords[c].steps[i].edge, b.chords.chords[c].steps[i].edge);
    }
  EXPECT_EQ(a.chords.chord_of, b.chords.chord_of);
}

TEST(Chords, SelfIntersectingChordOfOddSurface) {
  // A closed genus-0 surface with an odd quad count must have a self-intersecting chord: two
  // closed curves on a sphere cross an even number of times.
  const Found f = chords_of(test::prism_radial_soup());
  expect_consistent(f.surface, f.adj, f.chords);
  ASSERT_EQ(f.chords.chords.size(), 1u);
  const Chord& c = f.chords.chords[0];
  EXPECT_EQ(c.steps.size(), 18u);
  EXPECT_TRUE(c.self_intersecting);
  EXPECT_EQ(c.crossings, (std::vector<int32_t>{0, 1, 2, 3, 4, 5, 6, 7, 8}));
  EXPECT_EQ(chord_stats(f.chords).self_intersecting, 1);
}

PolygonSoup square_pyramid_radial() {
  return test::radial_soup({{1, 1, 0}, {-1, 1, 0}, {-1, -1, 0}, {1, -1, 0}, {0, 0, 1}},
                           {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}});
}

TEST(Chords, SelfIntersectingChordOfValidSurface) {
  const Found f = chords_of(square_pyramid_radial());
  expect_consistent(f.surface, f.adj, f.chords);
  ASSERT_EQ(f.chords.chords.size(), 1u);
  EXPECT_EQ(f.chords.chords[0].steps.size(), 16u);
  EXPECT_EQ(f.chords.chords[0].crossings, (std::vector<int32_t>{0, 1, 2, 3, 4, 5, 6, 7}));
}

TEST(EdgeGeometry, UnitCubeAllConvexSharp) {
  const Found f = chords_of(test::cube_soup());
  const EdgeGeometry g = classify_edges(f.surface, f.adj);
  EXPECT_EQ(g.sharp_convex, 12);
  EXPECT_EQ(g.sharp_concave, 0);
  EXPECT_EQ(g.flat, 0);
  for (size_t he = 0; he < g.kind.size(); ++he) {
    EXPECT_EQ(g.kind[he], EdgeKind::convex);
    EXPECT_NEAR(g.bend_deg[he], 90.0, 1e-9);
  }
  // Above the cube's 90 degrees nothing is sharp.
  const EdgeGeometry blunt = classify_edges(f.surface, f.adj, 95.0);
  EXPECT_EQ(blunt.flat, 12);
  EXPECT_NEAR(blunt.bend_deg[0], 90.0, 1e-9);
}

TEST(EdgeGeometry, LShapeHasOneConcaveEdge) {
  const PolygonSoup soup = test::voxel_soup({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const Found f = chords_of(soup);
  const EdgeGeometry g = classify_edges(f.surface, f.adj);
  // Prism over an L hexagon: 16 top/bottom rim edges and 5 vertical corner edges are convex, the
  // inner corner's vertical edge (1,1,0)-(1,1,1) is concave, 2 side and 4 cap edges are flat.
  EXPECT_EQ(g.sharp_convex, 21);
  EXPECT_EQ(g.sharp_concave, 1);
  EXPECT_EQ(g.flat, 6);
  for (int32_t he = 0; he < 4 * f.surface.num_quads(); ++he) {
    EXPECT_EQ(g.kind[he], g.kind[f.adj.opposite[he]]);
    EXPECT_EQ(g.bend_deg[he], g.bend_deg[f.adj.opposite[he]]);
    if (g.kind[he] != EdgeKind::concave) continue;
    const Vec3 a = f.surface.points[f.surface.quads[he >> 2][he & 3]];
    const Vec3 b = f.surface.points[f.surface.quads[he >> 2][((he & 3) + 1) & 3]];
    EXPECT_EQ(a.x(), 1.0);
    EXPECT_EQ(a.y(), 1.0);
    EXPECT_EQ(b.x(), 1.0);
    EXPECT_EQ(b.y(), 1.0);
    EXPECT_NEAR(g.bend_deg[he], -90.0, 1e-9);
  }
}

TEST(EdgeGeometry, FlatFaceInteriorEdges) {
  const Found f = chords_of(test::grid_soup(2));
  const EdgeGeometry g = classify_edges(f.surface, f.adj);
  EXPECT_EQ(g.sharp_convex, 24);
  EXPECT_EQ(g.sharp_concave, 0);
  EXPECT_EQ(g.flat, 24);  // 4 interior edges on each of the 6 faces
  for (int32_t he = 0; he < 4 * f.surface.num_quads(); ++he)
    if (g.kind[he] == EdgeKind::flat) {
      EXPECT_NEAR(g.bend_deg[he], 0.0, 1e-9);
    }
}

TEST(Diagnosis, CubeIsOk) {
  const SurfaceDiagnosis d = diagnose_surface(test::cube_soup());
  ASSERT_TRUE(d.status.ok()) << to_string(d.status);
  EXPECT_EQ(d.chord_stats.count, 3);
  EXPECT_EQ(d.edges.sharp_convex, 12);
  const std::string text = to_text(d);
  EXPECT_TRUE(contains(text, "status: ok")) << text;
  EXPECT_TRUE(contains(text, "6 quads, 8 vertices, 12 edges, 1 part, genus 0")) << text;
  EXPECT_TRUE(contains(text, "chords: 3, length min 4 / mean 4.0 / max 4, 0 self-intersecting"))
      << text;
  EXPECT_TRUE(contains(text, "edges at 60 deg: 12 sharp convex, 0 sharp concave, 0 flat")) << text;
  const nlohmann::json j = to_json(d);
  EXPECT_EQ(j["status"]["code"], "ok");
  EXPECT_EQ(j["chords"]["count"], 3);
  EXPECT_EQ(j["validation"]["genus"], 0);
  EXPECT_EQ(j["edges"]["sharp_convex"], 12);
}

TEST(Diagnosis, SelfIntersectingChordIsRefused) {
  const SurfaceDiagnosis d = diagnose_surface(square_pyramid_radial());
  EXPECT_TRUE(d.validation.status.ok()) << to_string(d.validation.status);
  EXPECT_EQ(d.status.code, StatusCode::self_intersecting_chord);
  EXPECT_TRUE(contains(d.status.message, "chord 0 (length 16) crosses itself at quads 0, 1, 2"))
      << d.status.message;
  EXPECT_TRUE(contains(d.status.message, "Müller-Hannemann 1999")) << d.status.message;
  EXPECT_TRUE(contains(d.status.message, "must be remeshed")) << d.status.message;
  const std::string text = to_text(d);
  EXPECT_TRUE(contains(text, "chord 0: length 16, crosses itself at quads 0, 1, 2")) << text;
  const nlohmann::json j = to_json(d);
  EXPECT_EQ(j["status"]["code"], "self_intersecting_chord");
  ASSERT_EQ(j["chords"]["self_intersecting"].size(), 1u);
  EXPECT_EQ(j["chords"]["self_intersecting"][0]["length"], 16);
}

TEST(Diagnosis, InvalidSurfaceKeepsValidationStatus) {
  const SurfaceDiagnosis odd = diagnose_surface(test::prism_radial_soup());
  EXPECT_EQ(odd.status.code, StatusCode::odd_quad_count);
  EXPECT_EQ(odd.chord_stats.self_intersecting, 1);  // still reported
  EXPECT_TRUE(odd.edges.kind.empty());

  const SurfaceDiagnosis torus = diagnose_surface(test::torus_soup(4, 4));
  EXPECT_EQ(torus.status.code, StatusCode::nonzero_genus);
  EXPECT_EQ(torus.chord_stats.count, 8);
  EXPECT_TRUE(contains(to_text(torus), "genus 1")) << to_text(torus);

  PolygonSoup open = test::cube_soup();
  open.indices.resize(open.offsets[5]);
  open.offsets.pop_back();
  const SurfaceDiagnosis d = diagnose_surface(open);
  EXPECT_EQ(d.status.code, StatusCode::open_boundary);
  EXPECT_EQ(d.chord_stats.count, 0);
  EXPECT_EQ(to_json(d)["validation"]["issues"][0]["code"], "open_boundary");
  EXPECT_TRUE(contains(to_text(d), "error open_boundary: ")) << to_text(d);
}

std::vector<testing::Generated> generated_surfaces() {
  using namespace testing;
  std::vector<Generated> gs{cube(1, 1, 1), cube(2, 3, 4), cube(3, 3, 3, 0.01), cubed_sphere(4),
                            cubed_sphere_equiangular(3)};
  for (const char* shape : {"L", "U", "T", "pocket", "notch", "stairs", "steps"})
    for (int m = 1; m <= 2; ++m) gs.push_back(named_solid(shape, m));
  for (uint64_t seed = 1; seed <= 6; ++seed) gs.push_back(random_voxel_solid(seed, 4, 12));
  gs.push_back(perturbed(named_solid("L", 2), 7));
  gs.push_back(refined(named_solid("U", 1)));
  return gs;
}

TEST(Generated, ValidAndChordsMatchTheGenerator) {
  for (const testing::Generated& g : generated_surfaces()) {
    SCOPED_TRACE(g.name);
    if (g.surface.quads.empty()) continue;  // generator declined (documented behaviour)
    const SurfaceDiagnosis d = diagnose_surface(to_polygon_soup(g.surface));
    ASSERT_TRUE(d.status.ok()) << to_string(d.status);
    EXPECT_FALSE(d.validation.stats.flipped);
    EXPECT_EQ(d.validation.surface.quads, g.surface.quads);  // ids and corner order kept
    expect_consistent(d.validation.surface, build_adjacency(d.validation.surface), d.chords);
    if (g.chords >= 0) {
      EXPECT_EQ(d.chord_stats.count, g.chords);
    }
    if (!g.chord_lengths.empty()) {
      EXPECT_EQ(sorted_lengths(d.chords), g.chord_lengths);
    }
    EXPECT_EQ(sorted_lengths(d.chords), testing::chord_lengths_of(g.surface));
  }
}

TEST(Generated, VoxelSolidsHaveOnlyRightAngles) {
  for (const char* shape : {"L", "U", "pocket", "stairs"}) {
    const testing::Generated g = testing::named_solid(shape, 2);
    SCOPED_TRACE(g.name);
    const QuadAdjacency adj = build_adjacency(g.surface);
    const EdgeGeometry e = classify_edges(g.surface, adj);
    EXPECT_GT(e.sharp_concave, 0);
    for (double b : e.bend_deg)
      EXPECT_TRUE(std::abs(b) < 1e-9 || std::abs(std::abs(b) - 90.0) < 1e-9) << b;
  }
}

}  // namespace
}  // namespace hexpeel
