// Internal pieces of the quality stage, shared by report.cpp and the tests: the topology of a
// hex complex (topology.cpp) and the comparison of its boundary with a surface
// (boundary_match.cpp). Not part of the public interface.
#pragma once

#include "hexpeel/hex_mesh.h"
#include "hexpeel/quad_surface.h"

#include <cstdint>
#include <string>
#include <vector>

namespace hexpeel::quality_detail {

/// Combinatorial facts about a hex complex. Faces are identified by their sorted vertex ids,
/// edges by their sorted end points, so coincident ids (not positions) define the gluing.
struct ComplexTopology {
  bool ids_valid = true;               ///< every hex corner is a valid point id
  int32_t vertices = 0;                ///< distinct point ids used by hexes
  int32_t edges = 0;                   ///< distinct edges of the complex
  int32_t faces = 0;                   ///< distinct faces of the complex
  int32_t boundary_faces = 0;          ///< faces used by exactly one hex
  int64_t euler_characteristic = 0;    ///< vertices - edges + faces - hexes
  int32_t singular_edges_interior = 0; ///< edges on no boundary face with other than 4 hexes
  int32_t singular_edges_boundary = 0; ///< edges on a boundary face with other than 2 hexes
  bool faces_manifold = true;          ///< every face used by one or two hexes
  bool is_ball = false;                ///< every check of analyze_topology passed
  std::string message;                 ///< failed checks with counts and first offending ids
  /// Faces used by one hex, corners as seen from outside the hex (kHexFaces order), sorted by
  /// slot 6*hex + local face.
  std::vector<Quad> boundary_quads;
  std::vector<int32_t> boundary_slots; ///< 6*hex + local face of each boundary quad
};

/// Counts, Euler characteristic, singular edges and the ball test: every face used by one or
/// two hexes; every edge link a cycle (interior edge) or a path (boundary edge); every vertex
/// link (one triangle per incident hex: the corner's three neighbours) a 2-sphere (interior
/// vertex) or a disk (boundary vertex); hexes connected through faces; the boundary surface
/// connected with Euler characteristic 2; the complex's Euler characteristic 1.
ComplexTopology analyze_topology(const HexMesh& mesh);

/// Whether hexes over vertices 0..num_vertices-1 form a ball (analyze_topology, positions unused).
inline bool is_ball(int32_t num_vertices, const std::vector<Hex>& hexes) {
  HexMesh m;
  m.points.assign(num_vertices, Vec3::Zero());
  m.hexes = hexes;
  return analyze_topology(m).is_ball;
}

struct BoundaryMatch {
  bool matches = false;
  std::string message;  ///< the first difference found, empty when matching
};

/// Compares the boundary quads of `topology` (computed from `mesh`) with `surface`: every mesh
/// boundary vertex must lie within `tolerance` * (bbox diagonal of the surface) of a distinct
/// surface vertex, and the quads, mapped through that, must equal the surface's quads as a
/// multiset up to rotation and reversal of each quad.
BoundaryMatch match_boundary(const HexMesh& mesh, const ComplexTopology& topology,
                             const QuadSurface& surface, double tolerance);

}  // namespace hexpeel::quality_detail
