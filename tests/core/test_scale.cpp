// Scale invariance: scale_exponent / scale_points, and the same mesh, up to scale, from the same
// surface given in units from 1e-100 to 1e100 (check, mesh and quality scale-free).
#include "hexpeel/pipeline.h"
#include "hexpeel/quality.h"
#include "support/generators.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace hexpeel {
namespace {

namespace gen = hexpeel::testing;

TEST(Scale, ExponentBringsFarExtentsNearOne) {
  EXPECT_EQ(scale_exponent({}), 0);
  EXPECT_EQ(scale_exponent({Vec3(1, 1, 1)}), 0);  // no extent
  EXPECT_EQ(scale_exponent({Vec3(0, 0, 0), Vec3(3, 1, 2)}), 0);        // moderate: untouched
  EXPECT_EQ(scale_exponent({Vec3(0, 0, 0), Vec3(1e4, 1, 2)}), 0);
  EXPECT_EQ(scale_exponent({Vec3(0, 0, 0), Vec3(1e-4, 0, 0)}), 0);
  EXPECT_EQ(scale_exponent({Vec3(0, 0, 0), Vec3(std::nan(""), 0, 0)}), 0);
  for (double s : {1e-300, 1e-30, 3e-7, 7e6, 1e30, 1e300, 1.7e308}) {
    std::vector<Vec3> p{Vec3(-s, 0, 0), Vec3(0.5 * s, 0.25 * s, 0)};
    if (s > 1e308) p[0] = Vec3(-s, 0, 0), p[1] = Vec3(s, 0, 0);  // extent overflows a double
    const int k = scale_exponent(p);
    ASSERT_NE(k, 0) << s;
    std::vector<Vec3> q = p;
    scale_points(q, k);
    const double extent = (0.5 * q[1] - 0.5 * q[0]).maxCoeff() * 2.0;
    EXPECT_GE(extent, 1.0) << s;
    EXPECT_LT(extent, 2.0) << s;
    scale_points(q, -k);
    EXPECT_EQ(q, p) << s;  // exact both ways
  }
}

/// The surface's soup with every coordinate multiplied by `scale`.
PolygonSoup scaled_soup(const QuadSurface& s, double scale) {
  PolygonSoup soup = to_polygon_soup(s);
  for (Vec3& p : soup.points) p *= scale;
  return soup;
}

TEST(Scale, SameMeshUpToScaleFrom1e100To1eMinus100) {
  const QuadSurface s = gen::perturbed(gen::cubed_sphere_equiangular(3), 5, 0.15).surface;
  const MeshResult unit = run_mesh(to_polygon_soup(s));
  ASSERT_TRUE(unit.status.ok()) << to_string(unit.status);
  ASSERT_EQ(unit.quality.sj_count_nonpositive, 0);
  // Powers of two far from 1: the very same mesh, every coordinate scaled exactly.
  for (int e : {-330, -200, -17, 17, 200, 330}) {
    SCOPED_TRACE(e);
    const double scale = std::ldexp(1.0, e);
    const MeshResult r = run_mesh(scaled_soup(s, scale));
    ASSERT_TRUE(r.status.ok()) << to_string(r.status);
    ASSERT_EQ(r.mesh.hexes, unit.mesh.hexes);
    ASSERT_EQ(r.mesh.points.size(), unit.mesh.points.size());
    for (size_t v = 0; v < r.mesh.points.size(); ++v)
      ASSERT_EQ(r.mesh.points[v], scale * unit.mesh.points[v]) << v;
    EXPECT_EQ(r.quality.sj_min, unit.quality.sj_min);
  }
  // Other units: the same hexes and boundary, every hex positive; the interior is placed by an
  // iterative optimizer from coordinates rounded differently, so it agrees to within a few
  // percent of the size, and the minimum scaled Jacobian to 1e-3.
  for (double scale : {1e-100, 1e-30, 1e-9, 1e9, 1e30, 1e100}) {
    SCOPED_TRACE(scale);
    const PolygonSoup soup = scaled_soup(s, scale);
    const MeshResult r = run_mesh(soup);
    ASSERT_TRUE(r.status.ok()) << to_string(r.status);
    ASSERT_EQ(r.mesh.hexes, unit.mesh.hexes);
    ASSERT_EQ(r.mesh.points.size(), unit.mesh.points.size());
    for (int32_t v = 0; v < s.num_points(); ++v) EXPECT_EQ(r.mesh.points[v], soup.points[v]);
    double worst = 0.0;
    for (size_t v = 0; v < r.mesh.points.size(); ++v)
      worst = std::max(worst, (r.mesh.points[v] / scale - unit.mesh.points[v]).norm());
    EXPECT_LT(worst, 0.05);
    EXPECT_NEAR(r.quality.sj_min, unit.quality.sj_min, 1e-3);
    EXPECT_EQ(r.quality.sj_count_nonpositive, 0);
    // The quality of the scaled mesh alone, against its scaled surface: the same figures.
    QuadSurface surface = s;
    for (Vec3& p : surface.points) p *= scale;
    const QualityReport q = run_quality(r.mesh, {}, &surface);
    EXPECT_NEAR(q.sj_min, r.quality.sj_min, 1e-12);
    EXPECT_EQ(q.boundary_matches_surface, true);
    ASSERT_FALSE(q.worst.empty());
    EXPECT_NEAR(q.worst[0].centroid.norm() / scale, r.quality.worst[0].centroid.norm() / scale, 1e-9);
  }
}

}  // namespace
}  // namespace hexpeel
