// Tests of the quality stage: Verdict's hex scaled Jacobian on hand-made hexes (values checked
// against VTK 9.1 vtkMeshQuality), the topology checks on small complexes, the boundary
// comparison, the report's JSON, and determinism across thread counts.
#include "hexpeel/quality.h"
#include "quality/quality_internal.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

namespace hexpeel {
namespace {

using Corners = std::array<Vec3, 8>;

Corners unit_cube() {
  return {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0),
          Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(1, 1, 1), Vec3(0, 1, 1)};
}

// The nine normalised Jacobians written out independently of the library's tables: corner c
// uses the edges to (a, b, d), as listed in Verdict's hex_scaled_jacobian.
double frame_value(const Vec3& x, const Vec3& y, const Vec3& z) {
  return x.dot(y.cross(z)) / (x.norm() * y.norm() * z.norm());
}
std::array<double, 8> corner_values(const Corners& p) {
  constexpr int frames[8][4] = {{0, 1, 3, 4}, {1, 2, 0, 5}, {2, 3, 1, 6}, {3, 0, 2, 7},
                                {4, 7, 5, 0}, {5, 4, 6, 1}, {6, 5, 7, 2}, {7, 6, 4, 3}};
  std::array<double, 8> v{};
  for (const auto& f : frames) v[f[0]] = frame_value(p[f[1]] - p[f[0]], p[f[2]] - p[f[0]], p[f[3]] - p[f[0]]);
  return v;
}
double centre_value(const Corners& p) {
  const Vec3 x = p[1] - p[0] + p[2] - p[3] + p[5] - p[4] + p[6] - p[7];
  const Vec3 y = p[3] - p[0] + p[2] - p[1] + p[7] - p[4] + p[6] - p[5];
  const Vec3 z = p[4] - p[0] + p[5] - p[1] + p[6] - p[2] + p[7] - p[3];
  return frame_value(x, y, z);
}

// Portable uniform double in [-1, 1) from a 64-bit engine (the std distributions are not
// portable across standard libraries).
double uniform(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53 * 2.0 - 1.0;
}

// nx*ny*nz unit cells; points (i,j,k) numbered x fastest; every point jittered by up to
// `jitter` per coordinate.
HexMesh grid(int nx, int ny, int nz, double jitter = 0.0, uint64_t seed = 1) {
  HexMesh m;
  std::mt19937_64 rng(seed);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        Vec3 p(i, j, k);
        if (jitter > 0)
          for (int c = 0; c < 3; ++c) p[c] += jitter * uniform(rng);
        m.points.push_back(p);
      }
  auto id = [&](int i, int j, int k) { return static_cast<int32_t>(i + (nx + 1) * (j + (ny + 1) * k)); };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        m.hexes.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
                           id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1),
                           id(i, j + 1, k + 1)});
  return m;
}

// The boundary of grid(nx,ny,nz) built from the grid's geometry (a cell face is on the
// boundary when the cell across it is outside the grid), with its own point numbering (reverse
// order), quads listed in reverse, every quad rotated and every third one reversed.
QuadSurface grid_boundary(const HexMesh& g, int nx, int ny, int nz) {
  // Neighbour direction of each local face of kHexFaces: -z, +z, -y, +x, +y, -x.
  constexpr int dir[6][3] = {{0, 0, -1}, {0, 0, 1}, {0, -1, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}};
  std::vector<Quad> quads;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (int lf = 0; lf < 6; ++lf) {
          const int a = i + dir[lf][0], b = j + dir[lf][1], c = k + dir[lf][2];
          if (a >= 0 && a < nx && b >= 0 && b < ny && c >= 0 && c < nz) continue;
          const Hex& h = g.hexes[i + nx * (j + ny * k)];
          quads.push_back({h[kHexFaces[lf][0]], h[kHexFaces[lf][1]], h[kHexFaces[lf][2]], h[kHexFaces[lf][3]]});
        }
  std::vector<int32_t> new_id(g.points.size(), -1);
  std::vector<int32_t> used;
  for (const Quad& q : quads) used.insert(used.end(), q.begin(), q.end());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  QuadSurface s;
  for (auto it = used.rbegin(); it != used.rend(); ++it) {
    new_id[*it] = s.num_points();
    s.points.push_back(g.points[*it]);
  }
  for (size_t n = quads.size(); n-- > 0;) {
    Quad q = quads[n];
    for (int32_t& v : q) v = new_id[v];
    std::rotate(q.begin(), q.begin() + n % 4, q.end());
    if (n % 3 == 0) std::reverse(q.begin(), q.end());
    s.quads.push_back(q);
  }
  return s;
}

