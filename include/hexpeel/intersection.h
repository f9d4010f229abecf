// Geometric self-intersection of a quad surface: pairs of quads that cut through or touch each
// other away from the vertices and edges they share (DESIGN.md "Input checking"). A surface that
// is a topological sphere but intersects itself bounds no solid, and no hex mesh of it can be
// valid, so validation refuses it naming the quads.
#pragma once

#include "hexpeel/quad_surface.h"

#include <cstdint>
#include <utility>
#include <vector>

namespace hexpeel {

struct SelfIntersections {
  /// Intersecting quad pairs (a < b), sorted, at most `max_pairs` of them.
  std::vector<std::pair<int32_t, int32_t>> pairs;
  int64_t total = 0;         ///< pairs found in all (may exceed pairs.size())
  int64_t tested = 0;        ///< triangle pairs given to the exact test (the broad phase's output)
};

/// Every quad is split into the two triangles of its better diagonal (the one whose triangles'
/// normals agree more), degenerate triangles are left out, and every pair of triangles from
/// different quads whose bounding boxes overlap is tested: triangles that share no vertex must
/// not meet at all; triangles that share one vertex only there; triangles that share an edge are
/// not tested (they are neighbours). Deterministic; linear in the surface's size for surfaces
/// whose quads have comparable sizes (a uniform grid of cells about two edge lengths wide).
SelfIntersections find_self_intersections(const QuadSurface& surface, int32_t max_pairs = 10);

}  // namespace hexpeel
