// Embedding: positions for the hex complex. Boundary vertices are copied from the input surface
// (never recomputed); interior vertices get an initial placement. Untangling and quality
// optimization are a later stage (issue "Geometry").
#pragma once

#include "hexpeel/context.h"
#include "hexpeel/hex_mesh.h"
#include "hexpeel/quad_surface.h"
#include "hexpeel/reconstruction.h"
#include "hexpeel/status.h"

namespace hexpeel {

struct PlacementParams {
  /// Interior vertices are the harmonic (uniform graph Laplacian) interpolation of the fixed
  /// boundary over the complex's edges, solved by conjugate gradients to this relative residual.
  double solver_tolerance = 1e-10;
  double min_separation = 1e-9;  ///< relative to the bbox diagonal: closer interior pairs are reported
};

struct PlacementStats {
  int32_t interior_vertices = 0;
  int32_t coincident_pairs = 0;   ///< vertex pairs closer than min_separation after the solve
  int32_t coincident_after = 0;   ///< ... after separating them (0 unless separation failed)
  int32_t nonpositive_hexes = 0;  ///< hexes with scaled Jacobian <= 0 after placement
  double time_s = 0.0;
};

struct PlacementResult {
  Status status;
  HexMesh mesh;   ///< complex vertex ids, boundary at input positions
  PlacementStats stats;
};

/// Harmonic (uniform graph Laplacian over the hex edges) positions for the vertices with
/// fixed[v] == 0, the others held where `points` has them; conjugate gradients to `tolerance`
/// (relative residual), the three coordinates solved in parallel (deterministic). Used by the
/// placement and by the untangler's boundary continuation (untangle.h).
Status harmonic_fill(const std::vector<Hex>& hexes, const std::vector<uint8_t>& fixed,
                     double tolerance, std::vector<Vec3>& points);

PlacementResult run_placement(const QuadSurface& surface, const HexComplex& complex,
                              const PlacementParams& params = {}, const Context& ctx = {});

}  // namespace hexpeel