HexMesh single(const Corners& c) {
  HexMesh m;
  m.points.assign(c.begin(), c.end());
  m.hexes.push_back({0, 1, 2, 3, 4, 5, 6, 7});
  return m;
}

// ---------------------------------------------------------------- scaled Jacobian

TEST(ScaledJacobian, UnitCubeIsOne) {
  EXPECT_NEAR(scaled_jacobian(unit_cube()), 1.0, 1e-15);
}

TEST(ScaledJacobian, ScaleAndTranslationInvariant) {
  Corners c = unit_cube();
  for (Vec3& p : c) p = p.cwiseProduct(Vec3(2.0, 0.5, 7.0)) + Vec3(100, 100, 100);
  EXPECT_NEAR(scaled_jacobian(c), 1.0, 1e-12);
}

TEST(ScaledJacobian, ShearedTopFace) {
  Corners c = unit_cube();
  for (int k = 4; k < 8; ++k) c[k].x() += 0.5;
  // Every bottom corner sees (1,0,0), (0,1,0), (0.5,0,1): 1/sqrt(1.25); the top corners and the
  // centre (axes (4,0,0), (0,4,0), (2,0,4)) give the same, and the other corners 1 or more.
  const double expected = 1.0 / std::sqrt(1.25);
  const auto corners = corner_values(c);
  EXPECT_NEAR(*std::min_element(corners.begin(), corners.end()), expected, 1e-15);
  EXPECT_NEAR(centre_value(c), expected, 1e-15);
  EXPECT_NEAR(scaled_jacobian(c), expected, 1e-15);
  EXPECT_NEAR(scaled_jacobian(c), 0.8944271909999159, 1e-15);  // VTK 9.1 vtkMeshQuality
}

TEST(ScaledJacobian, MirroredIsMinusOne) {
  const Corners c = unit_cube();
  Corners m;
  const Hex order = mirrored({0, 1, 2, 3, 4, 5, 6, 7});
  for (int k = 0; k < 8; ++k) m[k] = c[order[k]];
  EXPECT_NEAR(scaled_jacobian(m), -1.0, 1e-15);
}

TEST(ScaledJacobian, CentreJacobianCountsWhenAllCornersArePositive) {
  // Found by a random search over perturbed cubes: every corner frame is right-handed, but the
  // principal axes are not. VTK 9.1 vtkMeshQuality gives -0.0867005557466319 for it.
  const Corners c{Vec3(0.4, 0.7, -0.1), Vec3(1.4, 0.6, 0.0), Vec3(0.6, 1.2, 0.8),
                  Vec3(-0.5, 1.7, -0.6), Vec3(0.6, 0.3, 1.5), Vec3(0.2, 0.3, 0.4),
                  Vec3(0.3, 0.2, 0.1), Vec3(0.9, 0.6, 1.0)};
  const auto corners = corner_values(c);
  for (int k = 0; k < 8; ++k) EXPECT_GT(corners[k], 0.03) << "corner " << k;
  const double centre = centre_value(c);
  EXPECT_LT(centre, -0.08);
  EXPECT_NEAR(scaled_jacobian(c), centre, 1e-14);
  EXPECT_NEAR(scaled_jacobian(c), -0.0867005557466319, 1e-12);
}

TEST(ScaledJacobian, ZeroLengthEdgeIsDegenerate) {
  Corners c = unit_cube();
  c[5] = c[4];
  EXPECT_EQ(scaled_jacobian(c), kDegenerateScaledJacobian);
  // Verdict's threshold is absolute: squared length <= 1e-30.
  c[5] = c[4] + Vec3(1e-16, 0, 0);
  EXPECT_EQ(scaled_jacobian(c), kDegenerateScaledJacobian);
  c[5] = c[4] + Vec3(1e-14, 0, 0);
  EXPECT_NEAR(scaled_jacobian(c), 0.5, 1e-12);  // VTK 9.1: 0.500000000000005
  // A tiny but well-shaped hex is not degenerate.
  Corners tiny = unit_cube();
  for (Vec3& p : tiny) p *= 1e-12;
  EXPECT_NEAR(scaled_jacobian(tiny), 1.0, 1e-12);
}

TEST(ScaledJacobian, NonFiniteCornerGivesNoValueBelowVerdictsStart) {
  Corners c = unit_cube();
  for (Vec3& p : c) p.x() = std::nan("");
  EXPECT_EQ(scaled_jacobian(c), kDegenerateScaledJacobian);
}

