// Reconstruction: the hex complex from an elimination plan (paper section 3.3, Kremer et al. 5.3,
// DESIGN.md invariants 2-5). One hex from the final cube, then one extrusion (convex step) or
// intrusion (concave step) per plan step in reverse order. Topology only; geometry is the
// embedding stage's job.
#pragma once

#include "hexpeel/context.h"
#include "hexpeel/elimination.h"
#include "hexpeel/hex_mesh.h"
#include "hexpeel/status.h"

#include <cstdint>
#include <vector>

namespace hexpeel {

/// A hex complex whose boundary is the input surface.
struct HexComplex {
  int32_t num_vertices = 0;
  std::vector<Hex> hexes;              ///< complex vertex ids, VTK order, positive for outward input
  std::vector<int32_t> input_vertex;   ///< complex vertex -> input surface vertex, -1 if interior
  std::vector<int32_t> created_at;     ///< plan step whose reconstruction created the vertex
                                       ///< (-1 = the initial hex); deeper = smaller
};

struct ReconstructionParams {
#ifdef NDEBUG
  bool verify_each_step = false;  ///< check invariant 2 after every step (O(n) each); needs `replay`
#else
  bool verify_each_step = true;
#endif
  /// A concave step whose intrusion is invalid (paper 5.4) is replayed as an extrusion of the same
  /// side instead (a valid complex with more hexes, as the original method would build), with a
  /// warning; false fails the run with invalid_intrusion. Either way the step is in the stats.
  bool fallback_to_extrusion = true;
};

struct ReconstructionStats {
  int32_t hexes = 0;
  int32_t slit_edges = 0;      ///< edges cut open because a chord touched itself
  int32_t steps_verified = 0;  ///< steps checked against the intermediate surface
  int32_t intrusions = 0;      ///< concave steps reconstructed by intrusion (paper 5.3)
  int32_t hexes_intruded = 0;  ///< hexes they removed
  int32_t vertices_removed = 0;  ///< vertices no hex used after intrusions (renumbered away)
  /// Plan steps whose intrusion was invalid (paper 5.4), in reconstruction order: they failed the
  /// run, or were extruded instead with fallback_to_extrusion.
  std::vector<int32_t> invalid_intrusion_steps;
  double time_s = 0.0;
};

struct ReconstructionResult {
  Status status;
  HexComplex complex;
  ReconstructionStats stats;
};

/// Replays `plan` (status ok) in reverse. When `replay` is the EliminationState the plan was made
/// on (at the plan's end) and verify_each_step is set, every step is checked against the
/// intermediate surface, undoing the state as it goes; intrusions are checked that way whenever
/// `replay` is given. The final boundary is always checked against `surface` (invariant 5); a
/// mismatch is an internal_error, an impossible intrusion is invalid_intrusion (unless
/// fallback_to_extrusion), never a wrong complex. Vertices no hex uses after intrusions are
/// removed (the complex has no orphan vertices).
ReconstructionResult run_reconstruction(const QuadSurface& surface, const EliminationPlan& plan,
                                        const ReconstructionParams& params = {},
                                        const Context& ctx = {},
                                        EliminationState* replay = nullptr);

}  // namespace hexpeel
