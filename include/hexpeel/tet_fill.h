// Hexes by way of tetrahedra: how the surface repair fills the repaired surface (issue 31,
// --repair-fill tets). The surface is triangulated as refine_surface's six-split does (each quad
// on its shorter diagonal), the solid is tetrahedralized keeping every surface triangle (gmsh's
// 3D Delaunay, its library loaded at run time), and every tetrahedron is split into four hexes
// (a corner, three edge midpoints, three face centroids, the centre). The complex's boundary is
// the surface split into six everywhere, vertex for vertex; it always exists when the
// tetrahedralization does, but its hexes are poor until placed and optimized.
#pragma once

#include "hexpeel/quad_surface.h"
#include "hexpeel/reconstruction.h"
#include "hexpeel/status.h"

#include <cstdint>
#include <vector>

namespace hexpeel {

struct TetFillStats {
  int32_t tetrahedra = 0;
  int32_t interior_nodes = 0;  ///< points the tetrahedralization added inside
  double time_s = 0.0;
};

struct TetFill {
  Status status;
  /// Boundary vertices are `refined`'s (input_vertex = its ids), interior ones new.
  HexComplex complex;
  /// Per complex vertex: the boundary ones as `refined` has them, the interior ones as the tet
  /// split puts them (midpoints, centroids). Every hex is positive where the input quads are
  /// planar parallelograms; elsewhere a hex at the boundary may start inverted (the pipeline
  /// places and untangles the complex anyway).
  std::vector<Vec3> points;
  TetFillStats stats;
};

/// Whether the tetrahedralizer is there: this build has gmsh's C API header and its library
/// (libgmsh.so.4.8) loads at run time; tet_fill fails saying so if not.
bool tet_fill_available();

/// `refined` must be refine_surface(surface, six = every quad) (its quads in that function's
/// order). Fails (with the reason) when the tetrahedralization fails or changes the surface.
/// Not reentrant across threads in the library it calls: calls are serialized.
TetFill tet_fill(const QuadSurface& surface, const QuadSurface& refined);

}  // namespace hexpeel