TEST(ScaledJacobian, TermsAreTheNineJacobiansAndTheirMinimumIsTheValue) {
  // scaled_jacobian_term(c, 0) is the centre, (c, 1 + k) corner k; the local sweeps rely on the
  // minimum of the nine terms being bit for bit scaled_jacobian.
  std::mt19937_64 rng(11);
  auto jitter = [&] { return 0.45 * uniform(rng); };
  int inverted = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Corners c = unit_cube();
    for (Vec3& p : c) p += Vec3(jitter(), jitter(), jitter());
    // Moving point k changes only the centre, corner k and the corners of k's 3 frame
    // neighbours; the sweeps cache the other 4 corners' terms while a point moves.
    for (int k = 0; k < 8; ++k) {
      Corners moved = c;
      moved[k] += Vec3(jitter(), jitter(), jitter());
      const auto& nb = kHexCornerFrames[k];
      for (int corner = 0; corner < 8; ++corner) {
        const bool uses_k = corner == k || corner == nb[0] || corner == nb[1] || corner == nb[2];
        if (uses_k)
          EXPECT_NE(scaled_jacobian_term(moved, 1 + corner), scaled_jacobian_term(c, 1 + corner));
        else
          EXPECT_EQ(scaled_jacobian_term(moved, 1 + corner), scaled_jacobian_term(c, 1 + corner));
      }
    }
    const auto corners = corner_values(c);
    EXPECT_NEAR(scaled_jacobian_term(c, 0), centre_value(c), 1e-14);
    double lowest = scaled_jacobian_term(c, 0);
    for (int k = 0; k < 8; ++k) {
      EXPECT_NEAR(scaled_jacobian_term(c, 1 + k), corners[k], 1e-14) << "corner " << k;
      lowest = std::min(lowest, scaled_jacobian_term(c, 1 + k));
    }
    EXPECT_EQ(lowest, scaled_jacobian(c));
    inverted += lowest <= 0.0;
  }
  EXPECT_GT(inverted, 10);  // the jitter makes both signs
  // A zero-length edge makes only the terms that use it degenerate.
  Corners d = unit_cube();
  d[5] = d[4];  // edge 4-5: corners 4 and 5 use it, the centre and the other corners do not
  EXPECT_EQ(scaled_jacobian_term(d, 1 + 4), kDegenerateScaledJacobian);
  EXPECT_EQ(scaled_jacobian_term(d, 1 + 5), kDegenerateScaledJacobian);
  EXPECT_NE(scaled_jacobian_term(d, 1 + 0), kDegenerateScaledJacobian);
  EXPECT_NE(scaled_jacobian_term(d, 0), kDegenerateScaledJacobian);
  EXPECT_EQ(scaled_jacobian(d), kDegenerateScaledJacobian);
}

TEST(Report, DegenerateHexIsCountedNonpositive) {
  HexMesh m = grid(2, 1, 1);
  m.points[m.hexes[1][5]] = m.points[m.hexes[1][4]];  // collapse edge 4-5 of hex 1
  const QualityReport r = run_quality(m);
  EXPECT_EQ(r.per_hex_sj[1], kDegenerateScaledJacobian);
  EXPECT_EQ(r.sj_degenerate, 1);
  EXPECT_EQ(r.sj_count_nonpositive, 1);
  EXPECT_NEAR(r.sj_min, 1.0, 1e-15);  // over non-degenerate hexes
  EXPECT_NEAR(r.sj_mean, 1.0, 1e-15);
  EXPECT_EQ(r.histogram.front(), 1);
  EXPECT_EQ(r.histogram.back(), 1);
  ASSERT_EQ(r.worst.size(), 2u);
  EXPECT_EQ(r.worst[0].hex, 1);
  EXPECT_EQ(r.worst[1].hex, 0);
}

TEST(Report, InvertedHexCountedAndWorst) {
  HexMesh m = grid(3, 1, 1);
  m.hexes[2] = mirrored(m.hexes[2]);
  const QualityReport r = run_quality(m);
  EXPECT_EQ(r.sj_count_nonpositive, 1);
  EXPECT_EQ(r.sj_degenerate, 0);
  EXPECT_NEAR(r.sj_min, -1.0, 1e-15);
  EXPECT_NEAR(r.sj_mean, 1.0 / 3.0, 1e-15);
  EXPECT_EQ(r.worst[0].hex, 2);
  EXPECT_NEAR((r.worst[0].centroid - Vec3(2.5, 0.5, 0.5)).norm(), 0.0, 1e-15);
  EXPECT_EQ(r.histogram.front(), 1);
  EXPECT_EQ(r.histogram.back(), 2);
}

