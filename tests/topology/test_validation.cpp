// Tests of run_validation: one tiny hand-made soup per failure class, asserting the status code
// and that the message names the offending ids; robustness on malformed soups.
#include "hexpeel/validation.h"

#include "topology/soups.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace hexpeel {
namespace {

using test::cube_soup;
using test::voxel_soup;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

const ValidationIssue* find_issue(const ValidationResult& r, StatusCode code) {
  for (const auto& is : r.issues)
    if (is.code == code) return &is;
  return nullptr;
}

/// Whether every quad of s is the soup's face of the same id, up to its first corner.
bool same_cycles(const QuadSurface& s, const PolygonSoup& soup) {
  if (s.num_quads() != soup.num_faces()) return false;
  for (int32_t f = 0; f < soup.num_faces(); ++f) {
    bool found = false;
    for (int r = 0; r < 4 && !found; ++r) {
      found = true;
      for (int i = 0; i < 4; ++i)
        found = found && s.quads[f][(i + r) & 3] == soup.indices[soup.offsets[f] + i];
    }
    if (!found) return false;
  }
  return true;
}

TEST(Validation, CubeIsValid) {
  const ValidationResult r = run_validation(cube_soup());
  ASSERT_TRUE(r.status.ok()) << to_string(r.status);
  EXPECT_TRUE(r.issues.empty());
  EXPECT_TRUE(r.warnings.empty());
  EXPECT_EQ(r.surface.num_quads(), 6);
  EXPECT_EQ(r.surface.num_points(), 8);
  EXPECT_EQ(r.stats.edges, 12);
  EXPECT_EQ(r.stats.components, 1);
  EXPECT_EQ(r.stats.genus, 0);
  EXPECT_FALSE(r.stats.flipped);
  ASSERT_EQ(r.input_vertex.size(), 8u);
  for (int32_t v = 0; v < 8; ++v) EXPECT_EQ(r.input_vertex[v], v);
  EXPECT_GT(signed_volume(r.surface), 0.0);
}

TEST(Validation, VoxelSolidsAreValid) {
  for (int n = 1; n <= 3; ++n) {
    const ValidationResult r = run_validation(test::grid_soup(n));
    EXPECT_TRUE(r.status.ok()) << n << ": " << to_string(r.status);
    EXPECT_EQ(r.surface.num_quads(), 6 * n * n);
  }
  const ValidationResult l = run_validation(voxel_soup({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  EXPECT_TRUE(l.status.ok()) << to_string(l.status);
}

TEST(Validation, TriangleIsNonQuad) {
  PolygonSoup s = cube_soup();
  s.points.emplace_back(2, 2, 2);
  s.add_face({0, 1, 8});  // face 6
  const ValidationResult r = run_validation(s);
  EXPECT_EQ(r.status.code, StatusCode::non_quad_face);
  EXPECT_TRUE(contains(r.status.message, "face 6 has 3 corners")) << r.status.message;
  ASSERT_EQ(r.issues.size(), 1u);
  EXPECT_EQ(r.issues[0].faces, std::vector<int32_t>{6});
}

TEST(Validation, NonQuadAndNanAreBothReported) {
  PolygonSoup s = cube_soup();
  s.points[3].y() = std::numeric_limits<double>::quiet_NaN();
  s.points.emplace_back(2, 2, 2);
  s.add_face({0, 1, 2, 3, 8});  // face 6, five corners
  const ValidationResult r = run_validation(s);
  EXPECT_EQ(r.status.code, StatusCode::non_finite_coordinate);
  ASSERT_NE(find_issue(r, StatusCode::non_quad_face), nullptr);
  EXPECT_TRUE(contains(find_issue(r, StatusCode::non_quad_face)->message, "face 6 has 5 corners"));
  EXPECT_TRUE(contains(r.status.message, "3 at (")) << r.status.message;
  EXPECT_EQ(find_issue(r, StatusCode::non_finite_coordinate)->vertices, std::vector<int32_t>{3});
}

TEST(Validation, NanCoordinate) {
  PolygonSoup s = cube_soup();
  s.points[5].z() = std::numeric_limits<double>::infinity();
  const ValidationResult r = run_validation(s);
  EXPECT_EQ(r.status.code, StatusCode::non_finite_coordinate);
  EXPECT_TRUE(contains(r.status.message, "5 at (")) << r.status.message;
  EXPECT_TRUE(contains(r.status.message, "inf")) << r.status.message;
}

TEST(Validation, IndexOutOfRange) {
  PolygonSoup s = cube_soup();
  s.indices[s.offsets[2] + 1] = 42;
  s.indices[s.offsets[4]] = -1;
  const ValidationResult r = run_validation(s);
  EXPECT_EQ(r.status.code, StatusCode::index_out_of_range);
  EXPECT_TRUE(contains(r.status.message, "face 2 uses vertex 42")) << r.status.message;
  EXPECT_TRUE(contains(r.status.message, "face 4 uses vertex -1")) << r.status.message;
  EXPECT_EQ(r.issues[0].faces, (std::vector<int32_t>{2, 4}));
}

TEST(Validation, OpenBoundary) {
  PolygonSoup s = cube_soup();
  // Drop the last face: its four edges become boundary edges of the faces around it.
  const int32_t last = s.num_faces() - 1;
  s.indices.resize(s.offsets[last]);
  s.offsets.pop_back();
  const ValidationResult r = run_validation(s);
  EXPECT_EQ(r.status.code, StatusCode::open_boundary);
  EXPECT_TRUE(contains(r.status.message, "4 edges are used by one quad only")) << r.status.message;
  EXPECT_TRUE(contains(r.status.message, "of quad ")) << r.status.message;
  EXPECT_EQ(r.issues[0].faces.size(), 4u);
  EXPECT_EQ(r.issues[0].vertices.size(), 4u);
  // An open cube has 5 quads, but parity is not judged on an open surface.
  EXPECT_EQ(find_issue(r, StatusCode::odd_quad_count), nullptr);
}

TEST(Validation, ThreeQuadsOnOneEdge) {
  PolygonSoup s = cube_soup();
  const int32_t a = s.indices[0], b = s.indices[1];  // edge (a,b) of face 0
  s.points.emplace_back(0.5, 0.5, -1);
  s.points.emplace_back(0.7, 0.5, -1);
  s.add_face({b, a, 8, 9});  // a fin: face 6
  const ValidationResult r = run_validation(s);
  EXPECT_EQ(r.status.code, StatusCode::non_manifold_edge);
  const std::string edge = "(" + std::to_string(std::min(a, b)) + "," + std::to_string(std::max(a, b)) + ")";
  EXPECT_TRUE(contains(r.status.message, "edge " + edge + " is shared by quads 0, ")) << r.status.message;
  EXPECT_TRUE(contains(r.status.message, " and 6")) << r.status.message;
  EXPECT_NE(find_issue(r, StatusCode::open_boundary), nullptr);  // the fin's free edges
}

TEST(Validation, TwoCubesSharingAVertex) {
  // Voxels (0,0,0) and (1,1,1) touch at the point (1,1,1) only.
  const PolygonSoup s = voxel_soup({{0, 0, 0}, {1, 1, 1}});
  const ValidationResult r = run_validation(s);
  EXPECT_EQ(r.status.code, StatusCode::non_manifold_vertex);
  int32_t shared = -1;
  for (int32_t v = 0; v < static_cast<int32_t>(s.points.size()); ++v)
    if (s.points[v] == Vec3(1, 1, 1)) shared = v;
  EXPECT_TRUE(contains(r.status.message, "vertex " + std::to_string(shared) + " (2 fans)"))
      << r.status.message;
  EXPECT_EQ(r.issues[0].vertices, std::vector<int32_t>{shared});
  EXPECT_EQ(r.stats.genus, -1);
}

TEST(Validation, CubeWithOneFaceReversedIsReoriented) {
  const PolygonSoup given = test::with_face_reversed(cube_soup(), 3);
  const ValidationResult r = run_validation(given);
  ASSERT_TRUE(r.status.ok()) << to_string(r.status);
  EXPECT_EQ(r.stats.reoriented, std::vector<int32_t>{3});
  EXPECT_FALSE(r.stats.flipped);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_TRUE(contains(r.warnings[0], "disagree across 4 edges; 1 quad was reversed to agree with "
                                      "the rest: 3"))
      << r.warnings[0];
  // The surface is the cube as it was before its face was reversed.
  EXPECT_TRUE(same_cycles(r.surface, cube_soup()));

  ValidationParams strict;
  strict.reorient = false;
  const ValidationResult e = run_validation(given, strict);
  EXPECT_EQ(e.status.code, StatusCode::inconsistent_orientation);
  EXPECT_TRUE(contains(e.status.message, "4 edges are traversed in the same direction"))
      << e.status.message;
  EXPECT_TRUE(contains(e.status.message, "reversing quad 3 would make it consistent"))
      << e.status.message;
  EXPECT_NE(std::find(e.issues[0].faces.begin(), e.issues[0].faces.end(), 3),
            e.issues[0].faces.end());
}

TEST(Validation, MajorityReversedThenInwardIsFlippedWhole) {
  // Four of the six faces reversed: the two others are the minority, reversed to agree; the
  // result faces inward and is then flipped as a whole.
  PolygonSoup s = cube_soup();
  for (int32_t f : {0, 1, 2, 4}) s = test::with_face_reversed(s, f);
  const ValidationResult r = run_validation(s);
  ASSERT_TRUE(r.status.ok()) << to_string(r.status);
  EXPECT_EQ(r.stats.reoriented, (std::vector<int32_t>{3, 5}));
  EXPECT_TRUE(r.stats.flipped);
  EXPECT_GT(signed_volume(r.surface), 0.0);
  EXPECT_TRUE(same_cycles(r.surface, cube_soup()));
}

TEST(Validation, NonOrientableSurfaceIsRejected) {
  const ValidationResult r = run_validation(test::klein_soup(6, 4));
  EXPECT_EQ(r.status.code, StatusCode::inconsistent_orientation);
  EXPECT_TRUE(contains(r.status.message, "the surface is not orientable")) << r.status.message;
  EXPECT_TRUE(r.stats.reoriented.empty());
}

TEST(Validation, TwoDisjointCubes) {
  const ValidationResult r = run_validation(voxel_soup({{0, 0, 0}, {3, 0, 0}}));
  ASSERT_EQ(r.issues.size(), 1u) << to_string(r.status);
  EXPECT_EQ(r.status.code, StatusCode::multiple_components);
  EXPECT_TRUE(contains(r.status.message, "2 separate parts (one quad of each: 0, 6)"))
      << r.status.message;
  EXPECT_EQ(r.stats.components, 2);
  EXPECT_EQ(r.stats.genus, 0);
}

TEST(Validation, TorusHasGenusOne) {
  const ValidationResult r = run_validation(test::torus_soup(4, 4));
  ASSERT_EQ(r.issues.size(), 1u) << to_string(r.status);
  EXPECT_EQ(r.status.code, StatusCode::nonzero_genus);
  EXPECT_TRUE(contains(r.status.message, "genus 1")) << r.status.message;
  EXPECT_EQ(r.stats.genus, 1);
}

TEST(Validation, OddQuadCount) {
  // Radial mesh of a triangular prism: closed genus-0 quad surface with 9 quads.
  const ValidationResult r = run_validation(test::prism_radial_soup());
  ASSERT_EQ(r.issues.size(), 1u) << to_string(r.status);
  EXPECT_EQ(r.status.code, StatusCode::odd_quad_count);
  EXPECT_TRUE(contains(r.status.message, "9 quads: the boundary of any hex mesh has an even "
                                         "number of quads, so no hex mesh can exist"))
      << r.status.message;
  EXPECT_EQ(r.stats.genus, 0);
}

TEST(Validation, RepeatedCorner) {
  PolygonSoup s = cube_soup();
  s.indices[s.offsets[4] + 2] = s.indices[s.offsets[4]];
  const ValidationResult r = run_validation(s);
  EXPECT_EQ(r.status.code, StatusCode::degenerate_quad);
  EXPECT_TRUE(contains(r.status.message, "quad 4 repeats vertex " + std::to_string(s.indices[s.offsets[4]])))
      << r.status.message;
  EXPECT_EQ(r.issues[0].faces, std::vector<int32_t>{4});
}

TEST(Validation, ZeroAreaQuad) {
  PolygonSoup s = cube_soup();
  s.points.emplace_back(5, 0, 0);
  s.points.emplace_back(6, 0, 0);
  s.points.emplace_back(7, 0, 0);
  s.points.emplace_back(8, 0, 0);
  s.add_face({8, 9, 10, 11});  // collinear corners: face 6
  const ValidationResult r = run_validation(s);
  EXPECT_EQ(r.status.code, StatusCode::degenerate_quad);
  EXPECT_TRUE(contains(r.status.message, "quad 6 has area 0")) << r.status.message;
}

TEST(Validation, DuplicateVertices) {
  PolygonSoup s = cube_soup();
  s.points.push_back(s.points[2]);  // vertex 8 at the position of vertex 2
  for (int32_t i = s.offsets[0]; i < s.offsets[1]; ++i)  // the bottom quad uses vertex 2
    if (s.indices[i] == 2) s.indices[i] = 8;
  const ValidationResult r = run_validation(s);
  EXPECT_EQ(r.status.code, StatusCode::duplicate_vertex);
  EXPECT_TRUE(contains(r.status.message, "vertices 2 and 8 at (")) << r.status.message;
  EXPECT_EQ(r.issues[0].vertices, (std::vector<int32_t>{2, 8}));
}

TEST(Validation, DuplicateVerticesWithinTolerance) {
  PolygonSoup s = cube_soup();
  s.points.push_back(s.points[2] + Vec3(1e-9, 0, 0));
  for (int32_t i = s.offsets[0]; i < s.offsets[1]; ++i)  // the bottom quad uses vertex 2
    if (s.indices[i] == 2) s.indices[i] = 8;
  EXPECT_NE(run_validation(s).status.code, StatusCode::duplicate_vertex);  // exact by default
  ValidationParams p;
  p.duplicate_tolerance = 1e-6;
  const ValidationResult r = run_validation(s, p);
  EXPECT_EQ(r.status.code, StatusCode::duplicate_vertex);
  EXPECT_TRUE(contains(r.status.message, "vertices 2 and 8 near")) << r.status.message;
  EXPECT_EQ(r.issues[0].vertices, (std::vector<int32_t>{2, 8}));
  // Neighbours one grid step apart are not duplicates.
  EXPECT_TRUE(run_validation(test::grid_soup(3), p).status.ok());
}

TEST(Validation, UnusedDuplicateIsHarmless) {
  PolygonSoup s = cube_soup();
  s.points.push_back(s.points[0]);  // unused copy of vertex 0: dropped, not a duplicate
  const ValidationResult r = run_validation(s);
  EXPECT_TRUE(r.status.ok()) << to_string(r.status);
}

TEST(Validation, UnusedVerticesDroppedWithWarning) {
  PolygonSoup s = cube_soup();
  // Insert an unused vertex at id 0 and another at the end, shifting the cube's ids by one.
  s.points.insert(s.points.begin(), Vec3(9, 9, 9));
  for (auto& i : s.indices) ++i;
  s.points.emplace_back(7, 7, 7);
  std::string logged;
  Context ctx;
  ctx.log = [&](LogLevel, std::string_view m) { logged += m; };
  const ValidationResult r = run_validation(s, {}, ctx);
  ASSERT_TRUE(r.status.ok()) << to_string(r.status);
  EXPECT_EQ(r.stats.unused_vertices, 2);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_TRUE(contains(r.warnings[0], "2 vertices are used by no face and dropped: 0, 9"))
      << r.warnings[0];
  EXPECT_EQ(logged, r.warnings[0]);
  EXPECT_EQ(r.surface.num_points(), 8);
  ASSERT_EQ(r.input_vertex.size(), 8u);
  for (int32_t v = 0; v < 8; ++v) {
    EXPECT_EQ(r.input_vertex[v], v + 1);
    EXPECT_EQ(r.surface.points[v], s.points[v + 1]);
  }
}

/// The 3x3x3 block's boundary with its top-centre vertex pushed down through the bottom face.
PolygonSoup pushed_through_cube(int32_t& pushed) {
  PolygonSoup s = test::grid_soup(3);
  pushed = -1;
  for (int32_t v = 0; v < static_cast<int32_t>(s.points.size()); ++v)
    if (s.points[v] == Vec3(1, 1, 3) || s.points[v] == Vec3(2, 2, 3)) pushed = v;  // an inner top vertex
  s.points[pushed].z() = -0.5;
  return s;
}

TEST(Validation, SurfacePushedThroughItselfIsRefused) {
  int32_t pushed = -1;
  const PolygonSoup s = pushed_through_cube(pushed);
  ASSERT_GE(pushed, 0);
  const ValidationResult r = run_validation(s);
  ASSERT_EQ(r.status.code, StatusCode::self_intersecting_surface) << to_string(r.status);
  EXPECT_TRUE(contains(r.status.message, "the surface intersects itself")) << r.status.message;
  // Every quad named has the pushed vertex or lies on the bottom face it went through.
  ASSERT_FALSE(r.issues[0].faces.empty());
  bool around_pushed = false;
  for (int32_t f : r.issues[0].faces) {
    bool has_pushed = false, on_bottom = true;
    for (int i = 0; i < 4; ++i) {
      const int32_t v = s.indices[s.offsets[f] + i];
      has_pushed = has_pushed || v == pushed;
      on_bottom = on_bottom && s.points[v].z() == 0.0;
    }
    EXPECT_TRUE(has_pushed || on_bottom) << "quad " << f;
    around_pushed = around_pushed || has_pushed;
  }
  EXPECT_TRUE(around_pushed);
  ValidationParams off;
  off.check_self_intersection = false;
  EXPECT_TRUE(run_validation(s, off).status.ok());
}

TEST(Validation, SpheresWithAVertexPushedThroughAreRefusedAndIntactOnesAccepted) {
  for (int n = 2; n <= 5; ++n) {
    PolygonSoup s = test::grid_soup(n);
    const Vec3 c(0.5 * n, 0.5 * n, 0.5 * n);
    for (Vec3& p : s.points) p = c + (p - c).normalized();
    SCOPED_TRACE("n = " + std::to_string(n));
    EXPECT_TRUE(run_validation(s).status.ok());
    for (int32_t v = 0; v < static_cast<int32_t>(s.points.size()); v += 7) {
      PolygonSoup bad = s;
      bad.points[v] = c - 1.3 * (s.points[v] - c);  // through the centre, out the other side
      const ValidationResult r = run_validation(bad);
      EXPECT_EQ(r.status.code, StatusCode::self_intersecting_surface) << "vertex " << v;
    }
    // Dented inwards without reaching the other side: still a valid surface.
    PolygonSoup dented = s;
    dented.points[0] = c + 0.7 * (s.points[0] - c);
    EXPECT_TRUE(run_validation(dented).status.ok()) << to_string(run_validation(dented).status);
  }
}

TEST(Validation, InwardCubeIsFlipped) {
  PolygonSoup s = cube_soup();
  for (int32_t f = 0; f < s.num_faces(); ++f) s = test::with_face_reversed(s, f);
  const ValidationResult r = run_validation(s);
  ASSERT_TRUE(r.status.ok()) << to_string(r.status);
  EXPECT_TRUE(r.stats.flipped);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_TRUE(contains(r.warnings[0], "oriented inward")) << r.warnings[0];
  EXPECT_GT(signed_volume(r.surface), 0.0);
  // Quads keep their ids and their first corner.
  for (int32_t f = 0; f < s.num_faces(); ++f) EXPECT_EQ(r.surface.quads[f][0], s.indices[s.offsets[f]]);

  ValidationParams strict;
  strict.flip_inward = false;
  const ValidationResult e = run_validation(s, strict);
  EXPECT_EQ(e.status.code, StatusCode::inconsistent_orientation);
  EXPECT_TRUE(contains(e.status.message, "oriented inward")) << e.status.message;
}

TEST(Validation, LongListsAreCapped) {
  PolygonSoup s;
  for (int i = 0; i < 30; ++i) s.points.emplace_back(i, 0, 0);
  for (int i = 0; i < 25; ++i) s.add_face({i, i + 1, i + 2});
  const ValidationResult r = run_validation(s);
  EXPECT_EQ(r.status.code, StatusCode::non_quad_face);
  EXPECT_TRUE(contains(r.status.message, "25 faces are not quads")) << r.status.message;
  EXPECT_TRUE(contains(r.status.message, "face 9 has 3 corners and 15 more")) << r.status.message;
  EXPECT_FALSE(contains(r.status.message, "face 10 ")) << r.status.message;
}

TEST(Validation, NeverCrashesOnMalformedSoups) {
  {
    const ValidationResult r = run_validation(PolygonSoup{});
    EXPECT_EQ(r.status.code, StatusCode::empty_mesh);
  }
  {
    PolygonSoup s;
    s.offsets.clear();
    EXPECT_EQ(run_validation(s).status.code, StatusCode::empty_mesh);
  }
  {
    PolygonSoup s;  // faces of size 0, 1 and 2, no vertices
    s.add_face({});
    s.add_face({0});
    s.add_face({0, 1});
    const ValidationResult r = run_validation(s);
    EXPECT_EQ(r.status.code, StatusCode::index_out_of_range);
    EXPECT_NE(find_issue(r, StatusCode::non_quad_face), nullptr);
    EXPECT_TRUE(contains(find_issue(r, StatusCode::non_quad_face)->message, "face 0 has 0 corners"));
  }
  {
    PolygonSoup s = cube_soup();  // all vertices identical
    for (auto& p : s.points) p = Vec3(1, 2, 3);
    const ValidationResult r = run_validation(s);
    EXPECT_EQ(r.status.code, StatusCode::degenerate_quad);
    EXPECT_NE(find_issue(r, StatusCode::duplicate_vertex), nullptr);
  }
  {
    PolygonSoup s = cube_soup();  // malformed offsets
    s.offsets[3] = 1000;
    EXPECT_EQ(run_validation(s).status.code, StatusCode::index_out_of_range);
    s = cube_soup();
    s.offsets[0] = 2;
    EXPECT_EQ(run_validation(s).status.code, StatusCode::index_out_of_range);
    s = cube_soup();
    std::swap(s.offsets[2], s.offsets[3]);
    EXPECT_EQ(run_validation(s).status.code, StatusCode::index_out_of_range);
  }
  {
    PolygonSoup s = cube_soup();  // a quad listed twice: non-manifold edges, no crash
    s.add_face({s.indices[0], s.indices[1], s.indices[2], s.indices[3]});
    EXPECT_FALSE(run_validation(s).status.ok());
  }
  {
    PolygonSoup s;  // two quads glued into a pillow: closed, two faces per edge
    for (int i = 0; i < 4; ++i) s.points.emplace_back(i & 1, i >> 1, 0);
    s.add_face({0, 1, 3, 2});
    s.add_face({0, 2, 3, 1});
    const ValidationResult r = run_validation(s);
    EXPECT_TRUE(r.warnings.empty() || contains(r.warnings[0], "no volume"));
  }
}

}  // namespace
}  // namespace hexpeel
