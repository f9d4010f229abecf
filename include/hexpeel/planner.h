// Planner: a search over elimination orders that does not get stuck where greedy elimination does,
// and chooses sides by hex cost (issue "Planner"; DESIGN.md "What a plan really chooses").
//
// The surface after eliminating a set of chords depends only on the set, so search states are
// memoized by the set (a Zobrist hash) and the side of a step changes only the plan's cost, never
// what is feasible later. The portfolio, within a budget of work (feasibility tests weighted by
// chord length, in "budget seconds" of about a wall-clock second each on the reference machine;
// no clock is read, so the plan never depends on machine speed or load):
//   1. cost-guided greedy in the OrderPolicy's order; when stuck, a complete depth-first search
//      over the last k steps (k = 1..window) with dead states remembered;
//   2. when that found no plan: conflict-directed search (chords left at stuck states gain
//      priority; restarts with small repair windows and fresh noise per round);
//   3. when the plan needed backtracking: beam search over partial plans scored by cost, and
//   4. randomized restarts (noisy priorities) of 1, looking for a cheaper plan.
// The best complete plan by cost is kept and replayed on the state.
#pragma once

#include "hexpeel/context.h"
#include "hexpeel/elimination.h"
#include "hexpeel/elimination_state.h"
#include "hexpeel/order.h"

#include <cstdint>
#include <string>

namespace hexpeel {

struct PlannerParams {
  OrderParams order;            ///< priorities and side rule (run_mesh passes its own, with
                                ///< SideRule::cost, the planner's default)
  /// Budget of the whole search in budget seconds (> 0): work, counted deterministically, of
  /// about a wall-clock second each on the reference machine.
  double budget_s = 30.0;
  /// Budget for looking for a cheaper plan once one was found by backtracking (beam + restarts),
  /// within budget_s (budget seconds, >= 0).
  double improve_budget_s = 10.0;
  uint64_t seed = 1;            ///< seed of the randomized restarts
  double flat_penalty = 0.0;    ///< cost per flat step, in hexes; 0 = the quad count of the input
  int window = 12;              ///< deepest backtrack of the windowed search (steps)
  int64_t window_nodes = 20000; ///< node budget of one windowed search
  int beam_width = 8;           ///< states kept per beam level
  int beam_moves = 4;           ///< moves expanded per state
  int conflict_window = 12;     ///< conflict search: deepest repair backtrack per round (steps)
  int64_t conflict_window_nodes = 20;   ///< conflict search: node budget per repair window
  double conflict_bump = 0.05;  ///< conflict search: first activity bump (weight units)
  double conflict_growth = 1.1; ///< conflict search: bump growth per round (> 1 = recent first)
  int restarts = 8;             ///< randomized restarts after the beam
  double noise = 0.3;           ///< priority noise of restarts (in weight units)
  /// When the first plan needed backtracking, run beam and restarts for a cheaper one too.
  bool improve = true;
};

struct PlannerStats {
  int64_t plans_tried = 0;        ///< complete plans found (by any strategy)
  int64_t nodes = 0;              ///< elimination steps applied during the search
  int64_t backtracks = 0;         ///< steps undone
  int64_t states_remembered = 0;  ///< dead states in the memo
  int64_t stuck_events = 0;       ///< greedy descents that got stuck
  int64_t conflict_rounds = 0;    ///< conflict-directed restarts that got stuck
  double best_cost = 0.0;         ///< cost of the chosen plan
  std::string strategy;           ///< which strategy found it: greedy, window, conflict, beam, restart
  double time_s = 0.0;
  double first_plan_s = 0.0;      ///< time until the first complete plan (0 = none found)
  double effort_s = 0.0;          ///< work done, in budget seconds (deterministic)
  bool budget_exhausted = false;
};

struct PlannerResult {
  EliminationPlan plan;   ///< status ok, stuck (nothing found in the budget) or self_intersecting_chord
  PlannerStats stats;
};

/// Searches an elimination order for a fresh `state`; afterwards `state` holds the final cube of
/// the chosen plan (for reconstruction's verification), or the deepest stuck surface found.
PlannerResult run_planner(EliminationState& state, const PlannerParams& params = {},
                          const Context& ctx = {});

}  // namespace hexpeel