// ---------------------------------------------------------------- topology

TEST(Topology, GridIsABall) {
  const HexMesh m = grid(2, 2, 2);
  const QualityReport r = run_quality(m);
  EXPECT_TRUE(r.is_ball) << r.topology_message;
  EXPECT_TRUE(r.topology_message.empty());
  EXPECT_TRUE(r.faces_manifold);
  EXPECT_EQ(r.euler_characteristic, 1);
  EXPECT_EQ(r.vertices, 27);
  EXPECT_EQ(r.edges, 54);
  EXPECT_EQ(r.faces, 36);
  EXPECT_EQ(r.boundary_faces, 24);
  EXPECT_EQ(r.singular_edges_interior, 0);
  // By the documented definition (boundary edges with other than 2 hexes) the 24 boundary
  // edges along the cube's 12 feature edges, each in one hex, are singular.
  EXPECT_EQ(r.singular_edges_boundary, 24);
  EXPECT_NEAR(r.sj_min, 1.0, 1e-15);
  EXPECT_NEAR(r.sj_max, 1.0, 1e-15);
}

TEST(Topology, BoxGridSingularEdges) {
  const QualityReport r = run_quality(grid(3, 2, 4, 0.1, 7));
  EXPECT_TRUE(r.is_ball) << r.topology_message;
  EXPECT_EQ(r.singular_edges_interior, 0);
  EXPECT_EQ(r.singular_edges_boundary, 4 * (3 + 2 + 4));
}

TEST(Topology, ValenceThreeInteriorEdge) {
  // A triangular prism split into three hexes: the axis through the triangle's centre is an
  // interior edge of valence 3.
  HexMesh m;
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const Vec3 base[7] = {a, b, c, (a + b) / 2, (b + c) / 2, (c + a) / 2, (a + b + c) / 3};
  for (int z = 0; z < 2; ++z)
    for (const Vec3& p : base) m.points.push_back(p + Vec3(0, 0, z));
  const int32_t quads[3][4] = {{0, 3, 6, 5}, {1, 4, 6, 3}, {2, 5, 6, 4}};
  for (const auto& q : quads)
    m.hexes.push_back({q[0], q[1], q[2], q[3], q[0] + 7, q[1] + 7, q[2] + 7, q[3] + 7});
  const QualityReport r = run_quality(m);
  EXPECT_TRUE(r.is_ball) << r.topology_message;
  EXPECT_EQ(r.euler_characteristic, 1);
  EXPECT_EQ(r.singular_edges_interior, 1);
  EXPECT_EQ(r.singular_edges_boundary, 15);  // 3 vertical corner edges + 2 x 6 rim edges
  EXPECT_EQ(r.sj_count_nonpositive, 0);
}

TEST(Topology, TwoCubesSharingOnlyAnEdgeAreNotABall) {
  HexMesh m = grid(2, 2, 1);
  // Keep cells (0,0) and (1,1): they share the vertical edge through point (1,1,0)-(1,1,1).
  m.hexes = {m.hexes[0], m.hexes[3]};
  const QualityReport r = run_quality(m);
  EXPECT_FALSE(r.is_ball);
  EXPECT_TRUE(r.faces_manifold);
  const int32_t lo = 4, hi = 13;  // ids of (1,1,0) and (1,1,1) in the 3x3x2 point grid
  EXPECT_NE(r.topology_message.find("edge (" + std::to_string(lo) + ", " + std::to_string(hi) + ")"),
            std::string::npos)
      << r.topology_message;
  EXPECT_NE(r.topology_message.find("components"), std::string::npos) << r.topology_message;
}

TEST(Topology, TwoCubesSharingOnlyAVertexAreNotABall) {
  HexMesh m = grid(2, 2, 2);
  m.hexes = {m.hexes[0], m.hexes[7]};  // cells (0,0,0) and (1,1,1) share the centre point 13
  const QualityReport r = run_quality(m);
  EXPECT_FALSE(r.is_ball);
  EXPECT_NE(r.topology_message.find("point 13"), std::string::npos) << r.topology_message;
}

