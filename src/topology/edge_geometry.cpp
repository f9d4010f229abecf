// Sharp-edge classification (paper sections 3.4 and 5.1): each edge is flat, or sharp and then
// convex or concave, from the dihedral angle of its two quads.
//
// The angle is the one between the two quads' unit normals (0 = flat, 90 = a cube's edge); the
// edge is sharp when it exceeds the threshold. Convex or concave comes from a sign test that
// needs no planar quads: with outward normals n1, n2, centroids c1, c2 and the edge midpoint m,
// (c2 - m).n1 + (c1 - m).n2 < 0 means each quad lies below the other's plane, i.e. the solid is
// convex there. The sum of both terms keeps the test symmetric in the two quads.
//
// Assumes: a validated (outward, consistently oriented, closed) surface. An edge without a
// neighbour or with a zero-length normal is left flat.
#include "hexpeel/chords.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hexpeel {

EdgeGeometry classify_edges(const QuadSurface& surface, const QuadAdjacency& adjacency,
                            double sharp_angle_deg) {
  const int32_t nq = surface.num_quads();
  EdgeGeometry g;
  g.kind.assign(4 * static_cast<size_t>(nq), EdgeKind::flat);
  g.bend_deg.assign(4 * static_cast<size_t>(nq), 0.0);

  std::vector<Vec3> normal(nq), centroid(nq);
  for (int32_t q = 0; q < nq; ++q) {
    normal[q] = quad_normal(surface, q);
    centroid[q] = quad_centroid(surface, q);
  }
  for (int32_t he = 0; he < 4 * nq; ++he) {
    const int32_t o = adjacency.opposite[he];
    if (o < he) continue;  // each edge once; -1 (no neighbour) stays flat and uncounted
    const int32_t q1 = he >> 2, q2 = o >> 2;
    const Vec3 &n1 = normal[q1], &n2 = normal[q2];
    double bend = 0.0;
    if (n1.squaredNorm() > 0 && n2.squaredNorm() > 0) {
      const double angle =
          std::acos(std::clamp(n1.dot(n2), -1.0, 1.0)) * (180.0 / std::numbers::pi);
      const Vec3 mid = 0.5 * (surface.points[surface.quads[q1][he & 3]] +
                              surface.points[surface.quads[q1][((he & 3) + 1) & 3]]);
      const double side = (centroid[q2] - mid).dot(n1) + (centroid[q1] - mid).dot(n2);
      bend = side <= 0.0 ? angle : -angle;
    }
    EdgeKind kind = EdgeKind::flat;
    if (std::abs(bend) > sharp_angle_deg) kind = bend > 0 ? EdgeKind::convex : EdgeKind::concave;
    g.kind[he] = g.kind[o] = kind;
    g.bend_deg[he] = g.bend_deg[o] = bend;
    if (kind == EdgeKind::convex)
      ++g.sharp_convex;
    else if (kind == EdgeKind::concave)
      ++g.sharp_concave;
    else
      ++g.flat;
  }
  return g;
}

std::vector<int32_t> sharp_patches(const QuadSurface& surface, const QuadAdjacency& adjacency,
                                   const EdgeGeometry& edges, int32_t& count) {
  const int32_t nq = surface.num_quads();
  std::vector<int32_t> patch(nq, -1);
  count = 0;
  std::vector<int32_t> stack;
  for (int32_t q0 = 0; q0 < nq; ++q0) {
    if (patch[q0] >= 0) continue;
    patch[q0] = count;
    stack.assign(1, q0);
    while (!stack.empty()) {
      const int32_t q = stack.back();
      stack.pop_back();
      for (int k = 0; k < 4; ++k) {
        const int32_t he = 4 * q + k;
        const int32_t o = adjacency.opposite[he];
        if (o < 0 || edges.kind[he] != EdgeKind::flat || patch[o >> 2] >= 0) continue;
        patch[o >> 2] = count;
        stack.push_back(o >> 2);
      }
    }
    ++count;
  }
  return patch;
}

}  // namespace hexpeel
