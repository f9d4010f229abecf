// Does the boundary of a hex mesh equal a given quad surface? (DESIGN.md "Final boundary = input",
// checked from outside the pipeline, by position: the same test the independent checker does.)
//
// Every mesh boundary vertex is matched to the nearest surface vertex (used by some quad) within
// an absolute tolerance = relative tolerance * bbox diagonal of the surface, through a uniform
// grid of cell size = tolerance whose occupied cells are kept in one sorted array; a match must be
// unique in both directions. The mapped boundary quads and the surface quads are then compared as
// multisets of quads up to cyclic rotation and reversal, by sorting canonical forms.
// Input: a mesh whose ids were checked by analyze_topology, any surface (its ids are checked
// here). Output: match or not, and the first difference in words. O(n log n).
#include "quality_internal.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <tuple>

namespace hexpeel::quality_detail {
namespace {

using CellKey = std::array<int64_t, 3>;

struct GridEntry {
  CellKey key;
  int32_t vertex;  // surface vertex id
};

// Smallest of the 8 rotations / reversals of q: equal for quads that differ only by those.
Quad canonical(const Quad& q) {
  Quad best = q;
  for (int r = 0; r < 4; ++r) {
    const Quad fwd{q[r], q[(r + 1) % 4], q[(r + 2) % 4], q[(r + 3) % 4]};
    const Quad bwd{q[r], q[(r + 3) % 4], q[(r + 2) % 4], q[(r + 1) % 4]};
    best = std::min({best, fwd, bwd});
  }
  return best;
}

std::string point_text(const Vec3& p) {
  std::ostringstream s;
  s.precision(10);
  s << '(' << p.x() << ", " << p.y() << ", " << p.z() << ')';
  return s.str();
}

std::string quad_text(const Quad& q) {
  return "(" + std::to_string(q[0]) + ", " + std::to_string(q[1]) + ", " + std::to_string(q[2]) +
         ", " + std::to_string(q[3]) + ")";
}

struct Keyed {
  Quad canon;
  int32_t index;  // quad id (surface) or boundary quad index (mesh)
};

}  // namespace

BoundaryMatch match_boundary(const HexMesh& mesh, const ComplexTopology& topology,
                             const QuadSurface& surface, double tolerance) {
  if (!topology.ids_valid) return {false, "the mesh refers to missing points; boundary not compared"};
  const int32_t ns = surface.num_points();
  for (int32_t q = 0; q < surface.num_quads(); ++q)
    for (int32_t v : surface.quads[q])
      if (v < 0 || v >= ns)
        return {false, "surface quad " + std::to_string(q) + " refers to point " +
                           std::to_string(v) + " of " + std::to_string(ns)};

  std::vector<uint8_t> surface_used(ns, 0);
  for (const Quad& q : surface.quads)
    for (int32_t v : q) surface_used[v] = 1;
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (int32_t v = 0; v < ns; ++v) {
    if (!surface_used[v]) continue;
    if (!surface.points[v].allFinite())
      return {false, "surface point " + std::to_string(v) + " has a non-finite coordinate"};
    lo = lo.cwiseMin(surface.points[v]);
    hi = hi.cwiseMax(surface.points[v]);
  }
  const double diagonal = ns > 0 && lo.x() <= hi.x() ? (hi - lo).norm() : 0.0;
  const double tol = std::max(tolerance, 0.0) * diagonal;
  // Points within tol of each other have cell keys differing by at most one per axis. With a
  // zero tolerance only identical points match, and any cell size works for those.
  const double cell = tol > 0.0 ? tol : 1.0;
  auto key_of = [&](const Vec3& p) {
    CellKey k;
    for (int i = 0; i < 3; ++i) {
      const double c = std::clamp(std::floor((p[i] - lo[i]) / cell), -1e15, 1e15);
      k[i] = static_cast<int64_t>(c);
    }
    return k;
  };
  std::vector<GridEntry> grid;
  for (int32_t v = 0; v < ns; ++v)
    if (surface_used[v]) grid.push_back({key_of(surface.points[v]), v});
  std::sort(grid.begin(), grid.end(), [](const GridEntry& a, const GridEntry& b) {
    return std::tie(a.key, a.vertex) < std::tie(b.key, b.vertex);
  });

  // Mesh boundary vertices -> surface vertices.
  std::vector<int32_t> mesh_vertices;
  for (const Quad& q : topology.boundary_quads) mesh_vertices.insert(mesh_vertices.end(), q.begin(), q.end());
  std::sort(mesh_vertices.begin(), mesh_vertices.end());
  mesh_vertices.erase(std::unique(mesh_vertices.begin(), mesh_vertices.end()), mesh_vertices.end());
  std::vector<int32_t> to_surface(mesh.num_points(), -1), from_surface(ns, -1);
  for (int32_t v : mesh_vertices) {
    const Vec3& p = mesh.points[v];
    int32_t best = -1;
    double best_distance = std::numeric_limits<double>::infinity();
    if (p.allFinite()) {
      const CellKey k = key_of(p);
      for (int64_t dx = -1; dx <= 1; ++dx)
        for (int64_t dy = -1; dy <= 1; ++dy)
          for (int64_t dz = -1; dz <= 1; ++dz) {
            const CellKey nk{k[0] + dx, k[1] + dy, k[2] + dz};
            auto it = std::lower_bound(grid.begin(), grid.end(), nk,
                                       [](const GridEntry& e, const CellKey& key) { return e.key < key; });
            for (; it != grid.end() && it->key == nk; ++it) {
              const double d = (surface.points[it->vertex] - p).norm();
              if (d < best_distance || (d == best_distance && it->vertex < best)) {
                best_distance = d;
                best = it->vertex;
              }
            }
          }
    }
    if (best < 0 || !(best_distance <= tol)) {
      std::ostringstream s;
      s << "mesh boundary point " << v << " at " << point_text(p)
        << " has no surface vertex within " << tol;
      return {false, s.str()};
    }
    if (from_surface[best] >= 0)
      return {false, "mesh boundary points " + std::to_string(from_surface[best]) + " and " +
                         std::to_string(v) + " both lie on surface vertex " + std::to_string(best)};
    from_surface[best] = v;
    to_surface[v] = best;
  }

  // Quads as multisets of canonical forms.
  std::vector<Keyed> mesh_quads, surface_quads;
  for (size_t i = 0; i < topology.boundary_quads.size(); ++i) {
    Quad q = topology.boundary_quads[i];
    for (int32_t& v : q) v = to_surface[v];
    mesh_quads.push_back({canonical(q), static_cast<int32_t>(i)});
  }
  for (int32_t q = 0; q < surface.num_quads(); ++q)
    surface_quads.push_back({canonical(surface.quads[q]), q});
  auto by_canon = [](const Keyed& a, const Keyed& b) {
    return std::tie(a.canon, a.index) < std::tie(b.canon, b.index);
  };
  std::sort(mesh_quads.begin(), mesh_quads.end(), by_canon);
  std::sort(surface_quads.begin(), surface_quads.end(), by_canon);
  int32_t first_surface = std::numeric_limits<int32_t>::max();
  int32_t first_mesh = std::numeric_limits<int32_t>::max();
  size_t i = 0, j = 0;
  while (i < mesh_quads.size() || j < surface_quads.size()) {
    if (j == surface_quads.size() ||
        (i < mesh_quads.size() && mesh_quads[i].canon < surface_quads[j].canon)) {
      first_mesh = std::min(first_mesh, mesh_quads[i++].index);
    } else if (i == mesh_quads.size() || surface_quads[j].canon < mesh_quads[i].canon) {
      first_surface = std::min(first_surface, surface_quads[j++].index);
    } else {
      ++i;
      ++j;
    }
  }
  const std::string sizes = " (mesh boundary " + std::to_string(mesh_quads.size()) +
                            " quads, surface " + std::to_string(surface_quads.size()) + ")";
  if (first_surface != std::numeric_limits<int32_t>::max())
    return {false, "surface quad " + std::to_string(first_surface) + " " +
                       quad_text(surface.quads[first_surface]) +
                       " is not a boundary face of the mesh" + sizes};
  if (first_mesh != std::numeric_limits<int32_t>::max()) {
    const int32_t slot = topology.boundary_slots[first_mesh];
    return {false, "boundary face " + std::to_string(slot % 6) + " of hex " +
                       std::to_string(slot / 6) + ", points " +
                       quad_text(topology.boundary_quads[first_mesh]) + ", is not a surface quad" +
                       sizes};
  }
  return {true, {}};
}

}  // namespace hexpeel::quality_detail