TEST(Topology, FaceUsedThreeTimesIsNotABall) {
  HexMesh m = grid(1, 1, 2);  // hexes 0 (below) and 1 (above) share face 4-5-6-7
  const int32_t base = m.num_points();
  for (int k = 0; k < 4; ++k) m.points.push_back(m.points[8 + k] + Vec3(0.2, 0.2, 0.5));
  m.hexes.push_back({4, 5, 7, 6, base, base + 1, base + 3, base + 2});
  const QualityReport r = run_quality(m);
  EXPECT_FALSE(r.is_ball);
  EXPECT_FALSE(r.faces_manifold);
  EXPECT_NE(r.topology_message.find("face (4, 5, 6, 7) used by hexes (0, 1, 2)"), std::string::npos)
      << r.topology_message;
}

TEST(Topology, HollowGridIsNotABall) {
  HexMesh m = grid(3, 3, 3);
  m.hexes.erase(m.hexes.begin() + 13);  // the centre cell
  const QualityReport r = run_quality(m);
  EXPECT_FALSE(r.is_ball);
  EXPECT_TRUE(r.faces_manifold);
  EXPECT_EQ(r.euler_characteristic, 2);
  EXPECT_NE(r.topology_message.find("2 component(s)"), std::string::npos) << r.topology_message;
}

TEST(Topology, BadIdsAreReportedNotFatal) {
  HexMesh m = grid(2, 1, 1);
  m.hexes[1][6] = 100;
  const QuadSurface s = grid_boundary(grid(2, 1, 1), 2, 1, 1);
  const QualityReport r = run_quality(m, {}, &s);
  EXPECT_EQ(r.per_hex_sj[1], kDegenerateScaledJacobian);
  EXPECT_FALSE(r.is_ball);
  EXPECT_NE(r.topology_message.find("hex 1 corner 6 is point 100"), std::string::npos)
      << r.topology_message;
  EXPECT_EQ(r.boundary_matches_surface, false);
}

TEST(Topology, RepeatedVertexIsNotABall) {
  HexMesh m = grid(1, 1, 1);
  m.hexes[0][6] = m.hexes[0][5];
  const QualityReport r = run_quality(m);
  EXPECT_FALSE(r.is_ball);
  EXPECT_NE(r.topology_message.find("hex 0 uses point 5 twice"), std::string::npos)
      << r.topology_message;
}

TEST(Topology, EmptyMesh) {
  const QualityReport r = run_quality(HexMesh{});
  EXPECT_EQ(r.hexes, 0);
  EXPECT_FALSE(r.is_ball);
  EXPECT_TRUE(std::isnan(r.sj_min) && std::isnan(r.sj_mean) && std::isnan(r.sj_max));
  const nlohmann::json j = to_json(r);
  EXPECT_TRUE(j["scaled_jacobian"]["min"].is_null());
  EXPECT_TRUE(j["scaled_jacobian"]["mean"].is_null());
  EXPECT_EQ(j["scaled_jacobian"]["count_nonpositive"], 0);
  EXPECT_FALSE(to_text(r).empty());
}

// ---------------------------------------------------------------- boundary vs surface

TEST(Boundary, GridMatchesItsBoundarySurface) {
  const HexMesh m = grid(3, 2, 2, 0.15, 3);
  const QuadSurface s = grid_boundary(m, 3, 2, 2);
  const QualityReport r = run_quality(m, {}, &s);
  ASSERT_TRUE(r.boundary_matches_surface.has_value());
  EXPECT_TRUE(*r.boundary_matches_surface) << r.boundary_message;
  EXPECT_TRUE(r.boundary_message.empty());
}

TEST(Boundary, WithinToleranceStillMatches) {
  const HexMesh m = grid(2, 2, 2);
  QuadSurface s = grid_boundary(m, 2, 2, 2);
  s.points[5] += Vec3(1e-8, -1e-8, 1e-8);  // 1e-6 * diagonal is about 3.5e-6
  const QualityReport r = run_quality(m, {}, &s);
  EXPECT_TRUE(*r.boundary_matches_surface) << r.boundary_message;
}

TEST(Boundary, MovedVertexDoesNotMatch) {
  HexMesh m = grid(2, 2, 2);
  const QuadSurface s = grid_boundary(m, 2, 2, 2);
  m.points[0] += Vec3(0.01, 0, 0);
  const QualityReport r = run_quality(m, {}, &s);
  EXPECT_FALSE(*r.boundary_matches_surface);
  EXPECT_NE(r.boundary_message.find("mesh boundary point 0"), std::string::npos) << r.boundary_message;
}

