// QuadSurface helpers: half-edge adjacency in one pass, quad normals, enclosed volume.
#include "hexpeel/quad_surface.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace hexpeel {

PolygonSoup to_polygon_soup(const QuadSurface& surface) {
  PolygonSoup soup;
  soup.points = surface.points;
  soup.indices.reserve(4 * surface.quads.size());
  for (const Quad& q : surface.quads) soup.add_face({q[0], q[1], q[2], q[3]});
  return soup;
}

QuadAdjacency build_adjacency(const QuadSurface& surface) {
  const int32_t nq = surface.num_quads();
  // Sort half-edges by their undirected key; runs of equal keys are the edges.
  struct Item { int32_t lo, hi, he; };
  std::vector<Item> items;
  items.reserve(4 * static_cast<size_t>(nq));
  for (int32_t q = 0; q < nq; ++q)
    for (int k = 0; k < 4; ++k) {
      int32_t a = surface.quads[q][k], b = surface.quads[q][(k + 1) & 3];
      items.push_back({std::min(a, b), std::max(a, b), 4 * q + k});
    }
  std::sort(items.begin(), items.end(), [](const Item& x, const Item& y) {
    return std::tie(x.lo, x.hi, x.he) < std::tie(y.lo, y.hi, y.he);
  });
  QuadAdjacency adj;
  adj.opposite.assign(items.size(), -1);
  for (size_t i = 0; i < items.size();) {
    size_t j = i;
    while (j < items.size() && items[j].lo == items[i].lo && items[j].hi == items[i].hi) ++j;
    if (j - i == 2) {
      adj.opposite[items[i].he] = items[i + 1].he;
      adj.opposite[items[i + 1].he] = items[i].he;
    }
    i = j;
  }
  return adj;
}

Vec3 quad_normal(const QuadSurface& surface, int32_t q) {
  const Quad& f = surface.quads[q];
  const auto& p = surface.points;
  Vec3 n = (p[f[2]] - p[f[0]]).cross(p[f[3]] - p[f[1]]);
  double len = n.norm();
  return len > 0 ? Vec3(n / len) : Vec3::Zero();
}

Vec3 quad_centroid(const QuadSurface& surface, int32_t q) {
  const Quad& f = surface.quads[q];
  const auto& p = surface.points;
  return 0.25 * (p[f[0]] + p[f[1]] + p[f[2]] + p[f[3]]);
}

double signed_volume(const QuadSurface& surface) {
  // Split each quad into two triangles fanned from corner 0; sum tetrahedra against the origin,
  // offset by the first point to limit cancellation.
  if (surface.points.empty()) return 0.0;
  const Vec3 o = surface.points[0];
  double vol = 0.0;
  for (const Quad& f : surface.quads) {
    Vec3 a = surface.points[f[0]] - o, b = surface.points[f[1]] - o, c = surface.points[f[2]] - o,
         d = surface.points[f[3]] - o;
    vol += a.dot(b.cross(c)) + a.dot(c.cross(d));
  }
  return vol / 6.0;
}

int scale_exponent(const std::vector<Vec3>& points) {
  if (points.empty()) return 0;
  Vec3 lo = points.front(), hi = lo;
  for (const Vec3& p : points) {
    if (!p.allFinite()) return 0;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // Halves first: hi - lo itself may overflow near the largest doubles.
  const double half_extent = (0.5 * hi - 0.5 * lo).maxCoeff();
  if (!(half_extent > 0.0)) return 0;
  const int e = std::ilogb(half_extent) + 1;  // extent = 2 * half_extent in [2^e, 2^(e+1))
  return e < -16 || e >= 16 ? -e : 0;
}

void scale_points(std::vector<Vec3>& points, int k) {
  if (k == 0) return;
  for (Vec3& p : points)
    for (int i = 0; i < 3; ++i) p[i] = std::ldexp(p[i], k);
}

}  // namespace hexpeel
