// Terminal fill: a hex complex for the surface where elimination got stuck, so that the plan's
// steps down to it can still be reconstructed (our extension; not in the paper).
//
// Elimination can reach a surface on which no chord can be eliminated (typically a vertex of
// valence 3 next to another: collapsing the chord between them would leave valence 2). That
// surface still bounds a ball, and any hex complex of it will do: the plan's steps are then
// reconstructed outwards from that complex instead of from a cube. The fill digs a pit: one layer
// of hexes under a small disc F of quads (a quad, two or three edge-connected quads, the quads
// around a vertex). The surface left inside the layer, P, has F's quads moved one layer in, a new
// ring of quads around them (a new chord) and one more edge at every vertex of F's rim, which
// lifts the valences that blocked the collapses. P is planned and reconstructed like any input
// (its positions are the stuck surface's, the copies a little inside, for the order rules). P's
// complex gets a whole pillow layer (so that the pit layer meets it exactly in P's floor and
// walls) and the pit layer then closes it back to the stuck surface. Discs are tried in a fixed
// order until one works; when none does, the pit surfaces that got furthest (stopped on the
// smallest surfaces) have those surfaces filled the same way, to a depth.
#pragma once

#include "hexpeel/context.h"
#include "hexpeel/elimination.h"
#include "hexpeel/elimination_state.h"
#include "hexpeel/planner.h"
#include "hexpeel/status.h"

#include <cstdint>

namespace hexpeel {

struct TerminalParams {
  bool enabled = true;
  /// Largest stuck surface (quads) a fill is tried on; larger ones stay stuck (> 0).
  int32_t max_quads = 400;
  /// Pits (discs F) tried at most on one stuck surface, over all depths (> 0). High, since a try
  /// whose surface is dead at once is cheap and a nested descent tries many pits.
  int32_t max_tries = 30000;
  /// Nested fills at most: a pit surface that gets stuck on a smaller surface is filled in turn
  /// (>= 1; 1 = the pits of the stuck surface alone).
  int32_t depth = 4;
  /// At each depth, once no pit alone completes the plan, the surfaces of at most this many pits
  /// are filled in turn, those that stopped at the fewest quads first (>= 1).
  int32_t descend = 4;
  /// Planning budget of each pit surface, in the planner's budget seconds (> 0).
  double budget_s = 1.0;
  /// Planning work of the whole fill, all pits and depths, in budget seconds (> 0), each try
  /// also charged 1e-6 per quad of its pit surface for the set-up. Most pit surfaces are dead at
  /// once (no chord can go), so a fill usually costs far less.
  double total_budget_s = 10.0;
  /// Sharp angle of the pit surfaces' edge classification (degrees; the mesh's own).
  double sharp_angle_deg = 60.0;
};

struct TerminalStats {
  bool tried = false;          ///< elimination was stuck and the fill ran
  bool filled = false;         ///< a fill was found (the plan is complete)
  int32_t stuck_quads = 0;     ///< quads of the stuck surface
  int32_t tries = 0;           ///< pit surfaces planned (all depths)
  double effort_s = 0.0;       ///< their planning work, in budget seconds
  int32_t pits = 0;            ///< pits in the fill found (nested ones included)
  int32_t pit_quads = 0;       ///< quads of the outermost disc F of the fill found
  int32_t hexes = 0;           ///< hexes of the fill
  double time_s = 0.0;
};

/// Fills the surface `state` is stuck on (`plan` holds the steps that led there, status stuck):
/// on success sets plan.final_quads / final_corners to that surface's quads, plan.terminal to
/// a hex complex of it and plan.status to ok; otherwise leaves `plan` as it was. `planner`
/// gives the order rules and seed for the pit surfaces (its budget is replaced by
/// params.budget_s). Deterministic.
TerminalStats fill_stuck_surface(const EliminationState& state, EliminationPlan& plan,
                                 const TerminalParams& params, const PlannerParams& planner,
                                 const Context& ctx = {});

}  // namespace hexpeel