TEST(Boundary, DifferentQuadDoesNotMatch) {
  const HexMesh m = grid(2, 2, 2);
  QuadSurface s = grid_boundary(m, 2, 2, 2);
  // Same four vertices, different quad: (a, b, d, c) is no rotation or reversal of (a, b, c, d).
  std::swap(s.quads[7][2], s.quads[7][3]);
  const QualityReport r = run_quality(m, {}, &s);
  EXPECT_FALSE(*r.boundary_matches_surface);
  EXPECT_NE(r.boundary_message.find("surface quad 7 "), std::string::npos) << r.boundary_message;
}

TEST(Boundary, ReversedQuadStillMatches) {
  const HexMesh m = grid(2, 2, 2);
  QuadSurface s = grid_boundary(m, 2, 2, 2);
  std::reverse(s.quads[4].begin(), s.quads[4].end());
  EXPECT_TRUE(*run_quality(m, {}, &s).boundary_matches_surface);
}

TEST(Boundary, MissingQuadIsNamed) {
  const HexMesh m = grid(2, 2, 2);
  QuadSurface s = grid_boundary(m, 2, 2, 2);
  s.quads.pop_back();
  const QualityReport r = run_quality(m, {}, &s);
  EXPECT_FALSE(*r.boundary_matches_surface);
  EXPECT_NE(r.boundary_message.find("is not a surface quad"), std::string::npos) << r.boundary_message;
}

TEST(Boundary, NoSurfaceNoVerdict) {
  const QualityReport r = run_quality(grid(1, 1, 1));
  EXPECT_TRUE(r.is_ball) << r.topology_message;  // a single hex is a ball too
  EXPECT_FALSE(r.boundary_matches_surface.has_value());
  EXPECT_FALSE(to_json(r).contains("boundary_matches_surface"));
}

// ---------------------------------------------------------------- report

TEST(Report, JsonShape) {
  QualityParams params;
  params.histogram_bins = 4;
  params.worst_count = 3;
  const HexMesh m = grid(2, 2, 2);
  const QuadSurface s = grid_boundary(m, 2, 2, 2);
  const nlohmann::json j = to_json(run_quality(m, params, &s));
  EXPECT_EQ(j["hexes"], 8);
  EXPECT_EQ(j["points"], 27);
  const auto& sj = j["scaled_jacobian"];
  for (const char* key : {"min", "mean", "max", "count_nonpositive", "degenerate", "histogram", "worst"})
    EXPECT_TRUE(sj.contains(key)) << key;
  EXPECT_EQ(sj["histogram"]["lo"], -1.0);
  EXPECT_EQ(sj["histogram"]["hi"], 1.0);
  EXPECT_EQ(sj["histogram"]["counts"], nlohmann::json({0, 0, 0, 8}));
  ASSERT_EQ(sj["worst"].size(), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(sj["worst"][i]["id"], i);  // all equal: ties by id
  EXPECT_EQ(sj["worst"][1]["centroid"], nlohmann::json({1.5, 0.5, 0.5}));
  EXPECT_EQ(j["singular_edges"]["interior"], 0);
  EXPECT_EQ(j["euler_characteristic"], 1);
  EXPECT_EQ(j["is_ball"], true);
  EXPECT_EQ(j["topology_message"], "");
  EXPECT_EQ(j["boundary_matches_surface"], true);
  EXPECT_EQ(j["boundary_message"], "");
}

TEST(Report, SameResultForAnyThreadCount) {
  // More hexes than one parallel block, jittered enough to give distinct values.
  const HexMesh m = grid(16, 15, 14, 0.3, 11);
  QualityReport one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = run_quality(m);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = run_quality(m);
  }
  ASSERT_EQ(one.per_hex_sj.size(), m.hexes.size());
  EXPECT_EQ(one.per_hex_sj, two.per_hex_sj);
  EXPECT_EQ(one.sj_min, two.sj_min);
  EXPECT_EQ(one.sj_mean, two.sj_mean);
  EXPECT_EQ(one.sj_max, two.sj_max);
  EXPECT_EQ(to_json(one).dump(), to_json(two).dump());
  for (size_t h = 0; h < m.hexes.size(); h += 97) {
    Corners c;
    for (int k = 0; k < 8; ++k) c[k] = m.points[m.hexes[h][k]];
    EXPECT_EQ(one.per_hex_sj[h], scaled_jacobian(c));
  }
}

}  // namespace
}  // namespace hexpeel
