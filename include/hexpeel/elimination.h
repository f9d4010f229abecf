// Elimination: dual cycle (chord) elimination down to a single cube (paper sections 3.1-3.4),
// greedy in the order of the rules of order.h. Returns an EliminationPlan that reconstruction
// replays in reverse.
#pragma once

#include "hexpeel/context.h"
#include "hexpeel/elimination_state.h"
#include "hexpeel/hex_mesh.h"
#include "hexpeel/order.h"
#include "hexpeel/status.h"

#include <array>
#include <string>
#include <vector>

namespace hexpeel {

struct EliminationParams {
  OrderParams order;          ///< ranking and side rules
  double time_limit_s = 0.0;  ///< stop with `stuck` after this long; 0 = no limit
};

struct StuckReport {
  int32_t quads_left = 0, chords_left = 0;
  /// how many remaining chords fail for each reason (index = Infeasible value)
  std::array<int32_t, 10> reasons{};
  std::string text;  ///< human readable aggregate
};

struct EliminationStats {
  int32_t steps = 0;
  int32_t flat_steps = 0;          ///< flat chords eliminated (nothing else was feasible)
  int32_t concave_steps = 0;       ///< steps to be reconstructed by intrusion (Kremer 5.3)
  int64_t predicted_hexes = 0;     ///< 1 + sum of |side|
  int32_t feasibility_tests = 0;
  double time_s = 0.0;
  bool timed_out = false;          ///< stopped (status stuck) by EliminationParams::time_limit_s
};

/// A hex complex of a plan's final surface when that is not a cube (terminal.h): complex
/// vertices 0..num_vertices-1, and for each final quad (in final_quads order) its face's
/// complex vertices in the quad's corner order.
struct TerminalFill {
  int32_t num_vertices = 0;
  std::vector<Hex> hexes;          ///< positive VTK hexes (final quads outward)
  std::vector<Quad> faces;         ///< per final quad
  bool empty() const { return hexes.empty(); }
};

struct EliminationPlan {
  Status status;                   ///< ok, stuck
  std::vector<PlanStep> steps;     ///< in elimination order
  std::vector<int32_t> final_quads;///< the surviving quad ids (when ok), ascending: a cube's 6,
                                   ///< or the surface `terminal` fills
  std::vector<Quad> final_corners; ///< their corners (merged input vertex ids), input order
  TerminalFill terminal;           ///< empty unless the plan ends on a filled stuck surface
  StuckReport stuck;               ///< when stuck
  EliminationStats stats;
};

/// Why no remaining chord of `state` can be eliminated: counts per reason, and a sentence.
StuckReport diagnose_stuck(const EliminationState& state);

/// ok, or self_intersecting_chord naming the first chord that passes through a quad twice
/// (dual cycle elimination needs every chord to be simple).
Status check_simple_chords(const EliminationState& state);

/// Greedy elimination in the paper's order, applied to `state` (fresh from its constructor).
/// Self-intersecting chords make the status `self_intersecting_chord` at once. Afterwards `state`
/// holds the final cube, or the stuck surface (for --dump-stuck).
EliminationPlan run_elimination(EliminationState& state, const EliminationParams& params = {},
                                const Context& ctx = {});

}  // namespace hexpeel
