// Intrusion cover: a plan whose concave steps can be intruded (Kremer et al. 5.3-5.4).
//
// A concave step eliminates chord C towards its side S as if a layer of virtual hexes filled the
// concavity; at reconstruction the intrusion takes that layer out again: the hexes under S's
// quads at that moment. It is valid only when those are |S| distinct hexes forming a clean layer
// (paper 5.4; reconstruction.h checks it), which the paper leaves open. What decides it is the
// steps eliminated right after C, since they are reconstructed right before C is intruded:
// a convex step D whose side contains S while D's chord neither passes through S nor beside it
// lays one such clean layer under S. A convex step whose chord crosses S instead leaves hexes
// with two faces on S, and the intrusion is refused (it is then extruded: a valid mesh whose
// concavity is bounded by layers bent into the solid, with poor hexes there).
//
// cover_concave_steps rebuilds a plan so that every run of consecutive concave steps is
// followed by such covering steps, one per virtual layer (the smallest usable side that covers
// pending quads, whose chord keeps clear of them), and plans the rest of the surface again with
// the planner. It only reorders which chords go when; reconstruction still checks every
// intrusion, and the pipeline keeps the rebuilt plan only when none is refused.
#pragma once

#include "hexpeel/context.h"
#include "hexpeel/elimination.h"
#include "hexpeel/elimination_state.h"
#include "hexpeel/planner.h"

#include <cstdint>

namespace hexpeel {

struct IntrusionCoverStats {
  bool tried = false;             ///< a plan was rebuilt (the first plan had refused intrusions)
  bool kept = false;              ///< the rebuilt plan is the one meshed
  int32_t cover_steps = 0;        ///< covering steps inserted after concave runs
  int32_t replans = 0;            ///< planner runs for the rest after covering steps
  int32_t uncovered_quads = 0;    ///< virtual-layer quads no covering step was found for
  int32_t refused_before = 0;     ///< intrusions refused with the first plan
  int32_t refused_after = 0;      ///< ... and with the rebuilt one (-1 when it did not plan)
  int64_t predicted_hexes = 0;    ///< of the rebuilt plan
  double replan_effort_s = 0.0;   ///< planning work of the replans, in budget seconds
  double time_s = 0.0;            ///< rebuilding, planning and reconstruction of the rebuilt plan
                                  ///< (and of the flipped plans, below)
  // flip_refused_steps, when intrusions stayed refused in the plan meshed
  bool flip_tried = false;        ///< intrusions stayed refused in the plan meshed: flips ran
  bool flip_kept = false;         ///< ... and its mesh is the one kept
  int32_t flip_rounds = 0;        ///< flipped plans kept in turn (each refused fewer than the
                                  ///< last; each flips the steps the last one refused)
  int32_t flipped_steps = 0;      ///< steps turned to their other side, all rounds
  int32_t flip_refused_before = 0;  ///< intrusions refused by the plan that was flipped
  int32_t flip_refused_after = 0;   ///< ... and by the last flipped plan
};

/// Rebuilds `plan` (status ok, made on a state like `state`, no terminal fill) on `state`, which
/// must be fresh: replays its steps up to the end of its first run of concave steps, inserts
/// covering steps, plans the rest with run_planner(params) and goes on with the next concave run
/// of that plan. Virtual layers no covering step is found for are left to the plan's own later
/// steps (a later step may still lay them cleanly); after `max_replans` planner runs the rest
/// is replayed without covers. All replans together get params.budget_s (flat steps weighed by
/// the input's quad count); a planner run that finds no plan, or a spent budget, gives stuck. On success
/// `state` holds the new plan's final cube; its steps record concave and flat as the plans did.
EliminationPlan cover_concave_steps(EliminationState& state, const EliminationPlan& plan,
                                    const PlannerParams& params, const Context& ctx,
                                    IntrusionCoverStats& stats, int max_replans = 8);

/// The other remedy for refused intrusions: replays `plan` (status ok) on the fresh `state`,
/// eliminating each step listed in `refused` (indices into plan.steps, concave steps whose
/// intrusion was refused) towards its *other* side as a convex step. Extruding the refused side
/// instead (reconstruction's fallback) lays a layer outward into the concavity, where it must
/// fold; the other side's layer wraps the rest of the surface and meets the concavity with its
/// chord quads as walls, as Müller-Hannemann's method would build it (|other side| hexes more).
/// The set of chords eliminated is the same, so every step stays feasible; a step whose other
/// side is not usable is kept as it was. `flipped` counts the steps changed. On return `state`
/// holds the new plan's final surface.
EliminationPlan flip_refused_steps(EliminationState& state, const EliminationPlan& plan,
                                   const std::vector<int32_t>& refused, int32_t& flipped);

}  // namespace hexpeel
